//! Memory and capacity: a scene beyond the adapter's limits
//! is refused before any allocation; the pair list grows for a crowded scene.

use glam::Vec3;
use verlet::scenes::{self, box_body, sphere_body};
use verlet::world::max_bodies;
use verlet::{Error, Joint, World};

#[test]
fn a_scene_beyond_the_adapters_limits_is_refused_before_allocating() {
    let Some(gpu) = crate::common::gpu() else { return };
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

/// An island sleeps and wakes as one however large: `joint_rest` gathers
/// its least rest time one joint an invocation, so no invocation reads an
/// island whole, and an island longer than the driver's loops allow one
/// invocation (lavapipe ends them at 65535 trips summed) is taken. A chain
/// of 33 540 links lying on the ground, laid back and forth in rows of 180,
/// falls asleep whole and wakes whole when its first link is poked.
#[test]
fn a_joint_island_larger_than_the_drivers_loops_sleeps_and_wakes_as_one() {
    let Some(gpu) = crate::common::gpu() else { return };
    let (links, row) = (33_540usize, 180usize);
    let mut scene = scenes::stack(0);
    for k in 0..links {
        let (r, c) = (k / row, k % row);
        // even rows run along +x, odd ones back along -x
        let along = if r % 2 == 0 { 1.0 } else { -1.0 };
        let x = if r % 2 == 0 { c } else { row - 1 - c } as f32 - row as f32 / 2.0;
        scene.bodies.push(box_body([0.45, 0.1, 0.1], [x, 0.1, 0.5 * r as f32 - 45.0]));
        let joined = [k as i32 - 1, k as i32];
        if c > 0 {
            scene.joints.push(Joint { bodies: joined, anchors: [[0.5 * along, 0.0, 0.0], [-0.5 * along, 0.0, 0.0]] });
        } else if k > 0 {
            // a turn: the last link of a row and the first of the next lie side by side
            let end = -0.45 * along;
            scene.joints.push(Joint { bodies: joined, anchors: [[end, 0.0, 0.25], [end, 0.0, -0.25]] });
        }
    }
    assert!(scene.joints.len() as u32 > gpu.loop_trips().unwrap_or(0) / 2, "the island fits one invocation's loops");
    let mut w = World::with_gpu(gpu.clone(), &scene).expect("an island of any size is taken");
    w.step(60).unwrap();
    let state = w.read_state().unwrap();
    let asleep = state.iter().filter(|b| b.asleep).count();
    assert_eq!(asleep, links, "the chain did not fall asleep whole in 1 s");
    w.apply_impulse(0, [0.0, 0.0, 1.0], None).unwrap();
    w.step(1).unwrap();
    let state = w.read_state().unwrap();
    let awake = state.iter().filter(|b| !b.asleep).count();
    assert_eq!(awake, links, "a poke at one end did not wake the whole chain");
}

#[test]
fn the_pair_pools_grow_for_a_crowded_scene() {
    // 13 x 13 x 13 balls: about 10 owned pairs a body, more than the list
    // holds at first; 2197 bodies, so the pair scan spans two blocks
    // (SCAN_SPAN)
    let side = 13usize;
    let scene = ball_lattice(side);
    let n = scene.bodies.len();
    let Some(mut w) = crate::common::world(&scene) else { return };
    let before = w.contact_report().unwrap();
    let bytes_before = w.gpu_bytes();
    w.step(1).unwrap();
    let first = w.contact_report().unwrap();
    w.step(1).unwrap();
    let second = w.contact_report().unwrap();
    w.step(1).unwrap();
    let third = w.contact_report().unwrap();
    eprintln!("made {before:?}\nafter one step {first:?}\nafter two {second:?}\nafter three {third:?}");
    // pairs of lattice neighbours (face, edge and corner diagonals)
    let m = side - 1;
    let lattice_pairs = (3 * m * side * side + 6 * m * m * side + 4 * m * m * m) as u32;
    assert!(before.pair_capacity < lattice_pairs, "the list held every pair from the start: {before:?}");
    assert_eq!(first.pairs, lattice_pairs, "the first step's candidate pairs");
    assert!(second.pair_capacity >= lattice_pairs, "the list did not grow: {second:?}");
    // the memory the world reports follows the pools it grew
    let grown =
        |r: &verlet::world::ContactReport| r.pair_capacity as u64 * (8 + 2 * 4) + r.manifold_capacity as u64 * (32 + 128 + 64);
    assert_eq!(w.gpu_bytes() - bytes_before, grown(&second) - grown(&before), "gpu_bytes does not follow the pools");
    // the balls push apart (at most 3 m/s) and their reach grows with their
    // speed, so later steps may want more pairs; each growth keeps up
    assert!(third.pairs <= third.pair_capacity && third.manifolds <= third.manifold_capacity, "{third:?}");
    // every ball still holds a contact with each of its face neighbours
    // (0.55 apart at first, less than 0.1 m further after three steps)
    let contacts = w.read_contacts().unwrap();
    for (k, list) in contacts.iter().enumerate().take(n) {
        let (x, y, z) = (k % side, (k / side) % side, k / side / side);
        let index = |x: usize, y: usize, z: usize| (x + side * (y + side * z)) as u32;
        let mut faces = Vec::new();
        for (near, at) in [
            (x > 0, (x.wrapping_sub(1), y, z)),
            (x < m, (x + 1, y, z)),
            (y > 0, (x, y.wrapping_sub(1), z)),
            (y < m, (x, y + 1, z)),
            (z > 0, (x, y, z.wrapping_sub(1))),
            (z < m, (x, y, z + 1)),
        ] {
            if near {
                faces.push(index(at.0, at.1, at.2));
            }
        }
        let partners: Vec<u32> = list.iter().map(|c| c.partner).collect();
        for f in &faces {
            assert!(partners.contains(f), "ball {k} at {x} {y} {z} has no contact with its face neighbour {f}: {partners:?}");
        }
    }
}

#[test]
fn a_body_that_owns_more_pairs_than_its_scratch_room_lists_them_all() {
    // a ball ringed by 30 small balls, all in one grid cell and all of higher
    // index, so it owns every pair: more than the room pairs_count notes
    // partners in (twice the pair list over the bodies, 12 here), so
    // pairs_write walks again for it. Far balls, apart, make the ringed ball
    // a median one (a grid body, not a large one) and the cells big enough.
    let mut scene = scenes::stack(0);
    scene.ground = None;
    scene.settings.gravity = [0.0; 3];
    let centre = Vec3::splat(0.5);
    scene.bodies.push(sphere_body(0.42, centre.to_array()));
    let ring = 30;
    for k in 0..ring {
        // Fibonacci points on a sphere: the small balls stay apart
        let y = 1.0 - 2.0 * (k as f32 + 0.5) / ring as f32;
        let phi = k as f32 * 2.399_963;
        let dir = Vec3::new((1.0 - y * y).sqrt() * phi.cos(), y, (1.0 - y * y).sqrt() * phi.sin());
        scene.bodies.push(sphere_body(0.04, (centre + dir * 0.45).to_array()));
    }
    for k in 0..40 {
        scene.bodies.push(sphere_body(0.3, [10.0 + 2.0 * k as f32, 0.5, 0.5]));
    }
    let Some(mut w) = crate::common::world(&scene) else { return };
    let made = w.contact_report().unwrap();
    assert!(2 * made.pair_capacity / (scene.bodies.len() as u32) < ring as u32, "the room holds every pair: {made:?}");
    w.step(1).unwrap();
    let report = w.contact_report().unwrap();
    eprintln!("made {made:?}\nafter one step {report:?}");
    assert_eq!(report.pairs, ring as u32, "candidate pairs: {report:?}");
    assert!(!report.overflowed(), "{report:?}");
    let contacts = w.read_contacts().unwrap();
    // listed in walk order (the cell's bodies by where their bounds begin
    // along x): each small ball once
    let mut partners: Vec<u32> = contacts[0].iter().map(|c| c.partner).collect();
    partners.sort();
    partners.dedup();
    assert_eq!(partners, (1..=ring as u32).collect::<Vec<_>>(), "the ringed ball's contacts");
    for (k, list) in contacts.iter().enumerate().skip(1).take(ring) {
        assert!(!list.is_empty() && list.iter().all(|c| c.partner == 0), "small ball {k}: {list:?}");
    }
}

/// A `side` x `side` x `side` lattice of balls 0.55 diameters apart, no
/// ground, no gravity: every ball overlaps its 26 lattice neighbours, all of
/// them candidate pairs.
fn ball_lattice(side: usize) -> verlet::Scene {
    let mut scene = scenes::stack(0);
    scene.ground = None;
    scene.settings.gravity = [0.0; 3];
    for k in 0..side * side * side {
        let at = Vec3::new((k % side) as f32, ((k / side) % side) as f32, (k / side / side) as f32) * 0.55;
        scene.bodies.push(sphere_body(0.5, at.to_array()));
    }
    scene
}

/// Fifty unit boxes placed at one point 3 m up (1225 touching pairs).
fn fifty_at_one_point() -> verlet::Scene {
    let mut scene = scenes::stack(0);
    scene.bodies = (0..50).map(|_| box_body([0.5; 3], [0.0, 3.0, 0.0])).collect();
    scene
}

/// Every bit of a world's poses.
fn bits(w: &World) -> Vec<u8> {
    bytemuck::cast_slice::<_, u8>(&w.read_raw().unwrap()).to_vec()
}

/// A step that wants more pairs or manifolds than the pools hold is taken
/// again once they have grown: which manifolds found no room depended on
/// thread timing, so fifty boxes placed at one point (1225 touching pairs,
/// room for 150 manifolds at first) came out different in every run, and
/// flew apart at up to 5700 m/s.
#[test]
fn a_step_that_overflows_a_pool_is_taken_again() {
    let scene = fifty_at_one_point();
    let Some(mut batch) = crate::common::world(&scene) else { return };
    let made = batch.contact_report().unwrap();
    batch.step(3).unwrap();
    let report = batch.contact_report().unwrap();
    eprintln!("made {made:?}\nafter three steps {report:?}");
    assert!(made.manifold_capacity < 1225, "the pool held every manifold from the start: {made:?}");
    assert!(report.manifolds_max >= 1225 && !report.overflowed(), "{report:?}");
    let mut again = crate::common::world(&scene).unwrap();
    again.step(3).unwrap();
    assert!(bits(&again) == bits(&batch), "two runs of the same scene differ");
    let mut one_by_one = crate::common::world(&scene).unwrap();
    for _ in 0..3 {
        one_by_one.step(1).unwrap();
    }
    assert!(bits(&one_by_one) == bits(&batch), "steps taken one at a time differ from a batch");
}

/// A world's memory as made covers `bytes_per_body` (the figure `verlet
/// info` and the refusal of too large a scene use), less the grid's share:
/// the exact sizes round the hash table up.
#[test]
fn a_new_world_holds_at_least_the_per_body_estimate() {
    let scene = scenes::cubes(1000, 7);
    let Some(w) = crate::common::world(&scene) else { return };
    assert!(w.gpu_bytes() >= (verlet::world::bytes_per_body() - 20) * 1000, "{} bytes", w.gpu_bytes());
}

/// The pools follow the need down as well as up: fifty boxes apart, no
/// gravity, never touch; once no step of `SHRINK_AFTER_STEPS` wanted a
/// quarter of either pool, both shrink to the least. Restoring a snapshot
/// of the same boxes placed at one point then wants 1225 manifolds: the
/// pools grow, the batch is taken again, and the step comes out bit for
/// bit as it does in a world made crowded.
#[test]
fn the_pools_shrink_while_nothing_touches_and_grow_again_without_a_loss() {
    use verlet::world::SHRINK_AFTER_STEPS;
    let mut scene = fifty_at_one_point();
    scene.ground = None;
    scene.settings.gravity = [0.0; 3];
    let Some(mut crowded) = crate::common::world(&scene) else { return };
    let start = crowded.snapshot().unwrap();
    crowded.step(1).unwrap();
    let grown = crowded.contact_report().unwrap();
    let after_one = bits(&crowded);

    for (k, b) in scene.bodies.iter_mut().enumerate() {
        b.position = [2.0 * (k % 10) as f32, 3.0, 2.0 * (k / 10) as f32];
    }
    let mut w = crate::common::world(&scene).unwrap();
    let made = w.contact_report().unwrap();
    let bytes_made = w.gpu_bytes();
    w.step(SHRINK_AFTER_STEPS - 30).unwrap();
    assert_eq!(w.contact_report().unwrap().manifold_capacity, made.manifold_capacity, "shrunk too soon");
    w.step(60).unwrap();
    let shrunk = w.contact_report().unwrap();
    let bytes_shrunk = w.gpu_bytes();
    eprintln!("crowded {grown:?}\napart, made {made:?} ({bytes_made} B)\nthen {shrunk:?} ({bytes_shrunk} B)");
    assert!(grown.manifolds >= 1225 && !grown.overflowed(), "{grown:?}");
    assert!(made.manifold_capacity > 64 && made.pair_capacity > 64, "{made:?}");
    assert_eq!((shrunk.pair_capacity, shrunk.manifold_capacity, shrunk.manifolds_max), (64, 64, 0), "{shrunk:?}");
    let freed = (made.pair_capacity - 64) as u64 * (8 + 2 * 4) + (made.manifold_capacity - 64) as u64 * (160 + 64);
    assert_eq!(bytes_made - bytes_shrunk, freed, "gpu_bytes does not follow the pools");
    w.restore(&start).unwrap();
    w.step(1).unwrap();
    let again = w.contact_report().unwrap();
    eprintln!("restored crowded, one step: {again:?}");
    assert!(again.manifold_capacity >= 1225 && again.manifolds_max >= 1225 && !again.overflowed(), "{again:?}");
    assert!(bits(&w) == after_one, "the step taken on shrunk pools differs from the crowded world's");
}

/// A manifold pool larger than one storage binding is split into parts
/// (bindings.wgsl's `point_of` and `snap_of`: lavapipe binds at most 128
/// MiB, 838 860 whole manifolds, and a pile of a million cubes wants more
/// than two million). Made to bind at most 64 KiB, a GPU splits the pool of
/// a 700-cube pile (2048 slots) over all four parts of the points (512
/// slots each) and both of the snaps (1024 slots each); the pile steps to
/// the same bits as on the GPU as it is, its pool in one part each.
#[test]
fn a_pool_split_over_bindings_steps_to_the_same_bits() {
    let Some(gpu) = crate::common::gpu() else { return };
    let mut small = verlet::gpu::Gpu::new().unwrap();
    small.limits.max_storage_buffer_binding_size = 64 << 10;
    let scene = scenes::pile(700, 3);
    let mut split = World::with_gpu(std::sync::Arc::new(small), &scene).unwrap();
    let mut whole = World::with_gpu(gpu, &scene).unwrap();
    let made = split.contact_report().unwrap();
    assert_eq!(made.manifold_capacity, 2048, "{made:?}");
    for _ in 0..4 {
        split.step(30).unwrap();
        whole.step(30).unwrap();
        assert!(bits(&split) == bits(&whole), "the split pool's poses differ after {} steps", split.step_count());
    }
    let report = split.contact_report().unwrap();
    eprintln!("split: made {made:?}, after 120 steps {report:?}");
    assert!(report.manifold_capacity > 3 * 512 && report.manifolds_max > 1024 && !report.overflowed(), "{report:?}");
    // the contacts read back across the parts are the same too
    assert_eq!(split.read_contacts().unwrap(), whole.read_contacts().unwrap());
    // a pool that grows into parts (the passes compiled again for them):
    // fifty boxes at one point want 1225 manifolds, room for 150 at first
    let scene = fifty_at_one_point();
    let mut split = World::with_gpu(split.gpu().clone(), &scene).unwrap();
    let mut whole = crate::common::world(&scene).unwrap();
    assert!(split.contact_report().unwrap().manifold_capacity <= 512);
    split.step(3).unwrap();
    whole.step(3).unwrap();
    let report = split.contact_report().unwrap();
    assert!(report.manifold_capacity > 2 * 512 && report.manifolds_max >= 1225 && !report.overflowed(), "{report:?}");
    assert!(bits(&split) == bits(&whole), "the pool grown into parts steps differently");
}

/// The indirect dispatches over the pairs and the manifolds come in rows of
/// at most the device's workgroups per dimension (`write_dispatch` in
/// bindings.wgsl): a pile of a million cubes has more than 65535 x 64
/// pairs. Made to allow 16 workgroups a dimension (rows of 1024
/// invocations), a GPU steps a lattice of 216 balls, each overlapping its
/// 26 neighbours (1940 pairs and manifolds: two rows), to the same bits as
/// the GPU as it is (one row).
#[test]
fn the_pairs_and_manifolds_dispatched_in_rows_step_to_the_same_bits() {
    let Some(gpu) = crate::common::gpu() else { return };
    let mut narrow = verlet::gpu::Gpu::new().unwrap();
    narrow.limits.max_compute_workgroups_per_dimension = 16;
    let scene = ball_lattice(6);
    let mut rows = World::with_gpu(std::sync::Arc::new(narrow), &scene).unwrap();
    let mut one = World::with_gpu(gpu, &scene).unwrap();
    rows.step(3).unwrap();
    one.step(3).unwrap();
    let report = rows.contact_report().unwrap();
    eprintln!("in rows: {report:?}");
    assert!(report.pairs_max > 1024 && report.manifolds_max > 1024 && !report.overflowed(), "{report:?}");
    assert!(bits(&rows) == bits(&one), "the dispatches in rows step differently");
}
