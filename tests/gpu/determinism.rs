//! Determinism: a canonical scene's state after N steps
//! hashes to a pinned value on lavapipe, and two separate processes write
//! byte-identical state files.

use std::process::Command;

use verlet::{scenes, World};

/// `cubes --count 200 --seed 1`, 300 steps of the default settings.
const STEPS: u64 = 300;

/// FNV-1a 64 of `read_raw`'s bytes after `STEPS` steps on lavapipe as
/// `PINNED_ON` names it (its vector width follows the CPU, and with it the
/// rounding). Other adapters round differently and are only reported.
/// Re-pinned for the solve by manifold: each manifold's points are measured
/// once per sweep for both bodies (solve_contacts, restitution_contacts)
/// and each body sums what its manifolds ask, and the pair walk visits half
/// the neighbour cells, which reorders the pairs, so the float sums round
/// differently. Re-pinned again for the displacement state: the
/// pose holds x_n - x_(n-1) and a rounding remainder instead of the previous
/// position (different bytes hashed, and integrate, the snaps and
/// restitution now round differently). Re-pinned for the separating-axis
/// test in the first box's frame (the same axes and choices, other roundings).
/// Re-pinned for the clip in the reference face's plane (the same points,
/// other roundings) and FACE_BIAS (the second box's face is the reference
/// face only when it beats the first's by 2.5 mm). Re-pinned for settling
/// (solve.wgsl: old overlap deeper than 1 m/s of a substep is pushed out by
/// moving the poses, not the velocities; the cubes land hard enough to
/// leave such overlap). Re-pinned for the speculative margin by relative
/// motion (pairs.wgsl's pair_margin: cubes falling side by side no longer
/// get contacts, so fewer manifolds are summed). Re-pinned for the contact
/// passes' rotation and inertia matrices (solve.wgsl, restitution.wgsl: the
/// same maths, other roundings) and friction's split against ends that stay
/// (solve.wgsl's friction_split). Re-pinned for the face clip by candidate
/// corners (collide.wgsl: edges' entries and exits and the reference face's
/// corners inside, always reduced; no duplicated points where a corner lies
/// on a side, other roundings). Re-pinned for normal pushes and dynamic
/// friction split against ends that stay (solve.wgsl's normal_split,
/// restitution.wgsl's cut; bodies wedged between sleepers no longer shake),
/// then by the body's shares of all its pushes (contact_lists' normal_split).
/// Re-pinned for the cap on support (solve.wgsl's SUPPORT_SPEED: a push out
/// of shallow old overlap becomes upward velocity only while the body rises
/// slower than 0.2 m/s; other bits for the landing cubes). Re-pinned for
/// the restitution pass's bounces scaled like the solve's pushes, and a
/// body's bouncing manifolds combined so that bounces the same way count
/// once (restitution.wgsl: a box landing flat across four sleeping boxes
/// left at 40 m/s; the landing cubes' bounces differ). Re-pinned for the
/// speculative margin that counts how far a body's turn moves its points,
/// with the fixed part 1 cm instead of 2 (pairs.wgsl's pair_margin,
/// grid.wgsl's spin_reach_of: the tumbling cubes get other contacts).
/// Re-pinned for dynamic friction bounded on the impulse, mu times the
/// push's through the inverse mass along the normal (restitution.wgsl: a
/// sliding ball had 3.5 times too little; tilted cubes' contacts differ).
/// Any change to the step's arithmetic (shaders, settings
/// defaults, the cubes scene) moves it on purpose: check the change, then
/// pin the value the failure prints.
const PINNED_LAVAPIPE: u64 = 0x8495_2691_e9d7_6b2d;
/// The adapter name and driver the hash was pinned on.
const PINNED_ON: (&str, &str) = ("llvmpipe (LLVM 15.0.6, 256 bits)", "Mesa 22.3.6 (LLVM 15.0.6)");

fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn canonical_hash(world: &mut World) -> u64 {
    world.step(STEPS).unwrap();
    let states = world.read_raw().unwrap();
    fnv1a(bytemuck::cast_slice(&states))
}

#[test]
fn canonical_scene_hash_is_pinned() {
    let Some(gpu) = crate::common::gpu() else { return };
    let scene = scenes::cubes(200, 1);
    let hash = canonical_hash(&mut World::with_gpu(gpu.clone(), &scene).unwrap());
    // The same process, a second world: the same bits.
    let again = canonical_hash(&mut World::with_gpu(gpu.clone(), &scene).unwrap());
    assert_eq!(hash, again, "two worlds in one process disagree: {hash:#018x} vs {again:#018x}");
    let adapter = gpu.describe();
    if gpu.info.name == PINNED_ON.0 && gpu.info.driver_info.contains(PINNED_ON.1) {
        assert_eq!(
            hash, PINNED_LAVAPIPE,
            "state hash of cubes(200, 1) after {STEPS} steps is {hash:#018x}, pinned {PINNED_LAVAPIPE:#018x} on {adapter}; \
             if the physics changed on purpose, pin the new value"
        );
    } else {
        eprintln!("state hash {hash:#018x} on {adapter} (pinned only for lavapipe)");
    }
}

#[test]
fn two_processes_write_identical_state_files() {
    if crate::common::gpu().is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("verlet-determinism-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |name: &str| {
        let out = dir.join(name);
        let result = Command::new(env!("CARGO_BIN_EXE_verlet"))
            .args(["run", "--builtin", "cubes", "--count", "200", "--steps", &STEPS.to_string(), "--state-out"])
            .arg(&out)
            .output()
            .expect("verlet binary runs");
        assert!(result.status.success(), "verlet run failed: {}", String::from_utf8_lossy(&result.stderr));
        std::fs::read(&out).unwrap()
    };
    let first = run("first.json");
    let second = run("second.json");
    assert!(first.len() > 200 * 100, "state file of 200 bodies is only {} bytes", first.len());
    if let Some(at) = first.iter().zip(&second).position(|(a, b)| a != b) {
        panic!("state files differ first at byte {at}");
    }
    assert_eq!(first.len(), second.len());
    let _ = std::fs::remove_dir_all(&dir);
}
