//! The buffers the step's passes bind, by binding.

use super::Stage;

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
    IslandRest = 23,
    /// The hull records (src/world/hull_records.rs).
    Hulls = 24,
    /// `solve_paths`' elimination along its paths (`PATH_SLOT` vec4 words a path joint).
    PathScratch = 25,
}

impl Buffer {
    pub const ALL: [Buffer; 26] = [
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
        Buffer::IslandRest,
        Buffer::Hulls,
        Buffer::PathScratch,
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
