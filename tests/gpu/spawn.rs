//! Adding and removing bodies while a world runs.

use crate::common::{v3, world};
use verlet::scene::HullShape;
use verlet::scenes::{self, box_body};
use verlet::world::joint_gaps;
use verlet::{Body, Error, Joint, Shape};

#[test]
fn bodies_spawned_into_a_running_pile_settle_with_the_rest() {
    let scene = scenes::cubes(100, 4);
    let Some(mut w) = world(&scene) else { return };
    w.step(180).unwrap();
    let mut before = w.read_raw().unwrap();
    assert!(before.iter().any(|s| s.rest_time > 0.0), "no body at rest after 3 s");
    // an edit wakes every body: its seconds at rest (pos.w) start again
    for s in &mut before {
        s.rest_time = 0.0;
    }
    let spawned: Vec<_> = (0..10).map(|k| box_body([0.5; 3], [k as f32 * 1.2 - 6.0, 8.0, 0.3 * k as f32])).collect();
    let range = w.add_bodies(&spawned, &[]).unwrap();
    assert_eq!(range, 100..110);
    assert_eq!(w.body_count(), 110);
    assert_eq!(w.step_count(), 180);
    // the bodies that were there are carried over bit for bit, awake
    let after = w.read_raw().unwrap();
    assert!(bytemuck::cast_slice::<_, u8>(&before) == bytemuck::cast_slice::<_, u8>(&after[..100]), "adding moved the pile");
    w.step(600).unwrap();
    let state = w.read_state().unwrap();
    let fastest = state.iter().map(|b| v3(b.linear_velocity).length()).fold(0.0, f32::max);
    let lowest_new = state[100..].iter().map(|b| b.position[1]).fold(f32::MAX, f32::min);
    eprintln!("spawned 10 into a pile of 100: after 10 s fastest {fastest} m/s, lowest new centre at {lowest_new} m");
    assert!(fastest < 0.1, "still moving at {fastest} m/s");
    assert!(lowest_new > 0.45, "a spawned cube sank to {lowest_new} m");
}

#[test]
fn a_removed_body_leaves_no_ghost_contact() {
    // a box resting on another; the lower one is removed and the upper falls
    let mut scene = scenes::stack(2);
    scene.bodies.push(box_body([0.5; 3], [5.0, 0.5, 0.0]));
    let Some(mut w) = world(&scene) else { return };
    w.step(60).unwrap();
    let resting = w.read_state().unwrap()[1].position[1];
    w.remove_body(0).unwrap();
    assert_eq!(w.body_count(), 2);
    w.step(30).unwrap();
    let state = w.read_state().unwrap();
    eprintln!("upper box: {resting} m before the removal, {} m half a second after", state[0].position[1]);
    assert!(state[0].position[1] < resting - 0.5, "the upper box still rests on a removed one: {}", state[0].position[1]);
    for (i, list) in w.read_contacts().unwrap().iter().enumerate() {
        for c in list {
            assert!(c.partner == verlet::gpu::types::GROUND || (c.partner as usize) < 2, "body {i} touches {}", c.partner);
        }
    }
    assert!((state[1].position[0] - 5.0).abs() < 1e-3, "the other box moved");
}

#[test]
fn removing_renumbers_joints_and_drops_the_removed_bodys() {
    let scene = scenes::chain(5);
    let Some(mut w) = world(&scene) else { return };
    w.step(10).unwrap();
    w.remove_body(2).unwrap(); // the chain breaks: links 3 and 4 fall free
    assert_eq!(w.body_count(), 4);
    w.step(60).unwrap();
    let state = w.read_state().unwrap();
    let pinned = state[0].position[1];
    let loose = state[3].position[1];
    eprintln!("broken chain after 1 s: pinned link at {pinned} m, loose end at {loose} m");
    assert!(loose < pinned - 3.0, "the loose links did not fall: {loose} vs {pinned}");
}

#[test]
fn bad_edits_are_refused_and_change_nothing() {
    let scene = scenes::stack(3);
    let Some(mut w) = world(&scene) else { return };
    w.step(5).unwrap();
    let before = w.read_raw().unwrap();
    let bad = box_body([0.5, -1.0, 0.5], [0.0, 9.0, 0.0]);
    match w.add_bodies(&[bad], &[]) {
        Err(Error::Input(e)) => assert!(e.starts_with("bodies[0].shape.half_extents[1]"), "{e}"),
        other => panic!("a negative size was not refused: {other:?}"),
    }
    let joint = Joint { bodies: [0, 7], anchors: [[0.0; 3], [0.0; 3]] };
    assert!(w.add_bodies(&[], &[joint]).is_err(), "a joint to a missing body was accepted");
    assert!(matches!(w.remove_body(3), Err(Error::Input(_))));
    assert_eq!(w.body_count(), 3);
    let after = w.read_raw().unwrap();
    assert!(bytemuck::cast_slice::<_, u8>(&before) == bytemuck::cast_slice::<_, u8>(&after));
}

/// The passes are compiled without the code for shapes and joints a world
/// does not hold (`Contents` in src/step/pipelines.rs); a world of boxes
/// that is given a sphere, a capsule, a hull and a pendulum gets it back.
/// After 3 s each rests on the ground where its shape says, the sphere
/// set rolling has rolled, and the pendulum's joint is closed.
#[test]
fn shapes_and_joints_added_to_a_world_of_boxes_are_simulated() {
    let scene = scenes::cubes(20, 1);
    let Some(mut w) = world(&scene) else { return };
    w.step(30).unwrap();
    let corners =
        [-1.0f32, 1.0].iter().flat_map(|&x| [-1.0f32, 1.0].iter().flat_map(move |&y| [[x, y, -1.0], [x, y, 1.0]])).collect();
    let mut ball = Body::new(Shape::Sphere { radius: 0.4 }, [40.0, 2.0, 10.0]);
    ball.linear_velocity = [3.0, 0.0, 0.0];
    let mut lying = Body::new(Shape::Capsule { radius: 0.3, half_height: 0.5 }, [44.0, 2.0, 0.0]);
    lying.orientation = [0.0, 0.0, std::f32::consts::FRAC_1_SQRT_2, std::f32::consts::FRAC_1_SQRT_2];
    let added = [
        ball,
        lying,
        Body::new(Shape::Hull(HullShape::new(corners).unwrap()), [48.0, 3.0, 0.0]),
        box_body([0.5, 0.1, 0.1], [52.5, 5.0, 0.0]),
    ];
    let pin = Joint { bodies: [23, -1], anchors: [[-0.5, 0.0, 0.0], [52.0, 5.0, 0.0]] };
    let range = w.add_bodies(&added, std::slice::from_ref(&pin)).unwrap();
    assert_eq!(range, 20..24);
    w.step(180).unwrap();
    let state = w.read_state().unwrap();
    let heights: Vec<f32> = state[20..23].iter().map(|b| b.position[1]).collect();
    let rolled = state[20].position[0] - 40.0;
    let mut now = scene.clone();
    now.bodies.extend(added);
    now.joints = vec![pin];
    let gap = joint_gaps(&now, &w.read_raw().unwrap())[0];
    eprintln!(
        "added to a world of boxes: sphere, capsule and hull at heights {heights:?} m, the sphere rolled {rolled} m, \
         the pendulum's joint {gap} m open"
    );
    assert!((heights[0] - 0.4).abs() < 0.02, "the sphere rests at {} m", heights[0]);
    // compiled without the spheres' code, it slid as a box (2.2 m)
    assert!(rolled > 4.0, "the sphere, set off at 3 m/s, rolled {rolled} m");
    assert!((heights[1] - 0.3).abs() < 0.02, "the capsule rests at {} m", heights[1]);
    assert!((heights[2] - 1.0).abs() < 0.02, "the hull rests at {} m", heights[2]);
    assert!(gap < 1e-3, "the pendulum's joint opened {gap} m");
}
