//! User input between steps: impulses, poses and velocities,
//! explosions, fixed/dynamic switching, and the errors of bad arguments.

use crate::common::{quat, v3, world};
use glam::{DQuat, DVec3, Quat};
use verlet::scenes::{box_body, sphere_body};
use verlet::world::input::{BodyInput, Point, Wind};
use verlet::{Body, Error, Scene, Settings, World};

fn free_settings() -> Settings {
    Settings { gravity: [0.0; 3], linear_damping: 0.0, angular_damping: 0.0, ..Settings::default() }
}

fn scene(settings: Settings, bodies: Vec<Body>) -> Scene {
    Scene { settings, ground: None, bodies, joints: vec![], camera: None }
}

fn d3(a: [f32; 3]) -> DVec3 {
    v3(a).as_dvec3()
}

fn rel_err(got: DVec3, want: DVec3) -> f64 {
    (got - want).length() / want.length()
}

/// World-frame I^-1 (r x J) of a body at orientation q.
fn spin_change(b: &Body, q: DQuat, r: DVec3, j: DVec3) -> DVec3 {
    let ii = DVec3::from_array(b.inverse_inertia().map(|v| v as f64));
    q * (ii * (q.conjugate() * r.cross(j)))
}

/// Angle (rad) between two orientations, well conditioned near zero.
fn angle_between(a: DQuat, b: DQuat) -> f64 {
    let d = a * b.normalize().conjugate();
    2.0 * d.xyz().length().atan2(d.w.abs())
}

#[test]
fn impulse_at_the_centre_changes_velocity_by_j_over_m() {
    let mut b = box_body([0.5, 0.3, 0.2], [1.0, 2.0, -1.0]);
    b.linear_velocity = [0.5, -0.25, 1.0];
    b.orientation = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 0.2).to_array();
    let sc = scene(free_settings(), vec![b.clone()]);
    let Some(mut w) = world(&sc) else { return };
    w.step(3).unwrap();
    let before = w.read_state().unwrap()[0];
    let j = DVec3::new(3.0, -40.0, 25.0);
    w.apply_impulse(0, j.as_vec3().to_array(), None).unwrap();
    let now = w.read_state().unwrap()[0];
    w.step(1).unwrap();
    let after = w.read_state().unwrap()[0];
    let want = j / b.mass as f64;
    let err_now = rel_err(d3(now.linear_velocity) - d3(before.linear_velocity), want);
    let err = rel_err(d3(after.linear_velocity) - d3(before.linear_velocity), want);
    let spin = d3(after.angular_velocity).length();
    eprintln!(
        "impulse at centre: |dv| {:.5} m/s, error {:.2e} at once, {:.2e} after a step; spin {spin:.2e} rad/s",
        want.length(),
        err_now,
        err
    );
    assert!(err_now < 0.01 && err < 0.01, "velocity change off by {:.3}% / {:.3}%", err_now * 100.0, err * 100.0);
    assert!(spin < 1e-4, "a central impulse spun the body at {spin} rad/s");
    // the position moved on by the new velocity
    let moved = d3(after.position) - d3(now.position);
    let dt = sc.settings.dt as f64;
    assert!((moved - d3(now.linear_velocity) * dt).length() < 1e-5, "moved {moved:?}");
}

#[test]
fn impulse_at_an_offset_changes_spin_by_inverse_inertia_of_r_cross_j() {
    let q0 = DQuat::from_euler(glam::EulerRot::XYZ, 0.4, 0.9, -0.3);
    let mut b = box_body([0.6, 0.25, 0.15], [0.5, 1.5, 2.0]);
    b.orientation = q0.as_quat().to_array();
    let mut far = b.clone();
    far.position[0] += 10.0;
    let mut spinning = b.clone();
    spinning.position[0] -= 10.0;
    spinning.angular_velocity = [1.5, -0.5, 2.0];
    spinning.linear_velocity = [0.0, 1.0, 0.0];
    let sc = scene(free_settings(), vec![b.clone(), far, spinning]);
    let Some(mut w) = world(&sc) else { return };
    // the second body far away, hit at the same body-frame point
    let x0 = d3(b.position);
    let r = DVec3::new(0.3, 0.2, -0.1);
    let j = DVec3::new(0.0, 20.0, 8.0);
    let before = w.read_state().unwrap();
    w.apply_impulse(0, j.as_vec3().to_array(), Some((x0 + r).as_vec3().to_array())).unwrap();
    let local = (q0.conjugate() * r).as_vec3().to_array();
    w.apply_impulse_local(1, j.as_vec3().to_array(), local).unwrap();
    // a spinning body, hit where that body-frame point has turned to
    w.step(7).unwrap();
    let before_spinning = w.read_state().unwrap()[2];
    let q2 = quat(before_spinning.orientation).as_dquat();
    let r2 = q2 * (q0.conjugate() * r);
    w.apply_impulse(2, j.as_vec3().to_array(), Some((d3(before_spinning.position) + r2).as_vec3().to_array())).unwrap();
    w.step(1).unwrap();
    let mut before = before;
    before[2] = before_spinning;
    let after = w.read_state().unwrap();
    let want_v = j / b.mass as f64;
    for k in 0..3 {
        let want_w = if k == 2 { spin_change(&b, q2, r2, j) } else { spin_change(&b, q0, r, j) };
        let dw = d3(after[k].angular_velocity) - d3(before[k].angular_velocity);
        let dv = d3(after[k].linear_velocity) - d3(before[k].linear_velocity);
        let (ew, ev) = (rel_err(dw, want_w), rel_err(dv, want_v));
        let what = ["world point", "local point", "world point, spinning body"][k];
        eprintln!("impulse at offset ({what}): |dw| {:.4} rad/s error {ew:.2e}; dv error {ev:.2e}", want_w.length());
        assert!(ew < 0.02, "body {k}: spin change {dw:?}, want {want_w:?} ({:.3}% off)", ew * 100.0);
        assert!(ev < 0.01, "body {k}: velocity change {dv:?}, want {want_v:?}");
    }
}

#[test]
fn a_batch_of_impulses_on_one_body_adds_up() {
    let b = sphere_body(0.3, [0.0, 0.0, 0.0]);
    let sc = scene(free_settings(), vec![b.clone(), sphere_body(0.3, [3.0, 0.0, 0.0])]);
    let Some(mut w) = world(&sc) else { return };
    let (j1, j2) = ([10.0, 0.0, 0.0], [0.0, 0.0, -30.0]);
    w.apply_inputs(&[
        BodyInput::Impulse { body: 0, impulse: j1, point: Point::Centre },
        BodyInput::Impulse { body: 1, impulse: j2, point: Point::Centre },
        BodyInput::Impulse { body: 0, impulse: j2, point: Point::Centre },
    ])
    .unwrap();
    w.step(1).unwrap();
    let s = w.read_state().unwrap();
    let m = b.mass as f64;
    assert!(rel_err(d3(s[0].linear_velocity), (d3(j1) + d3(j2)) / m) < 0.01, "{:?}", s[0].linear_velocity);
    assert!(rel_err(d3(s[1].linear_velocity), d3(j2) / m) < 0.01, "{:?}", s[1].linear_velocity);
}

#[test]
fn a_body_given_a_pose_and_velocity_continues_from_exactly_there() {
    for gravity in [[0.0, 0.0, 0.0], [0.0, -9.81, 0.0]] {
        let mut b = box_body([0.4, 0.3, 0.2], [0.0, 5.0, 0.0]);
        b.linear_velocity = [1.0, 2.0, 3.0];
        b.angular_velocity = [0.5, -2.0, 1.0];
        let sc = scene(Settings { gravity, ..free_settings() }, vec![b]);
        let Some(mut w) = world(&sc) else { return };
        w.step(5).unwrap();
        let x = [2.0f32, 3.0, -1.5];
        let q = Quat::from_euler(glam::EulerRot::YXZ, 1.1, -0.4, 0.25);
        let (v, om) = ([-1.5f32, 0.75, 2.25], [0.8f32, 1.2, -3.0]);
        w.set_pose(0, x, q.to_array()).unwrap();
        w.set_velocity(0, v, om).unwrap();
        let now = w.read_state().unwrap()[0];
        assert_eq!(now.position, x, "the pose was not set exactly");
        w.step(1).unwrap();
        let s = w.read_state().unwrap()[0];
        let dt = sc.settings.dt as f64;
        let want = d3(x) + d3(v) * dt + 0.5 * d3(gravity) * dt * dt;
        let pos_err = (d3(s.position) - want).length();
        let want_q = Quat::from_scaled_axis(v3(om) * dt as f32) * q;
        let angle = angle_between(want_q.as_dquat(), quat(s.orientation).as_dquat());
        // read_state reports the velocity at the step's time
        let want_v = d3(v) + d3(gravity) * dt;
        let vel_err = (d3(s.linear_velocity) - want_v).length();
        let spin_err = (d3(s.angular_velocity) - d3(om)).length();
        eprintln!(
            "pose + velocity (g = {:?}): position off {pos_err:.2e} m, orientation off {angle:.2e} rad, velocity off {vel_err:.2e} m/s, spin off {spin_err:.2e} rad/s",
            gravity
        );
        assert!(pos_err < 2e-5, "position {:?}, want {want:?}", s.position);
        assert!(angle < 1e-5, "orientation {:?}, want {want_q:?}", s.orientation);
        assert!(vel_err < 1e-3, "velocity {:?}, want {want_v:?}", s.linear_velocity);
        assert!(spin_err < 1e-3, "spin {:?}, want {om:?}", s.angular_velocity);
    }
}

#[test]
fn a_new_pose_keeps_the_velocity() {
    let mut b = sphere_body(0.2, [0.0, 0.0, 0.0]);
    b.linear_velocity = [2.0, 0.0, -1.0];
    b.angular_velocity = [0.0, 3.0, 0.0];
    let sc = scene(free_settings(), vec![b.clone()]);
    let Some(mut w) = world(&sc) else { return };
    w.step(2).unwrap();
    w.set_pose(0, [10.0, 1.0, 4.0], [0.0, 0.0, 0.0, 2.0]).unwrap(); // normalised
    w.step(1).unwrap();
    let s = w.read_state().unwrap()[0];
    assert!((d3(s.linear_velocity) - d3(b.linear_velocity)).length() < 1e-3, "{:?}", s.linear_velocity);
    assert!((d3(s.angular_velocity) - d3(b.angular_velocity)).length() < 1e-3, "{:?}", s.angular_velocity);
    let want = d3([10.0, 1.0, 4.0]) + d3(b.linear_velocity) * sc.settings.dt as f64;
    assert!((d3(s.position) - want).length() < 2e-5, "{:?}", s.position);
}

/// Spheres at known distances from an explosion; some beyond its radius.
fn blast_scene(settings: Settings) -> (Scene, Vec<f64>) {
    let dirs =
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-0.6, 0.8, 0.0], [0.0, -0.6, 0.8], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let dists = [1.0, 2.0, 3.0, 4.0, 4.5, 6.0, 9.0];
    let bodies = dirs
        .iter()
        .zip(dists)
        .enumerate()
        .map(|(k, (d, r))| sphere_body(0.1 + 0.05 * k as f32, [d[0] * r, d[1] * r, d[2] * r]))
        .collect();
    (scene(settings, bodies), dists.iter().map(|&d| d as f64).collect())
}

#[test]
fn an_explosion_pushes_outward_with_its_falloff_and_nothing_outside_moves() {
    let (sc, dists) = blast_scene(free_settings());
    let Some(mut w) = world(&sc) else { return };
    let (strength, radius) = (500.0f32, 5.0f64);
    let mut worst = 0.0f64;
    for falloff in [0.0f32, 1.0, 2.0, 0.5] {
        let before = w.read_state().unwrap();
        let raw = w.read_raw().unwrap();
        w.explode([0.0; 3], strength, radius as f32, falloff).unwrap();
        let after = w.read_state().unwrap();
        let raw_after = w.read_raw().unwrap();
        for (k, b) in sc.bodies.iter().enumerate() {
            let d = dists[k];
            if d >= radius {
                assert_eq!(raw[k], raw_after[k], "body {k} at {d} m, outside the radius, was touched");
                continue;
            }
            let dir = d3(b.position).normalize();
            let want = dir * (strength as f64 * (1.0 - d / radius).powf(falloff as f64) / b.mass as f64);
            let dv = d3(after[k].linear_velocity) - d3(before[k].linear_velocity);
            let err = rel_err(dv, want);
            worst = worst.max(err);
            assert!(err < 0.01, "falloff {falloff}: body {k} at {d} m got {dv:?}, want {want:?}");
            assert!(d3(after[k].angular_velocity).length() < 1e-6, "body {k} spun");
        }
    }
    eprintln!("explosion: worst relative error of the velocity change {worst:.2e}");
}

#[test]
fn bodies_outside_an_explosion_step_exactly_as_without_it() {
    let (sc, dists) = blast_scene(Settings::default()); // with gravity
    let Some(mut quiet) = world(&sc) else { return };
    let Some(mut blasted) = world(&sc) else { return };
    blasted.explode([0.0; 3], 20.0, 5.0, 1.0).unwrap();
    for _ in 0..10 {
        quiet.step(1).unwrap();
        blasted.step(1).unwrap();
    }
    let (a, b) = (quiet.read_raw().unwrap(), blasted.read_raw().unwrap());
    for (k, &d) in dists.iter().enumerate() {
        if d >= 5.0 {
            assert_eq!(a[k], b[k], "body {k} outside the radius moved differently");
        } else {
            assert_ne!(a[k], b[k], "body {k} inside the radius was not pushed");
        }
    }
}

#[test]
fn a_fixed_body_ignores_impulses_and_explosions() {
    let mut f = box_body([0.5; 3], [1.0, 0.0, 0.0]);
    f.fixed = true;
    let sc = scene(free_settings(), vec![f]);
    let Some(mut w) = world(&sc) else { return };
    let raw = w.read_raw().unwrap();
    w.apply_impulse(0, [100.0, 0.0, 0.0], Some([1.0, 0.5, 0.0])).unwrap();
    w.set_velocity(0, [1.0, 2.0, 3.0], [1.0, 0.0, 0.0]).unwrap();
    w.explode([0.0; 3], 100.0, 5.0, 0.0).unwrap();
    assert_eq!(w.read_raw().unwrap(), raw);
}

#[test]
fn switching_fixed_and_dynamic() {
    let b = box_body([0.25; 3], [0.0, 10.0, 0.0]);
    let mut f = box_body([0.25; 3], [3.0, 10.0, 0.0]);
    f.fixed = true;
    let sc = scene(Settings { linear_damping: 0.0, angular_damping: 0.0, ..Settings::default() }, vec![b.clone(), f]);
    let Some(mut w) = world(&sc) else { return };
    w.step(10).unwrap();
    // a falling body made fixed stops where it is
    w.set_fixed(0, true).unwrap();
    let held = w.read_state().unwrap()[0];
    w.step(10).unwrap();
    let s = w.read_state().unwrap();
    assert_eq!(s[0].position, held.position, "a fixed body moved");
    assert_eq!(s[0].linear_velocity, [0.0; 3]);
    // and made dynamic again it falls from rest with its old mass
    w.set_fixed(0, false).unwrap();
    w.set_dynamic(1, 4.0).unwrap(); // loaded fixed: given a mass
    w.step(30).unwrap();
    let s = w.read_state().unwrap();
    let t = 30.0 * sc.settings.dt as f64;
    for (k, start) in [held.position[1], 10.0].into_iter().enumerate() {
        let fall = start as f64 - s[k].position[1] as f64;
        let want = 0.5 * 9.81 * t * t;
        assert!((fall - want).abs() < 0.01 * want + 1e-3, "body {k} fell {fall} m in {t} s, want {want}");
    }
    let before = w.read_state().unwrap();
    w.apply_impulse(0, [b.mass * 2.0, 0.0, 0.0], None).unwrap();
    w.apply_impulse(1, [8.0, 0.0, 0.0], None).unwrap();
    w.step(1).unwrap();
    let after = w.read_state().unwrap();
    for k in 0..2 {
        let dvx = after[k].linear_velocity[0] - before[k].linear_velocity[0];
        assert!((dvx - 2.0).abs() < 0.02, "body {k}: impulse gave {dvx} m/s, want 2 (mass not restored?)");
    }
    // the spin of the body made dynamic uses a solid box's inertia for its mass
    let r = DVec3::new(0.0, 0.25, 0.0);
    let j = DVec3::new(0.0, 0.0, 1.0);
    let before = w.read_state().unwrap();
    w.apply_impulse_local(1, j.as_vec3().to_array(), r.as_vec3().to_array()).unwrap();
    let after = w.read_state().unwrap();
    let mut as_dynamic = box_body([0.25; 3], [0.0; 3]);
    as_dynamic.mass = 4.0;
    let q = quat(before[1].orientation).as_dquat();
    let want = spin_change(&as_dynamic, q, q * r, j);
    let dw = d3(after[1].angular_velocity) - d3(before[1].angular_velocity);
    assert!(rel_err(dw, want) < 0.02, "spin change {dw:?}, want {want:?}");
}

/// A body loaded fixed has no mass kept on the GPU: made dynamic without
/// one it gets the mass its scene gave it (here a unit box of density 1000:
/// 1000 kg), as `BodyInput::Fixed` says. Before, it got an infinite mass
/// (the inverse of the 0 kept) and turned non-finite at its first contact,
/// and then 1 kg whatever the scene said (a 2000 kg ball bounced off a
/// stack as if off a wall). A mass f32 cannot invert for its shape is
/// refused, as a scene's is.
#[test]
fn a_body_loaded_fixed_made_dynamic_without_a_mass_gets_its_scenes_mass() {
    let mut f = box_body([0.5; 3], [0.0, 3.0, 0.0]);
    f.fixed = true;
    assert_eq!(f.mass, 1000.0);
    let mut sc = scene(Settings::default(), vec![f]);
    sc.ground = Some(verlet::scene::Ground { height: 0.0 });
    let Some(mut w) = world(&sc) else { return };
    for mass in [3e38f32, 1e-40] {
        let err = input_error(w.set_dynamic(0, mass));
        assert!(err.starts_with("mass: mass ") && err.contains("a GPU reads smaller ones as 0"), "{err}");
    }
    w.set_fixed(0, false).unwrap();
    // 1000 kg: an impulse of 2000 N s along x gives 2 m/s (in the air)
    w.apply_impulse(0, [2000.0, 0.0, 0.0], None).unwrap();
    w.step(1).unwrap();
    let vx = w.read_state().unwrap()[0].linear_velocity[0];
    assert!((vx - 2.0).abs() < 1e-3, "an impulse of 2000 N s gave {vx} m/s: not 1000 kg");
    // and it lands and rests
    w.step(240).unwrap();
    assert_eq!(w.faults().unwrap(), None);
    let s = w.read_state().unwrap()[0];
    assert!((s.position[1] - 0.5).abs() < 0.01, "landed at {:?}", s.position);
}

fn input_error(r: Result<(), Error>) -> String {
    match r {
        Err(Error::Input(msg)) => msg,
        other => panic!("expected an input error, got {other:?}"),
    }
}

#[test]
fn bad_arguments_are_input_errors_naming_the_argument() {
    let sc = scene(free_settings(), vec![sphere_body(0.5, [0.0; 3])]);
    let Some(mut w) = world(&sc) else { return };
    let raw = w.read_raw().unwrap();
    type Call = Box<dyn Fn(&mut World) -> Result<(), Error>>;
    let cases: Vec<(Call, &str)> = vec![
        (Box::new(|w| w.apply_impulse(1, [1.0; 3], None)), "body"),
        (Box::new(|w| w.apply_impulse(0, [1.0, f32::NAN, 0.0], None)), "impulse[1]"),
        (Box::new(|w| w.apply_impulse(0, [1.0; 3], Some([0.0, 0.0, f32::INFINITY]))), "point[2]"),
        (Box::new(|w| w.apply_force(0, [1.0; 3], None, -1.0)), "duration"),
        (Box::new(|w| w.set_pose(7, [0.0; 3], [0.0, 0.0, 0.0, 1.0])), "body"),
        (Box::new(|w| w.set_pose(0, [f32::NAN, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0])), "position[0]"),
        (Box::new(|w| w.set_pose(0, [0.0; 3], [0.0; 4])), "orientation"),
        (Box::new(|w| w.set_velocity(0, [0.0; 3], [0.0, f32::NEG_INFINITY, 0.0])), "angular[1]"),
        // what the step would stop at once as a fault
        (Box::new(|w| w.apply_impulse(0, [1.0; 3], Some([0.0, 2e6, 0.0]))), "point"),
        (Box::new(|w| w.set_pose(0, [0.0, 0.0, -1e7], [0.0, 0.0, 0.0, 1.0])), "position"),
        (Box::new(|w| w.set_velocity(0, [0.0, 1e5, 0.0], [0.0; 3])), "linear"),
        (Box::new(|w| w.apply_wind(&Wind::steady([3e4, 0.0, 0.0]), 0.1)), "wind.velocity"),
        (Box::new(|w| w.explode([0.0, f32::NAN, 0.0], 1.0, 1.0, 1.0)), "centre[1]"),
        (Box::new(|w| w.explode([0.0; 3], f32::NAN, 1.0, 1.0)), "strength"),
        (Box::new(|w| w.explode([0.0; 3], 1.0, 0.0, 1.0)), "radius"),
        (Box::new(|w| w.explode([0.0; 3], 1.0, 1.0, -1.0)), "falloff"),
        (Box::new(|w| w.set_dynamic(0, 0.0)), "mass"),
        (
            Box::new(|w| {
                w.apply_inputs(&[
                    BodyInput::Impulse { body: 0, impulse: [1.0; 3], point: Point::Centre },
                    BodyInput::Velocity { body: 0, linear: [f32::NAN; 3], angular: [0.0; 3] },
                ])
            }),
            "inputs[1].linear[0]",
        ),
    ];
    for (call, name) in cases {
        let msg = input_error(call(&mut w));
        assert!(msg.starts_with(&format!("{name}:")), "error {msg:?} does not start with {name:?}");
    }
    // nothing was applied
    assert_eq!(w.read_raw().unwrap(), raw);
}

#[test]
fn inputs_on_a_world_without_bodies_are_harmless() {
    let sc = scene(free_settings(), vec![]);
    let Some(mut w) = world(&sc) else { return };
    w.explode([0.0; 3], 1.0, 1.0, 1.0).unwrap();
    assert!(w.apply_impulse(0, [1.0; 3], None).is_err());
    w.step(1).unwrap();
}

#[test]
fn many_inputs_grow_the_op_list() {
    let bodies: Vec<Body> = (0..300).map(|k| sphere_body(0.1, [k as f32, 0.0, 0.0])).collect();
    let sc = scene(free_settings(), bodies.clone());
    let Some(mut w) = world(&sc) else { return };
    w.apply_impulse(0, [1.0, 0.0, 0.0], None).unwrap(); // built small
    let inputs: Vec<BodyInput> =
        (0..300).map(|k| BodyInput::Velocity { body: 299 - k, linear: [0.0, k as f32 * 0.01, 0.0], angular: [0.0; 3] }).collect();
    w.apply_inputs(&inputs).unwrap();
    w.step(1).unwrap();
    let s = w.read_state().unwrap();
    for (k, b) in s.iter().enumerate().take(300) {
        let want = (299 - k) as f32 * 0.01;
        assert!((b.linear_velocity[1] - want).abs() < 1e-3, "body {k}: {:?}", b.linear_velocity);
        assert!(s[k].linear_velocity[0].abs() < 1e-4, "body {k}: {:?}", s[k].linear_velocity);
    }
}

/// 70 000 impulses on one body in one call all act, in order. Its run of
/// ops was one invocation's loop, which lavapipe ended at 65535 trips: the
/// body got 65 573 of them, unsaid. A set_velocity after them in the same
/// call still has the last word.
#[test]
fn a_body_given_more_inputs_than_one_loop_holds_gets_them_all() {
    let mut ball = sphere_body(0.5, [0.0; 3]);
    ball.mass = 1e5;
    let sc = scene(free_settings(), vec![ball, sphere_body(0.5, [5.0, 0.0, 0.0])]);
    let Some(mut w) = world(&sc) else { return };
    let n = 70_000;
    let mut inputs: Vec<BodyInput> =
        (0..n).map(|_| BodyInput::Impulse { body: 0, impulse: [1.0, 0.0, 0.0], point: Point::Centre }).collect();
    inputs.push(BodyInput::Velocity { body: 1, linear: [0.0, 1.0, 0.0], angular: [0.0; 3] });
    w.apply_inputs(&inputs).unwrap();
    let v = w.read_state().unwrap()[0].linear_velocity[0];
    // 70 000 additions of 1e-5 m/s in f32: within a part in a thousand
    assert!((v - 0.7).abs() < 7e-4, "70 000 impulses of 1 N s on 1e5 kg gave {v} m/s, want 0.7");
    let inputs: Vec<BodyInput> = (0..n)
        .map(|_| BodyInput::Impulse { body: 1, impulse: [1e5, 0.0, 0.0], point: Point::Centre })
        .chain([BodyInput::Velocity { body: 1, linear: [0.0, 2.0, 0.0], angular: [0.0; 3] }])
        .collect();
    w.apply_inputs(&inputs).unwrap();
    assert_eq!(w.read_state().unwrap()[1].linear_velocity, [0.0, 2.0, 0.0], "the last input has the last word");
}

#[test]
fn wind_drags_bodies_towards_its_velocity_by_their_area() {
    use verlet::world::input::Wind;
    let mut ball = sphere_body(0.5, [0.0, 0.0, 0.0]);
    ball.mass = 1.0;
    let mut cube = box_body([0.5; 3], [0.0, 0.0, 5.0]); // lanes across the wind
    cube.mass = 50.0;
    let mut turned = cube.clone();
    turned.position = [0.0, 0.0, 10.0];
    turned.orientation = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4).to_array();
    let mut wall = box_body([0.5; 3], [0.0, 0.0, 15.0]);
    wall.fixed = true;
    let sc = scene(free_settings(), vec![ball.clone(), cube.clone(), turned, wall]);
    let Some(mut w) = world(&sc) else { return };
    let wind = Wind { velocity: [10.0, 0.0, 0.0], drag: 0.47, ..Wind::default() };
    let dt = sc.settings.dt;
    let raw = w.read_raw().unwrap();
    w.apply_wind(&wind, dt).unwrap();
    w.step(1).unwrap();
    let s = w.read_state().unwrap();
    // the ball: exact solution of du/dt = -k u^2 over dt
    let k = 0.5 * 1.225 * 0.47 * std::f64::consts::PI * 0.25 / 1.0;
    let want = 10.0 - 10.0 / (1.0 + k * 10.0 * dt as f64);
    let err = (s[0].linear_velocity[0] as f64 - want).abs() / want;
    eprintln!("wind on a 1 kg ball: dv {:.5} m/s, want {want:.5} (error {err:.2e})", s[0].linear_velocity[0]);
    assert!(err < 0.01, "ball: {:?}, want {want}", s[0].linear_velocity);
    // a cube turned 45 degrees shows sqrt(2) times the area
    let ratio = s[2].linear_velocity[0] / s[1].linear_velocity[0];
    assert!((ratio - 2f32.sqrt()).abs() < 0.01, "area ratio {ratio}");
    assert_eq!(w.read_raw().unwrap()[3], raw[3], "the wind moved a fixed body");
    // blown for long, the ball nears the wind's speed and never passes it
    let mut fastest = 0.0f32;
    for _ in 0..300 {
        w.apply_wind(&wind, dt).unwrap();
        w.step(1).unwrap();
        fastest = fastest.max(w.read_state().unwrap()[0].linear_velocity[0]);
    }
    let v = w.read_state().unwrap()[0].linear_velocity[0];
    assert!(fastest <= 10.0 + 1e-3 && v > 9.0, "ball at {v} m/s (fastest {fastest}) in a 10 m/s wind");
}

#[test]
fn gusts_stay_within_their_strength_and_bad_wind_is_refused() {
    use verlet::world::input::Wind;
    let wind = Wind { velocity: [0.0, 0.0, 8.0], gust: 0.5, gust_period: 3.0, ..Wind::default() };
    let speeds: Vec<f32> = (0..600).map(|k| wind.at(k as f64 * 0.01)[2]).collect();
    let (lo, hi) = speeds.iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(lo >= 4.0 - 1e-4 && hi <= 12.0 + 1e-4 && hi - lo > 4.0, "gusts span {lo}..{hi} m/s");
    let sc = scene(free_settings(), vec![sphere_body(0.5, [0.0; 3])]);
    let Some(mut w) = world(&sc) else { return };
    for (bad, name) in [
        (Wind { drag: -1.0, ..wind }, "wind.drag"),
        (Wind { gust_period: 0.0, ..wind }, "wind.gust_period"),
        (Wind { velocity: [f32::NAN, 0.0, 0.0], ..wind }, "wind.velocity[0]"),
    ] {
        let msg = input_error(w.apply_wind(&bad, 0.1));
        assert!(msg.starts_with(&format!("{name}:")), "{msg}");
    }
    assert!(input_error(w.apply_wind(&wind, f32::NAN)).starts_with("duration:"));
}

#[test]
fn inputs_queued_back_to_back_all_apply_in_order() {
    let b = sphere_body(0.2, [0.0; 3]);
    let sc = scene(free_settings(), vec![b.clone(), sphere_body(0.2, [2.0, 0.0, 0.0])]);
    let Some(mut w) = world(&sc) else { return };
    // no read in between: each call's op list and header reach the GPU before its dispatch
    w.apply_impulse(0, [b.mass, 0.0, 0.0], None).unwrap();
    w.apply_impulse(1, [0.0, b.mass, 0.0], None).unwrap();
    w.set_velocity(0, [0.0, 0.0, 3.0], [0.0; 3]).unwrap();
    w.apply_impulse(0, [b.mass, 0.0, 0.0], None).unwrap();
    w.explode([2.0, -1.0, 0.0], b.mass, 2.0, 0.0).unwrap(); // body 1 is 1 m above it
    w.step(1).unwrap();
    let s = w.read_state().unwrap();
    let close = |a: [f32; 3], b: [f32; 3]| (d3(a) - d3(b)).length() < 1e-3;
    assert!(close(s[0].linear_velocity, [1.0, 0.0, 3.0]), "body 0: {:?}", s[0].linear_velocity);
    assert!(close(s[1].linear_velocity, [0.0, 2.0, 0.0]), "body 1: {:?}", s[1].linear_velocity);
}

#[test]
fn a_kinematic_paddle_moved_by_set_pose_pushes_boxes_without_passing_through() {
    // a fixed body moved every step by set_pose is a kinematic body: it is
    // static within each step, so the solve pushes what it reaches out of it
    let mut paddle = box_body([0.1, 0.5, 1.0], [-1.0, 0.5, 0.0]);
    paddle.fixed = true;
    let mut bodies = vec![paddle];
    for k in 0..3 {
        bodies.push(box_body([0.25; 3], [0.0, 0.25, -0.6 + 0.6 * k as f32]));
    }
    let sc = Scene { ground: Some(verlet::Ground { height: 0.0 }), ..scene(Settings::default(), bodies) };
    let Some(mut w) = world(&sc) else { return };
    w.step(30).unwrap(); // settle
    let dt = sc.settings.dt as f64;
    let speed = 2.0;
    let mut deepest = 0.0f64;
    for n in 1..=90 {
        let x = -1.0 + speed * dt * n as f64;
        w.set_pose(0, [x as f32, 0.5, 0.0], [0.0, 0.0, 0.0, 1.0]).unwrap();
        w.step(1).unwrap();
        let s = w.read_state().unwrap();
        let face = x + 0.1;
        for (k, b) in s.iter().enumerate().take(4).skip(1) {
            // how far a box's back face is behind the paddle's front face
            let back = b.position[0] as f64 - 0.25;
            deepest = deepest.max(face - back);
            assert!(b.position[0] as f64 > x, "step {n}: box {k} at {:?} passed the paddle at {x}", b.position);
        }
    }
    let s = w.read_state().unwrap();
    let x = -1.0 + speed * dt * 90.0;
    eprintln!(
        "paddle at 2 m/s: deepest overlap {:.1} mm; boxes end at x = {:.3} {:.3} {:.3}, paddle front at {:.3}",
        deepest * 1e3,
        s[1].position[0],
        s[2].position[0],
        s[3].position[0],
        x + 0.1
    );
    assert!(deepest < 0.03, "the paddle sank {deepest} m into a box");
    for (k, b) in s.iter().enumerate().take(4).skip(1) {
        assert!(b.position[0] as f64 >= x + 0.1 + 0.25 - 0.03, "box {k} left behind at {:?}", b.position);
    }
}
