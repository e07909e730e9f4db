//! A step keeps the last pair list, empty, where the last walks found no pair
//! near and no body has moved out of what they saw (`pairs_kept` in
//! shaders/bindings.wgsl). Each scene here runs twice: as it is, and with a
//! ball far away flying fast, whose move makes every step walk; the bodies
//! they share end with the same bits.

use verlet::gpu::types::{BodyState, SCAN_SPAN, WORKGROUP};
use verlet::scene::SLEEP_AFTER;
use verlet::scenes::{box_body, sphere_body};
use verlet::step::Stage;
use verlet::world::plan_grid;
use verlet::{scenes, Joint, Scene, World, WORLD};

use crate::common::world;

/// `scene` with a ball 1 km away moving at 10 m/s: every step walks.
fn walking_every_step(scene: &Scene) -> Scene {
    let mut out = scene.clone();
    let mut ball = sphere_body(0.4, [1000.0, 0.0, 1000.0]);
    ball.linear_velocity = [10.0, 0.0, 0.0];
    out.bodies.push(ball);
    out
}

/// The first `n` bodies' raw states of `w`.
fn raw(w: &World, n: usize) -> Vec<BodyState> {
    w.read_raw().unwrap()[..n].to_vec()
}

/// Both runs of `scene`, `steps` steps: the scene's bodies' states, as it is
/// and walking every step, and the first world.
fn both(scene: &Scene, steps: u64) -> Option<(World, Vec<BodyState>, Vec<BodyState>)> {
    let n = scene.bodies.len();
    let mut kept = world(scene)?;
    let mut walked = world(&walking_every_step(scene))?;
    kept.step(steps).unwrap();
    walked.step(steps).unwrap();
    let (a, b) = (raw(&kept, n), raw(&walked, n));
    Some((kept, a, b))
}

/// Box3D's joint grid, 10 x 10, hangs still with no pair near: its steps
/// keep the list (the last walks found none near), to the same bits.
#[test]
fn a_still_joint_grid_keeps_its_empty_list_to_the_same_bits() {
    let scene = scenes::by_name("joint_grid", Some(10), 1).unwrap();
    let Some((kept, a, b)) = both(&scene, 120) else { return };
    let status = kept.read_status().unwrap();
    assert_eq!((status.near, status.walk, status.pairs), (0, 0, 0), "{status:?}");
    assert!(a == b, "the still grid's states differ from a run that walks every step");
}

/// The passes only a walk needs (the grid's scans, scatter and sort, the
/// pair scan and writes, the ground's narrowphase) are dispatched at their
/// size where a step walks, and at none where it keeps its list, and
/// `contact_lists` at one workgroup: `grid_count` sizes them.
#[test]
fn a_kept_step_dispatches_no_invocation_of_the_walk_s_passes() {
    let scene = scenes::by_name("joint_grid", Some(10), 1).unwrap();
    let Some((mut kept, _, _)) = both(&scene, 120) else { return };
    let mut walked = world(&walking_every_step(&scene)).unwrap();
    walked.step(120).unwrap();
    for w in [&mut kept, &mut walked] {
        w.run_stages(&[Stage::GridCount]).unwrap();
    }
    let sizes = |w: &World| w.read_status().unwrap().walk_dispatches;
    // contact_lists: one workgroup, its first invocation's part
    let mut none = [[0, 1, 1]; 6];
    none[5] = [1, 1, 1];
    assert_eq!(sizes(&kept), none, "a kept step");
    let radii: Vec<f32> = walking_every_step(&scene).bodies.iter().map(|b| b.bounding_radius()).collect();
    let (n, hash) = (radii.len() as u32, plan_grid(&radii).1.hash_size);
    let full = [
        hash.div_ceil(WORKGROUP),
        hash.div_ceil(SCAN_SPAN),
        n.div_ceil(WORKGROUP),
        n.div_ceil(SCAN_SPAN),
        1,
        n.div_ceil(WORKGROUP),
    ];
    assert_eq!(sizes(&walked), full.map(|x| [x.max(1), 1, 1]), "a step that walks");
}

/// A box drifting at 0.5 mm a step towards another 3 cm away, with no
/// gravity: steps keep the list while it is far, walk once it has moved half
/// the margin, and it meets the other box on the same step as where every
/// step walks, pushing it along.
#[test]
fn a_body_drifting_into_contact_meets_it_as_where_every_step_walks() {
    let mut scene = Scene { ground: None, ..scenes::stack(0) };
    scene.settings.gravity = [0.0; 3];
    scene.settings.sleeping = false;
    let mut drifting = box_body([0.5; 3], [1.03, 0.0, 0.0]);
    drifting.linear_velocity = [-0.03, 0.0, 0.0];
    scene.bodies = vec![box_body([0.5; 3], [0.0, 0.0, 0.0]), drifting];
    let Some((_, a, b)) = both(&scene, 150) else { return };
    assert!(a == b, "the drift differs from a run that walks every step: {a:?} against {b:?}");
    assert!(a[0].pos[0] < -1e-3, "the box drifted into was not pushed: {:?}", a[0].pos);
}

/// A fixed ball, as large as the grid's, set down onto the still grid
/// between steps that keep the list: the next step walks and finds its
/// contact, and the grid is pushed as where every step walks. (A box would
/// be kept out of the grid of balls this small, and with a body out of the
/// grid no step keeps.)
#[test]
fn an_edit_into_contact_after_kept_steps_is_found() {
    let mut scene = scenes::by_name("joint_grid", Some(10), 1).unwrap();
    let mut post = sphere_body(0.4, [4.0, 20.0, 0.0]);
    post.fixed = true;
    scene.bodies.push(post);
    let (post, n) = (scene.bodies.len() - 1, scene.bodies.len());
    // a ball of the grid's lowest row, away from its pinned top
    let lowest = (0..post).min_by(|&i, &j| scene.bodies[i].position[1].total_cmp(&scene.bodies[j].position[1])).unwrap();
    let Some(mut kept) = world(&scene) else { return };
    let Some(mut walked) = world(&walking_every_step(&scene)) else { return };
    for w in [&mut kept, &mut walked] {
        w.step(30).unwrap();
        let at = w.read_state().unwrap()[lowest].position;
        w.set_pose(post, [at[0] + 0.5, at[1], at[2] + 0.5], [0.0, 0.0, 0.0, 1.0]).unwrap();
        w.step(1).unwrap();
        assert!(w.contact_report().unwrap().pairs > 0, "no pair the step after the post was set down");
        w.step(20).unwrap();
    }
    assert!(raw(&kept, n) == raw(&walked, n), "the grid pushed by the post differs from a run that walks every step");
    let moved = kept.read_state().unwrap()[lowest].position;
    assert!(moved[0].abs() > 1e-3 || moved[2].abs() > 1e-3, "the post did not push the ball: {moved:?}");
}

/// Two pendulums far apart and far from anything, sleeping on: one hangs
/// still and falls asleep, the other swings and keeps the world awake. The
/// steps keep the list (nothing near), and the body lists `contact_lists`
/// made stand on them; a body falling asleep changes its `moves`, so that
/// step walks and lists it anew, and the bits are those of a run that
/// walks every step.
#[test]
fn a_body_falling_asleep_between_kept_steps_ends_as_where_every_step_walks() {
    let mut scene = Scene { ground: None, ..scenes::stack(0) };
    scene.settings.sleeping = true;
    let still = box_body([0.2; 3], [0.0, -1.0, 0.0]);
    let swinging = box_body([0.2; 3], [30.0 + 0.8, -0.6, 0.0]);
    scene.bodies = vec![still, swinging];
    scene.joints = vec![
        Joint { bodies: [0, WORLD], anchors: [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]] },
        Joint { bodies: [1, WORLD], anchors: [[0.0, 1.0, 0.0], [30.0, 0.0, 0.0]] },
    ];
    let Some((kept, a, b)) = both(&scene, 150) else { return };
    let status = kept.read_status().unwrap();
    assert_eq!((status.near, status.pairs), (0, 0), "{status:?}");
    assert!(a[0].rest_time >= SLEEP_AFTER, "the still pendulum did not fall asleep: rest {} s", a[0].rest_time);
    assert!(a[1].rest_time < SLEEP_AFTER, "the swinging pendulum fell asleep");
    assert!(a == b, "the pendulums' states differ from a run that walks every step");
}
