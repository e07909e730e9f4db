// Types and maths that bind nothing, shared by every compute pass and the
// renderer: the body layout, the per-step parameters, the contact records and
// the quaternion helpers. Every struct has a #[repr(C)] twin in
// src/gpu/types.rs (tests/gpu/layouts.rs checks them). The constants shared
// with Rust (NONE, GROUND, WORKGROUP, the fault codes and limits, ...) are
// written before this file from the Rust values (src/gpu/shaders.rs).

// What the world holds or does that some code is for (src/step/pipelines.rs's
// `Contents`): spheres or capsules, hulls, joints, sleeping. A pass is
// compiled without the code for what its world lacks: lavapipe runs every
// instruction of a kernel whether or not any invocation takes its branch
// (docs/lavapipe.md). Unset (the renderer, the tests' validation): all.
override HAS_ROUND: bool = true;
override HAS_HULLS: bool = true;
override HAS_JOINTS: bool = true;
override SLEEPING: bool = true;

// Pose of one body: what swaps between the two state buffers every pass. 64
// bytes; quaternions are (x, y, z, w). The displacement x_n - x_(n-1) is kept
// instead of the previous position, so the velocity disp / h is not the
// difference of two large f32 numbers, and `pos_low` keeps what rounding
// dropped from pos (docs/decisions/integration.md).
struct BodyState {
    pos: vec3<f32>,      // centre of mass (m)
    rest_time: f32,      // seconds at rest (see `asleep`)
    disp: vec3<f32>,     // x_n - x_(n-1): how far the centre moved over the last substep (m)
    pos_low: u32,        // bits 0-29: pos's rounding remainder (`pos_remainder`); bit 30: WAKES; bit 31: HELD
    rot: vec4<f32>,      // orientation, unit quaternion
    prev_rot: vec4<f32>, // orientation one step ago
}


// One step of pos_remainder's grid for a coordinate x (m): 1/512 of x's f32
// spacing, floored at 2^-92 m so that it never underflows.
fn remainder_unit(x: vec3<f32>) -> vec3<f32> {
    let exponent = max(bitcast<vec3<u32>>(x) & vec3<u32>(0x7f800000u), vec3<u32>(0x21800000u));
    return bitcast<vec3<f32>>(exponent) * 2.3283064e-10; // 2^-32 = 2^-23 / 512
}

// What rounding dropped from pos.xyz (m): the true centre is pos + this. Each
// coordinate a signed 10-bit multiple of remainder_unit (bits 0-9 x, 10-19 y, 20-29 z).
fn pos_remainder(s: BodyState) -> vec3<f32> {
    let q = (vec3<u32>(s.pos_low) >> vec3<u32>(0u, 10u, 20u)) & vec3<u32>(0x3ffu);
    return (vec3<f32>(q) - 512.0) * remainder_unit(s.pos);
}

// pos_low for a remainder r (m) of the position x, with `flags`' HELD and WAKES bits.
fn pack_remainder(r: vec3<f32>, x: vec3<f32>, flags: u32) -> u32 {
    let q = vec3<u32>(vec3<i32>(clamp(round(r / remainder_unit(x)), vec3<f32>(-511.0), vec3<f32>(511.0))) + 512);
    return q.x | (q.y << 10u) | (q.z << 20u) | (flags & (HELD | WAKES));
}

// What rarely changes: shape, mass and material. 64 bytes. What a contact
// reads of a body (`contact_end`) lies in two of its four words: inverse
// inertia and mass, then material, shape and flags.
struct BodyProps {
    half_extents: vec4<f32>, // box: xyz half extents; sphere: radius in x; w = bounding radius
    inv_inertia: vec4<f32>,  // xyz = body-frame principal inverse inertia (1/(kg m^2)); w = inverse mass (1/kg)
    restitution: f32,
    friction: f32,
    shape: u32,              // SHAPE_*
    flags: u32,              // FLAG_* bits
    kept_inv_mass: f32,      // a body an input made fixed: the inverse mass to restore (1/kg); else 0
    speed_limit: f32,        // the fastest the scene's energy can move it (m/s; see fault_of); 0: none
    grid_class: u32,         // GRID_BODY, or LARGE_BODY: kept out of the grid (see grid.wgsl)
    hull: u32,               // a hull's first word in `hulls` (bindings.wgsl)
}

// Velocities just after integration: the approach velocities restitution reflects. 32 bytes.
struct Velocity {
    linear: vec4<f32>,  // m/s
    angular: vec4<f32>, // rad/s, world frame
}

// Per-step parameters, one 256-byte slot per step of a submitted batch.
struct Params {
    gravity: vec3<f32>,      // m/s^2
    ground_height: f32,      // m
    dt: f32,                 // this step (s)
    dt_prev: f32,            // the step that produced disp (s)
    relaxation: f32,         // the paper's c_r
    linear_damping: f32,     // the paper's beta, per step
    angular_damping: f32,    // beta for rotation, per step
    body_count: u32,
    has_ground: u32,         // 1 if the ground plane exists
    ground_restitution: f32, // the ground's material (settings.restitution)
    ground_friction: f32,    // the ground's material (settings.friction)
    cell_size: f32,          // edge of a broadphase grid cell (m)
    hash_size: u32,          // buckets of the grid's hash table (a power of two)
    large_count: u32,        // bodies too large for the grid (see large_body())
    speed_limits: u32,       // 1: BodyProps' speed_limit holds (no input or edit since the scene began)
    substeps: u32,           // substeps per step: contacts found once serve them all
    step_index: u32,         // the world's step count as this step began (saturates at NO_FAULT - 1)
    sleep_after: f32,        // seconds at rest before a body sleeps; 0: never (settings.sleeping)
    substep: u32,            // which substep of the step this is (0 first)
    opaque_zero: u32,        // always 0; see `opaque` (integrate.wgsl)
    island_count: u32,       // joint islands (joint_rest)
    path_first: u32,         // the paths of this solve_joints or solve_paths pass's colour:
    path_end: u32,           //   path_first..path_end (joint_lists)
    path_count: u32,         // the paths of every colour
    second: u32,             // 1 in a substep's second solve_paths of each colour
    _pad2: u32,
}

// A candidate pair (pairs.wgsl): body a owns it; b is a body or GROUND. 8 bytes.
struct Pair {
    a: u32,
    b: u32,
}

// One contact point: the point on each body in its own frame (the ground's in world
// coordinates), its friction budget: the normal push summed this substep (m), and
// its normal push in the substep's last sweep (m; solve_contacts). 32 bytes.
struct ContactPoint {
    local_a: vec3<f32>,
    pushed: f32,
    local_b: vec3<f32>,
    last_push: f32,
}

// A pair's contact manifold, found once a step: up to MAX_POINTS points sharing one
// normal, from a to b. Its 32-byte header; the points lie in the pool's parts (`point_of`).
struct ContactManifold {
    normal: vec3<f32>,
    count: u32,
    a: u32,
    b: u32,
    clip_face: u32, // NONE, or the reference face narrowphase_clip still has to clip
    pair: u32,      // the candidate pair (index in `pairs`) it was found for
}

// A manifold's points (the first `count`; 128 bytes).
struct ManifoldPoints {
    at: array<ContactPoint, 4>,
}

// What one manifold asks of one of its bodies in a sweep, summed over its
// points: a move (m; m/s in restitution) and a turn (rad; rad/s), world axes;
// `count`: 1 if it snapped the body (solve, with SNAP_FIXED_PARTNER) or the
// points that acted (restitution); `flags`: SNAP_PRESSED, the settling share
// above SETTLE_SHIFT and the support share above SUPPORT_SHIFT (solve.wgsl).
// A manifold's two, a's then b's, sit at 2 x its slot (`snap_of`). 32 bytes.
struct EndSnap {
    dx: vec3<f32>,
    count: u32,
    dtheta: vec3<f32>,
    flags: u32,
}

const SNAP_PRESSED: u32 = 1u;
// In an EndSnap's count (solve): the manifold's other end is a fixed body.
const SNAP_FIXED_PARTNER: u32 = 0x80000000u;
const SETTLE_SHIFT: u32 = 16u;
const SETTLE_ONE: f32 = 65535.0;
const SUPPORT_SHIFT: u32 = 1u;
const SUPPORT_MASK: u32 = 0x7fffu;
const SUPPORT_ONE: f32 = 32767.0;

// Per-body pair bookkeeping, rebuilt every step (grid_count, pairs.wgsl,
// contact_lists): the pairs it owns and is in and their prefix sums, the
// cursor its incoming pairs are counted and listed by, WOKEN_NOW, MOVES /
// SLEEPS / STAYS_FIXED, its manifolds, its bounds grown by its reach (`spin`:
// the turn's part), and the splits against ends that stay (`held`,
// `normal_split`). The entry after the last body holds the totals. 64 bytes.
struct PairMeta {
    owned: u32,
    total: u32,
    owned_start: u32,
    list_start: u32,
    cursor: atomic<u32>,
    woken: atomic<u32>,
    moves: u32,
    contacts: u32,
    extent: vec3<f32>,
    bound: f32,
    held: u32,
    normal_split: f32,
    reach: f32,
    spin: f32,
}

// A grid body's bounds in the grid's order, as the pair walks read them
// (grid_sort): centre, bound, extent, and its index with pair_meta's moves in
// the top bits; one 32-byte record a candidate, a cell's side by side.
struct CellBound {
    pos: vec3<f32>,
    bound: f32,
    extent: vec3<f32>,
    body: u32,
}

// pair_meta[i].moves: contacts can move the body this step (awake, or woken by
// the last step's narrowphase); it sleeps (the movers find its pairs); it is fixed.
const MOVES: u32 = 1u;
const SLEEPS: u32 = 2u;
const STAYS_FIXED: u32 = 0u;

// pair_meta[i].woken's WOKEN_NOW (shared with Rust): set by the narrowphase
// when an awake partner wakes a sleeper; integrate moves it to the pose's
// WAKES bit (pos_low bit 30), which wakes the body a step later.

// A body's reference to one of its manifolds: the manifold's index and which end it is.
fn contact_ref(manifold: u32, is_b: bool) -> u32 {
    return 2u * manifold + u32(is_b);
}

// MAX_DEPENETRATION_SPEED (shared with Rust): the fastest (m/s) the solve
// pushes apart bodies that already overlapped at their previous poses.

// CONTACT_SLOP (shared with Rust): points closer than this (m) still touch
// when restitution is decided after the solve.
// One end of a ball joint as the body at that end sees it: both anchors, each in its
// body's frame (the world's in world coordinates). 32 bytes.
struct JointRef {
    local_self: vec3<f32>,
    partner: u32,
    local_partner: vec3<f32>,
    body: u32,               // the body at this end
}

// Half extents of a body's world box: |R| h for a box, the radius for a
// sphere, a capsule's segment's |R| h plus its radius.
fn world_extent(s: BodyState, p: BodyProps) -> vec3<f32> {
    if (HAS_ROUND && p.shape == SHAPE_SPHERE) {
        return vec3<f32>(p.half_extents.x);
    }
    if (HAS_ROUND && p.shape == SHAPE_CAPSULE) {
        return abs(quat_rotate(s.rot, vec3<f32>(0.0, p.half_extents.y, 0.0))) + p.half_extents.x;
    }
    let q = s.rot;
    let x = quat_rotate(q, vec3<f32>(p.half_extents.x, 0.0, 0.0));
    let y = quat_rotate(q, vec3<f32>(0.0, p.half_extents.y, 0.0));
    let z = quat_rotate(q, vec3<f32>(0.0, 0.0, p.half_extents.z));
    return abs(x) + abs(y) + abs(z);
}

// How far a body's shape reaches from its centre along unit vector dir (m).
fn reach_along(p: BodyProps, rot: vec4<f32>, dir: vec3<f32>) -> f32 {
    if (HAS_ROUND && p.shape == SHAPE_SPHERE) {
        return p.half_extents.x;
    }
    if (HAS_ROUND && p.shape == SHAPE_CAPSULE) {
        return abs(quat_rotate(quat_conj(rot), dir).y) * p.half_extents.y + p.half_extents.x;
    }
    return dot(abs(quat_rotate(quat_conj(rot), dir)), p.half_extents.xyz);
}

// Hamilton product a * b.
fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz),
        a.w * b.w - dot(a.xyz, b.xyz),
    );
}

fn quat_conj(q: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(-q.xyz, q.w);
}

fn quat_rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = 2.0 * cross(q.xyz, v);
    return v + q.w * t + cross(q.xyz, t);
}

// atan(x) for 0 <= x, without the builtin: Vulkan lets atan2, sin and cos be
// off by 2^-11, which a spinning body integrates into drift. Two half-angle
// reductions bring x under 0.27, where the series to x^11 is good to 1e-8.
fn atan_precise(x_in: f32) -> f32 {
    var x = x_in;
    var scale = 1.0;
    for (var k = 0; k < 2; k = k + 1) {
        if (x > 0.27) {
            x = x / (1.0 + sqrt(1.0 + x * x));
            scale = scale * 2.0;
        }
    }
    let x2 = x * x;
    let series = x * (1.0 + x2 * (-1.0 / 3.0 + x2 * (1.0 / 5.0 + x2 * (-1.0 / 7.0 + x2 * (1.0 / 9.0 - x2 / 11.0)))));
    return scale * series;
}

// Rotation vector (axis * angle, radians) of a unit quaternion, short way round.
fn quat_to_rotvec(q_in: vec4<f32>) -> vec3<f32> {
    var q = q_in;
    if (q.w < 0.0) {
        q = -q;
    }
    let s = length(q.xyz);
    if (s < 1e-12) {
        return 2.0 * q.xyz;
    }
    // atan(s / w), or pi/2 - atan(w / s) past 45 degrees: one inlined atan_precise
    let small = s <= q.w;
    let a = atan_precise(select(q.w / s, s / q.w, small));
    let half_angle = select(1.5707964 - a, a, small);
    return q.xyz * (2.0 * half_angle / s);
}

// Unit quaternion of a rotation vector; a series for one step's small angles (atan_precise).
fn quat_from_rotvec(v: vec3<f32>) -> vec4<f32> {
    let angle = length(v);
    let h = 0.5 * angle;
    if (h < 0.5) {
        let h2 = h * h;
        // sin(h) / h and cos(h), series to h^10
        let sinc = 1.0 + h2 * (-1.0 / 6.0 + h2 * (1.0 / 120.0 + h2 * (-1.0 / 5040.0 + h2 * (1.0 / 362880.0))));
        let c = 1.0 + h2 * (-0.5 + h2 * (1.0 / 24.0 + h2 * (-1.0 / 720.0 + h2 * (1.0 / 40320.0 - h2 / 3628800.0))));
        return normalize(vec4<f32>(0.5 * v * sinc, c));
    }
    return vec4<f32>(v * (sin(h) / angle), cos(h));
}

// No infinity or NaN (exponent bits all set): WGSL has no isNan, and x != x
// may be folded away by a driver's fast-math.
fn all_finite(v: vec4<f32>) -> bool {
    let exponent = bitcast<vec4<u32>>(v) & vec4<u32>(0x7f800000u);
    return all(exponent != vec4<u32>(0x7f800000u));
}

// Finite and within MAX_DISTANCE of the origin (integrate.wgsl's faults).
fn near(p: vec3<f32>) -> bool {
    return all_finite(vec4<f32>(p, 0.0)) && dot(p, p) <= MAX_DISTANCE * MAX_DISTANCE;
}

// Apply a small world-frame rotation dtheta (radians) to q: q' = q + 1/2 (dtheta, 0) q.
fn quat_add_rotation(q: vec4<f32>, dtheta: vec3<f32>) -> vec4<f32> {
    return normalize(q + 0.5 * quat_mul(vec4<f32>(dtheta, 0.0), q));
}

// The rotation matrix of unit quaternion q (columns: the body's axes).
fn quat_to_mat(q: vec4<f32>) -> mat3x3<f32> {
    let x2 = q.xyz * 2.0;
    let xx = q.x * x2.x;
    let yy = q.y * x2.y;
    let zz = q.z * x2.z;
    let xy = q.x * x2.y;
    let xz = q.x * x2.z;
    let yz = q.y * x2.z;
    let wx = q.w * x2.x;
    let wy = q.w * x2.y;
    let wz = q.w * x2.z;
    return mat3x3<f32>(vec3<f32>(1.0 - yy - zz, xy + wz, xz - wy), vec3<f32>(xy - wz, 1.0 - xx - zz, yz + wx),
                       vec3<f32>(xz + wy, yz - wx, 1.0 - xx - yy));
}

// World-frame inverse inertia as a matrix, R diag(inv_i) R^T from the rotation's
// matrix r: made once for a manifold's end, it spares each push two rotations.
fn world_inv_inertia(r: mat3x3<f32>, inv_i: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(r[0] * inv_i.x, r[1] * inv_i.y, r[2] * inv_i.z) * transpose(r);
}

// World-frame inverse inertia applied to v: R diag(inv_i) R^T v.
fn inv_inertia_world(q: vec4<f32>, inv_i: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let local = quat_rotate(quat_conj(q), v);
    return quat_rotate(q, inv_i * local);
}

fn is_fixed(p: BodyProps) -> bool {
    return (p.flags & FLAG_FIXED) != 0u;
}

// A kinematic body moves by its own velocities alone: no gravity, damping,
// contact or joint moves it, and it pushes what it meets.
fn is_kinematic(p: BodyProps) -> bool {
    return (p.flags & FLAG_KINEMATIC) != 0u;
}

// One body of a contact manifold as the contact passes see it: its poses,
// masses and material; the ground is an end at the origin with no mass.
struct ContactEnd {
    pos: vec3<f32>,
    disp: vec3<f32>,        // x_n - x_(n-1) (m), see BodyState
    rot: vec4<f32>,
    prev_rot: vec4<f32>,
    inv_inertia: vec4<f32>, // xyz body frame (1/(kg m^2)); w = inverse mass (1/kg)
    rot_m: mat3x3<f32>,       // rot as a matrix
    turn_m: mat3x3<f32>,      // rot's matrix less prev_rot's: what the last turn moved a point by
    inv_i_world: mat3x3<f32>, // the inverse inertia in world axes (world_inv_inertia)
    moves: bool,            // awake and not fixed: the contacts may move it
    fixed: bool,            // a fixed or kinematic body (not the ground): stays as the ground does
    restitution: f32,
    friction: f32,
    radius: f32,            // a sphere's or capsule's radius (m); 0 for a box or the ground
    half_height: f32,       // a capsule's half height (m); else 0
}

// The point of an end a contact of normal `toward` (from the end to its
// partner) measures, in the end's frame: the stored point, or for a sphere the
// point of its surface that faces the partner now (a fast roll turns the
// stored material point away, and the ball sank through the ground); for a
// capsule, that of the ball at the stored point's place along its segment.
fn end_point(e: ContactEnd, stored: vec3<f32>, toward: vec3<f32>) -> vec3<f32> {
    if (HAS_ROUND && e.radius > 0.0) {
        let surface = (toward * e.radius) * e.rot_m; // R^T (toward r)
        if (e.half_height > 0.0) {
            return surface + vec3<f32>(0.0, clamp(stored.y, -e.half_height, e.half_height), 0.0);
        }
        return surface;
    }
    return stored;
}

// Generalised inverse mass of an end along dir at offset r; 0 for an end that stays.
fn end_inv_mass(e: ContactEnd, r: vec3<f32>, dir: vec3<f32>) -> f32 {
    if (!e.moves) {
        return 0.0;
    }
    let rn = cross(r, dir);
    return e.inv_inertia.w + dot(rn, e.inv_i_world * rn);
}

// Each point's snap turns its ends as if it alone asked: summed, a face's
// points turn a box back past its tilt (four corners about 1.5 times), and
// their mean (a quarter of the sum) leaves most of it, so a box under a load
// off its middle stays tilted and, in a pyramid, its corner pushes its
// neighbour aside. For a point's ask along d at offset r (w: the pair's
// inverse mass along d there), end e's turn per unit ask, in each world axis,
// is I^-1 (r x d) (r x d) / w (end_turn / w); summed over the points that
// snapped (the diagonal of their operator K), its largest component is how far
// their summed turns overshoot a shared one.
fn end_turn(e: ContactEnd, r: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let rd = cross(r, d);
    return select(vec3<f32>(0.0), (e.inv_i_world * rd) * rd, e.moves);
}

// An end's inverse mass along d at r (end_inv_mass), from its end_turn.
fn row_inv_mass(e: ContactEnd, turn: vec3<f32>) -> f32 {
    return select(0.0, e.inv_inertia.w + turn.x + turn.y + turn.z, e.moves);
}

// The share of an end's summed turns it takes: the sum scaled back to one
// turn, never up (a single point's is taken whole).
fn turn_scale(k: vec3<f32>) -> f32 {
    return 1.0 / max(1.0, max(k.x, max(k.y, k.z)));
}

// What a summed impulse-like j (moments `moment` = sum of r x j) asks of an end:
// inverse mass times j, world inverse inertia times the moment (nothing if it stays).
fn end_snap(e: ContactEnd, j: vec3<f32>, moment: vec3<f32>, count: u32, flags: u32) -> EndSnap {
    if (!e.moves) {
        return EndSnap(vec3<f32>(0.0), 0u, vec3<f32>(0.0), flags);
    }
    return EndSnap(j * e.inv_inertia.w, count, e.inv_i_world * moment, flags);
}

// A contact's material: the larger restitution and the geometric mean of the
// frictions (Box2D's rule); the ground's is settings.restitution and .friction.
fn combined_restitution(a: ContactEnd, b: ContactEnd) -> f32 {
    return max(a.restitution, b.restitution);
}

fn combined_friction(a: ContactEnd, b: ContactEnd) -> f32 {
    return sqrt(a.friction * b.friction);
}
