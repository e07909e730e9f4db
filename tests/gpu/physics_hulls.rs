//! Hulls with known answers: a tetrahedron rests on a face and one tipped
//! onto an edge falls onto one, a slab tipped toward the corner its ground
//! manifold left out keeps it out of the ground, a pile of rocks settles
//! and sleeps without passing through the ground or each other (and forty
//! piles of other rocks all but a few), and cubes in a drum of kinematic
//! hull panels tumble as it turns without leaving it.

use crate::common::{quat, step_until_asleep, v3, world, Rng};
use glam::{Quat, Vec3};
use verlet::reference::collide::{collide, Placed, ShapeKind};
use verlet::scene::HullShape;
use verlet::scenes::{self, box_body};
use verlet::{Body, BodyOutput, Shape};

fn hull(points: Vec<[f32; 3]>, at: Vec3, rot: Quat) -> Body {
    let mut b = Body::new(Shape::Hull(HullShape::new(points).unwrap()), at.to_array());
    b.orientation = rot.to_array();
    b
}

/// A body's points in the world, as its state reads back (its own frame).
fn corners(b: &Body, s: &BodyOutput) -> Vec<Vec3> {
    let Shape::Hull(h) = &b.shape else { unreachable!() };
    h.points().iter().map(|p| v3(s.position) + quat(s.orientation) * Vec3::from(*p)).collect()
}

const TETRA: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]];

/// A tetrahedron set on its base stays there, still; one balanced on an
/// edge, tipped past it, falls and comes to rest on a face: three corners
/// on the ground, the fourth above.
#[test]
fn a_tetrahedron_rests_on_a_face() {
    let mut scene = scenes::stack(0);
    let on_base = hull(TETRA.to_vec(), Vec3::new(0.0, 0.0, 0.0), Quat::IDENTITY);
    // on the edge from (0,0,0) to (0,0,1), turned 20 degrees past upright about it
    let tipped = hull(TETRA.to_vec(), Vec3::new(4.0, 0.0, 0.0), Quat::from_rotation_z(70f32.to_radians()));
    scene.bodies = vec![on_base, tipped];
    let Some(mut w) = world(&scene) else { return };
    w.step(240).unwrap();
    let state = w.read_state().unwrap();
    let base = corners(&scene.bodies[0], &state[0]);
    let moved = (v3(state[0].position) - Vec3::ZERO).length();
    eprintln!("tetrahedron on its base after 4 s: moved {moved} m, corners {base:?}");
    assert!(moved < 1e-3, "the resting tetrahedron moved {moved} m");
    for (k, c) in base.iter().enumerate() {
        let expected = if k == 3 { 1.0 } else { 0.0 };
        assert!((c.y - expected).abs() < 2e-3, "corner {k} at height {}", c.y);
    }
    let fell = corners(&scene.bodies[1], &state[1]);
    let mut heights: Vec<f32> = fell.iter().map(|c| c.y).collect();
    heights.sort_by(f32::total_cmp);
    eprintln!("tipped tetrahedron after 4 s: corner heights {heights:?}");
    assert!(heights[..3].iter().all(|h| h.abs() < 3e-3), "not on a face: {heights:?}");
    assert!(heights[3] > 0.5, "its fourth corner is not above the face: {heights:?}");
    for s in &state {
        assert!(v3(s.linear_velocity).length() < 0.01 && v3(s.angular_velocity).length() < 0.02, "still moving: {s:?}");
    }
}

/// A rock: the hull of 8 to 24 random points in a box about 0.6 m across.
fn rock(rng: &mut Rng, at: Vec3) -> Body {
    let scale = Vec3::new(rng.range(0.4, 0.8), rng.range(0.3, 0.6), rng.range(0.4, 0.8));
    let n = 8 + (rng.f() * 16.0) as usize;
    let points = (0..n).map(|_| (Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * scale).to_array()).collect();
    hull(points, at, rng.quat())
}

/// Rocks dropped between walls, the bodies of the pile and the walls.
fn rock_pile(count: usize) -> verlet::Scene {
    rock_pile_of_seed(count, 5)
}

/// The pile with its rocks drawn from seed `seed`.
fn rock_pile_of_seed(count: usize, seed: u64) -> verlet::Scene {
    let mut scene = scenes::stack(0);
    let mut rng = Rng(0x4011_0001_0000_0000 + seed);
    for k in 0..count {
        let (x, z) = ((k % 4) as f32 * 0.9 - 1.35, (k / 4 % 4) as f32 * 0.9 - 1.35);
        scene.bodies.push(rock(&mut rng, Vec3::new(x, 0.6 + (k / 16) as f32 * 0.9, z)));
    }
    for (x, z, hx, hz) in [(-2.5, 0.0, 0.5, 3.0), (2.5, 0.0, 0.5, 3.0), (0.0, -2.5, 3.0, 0.5), (0.0, 2.5, 3.0, 0.5)] {
        let mut wall = box_body([hx, 1.5, hz], [x, 1.5, z]);
        wall.fixed = true;
        scene.bodies.push(wall);
    }
    scene
}

/// Rocks dropped between walls pile up: after 20 s none is under the
/// ground, no two overlap deeply (by the CPU reference), and a second run
/// repeats the first bit for bit.
#[test]
fn a_pile_of_hulls_settles_without_passing_through() {
    let count = 80;
    let scene = rock_pile(count);
    let run = || {
        let mut w = world(&scene)?;
        w.step(1200).unwrap();
        Some(w.read_state().unwrap())
    };
    let Some(state) = run() else { return };
    let placed = |i: usize| Placed {
        centre: v3(state[i].position),
        rot: quat(state[i].orientation),
        shape: ShapeKind::from(&scene.bodies[i].shape),
    };
    let (mut lowest, mut deepest) = (f32::MAX, 0.0f32);
    for (i, s) in state.iter().enumerate().take(count) {
        lowest = corners(&scene.bodies[i], s).iter().map(|c| c.y).fold(lowest, f32::min);
        for j in i + 1..scene.bodies.len() {
            if let Some(m) = collide(&placed(i), &placed(j), 0.0) {
                deepest = deepest.max(m.points.iter().map(|p| -p.separation(m.normal)).fold(0.0, f32::max));
            }
        }
    }
    let asleep = state[..count].iter().filter(|b| b.asleep).count();
    let fastest = state[..count].iter().map(|b| v3(b.linear_velocity).length()).fold(0.0, f32::max);
    eprintln!("hull pile after 20 s: lowest corner {lowest} m, deepest overlap {deepest} m, {asleep} of {count} asleep, fastest {fastest} m/s");
    assert!(lowest > -0.01, "a rock sank {lowest} m into the ground");
    assert!(deepest < 0.02, "two bodies overlap by {deepest} m");
    let again = run().unwrap();
    let bits =
        |s: &[BodyOutput]| s.iter().flat_map(|b| b.position.into_iter().chain(b.orientation)).map(f32::to_bits).collect::<Vec<_>>();
    assert!(bits(&state) == bits(&again), "a second run differs");
}

/// The same pile falls asleep, every rock: a rock that jitters in place by
/// a millimetre or two, faster than the sleeping speed now and then, still
/// comes to rest while it is slow more often than not.
#[test]
fn a_pile_of_hulls_falls_asleep() {
    let count = 80;
    let Some(mut w) = world(&rock_pile(count)) else { return };
    step_until_asleep(&mut w, count, 1800);
}

/// Whether a pile falls asleep whole is chaos: a rock may end wedged under
/// neighbours or jittering in a cluster (docs/decisions/hulls.md), about
/// one pile in seven, and a change to the solve moves which piles do, so
/// one pile says little. Forty do: thirteen or more keeping a rock awake
/// after 20 s would happen about once in two hundred by chance at those
/// odds (seeds 1 to 40 keep 7). The check for a change to the solve;
/// about 90 s on lavapipe.
#[test]
#[ignore = "90 s on lavapipe: run by hand with --ignored --nocapture"]
fn forty_piles_of_hulls_fall_asleep_but_a_few() {
    let count = 80;
    let mut awake = Vec::new();
    for seed in 1..=40 {
        let Some(mut w) = world(&rock_pile_of_seed(count, seed)) else { return };
        w.step(1200).unwrap();
        let left = w.read_state().unwrap()[..count].iter().filter(|b| !b.asleep).count();
        if left > 0 {
            awake.push((seed, left));
        }
    }
    eprintln!("hull piles of seeds 1 to 40 with rocks awake after 20 s (seed, rocks): {awake:?}");
    assert!(awake.len() <= 12, "{} of 40 piles keep rocks awake after 20 s: {awake:?}", awake.len());
}

/// A drum of twelve kinematic hull panels about the z axis, turning at 2
/// rad/s, closed by fixed walls, with 24 cubes inside: the cubes are carried
/// up its side and tumble, and none leaves it, through a panel or a wall.
#[test]
fn cubes_tumble_in_a_turning_drum_without_leaving_it() {
    let mut scene = scenes::stack(0);
    scene.ground = None;
    let (axis, radius, half_length, panels) = (Vec3::new(0.0, 3.0, 0.0), 1.5f32, 1.0f32, 12);
    // each panel a slab spanning a little more than its share of the turn,
    // so that neighbours overlap and leave no gap
    let half_turn = std::f32::consts::PI / panels as f32 * 1.15;
    for k in 0..panels {
        let centre = 2.0 * std::f32::consts::PI * k as f32 / panels as f32;
        let mut points = Vec::new();
        for a in [centre - half_turn, centre + half_turn] {
            for r in [radius, radius + 0.25] {
                for z in [-half_length - 0.2, half_length + 0.2] {
                    points.push([r * a.cos(), r * a.sin(), z]);
                }
            }
        }
        let mut panel = hull(points, axis, Quat::IDENTITY);
        panel.kinematic = true;
        panel.angular_velocity = [0.0, 0.0, 2.0];
        scene.bodies.push(panel);
    }
    for z in [-half_length - 0.1, half_length + 0.1] {
        let mut wall = box_body([2.0, 2.0, 0.1], [axis.x, axis.y, z]);
        wall.fixed = true;
        scene.bodies.push(wall);
    }
    let first_cube = scene.bodies.len();
    for k in 0..24 {
        let at = axis + Vec3::new((k % 4) as f32 * 0.4 - 0.6, (k / 12) as f32 * 0.4 - 0.8, (k / 4 % 3) as f32 * 0.5 - 0.5);
        scene.bodies.push(box_body([0.15; 3], at.to_array()));
    }
    let Some(mut w) = world(&scene) else { return };
    let inner = radius * half_turn.cos();
    let (mut highest, mut farthest, mut widest) = (f32::MIN, 0.0f32, 0.0f32);
    for chunk in 0..12 {
        w.step(30).unwrap();
        let state = w.read_state().unwrap();
        for s in &state[first_cube..] {
            if chunk < 4 {
                continue;
            }
            let p = v3(s.position) - axis;
            highest = highest.max(p.y);
            farthest = farthest.max(p.truncate().length());
            widest = widest.max(p.z.abs());
        }
    }
    let state = w.read_state().unwrap();
    let speed = state[first_cube..].iter().map(|s| v3(s.linear_velocity).length()).sum::<f32>() / 24.0;
    eprintln!(
        "drum: cubes reached {highest} m about the axis, {farthest} m from it (panels' inner faces at {inner}), {widest} m along it; mean speed at 6 s {speed} m/s"
    );
    assert!(farthest < inner, "a cube left through a panel: {farthest} m from the axis");
    assert!(widest < half_length, "a cube left through an end wall: {widest} m along the axis");
    assert!(highest > -0.5, "the cubes were not carried up: highest {highest} m about the axis");
    assert!(speed > 0.2, "the cubes do not tumble: mean speed {speed} m/s");
}

/// Hulls added to a world that had none, and one of them taken out again:
/// the world makes their records then, and they land and rest on the
/// ground and on a box as those loaded with the scene do.
#[test]
fn hulls_added_to_a_world_land_and_rest() {
    let mut scene = scenes::stack(1);
    scene.bodies[0].position = [3.0, 0.5, 0.0];
    let Some(mut w) = world(&scene) else { return };
    w.step(10).unwrap();
    let added = [
        hull(TETRA.to_vec(), Vec3::new(0.0, 0.3, 0.0), Quat::IDENTITY),
        hull(TETRA.to_vec(), Vec3::new(2.8, 1.3, -0.2), Quat::IDENTITY),
        hull(TETRA.to_vec(), Vec3::new(-3.0, 0.3, 0.0), Quat::IDENTITY),
    ];
    assert_eq!(w.add_bodies(&added, &[]).unwrap(), 1..4);
    w.remove_body(3).unwrap();
    w.step(180).unwrap();
    let state = w.read_state().unwrap();
    let on_ground = corners(&added[0], &state[1]);
    let on_box = corners(&added[1], &state[2]);
    eprintln!("added hulls after 3 s: on the ground {on_ground:?}, on the box {on_box:?}");
    for (k, c) in on_ground.iter().enumerate() {
        let expected = if k == 3 { 1.0 } else { 0.0 };
        assert!((c.y - expected).abs() < 3e-3, "on the ground: corner {k} at {}", c.y);
    }
    for (k, c) in on_box.iter().enumerate() {
        let expected = if k == 3 { 2.0 } else { 1.0 };
        assert!((c.y - expected).abs() < 3e-3, "on the box: corner {k} at {}", c.y);
    }
}

/// A rock resting on three corners, with two more corners 8 mm above the
/// ground beyond its edges: its ground manifold keeps the three that bear
/// before either that is only near. Kept over one of the three, a near
/// corner left the rock tipping toward the corner left out and back, awake
/// for good (a pile of 1000 such rocks kept 29 awake after 20 s).
#[test]
fn a_rock_on_three_corners_with_two_near_the_ground_rests_and_sleeps() {
    let points = vec![
        [0.35, 0.0, 0.0],
        [-0.2, 0.0, 0.3],
        [-0.2, 0.0, -0.3],
        [0.3, 0.008, 0.32],
        [0.3, 0.008, -0.32],
        [0.0, 0.4, 0.0],
        [0.2, 0.3, 0.2],
        [-0.1, 0.35, -0.2],
    ];
    let mut scene = scenes::stack(0);
    scene.bodies = vec![hull(points.clone(), Vec3::ZERO, Quat::IDENTITY)];
    let Some(mut w) = world(&scene) else { return };
    let steps = step_until_asleep(&mut w, 1, 600);
    let s = &w.read_state().unwrap()[0];
    let moved =
        corners(&scene.bodies[0], s).iter().zip(&points).map(|(c, p)| (*c - Vec3::from(*p)).length()).fold(0.0f32, f32::max);
    eprintln!("asleep after {steps} steps, its corners moved at most {moved} m");
    assert!(moved < 0.005, "a corner moved {moved} m");
}

/// A pentagonal slab lying on its face has five corners on the ground, of
/// which its manifold keeps four. Turned toward the one it leaves out, that
/// corner meets the ground within the step: the manifold, found once for
/// the step's substeps, keeps the corners the step's motion brings down, so
/// the corner never sinks farther than a step's slop.
#[test]
fn a_slab_tipped_toward_a_corner_its_manifold_left_out_stays_out_of_the_ground() {
    let points: Vec<[f32; 3]> = (0..10)
        .map(|k| {
            let a = (k % 5) as f32 * std::f32::consts::TAU / 5.0;
            [0.5 * a.cos(), if k < 5 { -0.1 } else { 0.1 }, 0.5 * a.sin()]
        })
        .collect();
    let mut scene = scenes::stack(0);
    scene.bodies = vec![hull(points.clone(), Vec3::new(0.0, 0.1, 0.0), Quat::IDENTITY)];
    let Some(mut w) = world(&scene) else { return };
    w.step(1).unwrap();
    let state = w.read_state().unwrap();
    let kept: Vec<Vec3> = w.read_contacts().unwrap()[0]
        .iter()
        .map(|c| v3(state[0].position) + quat(state[0].orientation) * v3(c.local_self))
        .collect();
    let bottom = corners(&scene.bodies[0], &state[0]);
    // five corners on the ground, at most four points: one is left out
    let left_out = (0..5).find(|&k| kept.iter().all(|p| (*p - bottom[k]).length() > 1e-3));
    eprintln!("slab at rest: {} ground points, corner left out {left_out:?}", kept.len());
    let m = left_out.expect("the slab's ground manifold keeps all five bottom corners");
    // turning at 3 rad/s about the horizontal axis that lowers corner m
    let r = Vec3::from(points[m]);
    let mut tipped = scene.clone();
    tipped.bodies[0].angular_velocity = (Vec3::new(r.z, 0.0, -r.x).normalize() * 3.0).to_array();
    let Some(mut w) = world(&tipped) else { return };
    let mut deepest = 0.0f32;
    for _ in 0..20 {
        w.step(1).unwrap();
        let s = w.read_state().unwrap();
        let low = corners(&tipped.bodies[0], &s[0]).iter().map(|c| c.y).fold(f32::MAX, f32::min);
        deepest = deepest.min(low);
    }
    eprintln!("slab tipped toward corner {m}: deepest corner {deepest} m");
    assert!(deepest > -0.004, "a corner sank {deepest} m into the ground");
}
