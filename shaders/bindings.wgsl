// The step's bindings and the helpers that read them (common.wgsl binds
// nothing). Each pass binds those its entry point uses (src/step/mod.rs), in
// two bind groups, A->B and B->A, which differ only in which state buffer is
// state_in and which state_out.
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
// the grid's bodies sorted by cell, then the large bodies (written when the
// world is made); then the step's lists of bodies, a run of body_count each
// (`body_in_run`)
@group(0) @binding(8) var<storage, read_write> sorted: array<u32>;              // 3 x body_count
// the grid bodies' bounds in sorted's order (CellBound)
@group(0) @binding(22) var<storage, read_write> cell_bounds: array<CellBoundWords>;  // body_count
// the pair pipeline (pairs.wgsl, narrowphase.wgsl): candidate pairs, the
// manifold pool, and each body's contact list in body_pairs (from list_start)
@group(0) @binding(10) var<storage, read_write> pairs: array<Pair>;             // pair capacity
@group(0) @binding(11) var<storage, read_write> manifolds: array<ManifoldWords>; // manifold capacity
// the manifolds' points, slot by slot, in up to four parts (`point_of`)
@group(0) @binding(17) var<storage, read_write> points: array<PointsWords>;
@group(0) @binding(18) var<storage, read_write> points_1: array<PointsWords>;
@group(0) @binding(19) var<storage, read_write> points_2: array<PointsWords>;
@group(0) @binding(20) var<storage, read_write> points_3: array<PointsWords>;
// what each manifold asks of its two bodies in a sweep, in up to two parts (`snap_of`)
@group(0) @binding(9) var<storage, read_write> snaps: array<SnapWords>;
@group(0) @binding(21) var<storage, read_write> snaps_1: array<SnapWords>;
@group(0) @binding(15) var<storage, read_write> pair_meta: array<PairMeta>;     // body_count + 1
@group(0) @binding(16) var<storage, read_write> body_pairs: array<u32>;         // 2 x pair capacity
// The status record (`Status` in src/gpu/status.rs, which says what each
// word holds): counters, maxima, the first fault and the indirect
// dispatches' sizes, indexed by the STATUS_* word constants written from it.
@group(0) @binding(12) var<storage, read_write> status: array<atomic<u32>>;

// The most trips an invocation's loops may take, summed (`Gpu::loop_trips`):
// lavapipe silently ends them at 65535 (ARCHITECTURE.md, Adding a stage, 8).
override LOOP_TRIPS: u32 = 0xffffffffu;
// ball joints: body i's ends are joint_refs[joint_start[i] .. joint_start[i + 1]]
@group(0) @binding(13) var<storage, read> joint_start: array<u32>;              // body_count + 1
@group(0) @binding(14) var<storage, read> joint_refs: array<JointRef>;          // 2 per joint
// each joint island's least rest time (its bits) and whether it is held, two
// words an island, gathered by joint_rest_gather with integer atomics
@group(0) @binding(23) var<storage, read_write> island_rest: array<atomic<u32>>; // 2 x island count
// the hull records (src/world/hull_records.rs): a run of words per hull
// shape, the first the cube of half extent 1 that a box is scaled from
@group(0) @binding(24) var<storage, read> hulls: array<vec4<f32>>;
// solve_paths' elimination along its paths, PATH_SLOT words a joint of the paths (solve_path in solve.wgsl)
@group(0) @binding(25) var<storage, read_write> path_scratch: array<vec4<f32>>;

// The busiest buffers are bound as vec4 words (the same bytes as their
// structs; tests/gpu/layouts.rs checks each pair) and read and written
// through the functions below: lavapipe loads a struct member by member, one
// loop over the lanes each, and a vec4 in one loop (docs/lavapipe.md).

// ManifoldPoints as stored: point q in at[2q] (local_a, pushed), at[2q + 1] (local_b, last_push).
struct PointsWords {
    at: array<vec4<f32>, 8>,
}

// A ContactManifold as stored: the same bytes in two vec4s.
struct ManifoldWords {
    head: vec4<f32>, // normal, count (its bits)
    ends: vec4<u32>, // a, b, clip_face, pair
}

fn manifold_of(k: u32) -> ContactManifold {
    let w = manifolds[k];
    return ContactManifold(w.head.xyz, bitcast<u32>(w.head.w), w.ends.x, w.ends.y, w.ends.z, w.ends.w);
}

fn set_manifold(k: u32, m: ContactManifold) {
    manifolds[k] = ManifoldWords(vec4<f32>(m.normal, bitcast<f32>(m.count)), vec4<u32>(m.a, m.b, m.clip_face, m.pair));
}

// A CellBound as stored: the same bytes in two vec4s.
struct CellBoundWords {
    a: vec4<f32>, // pos, bound
    b: vec4<f32>, // extent, body (its bits)
}

fn cell_bound_of(k: u32) -> CellBound {
    let w = cell_bounds[k];
    return CellBound(w.a.xyz, w.a.w, w.b.xyz, bitcast<u32>(w.b.w));
}

fn set_cell_bound(k: u32, c: CellBound) {
    cell_bounds[k] = CellBoundWords(vec4<f32>(c.pos, c.bound), vec4<f32>(c.extent, bitcast<f32>(c.body)));
}

// BodyProps as stored: the same bytes in four vec4s.
struct PropsWords {
    half_extents: vec4<f32>,
    inv_inertia: vec4<f32>,
    c: vec4<u32>,   // restitution, friction (their bits), shape, flags
    d: vec4<u32>,   // kept_inv_mass, speed_limit (their bits), grid_class, hull
}

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

fn state_from(w: StateWords) -> BodyState {
    return BodyState(w.a.xyz, w.a.w, w.b.xyz, bitcast<u32>(w.b.w), w.rot, w.prev_rot);
}

fn state_of(i: u32) -> BodyState {
    return state_from(state_in[i]);
}

// Body i's state in state_out (as a pass before wrote it).
fn out_state(i: u32) -> BodyState {
    return state_from(state_out[i]);
}

fn set_state(i: u32, s: BodyState) {
    state_out[i] = StateWords(vec4<f32>(s.pos, s.rest_time), vec4<f32>(s.disp, bitcast<f32>(s.pos_low)), s.rot, s.prev_rot);
}

// Body i's pose in state_out without its previous rotation (left at none),
// for a pass that moves the pose in place and turns the previous rotation
// only now and then (solve: where it settles): the words it does not need
// are neither loaded nor stored (`set_pose`).
fn out_pose(i: u32) -> BodyState {
    let a = state_out[i].a;
    let b = state_out[i].b;
    return BodyState(a.xyz, a.w, b.xyz, bitcast<u32>(b.w), state_out[i].rot, vec4<f32>(0.0, 0.0, 0.0, 1.0));
}

// Stores body i's pose but its previous rotation (see out_pose).
fn set_pose(i: u32, s: BodyState) {
    state_out[i].a = vec4<f32>(s.pos, s.rest_time);
    state_out[i].b = vec4<f32>(s.disp, bitcast<f32>(s.pos_low));
    state_out[i].rot = s.rot;
}

fn set_rest_time(i: u32, rest: f32) {
    state_out[i].a.w = rest;
}

// The step's lists of bodies, written by contact_lists into runs of `sorted`
// after the grid's order: run 1, the bodies the body passes (integrate,
// restitution) work on, every body but a sleeper the step leaves as it is
// (`sleeps_held`), whose pose is the same in both state buffers, so a resting
// pile pays these passes for its few awake bodies; run 2, those of them with
// contacts, which `solve` works on (a body with no contacts has nothing to
// sum). pairs_count fills both runs with NONE, so no invocation loads a
// count. The order depends on thread timing; no result does.
const LISTED_RUN: u32 = 1u;
const TOUCHING_RUN: u32 = 2u;

// The k-th body of list `run`, or NONE.
fn body_in_run(run: u32, k: u32) -> u32 {
    return select(NONE, sorted[run * params.body_count + k], k < params.body_count);
}

fn listed_body(k: u32) -> u32 {
    // where no body can sleep, every body is listed (contact_lists): by index
    if (!SLEEPING) {
        return select(NONE, k, k < params.body_count);
    }
    return body_in_run(LISTED_RUN, k);
}

fn touching_body(k: u32) -> u32 {
    return body_in_run(TOUCHING_RUN, k);
}

// Lists body i at the next place of list `run`, counted in status[count],
// with one more workgroup of its indirect dispatch (status[dispatch]) for
// each place that starts one.
fn list_in_run(run: u32, count: u32, dispatch: u32, i: u32) {
    let k = atomicAdd(&status[count], 1u);
    sorted[run * params.body_count + k] = i;
    if (k % WORKGROUP == 0u) {
        atomicAdd(&status[dispatch], 1u);
    }
}

// The k-th body kept out of the grid (its index).
fn large_body(k: u32) -> u32 {
    return sorted[params.body_count - params.large_count + k];
}

// Workgroups in a row of an indirect dispatch over the pairs or manifolds: the
// device's limit for one dimension (StepPipelines sets it); a million cubes'
// pairs need several rows (y) of at most this many workgroups (x).
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

// Whether this step keeps the last pair list, empty, and skips the grid and
// the pair walks: the last walks found no pair within keep_margin() more than
// they list (contact_lists carries that into status[STATUS_WALK]), and no
// body's grown box has left what they saw by half that (grid_count), so walks
// now would find none either. A hanging grid at rest keeps it for good; a
// body that moves walks again. The word stays put from grid_count to
// contact_lists.
fn pairs_kept() -> bool {
    return atomicLoad(&status[STATUS_WALK]) == 0u;
}

// Sizes the passes that run only where a step walks (the grid's scans,
// scatter and sort, the pair scan and writes, and the ground's narrowphase,
// which a kept list, empty, gives no pair), in the order of `Over::walk`:
// over the buckets, the grid scan's blocks, the bodies, the pair scan's
// blocks, one workgroup, the bodies again (pairs_count, contact_lists); or
// to nothing, so that a step that keeps its list pays no invocation for
// them, but one workgroup for pairs_count and contact_lists, whose first
// invocations' parts run every step.
fn size_walk_passes(walks: bool) {
    let buckets = (params.hash_size + WORKGROUP - 1u) / WORKGROUP;
    let scan_blocks = (params.hash_size + SCAN_SPAN - 1u) / SCAN_SPAN;
    let bodies = (params.body_count + WORKGROUP - 1u) / WORKGROUP;
    let body_scan_blocks = (params.body_count + SCAN_SPAN - 1u) / SCAN_SPAN;
    let sizes = array<u32, 6>(buckets, scan_blocks, bodies, body_scan_blocks, 1u, bodies);
    let keeping = array<u32, 6>(0u, 0u, 0u, 0u, 0u, 1u);
    for (var k = 0u; k < 6u; k = k + 1u) {
        atomicStore(&status[STATUS_WALK_DISPATCHES + 3u * k], select(keeping[k], max(sizes[k], 1u), walks));
    }
}

// The margin (m) beyond CONTACT_MARGIN within which the walks note a pair as
// near: within 0.001 of a cell, which a walk's neighbouring cells still cover
// (`fast_size` in grid.wgsl leaves that slack).
fn keep_margin() -> f32 {
    return 0.0009 * params.cell_size;
}

// The manifolds this step's narrowphase stored (status[STATUS_MANIFOLDS], within the pool).
fn manifolds_used() -> u32 {
    return min(atomicLoad(&status[STATUS_MANIFOLDS]), arrayLength(&manifolds));
}

// The slot of the k-th stored manifold (k < used): the pool fills from both
// ends (new_manifold in narrowphase.wgsl), the face contacts to clip at the top.
fn pool_slot(k: u32, used: u32) -> u32 {
    let top = min(atomicLoad(&status[STATUS_MANIFOLDS_TOP]), arrayLength(&manifolds));
    let bottom = used - top;
    return select(k, arrayLength(&manifolds) - top + (k - bottom), k >= bottom);
}

// The manifold pool may be larger than one storage binding (lavapipe binds at
// most 128 MiB), so it is split: headers in `manifolds`, points in up to four
// parts, snaps in up to two; slot k's points lie in part k / P at k % P, P the
// first part's length. Until a pool first needs parts the passes run with
// POOL_SPLIT off, which folds every access below to one load or store (the
// branches cost the contact passes a sixth); make_pools then recompiles them.
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

// Sets the fourth word of the manifold's (at `at`) points' vec4 `word`
// (PointsWords): a point's `pushed` or `last_push`.
fn set_points_w(at: vec2<u32>, word: u32, value: f32) {
    switch (at.x) {
        case 0u: { points[at.y].at[word].w = value; }
        case 1u: { points_1[at.y].at[word].w = value; }
        case 2u: { points_2[at.y].at[word].w = value; }
        default: { points_3[at.y].at[word].w = value; }
    }
}

// Sets point q's friction budget (`pushed`) of the manifold at `at`.
fn set_pushed(at: vec2<u32>, q: u32, pushed: f32) {
    set_points_w(at, 2u * q, pushed);
}

// Sets point q's push in the sweep just run (`last_push`) of the manifold at `at`.
fn set_last_push(at: vec2<u32>, q: u32, push: f32) {
    set_points_w(at, 2u * q + 1u, push);
}

fn store_points(k: u32, p: ManifoldPoints) {
    let at = point_slot(k);
    var w: PointsWords;
    for (var q = 0u; q < MAX_POINTS; q = q + 1u) {
        w.at[2u * q] = vec4<f32>(p.at[q].local_a, p.at[q].pushed);
        w.at[2u * q + 1u] = vec4<f32>(p.at[q].local_b, p.at[q].last_push);
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

// The snap manifold `r >> 1` asks of the body that holds reference r (a's at 2 x
// the slot, b's next), in the first part of the snaps or, past its end, the second.
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

fn set_snap(r: u32, s: EndSnap) {
    let per = arrayLength(&snaps);
    let w = SnapWords(vec4<f32>(s.dx, bitcast<f32>(s.count)), vec4<f32>(s.dtheta, bitcast<f32>(s.flags)));
    if (!POOL_SPLIT || r < per) {
        snaps[r] = w;
    } else {
        snaps_1[r - per] = w;
    }
}

// Sleeping (settings.sleeping; the paper has none): a body slower than
// SLEEP_SPEED while touching something for params.sleep_after seconds sleeps:
// held still and treated as fixed by awake bodies (a joint island as one). It
// wakes when a body touching it moves faster than WAKE_SPEED or lies
// WAKE_DEPTH inside it, and on any input or edit.
fn asleep(s: BodyState) -> bool {
    return SLEEPING && params.sleep_after > 0.0 && s.rest_time >= params.sleep_after;
}

const SLEEP_SPEED: f32 = 0.05; // m/s
const WAKE_SPEED: f32 = 0.2;   // m/s
// An awake body this far inside a sleeper wakes it (m): it squeezes it against something.
const WAKE_DEPTH: f32 = 0.01;

// Whether an awake body touching a sleeper at points `gap` apart (m) wakes it.
fn wakes(j: u32, gap: f32) -> bool {
    let o = state_of(j);
    return !asleep(o) && (gap < -WAKE_DEPTH || point_speed(o, props_of(j)) > WAKE_SPEED);
}

// An upper bound of any point's speed over the last substep (m/s): centre plus spin x radius.
fn point_speed(s: BodyState, p: BodyProps) -> f32 {
    let spin = length(quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))));
    return (length(s.disp) + spin * p.half_extents.w) / params.dt_prev;
}

// Friction against ends that stay (the ground, fixed or sleeping bodies): a
// body held by k of them (pair_meta's `held`) has each undo its whole slide,
// which solve's relaxation sums to c_r k slides, an overshoot; so each counts
// the body's inverse mass max(1, c_r k) times (mass splitting). Dynamic
// friction splits by max(1, k); normal pushes: solve.wgsl's stay_splits.
fn friction_split(i: u32, relaxation: f32) -> f32 {
    if (i == GROUND) {
        return 1.0;
    }
    return max(1.0, relaxation * f32(pair_meta[i].held));
}

// Whether body i has a joint: its contacts then neither split their normal pushes
// against ends that stay nor settle or cap their support (docs/decisions/joints.md).
fn is_jointed(i: u32) -> bool {
    return HAS_JOINTS && joint_start[i + 1u] > joint_start[i];
}

// Whether the contacts may move body i: awake and not fixed (ContactEnd's `moves`).
fn contact_end_moves(i: u32) -> bool {
    return moves_by_contacts(state_of(i), props_of(i));
}

fn moves_by_contacts(s: BodyState, p: BodyProps) -> bool {
    return !is_fixed(p) && !is_kinematic(p) && !asleep(s);
}

fn contact_end(i: u32) -> ContactEnd {
    if (i == GROUND) {
        let still = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        let identity = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
        return ContactEnd(vec3<f32>(0.0), vec3<f32>(0.0), still, still, vec4<f32>(0.0), identity, mat3x3<f32>(), mat3x3<f32>(), false, false,
                          params.ground_restitution, params.ground_friction, 0.0, 0.0);
    }
    let s = state_of(i);
    let p = props_of(i);
    let r = quat_to_mat(s.rot);
    // a sphere's or capsule's radius, read only for those: lavapipe skips the
    // load where no lane has one
    var radius = 0.0;
    var half_height = 0.0;
    if (HAS_ROUND && p.shape == SHAPE_SPHERE) {
        radius = props_of(i).half_extents.x;
    } else if (HAS_ROUND && p.shape == SHAPE_CAPSULE) {
        let h = props_of(i).half_extents;
        radius = h.x;
        half_height = h.y;
    }
    return ContactEnd(s.pos, s.disp, s.rot, s.prev_rot, p.inv_inertia, r, r - quat_to_mat(s.prev_rot),
                      world_inv_inertia(r, p.inv_inertia.xyz), moves_by_contacts(s, p), is_fixed(p) || is_kinematic(p),
                      p.restitution, p.friction, radius, half_height);
}

// A convex polytope as the hull records hold it, in its body's frame: a
// hull's run, or the unit cube's (the first run) scaled by a box's half
// extents. Its words: counts, corners, planes, face runs, indices, edges.
struct Poly {
    first: u32,
    scale: vec3<f32>,
    corners: u32,
    faces: u32,
    edges: u32,
    index_words: u32,
}

fn poly_of(p: BodyProps) -> Poly {
    let hull = p.shape == SHAPE_HULL;
    let first = select(0u, p.hull, hull);
    let counts = bitcast<vec4<u32>>(hulls[first]);
    return Poly(first, select(p.half_extents.xyz, vec3<f32>(1.0), hull), counts.x, counts.y, counts.z, (counts.w + 3u) / 4u);
}

fn poly_corner(h: Poly, k: u32) -> vec3<f32> {
    return hulls[h.first + 1u + k].xyz * h.scale;
}

// Face f's plane: outward unit normal (xyz) and offset (w). Scaled, n / s
// is the normal and the offset divides by its length.
fn poly_plane(h: Poly, f: u32) -> vec4<f32> {
    let w = hulls[h.first + 1u + h.corners + f];
    let n = w.xyz / h.scale;
    let inv = 1.0 / length(n);
    return vec4<f32>(n * inv, w.w * inv);
}

// Face f's outward unit normal: a hull's as stored, a box's the cube's
// (its axes, which scaling leaves as they are).
fn poly_normal(h: Poly, f: u32) -> vec3<f32> {
    return hulls[h.first + 1u + h.corners + f].xyz;
}

// Face f's corner indices: the first's place among the indices, and the count.
fn poly_face_run(h: Poly, f: u32) -> vec2<u32> {
    return bitcast<vec2<u32>>(hulls[h.first + 1u + h.corners + h.faces + f].xy);
}

// The corner index at place k of the faces' runs.
fn poly_index(h: Poly, k: u32) -> u32 {
    let w = bitcast<vec4<u32>>(hulls[h.first + 1u + h.corners + 2u * h.faces + k / 4u]);
    let j = k % 4u;
    return select(select(select(w.w, w.z, j == 2u), w.y, j == 1u), w.x, j == 0u);
}

// The sphere about the corners' box: centre (xyz), radius (w).
fn poly_sphere(h: Poly) -> vec4<f32> {
    return hulls[h.first + 1u + h.corners + 2u * h.faces + h.index_words + h.edges];
}

// Edge e: its two corners and the faces on either side.
fn poly_edge(h: Poly, e: u32) -> vec4<u32> {
    return bitcast<vec4<u32>>(hulls[h.first + 1u + h.corners + 2u * h.faces + h.index_words + e]);
}

// world_extent, for every shape: a hull's from its corners, about the
// centre `bound_sphere` gives.
fn body_extent(s: BodyState, p: BodyProps) -> vec3<f32> {
    if (!HAS_HULLS || p.shape != SHAPE_HULL) {
        return world_extent(s, p);
    }
    let h = poly_of(p);
    let r = quat_to_mat(s.rot);
    let c = bound_sphere(p).xyz;
    var extent = vec3<f32>(0.0);
    for (var k = 0u; k < h.corners; k = k + 1u) {
        extent = max(extent, abs(r * (poly_corner(h, k) - c)));
    }
    return extent;
}

// The sphere a body's broadphase bounds (pair_meta's extent and bound) are
// centred on, in its frame (xyz) and its radius (w): about its origin, but
// for a hull kept out of the grid about its corners' box (a drum panel's
// frame is the drum's axis; bounds about it held every body in the drum).
fn bound_sphere(p: BodyProps) -> vec4<f32> {
    if (HAS_HULLS && p.shape == SHAPE_HULL && p.grid_class == LARGE_BODY) {
        return poly_sphere(poly_of(p));
    }
    return vec4<f32>(0.0, 0.0, 0.0, p.half_extents.w);
}

// The world centre of a body kept out of the grid's bounds (bound_sphere).
fn large_centre(j: u32) -> vec3<f32> {
    let s = state_of(j);
    return s.pos + quat_rotate(s.rot, bound_sphere(props_of(j)).xyz);
}

// reach_along, for every shape: a hull's farthest corner along dir.
fn body_reach(p: BodyProps, rot: vec4<f32>, dir: vec3<f32>) -> f32 {
    if (!HAS_HULLS || p.shape != SHAPE_HULL) {
        return reach_along(p, rot, dir);
    }
    let h = poly_of(p);
    let local = quat_rotate(quat_conj(rot), dir);
    var reach = -3.4e38;
    for (var k = 0u; k < h.corners; k = k + 1u) {
        reach = max(reach, dot(local, poly_corner(h, k)));
    }
    return reach;
}
