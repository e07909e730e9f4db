//! The compute pipelines of one step, in the order they run:
//!
//! 1. `grid_*`       — broadphase: counting sort of bodies into a hashed grid (shaders/grid.wgsl)
//! 2. `pairs_*`      — every candidate pair once, where each body's pairs start (shaders/pairs.wgsl)
//! 3. `narrowphase`  — one invocation per pair: its manifold, into the pool, listed in both
//!    bodies' contact lists (shaders/narrowphase.wgsl, collide.wgsl; boxes: the separating
//!    axis); `contact_lists` sorts each body's list into pair order; `narrowphase_clip`
//!    clips the face contacts, over the top run of the pool
//! 4. `integrate`    — Verlet prediction of every pose (shaders/integrate.wgsl), after
//!    applying the last substep's restitution in a step's later substeps
//! 5. `solve_contacts`, `solve`, `joint_rest`, `solve_joints` — the substep's share of the
//!    `iterations` sweeps of corrective snaps: per manifold what it asks of its bodies, then
//!    per body the sum (Jacobi), then (only in scenes with joints; `joint_rest` once a
//!    substep) per colour of joint paths each path's joints in turn (Gauss-Seidel)
//!    (shaders/solve.wgsl)
//! 6. `restitution_contacts`, `restitution` — bounce and dynamic friction, by
//!    rewriting the previous pose, in the same two halves (shaders/restitution.wgsl);
//!    the body half as a pass only after the last substep (the next `integrate`
//!    applies it after the others)
//!
//! Passes 1-3 only read the state; `integrate`, `solve` and `restitution`
//! read one state buffer and write the other, so the current state flips
//! after each of them; the `*_contacts` passes write only the manifolds'
//! snaps and friction budgets. This type holds
//! only compiled pipelines and their layouts; the buffers live in `World`.

use crate::gpu::{shaders, types::*, Gpu};

/// The stages of a step, in order; their names are the WGSL entry points
/// and the labels of their compute passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    GridCount,
    GridScanBlocks,
    GridScanSums,
    GridScanAdd,
    GridScatter,
    GridSort,
    PairsCount,
    PairsScanBlocks,
    PairsScanSums,
    PairsWrite,
    Narrowphase,
    NarrowphaseGround,
    ContactLists,
    NarrowphaseClip,
    Integrate,
    SolveContacts,
    Solve,
    JointRest,
    SolveJoints,
    RestitutionContacts,
    Restitution,
}

/// What one invocation of a stage works on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Over {
    Bodies,
    Buckets,
    /// One workgroup of `SCAN_BLOCK` per block of `SCAN_SPAN` buckets.
    ScanBlocks,
    /// One workgroup of `SCAN_BLOCK` per block of `SCAN_SPAN` bodies.
    BodyScanBlocks,
    /// A single workgroup.
    One,
    /// The candidate pairs: an indirect dispatch whose size the pair scan
    /// wrote (status[8..11], copied to the world's `dispatch` buffer).
    Pairs,
    /// The manifolds in the pool: an indirect dispatch whose size
    /// `contact_lists` wrote (status[12..15], copied to `dispatch` + 16).
    Manifolds,
    /// The joint islands (see `joint_lists`).
    Islands,
    /// The joint paths of one colour (see `joint_lists`): the widest
    /// colour's count, each dispatch bounded by its Params.
    Paths,
    /// The bodies the step may change (`listed_body` in bindings.wgsl): an
    /// indirect dispatch whose size `contact_lists` counted (status[17..20],
    /// copied to `dispatch` + 32 after it).
    Listed,
}

/// The buffers of the step's bind group, by binding (shaders/bindings.wgsl,
/// which names them; ARCHITECTURE.md says who writes what and why).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Buffer {
    Params = 0,
    Props = 1,
    StateIn = 2,
    StateOut = 3,
    Vel0 = 4,
    CellCount = 5,
    CellStart = 6,
    BlockSums = 7,
    Sorted = 8,
    Snaps = 9,
    Pairs = 10,
    Manifolds = 11,
    Status = 12,
    JointStart = 13,
    JointRefs = 14,
    PairMeta = 15,
    BodyPairs = 16,
    /// The manifolds' points, in up to four parts (`point_of` in
    /// bindings.wgsl), and the snaps' second part (`snap_of`).
    Points = 17,
    Points1 = 18,
    Points2 = 19,
    Points3 = 20,
    Snaps1 = 21,
    CellBounds = 22,
}

impl Buffer {
    pub const ALL: [Buffer; 23] = [
        Buffer::Params,
        Buffer::Props,
        Buffer::StateIn,
        Buffer::StateOut,
        Buffer::Vel0,
        Buffer::CellCount,
        Buffer::CellStart,
        Buffer::BlockSums,
        Buffer::Sorted,
        Buffer::Snaps,
        Buffer::Pairs,
        Buffer::Manifolds,
        Buffer::Status,
        Buffer::JointStart,
        Buffer::JointRefs,
        Buffer::PairMeta,
        Buffer::BodyPairs,
        Buffer::Points,
        Buffer::Points1,
        Buffer::Points2,
        Buffer::Points3,
        Buffer::Snaps1,
        Buffer::CellBounds,
    ];

    pub fn binding(self) -> u32 {
        self as u32
    }

    /// Whether no stage writes the buffer: its binding is then read-only
    /// in the layout (as bindings.wgsl must declare it).
    pub fn read_only(self) -> bool {
        Stage::ALL.iter().all(|s| !s.writes().contains(&self))
    }
}

impl Stage {
    pub const ALL: [Stage; 21] = [
        Stage::GridCount,
        Stage::GridScanBlocks,
        Stage::GridScanSums,
        Stage::GridScanAdd,
        Stage::GridScatter,
        Stage::GridSort,
        Stage::PairsCount,
        Stage::PairsScanBlocks,
        Stage::PairsScanSums,
        Stage::PairsWrite,
        Stage::Narrowphase,
        Stage::NarrowphaseGround,
        Stage::ContactLists,
        Stage::NarrowphaseClip,
        Stage::Integrate,
        Stage::SolveContacts,
        Stage::Solve,
        Stage::JointRest,
        Stage::SolveJoints,
        Stage::RestitutionContacts,
        Stage::Restitution,
    ];

    /// The pass's name: the label of its compute pass, and its entry point
    /// but for the scan passes (see `entry_point`).
    pub fn name(self) -> &'static str {
        match self {
            Stage::GridCount => "grid_count",
            Stage::GridScanBlocks => "grid_scan_blocks",
            Stage::GridScanSums => "grid_scan_sums",
            Stage::GridScanAdd => "grid_scan_add",
            Stage::GridScatter => "grid_scatter",
            Stage::GridSort => "grid_sort",
            Stage::PairsCount => "pairs_count",
            Stage::PairsScanBlocks => "pairs_scan_blocks",
            Stage::PairsScanSums => "pairs_scan_sums",
            Stage::PairsWrite => "pairs_write",
            Stage::Narrowphase => "narrowphase",
            Stage::NarrowphaseGround => "narrowphase_ground",
            Stage::ContactLists => "contact_lists",
            Stage::NarrowphaseClip => "narrowphase_clip",
            Stage::Integrate => "integrate",
            Stage::SolveContacts => "solve_contacts",
            Stage::Solve => "solve",
            Stage::JointRest => "joint_rest",
            Stage::SolveJoints => "solve_joints",
            Stage::RestitutionContacts => "restitution_contacts",
            Stage::Restitution => "restitution",
        }
    }

    /// The WGSL entry point: named like the stage, but for the scan passes,
    /// which grid.wgsl holds once for the grid and the pairs (the override
    /// constant SCAN_PAIRS tells them apart).
    pub fn entry_point(self) -> &'static str {
        match self {
            Stage::GridScanBlocks | Stage::PairsScanBlocks => "scan_blocks",
            Stage::GridScanSums | Stage::PairsScanSums => "scan_sums",
            Stage::GridScanAdd => "scan_add",
            other => other.name(),
        }
    }

    /// The WGSL files its module is made of, in order (src/gpu/shaders.rs).
    pub fn pieces(self) -> &'static [&'static str] {
        match self {
            Stage::PairsCount | Stage::PairsWrite => shaders::PAIRS_PASS,
            Stage::Narrowphase | Stage::NarrowphaseGround | Stage::ContactLists | Stage::NarrowphaseClip => {
                shaders::NARROWPHASE_PASS
            }
            Stage::Integrate => shaders::INTEGRATE_PASS,
            Stage::SolveContacts | Stage::Solve | Stage::JointRest | Stage::SolveJoints => shaders::SOLVE_PASS,
            Stage::RestitutionContacts | Stage::Restitution => shaders::RESTITUTION_PASS,
            _ => shaders::GRID_PASS,
        }
    }

    /// Its module's source: the shared constants, then its pieces.
    pub fn source(self) -> String {
        shaders::shared_constants() + &self.pieces().concat()
    }

    /// The buffers the stage's entry point reads and writes: every buffer
    /// its code can touch, as naga's analysis of the entry point finds it
    /// (`tests/gpu/shaders.rs` checks both lists against it), so a branch not
    /// taken counts (the pair walks share one walk that writes in
    /// `pairs_write` and counts in `pairs_count`; the scan passes hold the
    /// grid's case and the pairs' both). An atomic is a read and a write;
    /// `arrayLength` is a read (the buffer must be bound).
    pub fn reads(self) -> &'static [Buffer] {
        use Buffer::*;
        match self {
            Stage::GridCount => &[Params, Props, StateIn, CellCount, Status],
            Stage::GridScanBlocks | Stage::PairsScanBlocks => &[Params, CellCount, CellStart, Pairs, Status, PairMeta],
            Stage::GridScanSums | Stage::PairsScanSums => &[Params, BlockSums, Pairs, Status],
            Stage::GridScanAdd => &[Params, CellStart, BlockSums],
            Stage::GridScatter => &[Params, Props, StateIn, CellCount, CellStart],
            Stage::GridSort => &[Params, Props, StateIn, CellStart, Sorted, PairMeta],
            Stage::PairsCount => &[Params, Props, StateIn, CellStart, Sorted, Pairs, Status, PairMeta, BodyPairs, CellBounds],
            Stage::PairsWrite => {
                &[Params, Props, StateIn, CellStart, BlockSums, Sorted, Pairs, Status, PairMeta, BodyPairs, CellBounds]
            }
            Stage::Narrowphase => {
                &[Params, Props, StateIn, Pairs, Manifolds, Status, JointStart, JointRefs, PairMeta, BodyPairs, Points]
            }
            Stage::NarrowphaseGround => &[Params, Props, StateIn, Pairs, Manifolds, Status, PairMeta, BodyPairs, Points],
            Stage::ContactLists => &[Params, Props, StateIn, Manifolds, Status, JointStart, PairMeta, BodyPairs],
            Stage::NarrowphaseClip => &[Params, Props, StateIn, Manifolds, Status, PairMeta, Points],
            Stage::Integrate => &[Params, Props, StateIn, Sorted, Status, JointStart, PairMeta, Snaps, BodyPairs, Snaps1],
            Stage::SolveContacts => {
                &[Params, Props, StateIn, Snaps, Manifolds, Status, PairMeta, Points, Points1, Points2, Points3]
            }
            Stage::Solve => &[Params, Props, StateIn, Sorted, Snaps, PairMeta, BodyPairs, JointStart, Snaps1],
            Stage::JointRest | Stage::SolveJoints => &[Params, Props, StateOut, JointStart, JointRefs],
            Stage::RestitutionContacts => {
                &[Params, Props, StateIn, Vel0, Snaps, Manifolds, Status, PairMeta, Points, Points1, Points2, Points3]
            }
            Stage::Restitution => &[Params, Props, StateIn, Sorted, Snaps, PairMeta, BodyPairs, Snaps1],
        }
    }

    /// See [`Stage::reads`].
    pub fn writes(self) -> &'static [Buffer] {
        use Buffer::*;
        match self {
            Stage::GridCount => &[CellCount, Status, PairMeta],
            Stage::GridScanBlocks | Stage::PairsScanBlocks => &[CellStart, BlockSums, Status, PairMeta],
            Stage::GridScanSums | Stage::PairsScanSums => &[CellStart, BlockSums, Status, PairMeta],
            Stage::GridScanAdd => &[CellStart],
            Stage::GridScatter => &[CellCount, Sorted],
            Stage::GridSort => &[Sorted, CellBounds],
            Stage::PairsCount => &[Sorted, Pairs, Status, PairMeta, BodyPairs],
            Stage::PairsWrite => &[Pairs, PairMeta, BodyPairs],
            Stage::Narrowphase | Stage::NarrowphaseGround => {
                &[Manifolds, Status, PairMeta, BodyPairs, Points, Points1, Points2, Points3]
            }
            Stage::ContactLists => &[Sorted, Status, PairMeta, BodyPairs],
            Stage::NarrowphaseClip => &[Manifolds, PairMeta, Points, Points1, Points2, Points3],
            Stage::Integrate => &[StateOut, Vel0, Status, PairMeta],
            Stage::SolveContacts | Stage::RestitutionContacts => &[Snaps, Points, Points1, Points2, Points3, Snaps1],
            Stage::Solve | Stage::JointRest | Stage::SolveJoints | Stage::Restitution => &[StateOut],
        }
    }

    /// The buffers it binds (what it reads or writes), by binding: its bind
    /// group layout holds these alone.
    pub fn buffers(self) -> Vec<Buffer> {
        Buffer::ALL.iter().copied().filter(|b| self.reads().contains(b) || self.writes().contains(b)).collect()
    }

    /// Whether the stage is part of the grid broadphase (`grid_*`).
    pub fn is_broadphase(self) -> bool {
        self.name().starts_with("grid_")
    }

    /// The part of the step the stage belongs to, as the bench and the
    /// profile sum them: broadphase (`grid_*`), narrowphase (`pairs_*`, the
    /// narrowphase and its dispatch), integrate, solve (both halves),
    /// restitution (both halves).
    pub fn part(self) -> Part {
        match self {
            s if s.is_broadphase() => Part::Broadphase,
            Stage::Integrate => Part::Integrate,
            Stage::SolveContacts | Stage::Solve | Stage::JointRest | Stage::SolveJoints => Part::Solve,
            Stage::RestitutionContacts | Stage::Restitution => Part::Restitution,
            _ => Part::Narrowphase,
        }
    }

    /// Whether the stage is one of grid.wgsl's scan passes run over the
    /// bodies' pair counts (its override constant SCAN_PAIRS).
    pub fn scans_pairs(self) -> bool {
        matches!(self, Stage::PairsScanBlocks | Stage::PairsScanSums)
    }

    /// Whether the pass edits the current state in place: it is bound
    /// through the bind group whose state_out is the current state (the one
    /// the pass before it wrote), and nothing flips.
    pub fn edits_in_place(self) -> bool {
        matches!(self, Stage::JointRest | Stage::SolveJoints)
    }

    /// Whether the pass writes state_out (so the current state flips).
    pub fn flips_state(self) -> bool {
        matches!(self, Stage::Integrate | Stage::Solve | Stage::Restitution)
    }

    pub fn over(self) -> Over {
        match self {
            Stage::GridScanAdd => Over::Buckets,
            Stage::GridScanBlocks => Over::ScanBlocks,
            Stage::GridScanSums | Stage::PairsScanSums => Over::One,
            Stage::PairsScanBlocks => Over::BodyScanBlocks,
            Stage::Narrowphase => Over::Pairs,
            Stage::NarrowphaseClip | Stage::SolveContacts | Stage::RestitutionContacts => Over::Manifolds,
            Stage::JointRest => Over::Islands,
            Stage::SolveJoints => Over::Paths,
            Stage::Integrate | Stage::Solve | Stage::Restitution => Over::Listed,
            _ => Over::Bodies,
        }
    }
}

/// The parts of a step (see `Stage::part`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    Broadphase,
    Narrowphase,
    Integrate,
    Solve,
    Restitution,
}

/// The most storage buffers any stage binds; the device must allow this
/// many per shader stage.
pub fn storage_buffers() -> u32 {
    Stage::ALL.iter().map(|s| s.buffers().iter().filter(|b| **b != Buffer::Params).count() as u32).max().unwrap_or(0)
}

/// The step's compiled pipelines, each with its own bind group layout (the
/// buffers its entry point uses: every pass of the step binds fewer than
/// the 16 storage buffers an adapter is asked for, though the step has
/// more).
pub struct StepPipelines {
    layouts: Vec<wgpu::BindGroupLayout>,
    pipelines: Vec<wgpu::ComputePipeline>,
    /// Compiled for a manifold pool in parts (POOL_SPLIT in bindings.wgsl).
    pub pool_split: bool,
}

fn entry(buffer: Buffer) -> wgpu::BindGroupLayoutEntry {
    let ty = match buffer {
        // one Params slot per substep, chosen by the dynamic offset
        Buffer::Params => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
        },
        // read-only where no stage writes (props, state_in, the joints)
        _ => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: buffer.read_only() },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    };
    wgpu::BindGroupLayoutEntry { binding: buffer.binding(), visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

/// Compiles one pass with its layout (the override constants: POOL_SPLIT,
/// DISPATCH_ROW from the device's limits, SCAN_PAIRS for the pairs' scan,
/// LOOP_TRIPS where the driver limits loops).
fn compile(gpu: &Gpu, stage: Stage, layout: &wgpu::BindGroupLayout, pool_split: bool) -> wgpu::ComputePipeline {
    let mut constants = vec![
        ("POOL_SPLIT", f64::from(u8::from(pool_split))),
        ("DISPATCH_ROW", f64::from(gpu.limits.max_compute_workgroups_per_dimension)),
    ];
    if stage.scans_pairs() {
        constants.push(("SCAN_PAIRS", 1.0));
    }
    if let Some(trips) = gpu.loop_trips() {
        constants.push(("LOOP_TRIPS", f64::from(trips)));
    }
    let mut one = gpu.compute_pipelines(stage.name(), &stage.source(), &[stage.entry_point()], Some(&[layout]), &constants);
    one.remove(0)
}

impl StepPipelines {
    /// Compiles the step's passes, for a manifold pool in parts where
    /// `pool_split` (see `World::make_pools`).
    pub fn new(gpu: &Gpu, pool_split: bool) -> StepPipelines {
        let device = &gpu.device;
        let layouts: Vec<wgpu::BindGroupLayout> = Stage::ALL
            .iter()
            .map(|stage| {
                let entries: Vec<wgpu::BindGroupLayoutEntry> = stage.buffers().into_iter().map(entry).collect();
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(stage.name()), entries: &entries })
            })
            .collect();
        let pipelines = Stage::ALL.iter().map(|&stage| compile(gpu, stage, &layouts[stage as usize], pool_split)).collect();
        StepPipelines { layouts, pipelines, pool_split }
    }

    /// Compiles the passes that touch the manifold pool's parts again, for
    /// a pool in parts (POOL_SPLIT on; see `World::make_pools`).
    pub fn split_pool(&mut self, gpu: &Gpu) {
        for stage in Stage::ALL {
            let buffers = stage.buffers();
            if buffers.contains(&Buffer::Points) || buffers.contains(&Buffer::Snaps1) {
                self.pipelines[stage as usize] = compile(gpu, stage, &self.layouts[stage as usize], true);
            }
        }
        self.pool_split = true;
    }

    pub fn pipeline(&self, stage: Stage) -> &wgpu::ComputePipeline {
        &self.pipelines[stage as usize]
    }

    pub fn layout(&self, stage: Stage) -> &wgpu::BindGroupLayout {
        &self.layouts[stage as usize]
    }
}
