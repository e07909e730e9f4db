//! Known answers, kernel by kernel: each test runs only the stages it needs
//! (`World::run_stages`) and checks what one kernel wrote against what it
//! must write, so a regression names its pass.

use crate::common::Rng;
use crate::common::{step_until_asleep, world};
use glam::{Quat, Vec3};
use verlet::gpu::types::{CellBound, ContactManifold, PairMeta, FAST_BODY, MOVES_SHIFT, SCAN_SPAN};
use verlet::scenes::{self, box_body, sphere_body};
use verlet::step::{Buffer, Stage};
use verlet::world::plan_grid;
use verlet::{Scene, Settings};

/// The stages before `integrate`: the grid, the pair list, the narrowphase.
fn contacts_stages() -> Vec<Stage> {
    Stage::ALL.iter().copied().take_while(|&s| s != Stage::Integrate).collect()
}

fn grid_stages() -> Vec<Stage> {
    Stage::ALL.iter().copied().filter(|s| s.is_broadphase()).collect()
}

/// The grid kernels, as a step runs them (`World::step_plan`), sort the
/// bodies as a CPU counting sort does: by hash bucket of their cell
/// (grid.wgsl's bucket_of), within a bucket by the low x side of their
/// bounds (grid_key: centre less pair_meta's extent), then index, the bodies
/// kept out of the grid at the tail; cell_start holds the buckets' prefix
/// sums, and `cell_bounds` each grid body's bounds at its place in
/// `sorted`. With 2500 bodies the scan spans four blocks; with 600 it is one
/// block, which its first pass finishes (the second and third are left out).
#[test]
fn the_grid_is_a_counting_sort_by_bucket() {
    for n in [2500, 600] {
        grid_sort_matches_a_counting_sort(n);
    }
}

fn grid_sort_matches_a_counting_sort(n: usize) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut bodies = Vec::new();
    for k in 0..n {
        let at = [40.0 * rng.f() - 20.0, 30.0 * rng.f() - 5.0, 40.0 * rng.f() - 20.0];
        let mut b = if k % 3 == 0 { sphere_body(0.2 + 0.3 * rng.f(), at) } else { box_body([0.3, 0.2 + 0.2 * rng.f(), 0.4], at) };
        // some fixed, for cell_bounds' moves (STAYS_FIXED, 0, beside MOVES)
        b.fixed = k % 7 == 0;
        bodies.push(b);
    }
    let blocks = plan_grid(&vec![0.5; n + 2]).1.hash_size.div_ceil(SCAN_SPAN);
    assert_eq!(blocks, if n > 1024 { 4 } else { 1 });
    // two bodies too large for the cells
    bodies.push(box_body([6.0, 0.5, 6.0], [0.0, -3.0, 0.0]));
    bodies.push(sphere_body(4.0, [10.0, 10.0, 10.0]));
    let scene = weightless(bodies);
    let Some(mut w) = world(&scene) else { return };
    let stages: Vec<Stage> = w.step_plan().iter().map(|&(s, _)| s).filter(|s| s.is_broadphase()).collect();
    assert_eq!(stages.len(), if blocks > 1 { grid_stages().len() } else { grid_stages().len() - 2 }, "{stages:?}");
    w.run_stages(&stages).unwrap();
    let sorted = w.read_words(Buffer::Sorted).unwrap();
    let cell_start = w.read_words(Buffer::CellStart).unwrap();

    let radii: Vec<f32> = scene.bodies.iter().map(|b| b.bounding_radius()).collect();
    let (large, grid) = plan_grid(&radii);
    assert_eq!(large, [n as u32, n as u32 + 1], "the two large bodies are kept out of the grid");
    let states = w.read_raw().unwrap();
    let bucket = |i: usize| bucket_of(Vec3::from(states[i].pos), grid.cell_size, grid.hash_size);
    // pair_meta's extent.x, read as words
    let meta = w.read_words(Buffer::PairMeta).unwrap();
    let (stride, extent) = (std::mem::size_of::<PairMeta>() / 4, std::mem::offset_of!(PairMeta, extent) / 4);
    let key = |i: usize| states[i].pos[0] - f32::from_bits(meta[stride * i + extent]);
    let mut expected: Vec<u32> = (0..n as u32).collect();
    expected.sort_by(|&a, &b| {
        let (a, b) = (a as usize, b as usize);
        bucket(a).cmp(&bucket(b)).then(key(a).total_cmp(&key(b))).then(a.cmp(&b))
    });
    expected.extend(&large);
    assert_eq!(&sorted[..n + 2], &expected[..], "sorted");
    let mut starts = vec![0u32; grid.hash_size as usize + 1];
    for i in 0..n {
        starts[bucket(i) as usize + 1] += 1;
    }
    for h in 0..grid.hash_size as usize {
        starts[h + 1] += starts[h];
    }
    assert_eq!(cell_start[..starts.len()], starts[..], "cell_start");
    let moves = assert_cell_bounds(&w, n);
    assert!(moves.contains(&STAYS_FIXED) && moves.contains(&MOVES), "{moves:?}");
}

/// The hash bucket of the cell that holds `p` (grid.wgsl's bucket_of): a
/// block of 8 x 8 x 8 cells in a run of 512 buckets placed by the block's
/// hash, in Morton order XOR bits of that hash.
fn bucket_of(p: Vec3, cell_size: f32, hash_size: u32) -> u32 {
    let c = (p / cell_size).floor();
    let [x, y, z] = [c.x, c.y, c.z].map(|v| v as i32 as u32);
    // b2 b1 b0 -> b2 0 0 b1 0 0 b0
    let spread = |v: u32| (v & 1) | ((v & 2) << 2) | ((v & 4) << 4);
    let morton = spread(x & 7) | (spread(y & 7) << 1) | (spread(z & 7) << 2);
    let h = (x >> 3).wrapping_mul(73_856_093) ^ (y >> 3).wrapping_mul(19_349_663) ^ (z >> 3).wrapping_mul(83_492_791);
    ((h << 9) | (morton ^ (h >> 23))) & (hash_size - 1)
}

/// Cells 8 apart (a lattice of bodies at the period of bucket_of's blocks)
/// spread over the buckets as other cells do. Every cell of this lattice
/// lies first in its block, and 1024 buckets hold two runs: in plain Morton
/// order the 512 would share 2 buckets (256 a bucket); with the place XOR
/// the block's hash bits, at most 7 share one; hashed cell by cell, as
/// before the blocks, 10 did. A uniform hash puts 512 cells at most about 5
/// or 6 to one of 1024 buckets.
#[test]
fn a_lattice_of_cells_eight_apart_spreads_over_the_buckets() {
    let n = 8;
    let mut bodies = Vec::new();
    for x in 0..n {
        for y in 0..n {
            for z in 0..n {
                bodies.push(sphere_body(0.2, [4.0 * x as f32 + 0.25, 4.0 * y as f32 + 0.25, 4.0 * z as f32 + 0.25]));
            }
        }
    }
    let grid = plan_grid(&vec![0.2; bodies.len()]).1;
    assert_eq!((grid.cell_size, grid.hash_size), (0.5, 1024), "cells 8 apart: the lattice's spacing is 4 m");
    let scene = weightless(bodies);
    let Some(mut w) = world(&scene) else { return };
    let stages: Vec<Stage> = w.step_plan().iter().map(|&(s, _)| s).filter(|s| s.is_broadphase()).collect();
    w.run_stages(&stages).unwrap();
    let cell_start = w.read_words(Buffer::CellStart).unwrap();
    let counts: Vec<u32> = (0..grid.hash_size as usize).map(|h| cell_start[h + 1] - cell_start[h]).collect();
    assert_eq!(counts.iter().sum::<u32>(), 512);
    let most = counts.iter().max().copied().unwrap_or(0);
    assert!(most <= 8, "{most} of the lattice's 512 bodies share one bucket");
    for (k, b) in scene.bodies.iter().enumerate().step_by(37) {
        let h = bucket_of(Vec3::from(b.position), grid.cell_size, grid.hash_size) as usize;
        assert!(counts[h] >= 1, "body {k}'s bucket {h} is empty");
    }
}

/// `bodies` with no ground and no gravity.
/// `n` unit boxes placed inside each other, their centres within 5 cm,
/// weightless: every pair of them touches, all in one cell of the grid.
fn boxes_inside_each_other(n: usize, seed: u64) -> Scene {
    let mut rng = Rng(seed);
    let at = |rng: &mut Rng| [rng.range(0.0, 0.05), 3.0 + rng.range(0.0, 0.05), rng.range(0.0, 0.05)];
    weightless((0..n).map(|_| box_body([0.5; 3], at(&mut rng))).collect())
}

/// The stages that build the pair list (the grid's, then the pairs'), in
/// the order a step runs them.
fn pair_list_stages(w: &verlet::World) -> Vec<Stage> {
    w.step_plan().iter().map(|&(s, _)| s).filter(|s| s.is_broadphase() || s.name().starts_with("pairs_")).collect()
}

fn weightless(bodies: Vec<verlet::Body>) -> Scene {
    Scene { settings: Settings { gravity: [0.0; 3], ..Settings::default() }, ground: None, bodies, joints: vec![], camera: None }
}

// PairMeta::moves (common.wgsl)
const STAYS_FIXED: u32 = 0;
const MOVES: u32 = 1;
const SLEEPS: u32 = 2;

/// cell_bounds holds each of the `n` grid bodies' centre, bounds, index and
/// moves at its place in sorted, copied bit for bit from state_in and
/// pair_meta (after the grid stages); returns the moves it found.
fn assert_cell_bounds(w: &verlet::World, n: usize) -> Vec<u32> {
    let sorted = w.read_words(Buffer::Sorted).unwrap();
    let states = w.read_raw().unwrap();
    let meta = w.read_words(Buffer::PairMeta).unwrap();
    let bounds = w.read_words(Buffer::CellBounds).unwrap();
    let (stride, record) = (std::mem::size_of::<PairMeta>() / 4, std::mem::size_of::<CellBound>() / 4);
    let word = |i: usize, field: usize| meta[stride * i + field / 4];
    let mut seen = Vec::new();
    for (k, &i) in sorted[..n].iter().enumerate() {
        let i = i as usize;
        let moves = word(i, std::mem::offset_of!(PairMeta, moves));
        let mut want: Vec<u32> = states[i].pos.iter().map(|v| v.to_bits()).collect();
        want.push(word(i, std::mem::offset_of!(PairMeta, bound)));
        want.extend((0..3).map(|c| word(i, std::mem::offset_of!(PairMeta, extent) + 4 * c)));
        // FAST_BODY: a grown box larger than grid.wgsl's fast_size (not a sleeper)
        let extent = (0..3).map(|c| f32::from_bits(word(i, std::mem::offset_of!(PairMeta, extent) + 4 * c)));
        let fast_size = 0.5 * (0.999 * w.grid().cell_size - verlet::limits::CONTACT_MARGIN);
        let fast = if extent.fold(0.0, f32::max) > fast_size && moves != SLEEPS { FAST_BODY } else { 0 };
        want.push(i as u32 | fast | moves << MOVES_SHIFT);
        assert_eq!(&bounds[record * k..record * (k + 1)], &want[..], "cell_bounds[{k}] (body {i})");
        if !seen.contains(&moves) {
            seen.push(moves);
        }
    }
    seen
}

/// A sleeper's moves (SLEEPS, the top bit of CellBound::body) beside its
/// index: a pile of 200 cubes run until some of it sleeps, then the grid
/// stages alone.
#[test]
fn cell_bounds_hold_a_sleepers_moves() {
    let scene = scenes::pile(200, 3);
    let n = scene.bodies.len();
    let Some(mut w) = world(&scene) else { return };
    step_until_asleep(&mut w, n / 4, 1200);
    w.run_stages(&grid_stages()).unwrap();
    let moves = assert_cell_bounds(&w, n);
    assert!(moves.contains(&SLEEPS) && moves.contains(&MOVES), "{moves:?}");
}

/// integrate carries a free body's displacement and adds g h^2 (eq. 6 with
/// a steady step), and repeats its last rotation (eq. 7): bit for bit what
/// the same f32 sums give on the CPU.
/// grid_count bounds each body by how far it may move in the coming step
/// (grid.wgsl's reach_of and spin_reach_of): its centre by its last
/// displacement, rescaled to the step, plus gravity's part; its points by
/// that plus its turn's part, 2 |q - q_prev| R a substep (the nearer of q
/// and -q), none for a sphere. A capsule's world box is its segment's plus
/// its radius. PairMeta's reach, spin, bound (the bounding
/// radius grown by the centre's move alone) and extent (the world box grown
/// by all of it), against the same sums on the CPU.
#[test]
fn grid_count_bounds_each_body_by_its_move_and_turn() {
    let mut bodies = Vec::new();
    for (k, spin) in [0.0f32, 4.0, 30.0].into_iter().enumerate() {
        let mut b = box_body([0.5, 0.25, 0.4], [3.0 * k as f32, 5.0, 0.0]);
        b.linear_velocity = [1.5, -2.0 * k as f32, 0.5];
        b.angular_velocity = [0.3 * spin, -spin, 0.5 * spin];
        b.orientation = Quat::from_rotation_y(0.4 + k as f32).to_array();
        bodies.push(b);
    }
    let mut ball = sphere_body(0.3, [0.0, 5.0, 3.0]);
    ball.angular_velocity = [0.0, 0.0, 20.0];
    ball.linear_velocity = [0.0, -3.0, 0.0];
    bodies.push(ball);
    let mut capsule = verlet::Body::new(verlet::Shape::Capsule { radius: 0.2, half_height: 0.6 }, [-3.0, 5.0, 0.0]);
    capsule.orientation = Quat::from_rotation_z(0.7).to_array();
    capsule.angular_velocity = [2.0, 0.0, 5.0];
    bodies.push(capsule);
    let scene = Scene { settings: Settings::default(), ground: None, bodies, joints: vec![], camera: None };
    let Some(mut w) = world(&scene) else { return };
    w.run_stages(&[Stage::GridCount]).unwrap();
    let states = w.read_raw().unwrap();
    let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
    let settings = scene.settings;
    // run_stages runs a step's first substep after one of the same length
    let steps = settings.substeps as f32;
    let h = settings.dt;
    for (i, body) in scene.bodies.iter().enumerate() {
        let s = &states[i];
        let (q, prev) = (glam::Vec4::from(s.rot), glam::Vec4::from(s.prev_rot));
        let radius = body.bounding_radius();
        let reach = Vec3::from(s.disp).length() * steps + Vec3::from(settings.gravity).length() * h * h;
        let turned = (q - prev).length().min((q + prev).length());
        let spin = match body.shape {
            verlet::Shape::Sphere { .. } => 0.0,
            verlet::Shape::Box { .. } | verlet::Shape::Capsule { .. } => 2.0 * turned * radius * steps,
            verlet::Shape::Hull(_) => unreachable!("no hull in this scene"),
        };
        let world_box = match body.shape {
            verlet::Shape::Sphere { radius } => Vec3::splat(radius),
            verlet::Shape::Box { half_extents } => {
                let r = glam::Mat3::from_quat(Quat::from_array(s.rot));
                let h = Vec3::from(half_extents);
                r.x_axis.abs() * h.x + r.y_axis.abs() * h.y + r.z_axis.abs() * h.z
            }
            verlet::Shape::Capsule { radius, half_height } => {
                let r = glam::Mat3::from_quat(Quat::from_array(s.rot));
                r.y_axis.abs() * half_height + Vec3::splat(radius)
            }
            verlet::Shape::Hull(_) => unreachable!("no hull in this scene"),
        };
        let m = &meta[i];
        let close = |got: f32, want: f32| (got - want).abs() <= 1e-5 * want.abs().max(1.0);
        assert!(close(m.spin, spin), "body {i}: spin {} against {spin}", m.spin);
        assert!(close(m.reach, reach + spin), "body {i}: reach {} against {}", m.reach, reach + spin);
        assert!(close(m.bound, radius + reach), "body {i}: bound {} against {}", m.bound, radius + reach);
        for c in 0..3 {
            let want = world_box[c] + reach + spin;
            assert!(close(m.extent[c], want), "body {i}: extent[{c}] {} against {want}", m.extent[c]);
        }
        if i == 2 {
            // 30 rad/s turns a point of this box 0.22 m a step
            assert!(spin > 0.2, "the fast spinner's spin reach {spin}");
        }
    }
}

/// The pair list (pairs_count, the pair scan, pairs_write) holds every
/// candidate pair once, whatever the bodies' speeds: a pair whose bounds
/// (pair_meta's sphere and box, grown by each body's reach) come within
/// CONTACT_MARGIN, against the CPU's test of every pair of the 400 bodies.
/// A fifth of them move at 20 to 2000 m/s, so their reach spans several
/// grid cells; before the walks counted the fast bodies' reach, the pairs
/// of a fast body with bodies more than a cell away were never listed, and
/// a cube thrown at 45 m/s ended inside the one it hit.
#[test]
fn the_pair_list_holds_every_pair_within_reach_once_at_any_speed() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut bodies = Vec::new();
    for k in 0..400 {
        let at = [rng.range(-7.0, 7.0), rng.range(0.0, 5.0), rng.range(-7.0, 7.0)];
        let mut b = if k % 3 == 0 {
            sphere_body(rng.range(0.2, 0.45), at)
        } else {
            box_body([rng.range(0.2, 0.5), rng.range(0.2, 0.5), rng.range(0.2, 0.5)], at)
        };
        b.orientation = rng.quat().to_array();
        let speed = if k % 5 == 0 { [20.0, 45.0, 80.0, 150.0, 400.0, 2000.0][k / 5 % 6] } else { rng.range(0.0, 3.0) };
        let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize();
        b.linear_velocity = (dir * speed).to_array();
        b.angular_velocity = [rng.range(-20.0, 20.0), rng.range(-20.0, 20.0), rng.range(-20.0, 20.0)];
        b.fixed = k % 11 == 0;
        bodies.push(b);
    }
    // a slab too large for the cells (kept out of the grid)
    bodies.push(box_body([9.0, 0.3, 9.0], [0.0, -0.5, 0.0]));
    let n = bodies.len();
    let scene = weightless(bodies);
    let Some(mut w) = world(&scene) else { return };
    let stages = pair_list_stages(&w);
    // steps, until the pair list has grown to hold the fast bodies' pairs
    let mut report = w.contact_report().unwrap();
    for _ in 0..4 {
        w.run_stages(&stages).unwrap();
        report = w.contact_report().unwrap();
        if report.pairs <= report.pair_capacity {
            break;
        }
        w.step(1).unwrap();
    }
    assert!(report.pairs <= report.pair_capacity, "the list dropped pairs: {report:?}");
    // the fast bodies marked in cell_bounds
    assert_cell_bounds(&w, n - 1);
    let bounds: Vec<CellBound> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::CellBounds).unwrap());
    let fast = bounds[..n - 1].iter().filter(|b| b.body & FAST_BODY != 0).count();
    assert!(fast >= 40, "fast bodies marked: {fast}");
    let words = w.read_words(Buffer::Pairs).unwrap();
    let mut listed: Vec<(u32, u32)> =
        words.chunks(2).take(report.pairs as usize).map(|p| (p[0].min(p[1]), p[0].max(p[1]))).collect();
    listed.sort();
    let before = listed.len();
    listed.dedup();
    assert_eq!(listed.len(), before, "a pair listed twice");

    let states = w.read_raw().unwrap();
    let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
    let cell = w.grid().cell_size;
    let margin = verlet::limits::CONTACT_MARGIN;
    // how far the pair is from wanted_bounds's limits (pairs.wgsl): > 0
    // wanted, < 0 not; within a rounding of 0 either may be
    let inside = |i: usize, j: usize| -> f32 {
        let (a, b) = (&meta[i], &meta[j]);
        if a.moves != MOVES && b.moves != MOVES {
            return -1.0;
        }
        let d = Vec3::from(states[i].pos) - Vec3::from(states[j].pos);
        let sphere = a.bound + b.bound + margin - d.length();
        let apart = d.abs() - Vec3::from(a.extent) - Vec3::from(b.extent);
        sphere.min(margin - apart.max_element())
    };
    let (mut wanted, mut far) = (0, 0);
    for i in 0..n {
        for j in i + 1..n {
            let slack = inside(i, j);
            let found = listed.binary_search(&(i as u32, j as u32)).is_ok();
            let reach = 1e-4 * (1.0 + meta[i].reach + meta[j].reach);
            if slack > reach {
                assert!(found, "pair ({i}, {j}) within reach ({slack} m inside) is not listed");
                wanted += 1;
                let d = (Vec3::from(states[i].pos) - Vec3::from(states[j].pos)).abs();
                far += usize::from(d.max_element() > cell);
            } else if slack < -reach {
                assert!(!found, "pair ({i}, {j}) out of reach ({slack} m) is listed");
            }
        }
    }
    eprintln!(
        "{wanted} pairs within reach, {far} of them more than a cell ({cell} m) apart along an axis; {} listed",
        listed.len()
    );
    assert!(far >= 20, "too few pairs beyond the neighbouring cells to test the fast walks: {far}");
}

/// Boxes placed inside each other, all in one bucket of the grid: the
/// bucket comes out in grid_key order, then index, and every pair is
/// wanted. grid_sort counts each body's place over its bucket; before, one
/// invocation sorted a bucket by insertion, and lavapipe ends an
/// invocation's loops once their trips sum to 65535 (gallivm's
/// LP_MAX_TGSI_LOOP_ITERATIONS): from about 510 bodies in one bucket the
/// sort stopped part way, and 600 such boxes wanted 177 of their 179 700
/// pairs.
#[test]
fn boxes_placed_inside_each_other_want_every_pair() {
    let n = 600;
    let scene = boxes_inside_each_other(n, 0x5851_f42d_4c95_7f2d);
    let Some(mut w) = world(&scene) else { return };
    let stages = pair_list_stages(&w);
    w.run_stages(&stages).unwrap();
    let cell_start = w.read_words(Buffer::CellStart).unwrap();
    let buckets = cell_start.windows(2).filter(|c| c[1] > c[0]).count();
    assert_eq!(buckets, 1, "the boxes lie in one bucket");
    let sorted = w.read_words(Buffer::Sorted).unwrap();
    let states = w.read_raw().unwrap();
    let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
    let key = |i: usize| states[i].pos[0] - meta[i].extent[0];
    let mut expected: Vec<u32> = (0..n as u32).collect();
    expected.sort_by(|&a, &b| key(a as usize).total_cmp(&key(b as usize)).then(a.cmp(&b)));
    if let Some(k) = (0..n).find(|&k| sorted[k] != expected[k]) {
        panic!("the bucket's order differs first at place {k} of {n}: body {}, not {}", sorted[k], expected[k]);
    }
    assert_cell_bounds(&w, n);
    let report = w.contact_report().unwrap();
    assert_eq!(report.pairs as usize, n * (n - 1) / 2, "pairs wanted");
    assert!(!report.walks_cut, "a walk of 600 candidates reported as cut");
}

/// A ball at 3000 m/s over a floor of `side` x `side` cubes, 1.5 m apart,
/// no gravity: its grown box reaches past any grid's cells, so its walk
/// takes every body of the grid. The broadphase and the pair list run
/// once; returns the world, its report, and the ball's pairs wanted (by
/// the CPU's test of the same bounds) and not listed.
fn ball_over_a_floor(side: usize) -> Option<(verlet::World, verlet::world::ContactReport, usize, usize)> {
    let mut bodies: Vec<verlet::Body> = (0..side * side)
        .map(|k| {
            let at = |c: usize| c as f32 * 1.5 - 0.75 * side as f32;
            box_body([0.5; 3], [at(k % side), 0.5, at(k / side)])
        })
        .collect();
    let mut ball = sphere_body(0.5, [-0.7 * side as f32, 3.0, 0.0]);
    ball.linear_velocity = [3000.0, 0.0, 0.0];
    bodies.push(ball);
    let n = bodies.len();
    let mut scene = weightless(bodies);
    scene.settings.sleeping = false;
    let mut w = world(&scene)?;
    assert!(w.grid().hash_size >= 65_536, "{:?}", w.grid());
    let stages = pair_list_stages(&w);
    w.run_stages(&stages).unwrap();
    let report = w.contact_report().unwrap();
    assert!(report.pairs <= report.pair_capacity, "{report:?}");
    let words = w.read_words(Buffer::Pairs).unwrap();
    let listed: std::collections::HashSet<u32> =
        words.chunks(2).take(report.pairs as usize).filter(|p| p.contains(&(n as u32 - 1))).map(|p| p[0].min(p[1])).collect();
    let states = w.read_raw().unwrap();
    let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
    let margin = verlet::limits::CONTACT_MARGIN;
    let ball = &meta[n - 1];
    let wanted: Vec<u32> = (0..n - 1)
        .filter(|&j| {
            let d = Vec3::from(states[n - 1].pos) - Vec3::from(states[j].pos);
            let sphere = ball.bound + meta[j].bound + margin - d.length();
            let apart = d.abs() - Vec3::from(ball.extent) - Vec3::from(meta[j].extent);
            sphere.min(margin - apart.max_element()) > 1e-3
        })
        .map(|j| j as u32)
        .collect();
    let missing = wanted.iter().filter(|j| !listed.contains(j)).count();
    eprintln!("{side} x {side}: the ball's pairs: {} wanted, {missing} not listed; {report:?}", wanted.len());
    assert!(wanted.len() > 1000, "too few of the ball's pairs to test its walk: {}", wanted.len());
    Some((w, report, wanted.len(), missing))
}

/// A fast body's walk over a whole grid takes every pair it wants, and a
/// walk long enough that the driver may cut it short is reported
/// (`ContactReport::walks_cut`, `Status::walks_cut`). Over 20 164 cubes the ball
/// walked every one of the grid's 65 536 buckets, past lavapipe's 65535
/// loop trips, and 1489 of its 2145 pairs were lost (reported); it now
/// walks the grid's 20 164 places, finds them all, and its workgroup's
/// trips (about 21 500) are within the limit: not reported. (A loop over
/// the walker's joint ends, entered at every place, cost each place two
/// of the driver's counts: the walk was cut from 33 000 cubes on.) Over
/// 67 600 cubes its walk alone passes the limit, and is reported where the
/// driver has one.
#[test]
fn a_fast_walk_over_the_whole_grid_takes_every_pair_or_is_reported() {
    let Some((w, report, _, missing)) = ball_over_a_floor(142) else { return };
    assert_eq!(missing, 0, "pairs of the ball's not listed");
    assert!(!report.walks_cut, "a walk within the limit reported as cut");
    let limited = w.gpu().loop_trips().is_some();
    drop(w);
    let (_, report, _, missing) = ball_over_a_floor(260).unwrap();
    assert_eq!(report.walks_cut, limited, "limited loops: {limited}");
    if !limited {
        assert_eq!(missing, 0);
    }
}

#[test]
fn integrate_carries_the_displacement_and_adds_gravity() {
    let mut body = box_body([0.5, 0.25, 0.4], [3.0, 12.0, -2.0]);
    body.linear_velocity = [1.5, 2.0, -0.5];
    body.angular_velocity = [0.3, -1.2, 2.0];
    body.orientation = Quat::from_rotation_y(0.4).to_array();
    let scene = Scene { settings: Settings::default(), ground: None, bodies: vec![body], joints: vec![], camera: None };
    let Some(mut w) = world(&scene) else { return };
    let before = w.read_raw().unwrap()[0];
    w.run_stages(&[Stage::Integrate]).unwrap();
    let after = w.read_raw().unwrap()[0];
    let h = scene.settings.dt / scene.settings.substeps as f32;
    let g = Vec3::from(scene.settings.gravity);
    let disp = Vec3::from(before.disp) + g * (h * 0.5 * (h + h));
    assert_eq!(Vec3::from(after.disp), disp, "disp");
    // the position moves by it to within two of its f32 spacings: this
    // addition's rounding, and the remainder the last one left in pos_low,
    // added back now (what rounding drops is kept, not lost)
    let moved = Vec3::from(after.pos) - Vec3::from(before.pos);
    let spacing = 2.0 * Vec3::from(after.pos).abs() * f32::EPSILON;
    assert!(((moved - disp).abs() - spacing).max_element() <= 0.0, "moved {moved}, displacement {disp}");
    assert_eq!(after.prev_rot, before.rot, "the previous rotation is the last one");
    let last = Quat::from_array(before.rot) * Quat::from_array(before.prev_rot).conjugate();
    let expected = (last * Quat::from_array(before.rot)).normalize();
    assert!(Quat::from_array(after.rot).dot(expected).abs() > 1.0 - 1e-6, "rot {:?}, expected {expected:?}", after.rot);
}

/// One resting contact: a body already inside the ground by d (less than
/// the depenetration speed allows in a substep), at rest, no gravity. One
/// sweep (solve_contacts, then solve) lifts it straight up, without turning
/// it, by c_r d times the share solve.wgsl gives the points: each point's
/// push is worked out as if it were alone, d / w_k with w_k = 1/m + (r_k x
/// n) . I^-1 (r_k x n), and their sum moves the body by d sum_k (1/m) / w_k,
/// scaled down to d where that is more (never up). A sphere (one point,
/// no turn: the share is 1) and a flat box (four corners, whose turns
/// absorb part of each push: a share of 0.78 here).
#[test]
fn one_sweep_lifts_a_body_out_of_the_ground_by_relaxation_times_depth() {
    let d = 0.004f32;
    let h = Vec3::new(0.5, 0.3, 0.4);
    // the box's corners under it, r x n for n = -y: (r.z, 0, -r.x); m I^-1 of a box
    let m_inv_inertia = Vec3::new(3.0 / (h.y * h.y + h.z * h.z), 3.0 / (h.x * h.x + h.z * h.z), 3.0 / (h.x * h.x + h.y * h.y));
    let box_share: f32 = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
        .iter()
        .map(|&(sx, sz)| {
            let rn = Vec3::new(sz * h.z, 0.0, -sx * h.x);
            1.0 / (1.0 + rn.dot(m_inv_inertia * rn))
        })
        .sum::<f32>()
        .min(1.0);
    for (body, share) in [(sphere_body(0.5, [1.0, 0.5 - d, -2.0]), 1.0), (box_body(h.to_array(), [1.0, 0.3 - d, -2.0]), box_share)]
    {
        let settings = Settings { gravity: [0.0; 3], ..Settings::default() };
        let scene = Scene {
            settings,
            ground: Some(verlet::scene::Ground { height: 0.0 }),
            bodies: vec![body],
            joints: vec![],
            camera: None,
        };
        let Some(mut w) = world(&scene) else { return };
        let before = w.read_raw().unwrap()[0];
        let mut stages = contacts_stages();
        stages.extend([Stage::SolveContacts, Stage::Solve]);
        w.run_stages(&stages).unwrap();
        let after = w.read_raw().unwrap()[0];
        let lift = Vec3::from(after.pos) - Vec3::from(before.pos);
        let expected = settings.relaxation * d * share;
        assert!((lift.y - expected).abs() < 2e-6, "{:?}: lifted {} m, expected {expected}", scene.bodies[0].shape, lift.y);
        assert!(lift.x.abs() < 1e-6 && lift.z.abs() < 1e-6, "{:?}: moved sideways {lift}", scene.bodies[0].shape);
        assert!(Quat::from_array(after.rot).dot(Quat::from_array(before.rot)).abs() > 1.0 - 1e-6, "turned");
        // the snap moves the velocity with it (Verlet)
        assert!((Vec3::from(after.disp) - Vec3::from(before.disp) - lift).length() < 1e-6, "disp");
    }
}

/// restitution: a sphere that hits the ground at 5 m/s in one substep
/// (no gravity) leaves at e times that once the sweeps have stopped it;
/// `restitution_in_place` (a world where no body sleeps) gives the same bits.
#[test]
fn restitution_returns_e_times_the_approach_speed() {
    let e = 0.5;
    let mut ball = sphere_body(0.5, [0.0, 0.52, 0.0]);
    ball.linear_velocity = [0.0, -5.0, 0.0];
    ball.restitution = Some(e);
    let settings = Settings { gravity: [0.0; 3], restitution: e, ..Settings::default() };
    let scene =
        Scene { settings, ground: Some(verlet::scene::Ground { height: 0.0 }), bodies: vec![ball], joints: vec![], camera: None };
    let mut left = Vec::new();
    for last in [Stage::Restitution, Stage::RestitutionInPlace] {
        let Some(mut w) = world(&scene) else { return };
        let mut stages = contacts_stages();
        stages.push(Stage::Integrate);
        for _ in 0..settings.iterations {
            stages.extend([Stage::SolveContacts, Stage::Solve]);
        }
        stages.extend([Stage::RestitutionContacts, last]);
        w.run_stages(&stages).unwrap();
        let after = w.read_raw().unwrap()[0];
        let h = settings.dt / settings.substeps as f32;
        let v = Vec3::from(after.disp) / h;
        assert!(
            (v.y - e * 5.0).abs() < 1e-3 && v.x.abs() < 1e-5 && v.z.abs() < 1e-5,
            "{last:?}: left at {v} m/s, expected {} up",
            e * 5.0
        );
        left.push(after);
    }
    assert!(left[0] == left[1], "restitution_in_place differs from restitution: {:?} against {:?}", left[1], left[0]);
}

/// contact_lists leaves every body's list of manifolds in pair order (the
/// manifolds whose pair another body owns first, then the body's own, each
/// by pair index; narrowphase.wgsl's list_order), whatever order the
/// narrowphase's atomics listed them in: a list of up to SHORT_LIST sorted
/// in registers, a longer one by insertion (finished by a heap sort past
/// INSERTION_TRIPS). A landed pile gives lists of one to eight; a slab
/// resting on sixteen cubes, one of sixteen.
#[test]
fn contact_lists_put_each_body_s_manifolds_in_pair_order() {
    let mut scene = scenes::pile(300, 3);
    scene.settings.sleeping = false; // a sleeper the step leaves as it is lists nothing
    for k in 0..16 {
        scene.bodies.push(box_body([0.5; 3], [40.0 + (k % 4) as f32 * 1.05, 0.5, (k / 4) as f32 * 1.05]));
    }
    scene.bodies.push(box_body([2.2, 0.25, 2.2], [41.575, 1.24, 1.575]));
    let slab = scene.bodies.len() - 1;
    let Some(mut w) = world(&scene) else { return };
    w.step(120).unwrap();
    let (meta, lengths) = lists_after_contact_lists(&mut w);
    assert!(meta[slab].contacts >= 16, "the slab lists {} manifolds", meta[slab].contacts);
    let short: usize = lengths[3..=8].iter().sum();
    assert!(short >= 100, "lists of 3 to 8 manifolds: {short} ({lengths:?})");
}

/// The same for lists long and in random order: 600 boxes placed inside
/// each other, a step taken (the pools grow to hold their pairs), each
/// lists hundreds of manifolds, more inversions than INSERTION_TRIPS.
/// Sorted by insertion alone, lavapipe stopped these sorts part way (its
/// loop limit, see sort_long_list), and the lists' order, so the solve's
/// sums, changed from run to run.
#[test]
fn long_lists_in_random_order_come_out_in_pair_order() {
    let n = 600;
    let scene = boxes_inside_each_other(n, 0x1405_7b7e_f767_814f);
    let Some(mut w) = world(&scene) else { return };
    w.step(1).unwrap();
    let (meta, _) = lists_after_contact_lists(&mut w);
    let long = meta[..n].iter().filter(|m| m.contacts >= 400).count();
    assert!(long >= n / 2, "lists of 400 manifolds or more: {long} of {n}");
    assert!(!w.contact_report().unwrap().lists_cut, "lists sorted whole reported as cut");
}

/// A list too long for the driver to sort within its loop limit is
/// reported (`ContactReport::lists_cut`, `Status::lists_cut`): a box resting on 5000
/// fixed boxes placed at one spot lists 5000 manifolds, and its sums ran in
/// an order that changed from run to run (it diverged at step 33 or 46 by
/// the run). 2000 are sorted whole and not reported. Where the driver has
/// no such limit, nothing is reported. A list of 5000 that the narrowphase
/// happened to write in order sorts within the limit (the order follows
/// thread timing): it must then be in pair order, which is checked instead.
#[test]
fn a_list_too_long_to_sort_within_the_drivers_loops_is_reported() {
    for (count, long) in [(2000, false), (5000, true)] {
        let mut bodies: Vec<verlet::Body> = (0..count)
            .map(|_| {
                let mut b = box_body([0.5; 3], [0.0, 0.5, 0.0]);
                b.fixed = true;
                b
            })
            .collect();
        bodies.push(box_body([0.5; 3], [0.0, 1.49, 0.0]));
        let scene = Scene { settings: Settings::default(), ground: None, bodies, joints: vec![], camera: None };
        let Some(mut w) = world(&scene) else { return };
        w.step(2).unwrap();
        let report = w.contact_report().unwrap();
        let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
        assert_eq!(meta[count].contacts as usize, count, "the box's list: {report:?}");
        let limited = w.gpu().loop_trips().is_some();
        if report.lists_cut {
            assert!(long && limited, "{count} manifolds, limited loops: {limited}: reported as cut");
        } else {
            let lists = w.read_words(Buffer::BodyPairs).unwrap();
            let heads: Vec<ContactManifold> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::Manifolds).unwrap());
            let first = meta[count].list_start as usize;
            let keys: Vec<u32> = lists[first..first + count]
                .iter()
                .map(|&r| heads[r as usize / 2].pair | if r % 2 == 0 { 0x8000_0000 } else { 0 })
                .collect();
            assert!(
                keys.windows(2).all(|k| k[0] < k[1]),
                "{count} manifolds, limited loops: {limited}: out of order, not reported"
            );
        }
    }
}

/// Runs the stages up to contact_lists and checks every body's list is in
/// pair order; returns pair_meta and how many lists had each length
/// (19: 19 or more).
fn lists_after_contact_lists(w: &mut verlet::World) -> (Vec<PairMeta>, Vec<usize>) {
    let stages: Vec<Stage> = w.step_plan().iter().map(|&(s, _)| s).take_while(|&s| s != Stage::Integrate).collect();
    assert!(stages.contains(&Stage::ContactLists));
    w.run_stages(&stages).unwrap();
    let report = w.contact_report().unwrap();
    assert!(report.pairs <= report.pair_capacity && report.manifolds <= report.manifold_capacity, "{report:?}");
    let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::PairMeta).unwrap());
    let lists = w.read_words(Buffer::BodyPairs).unwrap();
    let manifolds: Vec<ContactManifold> = bytemuck::pod_collect_to_vec(&w.read_words(Buffer::Manifolds).unwrap());
    let mut lengths = vec![0usize; 20];
    for (i, m) in meta.iter().enumerate().take(w.body_count()) {
        let first = m.list_start as usize;
        let list = &lists[first..first + m.contacts as usize];
        let mut last = None;
        for &r in list {
            let head = &manifolds[r as usize / 2];
            let (me, owned) = if r % 2 == 0 { (head.a, true) } else { (head.b, false) };
            assert_eq!(me as usize, i, "body {i} lists a manifold of {} and {}", head.a, head.b);
            let key = head.pair | if owned { 0x8000_0000 } else { 0 };
            assert!(last < Some(key), "body {i}: a list of {} is not in pair order (key {key:#x} after {last:?})", list.len());
            last = Some(key);
        }
        lengths[list.len().min(19)] += 1;
    }
    (meta, lengths)
}
