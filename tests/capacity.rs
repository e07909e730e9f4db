//! Memory and capacity (issue 3, part 6): a scene beyond the adapter's limits
//! is refused before any allocation; a full contact list is reported.

mod common;

use glam::Vec3;
use verlet::scenes::{self, box_body, sphere_body};
use verlet::world::max_bodies;
use verlet::{Error, World};

#[test]
fn a_scene_beyond_the_adapters_limits_is_refused_before_allocating() {
    let Some(gpu) = common::gpu() else { return };
    let max = max_bodies(&gpu) as usize;
    let mut scene = scenes::stack(0);
    scene.bodies = (0..max + 1).map(|k| box_body([0.5; 3], [2.0 * (k % 1000) as f32, 0.5, 2.0 * (k / 1000) as f32])).collect();
    match World::with_gpu(gpu.clone(), &scene) {
        Err(Error::Capacity(why)) => {
            eprintln!("refused: {why}");
            assert!(why.contains(&format!("{}", max + 1)), "the reason names the body count: {why}");
        }
        Err(other) => panic!("refused for the wrong reason: {other}"),
        Ok(_) => panic!("a scene of {} bodies was accepted; the adapter holds {max}", max + 1),
    }
    // nothing was allocated, so the device is still healthy
    gpu.check().unwrap();
}

#[test]
fn a_full_contact_list_is_reported() {
    // one ball touched by 40 small balls spread over its surface: more points
    // than one body's list holds
    let mut scene = scenes::stack(0);
    scene.ground = None;
    scene.settings.gravity = [0.0; 3];
    scene.bodies.push(sphere_body(1.0, [0.0; 3]));
    let n = 40;
    for k in 0..n {
        // Fibonacci sphere
        let y = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
        let phi = k as f32 * std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let dir = Vec3::new((1.0 - y * y).sqrt() * phi.cos(), y, (1.0 - y * y).sqrt() * phi.sin());
        scene.bodies.push(sphere_body(0.2, (dir * 1.19).to_array()));
    }
    let Some(mut w) = common::world(&scene) else { return };
    w.step(1).unwrap();
    let report = w.contact_report().unwrap();
    eprintln!("{report:?}");
    assert!(report.overflowed(), "40 touching neighbours did not overflow a list of {}: {report:?}", report.capacity);
    assert!(report.run_max >= n, "the report undercounts: {report:?}");
}
