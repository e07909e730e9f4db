//! `World`: a scene's bodies living on the GPU, stepped by the passes of
//! `step`, read back only on request.

use std::sync::Arc;

use crate::gpu::{types::*, Gpu};
use crate::scene::{Scene, Settings};
use crate::step::{storage_buffers, Buffer, Over, Stage, StepPipelines};
use crate::Error;

pub mod edit;
pub mod input;
mod records;
pub mod snapshot;

pub use records::{
    body_output, body_props, initial_state, joint_gaps, joint_lists, plan_grid, scene_props, GridLayout, JointLists,
};

/// Steps encoded into one submission; each gets its own `Params` slot.
const MAX_BATCH: usize = 64;

/// The state of one body as a user sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyOutput {
    pub position: [f32; 3],
    /// Unit quaternion (x, y, z, w).
    pub orientation: [f32; 4],
    /// Velocity at the step's time (m/s), from Verlet's displacement (see
    /// [`body_output`]).
    pub linear_velocity: [f32; 3],
    /// World frame (rad/s).
    pub angular_velocity: [f32; 3],
    /// Whether the body sleeps (`Settings::sleeping`): held still until
    /// something moving touches it or an input wakes it.
    pub asleep: bool,
}

/// The GPU buffers of a world, made at start-up; only the pair list and the
/// manifold pool are made again, larger, when a step fills three quarters
/// of either.
struct WorldData {
    states: [wgpu::Buffer; 2],
    params: wgpu::Buffer,
    status: wgpu::Buffer,
    /// The pair pipeline (shaders/pairs.wgsl): candidate pairs, the
    /// manifold pool, each body's pair bookkeeping and its pair list.
    pairs: wgpu::Buffer,
    /// The manifolds' headers, and their points in up to four parts (see
    /// `pool_parts`).
    manifolds: wgpu::Buffer,
    points: [wgpu::Buffer; 4],
    /// What each manifold asks of its two bodies in a sweep (two per
    /// manifold slot; solve.wgsl, restitution.wgsl), in up to two parts.
    snaps: [wgpu::Buffer; 2],
    pair_meta: wgpu::Buffer,
    body_pairs: wgpu::Buffer,
    /// The indirect dispatches: the narrowphase's at 0, copied from
    /// `status` before it, the contact passes' at 16, copied after
    /// `contact_lists`.
    dispatch: wgpu::Buffer,
    /// Each stage's two bind groups, by stage (`step_bind_groups`; always
    /// made, right after the buffers).
    bind_groups: Option<Vec<[wgpu::BindGroup; 2]>>,
    /// Shapes, masses and materials (written by the input kernel too).
    props: wgpu::Buffer,
    /// What the scene fixed at start-up: the bodies kept out of the grid
    /// (copied into the tail of `sorted`, where the passes read them) and the
    /// joint lists (the snapshot's scene hash reads them all).
    statics: [wgpu::Buffer; 3],
    /// Working buffers of the passes: vel0, and the grid's cell_count,
    /// cell_start, block_sums, sorted and cell_bounds.
    scratch: [wgpu::Buffer; 6],
    /// What a batch of steps starts from (the state and `status`; nothing
    /// else carries over from one step to the next, see snapshot.rs),
    /// copied as each batch begins, so that a batch during which a pool
    /// overflowed is taken again from the same start once the pools have
    /// grown (`World::step_with`).
    batch_start: [wgpu::Buffer; 2],
}

impl WorldData {
    /// The buffer bound at `buffer`'s binding while `states[from]` is the
    /// current state (state_in) and the other the next (state_out).
    fn buffer(&self, buffer: Buffer, from: usize) -> &wgpu::Buffer {
        let [vel0, cell_count, cell_start, block_sums, sorted, cell_bounds] = &self.scratch;
        let [_, joint_start, joint_refs] = &self.statics;
        match buffer {
            Buffer::Params => &self.params,
            Buffer::Props => &self.props,
            Buffer::StateIn => &self.states[from],
            Buffer::StateOut => &self.states[1 - from],
            Buffer::Vel0 => vel0,
            Buffer::CellCount => cell_count,
            Buffer::CellStart => cell_start,
            Buffer::BlockSums => block_sums,
            Buffer::Sorted => sorted,
            Buffer::Snaps => &self.snaps[0],
            Buffer::Snaps1 => &self.snaps[1],
            Buffer::Points => &self.points[0],
            Buffer::Points1 => &self.points[1],
            Buffer::Points2 => &self.points[2],
            Buffer::Points3 => &self.points[3],
            Buffer::Pairs => &self.pairs,
            Buffer::Manifolds => &self.manifolds,
            Buffer::Status => &self.status,
            Buffer::JointStart => joint_start,
            Buffer::JointRefs => joint_refs,
            Buffer::PairMeta => &self.pair_meta,
            Buffer::BodyPairs => &self.body_pairs,
            Buffer::CellBounds => cell_bounds,
        }
    }

    /// Every stage's two bind groups (its buffers, `Stage::buffers`), by
    /// stage: `[k]` reads `states[k]` and writes `states[1 - k]`.
    fn step_bind_groups(&self, device: &wgpu::Device, pipelines: &StepPipelines) -> Vec<[wgpu::BindGroup; 2]> {
        let group = |stage: Stage, from: usize| {
            let entries: Vec<wgpu::BindGroupEntry> = stage
                .buffers()
                .into_iter()
                .map(|buffer| {
                    let b = self.buffer(buffer, from);
                    // Params: one substep's slot, chosen by the dynamic offset
                    let size = (buffer == Buffer::Params).then_some(std::mem::size_of::<Params>() as u64);
                    let resource = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: b,
                        offset: 0,
                        size: size.and_then(wgpu::BufferSize::new),
                    });
                    wgpu::BindGroupEntry { binding: buffer.binding(), resource }
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(stage.name()),
                layout: pipelines.layout(stage),
                entries: &entries,
            })
        };
        Stage::ALL.iter().map(|&stage| [group(stage, 0), group(stage, 1)]).collect()
    }
}

/// Time per step spent in each stage (ms), from `World::profile`.
#[derive(Clone, Debug)]
pub struct StageTimes {
    pub ms_per_step: Vec<(Stage, f64)>,
    /// True: GPU timestamp queries; false: wall clock around each pass.
    pub gpu_timestamps: bool,
}

/// What the GPU reports about the pair list and the manifold pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactReport {
    /// Candidate pairs in the last step's list.
    pub pairs: u32,
    /// Most candidate pairs in any step so far.
    pub pairs_max: u32,
    /// Pairs the list holds now; more are dropped (and reported).
    pub pair_capacity: u32,
    /// Manifolds (pairs with contact points) in the last step.
    pub manifolds: u32,
    /// Most manifolds in any step so far.
    pub manifolds_max: u32,
    /// Manifolds the pool holds now; more are dropped (and reported).
    pub manifold_capacity: u32,
    /// Whether any step so far wanted more pairs or manifolds than its pool
    /// held, even once grown (the pools also shrink, so the maxima above
    /// may exceed today's capacities without any loss).
    pub dropped: bool,
    /// Whether any step so far had a body's pair walk long enough that the
    /// driver may have cut it short (lavapipe ends an invocation's loops
    /// past 65535 trips: a body far faster than its neighbours, in a scene
    /// of about 65 000 bodies or more); its pairs may be missing.
    pub walks_cut: bool,
    /// Whether any step so far had a body's contact list so long that the
    /// driver may have cut its sort short (lavapipe: a body touching about
    /// 4500 others): its sums may then differ from run to run.
    pub lists_cut: bool,
}

/// Bytes of the `status` buffer the GPU reports through (21 words; see
/// shaders/bindings.wgsl, binding 12).
const STATUS_BYTES: u64 = 88;
/// `status[2]` and `status[3]` before any fault (`NO_FAULT` in integrate.wgsl).
pub const NO_FAULT: u32 = u32::MAX;
/// The speed (m/s) and distance from the origin (m) beyond which a body's
/// state is absurd (`MAX_SPEED`, `MAX_DISTANCE` in integrate.wgsl).
pub const MAX_SPEED: f32 = 1e4;
pub const MAX_DISTANCE: f32 = 1e6;
/// The spin (rad/s) beyond which a body is absurd, and the most it may turn
/// in one substep (rad; a pose pair holds under half a turn, pi, per
/// substep): `MAX_SPIN` and `MAX_TURN` in integrate.wgsl.
pub const MAX_SPIN: f32 = 1e4;
/// The shortest substep (s, dt / substeps) a world takes. Velocities are
/// displacements over the substep, and over shorter ones the rounding of
/// the poses reads as speed: a pyramid of ten boxes placed at rest read
/// 0.009 m/s after 300 steps at substeps of 1e-5 s, 0.085 at 3.3e-6 s and
/// 0.35 at 3.3e-7 (bodies sleep below 0.05), and at 3.3e-10 s a pile at
/// rest was stopped at its first step as thrown by the solver.
pub const MIN_SUBSTEP: f32 = 1e-5;
/// Fastest speed (m/s) at which the solve pushes apart bodies that already
/// overlapped at their previous poses (Box2D's contact push speed is 3 m/s);
/// joints close an old gap no faster (`MAX_DEPENETRATION_SPEED` in the
/// shaders).
pub const MAX_DEPENETRATION_SPEED: f32 = 3.0;
pub const MAX_TURN: f32 = 3.0;
/// The gap (m) within which two bodies get contacts whatever their speed
/// (`CONTACT_MARGIN` in the shaders): it covers what the step's own snaps
/// bring them nearer by, since contacts are found once a step. What their
/// motion brings them nearer by within the step comes on top of it
/// (pairs.wgsl's `pair_margin`: their relative displacement, gravity, and
/// how far each one's turn moves its points).
pub const CONTACT_MARGIN: f32 = 0.01;

/// What was wrong with a faulted body (the low three bits of `status[2]`,
/// `FAULT_*` in integrate.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// An infinity or a NaN in its pose.
    NonFinite = 0,
    /// Farther than `MAX_DISTANCE` from the origin.
    TooFar = 1,
    /// Faster than `MAX_SPEED`.
    TooFast = 2,
    /// Spinning faster than `MAX_SPIN`, or turning more than `MAX_TURN` in a substep.
    SpinsTooFast = 3,
    /// Faster than the scene's energy can move it (`BodyProps::speed_limit`):
    /// thrown by the solver.
    FasterThanItsEnergy = 4,
}

/// The first numerical fault the GPU found: the lowest body found bad in the
/// first step that found any. The integration checks every body's state
/// every substep (no readback); a bad body is stopped, parked at rest at
/// its last sane pose, and the run goes on (see shaders/integrate.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    pub body: usize,
    /// The step (0-based: the world's step count as it began) whose
    /// integration found the bad state: the state went bad during it
    /// (between substeps), during the step before, or through the scene or
    /// an input given before it.
    pub step: u64,
    pub kind: FaultKind,
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.kind {
            FaultKind::NonFinite => "non-finite".to_string(),
            FaultKind::TooFar => format!("absurd (farther than {MAX_DISTANCE:e} m from the origin)"),
            FaultKind::TooFast => format!("absurd (faster than {MAX_SPEED:e} m/s)"),
            FaultKind::SpinsTooFast => {
                format!("absurd (spinning faster than {MAX_SPIN:e} rad/s or {MAX_TURN} rad in one substep)")
            }
            FaultKind::FasterThanItsEnergy => "absurd (faster than all the energy of the scene could move it: \
                                               the solver threw it)"
                .to_string(),
        };
        write!(f, "body {} became {what} at step {}; it was stopped at its last sane pose", self.body, self.step)
    }
}

impl ContactReport {
    /// Whether any step so far found more pairs or manifolds than fit.
    pub fn overflowed(&self) -> bool {
        self.dropped
    }
}

/// The pools' use as the host follows it from batch to batch: the GPU's
/// maxima (`status[1]`, `status[5]`) are cleared after each batch is read,
/// so that they tell what that batch wanted. Index 0: the pair list, 1: the
/// manifold pool.
#[derive(Clone, Copy, Debug, Default)]
struct PoolWatch {
    /// Most any step wanted so far.
    peak: [u32; 2],
    /// Whether a step wanted more than its pool held, even once grown.
    dropped: bool,
    /// Steps in a row whose wants stayed under a quarter of the pool, and
    /// the most they wanted.
    quiet_steps: [u64; 2],
    quiet_most: [u32; 2],
    /// What to make the pool before the next batch (`World::shrink_pools`).
    shrink_to: [Option<u64>; 2],
}

/// A pool that no step of this many in a row filled a quarter of is made
/// twice what the most of them wanted (and no smaller than at least 64
/// entries) before the next batch: contact memory follows the need down as
/// well as up, so a pile that has settled and sleeps (no contacts between
/// sleepers) holds little more than its bodies. Twice the need sits midway
/// between the quarter and the three quarters that grow it again.
pub const SHRINK_AFTER_STEPS: u64 = 120;
/// The fewest entries a pool is made with.
const MIN_POOL: u64 = 64;

/// Candidate pairs the list holds per body at first (pairs a body owns; see
/// shaders/pairs.wgsl). A settled pile of cubes
/// four deep owns about 2.5 (2.1 with other cubes, 0.4 with the ground,
/// measured); both pools grow when a step fills three quarters
/// (`World::fit_pools`).
pub const PAIRS_PER_BODY: u64 = 6;

/// Gauss-Seidel sweeps over the joints in a substep, spread over its
/// `solve_joints` passes, one after each relaxation sweep (rounded up). A chain converges in a
/// few; a bridge pinned taut at both ends and loaded is the slowest case met:
/// `bridge(20)` with ten boxes on it opens 7.3 mm with 24 sweeps a substep,
/// 4.3 mm with 48 and 2.7 mm with 66 (64 over 3 sweeps; default settings).
pub const JOINT_SWEEPS_PER_SUBSTEP: u32 = 64;
/// Manifolds the pool holds per body at first (pairs with contact points;
/// about 2.5 in a settled pile, fewer while bodies fall).
pub const MANIFOLDS_PER_BODY: u64 = 3;

/// The pair list's and the manifold pool's sizes for `n` bodies on `gpu`:
/// per body as above; the pair list (and the bodies' lists, two words a
/// pair) within one storage binding, the pool within its parts'
/// (`pool_parts`). The passes over them are dispatched indirectly, in rows
/// (`write_dispatch` in bindings.wgsl), and wgpu's check of an indirect
/// dispatch's size is off (see `Gpu::new`).
pub fn pair_capacities(gpu: &Gpu, n: u64) -> (u64, u64) {
    let binding = binding_limit(gpu);
    let pair_bytes = std::mem::size_of::<Pair>().max(2 * 4) as u64;
    let pairs = n.saturating_mul(PAIRS_PER_BODY).max(MIN_POOL).min(binding / pair_bytes).min(MAX_INDEX);
    let (points_per_part, snaps_per_part) = pool_part_lengths(gpu);
    let manifolds = n
        .saturating_mul(MANIFOLDS_PER_BODY)
        .max(MIN_POOL)
        .min(binding / std::mem::size_of::<ContactManifold>() as u64)
        .min(4 * points_per_part)
        .min(2 * snaps_per_part / 2)
        .min(MAX_INDEX);
    (pairs, manifolds)
}

/// Most pairs, and most manifolds, whatever the bindings hold: a pair's
/// index keeps the top bit free (`list_order` in narrowphase.wgsl), and a
/// manifold's contact references (2 x slot + 1) fit 32 bits.
const MAX_INDEX: u64 = 1 << 31;

/// Most entries a part of the pool's points and of its snaps holds: one
/// storage binding's worth (bindings.wgsl's `point_of`, `snap_of`).
fn pool_part_lengths(gpu: &Gpu) -> (u64, u64) {
    let binding = binding_limit(gpu);
    (binding / std::mem::size_of::<ManifoldPoints>() as u64, binding / std::mem::size_of::<EndSnap>() as u64)
}

/// Whether a pool of `manifolds` slots takes more than one part (the first
/// part of the snaps holds twice the slots of the first part of the points).
fn pool_in_parts(gpu: &Gpu, manifolds: u64) -> bool {
    manifolds > pool_part_lengths(gpu).0
}

/// The sizes (bytes) of a pool of `manifolds` slots: its headers, its
/// points' four parts and its snaps' two. Every part but the last used is
/// full; a part not used holds one entry, never read.
fn pool_parts(gpu: &Gpu, manifolds: u64) -> (u64, [u64; 4], [u64; 2]) {
    let (points_per_part, snaps_per_part) = pool_part_lengths(gpu);
    let part = |k: u64, total: u64, per: u64| total.saturating_sub(k * per).min(per).max(1);
    let points = std::mem::size_of::<ManifoldPoints>() as u64;
    let snap = std::mem::size_of::<EndSnap>() as u64;
    (
        manifolds * std::mem::size_of::<ContactManifold>() as u64,
        [0, 1, 2, 3].map(|k| part(k, manifolds, points_per_part) * points),
        [0, 1].map(|k| part(k, 2 * manifolds, snaps_per_part) * snap),
    )
}

/// Bytes of GPU memory per body as a world is made: its own share
/// (`body_bytes`) and its share of the contact pools at their first size
/// (`PAIRS_PER_BODY` pairs and `MANIFOLDS_PER_BODY` manifolds). The pools
/// then follow the need (`World::fit_pools`): a settled pile that sleeps
/// holds little more than `body_bytes`.
pub fn bytes_per_body() -> u64 {
    body_bytes() + PAIRS_PER_BODY * pair_bytes() + MANIFOLDS_PER_BODY * manifold_bytes()
}

/// Bytes of GPU memory a body holds whatever it touches: poses (two
/// buffers), properties, velocities, its pair bookkeeping, the grid's share
/// (sorted list, its bounds in that order, about two hash buckets with
/// their counts and starts), its place in the list of bodies the body
/// passes run over, and the copy of the pose a batch of steps starts from.
pub fn body_bytes() -> u64 {
    let state = std::mem::size_of::<BodyState>() as u64;
    let meta = std::mem::size_of::<PairMeta>() as u64;
    let grid = 2 * 4 + std::mem::size_of::<CellBound>() as u64 + 2 * 8;
    3 * state + std::mem::size_of::<BodyProps>() as u64 + std::mem::size_of::<Velocity>() as u64 + meta + grid
}

/// Bytes a candidate pair takes: its entry in the pair list and in its two
/// bodies' lists.
pub fn pair_bytes() -> u64 {
    std::mem::size_of::<Pair>() as u64 + 2 * 4
}

/// Bytes a manifold takes: its slot in the pool and its two snaps.
pub fn manifold_bytes() -> u64 {
    (std::mem::size_of::<ContactManifold>() + std::mem::size_of::<ManifoldPoints>() + 2 * std::mem::size_of::<EndSnap>()) as u64
}

/// The host's side of where a batch of steps started (`World::batch_start`).
#[derive(Clone, Copy)]
struct BatchStart {
    current: usize,
    step: u64,
    time: f64,
    dt_prev: f32,
}

pub struct World {
    gpu: Arc<Gpu>,
    pipelines: StepPipelines,
    data: WorldData,
    settings: Settings,
    ground: Option<f32>,
    grid: GridLayout,
    large_count: u32,
    body_count: u32,
    /// Joint islands (`joint_rest` and `solve_joints` run only when there
    /// are any).
    island_count: u32,
    /// Where each colour of the joint paths begins, and after the last its
    /// end (`JointLists::colours`): `solve_joints` runs once per colour.
    path_colours: Vec<u32>,
    /// Whether the bodies' speed limits (`BodyProps::speed_limit`, from the
    /// scene's energy) still hold: no input, edit or restore since.
    speed_limits: bool,
    /// Which of `data.states` holds the current state.
    current: usize,
    step: u64,
    time: f64,
    /// Length of the last (sub)step taken (s): what `disp` spans.
    dt_prev: f32,
    /// The user-input kernels (`input.rs`), built on the first input.
    input: Option<input::InputGpu>,
    /// The scene as loaded or last edited (`edit.rs` rebuilds from it).
    scene: Scene,
    /// How full the contact pools got (`World::fit_pools`).
    pools: PoolWatch,
    /// Nothing moved in the last step taken and no sleeper is due to wake
    /// (`status[15]`, read by `fit_pools`), and no input, edit or restore
    /// came since: every body is asleep or fixed, and each step would leave
    /// every pose as it is, so `step_with` only counts the steps.
    at_rest: bool,
    /// The last step was skipped at rest: it listed no pair (nothing
    /// moves), whatever the last step taken on the GPU left in the pools.
    skipped: bool,
}

impl World {
    /// Opens the default GPU and uploads the scene.
    pub fn new(scene: &Scene) -> Result<World, Error> {
        scene.validate()?;
        let gpu = Arc::new(Gpu::new()?);
        World::with_gpu(gpu, scene)
    }

    /// Uploads the scene to an already opened GPU. Refuses a scene beyond the
    /// adapter's limits before allocating anything.
    pub fn with_gpu(gpu: Arc<Gpu>, scene: &Scene) -> Result<World, Error> {
        scene.validate()?;
        let n = scene.bodies.len();
        check_capacity(&gpu, n)?;
        let joints = joint_lists(scene);
        if scene.settings.sleeping {
            check_islands(&gpu, &joints, n)?;
        }
        let settings = scene.settings;
        let device = &gpu.device;
        let count = n.max(1); // wgpu buffers may not be empty

        let (props, large, grid) = scene_props(scene);
        let states: Vec<BodyState> = scene.bodies.iter().map(|b| initial_state(b, &settings)).collect();

        let storage = |label: &str, size: u64| storage_buffer(device, label, size);
        let with_data = |label: &str, bytes: &[u8]| {
            let buf = storage(label, bytes.len() as u64);
            if !bytes.is_empty() {
                gpu.queue.write_buffer(&buf, 0, bytes);
            }
            buf
        };
        let hash = grid.hash_size as u64;
        let props_buf = with_data("props", bytemuck::cast_slice(&props));
        let state_bufs = [with_data("state A", bytemuck::cast_slice(&states)), with_data("state B", bytemuck::cast_slice(&states))];
        let vel0 = storage("vel0", (count * std::mem::size_of::<Velocity>()) as u64);
        let cell_count = storage("grid/cell_count", 4 * hash);
        let cell_start = storage("grid/cell_start", 4 * (hash + 1));
        // block totals of the grid's scan and the pairs' (xy)
        let block_sums = storage("scan/block_sums", 8 * hash.max(count as u64).div_ceil(SCAN_SPAN as u64));
        // the grid's order, then the step's listed bodies (`listed_body` in bindings.wgsl)
        let sorted = storage("grid/sorted", 8 * count as u64);
        // the grid bodies' bounds in the grid's order (grid_sort, for the pair walks)
        let cell_bounds = storage("grid/cell_bounds", (count * std::mem::size_of::<CellBound>()) as u64);
        let large_buf = with_data("grid/large", bytemuck::cast_slice(&large));
        let (pair_capacity, manifold_capacity) = pair_capacities(&gpu, count as u64);
        let pairs = storage("pairs", pair_capacity * std::mem::size_of::<Pair>() as u64);
        let (heads, point_parts, snap_parts) = pool_parts(&gpu, manifold_capacity);
        let manifolds = storage("manifolds", heads);
        let points = point_parts.map(|size| storage("manifolds/points", size));
        let snaps = snap_parts.map(|size| storage("manifolds/snaps", size));
        let meta_bytes = (count as u64 + 1) * std::mem::size_of::<PairMeta>() as u64;
        let pair_meta = storage("pairs/meta", meta_bytes);
        let state_bytes = (count * std::mem::size_of::<BodyState>()) as u64;
        let body_pairs = storage("pairs/body_lists", 2 * pair_capacity * 4);
        let status = with_data("status", bytemuck::cast_slice(&STATUS_INIT));
        let dispatch = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("indirect dispatches"),
            size: 48,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let joint_start = with_data("joints/start", bytemuck::cast_slice(&joints.starts));
        let joint_refs = with_data("joints/refs", bytemuck::cast_slice(&joints.refs));
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: PARAMS_STRIDE * MAX_BATCH.max(settings.substeps as usize * (1 + joints.colour_count() as usize)) as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let pipelines = StepPipelines::new(&gpu, pool_in_parts(&gpu, manifold_capacity));
        let mut data = WorldData {
            states: state_bufs,
            params,
            status,
            pairs,
            manifolds,
            points,
            snaps,
            pair_meta,
            body_pairs,
            dispatch,
            bind_groups: None,
            props: props_buf,
            statics: [large_buf, joint_start, joint_refs],
            scratch: [vel0, cell_count, cell_start, block_sums, sorted, cell_bounds],
            batch_start: [storage("batch start/state", state_bytes), storage("batch start/status", STATUS_BYTES)],
        };
        data.bind_groups = Some(data.step_bind_groups(device, &pipelines));
        if !large.is_empty() {
            // the grid's part of `sorted` holds the other bodies, n - large of them
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("large bodies") });
            let [large_buf, ..] = &data.statics;
            let sorted = &data.scratch[4];
            encoder.copy_buffer_to_buffer(large_buf, 0, sorted, 4 * (n - large.len()) as u64, 4 * large.len() as u64);
            gpu.queue.submit([encoder.finish()]);
        }
        gpu.check()?;
        let substep_dt = settings.dt / settings.substeps as f32;
        Ok(World {
            gpu,
            pipelines,
            data,
            settings,
            ground: scene.ground.as_ref().map(|g| g.height),
            grid,
            large_count: large.len() as u32,
            body_count: n as u32,
            island_count: joints.islands,
            path_colours: joints.colours.clone(),
            speed_limits: true,
            current: 0,
            step: 0,
            time: 0.0,
            dt_prev: substep_dt,
            input: None,
            scene: scene.clone(),
            pools: PoolWatch::default(),
            at_rest: false,
            skipped: false,
        })
    }

    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    pub fn body_count(&self) -> usize {
        self.body_count as usize
    }

    /// Steps taken so far.
    pub fn step_count(&self) -> u64 {
        self.step
    }

    /// Simulated time so far (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The buffer holding the current poses (for drawing without readback).
    pub fn current_state_buffer(&self) -> &wgpu::Buffer {
        &self.data.states[self.current]
    }

    /// Takes `steps` steps of `settings.dt`.
    pub fn step(&mut self, steps: u64) -> Result<(), Error> {
        let dt = self.settings.dt;
        let mut left = steps;
        while left > 0 {
            if self.at_rest {
                // nothing moves: the steps are counted at once, not a batch
                // at a time (a run of 2^64 - 1 steps at rest ended only when
                // its batches had been counted one by one)
                return self.skip_at_rest(left, dt);
            }
            let batch = left.min(self.steps_per_batch() as u64);
            let dts = vec![dt; batch as usize];
            self.step_with(&dts)?;
            left -= batch;
        }
        Ok(())
    }

    /// Takes one step per entry of `dts`, each of that length (s); Verlet's
    /// time correction (eq. 11) carries the motion across changes of dt.
    /// A lost device or any error it raised is reported here, by the next
    /// call after it happened.
    pub fn step_with(&mut self, dts: &[f32]) -> Result<(), Error> {
        self.gpu.check()?;
        for (k, &dt) in dts.iter().enumerate() {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(Error::Input(format!("dt[{k}]: must be a positive finite number of seconds, got {dt}")));
            }
            if let Some(why) = crate::scene::dt_too_short(dt, self.settings.substeps) {
                return Err(Error::Input(format!("dt[{k}]: {why}")));
            }
        }
        let substeps = self.settings.substeps as usize;
        for chunk in dts.chunks(self.steps_per_batch()) {
            if self.at_rest {
                // what the skipped steps would have listed: nothing moves,
                // so no pair and no manifold (the pools follow)
                self.skipped = true;
                self.note_wants([0, 0], chunk.len());
                self.shrink_pools()?;
                self.finish_steps(chunk, substeps);
                continue;
            }
            self.skipped = false;
            self.shrink_pools()?;
            let start = self.batch_start();
            self.encode_and_submit(chunk, substeps);
            while self.fit_pools(chunk.len())? {
                self.restore_batch_start(start);
                self.encode_and_submit(chunk, substeps);
            }
        }
        Ok(())
    }

    /// Where the next batch starts from, on the host's side: which state
    /// buffer is current, the step count, the time and the last substep's
    /// length (the GPU's side is copied by `encode_and_submit`).
    fn batch_start(&self) -> BatchStart {
        BatchStart { current: self.current, step: self.step, time: self.time, dt_prev: self.dt_prev }
    }

    /// Puts the world back where a batch started (`batch_start` and the
    /// copies `encode_and_submit` made), to take the batch again.
    fn restore_batch_start(&mut self, start: BatchStart) {
        let BatchStart { current, step, time, dt_prev } = start;
        (self.current, self.step, self.time, self.dt_prev) = (current, step, time, dt_prev);
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("redo batch") });
        let [state, status] = &self.data.batch_start;
        // into both state buffers: a body the step leaves as it is holds the
        // same in both (`listed_body` in bindings.wgsl)
        for to in &self.data.states {
            encoder.copy_buffer_to_buffer(state, 0, to, 0, state.size());
        }
        encoder.copy_buffer_to_buffer(status, 0, &self.data.status, 0, STATUS_BYTES);
        self.gpu.queue.submit([encoder.finish()]);
    }

    /// Grows the pair list and the manifold pool, before the next step, to
    /// 1.5 times the most a step used once a step has used more than three
    /// quarters of either (a 64-byte blocking readback of the status words
    /// after every batch of `steps` steps). Growing to twice that once a step
    /// used half held pile-10k's settled contacts in 1862 bytes a body, 1432
    /// so; a batch that overflows is taken again, so a tight pool costs time
    /// only when contacts grow by a third within one batch (none in the
    /// bench's piles). Both are rebuilt every step, so nothing is carried
    /// over. Returns whether a step of the last batch wanted more than a pool
    /// held and the pool has grown: which pairs or manifolds then found no
    /// room depended on thread timing, so the caller takes the batch again.
    /// A pool already at its limit (`pair_capacities`) stays, and its overflow is
    /// reported by `contact_report`. Otherwise the batch stands: its wants
    /// are added to `pools`, which may mark a pool to shrink
    /// (`SHRINK_AFTER_STEPS`), and the GPU's maxima are cleared for the next.
    fn fit_pools(&mut self, steps: usize) -> Result<bool, Error> {
        let words = self.status_words()?;
        let report = self.batch_report_of(&words);
        let (most_pairs, most_manifolds) = pair_capacities(&self.gpu, u64::MAX);
        let want = |used: u32, capacity: u32, most: u64| {
            let grown = (3 * used as u64 / 2).max(capacity as u64).min(most);
            (4 * used as u64 > 3 * capacity as u64 && grown > capacity as u64).then_some(grown)
        };
        let pairs = want(report.pairs_max, report.pair_capacity, most_pairs);
        let manifolds = want(report.manifolds_max, report.manifold_capacity, most_manifolds);
        if pairs.is_some() || manifolds.is_some() {
            let (pairs, manifolds) =
                (pairs.unwrap_or(report.pair_capacity as u64), manifolds.unwrap_or(report.manifold_capacity as u64));
            self.make_pools(pairs, manifolds, true)?;
            if report.dropped && report.pairs_max as u64 <= pairs && report.manifolds_max as u64 <= manifolds {
                return Ok(true);
            }
        }
        // the batch stands
        self.pools.dropped |= report.dropped;
        self.note_wants([report.pairs_max, report.manifolds_max], steps);
        self.gpu.queue.write_buffer(&self.data.status, 4, bytemuck::bytes_of(&0u32));
        self.gpu.queue.write_buffer(&self.data.status, 20, bytemuck::bytes_of(&0u32));
        self.at_rest = words[15] == 0;
        Ok(false)
    }

    /// Adds a batch of `steps` steps that wanted at most `wanted` pairs and
    /// manifolds to `pools`: the peaks, and whether a pool (as it is now, grown
    /// or not) has stayed under a quarter for `SHRINK_AFTER_STEPS` (then it is
    /// marked to shrink to twice the most those steps wanted).
    fn note_wants(&mut self, wanted: [u32; 2], steps: usize) {
        let (pairs, manifolds) = self.capacities();
        let capacity = [pairs, manifolds];
        let watch = &mut self.pools;
        for k in 0..2 {
            watch.peak[k] = watch.peak[k].max(wanted[k]);
            if 4 * wanted[k] as u64 >= capacity[k] as u64 {
                watch.quiet_steps[k] = 0;
                watch.quiet_most[k] = 0;
                continue;
            }
            watch.quiet_steps[k] = watch.quiet_steps[k].saturating_add(steps as u64);
            watch.quiet_most[k] = watch.quiet_most[k].max(wanted[k]);
            let to = (2 * watch.quiet_most[k] as u64).max(MIN_POOL);
            if watch.quiet_steps[k] >= SHRINK_AFTER_STEPS && to < capacity[k] as u64 {
                watch.shrink_to[k] = Some(to);
            }
        }
    }

    /// Whether the world is at rest: every body asleep or fixed, none due to
    /// wake, after the last step taken, and no input, edit or restore since.
    /// Its steps then change no pose, and `step` skips the GPU's work,
    /// counting only the steps and the time, until an input wakes the
    /// bodies (a scene that never sleeps, `settings.sleeping` off, is never
    /// at rest unless every body is fixed).
    pub fn at_rest(&self) -> bool {
        self.at_rest
    }

    /// Makes the pools `fit_pools` marked smaller, before a batch: no copy,
    /// since the batch rebuilds them (and nothing reads them before it).
    fn shrink_pools(&mut self) -> Result<(), Error> {
        let [pairs, manifolds] = std::mem::take(&mut self.pools.shrink_to);
        if pairs.is_none() && manifolds.is_none() {
            return Ok(());
        }
        let (pair_capacity, manifold_capacity) = self.capacities();
        self.make_pools(pairs.unwrap_or(pair_capacity as u64), manifolds.unwrap_or(manifold_capacity as u64), false)?;
        for (k, shrunk) in [pairs, manifolds].iter().enumerate() {
            if shrunk.is_some() {
                self.pools.quiet_steps[k] = 0;
                self.pools.quiet_most[k] = 0;
            }
        }
        Ok(())
    }

    /// Makes the pair list (with the bodies' lists) and the manifold pool
    /// (with its snaps) hold `pairs` and `manifolds` where they differ from
    /// today's, copying the old contents over when `keep` (so that
    /// `read_contacts` still reads the last step's contacts).
    fn make_pools(&mut self, pairs: u64, manifolds: u64, keep: bool) -> Result<(), Error> {
        let (pair_capacity, manifold_capacity) = self.capacities();
        let device = &self.gpu.device;
        let storage = |label: &str, size: u64| storage_buffer(device, label, size);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("resize pools") });
        let mut remake = |old: &mut wgpu::Buffer, label: &str, size: u64| {
            let new = storage(label, size);
            if keep {
                encoder.copy_buffer_to_buffer(old, 0, &new, 0, old.size().min(size));
            }
            *old = new;
        };
        if pairs != pair_capacity as u64 {
            remake(&mut self.data.pairs, "pairs", pairs * std::mem::size_of::<Pair>() as u64);
            remake(&mut self.data.body_pairs, "pairs/body_lists", 2 * pairs * 4);
        }
        if manifolds != manifold_capacity as u64 {
            let (heads, point_parts, snap_parts) = pool_parts(&self.gpu, manifolds);
            remake(&mut self.data.manifolds, "manifolds", heads);
            for (buffer, size) in self.data.points.iter_mut().zip(point_parts) {
                remake(buffer, "manifolds/points", size);
            }
            for (buffer, size) in self.data.snaps.iter_mut().zip(snap_parts) {
                remake(buffer, "manifolds/snaps", size);
            }
        }
        self.gpu.queue.submit([encoder.finish()]);
        if pool_in_parts(&self.gpu, manifolds) && !self.pipelines.pool_split {
            // once, for the largest scenes: the passes read and write the parts
            self.pipelines.split_pool(&self.gpu);
        }
        self.data.bind_groups = Some(self.data.step_bind_groups(device, &self.pipelines));
        self.gpu.check()?;
        Ok(())
    }

    /// The pair list's and the manifold pool's capacities now.
    fn capacities(&self) -> (u32, u32) {
        let size = |b: &wgpu::Buffer, each: usize| (b.size() / each as u64) as u32;
        (size(&self.data.pairs, std::mem::size_of::<Pair>()), size(&self.data.manifolds, std::mem::size_of::<ContactManifold>()))
    }

    /// The Params slots a substep takes: its own, then one per colour of
    /// the joint paths (`solve_joints` reads its colour's paths from it).
    fn slots_per_substep(&self) -> usize {
        self.path_colours.len().max(1)
    }

    /// The steps a batch holds: as many as the Params buffer has slots for
    /// (`MAX_BATCH`), at least one (the buffer holds one step's).
    fn steps_per_batch(&self) -> usize {
        (MAX_BATCH / (self.settings.substeps as usize * self.slots_per_substep())).max(1)
    }

    /// Writes the Params slots of every substep of `dts` (`slots_per_substep`
    /// each) and returns how many.
    fn write_params(&mut self, dts: &[f32], substeps: usize) -> usize {
        let s = &self.settings;
        let slots_each = self.slots_per_substep();
        let mut slots = vec![0u8; PARAMS_STRIDE as usize * dts.len() * substeps * slots_each];
        let mut dt_prev = self.dt_prev;
        let mut slot = 0;
        for (k, &dt) in dts.iter().enumerate() {
            let h = dt / substeps as f32;
            // NO_FAULT is reserved: the step index saturates just below it
            let step_index = (self.step + k as u64).min(NO_FAULT as u64 - 1) as u32;
            for substep in 0..substeps {
                let p = Params {
                    gravity: s.gravity,
                    ground_height: self.ground.unwrap_or(0.0),
                    dt: h,
                    dt_prev,
                    relaxation: s.relaxation,
                    // the paper's beta is per step: spread it over the substeps
                    linear_damping: per_substep(s.linear_damping, substeps),
                    angular_damping: per_substep(s.angular_damping, substeps),
                    body_count: self.body_count,
                    has_ground: self.ground.is_some() as u32,
                    ground_restitution: s.restitution,
                    ground_friction: s.friction,
                    cell_size: self.grid.cell_size,
                    hash_size: self.grid.hash_size,
                    large_count: self.large_count,
                    speed_limits: self.speed_limits as u32,
                    substeps: substeps as u32,
                    step_index,
                    sleep_after: if s.sleeping { crate::scene::SLEEP_AFTER } else { 0.0 },
                    substep: substep as u32,
                    opaque_zero: 0,
                    island_count: self.island_count,
                    joint_sweeps: JOINT_SWEEPS_PER_SUBSTEP.div_ceil(s.sweeps(substep as u32)),
                    path_count: self.path_colours.last().copied().unwrap_or(0),
                    ..Params::default()
                };
                // the substep's own, then one per colour of the joint paths
                let colours = self.path_colours.windows(2).map(|w| (w[0], w[1]));
                for p in std::iter::once(p).chain(colours.map(|(first, end)| Params { path_first: first, path_end: end, ..p })) {
                    let at = slot * PARAMS_STRIDE as usize;
                    slots[at..at + std::mem::size_of::<Params>()].copy_from_slice(bytemuck::bytes_of(&p));
                    slot += 1;
                }
                dt_prev = h;
            }
        }
        self.gpu.queue.write_buffer(&self.data.params, 0, &slots);
        slot
    }

    /// Counts `steps` steps of `dt` of a world at rest (`at_rest`): what
    /// `step_with` does for each batch of them, in one go.
    fn skip_at_rest(&mut self, steps: u64, dt: f32) -> Result<(), Error> {
        self.skipped = true;
        self.note_wants([0, 0], usize::try_from(steps).unwrap_or(usize::MAX));
        self.shrink_pools()?;
        self.dt_prev = dt / self.settings.substeps as f32;
        self.step = self.step.saturating_add(steps);
        self.time += steps as f64 * dt as f64;
        Ok(())
    }

    fn finish_steps(&mut self, dts: &[f32], substeps: usize) {
        self.dt_prev = dts.last().map_or(self.dt_prev, |&dt| dt / substeps as f32);
        self.step += dts.len() as u64;
        self.time += dts.iter().map(|&d| d as f64).sum::<f64>();
    }

    /// Records copies of what a batch starts from on the GPU (see
    /// `WorldData::batch_start`).
    fn copy_batch_start(&self, encoder: &mut wgpu::CommandEncoder) {
        let [state, status] = &self.data.batch_start;
        encoder.copy_buffer_to_buffer(&self.data.states[self.current], 0, state, 0, state.size());
        encoder.copy_buffer_to_buffer(&self.data.status, 0, status, 0, STATUS_BYTES);
    }

    fn encode_and_submit(&mut self, dts: &[f32], substeps: usize) {
        let slot = self.write_params(dts, substeps);

        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("step") });
        self.copy_batch_start(&mut encoder);
        let plan = self.step_plan();
        for first in (0..slot).step_by(substeps * self.slots_per_substep()) {
            self.encode_step(&mut encoder, &plan, first);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.finish_steps(dts, substeps);
    }

    /// Records one step's dispatches (`plan`, its substeps' Params from batch
    /// slot `first` on) in as few compute passes as the copies of the
    /// indirect dispatch sizes allow: three. A pass of its own for every
    /// dispatch cost lavapipe about 30 us more a dispatch, a third of a
    /// small scene's step (`encode_pass` does so, for `profile`'s
    /// timestamps).
    fn encode_step(&mut self, encoder: &mut wgpu::CommandEncoder, plan: &[(Stage, usize)], first: usize) {
        let mut pass: Option<wgpu::ComputePass<'static>> = None;
        for &(stage, sub) in plan {
            if stage == Stage::Narrowphase {
                drop(pass.take());
            }
            self.copy_dispatch_sizes(encoder, stage, true);
            let open = pass.get_or_insert_with(|| {
                encoder
                    .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("step"), timestamp_writes: None })
                    .forget_lifetime()
            });
            self.dispatch(open, stage, first + sub);
            if stage == Stage::ContactLists {
                drop(pass.take());
            }
            self.copy_dispatch_sizes(encoder, stage, false);
        }
    }

    /// The copies of the indirect dispatch sizes around `stage` (`before`
    /// it runs, or after): the narrowphase's, which the pair scan wrote into
    /// status[8..11], before it; the contact passes', which contact_lists
    /// wrote into status[12..15], after that. Outside any compute pass.
    fn copy_dispatch_sizes(&self, encoder: &mut wgpu::CommandEncoder, stage: Stage, before: bool) {
        match (stage, before) {
            (Stage::Narrowphase, true) => encoder.copy_buffer_to_buffer(&self.data.status, 32, &self.data.dispatch, 0, 12),
            (Stage::ContactLists, false) => {
                encoder.copy_buffer_to_buffer(&self.data.status, 48, &self.data.dispatch, 16, 12);
                encoder.copy_buffer_to_buffer(&self.data.status, 68, &self.data.dispatch, 32, 12);
            }
            _ => {}
        }
    }

    /// Records `stage`'s dispatch with the Params of batch slot `slot`, bound
    /// to the current state, and flips the current state if it writes.
    fn dispatch(&mut self, pass: &mut wgpu::ComputePass<'_>, stage: Stage, slot: usize) {
        let offset = [(slot as u64 * PARAMS_STRIDE) as u32];
        pass.set_pipeline(self.pipelines.pipeline(stage));
        let groups = &self.data.bind_groups.as_ref().expect("made with the buffers")[stage as usize];
        let group = if stage.edits_in_place() { 1 - self.current } else { self.current };
        pass.set_bind_group(0, &groups[group], &offset);
        match stage.over() {
            Over::Pairs => pass.dispatch_workgroups_indirect(&self.data.dispatch, 0),
            Over::Manifolds => pass.dispatch_workgroups_indirect(&self.data.dispatch, 16),
            Over::Listed => pass.dispatch_workgroups_indirect(&self.data.dispatch, 32),
            over => pass.dispatch_workgroups(self.workgroups(over), 1, 1),
        }
        if stage.flips_state() {
            self.current = 1 - self.current;
        }
    }

    /// The passes of one step, each with the Params slot it uses within the
    /// step (`slots_per_substep` a substep; `solve_joints` one per colour):
    /// the broadphase and narrowphase once, then for every substep the
    /// integration, its share of the `iterations` sweeps of the solve's two
    /// halves (`Settings::sweeps`) and the
    /// restitution's two (the contacts, kept in the bodies' own frames,
    /// serve all substeps). A scan of at most `SCAN_SPAN` buckets or
    /// bodies is one block, which its first pass finishes: the grid's
    /// `grid_scan_sums` and `grid_scan_add` and the pairs' `pairs_scan_sums`
    /// are then left out (three dispatches fewer up to 1024 bodies).
    pub fn step_plan(&self) -> Vec<(Stage, usize)> {
        // a scan of one block is finished by its first pass (grid.wgsl)
        let one_block = |len: u32| len <= SCAN_SPAN;
        let needed = |s: &Stage| match s {
            Stage::GridScanSums | Stage::GridScanAdd => !one_block(self.grid.hash_size),
            Stage::PairsScanSums => !one_block(self.body_count),
            _ => true,
        };
        let mut plan: Vec<(Stage, usize)> =
            Stage::ALL.iter().take_while(|s| **s != Stage::Integrate).filter(|s| needed(s)).map(|&s| (s, 0)).collect();
        let per_substep = self.slots_per_substep();
        for sub in 0..self.settings.substeps as usize {
            let at = sub * per_substep;
            plan.push((Stage::Integrate, at));
            for sweep in 0..self.settings.sweeps(sub as u32) {
                plan.extend([(Stage::SolveContacts, at), (Stage::Solve, at)]);
                if self.island_count > 0 {
                    // islands sleep as one only where bodies sleep at all
                    if sweep == 0 && self.settings.sleeping {
                        plan.push((Stage::JointRest, at));
                    }
                    plan.extend((1..per_substep).map(|c| (Stage::SolveJoints, at + c)));
                }
            }
            plan.push((Stage::RestitutionContacts, at));
            // the next substep's integrate applies what it asks (integrate.wgsl)
            if sub + 1 == self.settings.substeps as usize {
                plan.push((Stage::Restitution, at));
            }
        }
        plan
    }

    /// Records one dispatch of `stage` with the Params of batch slot `slot`,
    /// optionally with timestamps, and flips the current state if it writes.
    fn encode_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        stage: Stage,
        slot: usize,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        self.copy_dispatch_sizes(encoder, stage, true);
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(stage.name()), timestamp_writes: timestamps });
        self.dispatch(&mut pass, stage, slot);
        drop(pass);
        self.copy_dispatch_sizes(encoder, stage, false);
    }

    /// Runs `stages` alone, in order, each as a step's first substep runs it,
    /// and leaves the step count as it was: a way to check one kernel
    /// against a known answer (tests/gpu/kernels.rs), not a way to simulate.
    #[doc(hidden)]
    pub fn run_stages(&mut self, stages: &[Stage]) -> Result<(), Error> {
        (self.at_rest, self.skipped) = (false, false);
        self.write_params(&[self.settings.dt], self.settings.substeps as usize);
        if !stages.contains(&Stage::ContactLists) {
            let clears = [Stage::GridScatter, Stage::PairsCount];
            if stages.iter().any(|s| clears.contains(s)) && stages.iter().any(|s| s.over() == Over::Listed) {
                return Err(Error::Input(
                    "run_stages: grid_scatter and pairs_count overwrite the list of bodies that contact_lists makes".into(),
                ));
            }
            // no list made: the body passes run over every body
            let n = self.body_count;
            let every: Vec<u32> = (0..n).collect();
            let queue = &self.gpu.queue;
            queue.write_buffer(&self.data.scratch[4], 4 * n as u64, bytemuck::cast_slice(&every));
            queue.write_buffer(&self.data.status, 16 * 4, bytemuck::bytes_of(&n));
            let all = [self.workgroups(Over::Bodies), 1, 1];
            queue.write_buffer(&self.data.dispatch, 32, bytemuck::cast_slice(&all));
        }
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("stages") });
        for &stage in stages {
            self.encode_pass(&mut encoder, stage, 0, None);
        }
        self.gpu.queue.submit([encoder.finish()]);
        Ok(self.gpu.wait()?)
    }

    /// One of the step's buffers, read back as 32-bit words (tests).
    #[doc(hidden)]
    pub fn read_words(&self, buffer: Buffer) -> Result<Vec<u32>, Error> {
        let b = self.data.buffer(buffer, self.current);
        Ok(bytemuck::pod_collect_to_vec(&self.gpu.read_buffer(b, b.size())?))
    }

    /// Takes `steps` steps of `settings.dt` one at a time, timing every pass:
    /// with GPU timestamp queries where the adapter has them, else by the
    /// wall clock around each pass submitted and waited for alone (which
    /// adds the submission's overhead to every pass).
    pub fn profile(&mut self, steps: u64) -> Result<StageTimes, Error> {
        let plan = self.step_plan();
        let substeps = self.settings.substeps as usize;
        let passes = plan.len();
        let mut totals = [0.0f64; Stage::ALL.len()];
        let gpu = self.gpu.clone();
        let timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let timer = timestamps.then(|| crate::gpu::PassTimer::new(&gpu, "profile", passes));
        let mut step = 0;
        while step < steps {
            self.skipped = false;
            self.shrink_pools()?;
            let start = self.batch_start();
            let before = totals;
            let dt = [self.settings.dt];
            self.write_params(&dt, substeps);
            let mut k = 0;
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.copy_batch_start(&mut encoder);
            {
                for &(stage, slot) in &plan {
                    match &timer {
                        Some(timer) => self.encode_pass(&mut encoder, stage, slot, Some(timer.writes(k))),
                        None => {
                            gpu.queue.submit([encoder.finish()]);
                            gpu.wait()?;
                            let started = std::time::Instant::now();
                            encoder = gpu.device.create_command_encoder(&Default::default());
                            self.encode_pass(&mut encoder, stage, slot, None);
                            gpu.queue.submit([encoder.finish()]);
                            gpu.wait()?;
                            totals[stage as usize] += started.elapsed().as_secs_f64() * 1e3;
                            encoder = gpu.device.create_command_encoder(&Default::default());
                        }
                    }
                    k += 1;
                }
            }
            if let Some(timer) = &timer {
                timer.resolve(&mut encoder);
            }
            gpu.queue.submit([encoder.finish()]);
            if let Some(timer) = &timer {
                for ((stage, _), ms) in plan.iter().zip(timer.read_ms(&gpu)?) {
                    totals[*stage as usize] += ms;
                }
            }
            self.finish_steps(&dt, substeps);
            if self.fit_pools(1)? {
                // a pool overflowed: the step is taken again (as step_with
                // does), its first timing dropped
                self.restore_batch_start(start);
                totals = before;
                continue;
            }
            step += 1;
        }
        let n = steps.max(1) as f64;
        Ok(StageTimes {
            ms_per_step: Stage::ALL.iter().map(|&s| (s, totals[s as usize] / n)).collect(),
            gpu_timestamps: timestamps,
        })
    }

    fn workgroups(&self, over: Over) -> u32 {
        let n = match over {
            Over::Bodies => self.body_count.div_ceil(WORKGROUP),
            Over::Buckets => self.grid.hash_size.div_ceil(WORKGROUP),
            Over::ScanBlocks => self.grid.hash_size.div_ceil(SCAN_SPAN),
            Over::BodyScanBlocks => self.body_count.div_ceil(SCAN_SPAN),
            Over::One => 1,
            Over::Islands => self.island_count.div_ceil(WORKGROUP),
            Over::Paths => self.path_colours.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0).div_ceil(WORKGROUP),
            Over::Pairs | Over::Manifolds | Over::Listed => unreachable!("dispatched indirectly"),
        };
        n.max(1)
    }

    /// The grid the broadphase uses.
    pub fn grid(&self) -> GridLayout {
        self.grid
    }

    /// Bytes of GPU memory the world's buffers hold now: what `with_gpu`
    /// allocated, with the pair list and the manifold pool as they have
    /// grown, and the input kernels' buffers once an input was given.
    pub fn gpu_bytes(&self) -> u64 {
        let d = &self.data;
        let buffers = [&d.params, &d.status, &d.pairs, &d.manifolds, &d.pair_meta, &d.body_pairs, &d.dispatch, &d.props];
        buffers.iter().map(|b| b.size()).sum::<u64>()
            + d.states.iter().chain(&d.statics).chain(&d.scratch).chain(&d.batch_start).map(|b| b.size()).sum::<u64>()
            + d.points.iter().chain(&d.snaps).map(|b| b.size()).sum::<u64>()
            + self.input.as_ref().map_or(0, |i| i.gpu_bytes())
    }

    /// How full the pair list and the manifold pool got (a blocking readback).
    pub fn contact_report(&self) -> Result<ContactReport, Error> {
        let batch = self.batch_report_of(&self.status_words()?);
        let last = |n: u32| if self.skipped { 0 } else { n };
        Ok(ContactReport {
            pairs: last(batch.pairs),
            manifolds: last(batch.manifolds),
            pairs_max: batch.pairs_max.max(self.pools.peak[0]),
            manifolds_max: batch.manifolds_max.max(self.pools.peak[1]),
            dropped: batch.dropped || self.pools.dropped,
            ..batch
        })
    }

    /// The status words (a blocking readback; see shaders/bindings.wgsl).
    fn status_words(&self) -> Result<Vec<u32>, Error> {
        Ok(bytemuck::pod_collect_to_vec(&self.gpu.read_buffer(&self.data.status, STATUS_BYTES)?))
    }

    /// The status words' report: the maxima since `fit_pools` last cleared
    /// them (the last batch, or the one under way).
    fn batch_report_of(&self, v: &[u32]) -> ContactReport {
        let (pair_capacity, manifold_capacity) = self.capacities();
        ContactReport {
            pairs: v[0],
            pairs_max: v[1],
            pair_capacity,
            manifolds: v[4],
            manifolds_max: v[5],
            manifold_capacity,
            dropped: v[1] > pair_capacity || v[5] > manifold_capacity,
            walks_cut: v[20] != 0,
            lists_cut: v[21] != 0,
        }
    }

    /// The first numerical fault since the world was made or
    /// [`World::clear_faults`], if any (a 32-byte blocking readback; the
    /// step loop never reads it).
    pub fn faults(&self) -> Result<Option<Fault>, Error> {
        let v = self.status_words()?;
        Ok(decode_fault(v[2], v[3]))
    }

    /// Forgets the recorded fault, so that the next one is reported (the
    /// faulted body stays where it was stopped).
    pub fn clear_faults(&mut self) -> Result<(), Error> {
        self.gpu.check()?;
        self.gpu.queue.write_buffer(&self.data.status, 8, bytemuck::cast_slice(&[NO_FAULT, NO_FAULT]));
        Ok(())
    }

    /// The contact points of every body as it sees them, from the last
    /// step's narrowphase, in its pair order (a blocking readback, for tests
    /// and debugging).
    pub fn read_contacts(&self) -> Result<Vec<Vec<BodyContact>>, Error> {
        let n = self.body_count as usize;
        if self.skipped {
            return Ok(vec![Vec::new(); n]);
        }
        let read = |b: &wgpu::Buffer| self.gpu.read_buffer(b, b.size());
        let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&read(&self.data.pair_meta)?);
        let lists: Vec<u32> = bytemuck::pod_collect_to_vec(&read(&self.data.body_pairs)?);
        let manifolds: Vec<ContactManifold> = bytemuck::pod_collect_to_vec(&read(&self.data.manifolds)?);
        // the parts in order: every part but the last used is full
        let mut points: Vec<ManifoldPoints> = Vec::new();
        for part in &self.data.points {
            points.extend(bytemuck::pod_collect_to_vec::<u8, ManifoldPoints>(&read(part)?));
        }
        let mut out = vec![Vec::new(); n];
        for (i, list) in out.iter_mut().enumerate() {
            // contact references (shaders/narrowphase.wgsl's contact_lists)
            let first = meta[i].list_start as usize;
            let entries = lists.get(first..first + meta[i].contacts as usize).unwrap_or(&[]);
            for &r in entries {
                let (Some(m), Some(p)) = (manifolds.get(r as usize / 2), points.get(r as usize / 2)) else { continue };
                let me_a = r % 2 == 0;
                for pt in &p.at[..m.count as usize] {
                    let (local_self, partner, local_partner, sign) =
                        if me_a { (pt.local_a, m.b, pt.local_b, -1.0) } else { (pt.local_b, m.a, pt.local_a, 1.0) };
                    list.push(BodyContact { local_self, partner, local_partner, normal: m.normal.map(|v| v * sign) });
                }
            }
        }
        Ok(out)
    }

    /// Reads every body's pose back and derives its velocities.
    pub fn read_raw(&self) -> Result<Vec<BodyState>, Error> {
        let size = (self.body_count.max(1) as usize * std::mem::size_of::<BodyState>()) as u64;
        let bytes = self.gpu.read_buffer(&self.data.states[self.current], size)?;
        let mut states: Vec<BodyState> = bytemuck::pod_collect_to_vec(&bytes);
        states.truncate(self.body_count as usize);
        Ok(states)
    }

    /// Reads every body's state back (a blocking readback). Fails with
    /// `Error::Diverged`, naming the body and the step, once the GPU has
    /// flagged a numerical fault (see [`World::faults`]; after
    /// [`World::clear_faults`] it reads again) or a state is not finite.
    pub fn read_state(&self) -> Result<Vec<BodyOutput>, Error> {
        let dt = self.dt_prev as f64;
        let states = self.read_raw()?;
        if let Some(fault) = self.faults()? {
            return Err(Error::Diverged(fault.to_string()));
        }
        let mut joined = vec![false; states.len()];
        for j in &self.scene.joints {
            for b in j.bodies {
                if let Some(k) = usize::try_from(b).ok().filter(|&k| k < joined.len()) {
                    joined[k] = true;
                }
            }
        }
        let gravity = self.settings.gravity;
        let out: Vec<BodyOutput> = states.iter().zip(&joined).map(|(s, &j)| body_output(s, dt, gravity, j)).collect();
        if let Some(k) = out.iter().position(|b| !finite_output(b)) {
            return Err(Error::Diverged(format!(
                "body {k} has a non-finite state after step {} (time {:.4} s)",
                self.step, self.time
            )));
        }
        Ok(out)
    }
}

/// The status words as made: pair and manifold counts 0 (maxima
/// atomicMax-ed), no fault (atomicMin-ed), the rest spare.
const STATUS_INIT: [u32; (STATUS_BYTES / 4) as usize] =
    [0, 0, NO_FAULT, NO_FAULT, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0];

/// The damping per substep that removes `beta` per step: 1 - (1 - beta)^(1/n).
fn per_substep(beta: f32, substeps: usize) -> f32 {
    1.0 - (1.0 - beta as f64).powf(1.0 / substeps as f64) as f32
}

/// The fault `status[2]` and `status[3]` describe, if any.
fn decode_fault(code: u32, step: u32) -> Option<Fault> {
    if step == NO_FAULT || code == NO_FAULT {
        return None;
    }
    let kind = match code & 7 {
        0 => FaultKind::NonFinite,
        1 => FaultKind::TooFar,
        2 => FaultKind::TooFast,
        3 => FaultKind::SpinsTooFast,
        _ => FaultKind::FasterThanItsEnergy,
    };
    Some(Fault { body: (code / 8) as usize, step: step as u64, kind })
}

fn finite_output(b: &BodyOutput) -> bool {
    b.position.iter().chain(&b.orientation).chain(&b.linear_velocity).chain(&b.angular_velocity).all(|v| v.is_finite())
}

fn check_capacity(gpu: &Gpu, n: usize) -> Result<(), Error> {
    let l = &gpu.limits;
    let needed = storage_buffers();
    if l.max_storage_buffers_per_shader_stage < needed {
        return Err(Error::Capacity(format!(
            "a pass of the step binds {needed} storage buffers but this adapter allows {} per shader stage",
            l.max_storage_buffers_per_shader_stage
        )));
    }
    let max = max_bodies(gpu);
    if n as u64 > max {
        return Err(Error::Capacity(format!(
            "the scene has {n} bodies but this adapter holds at most {max}: each body's pose takes {} bytes \
             of one storage buffer, and the adapter binds at most {} bytes",
            std::mem::size_of::<BodyState>(),
            binding_limit(gpu)
        )));
    }
    Ok(())
}

/// Whether `joint_rest` can keep every joint island's rest time (where
/// bodies sleep; it runs only then): one invocation reads and writes an
/// island's, and where the driver ends an invocation's loops past
/// `Gpu::loop_trips` (lavapipe), an island of n joints takes 2n trips.
/// (The sweeps go along paths of at most `PATH_JOINTS` joints, which any
/// island is cut into.)
fn check_islands(gpu: &Gpu, joints: &JointLists, bodies: usize) -> Result<(), Error> {
    let (Some(trips), largest) = (gpu.loop_trips(), joints.largest_island(bodies)) else { return Ok(()) };
    let most = trips / 2;
    if largest > most {
        return Err(Error::Capacity(format!(
            "joints: an island of {largest} joints (bodies joined to each other, directly or through others) is more \
             than this adapter can keep asleep or awake as one: one invocation reads an island's rest times, and {} \
             ends an invocation's loops after 65535 trips, room for islands of at most {most} joints (with \
             settings.sleeping off there is no such limit)",
            gpu.info.name
        )));
    }
    Ok(())
}

/// A storage buffer of the step (copied to and from), of at least one
/// element of the largest struct a binding holds: an empty list still binds
/// a buffer as large as the shader's element.
fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(64),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn binding_limit(gpu: &Gpu) -> u64 {
    gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size)
}

/// The most bodies this GPU can hold: the poses must fit one storage
/// binding, the hash table (up to four buckets per body after rounding to a
/// power of two) too, and a dispatch has a workgroup limit. The pair list
/// and the manifold pool grow within their bindings (see
/// `pair_capacities`); a pool too small for a scene is reported. A body's
/// index must also fit the bits `CellBound::body` keeps for it.
pub fn max_bodies(gpu: &Gpu) -> u64 {
    let per_binding = binding_limit(gpu);
    let by_state = per_binding / std::mem::size_of::<BodyState>() as u64;
    let by_hash = per_binding / 16;
    let by_groups = gpu.limits.max_compute_workgroups_per_dimension as u64 * WORKGROUP as u64 / 4;
    by_state.min(by_hash).min(by_groups).min(BODY_BITS as u64 + 1)
}
