//! Sleeping (`settings.sleeping`, an extension, on by default): a body that
//! has been slower than 5 cm/s at every point for half a second while
//! touching something is held still; it wakes when an awake body touching it
//! moves faster than 20 cm/s, and every body wakes after any input or edit.
//! Bodies on joints sleep and wake with their whole joint island; free-flying
//! bodies and islands never sleep.

use crate::common::{step_until_asleep, v3, world};
use verlet::scene::{Joint, WORLD};
use verlet::scenes::{self, box_body, sphere_body};
use verlet::step::Buffer;

#[test]
fn a_box_at_rest_falls_asleep_and_then_does_not_move_at_all() {
    let scene = scenes::drop();
    let Some(mut w) = world(&scene) else { return };
    w.step(180).unwrap(); // 3 s: landed at about 0.8 s
    let a = w.read_state().unwrap()[0];
    assert!(a.asleep, "a box lying still on the ground for 2 s is awake: {a:?}");
    w.step(600).unwrap();
    let b = w.read_state().unwrap()[0];
    assert!(b.asleep);
    assert_eq!((a.position, a.orientation), (b.position, b.orientation), "a sleeping box moved");
    assert_eq!(b.linear_velocity, [0.0; 3]);
    assert_eq!(b.angular_velocity, [0.0; 3]);
    assert!((b.position[1] - 0.5).abs() < 0.005, "it sleeps at y = {} (resting: 0.5)", b.position[1]);
}

#[test]
fn with_sleeping_off_no_body_sleeps() {
    let mut scene = scenes::drop();
    scene.settings.sleeping = false;
    let Some(mut w) = world(&scene) else { return };
    w.step(180).unwrap();
    assert!(w.read_raw().unwrap().iter().all(|s| s.rest_time == 0.0), "seconds at rest were counted with sleeping off");
    assert!(!w.read_state().unwrap()[0].asleep);
}

#[test]
fn a_slow_body_in_free_flight_never_sleeps() {
    // no gravity, nothing to touch: 1 cm/s for 3 s is 3 cm, asleep or not
    let mut scene = scenes::stack(0);
    scene.settings.gravity = [0.0; 3];
    let mut b = box_body([0.5; 3], [0.0, 5.0, 0.0]);
    b.linear_velocity = [0.01, 0.0, 0.0];
    scene.bodies = vec![b];
    let Some(mut w) = world(&scene) else { return };
    w.step(180).unwrap();
    let s = w.read_state().unwrap()[0];
    assert!(!s.asleep);
    assert!((s.position[0] - 0.03).abs() < 1e-4, "drifted to x = {} (3 cm expected)", s.position[0]);
}

#[test]
fn an_impulse_wakes_a_sleeping_box() {
    let scene = scenes::drop();
    let Some(mut w) = world(&scene) else { return };
    w.step(180).unwrap();
    assert!(w.read_state().unwrap()[0].asleep);
    // 1000 kg: 2000 N s is 2 m/s along x
    w.apply_impulse(0, [2000.0, 0.0, 0.0], None).unwrap();
    assert!(!w.read_state().unwrap()[0].asleep, "the input did not wake the box");
    w.step(1).unwrap();
    let s = w.read_state().unwrap()[0];
    assert!(!s.asleep);
    // friction (mu 0.5 with the ground) takes mu g dt = 0.08 m/s per step
    assert!((s.linear_velocity[0] - 2.0).abs() < 0.15, "after the impulse and a step: {:?}", s.linear_velocity);
}

#[test]
fn a_falling_ball_wakes_a_sleeping_box_and_comes_to_rest_on_it() {
    let mut scene = scenes::stack(1); // a unit box resting on the ground
    let ball = sphere_body(0.25, [0.0, 12.0, 0.0]); // lands at about 1.5 s, at 14 m/s
    scene.bodies.push(ball);
    let Some(mut w) = world(&scene) else { return };
    w.step(80).unwrap();
    let before = w.read_state().unwrap();
    assert!(before[0].asleep, "the box should sleep before the ball arrives: {:?}", before[0]);
    assert!(!before[1].asleep);
    let mut box_woke = false;
    for _ in 0..40 {
        w.step(1).unwrap();
        box_woke |= !w.read_state().unwrap()[0].asleep;
    }
    assert!(box_woke, "the ball's impact did not wake the box");
    w.step(300).unwrap();
    let after = w.read_state().unwrap();
    assert!((after[1].position[1] - 1.25).abs() < 0.02, "the ball is at y = {} (on the box: 1.25)", after[1].position[1]);
    assert!((after[0].position[1] - 0.5).abs() < 0.01, "the box is at y = {}", after[0].position[1]);
    assert!(after[0].asleep && after[1].asleep, "both should sleep again: {after:?}");
}

/// Three boxes lying on the ground in a row, joined at their top edges,
/// the last of them struck later by a falling ball.
fn joined_row() -> verlet::Scene {
    let mut scene = scenes::stack(0);
    scene.bodies = (0..3).map(|k| box_body([0.5; 3], [k as f32 * 1.05, 0.5, 0.0])).collect();
    scene.joints = (0..2).map(|k| Joint { bodies: [k, k + 1], anchors: [[0.525, 0.5, 0.0], [-0.525, 0.5, 0.0]] }).collect();
    scene.bodies.push(sphere_body(0.25, [2.1, 12.0, 0.0])); // lands at about 1.5 s, at 14 m/s
    scene
}

#[test]
fn a_joint_island_sleeps_and_wakes_as_one() {
    let scene = joined_row();
    let Some(mut w) = world(&scene) else { return };
    let (mut slept, mut woke) = (None, None);
    for step in 1..=150u32 {
        w.step(1).unwrap();
        let s = w.read_state().unwrap();
        let row: Vec<bool> = s[..3].iter().map(|b| b.asleep).collect();
        assert!(row.iter().all(|&a| a == row[0]), "step {step}: the joined boxes sleep apart: {row:?}");
        if row[0] && slept.is_none() {
            slept = Some(step);
        }
        if !row[0] && slept.is_some() && woke.is_none() {
            woke = Some(step);
        }
    }
    eprintln!("joined row: asleep from step {slept:?}, woken by the ball at step {woke:?}");
    assert!(slept.is_some_and(|s| s < 80), "the joined boxes at rest did not sleep before the ball came: {slept:?}");
    assert!(woke.is_some(), "the ball's impact on the last box did not wake the row");
    w.step(300).unwrap();
    assert!(w.read_state().unwrap()[..3].iter().all(|b| b.asleep), "the row did not sleep again");
}

#[test]
fn a_joint_island_flying_free_never_sleeps() {
    // no gravity, nothing to touch, no joint to the world: two joined boxes
    // drifting at 1 cm/s for 3 s are awake and 3 cm further
    let mut scene = scenes::stack(0);
    scene.settings.gravity = [0.0; 3];
    scene.bodies = (0..2).map(|k| box_body([0.5; 3], [k as f32 * 1.05, 5.0, 0.0])).collect();
    for b in &mut scene.bodies {
        b.linear_velocity = [0.01, 0.0, 0.0];
    }
    scene.joints = vec![Joint { bodies: [0, 1], anchors: [[0.525, 0.0, 0.0], [-0.525, 0.0, 0.0]] }];
    let Some(mut w) = world(&scene) else { return };
    w.step(180).unwrap();
    let s = w.read_state().unwrap();
    assert!(!s[0].asleep && !s[1].asleep);
    assert!((s[0].position[0] - 0.03).abs() < 1e-4, "drifted to x = {} (3 cm expected)", s[0].position[0]);
}

#[test]
fn a_box_hanging_still_on_a_joint_sleeps() {
    // a box lying on the ground, held by a ball joint at a top corner: at
    // rest, held by the ground and the joint, it sleeps
    let mut scene = scenes::stack(1);
    scene.joints = vec![Joint { bodies: [0, WORLD], anchors: [[0.5, 0.5, 0.5], [0.5, 1.0, 0.5]] }];
    let Some(mut w) = world(&scene) else { return };
    w.step(120).unwrap();
    let s = w.read_state().unwrap()[0];
    assert!(v3(s.position).distance(glam::Vec3::new(0.0, 0.5, 0.0)) < 0.01, "{s:?}");
    assert!(s.asleep, "a jointed body at rest stayed awake");
}

/// A pyramid's boxes all fall asleep: a box pressed between sleepers above
/// and awake boxes below used to flip up and down every sweep (0.5 mm,
/// 0.09-0.13 m/s) and never sleep, in pyramids of 12 to 20 rows (the
/// splits against ends that stay, shaders/solve.wgsl's stay_splits).
#[test]
fn every_box_of_a_fifteen_row_pyramid_falls_asleep() {
    let scene = scenes::pyramid(15);
    let Some(mut w) = world(&scene) else { return };
    w.step(900).unwrap(); // 15 s
    let state = w.read_state().unwrap();
    let awake: Vec<(usize, f32)> =
        state.iter().enumerate().filter(|(_, b)| !b.asleep).map(|(i, b)| (i, v3(b.linear_velocity).length())).collect();
    eprintln!("15-row pyramid after 15 s: awake (body, m/s) {awake:?}");
    assert!(awake.is_empty(), "boxes still awake after 15 s: {awake:?}");
}

/// A tall pyramid that fell asleep stays put when a poke wakes it: every
/// body wakes at rest, and the sweeps' lag lets the stack sink into itself
/// again before support reaches its top. Pushed out as velocity, that
/// overlap threw the top box of a 30-row pyramid 6 cm up (solve.wgsl's
/// SUPPORT_SPEED caps it now: 0.3 cm).
#[test]
fn a_slept_thirty_row_pyramid_woken_by_a_poke_stays_put() {
    let scene = scenes::pyramid(30);
    let Some(mut w) = world(&scene) else { return };
    w.step(900).unwrap(); // 15 s
    let before = w.read_state().unwrap();
    assert!(before.iter().all(|b| b.asleep), "the pyramid did not fall asleep in 15 s");
    w.apply_impulse(0, [0.0, 0.0, 0.001], None).unwrap();
    let top = before.len() - 1;
    let mut rose = 0.0f32;
    for _ in 0..60 {
        w.step(1).unwrap();
        rose = rose.max(w.read_state().unwrap()[top].position[1] - before[top].position[1]);
    }
    let after = w.read_state().unwrap();
    let moved = before.iter().zip(&after).map(|(a, b)| v3(a.position).distance(v3(b.position))).fold(0.0, f32::max);
    eprintln!("slept 30-row pyramid poked: top box rose {rose} m, largest move in the next second {moved} m");
    assert!(rose < 0.01, "the top box jumped {rose} m");
    assert!(moved < 0.02, "a box moved {moved} m");
}

/// A sleeper walks no grid cells: the bodies that move own their pairs with
/// sleepers, in their own cell, ahead of it and behind it (pairs.wgsl).
/// Boxes dropped onto a bed of sleeping boxes, over places that put the
/// bed's boxes in every relation to their cells, must each land on it: a
/// pair with a sleeper that no walk listed would let the box fall through.
#[test]
fn boxes_dropped_on_a_bed_of_sleepers_land_on_it_wherever_they_fall() {
    let mut scene = scenes::stack(0); // the ground alone
    for i in 0..7 {
        for k in 0..7 {
            scene.bodies.push(box_body([0.5; 3], [(i as f32 - 3.0) * 1.02, 0.5, (k as f32 - 3.0) * 1.02]));
        }
    }
    let bed = scene.bodies.len();
    // they reach the bed's top (y = 1) at about 1.45 s, at 14 m/s
    let drops =
        [[-2.63, -2.41], [2.2, 1.7], [0.51, -0.49], [-1.5, 2.6], [2.45, -2.3], [-2.7, 0.4], [0.9, 2.2], [-0.3, 0.8], [1.4, -1.3]];
    for [x, z] in drops {
        scene.bodies.push(box_body([0.5; 3], [x, 12.0, z]));
    }
    let Some(mut w) = world(&scene) else { return };
    w.step(80).unwrap();
    let before = w.read_state().unwrap();
    assert!(before[..bed].iter().all(|b| b.asleep), "the bed should sleep before the boxes arrive");
    assert!(before[bed..].iter().all(|b| b.position[1] > 2.5), "a box arrived too early");
    let mut lowest = vec![f32::MAX; drops.len()];
    for _ in 0..60 {
        w.step(1).unwrap();
        for (low, b) in lowest.iter_mut().zip(&w.read_state().unwrap()[bed..]) {
            *low = low.min(b.position[1]);
        }
    }
    eprintln!("lowest centres of the dropped boxes: {lowest:?}");
    for (k, low) in lowest.iter().enumerate() {
        assert!(*low > 1.35, "box {k} dropped at {:?} went down to y = {low} (resting on the bed: 1.5)", drops[k]);
    }
    w.step(240).unwrap();
    let after = w.read_state().unwrap();
    for (k, b) in after[bed..].iter().enumerate() {
        assert!((b.position[1] - 1.5).abs() < 0.05, "box {k} dropped at {:?} rests at y = {}", drops[k], b.position[1]);
    }
}

/// The restitution pass computes each point's bounce as if that point
/// alone turned the approach around; a box landing flat across four boxes
/// that stay (asleep, or fixed) touches them at sixteen points, most near
/// its middle, and their summed bounces sent it off at 40 m/s after it hit
/// them at 14 (restitution 0.2). It must leave at no more than its
/// restitution times the speed it came with, and come to rest on them.
#[test]
fn a_box_landing_across_four_that_stay_bounces_no_more_than_its_restitution() {
    for fixed in [false, true] {
        let mut scene = scenes::stack(0); // the ground alone
        for (x, z) in [(-0.51, -0.51), (0.51, -0.51), (-0.51, 0.51), (0.51, 0.51)] {
            let mut b = box_body([0.5; 3], [x, 0.5, z]);
            b.fixed = fixed;
            scene.bodies.push(b);
        }
        // lands flat across all four at about 1.45 s, at 14 m/s
        scene.bodies.push(box_body([0.5; 3], [0.0, 12.0, 0.0]));
        let e = scene.settings.restitution;
        let Some(mut w) = world(&scene) else { return };
        w.step(80).unwrap();
        let before = w.read_state().unwrap();
        assert!(fixed || before[..4].iter().all(|b| b.asleep), "the four should sleep before the box arrives");
        let (approach, leave) = speeds_in_and_out(&mut w, 4, [0.0, -1.0, 0.0], 40);
        eprintln!("fixed {fixed}: hit at {approach} m/s, left at {leave} m/s (e = {e})");
        assert!(approach > 13.0, "the box came at {approach} m/s");
        assert!(leave <= 1.05 * e * approach, "the box left at {leave} m/s after hitting at {approach} (e = {e})");
        w.step(240).unwrap();
        let top = w.read_state().unwrap()[4];
        assert!((top.position[1] - 1.5).abs() < 0.02, "the box rests at y = {} (on the four: 1.5)", top.position[1]);
    }
}

/// The other side of combining bounces: a ball rolling on the ground into
/// a fixed wall bounces off the wall in full (its manifold with the ground
/// does not bounce, and bounces at right angles each count whole), where
/// splitting a bounce among the ends that stay had it leave at a quarter.
#[test]
fn a_ball_rolling_into_a_fixed_wall_bounces_back_by_its_restitution() {
    let mut scene = scenes::stack(0); // the ground alone
    let mut ball = sphere_body(0.5, [0.0, 0.5, 0.0]);
    ball.linear_velocity = [6.0, 0.0, 0.0];
    ball.restitution = Some(0.8);
    scene.bodies.push(ball);
    let mut wall = box_body([0.2, 1.0, 2.0], [3.0, 1.0, 0.0]);
    wall.fixed = true;
    scene.bodies.push(wall);
    let Some(mut w) = world(&scene) else { return };
    let (approach, leave) = speeds_in_and_out(&mut w, 0, [1.0, 0.0, 0.0], 90);
    eprintln!("ball into the wall at {approach} m/s, back at {leave} m/s (e = 0.8)");
    assert!(approach > 4.0, "the ball came at {approach} m/s");
    assert!(
        leave >= 0.7 * 0.8 * approach && leave <= 1.05 * 0.8 * approach,
        "the ball left at {leave} m/s after hitting at {approach}"
    );
}

/// Steps `steps` times one at a time and returns body `i`'s fastest speed
/// along `toward` before it first turns back, and its fastest speed back
/// against it after.
fn speeds_in_and_out(w: &mut verlet::World, i: usize, toward: [f32; 3], steps: u32) -> (f32, f32) {
    let (mut approach, mut leave) = (0.0f32, 0.0f32);
    for _ in 0..steps {
        w.step(1).unwrap();
        let v = v3(w.read_state().unwrap()[i].linear_velocity).dot(v3(toward));
        if leave == 0.0 {
            approach = approach.max(v);
        }
        leave = leave.max(-v);
    }
    (approach, leave)
}

/// A world whose bodies all sleep is at rest: its steps would leave every
/// pose as it is, so they are counted and skipped, as listing no contacts
/// (the pools shrink as if they had run). A fresh world restored from it
/// runs its first batch on the GPU and comes out with the same bits, and
/// counts 2^64 - 1 steps more at once; an impulse wakes the bodies and the
/// steps run again.
#[test]
fn a_world_at_rest_skips_its_steps_until_an_input_wakes_it() {
    let mut scene = scenes::drop();
    scene.bodies.extend((1..30).map(|k| box_body([0.5; 3], [3.0 * k as f32, 0.5, 0.0])));
    let bits = |w: &verlet::World| bytemuck::cast_slice::<_, u8>(&w.read_raw().unwrap()).to_vec();
    let Some(mut w) = world(&scene) else { return };
    assert!(!w.at_rest(), "a new world is not known to be at rest");
    let mut steps = 0;
    while !w.at_rest() {
        w.step(10).unwrap();
        steps += 10;
        assert!(steps <= 600, "the boxes never came to rest");
    }
    assert!(w.read_state().unwrap().iter().all(|b| b.asleep), "at rest with a body awake");
    let (rested, time) = (bits(&w), w.time());
    let snapshot = w.snapshot().unwrap();
    let pools = w.contact_report().unwrap();
    w.step(verlet::world::SHRINK_AFTER_STEPS + 30).unwrap();
    let skipped = verlet::world::SHRINK_AFTER_STEPS + 30;
    assert!(w.at_rest());
    assert_eq!(w.step_count(), steps + skipped);
    assert!((w.time() - time - skipped as f64 * scene.settings.dt as f64).abs() < 1e-9, "the time did not advance");
    assert!(bits(&w) == rested, "a pose changed while at rest");
    let report = w.contact_report().unwrap();
    eprintln!("at rest: {pools:?}\nafter {skipped} steps skipped: {report:?}");
    assert_eq!((report.pairs, report.manifolds), (0, 0), "skipped steps list no contacts");
    assert!(w.read_contacts().unwrap().iter().all(|c| c.is_empty()));
    assert!(pools.manifold_capacity > 64, "{pools:?}");
    assert_eq!((report.pair_capacity, report.manifold_capacity), (64, 64), "the pools did not follow the skipped steps");
    // the same steps run on the GPU (the first batch at least): the same bits
    let mut run = world(&scene).unwrap();
    run.restore(&snapshot).unwrap();
    assert!(!run.at_rest());
    run.step(skipped).unwrap();
    assert!(run.at_rest(), "the restored world did not find itself at rest");
    assert!(bits(&run) == rested, "stepping the resting world moved a pose");
    // however many steps are asked of a world at rest, they are counted at
    // once (a trillion of them, a batch at a time, would take years)
    let many = 1_000_000_000_000;
    let counted = run.step_count() + many;
    run.step(many).unwrap();
    assert_eq!(run.step_count(), counted);
    assert!(run.at_rest() && bits(&run) == rested, "the counted steps moved a pose");
    // an input wakes it
    w.apply_impulse(1, [0.0, 5000.0, 0.0], None).unwrap();
    assert!(!w.at_rest());
    w.step(1).unwrap();
    let b = w.read_state().unwrap()[1];
    assert!(!b.asleep && b.position[1] > 0.52, "the box did not move after the impulse: {b:?}");
    println!("at rest after {steps} steps");
}

/// The body passes (integrate, solve, restitution) run over the bodies a
/// step may change (`listed_body` in shaders/bindings.wgsl): in a pile half
/// asleep every awake body is listed, once, and every body left out is a
/// sleeper whose pose is the same, bit for bit, in both state buffers (what
/// the passes' copies would have left there); an input wakes and lists all.
#[test]
fn the_body_passes_run_over_the_awake_bodies_and_leave_sleepers_alike_in_both_buffers() {
    let scene = scenes::pile(200, 3);
    let n = scene.bodies.len();
    let Some(mut w) = world(&scene) else { return };
    let steps = step_until_asleep(&mut w, n / 2, 1200);
    let listed = |w: &verlet::World| {
        let count = w.read_status().unwrap().listed as usize;
        w.read_words(Buffer::Sorted).unwrap()[n..n + count].to_vec()
    };
    let list = listed(&w);
    let mut once = list.clone();
    once.sort_unstable();
    once.dedup();
    assert_eq!(once.len(), list.len(), "a body listed twice");
    let bodies = w.read_state().unwrap();
    let (a, b) = (w.read_words(Buffer::StateIn).unwrap(), w.read_words(Buffer::StateOut).unwrap());
    let words = std::mem::size_of::<verlet::gpu::types::BodyState>() / 4;
    for (i, body) in bodies.iter().enumerate() {
        if once.binary_search(&(i as u32)).is_ok() {
            continue;
        }
        assert!(body.asleep, "body {i} is awake and was left out of the body passes");
        assert_eq!(a[i * words..(i + 1) * words], b[i * words..(i + 1) * words], "sleeper {i} differs between the state buffers");
    }
    // solve's list: the listed bodies with contacts, each once
    let touching = {
        let count = w.read_status().unwrap().touching as usize;
        w.read_words(Buffer::Sorted).unwrap()[2 * n..2 * n + count].to_vec()
    };
    let meta: Vec<verlet::gpu::types::PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
    let mut with_contacts: Vec<u32> = list.iter().copied().filter(|&i| meta[i as usize].contacts > 0).collect();
    with_contacts.sort_unstable();
    let mut solved = touching.clone();
    solved.sort_unstable();
    assert_eq!(solved, with_contacts, "solve's list is not the listed bodies with contacts, each once");
    let asleep = bodies.iter().filter(|b| b.asleep).count();
    println!("after {steps} steps: {asleep} of {n} asleep, {} listed, {} with contacts", list.len(), touching.len());
    assert!(list.len() < n, "every body was listed in a pile half asleep");
    w.apply_impulse(0, [0.0, 100.0, 0.0], None).unwrap();
    w.step(1).unwrap();
    assert_eq!(listed(&w).len(), n, "an input wakes every body, and every body is listed");
}
