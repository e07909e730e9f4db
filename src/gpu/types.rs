//! Host twins of the structs in `shaders/common.wgsl`. Each is `#[repr(C)]`
//! with its padding written out; `tests/gpu/layouts.rs` checks every member's
//! name and offset and the size against the WGSL.

use bytemuck::{Pod, Zeroable};

/// Pose of one body (64 bytes): what swaps between the two state buffers.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BodyState {
    /// Centre of mass (m).
    pub pos: [f32; 3],
    /// Seconds at rest (see `asleep` in common.wgsl).
    pub rest_time: f32,
    /// x_n - x_(n-1): how far the centre moved over the last substep (m).
    /// Verlet's velocity is `disp / h`; kept instead of the previous position
    /// so that it is not the difference of two large numbers.
    pub disp: [f32; 3],
    /// Bits 0-29: what rounding dropped from `pos` (three signed 10-bit
    /// multiples of 1/512 of each coordinate's f32 spacing, see
    /// `pos_remainder` in common.wgsl); bit 30 ([`WAKES`]): a sleeper woken,
    /// due to wake; bit 31 ([`HELD`]): something besides gravity held the
    /// body over the last substep (a contact, or it is fixed or asleep).
    pub pos_low: u32,
    /// Orientation, unit quaternion (x, y, z, w).
    pub rot: [f32; 4],
    /// Orientation one step ago.
    pub prev_rot: [f32; 4],
}

/// `BodyState::pos_low` bit 31: something besides gravity held the body over
/// the last substep: a contact pushed it (the solve sets it; integrate's test
/// for sleeping reads it), or it is fixed or asleep. The host then reports
/// disp / h as its velocity, without the half substep of gravity that a free
/// body's disp / h lags by (`World::read_state`).
pub const HELD: u32 = 0x8000_0000;

/// `BodyState::pos_low` bit 30: the last step's narrowphase found an awake
/// partner waking this sleeper (`PairMeta::woken`'s `WOKEN_NOW`, moved here
/// by the step's integration): it wakes in the next step's first substep.
/// Kept in the pose, which a batch of steps starts from, so that nothing
/// else carries over from one step to the next (a snapshot's wake flags
/// call it `WOKEN_LAST`).
pub const WAKES: u32 = 0x4000_0000;

/// Shape, mass and material of one body (64 bytes), read-only on the GPU.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BodyProps {
    /// Box: half extents (m); sphere: radius in x; capsule: (radius, half
    /// height, radius). w = bounding radius (m).
    pub half_extents: [f32; 4],
    /// xyz = body-frame principal inverse inertia (1/(kg m^2)); w = inverse mass (1/kg).
    pub inv_inertia: [f32; 4],
    pub restitution: f32,
    pub friction: f32,
    /// `SHAPE_BOX`, `SHAPE_SPHERE`, `SHAPE_CAPSULE` or `SHAPE_HULL`.
    pub shape: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    /// A body an input made fixed: the inverse mass to restore (1/kg); else 0.
    pub kept_inv_mass: f32,
    /// The fastest the scene's energy can move the body (m/s; 0: no limit
    /// but `MAX_SPEED`); see `speed_limits` in src/world/records.rs.
    pub speed_limit: f32,
    /// `GRID_BODY`, or `LARGE_BODY` (kept out of the broadphase grid).
    pub grid_class: u32,
    /// A hull's first word in the hull records (src/world/hull_records.rs);
    /// `NO_HULL` for the other shapes.
    pub hull: u32,
}

/// Velocity after integration, before constraints (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Velocity {
    pub linear: [f32; 4],
    pub angular: [f32; 4],
}

/// Per-step parameters (96 bytes, stored in 256-byte slots).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    /// m/s^2.
    pub gravity: [f32; 3],
    /// m.
    pub ground_height: f32,
    pub dt: f32,
    pub dt_prev: f32,
    pub relaxation: f32,
    pub linear_damping: f32,
    pub angular_damping: f32,
    pub body_count: u32,
    pub has_ground: u32,
    pub ground_restitution: f32,
    pub ground_friction: f32,
    /// Edge of a broadphase cell (m).
    pub cell_size: f32,
    /// Buckets of the grid's hash table (a power of two).
    pub hash_size: u32,
    /// Bodies in the `large` list, outside the grid.
    pub large_count: u32,
    /// 1 while `BodyProps::speed_limit` holds: no input, edit or restore
    /// has added energy since the scene began.
    pub speed_limits: u32,
    /// Substeps per step; contacts found once per step serve them all.
    pub substeps: u32,
    /// The world's step count as this step began (saturating at
    /// `u32::MAX - 1`): the step a numerical fault is reported at.
    pub step_index: u32,
    /// Seconds at rest before a body sleeps; 0 when `settings.sleeping` is off.
    pub sleep_after: f32,
    /// Which substep of the step this is (0 first): sleepers wake only at 0.
    pub substep: u32,
    /// Always 0, but unknown to the shader compiler: integrate XORs a sum's
    /// bits with it so that the driver cannot fold TwoSum's `(a + b) - a`
    /// back to `b` (Mesa's optimiser does, for operations not marked exact).
    pub opaque_zero: u32,
    /// Joint islands `joint_rest` keeps asleep or awake as one (see
    /// `joint_lists`).
    pub island_count: u32,
    /// The paths of this `solve_joints` or `solve_paths` pass's colour: `path_first..path_end`.
    pub path_first: u32,
    pub path_end: u32,
    /// The paths of every colour (whether each is swept or solved directly
    /// follows their starts in `joint_start`).
    pub path_count: u32,
    /// 1 in the slots of a substep's second `solve_paths`, one a colour.
    pub second: u32,
    pub _pad2: u32,
}

/// A candidate pair (8 bytes); see `Pair` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Pair {
    /// The body that owns the pair (shaders/pairs.wgsl).
    pub a: u32,
    /// Another body, or `GROUND`.
    pub b: u32,
}

/// One contact point of a pair's manifold (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ContactPoint {
    /// On body a, in its frame.
    pub local_a: [f32; 3],
    /// The normal push summed over the substep's sweeps (m): the point's
    /// friction budget.
    pub pushed: f32,
    /// On body b, in its frame (the ground's: world coordinates).
    pub local_b: [f32; 3],
    /// Its normal push in the substep's last sweep (m), which the next
    /// sweep's weighted push builds on (shaders/solve.wgsl's `sweep_weight`).
    pub last_push: f32,
}

/// A pair's manifold's header (32 bytes): up to `MAX_POINTS` points sharing
/// one world normal, pointing from a to b (a body, or `GROUND`); its points
/// are a `ManifoldPoints` at the same slot of the pool's point parts
/// (`point_of` in bindings.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ContactManifold {
    pub normal: [f32; 3],
    pub count: u32,
    pub a: u32,
    pub b: u32,
    /// `NONE`, or the face the narrowphase left to clip (within a step).
    pub clip_face: u32,
    /// The candidate pair (index into the pair list) it was found for.
    pub pair: u32,
}

/// A manifold's points (the first `count`; 128 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ManifoldPoints {
    pub at: [ContactPoint; 4],
}

/// What a manifold asks of one of its bodies in a sweep (32 bytes); see
/// `EndSnap` in common.wgsl. A manifold's two sit at 2 x its slot (a's,
/// then b's).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EndSnap {
    pub dx: [f32; 3],
    pub count: u32,
    pub dtheta: [f32; 3],
    pub flags: u32,
}

/// `CellBound::body`: the body's index in the low bits (`BODY_BITS`),
/// `FAST_BODY` if the body is fast (shaders/grid.wgsl's `is_fast`),
/// `PairMeta::moves` from bit `MOVES_SHIFT` on (shared with WGSL).
pub const MOVES_SHIFT: u32 = 30;
pub const FAST_BODY: u32 = 1 << 29;
pub const BODY_BITS: u32 = FAST_BODY - 1;

/// A grid body's bounds as the pair walks read them, in the grid's order
/// (32 bytes); see `CellBound` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CellBound {
    /// Centre (m).
    pub pos: [f32; 3],
    /// Bounding radius grown by the reach (m).
    pub bound: f32,
    /// Half extents of the world box grown by the reach (m).
    pub extent: [f32; 3],
    /// The body's index, `FAST_BODY` if it is fast, and in the top two bits
    /// `PairMeta::moves` (an index fits `BODY_BITS`: `world::max_bodies`
    /// holds worlds within it).
    pub body: u32,
}

/// A body's pair bookkeeping (64 bytes); see `PairMeta` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PairMeta {
    pub owned: u32,
    pub total: u32,
    pub owned_start: u32,
    pub list_start: u32,
    pub cursor: u32,
    pub woken: u32,
    /// 1 if contacts can move the body this step.
    pub moves: u32,
    /// How many of its list's entries, after the narrowphase, are contact
    /// references (`2 * manifold + 1 if the body is the pair's b`).
    pub contacts: u32,
    /// Half extents of its world box grown by its reach (m).
    pub extent: [f32; 3],
    /// Its bounding radius grown by its reach (m); beside `extent`, so the
    /// pair walk reads both bounds of a candidate at once.
    pub bound: f32,
    /// How many of its manifolds are with an end that stays (the ground, a
    /// fixed or a sleeping body): friction's split (shaders/bindings.wgsl).
    pub held: u32,
    /// How many times its normal pushes against ends that stay count its
    /// inverse mass (contact_lists; shaders/solve.wgsl's stay_splits).
    pub normal_split: f32,
    /// How far any point of it may move this step (m): its centre's move and
    /// `spin`.
    pub reach: f32,
    /// How far its turn may move any point of it this step (m).
    pub spin: f32,
}

/// One contact point as one body of its pair sees it (host only, from
/// `World::read_contacts`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyContact {
    /// On this body, in its frame.
    pub local_self: [f32; 3],
    /// Body index, or `GROUND`.
    pub partner: u32,
    /// On the partner, in its frame; for the ground, in world coordinates.
    pub local_partner: [f32; 3],
    /// Unit, world frame, pointing from the partner to this body.
    pub normal: [f32; 3],
}

/// One end of a ball joint as the body at that end sees it (32 bytes): its
/// anchor in its own frame, and the partner's anchor in the partner's frame
/// (in world coordinates when the partner is `WORLD`); `body` is the body
/// at this end (see `joint_lists`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct JointRef {
    pub local_self: [f32; 3],
    pub partner: u32,
    pub local_partner: [f32; 3],
    pub body: u32,
}

/// `PairMeta::woken`: the narrowphase found an awake partner waking this
/// sleeper (`WOKEN_NOW`, the same name in WGSL), moved to the pose's
/// [`WAKES`] bit by the step's integration; the sleeper wakes at the next
/// step. A snapshot's wake flags name the two `WOKEN_NOW` and `WOKEN_LAST`.
pub const WOKEN_NOW: u32 = 1;
pub(crate) const WOKEN_LAST: u32 = 2;

/// The partner of a joint pinned to the world (`WORLD` in WGSL).
pub const WORLD: u32 = u32::MAX;

/// The partner of a contact with the ground (`GROUND` in WGSL).
pub const GROUND: u32 = u32::MAX;

/// Points a manifold holds (`MAX_POINTS` in WGSL).
pub const MAX_POINTS: u32 = 4;
/// No pair / no manifold (`NONE` in WGSL).
pub const NONE: u32 = u32::MAX;
/// Invocations of a scan workgroup (`SCAN_BLOCK` in WGSL).
pub const SCAN_BLOCK: u32 = 256;
/// Buckets (or bodies) each invocation of a scan sums in turn (`SCAN_RUN`).
pub const SCAN_RUN: u32 = 8;
/// Buckets (or bodies) a scan workgroup sums: a block (`SCAN_SPAN`).
pub const SCAN_SPAN: u32 = SCAN_BLOCK * SCAN_RUN;

/// `BodyProps::shape`.
pub const SHAPE_BOX: u32 = 0;
pub const SHAPE_SPHERE: u32 = 1;
/// A capsule: `half_extents` holds (radius, half height, radius).
pub const SHAPE_CAPSULE: u32 = 2;
/// A convex hull: its corners, faces and edges are in the hull records
/// (`BodyProps::hull`); `half_extents` holds the half extents of a box about
/// the body's origin that holds it.
pub const SHAPE_HULL: u32 = 3;
/// `BodyProps::hull` of a body that is not a hull.
pub const NO_HULL: u32 = u32::MAX;
/// `BodyProps::flags` bit: the body never moves.
pub const FLAG_FIXED: u32 = 1;
/// A kinematic body: moved by its own velocities alone (`Body::kinematic`).
pub const FLAG_KINEMATIC: u32 = 2;
/// `BodyProps::grid_class` of a body in the broadphase grid, and of one too
/// large for it (`GRID_BODY`, `LARGE_BODY` in WGSL).
pub const GRID_BODY: u32 = 0;
pub const LARGE_BODY: u32 = 1;

/// Threads per workgroup of every per-body pass (`WORKGROUP` in WGSL).
pub const WORKGROUP: u32 = 64;

/// Threads per workgroup of `solve_joints` and `solve_paths`, one a joint path: a colour may
/// have a few paths only, each a long serial loop, and small workgroups
/// spread them evenly over a software adapter's threads (`PATH_WORKGROUP`
/// in WGSL).
pub const PATH_WORKGROUP: u32 = 8;

/// vec4 words of `path_scratch` a joint of the paths takes (`PATH_SLOT` in
/// WGSL; shaders/solve.wgsl's `solve_path`): its pivot's inverse with the
/// eliminated gap. Its coupling to the joint before, and which end it
/// shares with it, are worked out again on the way back.
pub const PATH_SLOT: u32 = 3;

/// Byte stride between the per-step `Params` slots of a batch: the
/// uniform-buffer offset alignment WebGPU guarantees to work everywhere.
pub(crate) const PARAMS_STRIDE: u64 = 256;
