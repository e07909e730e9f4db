//! Known answers for the integrator and the ground contacts.

use crate::common::{quat, v3, world};
use glam::{DVec3, Quat, Vec3};
use verlet::scenes::{box_body, sphere_body};
use verlet::{Ground, Scene, Settings};

fn empty(settings: Settings, ground: bool) -> Scene {
    Scene { settings, ground: ground.then_some(Ground { height: 0.0 }), bodies: vec![], joints: vec![], camera: None }
}

fn parabola(x0: [f32; 3], v0: [f32; 3], g: [f32; 3], t: f64) -> DVec3 {
    let f = |a: [f32; 3]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    f(x0) + f(v0) * t + 0.5 * f(g) * t * t
}

#[test]
fn projectile_stays_on_its_parabola() {
    let mut scene = empty(Settings::default(), false);
    let (x0, v0) = ([0.0, 1.0, 0.0], [3.0, 8.0, -1.0]);
    let mut b = box_body([0.2; 3], x0);
    b.linear_velocity = v0;
    scene.bodies.push(b);
    let Some(mut w) = world(&scene) else { return };
    let mut worst = 0.0f64;
    for _ in 0..12 {
        w.step(10).unwrap();
        let s = w.read_state().unwrap();
        let want = parabola(x0, v0, scene.settings.gravity, w.time());
        worst = worst.max((v3(s[0].position).as_dvec3() - want).length());
    }
    assert!((w.time() - 2.0).abs() < 1e-4);
    eprintln!("projectile: farthest from the parabola over 2 s: {worst} m");
    assert!(worst < 0.002, "left the parabola by {worst} m");
}

#[test]
fn time_corrected_verlet_follows_the_parabola_when_dt_alternates() {
    let mut scene = empty(Settings::default(), false);
    let (x0, v0) = ([0.0, 1.0, 0.0], [2.0, 9.0, 0.5]);
    let mut b = sphere_body(0.2, x0);
    b.linear_velocity = v0;
    scene.bodies.push(b);
    let Some(mut w) = world(&scene) else { return };
    let mut worst = 0.0f64;
    // 2 s as 80 pairs of 1/60 s and 1/120 s
    for _ in 0..20 {
        let dts: Vec<f32> = (0..8).map(|k| if k % 2 == 0 { 1.0 / 60.0 } else { 1.0 / 120.0 }).collect();
        w.step_with(&dts).unwrap();
        let s = w.read_state().unwrap();
        let want = parabola(x0, v0, scene.settings.gravity, w.time());
        worst = worst.max((v3(s[0].position).as_dvec3() - want).length());
    }
    assert!((w.time() - 2.0).abs() < 1e-3, "time {}", w.time());
    eprintln!("alternating dt: farthest from the parabola over 2 s: {worst} m");
    assert!(worst < 0.005, "left the parabola by {worst} m");
}

/// Farthest each body of `starts` strays from its parabola over 2 s (m),
/// launched with the same velocity, at `substeps` substeps of 1/60 s steps.
fn parabola_errors(starts: &[[f32; 3]], v0: [f32; 3], substeps: u32) -> Option<Vec<f64>> {
    let mut scene = empty(Settings { substeps, ..Settings::default() }, false);
    for &x0 in starts {
        let mut b = sphere_body(0.2, x0);
        b.linear_velocity = v0;
        scene.bodies.push(b);
    }
    let mut w = world(&scene)?;
    let mut worst = vec![0.0f64; starts.len()];
    for _ in 0..24 {
        w.step(5).unwrap();
        let s = w.read_state().unwrap();
        for (k, &x0) in starts.iter().enumerate() {
            let want = parabola(x0, v0, scene.settings.gravity, w.time());
            worst[k] = worst[k].max((DVec3::from_array(s[k].position.map(|v| v as f64)) - want).length());
        }
    }
    assert!((w.time() - 2.0).abs() < 1e-4);
    Some(worst)
}

// Verlet kept as pos - prev_pos lost the velocity's low bits far
// from the origin (155 mm off at 100 m up); the displacement and the
// position's rounding remainder (common.wgsl, BodyState) keep every start
// on its parabola. The launch has a component along every axis, so no
// coordinate sits still where rounding could not show.
#[test]
fn projectiles_far_from_the_origin_stay_on_their_parabolas() {
    let starts = [
        [0.0, 0.0, 0.0],
        [0.0, 100.0, 0.0],
        [1000.0, 0.0, 0.0],
        [0.0, 1000.0, 0.0],
        [0.0, 0.0, 1000.0],
        [-1000.0, 0.0, 0.0],
        [0.0, 0.0, -1000.0],
    ];
    let v0 = [3.3, 10.7, -2.9];
    for substeps in [Settings::default().substeps, 8] {
        let Some(worst) = parabola_errors(&starts, v0, substeps) else { return };
        let report: Vec<String> = starts.iter().zip(&worst).map(|(x0, e)| format!("from {x0:?}: {:.3} mm", e * 1e3)).collect();
        eprintln!("{substeps} substeps, farthest from the parabola over 2 s: {}", report.join(", "));
        assert!(
            worst.iter().all(|&e| e < 0.002),
            "{substeps} substeps: a projectile left its parabola by more than 2 mm: {}",
            report.join(", ")
        );
    }
}

// The state and the trace report velocities at the step's
// time, so a scene's velocities read back as given at step 0, free fall
// reads v0 + g t, and a box at rest on the ground reads 0.
#[test]
fn velocities_read_back_at_the_steps_time() {
    let mut scene = empty(Settings::default(), true);
    let given = [[0.0, 0.0, 0.0], [1.5, 4.0, -2.5], [-20.0, 30.0, 10.0]];
    for (k, v) in given.iter().enumerate() {
        let mut b = sphere_body(0.2, [10.0 * k as f32, 50.0, 0.0]);
        b.linear_velocity = *v;
        scene.bodies.push(b);
    }
    scene.bodies.push(box_body([0.5; 3], [-10.0, 0.5, 0.0])); // resting on the ground
    let mut fixed = box_body([0.5; 3], [-20.0, 3.0, 0.0]);
    fixed.fixed = true;
    scene.bodies.push(fixed);
    let Some(mut w) = world(&scene) else { return };
    let s = w.read_state().unwrap();
    for (k, v) in given.iter().enumerate() {
        let err = (v3(s[k].linear_velocity) - v3(*v)).length();
        assert!(err < 1e-5, "body {k} given {v:?} reads {:?} at step 0", s[k].linear_velocity);
    }
    // (f32: the displacement -g h^2 / 2 is stored rounded)
    assert!(v3(s[3].linear_velocity).length() < 1e-6, "a body given no velocity reads {:?} at step 0", s[3].linear_velocity);
    assert_eq!(s[4].linear_velocity, [0.0; 3], "a fixed body reads no velocity");
    let g = DVec3::from_array(scene.settings.gravity.map(|v| v as f64));
    let mut worst = 0.0f64;
    for _ in 0..6 {
        w.step(10).unwrap();
        let s = w.read_state().unwrap();
        for (k, v) in given.iter().enumerate() {
            let want = DVec3::from_array(v.map(|c| c as f64)) + g * w.time();
            let got = DVec3::from_array(s[k].linear_velocity.map(|c| c as f64));
            // f32: the displacement is held to 6e-8 of itself, summed over
            // the substeps
            let err = (got - want).length() / want.length().max(1.0);
            worst = worst.max(err);
            assert!(err < 1e-4, "body {k} at t = {} reads {got:?}, v0 + g t = {want:?}", w.time());
        }
        assert!(v3(s[3].linear_velocity).length() < 1e-3, "resting box reads {:?}", s[3].linear_velocity);
        assert_eq!(s[4].linear_velocity, [0.0; 3], "a fixed body reads no velocity");
    }
    eprintln!("free fall: velocity within {worst:.2e} (relative) of v0 + g t");
    // a velocity set between steps reads back as set, too
    w.set_velocity(1, [2.0, -1.0, 0.5], [0.0; 3]).unwrap();
    let v = w.read_state().unwrap()[1].linear_velocity;
    assert!((v3(v) - Vec3::new(2.0, -1.0, 0.5)).length() < 1e-5, "set 2, -1, 0.5; reads {v:?}");
}

#[test]
fn box_spinning_about_a_principal_axis_keeps_its_spin() {
    let mut scene = empty(Settings { gravity: [0.0; 3], ..Settings::default() }, false);
    let q0 = Quat::from_rotation_x(0.3);
    let omega = q0 * Vec3::new(0.0, 0.0, 3.0); // the body's own z axis, in world axes
    let mut b = box_body([0.5, 0.3, 0.2], [0.0, 0.0, 0.0]);
    b.orientation = q0.to_array();
    b.angular_velocity = omega.to_array();
    scene.bodies.push(b);
    let Some(mut w) = world(&scene) else { return };
    for _ in 0..24 {
        w.step(10).unwrap();
        let s = w.read_state().unwrap()[0];
        let q = quat(s.orientation);
        assert!((q.length() - 1.0).abs() < 1e-4, "|q| = {}", q.length());
        let err = (v3(s.angular_velocity) - omega).length() / omega.length();
        assert!(err < 0.01, "spin changed by {:.3}% at t = {}", err * 100.0, w.time());
    }
    let q = quat(w.read_state().unwrap()[0].orientation);
    let predicted = Quat::from_scaled_axis(omega * w.time() as f32) * q0;
    let angle = predicted.angle_between(q);
    eprintln!("spin: {angle} rad from the predicted orientation after {} s", w.time());
    assert!(angle < 0.01, "ended {angle} rad away from the predicted orientation");
}

#[test]
fn linear_damping_decays_speed_as_eq_12() {
    let beta = 0.05f32;
    let settings = Settings { gravity: [0.0; 3], linear_damping: beta, ..Settings::default() };
    let mut scene = empty(settings, false);
    let mut b = box_body([0.5; 3], [0.0; 3]);
    b.linear_velocity = [4.0, 0.0, 0.0];
    scene.bodies.push(b);
    let Some(mut w) = world(&scene) else { return };
    for _ in 0..6 {
        w.step(10).unwrap();
        let v = v3(w.read_state().unwrap()[0].linear_velocity).length() as f64;
        let want = 4.0 * (1.0 - beta as f64).powi(w.step_count() as i32);
        assert!((v - want).abs() / want < 1e-3, "speed {v}, eq. 12 says {want} after {} steps", w.step_count());
    }
}

/// A ball of restitution 0.8 dropped onto the ground rebounds to e^2 of its
/// fall, wherever in a step it lands: the bounce is asked in the substep
/// of the landing (restitution_contacts) and applied by the next
/// substep's integrate, or by the pass "restitution" after a step's last
/// substep (restitution.wgsl's `restituted`). The falls are chosen so the
/// landing (the centre crossing one radius, by the parabola the substeps
/// sample exactly) falls in each of the three substeps of step 57.
#[test]
fn sphere_rebounds_to_restitution_squared_of_its_fall_in_any_substep() {
    let radius = 0.5f32;
    let g = 9.81f64;
    let substeps = 3.0;
    for substep in 0..3 {
        // the landing a sixth into that substep
        let t = (57.0 + (substep as f64 + 1.0 / 6.0) / substeps) / 60.0;
        let fall = (0.5 * g * t * t) as f32;
        let mut scene = verlet::scenes::sphere();
        assert_eq!(scene.settings.substeps, 3);
        scene.bodies[0].position[1] = radius + fall;
        let Some(mut w) = world(&scene) else { return };
        // fall, bounce, and find the top of the first rebound
        let mut bounced = false;
        let mut top = 0.0f32;
        for _ in 0..240 {
            w.step(1).unwrap();
            let s = w.read_state().unwrap()[0];
            if !bounced && s.linear_velocity[1] > 0.0 {
                bounced = true;
            }
            if bounced {
                if s.linear_velocity[1] < 0.0 {
                    break;
                }
                top = top.max(s.position[1]);
            }
        }
        assert!(bounced, "landing in substep {substep}: never bounced");
        let ratio = (top - radius) / fall;
        eprintln!("sphere landing in substep {substep} ({fall} m fall): rebound ratio {ratio} (e^2 = 0.64)");
        assert!((ratio - 0.64).abs() < 0.064, "landing in substep {substep}: rebound ratio {ratio}, want 0.64 within 10%");
    }
}

#[test]
fn tilted_box_comes_to_rest_flat() {
    let scene = verlet::scenes::drop();
    let Some(mut w) = world(&scene) else { return };
    w.step(300).unwrap();
    let s = w.read_state().unwrap()[0];
    let up = quat(s.orientation) * Vec3::Y;
    // any face may end up down: tilt is the angle of the nearest body axis to vertical
    let q = quat(s.orientation);
    let tilt = [Vec3::X, Vec3::Y, Vec3::Z]
        .iter()
        .map(|a| (q * *a).dot(Vec3::Y).abs().clamp(0.0, 1.0).acos())
        .fold(f32::MAX, f32::min)
        .to_degrees();
    let _ = up;
    assert!((s.position[1] - 0.5).abs() < 0.01, "centre at {} m, want 0.5", s.position[1]);
    assert!(tilt < 1.0, "tilted {tilt} degrees");
    let speed = v3(s.linear_velocity).length();
    eprintln!("tilted box after 5 s: centre {} m, tilt {tilt} degrees, speed {speed} m/s", s.position[1]);
    assert!(speed < 0.01, "still moving at {speed} m/s");
}
