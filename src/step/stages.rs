//! The stages of a step, one row of `TABLE` each: everything the host knows
//! of a stage is in its row, and every other list (the stages in order,
//! the bind group layouts, the dispatches, the profile's parts) is derived
//! from the table.

use super::Buffer;
use crate::gpu::shaders;

/// The stages of a step, in order; each indexes its row of `TABLE`.
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
    NarrowphaseHull,
    NarrowphaseGround,
    ContactLists,
    NarrowphaseClip,
    Integrate,
    SolveContacts,
    Solve,
    JointRestClear,
    JointRestGather,
    JointRest,
    SolveJoints,
    SolvePaths,
    RestitutionContacts,
    Restitution,
    RestitutionInPlace,
}

/// What one invocation of a stage works on, which sizes its dispatch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Over {
    Bodies,
    /// The candidate pairs: an indirect dispatch whose size the pair scan
    /// wrote (`Status::pairs_dispatch`).
    Pairs,
    /// The manifolds in the pool: an indirect dispatch whose size
    /// `contact_lists` wrote (`Status::manifolds_dispatch`).
    Manifolds,
    /// The joint islands (see `joint_lists`).
    Islands,
    /// The joints of the islands' lists (see `joint_lists`).
    IslandJoints,
    /// The joint paths of one colour (see `joint_lists`): the widest
    /// colour's count, each dispatch bounded by its Params.
    Paths,
    /// The bodies the step may change (`listed_body` in bindings.wgsl): an
    /// indirect dispatch whose size `contact_lists` counted
    /// (`Status::listed_dispatch`).
    Listed,
    /// Of those, the bodies with contacts (`touching_body`): sized alike
    /// (`Status::touching_dispatch`).
    Touching,
    // The passes only a step that walks for pairs needs: on a step that
    // keeps its empty pair list (`pairs_kept` in bindings.wgsl) they are
    // dispatched at no size. Indirect dispatches grid_count sizes
    // (`Status::walk_dispatches`, `size_walk_passes` in bindings.wgsl).
    /// The grid's buckets.
    WalkBuckets,
    /// One workgroup of `SCAN_BLOCK` per block of `SCAN_SPAN` buckets.
    WalkScanBlocks,
    /// The bodies.
    WalkBodies,
    /// One workgroup of `SCAN_BLOCK` per block of `SCAN_SPAN` bodies.
    WalkBodyScanBlocks,
    /// A single workgroup.
    WalkOne,
    /// The bodies where the step walks, a single workgroup where it keeps
    /// its list: `pairs_count` and `contact_lists`, whose first invocations'
    /// parts run every step (the lists of a kept step stand).
    WalkBodiesOrOne,
}

impl Over {
    /// A walk's dispatch: its place among `Status::walk_dispatches` (the
    /// order `size_walk_passes` in bindings.wgsl writes them in).
    pub(crate) fn walk(self) -> Option<usize> {
        Some(match self {
            Over::WalkBuckets => 0,
            Over::WalkScanBlocks => 1,
            Over::WalkBodies => 2,
            Over::WalkBodyScanBlocks => 3,
            Over::WalkOne => 4,
            Over::WalkBodiesOrOne => 5,
            _ => return None,
        })
    }
}

/// What a stage does with the pose buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Poses {
    /// Reads the current state only.
    Read,
    /// Reads the current state and writes the other (state_out), which then
    /// becomes current.
    Flip,
    /// Edits the current state in place: it is bound through the bind group
    /// whose state_out is the current state (the one the pass before it
    /// wrote), and nothing flips.
    InPlace,
}

/// When a stage runs within a step (`World::step_plan`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Runs {
    /// Once a step, before the substeps, in the table's order.
    EachStep,
    /// Once a step, where a body is a hull.
    EachStepWithHulls,
    /// Once a step, where the grid's scan spans more than one block of
    /// `SCAN_SPAN` buckets: the scan's first pass finishes a scan of one.
    EachStepOverManyBuckets,
    /// Once a step, where the pairs' scan spans more than one block of
    /// `SCAN_SPAN` bodies.
    EachStepOverManyBodies,
    /// In every substep, where `World::step_plan` places it.
    InSubsteps,
}

/// The parts of a step, as the bench and the profile sum them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    Broadphase,
    Narrowphase,
    Integrate,
    Solve,
    Restitution,
}

/// One row of the table: a stage as the host sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StageInfo {
    pub stage: Stage,
    /// The label of its compute pass and its bind group.
    pub name: &'static str,
    /// Its WGSL entry point: named like the stage, but for the scan passes,
    /// which grid.wgsl holds once for the grid and the pairs.
    pub entry_point: &'static str,
    /// The WGSL files its module is made of, in order (src/gpu/shaders.rs).
    pub pieces: &'static [&'static str],
    /// Override constants of its own (besides the ones every stage gets).
    pub constants: &'static [(&'static str, f64)],
    pub over: Over,
    pub poses: Poses,
    pub runs: Runs,
    /// The buffers the entry point reads and writes: every buffer its code
    /// can touch, as naga's analysis finds it (tests/gpu/shaders.rs checks
    /// both lists), so a branch not taken counts. An atomic is a read and a
    /// write; `arrayLength` is a read (the buffer must be bound).
    pub reads: &'static [Buffer],
    pub writes: &'static [Buffer],
    /// The indirect dispatch sizes copied out of the status record before
    /// the stage runs, and after: a copy cannot sit inside a compute pass,
    /// so the step's passes are split there (`World::encode_step`).
    pub copy_before: &'static [Over],
    pub copy_after: &'static [Over],
    /// Buffers filled with zeros once the stage has run (outside any
    /// compute pass, as the copies).
    pub clear_after: &'static [Buffer],
    pub part: Part,
}

impl StageInfo {
    /// A row with the commonest values, for the table to override.
    const fn row(stage: Stage, name: &'static str, pieces: &'static [&'static str], part: Part) -> StageInfo {
        StageInfo {
            stage,
            name,
            entry_point: name,
            pieces,
            constants: &[],
            over: Over::Bodies,
            poses: Poses::Read,
            runs: Runs::EachStep,
            reads: &[],
            writes: &[],
            copy_before: &[],
            copy_after: &[],
            clear_after: &[],
            part,
        }
    }
}

/// Every stage, in the order of `Stage` (checked as the table is built).
pub(crate) const TABLE: [StageInfo; 26] = {
    use shaders::{GRID_PASS, INTEGRATE_PASS, NARROWPHASE_PASS, PAIRS_PASS, RESTITUTION_PASS, SOLVE_PASS};
    use Buffer::*;
    use Part::{Broadphase, Narrowphase};
    use StageInfo as S;
    // grid.wgsl's scans, for the grid's buckets or (SCAN_PAIRS) the bodies' pair counts
    const SCAN_BLOCKS_READS: &[Buffer] = &[Params, CellCount, CellStart, Pairs, Status, PairMeta];
    const SCAN_SUMS_READS: &[Buffer] = &[Params, BlockSums, Pairs, Status];
    const SCAN_WRITES: &[Buffer] = &[CellStart, BlockSums, Status, PairMeta];
    const SCAN_PAIRS: &[(&str, f64)] = &[("SCAN_PAIRS", 1.0)];
    const POOL_WRITES: &[Buffer] = &[Manifolds, Status, PairMeta, BodyPairs, Points, Points1, Points2, Points3];
    const SNAP_WRITES: &[Buffer] = &[Snaps, Points, Points1, Points2, Points3, Snaps1];
    const JOINT_READS: &[Buffer] = &[Params, Props, StateOut, JointStart, JointRefs];
    let table = [
        S {
            reads: &[Params, Props, StateIn, CellCount, Status, Sorted, PairMeta, CellBounds, Hulls],
            writes: &[CellCount, Status, PairMeta],
            // what the walk's passes are over this step, sized as the pass ends
            copy_after: &[
                Over::WalkBuckets,
                Over::WalkScanBlocks,
                Over::WalkBodies,
                Over::WalkBodyScanBlocks,
                Over::WalkOne,
                Over::WalkBodiesOrOne,
            ],
            ..S::row(Stage::GridCount, "grid_count", GRID_PASS, Broadphase)
        },
        S {
            entry_point: "scan_blocks",
            over: Over::WalkScanBlocks,
            reads: SCAN_BLOCKS_READS,
            writes: SCAN_WRITES,
            ..S::row(Stage::GridScanBlocks, "grid_scan_blocks", GRID_PASS, Broadphase)
        },
        S {
            entry_point: "scan_sums",
            over: Over::WalkOne,
            runs: Runs::EachStepOverManyBuckets,
            reads: SCAN_SUMS_READS,
            writes: SCAN_WRITES,
            ..S::row(Stage::GridScanSums, "grid_scan_sums", GRID_PASS, Broadphase)
        },
        S {
            entry_point: "scan_add",
            over: Over::WalkBuckets,
            runs: Runs::EachStepOverManyBuckets,
            reads: &[Params, CellStart, BlockSums],
            writes: &[CellStart],
            ..S::row(Stage::GridScanAdd, "grid_scan_add", GRID_PASS, Broadphase)
        },
        S {
            over: Over::WalkBodies,
            reads: &[Params, Props, StateIn, CellCount, CellStart],
            writes: &[CellCount, Sorted],
            ..S::row(Stage::GridScatter, "grid_scatter", GRID_PASS, Broadphase)
        },
        S {
            over: Over::WalkBodies,
            reads: &[Params, Props, StateIn, CellStart, Sorted, PairMeta, Hulls],
            writes: &[Sorted, CellBounds],
            ..S::row(Stage::GridSort, "grid_sort", GRID_PASS, Broadphase)
        },
        S {
            // its first invocation's part runs every step (`status.kept`)
            over: Over::WalkBodiesOrOne,
            reads: &[Params, Props, StateIn, CellStart, Sorted, Pairs, Status, PairMeta, BodyPairs, CellBounds, Hulls],
            writes: &[Sorted, Pairs, Status, PairMeta, BodyPairs],
            ..S::row(Stage::PairsCount, "pairs_count", PAIRS_PASS, Narrowphase)
        },
        S {
            entry_point: "scan_blocks",
            constants: SCAN_PAIRS,
            over: Over::WalkBodyScanBlocks,
            reads: SCAN_BLOCKS_READS,
            writes: SCAN_WRITES,
            ..S::row(Stage::PairsScanBlocks, "pairs_scan_blocks", GRID_PASS, Narrowphase)
        },
        S {
            entry_point: "scan_sums",
            constants: SCAN_PAIRS,
            over: Over::WalkOne,
            runs: Runs::EachStepOverManyBodies,
            reads: SCAN_SUMS_READS,
            writes: SCAN_WRITES,
            ..S::row(Stage::PairsScanSums, "pairs_scan_sums", GRID_PASS, Narrowphase)
        },
        S {
            over: Over::WalkBodies,
            reads: &[Params, Props, StateIn, CellStart, BlockSums, Sorted, Pairs, Status, PairMeta, BodyPairs, CellBounds, Hulls],
            writes: &[Pairs, Status, PairMeta, BodyPairs],
            ..S::row(Stage::PairsWrite, "pairs_write", PAIRS_PASS, Narrowphase)
        },
        S {
            over: Over::Pairs,
            reads: &[Params, Props, StateIn, Pairs, Manifolds, Status, JointStart, JointRefs, PairMeta, BodyPairs, Points],
            writes: POOL_WRITES,
            // the pair scan's last pass wrote it: the grid's or the pairs' sums where they run
            copy_before: &[Over::Pairs],
            ..S::row(Stage::Narrowphase, "narrowphase", NARROWPHASE_PASS, Narrowphase)
        },
        S {
            over: Over::Pairs,
            runs: Runs::EachStepWithHulls,
            reads: &[Params, Props, StateIn, Pairs, Manifolds, Status, JointStart, JointRefs, PairMeta, BodyPairs, Points, Hulls],
            writes: POOL_WRITES,
            ..S::row(Stage::NarrowphaseHull, "narrowphase_hull", NARROWPHASE_PASS, Narrowphase)
        },
        S {
            // a kept list is empty: no ground pair to test
            over: Over::WalkBodies,
            reads: &[Params, Props, StateIn, Pairs, Manifolds, Status, PairMeta, BodyPairs, Points],
            writes: POOL_WRITES,
            ..S::row(Stage::NarrowphaseGround, "narrowphase_ground", NARROWPHASE_PASS, Narrowphase)
        },
        S {
            over: Over::WalkBodiesOrOne,
            reads: &[Params, Props, StateIn, Manifolds, Status, JointStart, PairMeta, BodyPairs],
            writes: &[Sorted, Status, PairMeta, BodyPairs],
            // once, for every contact and body pass of the step's substeps
            copy_after: &[Over::Manifolds, Over::Listed, Over::Touching],
            // what grid_count counted on a step that kept its list, which no
            // scatter took back: the next step counts from 0
            clear_after: &[CellCount],
            ..S::row(Stage::ContactLists, "contact_lists", NARROWPHASE_PASS, Narrowphase)
        },
        S {
            over: Over::Manifolds,
            reads: &[Params, Props, StateIn, Manifolds, Status, PairMeta, Points],
            writes: &[Manifolds, PairMeta, Points, Points1, Points2, Points3],
            ..S::row(Stage::NarrowphaseClip, "narrowphase_clip", NARROWPHASE_PASS, Narrowphase)
        },
        S {
            over: Over::Listed,
            poses: Poses::Flip,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateIn, Sorted, Status, JointStart, PairMeta, Snaps, BodyPairs, Snaps1],
            writes: &[StateOut, Vel0, Status, PairMeta],
            ..S::row(Stage::Integrate, "integrate", INTEGRATE_PASS, Part::Integrate)
        },
        S {
            over: Over::Manifolds,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateIn, Snaps, Manifolds, Status, PairMeta, Points, Points1, Points2, Points3, JointStart],
            writes: SNAP_WRITES,
            ..S::row(Stage::SolveContacts, "solve_contacts", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::Touching,
            poses: Poses::InPlace,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateOut, Sorted, Snaps, PairMeta, BodyPairs, JointStart, Snaps1, Manifolds, Hulls, Status],
            writes: &[StateOut, Status],
            ..S::row(Stage::Solve, "solve", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::Islands,
            runs: Runs::InSubsteps,
            reads: &[Params],
            writes: &[IslandRest],
            ..S::row(Stage::JointRestClear, "joint_rest_clear", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::IslandJoints,
            poses: Poses::InPlace,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateOut, JointStart, JointRefs, IslandRest],
            writes: &[IslandRest],
            ..S::row(Stage::JointRestGather, "joint_rest_gather", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::IslandJoints,
            poses: Poses::InPlace,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, JointStart, JointRefs, IslandRest],
            writes: &[StateOut],
            ..S::row(Stage::JointRest, "joint_rest", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::Paths,
            poses: Poses::InPlace,
            runs: Runs::InSubsteps,
            reads: JOINT_READS,
            writes: &[StateOut],
            ..S::row(Stage::SolveJoints, "solve_joints", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::Paths,
            poses: Poses::InPlace,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateOut, Status, JointStart, JointRefs, PathScratch],
            writes: &[StateOut, Status, PathScratch],
            ..S::row(Stage::SolvePaths, "solve_paths", SOLVE_PASS, Part::Solve)
        },
        S {
            over: Over::Manifolds,
            runs: Runs::InSubsteps,
            reads: &[
                Params, Props, StateIn, Vel0, Snaps, Manifolds, Status, PairMeta, Points, Points1, Points2, Points3, JointStart,
            ],
            writes: SNAP_WRITES,
            ..S::row(Stage::RestitutionContacts, "restitution_contacts", RESTITUTION_PASS, Part::Restitution)
        },
        S {
            over: Over::Listed,
            poses: Poses::Flip,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateIn, Sorted, Snaps, PairMeta, BodyPairs, Snaps1],
            writes: &[StateOut],
            ..S::row(Stage::Restitution, "restitution", RESTITUTION_PASS, Part::Restitution)
        },
        S {
            // in place of `restitution` where no body sleeps (`World::step_plan`)
            over: Over::Touching,
            poses: Poses::InPlace,
            runs: Runs::InSubsteps,
            reads: &[Params, Props, StateOut, Sorted, Snaps, PairMeta, BodyPairs, Snaps1],
            writes: &[StateOut],
            ..S::row(Stage::RestitutionInPlace, "restitution_in_place", RESTITUTION_PASS, Part::Restitution)
        },
    ];
    // each row sits at its stage's index
    let mut k = 0;
    while k < table.len() {
        assert!(table[k].stage as usize == k, "TABLE is out of the order of Stage");
        k += 1;
    }
    table
};

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; TABLE.len()] = {
        let mut all = [Stage::GridCount; TABLE.len()];
        let mut k = 0;
        while k < all.len() {
            all[k] = TABLE[k].stage;
            k += 1;
        }
        all
    };

    /// Its row of the table.
    pub(crate) fn info(self) -> &'static StageInfo {
        &TABLE[self as usize]
    }

    /// The label of its compute pass; its entry point but for the scans.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    pub fn entry_point(self) -> &'static str {
        self.info().entry_point
    }

    pub(crate) fn pieces(self) -> &'static [&'static str] {
        self.info().pieces
    }

    /// Its module's source: the shared constants, then its pieces.
    pub fn source(self) -> String {
        shaders::shared_constants() + &self.pieces().concat()
    }

    pub fn reads(self) -> &'static [Buffer] {
        self.info().reads
    }

    pub fn writes(self) -> &'static [Buffer] {
        self.info().writes
    }

    /// The buffers it binds (what it reads or writes), by binding: its bind
    /// group layout holds these alone.
    pub(crate) fn buffers(self) -> Vec<Buffer> {
        Buffer::ALL.iter().copied().filter(|b| self.reads().contains(b) || self.writes().contains(b)).collect()
    }

    pub(crate) fn over(self) -> Over {
        self.info().over
    }

    pub(crate) fn poses(self) -> Poses {
        self.info().poses
    }

    /// The part of the step it belongs to, as the bench and the profile sum them.
    pub fn part(self) -> Part {
        self.info().part
    }

    /// Whether the stage is part of the grid broadphase (`grid_*`).
    pub fn is_broadphase(self) -> bool {
        self.part() == Part::Broadphase
    }
}
