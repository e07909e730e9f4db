//! What `verlet scene` prints: Box3D's benchmark scenes load as scene files,
//! at their default sizes and at a `--count`.

use crate::common::verlet;
use verlet::scene::Scene;

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
