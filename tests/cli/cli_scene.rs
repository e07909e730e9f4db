//! What `verlet scene` prints: Box3D's benchmark scenes and the scenes of
//! hulls load as scene files, at their default sizes and at a `--count`.

use crate::common::verlet;
use verlet::scene::{Scene, Shape};

#[test]
fn box3ds_scenes_print_as_scenes_that_load() {
    for (args, bodies, joints) in [
        (&["scene", "large_pyramid"][..], 5050, 0),
        (&["scene", "large_pyramid", "--count", "4"], 10, 0),
        (&["scene", "many_pyramids"], 10_780, 0),
        (&["scene", "many_pyramids", "--count", "2"], 220, 0),
        (&["scene", "joint_grid"], 10_000, 19_800),
        (&["scene", "joint_grid", "--count", "3"], 9, 12),
    ] {
        let out = verlet(args);
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        let scene = Scene::from_json_str(&String::from_utf8_lossy(&out.stdout)).unwrap_or_else(|e| panic!("{args:?}: {e}"));
        assert_eq!((scene.bodies.len(), scene.joints.len()), (bodies, joints), "{args:?}");
        assert_eq!(scene.settings.gravity, [0.0, -10.0, 0.0], "{args:?}: Box3D's gravity");
    }
}

/// `verlet scene NAME ARGS`'s output, which must succeed, and the scene it loads as.
fn printed(args: &[&str]) -> (Vec<u8>, Scene) {
    let out = verlet(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let scene = Scene::from_json_str(&String::from_utf8_lossy(&out.stdout)).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    (out.stdout, scene)
}

/// Rocks of convex hulls, as many as `--count` asks, the same for a seed
/// every time and others for another seed.
#[test]
fn convex_pile_prints_seeded_rocks_that_load() {
    let (text, scene) = printed(&["scene", "convex_pile", "--count", "60", "--seed", "5"]);
    assert_eq!(scene.bodies.len(), 60);
    for (n, b) in scene.bodies.iter().enumerate() {
        assert!(matches!(b.shape, Shape::Hull(_)) && b.is_dynamic(), "rock {n}: {b:?}");
    }
    assert_eq!(printed(&["scene", "convex_pile", "--count", "60", "--seed", "5"]).0, text, "the same seed, another scene");
    assert_ne!(printed(&["scene", "convex_pile", "--count", "60", "--seed", "6"]).0, text, "another seed, the same scene");
    assert_eq!(printed(&["scene", "convex_pile"]).1.bodies.len(), 1000, "its default count");
}

/// Box3D's washer: the cubes `--count` asks for a side, in a drum of 36
/// panels and 4 baffles, kinematic hulls turning about the drum's axis at
/// one speed, closed by two fixed boxes; the same every time.
#[test]
fn washer_prints_a_drum_of_kinematic_hulls_that_loads() {
    let (text, scene) = printed(&["scene", "washer", "--count", "3"]);
    assert_eq!(scene.bodies.len(), 27 + 42);
    let drum: Vec<_> = scene.bodies.iter().filter(|b| b.kinematic).collect();
    assert_eq!(drum.len(), 40);
    for b in &drum {
        assert!(matches!(b.shape, Shape::Hull(_)), "{b:?}");
        assert_eq!(b.angular_velocity, drum[0].angular_velocity, "one spin for the whole drum");
        assert_eq!(b.position, drum[0].position, "every panel turns about the axis");
    }
    let spin = drum[0].angular_velocity;
    assert!(spin[0] == 0.0 && spin[1] == 0.0 && (spin[2] - 25f32.to_radians()).abs() < 1e-6, "{spin:?}");
    let walls = scene.bodies.iter().filter(|b| b.fixed && matches!(b.shape, Shape::Box { .. })).count();
    let cubes = scene.bodies.iter().filter(|b| b.is_dynamic() && b.shape == Shape::Box { half_extents: [0.2; 3] }).count();
    assert_eq!((walls, cubes), (2, 27));
    assert_eq!(printed(&["scene", "washer", "--count", "3"]).0, text, "the same count, another scene");
    assert_eq!(printed(&["scene", "washer"]).1.bodies.len(), 8042, "Box3D's 20 x 20 x 20 cubes by default");
}
