//! A scene turned into the GPU's records (each body's properties and first
//! pose, the joint lists, the grid's shape), and a body's GPU state turned
//! back into what a user reads (`body_output`).

use glam::{DQuat, DVec3};

use super::BodyOutput;
use crate::gpu::types::*;
use crate::scene::{Body, Scene, Settings, Shape};

/// The broadphase grid's shape, fixed at start-up from the bodies' sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridLayout {
    /// Edge of a cell (m): two grid bodies that can touch within the
    /// speculative gap are never more than one cell apart.
    pub cell_size: f32,
    /// Buckets of the hash table (a power of two, about two per body).
    pub hash_size: u32,
    /// Farthest gap (m) at which grid pairs get contacts.
    pub speculative: f32,
}

/// A body whose bounding radius exceeds this many times the median one is
/// kept out of the grid (a ramp, a wall, a floor made of boxes) and checked
/// by every body instead, so it never inflates the cells.
const LARGE_FACTOR: f32 = 2.0;
/// At most this many bodies are kept out of the grid; beyond it the cells
/// grow to hold the rest.
const MAX_LARGE: usize = 256;

/// Which bodies stay out of the grid, and the grid for the rest.
pub fn plan_grid(radii: &[f32]) -> (Vec<u32>, GridLayout) {
    let mut sorted: Vec<f32> = radii.to_vec();
    sorted.sort_by(f32::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.5);
    let mut large: Vec<u32> = (0..radii.len() as u32).filter(|&i| radii[i as usize] > LARGE_FACTOR * median).collect();
    if large.len() > MAX_LARGE {
        large.sort_by(|&a, &b| radii[b as usize].total_cmp(&radii[a as usize]).then(a.cmp(&b)));
        large.truncate(MAX_LARGE);
        large.sort();
    }
    let is_large = |i: usize| large.binary_search(&(i as u32)).is_ok();
    let r = (0..radii.len()).filter(|&i| !is_large(i)).map(|i| radii[i]).fold(0.0f32, f32::max).max(1e-3);
    let speculative = 0.5 * r;
    (large, GridLayout { cell_size: 2.0 * r + speculative, hash_size: hash_size(radii.len()), speculative })
}

/// Buckets of the grid's hash table for `bodies` bodies: a power of two,
/// about two per body, at least 1024.
pub(crate) fn hash_size(bodies: usize) -> u32 {
    (2 * bodies).max(1024).next_power_of_two() as u32
}

fn dvec(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

fn dquat(v: [f32; 4]) -> DQuat {
    DQuat::from_xyzw(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64)
}

/// What a user sees of a body: its pose and its velocities at the step's
/// time, from a Verlet state whose last substep took `dt` s.
///
/// The displacement `disp = x_n - x_(n-1)` over `dt` is the mean velocity
/// over the last substep, the velocity half a substep ago: reported as it
/// is, a body given zero velocity read `-g dt / 2` (0.027 m/s upward at the
/// default settings) at step 0. The velocity at the step's time is
/// `disp / dt + a dt / 2` with `a` the acceleration at that time, exact for
/// a constant one (`initial_state` sets `disp = v0 dt - g dt^2 / 2`, so step
/// 0 reads v0 back, and free fall reads v0 + g t at every step). A free body
/// accelerates at `gravity`; one that something held over the last substep
/// (a contact pushed it, it is fixed or asleep: `HELD`) or that hangs on a
/// joint is not known to, and resting on the ground it accelerates at none,
/// so it reads `disp / dt`, which is 0 at rest; a kinematic body never
/// accelerates. `not_free`: the body hangs on a joint or is kinematic.
/// Angular velocity has no acceleration to correct (no torques): the last
/// substep's turn over dt.
pub(crate) fn body_output(s: &BodyState, dt: f64, gravity: [f32; 3], not_free: bool) -> BodyOutput {
    let free = s.pos_low & HELD == 0 && !not_free;
    let half_step = if free { DVec3::from_array(gravity.map(|g| g as f64)) * (0.5 * dt) } else { DVec3::ZERO };
    let disp = DVec3::new(s.disp[0] as f64, s.disp[1] as f64, s.disp[2] as f64);
    let v = disp / dt + half_step;
    let mut dq = dquat(s.rot) * dquat(s.prev_rot).conjugate();
    if dq.w < 0.0 {
        dq = -dq;
    }
    let w = dq.to_scaled_axis() / dt;
    BodyOutput {
        position: [s.pos[0], s.pos[1], s.pos[2]],
        orientation: s.rot,
        linear_velocity: v.as_vec3().to_array(),
        angular_velocity: w.as_vec3().to_array(),
        asleep: s.rest_time >= crate::scene::SLEEP_AFTER,
    }
}

/// The ball joints as the GPU holds them (`joints/start`, `joints/refs`).
///
/// - Each body's joint ends, as CSR lists: body i's are
///   `refs[starts[i]..starts[i + 1]]`, in the order the joints are listed
///   (the pair pass skips jointed pairs; integrate counts a jointed body
///   as held up when it decides whether it rests).
/// - After them, the joint islands, for `joint_rest` (an island sleeps and
///   wakes as one): island k's joints are
///   `refs[starts[n + 1 + k]..starts[n + 2 + k]]` (n bodies), each once,
///   seen from its `body` end. An island
///   is a set of movable bodies joined to each other (fixed bodies and the
///   world join nothing: a joint to one belongs to its movable body's
///   island), its joints ordered outward from where it is held (breadth
///   first from the bodies joined to the world or a fixed body, else from
///   its lowest body). Joints between two fixed bodies are left out:
///   nothing can move them.
/// - After the islands, the paths `solve_joints` and `solve_paths` solve
///   (path p's joints are `refs[starts[n + islands + 2 + p]..]`): every joint once, an
///   island of at most `PATH_JOINTS` joints as one path (a chain along
///   itself, from its first end in the island's order; an island with a
///   branch or a loop, a bridge or a ragdoll, in its order), a larger one
///   cut into runs of at most `CUT_PATH_JOINTS` joints that go on through a
///   shared body as nearly straight as they can, from where the island is
///   held (a hanging grid's columns, then its rows). Along a chain or a cut
///   path each joint is seen from the end it shares with the one before it,
///   and the path never comes back to a body it holds: it is a chain.
///   After the paths' starts, each path's joint closes a `solve_joints`
///   pass: `u32::MAX` for an island with a branch or a loop (swept, as many
///   sweeps as the pass asks), 0 for a chain or a path cut from a larger
///   island (`solve_paths` solves it directly, as one system). They come by
///   colour: no two paths of one colour share a movable body, so a
///   colour's paths are solved side by side, one invocation each, and the
///   colours one after the other (Gauss-Seidel between colours).
pub(crate) struct JointLists {
    pub starts: Vec<u32>,
    pub refs: Vec<JointRef>,
    pub islands: u32,
    /// Where each colour's paths begin, and after the last its end: colour
    /// c holds paths `colours[c]..colours[c + 1]`.
    pub colours: Vec<u32>,
}

/// The most joints of an island kept whole as one path: swept
/// (`solve_joints`), its sweeps out and back stay within the driver's loop
/// limit with room to spare. A larger island is cut (`CUT_PATH_JOINTS`).
pub(crate) const PATH_JOINTS: usize = 128;

/// The most joints of a path cut from a larger island: `solve_paths` takes
/// it in 4n loop trips, well within the driver's limit, and a chain of up to
/// this many links is one path, solved whole. Where two paths meet, each
/// solve moves the body they share as if its own path alone held it: a chain
/// of 200 links cut at 128 joints, whipping down from its pin at 50 m/s,
/// opened the joint where its paths met by 118 mm for a moment; whole, 0.02
/// mm (docs/decisions/joints.md).
pub(crate) const CUT_PATH_JOINTS: usize = 1024;

impl JointLists {
    /// The joints of all the islands' lists (`joint_rest`'s invocations),
    /// of a scene of `bodies` bodies.
    pub(crate) fn island_joints(&self, bodies: usize) -> u32 {
        self.starts[bodies + 1 + self.islands as usize] - self.starts[bodies + 1]
    }

    /// The joints of the paths (every joint of the islands, once).
    pub(crate) fn path_joints(&self) -> u32 {
        let paths = self.colours.last().copied().unwrap_or(0) as usize;
        let first = self.starts.len() - 2 * paths - 1;
        self.refs.len() as u32 - self.starts[first]
    }

    /// Whether some paths are swept (`solve_joints`), and whether some are
    /// solved directly (`solve_paths`).
    pub(crate) fn path_kinds(&self) -> (bool, bool) {
        let paths = self.colours.last().copied().unwrap_or(0) as usize;
        let closes = &self.starts[self.starts.len() - paths..];
        (closes.contains(&u32::MAX), closes.contains(&0))
    }

    /// The paths' colours: `solve_joints` and `solve_paths` are dispatched once per colour.
    pub(crate) fn colour_count(&self) -> u32 {
        self.colours.len().saturating_sub(1) as u32
    }
}

pub(crate) fn joint_lists(scene: &Scene) -> JointLists {
    let n = scene.bodies.len();
    let movable = |b: i32| b >= 0 && scene.bodies[b as usize].is_dynamic();
    let mut per_body: Vec<Vec<JointRef>> = vec![Vec::new(); n];
    for j in &scene.joints {
        for me in 0..2 {
            if j.bodies[me] >= 0 {
                per_body[j.bodies[me] as usize].push(joint_end(scene, j, me));
            }
        }
    }
    let mut starts = Vec::with_capacity(n + 1);
    let mut refs = Vec::new();
    for list in per_body {
        starts.push(refs.len() as u32);
        refs.extend(list);
    }
    starts.push(refs.len() as u32);

    // the joints each movable body takes part in, by joint index
    let mut touching: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (k, j) in scene.joints.iter().enumerate() {
        for b in j.bodies {
            if movable(b) {
                touching[b as usize].push(k);
            }
        }
    }
    // roots first: bodies held by the world or a fixed body, in index order
    let held = |b: usize| touching[b].iter().any(|&k| scene.joints[k].bodies.iter().any(|&o| !movable(o)));
    let mut seeds: Vec<usize> = (0..n).filter(|&b| !touching[b].is_empty() && held(b)).collect();
    seeds.extend((0..n).filter(|&b| !touching[b].is_empty() && !held(b)));
    // bodies already given to an island
    let mut placed = vec![false; n];
    let mut joint_done = vec![false; scene.joints.len()];
    let mut islands = 0u32;
    let mut queue = std::collections::VecDeque::new();
    let mut island_starts = Vec::new();
    // the islands' joints in order, each with the body it is seen from
    let mut island_order: Vec<Vec<(usize, u32)>> = Vec::new();
    // reached by an island's walk (each body belongs to one island)
    let mut reached = vec![false; n];
    for seed in seeds {
        if placed[seed] {
            continue;
        }
        // this seed's island: every root in it starts the breadth-first walk
        island_starts.push(refs.len() as u32);
        island_order.push(Vec::new());
        let mut members = vec![seed];
        placed[seed] = true;
        let mut at = 0;
        while at < members.len() {
            for &k in &touching[members[at]] {
                for b in scene.joints[k].bodies {
                    if movable(b) && !placed[b as usize] {
                        placed[b as usize] = true;
                        members.push(b as usize);
                    }
                }
            }
            at += 1;
        }
        members.sort_unstable();
        queue.extend(members.iter().copied().filter(|&b| held(b)));
        if queue.is_empty() {
            queue.push_back(members[0]);
        }
        for &b in &queue {
            reached[b] = true;
        }
        while let Some(b) = queue.pop_front() {
            for &k in &touching[b] {
                if joint_done[k] {
                    continue;
                }
                joint_done[k] = true;
                let j = &scene.joints[k];
                let me = if j.bodies[0] == b as i32 { 0 } else { 1 };
                refs.push(joint_end(scene, j, me));
                island_order.last_mut().expect("the island begun above").push((k, b as u32));
                let other = j.bodies[1 - me];
                if movable(other) && !reached[other as usize] {
                    reached[other as usize] = true;
                    queue.push_back(other as usize);
                }
            }
        }
        islands += 1;
    }
    island_starts.push(refs.len() as u32);
    starts.extend(island_starts);
    let (paths, colours) = joint_paths(scene, &island_order, &touching);
    let mut closes = Vec::with_capacity(paths.len());
    for (path, swept) in paths {
        starts.push(refs.len() as u32);
        refs.extend(path);
        closes.push(if swept { u32::MAX } else { 0 });
    }
    starts.push(refs.len() as u32);
    starts.extend(closes);
    JointLists { starts, refs, islands, colours }
}

/// Anchor `k` of joint `j` in the frame its body's pose is kept in
/// (`Body::mass_frame`); the world's as given.
pub(crate) fn local_anchor(scene: &Scene, j: &crate::scene::Joint, k: usize) -> [f32; 3] {
    match usize::try_from(j.bodies[k]) {
        Ok(b) => to_mass_frame(&scene.bodies[b], j.anchors[k]),
        Err(_) => j.anchors[k],
    }
}

/// Joint `j` seen from its end `me` (0 or 1).
fn joint_end(scene: &Scene, j: &crate::scene::Joint, me: usize) -> JointRef {
    let other = j.bodies[1 - me];
    let local = |k: usize| local_anchor(scene, j, k);
    JointRef {
        local_self: local(me),
        partner: if other < 0 { WORLD } else { other as u32 },
        local_partner: local(1 - me),
        body: j.bodies[me] as u32,
    }
}

/// The pose of body `b`'s own frame, from the pose the simulation keeps
/// (`Body::mass_frame`): the inverse of `initial_state`'s.
pub(crate) fn from_mass_frame(b: &Body, position: [f32; 3], orientation: [f32; 4]) -> ([f32; 3], [f32; 4]) {
    let Some((centre, axes)) = b.mass_frame() else { return (position, orientation) };
    let o = orientation.map(|v| v as f64);
    let frame = (DQuat::from_xyzw(o[0], o[1], o[2], o[3]) * axes.conjugate()).normalize();
    let origin = DVec3::from_array(position.map(|v| v as f64)) - frame * centre;
    (origin.as_vec3().to_array(), frame.as_quat().to_array())
}

/// The pose the simulation keeps for body `b` whose own frame is at
/// `position`, turned by `orientation` (`Body::mass_frame`).
pub(crate) fn to_mass_pose(b: &Body, position: [f32; 3], orientation: [f32; 4]) -> ([f32; 3], [f32; 4]) {
    let Some((centre, axes)) = b.mass_frame() else { return (position, orientation) };
    let o = orientation.map(|v| v as f64);
    let frame = DQuat::from_xyzw(o[0], o[1], o[2], o[3]).normalize();
    let pos = DVec3::from_array(position.map(|v| v as f64)) + frame * centre;
    (pos.as_vec3().to_array(), (frame * axes).normalize().as_quat().to_array())
}

/// A point in body `b`'s own frame, in the frame the simulation keeps its
/// pose in (`Body::mass_frame`).
pub(crate) fn to_mass_frame(b: &Body, p: [f32; 3]) -> [f32; 3] {
    let Some((centre, axes)) = b.mass_frame() else { return p };
    (axes.conjugate() * (DVec3::from_array(p.map(|v| v as f64)) - centre)).as_vec3().to_array()
}

/// An island's joints along the chain they form, where they form one: each
/// movable body in at most two of them, the bodies joined in a line, and
/// the line held (by the world or a fixed body) at one point at most (a
/// rope, a chain hung by one end, a pendulum, a free chain). From the first
/// end in the island's order, each joint seen from the body it shares with
/// the joint before (the first from its movable body), so that
/// `solve_paths` solves it as one system. None for an island with a branch
/// or a loop, or held at two points.
fn chain_order(scene: &Scene, island: &[(usize, u32)], touching: &[Vec<usize>]) -> Option<Vec<JointRef>> {
    let movable = |b: i32| b >= 0 && scene.bodies[b as usize].is_dynamic();
    let ends = |k: usize| scene.joints[k].bodies;
    // a joint between two movable bodies, not an anchor
    let links = |k: usize| ends(k).iter().all(|&b| movable(b));
    let degree = |b: u32| touching[b as usize].len();
    let bodies: std::collections::BTreeSet<u32> =
        island.iter().flat_map(|&(k, _)| ends(k)).filter(|&b| movable(b)).map(|b| b as u32).collect();
    let link_count = island.iter().filter(|&&(k, _)| links(k)).count();
    let link_degree = |b: u32| touching[b as usize].iter().filter(|&&k| links(k)).count();
    // Held at two points, the line is a loop through what holds it, and
    // its system can be singular: a body on two hinges (a door) turns about
    // the line between them however it is pushed, and a chain pulled
    // straight between two pins cannot close along its line (solved
    // directly it shook at 2.3 m/s after 20 s; swept it comes to rest
    // stretched 1.6 mm a joint).
    let anchors = island.len() - link_count;
    if bodies.iter().any(|&b| degree(b) > 2) || link_count + 1 != bodies.len() || anchors > 1 {
        return None;
    }
    let start = island.iter().map(|&(_, at)| at).find(|&at| link_degree(at) <= 1)?;
    let end_at = |k: usize, at: u32| joint_end(scene, &scene.joints[k], usize::from(ends(k)[0] != at as i32));
    let mut path = Vec::with_capacity(island.len());
    let (mut at, mut came) = (start, usize::MAX);
    loop {
        // its anchors, then on along its link not yet taken
        path.extend(touching[at as usize].iter().filter(|&&k| !links(k)).map(|&k| end_at(k, at)));
        let Some(&next) = touching[at as usize].iter().find(|&&k| links(k) && k != came) else { break };
        let r = end_at(next, at);
        path.push(r);
        (at, came) = (r.partner, next);
    }
    // a line of bodies walked from one end takes every joint once
    (path.len() == island.len()).then_some(path)
}

/// The joints cut into coloured paths (see `JointLists`), from the islands'
/// joints in their order (each joint with the body it is seen from);
/// `touching`: the joints each movable body takes part in. Returns
/// the paths in colour order, each with whether it is swept (else solved
/// directly), and where each colour begins.
fn joint_paths(scene: &Scene, islands: &[Vec<(usize, u32)>], touching: &[Vec<usize>]) -> (Vec<(Vec<JointRef>, bool)>, Vec<u32>) {
    let movable = |b: u32| b != WORLD && scene.bodies[b as usize].is_dynamic();
    // joint k seen from its end at body `at`
    let end_at = |k: usize, at: u32| joint_end(scene, &scene.joints[k], usize::from(scene.joints[k].bodies[0] != at as i32));
    let mut taken = vec![false; scene.joints.len()];
    // the joint at body `at` (a movable one) not yet taken that goes on most
    // nearly straight from `from` (where, in its frame, the path came in;
    // the first listed among equals) to another movable body, taken, seen
    // from `at`: a joint to the world or a fixed body only starts a path, so
    // that no path holds a body at two points (its system is singular, as
    // `chain_order` says)
    let straightest = |at: u32, from: [f32; 3], taken: &mut Vec<bool>| -> Option<(usize, JointRef)> {
        if !movable(at) {
            return None;
        }
        let came = -glam::Vec3::from(from).normalize_or_zero();
        let straight = |r: &JointRef| glam::Vec3::from(r.local_self).normalize_or_zero().dot(came);
        let mut best: Option<(usize, JointRef)> = None;
        // a turn of a right angle or more ends the path: a grid's columns
        // and rows stay apart, so that two colours hold them
        let ahead =
            touching[at as usize].iter().filter(|&&k| !taken[k]).map(|&k| (k, end_at(k, at))).filter(|(_, r)| movable(r.partner));
        for (k, r) in ahead.filter(|(_, r)| straight(r) > 0.0 || came == glam::Vec3::ZERO) {
            if best.as_ref().is_none_or(|(_, b)| straight(&r) > straight(b)) {
                best = Some((k, r));
            }
        }
        let (k, r) = best?;
        taken[k] = true;
        Some((k, r))
    };
    let mut paths: Vec<(Vec<JointRef>, Vec<u32>, bool)> = Vec::new();
    // an island of at most PATH_JOINTS joints is one path: a chain along
    // itself, solved directly; any other (a bridge's two ropes, a
    // ragdoll's branches) in its order (outward from where it is held),
    // swept whole, its parallel joints together
    for island in islands.iter().filter(|i| i.len() <= PATH_JOINTS) {
        let chain = chain_order(scene, island, touching);
        let swept = chain.is_none();
        let path: Vec<JointRef> = chain.unwrap_or_else(|| island.iter().map(|&(k, at)| end_at(k, at)).collect());
        let bodies = path.iter().flat_map(|r| [r.body, r.partner]).filter(|&b| movable(b)).collect();
        island.iter().for_each(|&(k, _)| taken[k] = true);
        paths.push((path, bodies, swept));
    }
    // a larger one is cut into paths, the first ones starting where it is
    // held (a joint to the world or a fixed body), so that they sweep
    // outward from their anchors
    let order: Vec<(usize, u32)> = islands.iter().filter(|i| i.len() > PATH_JOINTS).flatten().copied().collect();
    let anchored = order.iter().filter(|&&(k, at)| !movable(end_at(k, at).partner));
    for &(k, at) in anchored.chain(&order) {
        if taken[k] {
            continue;
        }
        taken[k] = true;
        let r = end_at(k, at);
        let mut path = vec![r];
        let mut bodies: Vec<u32> = [r.body, r.partner].into_iter().filter(|&b| movable(b)).collect();
        // on from the far end (from the body where the far end is the world
        // or a fixed body), through joints not yet taken, each time the one
        // that goes on most nearly straight (a hanging grid's columns and
        // rows each become paths); `from`: where, in the end body's frame,
        // the path came in
        let anchored = !movable(r.partner);
        let (mut end, mut from) = if anchored { (r.body, r.local_self) } else { (r.partner, r.local_partner) };
        while path.len() < CUT_PATH_JOINTS {
            let Some((k, e)) = straightest(end, from, &mut taken) else { break };
            if bodies.contains(&e.partner) {
                taken[k] = false;
                break;
            }
            path.push(e);
            (end, from) = (e.partner, e.local_partner);
            bodies.extend([end].into_iter().filter(|&b| movable(b)));
        }
        // and back from its start, where it does not start at an anchor (a
        // row found in its middle is one path, not two)
        let (mut start, mut from) = (r.body, r.local_self);
        while !anchored && path.len() < CUT_PATH_JOINTS {
            let Some((k, e)) = straightest(start, from, &mut taken) else { break };
            if bodies.contains(&e.partner) {
                taken[k] = false;
                break;
            }
            // seen from the far end, so that the path reads on into its start
            path.insert(0, end_at(k, e.partner));
            (start, from) = (e.partner, e.local_partner);
            bodies.extend([start].into_iter().filter(|&b| movable(b)));
        }
        paths.push((path, bodies, false));
    }
    // greedy colours in path order: the first colour none of the path's
    // bodies has been given yet
    let mut used: Vec<Vec<u32>> = vec![Vec::new(); scene.bodies.len()];
    let mut colour_of = Vec::with_capacity(paths.len());
    for (_, bodies, _) in &paths {
        let c = (0u32..).find(|c| bodies.iter().all(|&b| !used[b as usize].contains(c))).expect("a free colour");
        for &b in bodies {
            used[b as usize].push(c);
        }
        colour_of.push(c);
    }
    // the paths by colour, in path order within one (a stable sort)
    let mut by_colour: Vec<usize> = (0..paths.len()).collect();
    by_colour.sort_by_key(|&p| colour_of[p]);
    let count = colour_of.iter().max().map_or(0, |&c| c + 1);
    let colours = (0..=count).map(|c| colour_of.iter().filter(|&&pc| pc < c).count() as u32).collect();
    let mut paths: Vec<Option<(Vec<JointRef>, bool)>> = paths.into_iter().map(|(p, _, whole)| Some((p, whole))).collect();
    let ordered = by_colour.into_iter().map(|p| paths[p].take().expect("each path once")).collect();
    (ordered, colours)
}

/// How far each joint has opened (m): the distance between its two anchors.
pub fn joint_gaps(scene: &Scene, states: &[BodyState]) -> Vec<f32> {
    let anchor = |body: i32, local: [f32; 3]| -> DVec3 {
        let l = DVec3::new(local[0] as f64, local[1] as f64, local[2] as f64);
        if body < 0 {
            return l;
        }
        let s = &states[body as usize];
        dvec(s.pos) + dquat(s.rot).normalize() * l
    };
    scene.joints.iter().map(|j| (anchor(j.bodies[0], j.anchors[0]) - anchor(j.bodies[1], j.anchors[1])).length() as f32).collect()
}

/// Every body's GPU record, the bodies kept out of the grid (`LARGE_BODY` in
/// their records), the grid for the rest, and the hull records.
pub(crate) fn scene_props(scene: &Scene) -> (Vec<BodyProps>, Vec<u32>, GridLayout, Vec<[f32; 4]>) {
    let mut props: Vec<BodyProps> = scene.bodies.iter().map(|b| body_props(b, &scene.settings)).collect();
    let (hulls, firsts) = super::hull_records::hull_records(&scene.bodies);
    for (p, first) in props.iter_mut().zip(firsts) {
        p.hull = first;
    }
    for (p, limit) in props.iter_mut().zip(speed_limits(scene)) {
        p.speed_limit = limit;
    }
    let radii: Vec<f32> = props.iter().map(|p| p.half_extents[3]).collect();
    let (large, grid) = plan_grid(&radii);
    for &i in &large {
        props[i as usize].grid_class = LARGE_BODY;
    }
    (props, large, grid, hulls)
}

/// Each body's speed limit (m/s, `BodyProps::speed_limit`; 0: none): twice
/// the speed at which all the energy the scene can have would move the body
/// if it alone had it. That energy is what the bodies have as placed
/// (moving and spinning), what gravity can give them down to the ground
/// (each centre's height above it: a bound), and what pushing out overlap
/// or closing a joint's gap can add (every body moved at
/// `MAX_DEPENETRATION_SPEED`). Restitution of at most 1,
/// friction, damping, contacts and joints add none; twice the speed leaves
/// the integration's own error room. With gravity but no ground under it
/// (none, or gravity not straight down) a fall has no bound, and no body
/// gets a limit; fixed and kinematic bodies need none, and where a
/// kinematic body moves (it can add energy without end) no body gets one.
pub(crate) fn speed_limits(scene: &Scene) -> Vec<f32> {
    let g = DVec3::from_array(scene.settings.gravity.map(|v| v as f64));
    let ground = match &scene.ground {
        Some(ground) if g.x == 0.0 && g.z == 0.0 && g.y <= 0.0 => Some(ground.height as f64),
        _ if g == DVec3::ZERO => None,
        _ => return vec![0.0; scene.bodies.len()],
    };
    // a kinematic body that moves can add energy without end (a drum turning)
    let moving = |v: [f32; 3]| v != [0.0; 3];
    if scene.bodies.iter().any(|b| b.kinematic && (moving(b.linear_velocity) || moving(b.angular_velocity))) {
        return vec![0.0; scene.bodies.len()];
    }
    let push = crate::limits::MAX_DEPENETRATION_SPEED as f64;
    let mut energy = 0.0;
    for b in scene.bodies.iter().filter(|b| b.is_dynamic()) {
        let m = b.mass as f64;
        let v = DVec3::from_array(b.linear_velocity.map(|v| v as f64));
        let w = DVec3::from_array(b.angular_velocity.map(|v| v as f64));
        let inertia = b.shape.inertia_f64(b.mass).into_iter().fold(0.0, f64::max);
        let fall = ground.map_or(0.0, |h| -g.y * (b.position[1] as f64 - h).max(0.0));
        energy += 0.5 * m * (v.length_squared() + push * push) + 0.5 * inertia * w.length_squared() + m * fall;
    }
    scene.bodies.iter().map(|b| if b.is_dynamic() { (2.0 * (2.0 * energy / b.mass as f64).sqrt()) as f32 } else { 0.0 }).collect()
}

/// The GPU record of a body's shape, mass and material.
pub(crate) fn body_props(b: &Body, settings: &Settings) -> BodyProps {
    let mut radius = b.bounding_radius();
    let (half, shape) = match b.shape {
        Shape::Box { half_extents: h } => ([h[0], h[1], h[2]], SHAPE_BOX),
        Shape::Sphere { radius } => ([radius, radius, radius], SHAPE_SPHERE),
        Shape::Capsule { radius, half_height } => ([radius, half_height, radius], SHAPE_CAPSULE),
        Shape::Hull(ref h) => {
            // about the origin of the frame the pose is kept in, which a
            // kinematic hull's points need not surround
            let corners = super::hull_records::kept_corners(b, h);
            let half = corners.iter().fold(DVec3::ZERO, |m, c| m.max(c.abs()));
            radius = corners.iter().map(|c| c.length()).fold(0.0, f64::max) as f32;
            ([half.x as f32, half.y as f32, half.z as f32], SHAPE_HULL)
        }
    };
    let ii = b.inverse_inertia();
    BodyProps {
        half_extents: [half[0], half[1], half[2], radius],
        inv_inertia: [ii[0], ii[1], ii[2], b.inverse_mass()],
        restitution: b.restitution.unwrap_or(settings.restitution),
        friction: b.friction.unwrap_or(settings.friction),
        shape,
        flags: if b.fixed {
            FLAG_FIXED
        } else if b.kinematic {
            FLAG_KINEMATIC
        } else {
            0
        },
        grid_class: GRID_BODY,
        hull: NO_HULL,
        ..Default::default()
    }
}

/// The starting pose, with the displacement from the previous pose set so
/// that the first Verlet step reproduces the initial velocities exactly:
/// disp = x0 - x_prev = v0 h - g h^2/2 makes x1 = x0 + v0 h + g h^2/2, and
/// Verlet then stays on the parabola. A fixed body is `HELD` (see
/// `body_output`); no rounding remainder yet (x0 is exact).
pub fn initial_state(b: &Body, settings: &Settings) -> BodyState {
    let o = b.orientation;
    let mut x0 = DVec3::from_array(b.position.map(|v| v as f64));
    let mut q0 = DQuat::from_xyzw(o[0] as f64, o[1] as f64, o[2] as f64, o[3] as f64).normalize();
    // the pose the simulation keeps (`Body::mass_frame`)
    if let Some((centre, axes)) = b.mass_frame() {
        x0 += q0 * centre;
        q0 = (q0 * axes).normalize();
    }
    let (disp, prev_q) = if b.fixed {
        (DVec3::ZERO, q0)
    } else {
        let h = (settings.dt / settings.substeps as f32) as f64;
        let v0 = DVec3::from_array(b.linear_velocity.map(|v| v as f64));
        let w0 = DVec3::from_array(b.angular_velocity.map(|v| v as f64));
        // a kinematic body moves by its velocities alone
        let g = if b.kinematic { DVec3::ZERO } else { DVec3::from_array(settings.gravity.map(|v| v as f64)) };
        (v0 * h - 0.5 * g * h * h, (DQuat::from_scaled_axis(-w0 * h) * q0).normalize())
    };
    let v3 = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
    let q4 = |q: DQuat| [q.x as f32, q.y as f32, q.z as f32, q.w as f32];
    let x = v3(x0);
    BodyState { pos: x, rest_time: 0.0, disp: v3(disp), pos_low: if b.fixed { HELD } else { 0 }, rot: q4(q0), prev_rot: q4(prev_q) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hull's pose is kept at its centre of mass on its principal axes, and
    /// read back as its own frame's: out and back agree, and the kept centre
    /// is where the frame puts the centroid.
    #[test]
    fn a_hulls_pose_goes_to_its_mass_frame_and_back() {
        let points = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5], [0.3, 0.2, 0.1]];
        let shape = Shape::Hull(crate::scene::HullShape::new(points).unwrap());
        let mut b = Body::new(shape, [1.0, 2.0, 3.0]);
        b.orientation = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0).as_quat().to_array();
        let s = initial_state(&b, &Settings::default());
        let (centre, axes) = b.mass_frame().unwrap();
        assert!(axes.angle_between(DQuat::IDENTITY) > 0.01, "the principal axes are not the frame's");
        let frame = DQuat::from_array(b.orientation.map(|v| v as f64));
        let want = DVec3::new(1.0, 2.0, 3.0) + frame * centre;
        assert!((DVec3::from_array(s.pos.map(|v| v as f64)) - want).length() < 1e-6);
        assert_eq!(to_mass_pose(&b, b.position, b.orientation), (s.pos, s.rot));
        let (position, orientation) = from_mass_frame(&b, s.pos, s.rot);
        assert!((glam::Vec3::from(position) - glam::Vec3::from(b.position)).length() < 1e-6, "{position:?}");
        let back = glam::Quat::from_array(orientation);
        assert!(back.angle_between(glam::Quat::from_array(b.orientation)) < 1e-5, "{orientation:?}");
        // an anchor at the hull's corner (2, 0, 0) stays that corner in the kept frame
        let local = glam::Vec3::from(to_mass_frame(&b, [2.0, 0.0, 0.0]));
        let world = glam::Vec3::from(s.pos) + glam::Quat::from_array(s.rot) * local;
        let direct = glam::Vec3::from(b.position) + glam::Quat::from_array(b.orientation) * glam::Vec3::new(2.0, 0.0, 0.0);
        assert!((world - direct).length() < 1e-5, "{world} against {direct}");
        // a kinematic hull keeps its own frame
        b.kinematic = true;
        assert_eq!(b.mass_frame(), None);
    }
    use crate::scene::Joint;
    use crate::scenes::{box_body, stack};

    /// A box of 1000 kg centred 3 m above the ground, another moving at
    /// 4 m/s on it (centred 0.5 m above it), a fixed one: the energy is
    /// gravity's 1000 g (3 + 0.5) J (down to the centres' heights: a bound),
    /// the moving box's 8 kJ and the push allowance, 1000 x 3^2 / 2 J for
    /// each free box.
    #[test]
    fn speed_limits_follow_the_scenes_energy() {
        let mut scene = stack(0);
        let mut moving = box_body([0.5; 3], [2.0, 0.5, 0.0]);
        moving.linear_velocity = [4.0, 0.0, 0.0];
        let mut fixed = box_body([0.5; 3], [5.0, 0.5, 0.0]);
        fixed.fixed = true;
        scene.bodies = vec![box_body([0.5; 3], [0.0, 3.0, 0.0]), moving, fixed];
        let m = scene.bodies[0].mass as f64;
        let g = -scene.settings.gravity[1] as f64;
        let energy = m * g * 3.5 + 0.5 * m * 16.0 + 2.0 * 0.5 * m * 9.0;
        let limit = (2.0 * (2.0 * energy / m).sqrt()) as f32;
        let limits = speed_limits(&scene);
        assert!((limits[0] - limit).abs() < 1e-4 * limit && limits[1] == limits[0], "{limits:?}, expected {limit}");
        assert_eq!(limits[2], 0.0, "a fixed body needs no limit");
        // gravity with nothing to stop a fall: no limit
        scene.ground = None;
        assert!(speed_limits(&scene).iter().all(|&v| v == 0.0));
        // no gravity, no ground: what the bodies have and the push
        scene.settings.gravity = [0.0; 3];
        let energy = 0.5 * m * 16.0 + 2.0 * 0.5 * m * 9.0;
        let limit = (2.0 * (2.0 * energy / m).sqrt()) as f32;
        assert!((speed_limits(&scene)[0] - limit).abs() < 1e-4 * limit);
    }

    /// Islands: a chain pinned to the world at its far end (ordered outward
    /// from the pin), a body held by a fixed one, and a joint between two
    /// fixed bodies (left out).
    #[test]
    fn joint_lists_split_and_order_the_islands() {
        let mut scene = stack(0);
        scene.bodies = (0..6).map(|k| box_body([0.5; 3], [k as f32, 1.0, 0.0])).collect();
        scene.bodies[4].fixed = true;
        scene.bodies[5].fixed = true;
        let j = |a: i32, b: i32| Joint { bodies: [a, b], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] };
        scene.joints = vec![
            j(0, 1),
            j(1, 2),
            Joint { bodies: [2, -1], anchors: [[0.5, 0.0, 0.0], [2.5, 1.0, 0.0]] },
            j(3, 4), // 3 held by fixed 4
            j(4, 5), // two fixed bodies: left out
        ];
        let lists = joint_lists(&scene);
        let n = scene.bodies.len();
        assert_eq!(lists.islands, 2);
        // per-body ends: two per joint between bodies, one per world joint
        let per_body = lists.starts[n] as usize;
        assert_eq!(per_body, 9);
        let island = |k: usize| {
            let (from, to) = (lists.starts[n + 1 + k] as usize, lists.starts[n + 2 + k] as usize);
            lists.refs[from..to].iter().map(|r| (r.body, r.partner)).collect::<Vec<_>>()
        };
        // held bodies seed first, in index order: 2 (world), then 3 (fixed
        // 4); a body's joints in the scene's order
        assert_eq!(island(0), vec![(2, 1), (2, WORLD), (1, 0)]);
        assert_eq!(island(1), vec![(3, 4)]);
        // then the paths: each island is one (they are small); both are
        // chains, so each runs along itself from its held end, each joint
        // seen from the body it shares with the one before, and is solved
        // directly; they share no body, so one colour holds both
        let path = |p: usize| {
            let at = n + 1 + 2 + 1 + p;
            let (from, to) = (lists.starts[at] as usize, lists.starts[at + 1] as usize);
            lists.refs[from..to].iter().map(|r| (r.body, r.partner)).collect::<Vec<_>>()
        };
        assert_eq!(path(0), vec![(2, WORLD), (2, 1), (1, 0)]);
        assert_eq!(path(1), vec![(3, 4)]);
        assert_eq!(lists.colours, vec![0, 2]);
        assert_eq!(lists.starts.len(), n + 1 + 3 + 3 + 2);
        assert_eq!(lists.starts[n + 1 + 3 + 3..], [0, 0]);
        assert_eq!(lists.path_kinds(), (false, true));
    }

    /// Which small islands are chains, solved directly, and which are swept:
    /// a line of bodies held at one point at most is a chain; a line held at
    /// two, a body with a third joint, or two bodies joined twice, is not.
    #[test]
    fn chains_are_told_from_other_islands() {
        let kinds = |joints: Vec<Joint>, fixed: &[usize]| {
            let mut scene = stack(0);
            scene.bodies = (0..5).map(|k| box_body([0.5; 3], [k as f32, 1.0, 0.0])).collect();
            for &f in fixed {
                scene.bodies[f].fixed = true;
            }
            scene.joints = joints;
            let lists = joint_lists(&scene);
            let paths = *lists.colours.last().unwrap() as usize;
            let n = scene.bodies.len() + 2 + lists.islands as usize;
            let path = |p: usize| {
                let (from, to) = (lists.starts[n + p] as usize, lists.starts[n + p + 1] as usize);
                lists.refs[from..to].iter().map(|r| (r.body, r.partner)).collect::<Vec<_>>()
            };
            (lists.starts[lists.starts.len() - paths..].to_vec(), (0..paths).map(path).collect::<Vec<_>>())
        };
        let j = |a: i32, b: i32| Joint { bodies: [a, b], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] };
        let world = |a: i32| Joint { bodies: [a, -1], anchors: [[0.0, 0.5, 0.0], [a as f32, 1.5, 0.0]] };
        // a line hung from a fixed body, listed out of order: one path
        // along it from the held end
        let (closes, paths) = kinds(vec![j(2, 3), j(0, 1), j(1, 2)], &[0]);
        assert_eq!(closes, [0]);
        assert_eq!(paths, [vec![(1, 0), (1, 2), (2, 3)]]);
        // from the world at its far end
        let (closes, paths) = kinds(vec![j(0, 1), j(1, 2), world(2)], &[]);
        assert_eq!(closes, [0]);
        assert_eq!(paths, [vec![(2, WORLD), (2, 1), (1, 0)]]);
        // held at both ends (by a fixed body and the world), and a body held
        // at two points (a door on two hinges): loops through what holds
        // them, swept; two free bodies on one joint: a chain
        assert_eq!(kinds(vec![j(2, 3), j(0, 1), world(3), j(1, 2)], &[0]).0, [u32::MAX]);
        let (closes, paths) = kinds(vec![j(0, 1), world(3), world(3)], &[]);
        assert_eq!(closes, [u32::MAX, 0]);
        assert_eq!(paths, [vec![(3, WORLD), (3, WORLD)], vec![(0, 1)]]);
        // a body with three joints (a branch), and two bodies joined twice (a loop)
        assert_eq!(kinds(vec![j(0, 1), j(1, 2), j(1, 3)], &[]).0, [u32::MAX]);
        assert_eq!(kinds(vec![j(0, 1), world(1), j(1, 2)], &[]).0, [u32::MAX]);
        assert_eq!(kinds(vec![j(0, 1), j(0, 1)], &[]).0, [u32::MAX]);
    }

    /// Every joint is in one path; no two paths of a colour share a body
    /// that moves; a path follows its joints through shared bodies.
    #[test]
    fn joint_paths_cover_every_joint_and_colours_share_no_body() {
        // whether its paths are swept (an island with a branch or a loop)
        // or solved directly (a chain, or paths cut from a larger island)
        for (name, scene, swept) in [
            ("chain", crate::scenes::chain(21), false),
            ("catenary", crate::scenes::hanging(20), true),
            ("bridge", crate::scenes::bridge(20), true),
            ("ragdoll", crate::scenes::ragdoll(3), true),
            ("joint_grid", crate::scenes::joint_grid(20), false),
            ("large joint_grid", crate::scenes::joint_grid(100), false),
            ("long chain", crate::scenes::chain(300), false),
        ] {
            let lists = joint_lists(&scene);
            let n = scene.bodies.len();
            let first = n + 2 + lists.islands as usize;
            let count = lists.colours.last().copied().unwrap_or(0) as usize;
            let paths: Vec<&[JointRef]> =
                lists.starts[first..first + count + 1].windows(2).map(|w| &lists.refs[w[0] as usize..w[1] as usize]).collect();
            let moving = |b: u32| b != WORLD && scene.bodies[b as usize].is_dynamic();
            let solved = scene.joints.iter().filter(|j| j.bodies.iter().any(|&b| b >= 0 && moving(b as u32))).count();
            let closes = &lists.starts[first + count + 1..];
            assert_eq!(closes.len(), count, "{name}");
            let whole = solved <= PATH_JOINTS;
            assert!(closes.iter().all(|&c| c == if swept { u32::MAX } else { 0 }), "{name}");
            assert_eq!(lists.path_kinds(), (swept, !swept), "{name}");
            assert_eq!(paths.iter().map(|p| p.len()).sum::<usize>(), solved, "{name}: every joint once");
            for p in &paths {
                assert!(p.len() <= if whole { PATH_JOINTS } else { CUT_PATH_JOINTS }, "{name}: a path of {}", p.len());
                // a path solved directly goes on through shared bodies
                if !swept {
                    for w in p.windows(2) {
                        assert!(w[1].body == w[0].partner || w[1].body == w[0].body, "{name}: a path jumps");
                    }
                    // and is a chain: joints two or more apart share no body
                    for (k, r) in p.iter().enumerate() {
                        for later in p.iter().skip(k + 2) {
                            let shares = |b: u32| moving(b) && (b == later.body || b == later.partner);
                            assert!(!shares(r.body) && !shares(r.partner), "{name}: a direct path comes back to a body");
                        }
                    }
                }
            }
            for c in lists.colours.windows(2) {
                let mut seen = std::collections::HashSet::new();
                for p in &paths[c[0] as usize..c[1] as usize] {
                    let bodies: std::collections::HashSet<u32> =
                        p.iter().flat_map(|r| [r.body, r.partner]).filter(|&b| moving(b)).collect();
                    for b in bodies {
                        assert!(seen.insert(b), "{name}: body {b} in two paths of one colour");
                    }
                }
            }
            assert_eq!(*lists.colours.last().unwrap() as usize, paths.len(), "{name}");
            eprintln!("{name}: {} joints in {} paths, {} colours", solved, paths.len(), lists.colour_count());
        }
        // a chain hung from the world is one path; a large grid's columns
        // are one colour and its rows the other
        assert_eq!(joint_lists(&crate::scenes::chain(21)).colour_count(), 1);
        // so is one of up to CUT_PATH_JOINTS links, cut from nothing
        assert_eq!(joint_lists(&crate::scenes::chain(300)).colour_count(), 1);
        assert_eq!(joint_lists(&crate::scenes::joint_grid(100)).colour_count(), 2);
    }
}
