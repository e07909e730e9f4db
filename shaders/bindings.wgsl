// The step's bindings. Each pass binds those its entry point uses (its own
// layout, src/step/mod.rs), in two bind groups, A->B and B->A, which differ
// only in which state buffer is state_in and which state_out (made again
// when the pools are).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> props: array<PropsWords>;
@group(0) @binding(2) var<storage, read> state_in: array<StateWords>;
@group(0) @binding(3) var<storage, read_write> state_out: array<StateWords>;
@group(0) @binding(4) var<storage, read_write> vel0: array<Velocity>;
// broadphase grid: bodies counted per hash bucket, then sorted by bucket
@group(0) @binding(5) var<storage, read_write> cell_count: array<atomic<u32>>;  // hash_size
@group(0) @binding(6) var<storage, read_write> cell_start: array<u32>;          // hash_size + 1
// the block totals of a prefix sum (grid.wgsl's scan): x for the grid, xy for the pairs
@group(0) @binding(7) var<storage, read_write> block_sums: array<vec2<u32>>;
// the grid's bodies sorted by cell, then (the last large_count entries,
// written once when the world is made) the bodies kept out of the grid;
// from body_count on, the step's listed bodies (see `listed_body`)
@group(0) @binding(8) var<storage, read_write> sorted: array<u32>;              // 2 x body_count
// the grid bodies' bounds in sorted's order (CellBound)
@group(0) @binding(22) var<storage, read_write> cell_bounds: array<CellBoundWords>;  // body_count
// the pair pipeline (pairs.wgsl, narrowphase.wgsl): candidate pairs, each
// found once; the manifold pool, filled by need; each body's pair list,
// body i's at body_pairs[pair_meta[i].list_start ..][.. pair_meta[i].total],
// sorted by pair index
@group(0) @binding(10) var<storage, read_write> pairs: array<Pair>;             // pair capacity
@group(0) @binding(11) var<storage, read_write> manifolds: array<ManifoldWords>; // manifold capacity
// the manifolds' points, slot by slot, in up to four parts (`point_of`)
@group(0) @binding(17) var<storage, read_write> points: array<PointsWords>;
@group(0) @binding(18) var<storage, read_write> points_1: array<PointsWords>;
@group(0) @binding(19) var<storage, read_write> points_2: array<PointsWords>;
@group(0) @binding(20) var<storage, read_write> points_3: array<PointsWords>;
// what each manifold asks of its two bodies in a sweep (solve.wgsl,
// restitution.wgsl), two a slot, in up to two parts (`snap_of`)
@group(0) @binding(9) var<storage, read_write> snaps: array<SnapWords>;
@group(0) @binding(21) var<storage, read_write> snaps_1: array<SnapWords>;
@group(0) @binding(15) var<storage, read_write> pair_meta: array<PairMeta>;     // body_count + 1
@group(0) @binding(16) var<storage, read_write> body_pairs: array<u32>;         // 2 x pair capacity
// The status record (`Status` in src/gpu/status.rs, which says what each
// word holds): counters, maxima, the first fault and the indirect
// dispatches' sizes, indexed by the STATUS_* word constants written from it.
@group(0) @binding(12) var<storage, read_write> status: array<atomic<u32>>;

// The most trips an invocation's loops may take, summed (`Gpu::loop_trips`):
// lavapipe ends every loop of an invocation once their trips sum to 65535,
// silently (ARCHITECTURE.md, Adding a stage, 8). Unlimited elsewhere.
override LOOP_TRIPS: u32 = 0xffffffffu;
// ball joints: body i's ends are joint_refs[joint_start[i] .. joint_start[i + 1]]
@group(0) @binding(13) var<storage, read> joint_start: array<u32>;              // body_count + 1
@group(0) @binding(14) var<storage, read> joint_refs: array<JointRef>;          // 2 per joint

// The busiest buffers are bound as vec4 words, not as the structs they
// hold (the same bytes: tests/gpu/layouts.rs checks each pair), and read
// and written through the functions below. Lavapipe runs every load or
// store of a storage buffer as a loop over the lanes of a vector, one loop
// for a vec4 as for a single word; a struct is loaded member by member, so
// BodyState's six members took six loops where its four words take four.
// Measured on a 10k pile (sleeping off, 150 steps, medians of four runs in
// turns, same bits): the step's passes went from 41.5 to 38.2 ms, solve
// 6.0 -> 4.9, integrate 2.3 -> 2.0, narrowphase 4.4 -> 3.7, pairs_count
// 4.4 -> 4.0. A member that is not read is not loaded either way.

// ManifoldPoints as stored: point q in at[2q] (local_a, pushed) and
// at[2q + 1] (local_b, _pad0).
struct PointsWords {
    at: array<vec4<f32>, 8>,
}

// A ContactManifold as stored: the same bytes in two vec4s.
struct ManifoldWords {
    head: vec4<f32>, // normal, count (its bits)
    ends: vec4<u32>, // a, b, clip_face, pair
}

// Manifold slot k's header.
fn manifold_of(k: u32) -> ContactManifold {
    let w = manifolds[k];
    return ContactManifold(w.head.xyz, bitcast<u32>(w.head.w), w.ends.x, w.ends.y, w.ends.z, w.ends.w);
}

// Writes manifold slot k's header.
fn set_manifold(k: u32, m: ContactManifold) {
    manifolds[k] = ManifoldWords(vec4<f32>(m.normal, bitcast<f32>(m.count)), vec4<u32>(m.a, m.b, m.clip_face, m.pair));
}

// A CellBound as stored: the same bytes in two vec4s.
struct CellBoundWords {
    a: vec4<f32>, // pos, bound
    b: vec4<f32>, // extent, body (its bits)
}

// The bounds at place k of the grid's order.
fn cell_bound_of(k: u32) -> CellBound {
    let w = cell_bounds[k];
    return CellBound(w.a.xyz, w.a.w, w.b.xyz, bitcast<u32>(w.b.w));
}

// Writes the bounds at place k of the grid's order.
fn set_cell_bound(k: u32, c: CellBound) {
    cell_bounds[k] = CellBoundWords(vec4<f32>(c.pos, c.bound), vec4<f32>(c.extent, bitcast<f32>(c.body)));
}

// BodyProps as stored: the same bytes in four vec4s.
struct PropsWords {
    half_extents: vec4<f32>,
    inv_inertia: vec4<f32>,
    c: vec4<u32>,   // restitution, friction (their bits), shape, flags
    d: vec4<u32>,   // kept_inv_mass, speed_limit (their bits), grid_class, _pad1
}

// Body i's properties.
fn props_of(i: u32) -> BodyProps {
    let w = props[i];
    let f = bitcast<vec4<f32>>(vec4<u32>(w.c.xy, w.d.xy));
    return BodyProps(w.half_extents, w.inv_inertia, f.x, f.y, w.c.z, w.c.w, f.z, f.w, w.d.z, w.d.w);
}

// BodyState as stored: the same bytes in four vec4s.
struct StateWords {
    a: vec4<f32>, // pos, rest_time
    b: vec4<f32>, // disp, pos_low (its bits)
    rot: vec4<f32>,
    prev_rot: vec4<f32>,
}

// The BodyState the words hold.
fn state_from(w: StateWords) -> BodyState {
    return BodyState(w.a.xyz, w.a.w, w.b.xyz, bitcast<u32>(w.b.w), w.rot, w.prev_rot);
}

// Body i's state in state_in.
fn state_of(i: u32) -> BodyState {
    return state_from(state_in[i]);
}

// Body i's state in state_out (as a pass before wrote it).
fn out_state(i: u32) -> BodyState {
    return state_from(state_out[i]);
}

// Writes body i's state to state_out.
fn set_state(i: u32, s: BodyState) {
    state_out[i] = StateWords(vec4<f32>(s.pos, s.rest_time), vec4<f32>(s.disp, bitcast<f32>(s.pos_low)), s.rot, s.prev_rot);
}

// Sets body i's rest_time in state_out alone.
fn set_rest_time(i: u32, rest: f32) {
    state_out[i].a.w = rest;
}

// The body that invocation k of a body pass (integrate, solve,
// restitution) works on, or NONE: the k-th body contact_lists listed this
// step, in sorted[body_count ..] (status[STATUS_LISTED] of them; pairs_count fills the
// rest of the run with NONE, so no invocation reads the count: an atomic
// load is a loop over the lanes on lavapipe). World::run_stages without
// contact_lists lists every body itself. Every body is listed but a
// sleeper that the step leaves as it is (see `sleeps_held` in
// narrowphase.wgsl): its pose is then the same in both state buffers, as
// every pass would have copied it, and a resting pile with a few bodies
// awake pays these passes for the few. The list's order depends on thread
// timing, but each body's result depends on its own data alone.
fn listed_body(k: u32) -> u32 {
    return select(NONE, sorted[params.body_count + k], k < params.body_count);
}

// Lists body i for the body passes (contact_lists, see `listed_body`): at
// the next place of sorted's second half, counting one more workgroup of
// their indirect dispatch (status[STATUS_LISTED_DISPATCH]) with each place that starts one.
fn list_body(i: u32) {
    let k = atomicAdd(&status[STATUS_LISTED], 1u);
    sorted[params.body_count + k] = i;
    if (k % WORKGROUP == 0u) {
        atomicAdd(&status[STATUS_LISTED_DISPATCH], 1u);
    }
}

// The k-th body kept out of the grid (its index).
fn large_body(k: u32) -> u32 {
    return sorted[params.body_count - params.large_count + k];
}

// Workgroups in a row of an indirect dispatch over the pairs or the
// manifolds: the device's limit for one dimension (StepPipelines sets it).
// A pile of a million cubes has more than 65535 x WORKGROUP pairs, so those
// dispatches come in rows (y) of at most this many workgroups (x).
override DISPATCH_ROW: u32 = 65535u;

// Writes the indirect dispatch of `count` invocations into the three status
// words from `at` (a `*_DISPATCH` triple: x, then DISPATCH_Y, DISPATCH_Z):
// as few rows as hold them, of equal length.
fn write_dispatch(at: u32, count: u32) {
    let groups = (count + WORKGROUP - 1u) / WORKGROUP;
    let rows = max((groups + DISPATCH_ROW - 1u) / DISPATCH_ROW, 1u);
    atomicStore(&status[at], (groups + rows - 1u) / rows);
    atomicStore(&status[at + DISPATCH_Y], rows);
    atomicStore(&status[at + DISPATCH_Z], 1u);
}

// The invocation's place in a dispatch that write_dispatch sized.
fn dispatch_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * WORKGROUP;
}

// The manifolds this step's narrowphase stored (status[STATUS_MANIFOLDS], within the pool).
fn manifolds_used() -> u32 {
    return min(atomicLoad(&status[STATUS_MANIFOLDS]), arrayLength(&manifolds));
}

// The slot of the k-th stored manifold (k < used = manifolds_used()): the
// pool fills from both ends (see new_manifold in narrowphase.wgsl), the
// face contacts left for clipping at the top.
fn pool_slot(k: u32, used: u32) -> u32 {
    let top = min(atomicLoad(&status[STATUS_MANIFOLDS_TOP]), arrayLength(&manifolds));
    let bottom = used - top;
    return select(k, arrayLength(&manifolds) - top + (k - bottom), k >= bottom);
}

// Helpers that read the bindings (common.wgsl binds nothing).

// The manifold pool is larger than one storage binding may be in a big
// scene (lavapipe binds at most 128 MiB: 838 860 manifolds of 160 bytes, and
// a pile of a million cubes wants more than two million), so it is split:
// the headers (32 bytes) in `manifolds`, the points (128 bytes) in up to
// four parts, the snaps (64 bytes a slot) in up to two. Slot k's points lie
// in part k / P at k % P, P the first part's length (every part but the
// last is full; a part not needed holds one entry and is never read). The
// manifold passes run over consecutive slots, so the lanes of a vector
// take the same part but where one part ends. Until a pool first needs
// parts (every scene but the largest never does) the passes run with
// POOL_SPLIT off, which folds every access below to one load or store with
// no branch (the branches cost the contact passes a sixth of their time);
// World's make_pools compiles the passes that touch the parts again with
// it on then, and they stay so (right at any size).
override POOL_SPLIT: bool = false;

// Where slot k's points lie: (part, index in it).
fn point_slot(k: u32) -> vec2<u32> {
    if (!POOL_SPLIT) {
        return vec2<u32>(0u, k);
    }
    let per = arrayLength(&points);
    let part = u32(k >= per) + u32(k >= 2u * per) + u32(k >= 3u * per);
    return vec2<u32>(part, k - part * per);
}

// Point q of the manifold whose points lie at `at` (point_slot).
fn point_of(at: vec2<u32>, q: u32) -> ContactPoint {
    var w: array<vec4<f32>, 2>;
    switch (at.x) {
        case 0u: { w = array(points[at.y].at[2u * q], points[at.y].at[2u * q + 1u]); }
        case 1u: { w = array(points_1[at.y].at[2u * q], points_1[at.y].at[2u * q + 1u]); }
        case 2u: { w = array(points_2[at.y].at[2u * q], points_2[at.y].at[2u * q + 1u]); }
        default: { w = array(points_3[at.y].at[2u * q], points_3[at.y].at[2u * q + 1u]); }
    }
    return ContactPoint(w[0].xyz, w[0].w, w[1].xyz, w[1].w);
}

// Sets point q's friction budget (`pushed`) of the manifold at `at`.
fn set_pushed(at: vec2<u32>, q: u32, pushed: f32) {
    switch (at.x) {
        case 0u: { points[at.y].at[2u * q].w = pushed; }
        case 1u: { points_1[at.y].at[2u * q].w = pushed; }
        case 2u: { points_2[at.y].at[2u * q].w = pushed; }
        default: { points_3[at.y].at[2u * q].w = pushed; }
    }
}

// Stores slot k's points.
fn store_points(k: u32, p: ManifoldPoints) {
    let at = point_slot(k);
    var w: PointsWords;
    for (var q = 0u; q < MAX_POINTS; q = q + 1u) {
        w.at[2u * q] = vec4<f32>(p.at[q].local_a, p.at[q].pushed);
        w.at[2u * q + 1u] = vec4<f32>(p.at[q].local_b, p.at[q]._pad0);
    }
    switch (at.x) {
        case 0u: { points[at.y] = w; }
        case 1u: { points_1[at.y] = w; }
        case 2u: { points_2[at.y] = w; }
        default: { points_3[at.y] = w; }
    }
}

// An EndSnap as stored: the same bytes in two vec4s.
struct SnapWords {
    a: vec4<f32>, // dx, count (its bits)
    b: vec4<f32>, // dtheta, flags (its bits)
}

// The snap manifold `r >> 1` asks of the body that holds reference r: at
// r itself (a's at 2 x the slot, b's next), in the first part of the snaps
// or, past its end, the second.
fn snap_of(r: u32) -> EndSnap {
    let per = arrayLength(&snaps);
    var w: SnapWords;
    if (!POOL_SPLIT || r < per) {
        w = snaps[r];
    } else {
        w = snaps_1[r - per];
    }
    return EndSnap(w.a.xyz, bitcast<u32>(w.a.w), w.b.xyz, bitcast<u32>(w.b.w));
}

// Stores the snap at reference r (see snap_of).
fn set_snap(r: u32, s: EndSnap) {
    let per = arrayLength(&snaps);
    let w = SnapWords(vec4<f32>(s.dx, bitcast<f32>(s.count)), vec4<f32>(s.dtheta, bitcast<f32>(s.flags)));
    if (!POOL_SPLIT || r < per) {
        snaps[r] = w;
    } else {
        snaps_1[r - per] = w;
    }
}

// Sleeping (settings.sleeping; the paper has none). A body that has been
// slower than SLEEP_SPEED while touching something for params.sleep_after
// seconds sleeps: integrate holds it still, without gravity, the solve and
// restitution passes leave it as it is, and every awake body treats it as
// fixed. It wakes when an awake body touching it moves faster than
// WAKE_SPEED or lies more than WAKE_DEPTH inside it, and every body wakes
// after any user input or edit. BodyState
// rest_time counts the seconds at rest. Bodies on joints sleep and wake as
// their whole joint island (see solve_joints), held by the joints.
fn asleep(s: BodyState) -> bool {
    return params.sleep_after > 0.0 && s.rest_time >= params.sleep_after;
}

const SLEEP_SPEED: f32 = 0.05; // m/s
const WAKE_SPEED: f32 = 0.2;   // m/s
// An awake body this far inside a sleeper wakes it too (m): it is being
// squeezed against something that cannot give way.
const WAKE_DEPTH: f32 = 0.01;

// Whether an awake body touching a sleeper at points `gap` apart (m) wakes it.
fn wakes(j: u32, gap: f32) -> bool {
    let o = state_of(j);
    return !asleep(o) && (gap < -WAKE_DEPTH || point_speed(o, props_of(j)) > WAKE_SPEED);
}

// An upper bound of the speed of any point of a body over the last substep
// (m/s): the centre's speed plus the spin times the bounding radius.
fn point_speed(s: BodyState, p: BodyProps) -> f32 {
    let spin = length(quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))));
    return (length(s.disp) + spin * p.half_extents.w) / params.dt_prev;
}

// Friction against ends that stay. A body held by k such ends (the ground,
// fixed or sleeping bodies, pair_meta's `held`) had each of them undo its
// whole slide, and solve relaxes their sum by c_r: c_r k times the slide,
// which for k > 2 at c_r = 0.5 overshoots, and a body wedged between
// sleepers (seven manifolds) then jittered at 7 cm/s for good, awake. Each
// such contact now counts the body's inverse mass max(1, c_r k) times (mass
// splitting), so together they undo the slide once. 1000 cubes piled (seeds
// 7 to 14), farthest move of any cube in the second after 15 s: 0.1 to 2.2
// cm before, at most 0.2 cm after (every cube asleep in three of them).
// Dynamic friction (restitution.wgsl) splits what stops the sliding the
// same way, by max(1, k) as nothing relaxes its sum (each contact's own
// Coulomb budget stays whole): there each such contact cut all the sliding
// left, k times over, and a cube wedged between sleepers shook sideways
// every other step at 0.13 m/s. Normal pushes split so too (solve.wgsl's
// stay_splits).
fn friction_split(i: u32, relaxation: f32) -> f32 {
    if (i == GROUND) {
        return 1.0;
    }
    return max(1.0, relaxation * f32(pair_meta[i].held));
}

// Whether body i has a joint: its contacts then neither split their normal
// pushes against ends that stay (contact_lists) nor settle or cap their
// support (solve), as its joints pull it back against weakened pushes.
fn is_jointed(i: u32) -> bool {
    return joint_start[i + 1u] > joint_start[i];
}

// Whether the contacts may move body i: awake and not fixed (ContactEnd's
// `moves`).
fn contact_end_moves(i: u32) -> bool {
    return moves_by_contacts(state_of(i), props_of(i));
}

// The same, from the body's state and properties already read.
fn moves_by_contacts(s: BodyState, p: BodyProps) -> bool {
    return !is_fixed(p) && !asleep(s);
}

fn contact_end(i: u32) -> ContactEnd {
    if (i == GROUND) {
        let still = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        let identity = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
        return ContactEnd(vec3<f32>(0.0), vec3<f32>(0.0), still, still, vec4<f32>(0.0), identity, mat3x3<f32>(), mat3x3<f32>(), false,
                          params.ground_restitution, params.ground_friction, 0.0);
    }
    let s = state_of(i);
    let p = props_of(i);
    let r = quat_to_mat(s.rot);
    // a sphere's radius, read only for a sphere: where no lane holds one
    // (a pile of boxes), lavapipe skips the load
    var radius = 0.0;
    if (p.shape == SHAPE_SPHERE) {
        radius = props_of(i).half_extents.x;
    }
    return ContactEnd(s.pos, s.disp, s.rot, s.prev_rot, p.inv_inertia, r, r - quat_to_mat(s.prev_rot),
                      world_inv_inertia(r, p.inv_inertia.xyz), moves_by_contacts(s, p),
                      p.restitution, p.friction, radius);
}
