//! Snapshots: restoring and continuing is bit-identical to
//! a straight run, through the API and through a file; files that are not
//! snapshots, and snapshots of other scenes, are refused.

use verlet::world::snapshot::Snapshot;
use verlet::{scenes, Scene, World};

fn bytes(world: &World) -> Vec<u8> {
    bytemuck::cast_slice(&world.read_raw().expect("readback")).to_vec()
}

/// A file in a temp dir of its own, both removed when dropped: the tests
/// leave nothing behind.
struct TempFile(std::path::PathBuf);

impl std::ops::Deref for TempFile {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::path::Path> for TempFile {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
        if let Some(dir) = self.0.parent() {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

fn temp(name: &str) -> TempFile {
    let dir = std::env::temp_dir().join(format!("verlet-snapshot-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    TempFile(dir.join(name))
}

/// Run A: 200 steps straight. Run B: 100 steps, snapshot (through a file
/// when `via_file`), a fresh world restored from it, 100 more steps.
fn continue_is_bit_identical(scene: &Scene, via_file: bool) {
    let Some(gpu) = crate::common::gpu() else { return };
    let mut a = World::with_gpu(gpu.clone(), scene).unwrap();
    a.step(200).unwrap();

    let mut b = World::with_gpu(gpu.clone(), scene).unwrap();
    b.step(100).unwrap();
    let mut snap = b.snapshot().unwrap();
    assert_eq!(snap.step(), 100);
    assert_eq!(snap.body_count(), scene.bodies.len());
    drop(b);
    if via_file {
        let path = temp(&format!("b{}.snap", scene.bodies.len()));
        snap.write(&path).unwrap();
        let size = std::fs::metadata(&path).unwrap().len();
        assert_eq!(size, 56 + 65 * scene.bodies.len() as u64, "56 bytes of header and checksum, 65 per body");
        let again = Snapshot::read(&path).unwrap();
        assert_eq!(again, snap);
        snap = again;
    }
    let mut c = World::with_gpu(gpu, scene).unwrap();
    c.restore(&snap).unwrap();
    assert_eq!(c.step_count(), 100);
    c.step(100).unwrap();
    assert_eq!(c.step_count(), a.step_count());
    assert_eq!(c.time(), a.time());
    let (ba, bc) = (bytes(&a), bytes(&c));
    let differ = ba.chunks(64).zip(bc.chunks(64)).filter(|(x, y)| x != y).count();
    assert!(differ == 0, "{differ} of {} bodies differ after restore + 100 steps", scene.bodies.len());
    assert_eq!(a.read_state().unwrap(), c.read_state().unwrap(), "velocities use dt_prev");
}

/// A sleeper an awake body woke in the step before the snapshot wakes in
/// the step after it, restored or not (the wake flags are in the snapshot):
/// the restored run matches the straight one at every step.
#[test]
fn restore_keeps_a_wake_that_is_due() {
    let Some(gpu) = crate::common::gpu() else { return };
    let mut scene = scenes::stack(1); // a unit box on the ground, asleep from about 0.5 s
    scene.bodies.push(scenes::sphere_body(0.25, [0.0, 12.0, 0.0])); // lands at about 1.5 s
    let mut a = World::with_gpu(gpu.clone(), &scene).unwrap();
    let snap = loop {
        a.step(1).unwrap();
        let snap = a.snapshot().unwrap();
        if snap.woken().iter().any(|&w| w != 0) {
            break snap;
        }
        assert!(a.step_count() < 150, "the ball never woke the box");
    };
    assert!(snap.states()[0].rest_time >= verlet::scene::SLEEP_AFTER, "the box should still sleep when the snapshot is taken");
    let path = temp("woken.snap");
    snap.write(&path).unwrap();
    let mut c = World::with_gpu(gpu, &scene).unwrap();
    c.restore(&Snapshot::read(&path).unwrap()).unwrap();
    for _ in 0..30 {
        a.step(1).unwrap();
        c.step(1).unwrap();
        assert_eq!(bytes(&a), bytes(&c), "the restored run differs from the straight one at step {}", a.step_count());
    }
}

#[test]
fn restore_continues_bit_identically_cubes() {
    continue_is_bit_identical(&scenes::cubes(200, 1), false);
}

#[test]
fn restore_from_file_continues_bit_identically_cubes() {
    continue_is_bit_identical(&scenes::cubes(200, 1), true);
}

#[test]
fn restore_from_file_continues_bit_identically_joints() {
    let scene = scenes::by_name("ragdoll", None, 1).expect("ragdoll scene");
    continue_is_bit_identical(&scene, true);
    let chain = scenes::by_name("chain", Some(12), 1).expect("chain scene");
    continue_is_bit_identical(&chain, true);
}

#[test]
fn restore_rewinds_a_world() {
    let Some(gpu) = crate::common::gpu() else { return };
    let scene = scenes::cubes(50, 3);
    let mut w = World::with_gpu(gpu, &scene).unwrap();
    w.step(30).unwrap();
    let snap = w.snapshot().unwrap();
    let at30 = bytes(&w);
    w.step(40).unwrap();
    let at70 = bytes(&w);
    w.restore(&snap).unwrap();
    assert_eq!(bytes(&w), at30);
    assert_eq!(w.step_count(), 30);
    w.step(40).unwrap();
    assert_eq!(bytes(&w), at70, "rewinding into the same world and replaying is bit-identical");
}

#[test]
fn restore_into_another_scene_is_refused() {
    let Some(gpu) = crate::common::gpu() else { return };
    let scene = scenes::cubes(20, 1);
    let mut w = World::with_gpu(gpu.clone(), &scene).unwrap();
    w.step(5).unwrap();
    let snap = w.snapshot().unwrap();

    // Another body count.
    let mut other = World::with_gpu(gpu.clone(), &scenes::cubes(21, 1)).unwrap();
    let e = other.restore(&snap).unwrap_err().to_string();
    assert!(e.contains("another scene"), "{e}");

    // Same count and positions, one mass changed.
    let mut heavier = scene.clone();
    heavier.bodies[7].mass *= 2.0;
    let mut other = World::with_gpu(gpu.clone(), &heavier).unwrap();
    let before = bytes(&other);
    let e = other.restore(&snap).unwrap_err().to_string();
    assert!(e.contains("another scene"), "{e}");
    assert_eq!(bytes(&other), before, "a refused restore changes nothing");
    assert_eq!(other.step_count(), 0);

    // Same bodies, other settings.
    let mut slower = scene.clone();
    slower.settings.iterations += 1;
    let mut other = World::with_gpu(gpu, &slower).unwrap();
    assert!(other.restore(&snap).is_err());
}

#[test]
fn bad_files_are_refused_with_a_reason() {
    let Some(gpu) = crate::common::gpu() else { return };
    let scene = scenes::cubes(3, 1);
    let mut w = World::with_gpu(gpu, &scene).unwrap();
    w.step(2).unwrap();
    let good = w.snapshot().unwrap().to_bytes();
    assert_eq!(Snapshot::from_bytes(&good).unwrap(), w.snapshot().unwrap());

    let mut cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty", vec![], "not a verlet snapshot"),
        ("json", br#"{"step": 1}"#.to_vec(), "not a verlet snapshot"),
        ("magic only", b"VRLTSNAP".to_vec(), "truncated"),
        ("truncated", good[..good.len() - 9].to_vec(), "bodies should be"),
        ("padded", [good.clone(), vec![0; 64]].concat(), "bodies should be"),
    ];
    let mut version = good.clone();
    version[8] = 4; // versions 1 and 2 (converted) and 3 are read
    cases.push(("version", version, "version 4"));
    let mut flipped = good.clone();
    flipped[100] ^= 1;
    cases.push(("bit flip", flipped, "corrupt"));
    let mut huge = good.clone();
    huge[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    cases.push(("huge count", huge, "bodies should be"));
    for (name, data, why) in cases {
        let e = Snapshot::from_bytes(&data).unwrap_err();
        assert!(e.contains(why), "{name}: {e:?} should say {why:?}");
        let path = temp(&format!("bad-{}.snap", name.replace(' ', "_")));
        std::fs::write(&path, &data).unwrap();
        let e = Snapshot::read(&path).unwrap_err().to_string();
        assert!(e.contains(why) && e.contains(&*path.to_string_lossy()), "{name}: {e}");
    }
    let missing = Snapshot::read(temp("missing.snap")).unwrap_err().to_string();
    assert!(missing.contains("missing.snap"), "{missing}");

    // Random garbage of every length up to a few headers: refused, never a panic.
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    for len in 0..400 {
        let data: Vec<u8> = (0..len)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u8
            })
            .collect();
        assert!(Snapshot::from_bytes(&data).is_err());
        let mut headed = good.clone();
        headed.truncate(len.min(good.len()));
        headed.extend_from_slice(&data);
        let _ = Snapshot::from_bytes(&headed);
    }
}

/// With two substeps a step flips the pose buffers three times (`integrate`
/// in each, `restitution` after the last), so after an odd number of steps
/// the original world's current buffer is the other one than a fresh
/// world's: only the current poses carry state.
#[test]
fn restore_does_not_depend_on_which_buffer_is_current() {
    let Some(gpu) = crate::common::gpu() else { return };
    let mut scene = scenes::cubes(100, 2);
    scene.settings.substeps = 2;
    scene.settings.iterations = 3;
    let mut a = World::with_gpu(gpu.clone(), &scene).unwrap();
    a.step(160).unwrap();
    let mut b = World::with_gpu(gpu.clone(), &scene).unwrap();
    b.step(101).unwrap();
    let snap = b.snapshot().unwrap();
    let mut c = World::with_gpu(gpu, &scene).unwrap();
    c.restore(&snap).unwrap();
    c.step(59).unwrap();
    assert_eq!(bytes(&a), bytes(&c));
}

/// The scene hash a snapshot carries does not move when the GPU's layout of
/// the bodies' properties does (BodyProps' members were reordered so that a
/// contact reads its end's material, shape and flags in one load): a
/// snapshot taken by an earlier build still restores. The scene holds every
/// kind of property: boxes and a ball, fixed posts, a body kept out of the
/// grid (a slab wider than its cells), materials of its own and joints.
#[test]
fn scene_hash_is_pinned() {
    let Some(gpu) = crate::common::gpu() else { return };
    let mut scene = scenes::bridge(3);
    let mut ball = scenes::sphere_body(0.4, [1.0, 5.0, 0.0]);
    ball.restitution = Some(0.7);
    ball.friction = Some(0.3);
    scene.bodies.push(ball);
    scene.bodies.push(scenes::box_body([20.0, 0.25, 20.0], [0.0, 8.0, 0.0]));
    let hash = World::with_gpu(gpu, &scene).unwrap().snapshot().unwrap().scene_hash();
    assert_eq!(
        hash, PINNED_SCENE_HASH,
        "scene hash {hash:#018x}, pinned {PINNED_SCENE_HASH:#018x}: snapshots taken before no longer restore"
    );
}

/// `scene_hash_is_pinned`'s scene hash. It covers the settings and the
/// joint lists as the GPU holds them (islands, then paths by colour), so a
/// change to either moves it on purpose.
const PINNED_SCENE_HASH: u64 = 0xf8d9_8f19_3f30_da89;
