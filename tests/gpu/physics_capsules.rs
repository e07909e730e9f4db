//! Capsules with known answers: rolling down a ramp at the rate rolling
//! gives, resting on a side and on an end, on the ground and on a box, and a
//! pile that settles without passing through the ground or each other.

use crate::common::{quat, ramp, v3, world};
use glam::{Quat, Vec3};
use verlet::reference::collide::{collide, Placed, ShapeKind};
use verlet::scenes::{self, box_body};
use verlet::{Body, BodyOutput, Shape};

fn capsule(radius: f32, half_height: f32, at: Vec3, rot: Quat) -> Body {
    let mut b = Body::new(Shape::Capsule { radius, half_height }, at.to_array());
    b.orientation = rot.to_array();
    b
}

/// The capsule's axis (its body y) in the world.
fn axis(s: &BodyOutput) -> Vec3 {
    quat(s.orientation) * Vec3::Y
}

/// A capsule lying across a ramp of 20 degrees rolls down it without
/// slipping: a = g sin(theta) / (1 + I / (m r^2)), I its moment about its
/// own axis (the cylinder's m r^2 / 2 and the caps' 2/5 m r^2); it turns
/// at v / r.
#[test]
fn a_capsule_rolls_down_a_ramp_at_the_rate_rolling_gives() {
    let (r, h) = (0.2f32, 0.5f32);
    let angle = 20f32.to_radians();
    let mut scene = scenes::stack(0);
    // the capsule's axis lies along z, across the ramp
    let (ramp, tilt, start) = ramp(r);
    let (along, normal) = (tilt * Vec3::X, tilt * Vec3::Y);
    let body = capsule(r, h, start, tilt * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2));
    // the moment about the axis per m r^2, as Shape::inertia_f64 sums it
    let (cylinder, ball) = (2.0 * h, 4.0 / 3.0 * r);
    let k = (cylinder * 0.5 + ball * 0.4) / (cylinder + ball);
    scene.bodies = vec![ramp, body];
    let Some(mut w) = world(&scene) else { return };
    let t = 1.0;
    w.step(60).unwrap();
    let s = w.read_state().unwrap()[1];
    let a = 9.81 * angle.sin() / (1.0 + k);
    let (expected, moved) = (0.5 * a * t * t, (v3(s.position) - start).dot(-along));
    let speed = v3(s.linear_velocity).length();
    let spin = v3(s.angular_velocity).dot(axis(&s));
    eprintln!(
        "capsule on a ramp: {moved} m down in {t} s (rolling says {expected}), {speed} m/s, spin {spin} rad/s (v / r = {})",
        speed / r
    );
    assert!((moved - expected).abs() < 0.05 * expected, "rolled {moved} m, rolling says {expected} m");
    assert!((spin.abs() - speed / r).abs() < 0.05 * speed / r, "spins at {spin} rad/s while moving at {speed} m/s");
    let off = (v3(s.position) - start).dot(normal);
    assert!(off.abs() < 0.01, "left the ramp's surface by {off} m");
    assert!(axis(&s).z.abs() > 0.999, "the axis turned off the ramp's width: {:?}", axis(&s));
}

/// Capsules at rest stay put: on their side on the ground and on a fixed
/// box (two points, one under each end of the segment), and standing on an
/// end, balanced on one point under the axis.
#[test]
fn a_capsule_rests_on_its_side_and_on_its_end() {
    let (r, h) = (0.25f32, 0.6f32);
    let side = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let mut scene = scenes::stack(0);
    let mut table = box_body([1.0, 0.5, 1.0], [6.0, 0.5, 0.0]);
    table.fixed = true;
    scene.bodies = vec![
        capsule(r, h, Vec3::new(0.0, r, 0.0), side),
        capsule(r, h, Vec3::new(3.0, h + r, 0.0), Quat::IDENTITY),
        table,
        capsule(r, h, Vec3::new(6.0, 1.0 + r, 0.0), side * Quat::from_rotation_y(0.3)),
    ];
    let start: Vec<Vec3> = scene.bodies.iter().map(|b| Vec3::from(b.position)).collect();
    let Some(mut w) = world(&scene) else { return };
    w.step(300).unwrap();
    let state = w.read_state().unwrap();
    for i in [0, 1, 3] {
        let s = &state[i];
        let moved = v3(s.position) - start[i];
        eprintln!("capsule {i}: moved {moved:?}, axis {:?}, speed {}", axis(s), v3(s.linear_velocity).length());
        assert!(moved.length() < 0.01, "capsule {i} moved {moved:?}");
        assert!(v3(s.linear_velocity).length() < 0.01 && v3(s.angular_velocity).length() < 0.05, "capsule {i} still moves");
    }
    assert!(axis(&state[1]).y > 0.9999, "the upright capsule tipped: {:?}", axis(&state[1]));
    assert!(axis(&state[0]).y.abs() < 1e-3 && axis(&state[3]).y.abs() < 1e-3, "a lying capsule tipped");
}

/// Capsules of several sizes dropped in a heap settle: none ends under the
/// ground, no two overlap deeply (by the CPU reference), all come to rest,
/// and a second run repeats the first bit for bit.
#[test]
fn a_heap_of_capsules_settles_without_passing_through() {
    let mut scene = scenes::stack(0);
    let mut rng = crate::common::Rng(0xca95_01e5_0000_0003);
    for k in 0..150 {
        let (x, z) = ((k % 5) as f32 * 1.2 - 2.4, (k / 5 % 5) as f32 * 1.2 - 2.4);
        let at = Vec3::new(x + 0.2 * rng.f(), 1.0 + (k / 25) as f32 * 1.6, z + 0.2 * rng.f());
        scene.bodies.push(capsule(0.15 + 0.15 * rng.f(), 0.1 + 0.5 * rng.f(), at, rng.quat()));
    }
    // walls keep the heap together
    for (x, z, hx, hz) in [(-4.0, 0.0, 0.5, 4.5), (4.0, 0.0, 0.5, 4.5), (0.0, -4.0, 4.5, 0.5), (0.0, 4.0, 4.5, 0.5)] {
        let mut wall = box_body([hx, 2.0, hz], [x, 2.0, z]);
        wall.fixed = true;
        scene.bodies.push(wall);
    }
    let run = || {
        let mut w = world(&scene)?;
        w.step(600).unwrap();
        Some(w.read_state().unwrap())
    };
    let Some(state) = run() else { return };
    let mut lowest = f32::MAX;
    let mut deepest = 0.0f32;
    let placed = |i: usize| Placed {
        centre: v3(state[i].position),
        rot: quat(state[i].orientation),
        shape: ShapeKind::from(&scene.bodies[i].shape),
    };
    for (i, s) in state.iter().enumerate().take(150) {
        let Shape::Capsule { radius, half_height } = scene.bodies[i].shape else { unreachable!() };
        lowest = lowest.min(s.position[1] - axis(s).y.abs() * half_height - radius);
        for j in i + 1..scene.bodies.len() {
            if let Some(m) = collide(&placed(i), &placed(j), 0.0) {
                deepest = deepest.max(m.points.iter().map(|p| -p.separation(m.normal)).fold(0.0, f32::max));
            }
        }
    }
    let fastest = state[..150].iter().map(|b| v3(b.linear_velocity).length()).fold(0.0, f32::max);
    eprintln!("capsule heap after 10 s: lowest point {lowest} m, deepest overlap {deepest} m, fastest {fastest} m/s");
    assert!(lowest > -0.01, "a capsule sank {lowest} m into the ground");
    assert!(deepest < 0.02, "two bodies overlap by {deepest} m");
    assert!(fastest < 0.1, "a capsule still moves at {fastest} m/s");
    let again = run().unwrap();
    let bits =
        |s: &[BodyOutput]| s.iter().flat_map(|b| b.position.into_iter().chain(b.orientation)).map(f32::to_bits).collect::<Vec<_>>();
    assert!(bits(&state) == bits(&again), "a second run differs");
}

/// Ten ragdolls with capsule limbs and ball heads (`capsule_ragdoll`),
/// dropped on a pile of boxes, keep their joints closed and come to rest:
/// limbs that roll about their axes settle later than boxes do.
#[test]
fn ten_capsule_ragdolls_come_to_rest_on_a_pile() {
    let widest = crate::physics_joints::widest_gap_and_fastest(&scenes::capsule_ragdoll(10), 1800);
    let Some((worst, fastest)) = widest else { return };
    eprintln!("capsule ragdolls: worst joint gap {worst} m, fastest body after 30 s {fastest} m/s");
    assert!(worst < 0.02, "a ragdoll joint opened {worst} m");
    assert!(fastest < 0.1, "ragdolls still moving at {fastest} m/s");
}
