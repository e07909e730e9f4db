//! The status record: what the step's kernels report to the host and hand
//! each other across passes (binding 12, `status` in shaders/bindings.wgsl).
//! WGSL sees it as an array of atomic words and indexes it by the
//! `STATUS_*` constants written from `Status::WORDS`, so its layout is
//! written once, here.

use std::mem::{offset_of, size_of};

use bytemuck::{Pod, Zeroable};

use crate::limits::NO_FAULT;

/// How many sizes the passes that run only where a step walks for pairs
/// take (`Status::walk_dispatches`).
pub const WALK_DISPATCHES: usize = 6;

/// The status words, in buffer order (200 bytes). The host reads it back
/// after each batch of steps (`World::fit_pools`), and on request.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct Status {
    /// Candidate pairs the pair scan found this step (the list keeps those that fit).
    pub pairs: u32,
    /// Most candidate pairs any step wanted since the host last cleared it (after each batch).
    pub pairs_max: u32,
    /// The first numerical fault: 8 x body + `FAULT_*` of the lowest body found bad, atomicMin-ed.
    pub fault: u32,
    /// The `step_index` of the step that found that fault, atomicMin-ed.
    pub fault_step: u32,
    /// Manifolds the narrowphase asked the pool for this step (those past its end are counted, not stored).
    pub manifolds: u32,
    /// Most manifolds any step wanted since the host last cleared it (after each batch).
    pub manifolds_max: u32,
    /// Of them, the face contacts left for `narrowphase_clip`, taken from the top of the pool.
    pub manifolds_top: u32,
    /// The others, taken from the bottom of the pool.
    pub manifolds_bottom: u32,
    /// The narrowphase's indirect dispatch over the pairs (x, y, z; `write_dispatch`), written by
    /// the pair scan and copied out before the narrowphase.
    pub pairs_dispatch: [u32; 3],
    /// 1 if a grid body sleeps this step (grid_count sets it, contact_lists clears it; pairs.wgsl's walks read it).
    pub grid_sleeps: u32,
    /// The contact passes' indirect dispatch over the manifolds, written by contact_lists and
    /// copied out after it.
    pub manifolds_dispatch: [u32; 3],
    /// 1 if a body moves or is due to wake after the step (integrate sets it, grid_count clears it):
    /// 0 after a batch and the world is at rest (`World::at_rest`).
    pub moving: u32,
    /// Bodies the step's body passes run over (`listed_body`), listed by contact_lists.
    pub listed: u32,
    /// Their indirect dispatch (workgroups over them, 1, 1), counted by contact_lists and copied
    /// out after it.
    pub listed_dispatch: [u32; 3],
    /// Of them, the bodies with contacts, which `solve` runs over (`touching_body`), listed by
    /// contact_lists.
    pub touching: u32,
    /// Their indirect dispatch, counted and copied as `listed_dispatch` is.
    pub touching_dispatch: [u32; 3],
    /// 1 if the last pair walks found a pair within `keep_margin` more than
    /// the contact margin, a fast body or a body near the ground (bindings.wgsl's
    /// `pairs_kept`): contact_lists sets it from `near_now` after a step that walked.
    pub near: u32,
    /// What this step's walks found of that (pairs_count sets it).
    pub near_now: u32,
    /// 1 if this step builds the grid and walks for pairs: `near` as the
    /// last step left it (contact_lists), or set by grid_count where a body's
    /// grown box left the bounds the last walks saw by half `keep_margin`, or
    /// its `moves` changed. 0: the step keeps the last pair list, empty.
    pub walk: u32,
    /// The indirect dispatches of the passes that run only where the step
    /// walks (`Over::walk` orders them): at full size once the step
    /// walks (grid_count), none as the step ends (contact_lists; one
    /// workgroup for contact_lists itself); copied out after grid_count.
    pub walk_dispatches: [[u32; 3]; WALK_DISPATCHES],
    /// 1 once a pair walk took so many loop trips that the driver may have cut it short (LOOP_TRIPS); never cleared.
    pub walks_cut: u32,
    /// 1 once a contact list's sort may have been cut short alike (contact_lists); never cleared.
    pub lists_cut: u32,
    /// The sweeps the substep has run so far (integrate clears it, solve
    /// counts them): which weight solve_contacts gives its pushes
    /// (solve.wgsl's `sweep_weight`).
    pub sweeps: u32,
    /// 1 if the substep's second `solve_paths` has work: the contacts
    /// pushed a jointed body (`solve`), or a first solve closed a gap wider
    /// than `PATH_RECHECK` (solve.wgsl); integrate clears it.
    pub paths_again: u32,
    /// 1 if this step keeps the last walks' pair list, empty (`pairs_kept`),
    /// and with it the body lists contact_lists made then: pairs_count sets
    /// it for contact_lists, whose first invocation sets `walk` for the next step.
    pub kept: u32,
}

/// The word index of a field of `Status`.
macro_rules! word {
    ($field:ident) => {
        (offset_of!(Status, $field) / 4) as u32
    };
}

impl Status {
    /// Its size in bytes, as the buffer is made and copied.
    pub const BYTES: u64 = size_of::<Status>() as u64;

    /// As the buffer is made: no pairs or manifolds yet (the maxima are
    /// atomicMax-ed from 0), no fault (atomicMin-ed from `NO_FAULT`), and
    /// the dispatches' unused dimensions at 1.
    pub const INIT: Status = Status {
        pairs: 0,
        pairs_max: 0,
        fault: NO_FAULT,
        fault_step: NO_FAULT,
        manifolds: 0,
        manifolds_max: 0,
        manifolds_top: 0,
        manifolds_bottom: 0,
        pairs_dispatch: [0, 1, 1],
        grid_sleeps: 0,
        manifolds_dispatch: [0, 0, 0],
        moving: 0,
        listed: 0,
        listed_dispatch: [0, 1, 1],
        touching: 0,
        touching_dispatch: [0, 1, 1],
        // no walk yet: the first step walks
        near: 1,
        near_now: 0,
        walk: 1,
        walk_dispatches: [[0, 1, 1]; WALK_DISPATCHES],
        walks_cut: 0,
        lists_cut: 0,
        sweeps: 0,
        paths_again: 0,
        kept: 0,
    };

    /// The WGSL name and the first word of every field, in order: the
    /// shared constants (`shaders::shared_constants`) by which WGSL indexes
    /// the status words.
    pub const WORDS: [(&'static str, u32); 25] = [
        ("STATUS_PAIRS", word!(pairs)),
        ("STATUS_PAIRS_MAX", word!(pairs_max)),
        ("STATUS_FAULT", word!(fault)),
        ("STATUS_FAULT_STEP", word!(fault_step)),
        ("STATUS_MANIFOLDS", word!(manifolds)),
        ("STATUS_MANIFOLDS_MAX", word!(manifolds_max)),
        ("STATUS_MANIFOLDS_TOP", word!(manifolds_top)),
        ("STATUS_MANIFOLDS_BOTTOM", word!(manifolds_bottom)),
        ("STATUS_PAIRS_DISPATCH", word!(pairs_dispatch)),
        ("STATUS_GRID_SLEEPS", word!(grid_sleeps)),
        ("STATUS_MANIFOLDS_DISPATCH", word!(manifolds_dispatch)),
        ("STATUS_MOVING", word!(moving)),
        ("STATUS_LISTED", word!(listed)),
        ("STATUS_LISTED_DISPATCH", word!(listed_dispatch)),
        ("STATUS_TOUCHING", word!(touching)),
        ("STATUS_TOUCHING_DISPATCH", word!(touching_dispatch)),
        ("STATUS_NEAR", word!(near)),
        ("STATUS_NEAR_NOW", word!(near_now)),
        ("STATUS_WALK", word!(walk)),
        ("STATUS_WALK_DISPATCHES", word!(walk_dispatches)),
        ("STATUS_WALKS_CUT", word!(walks_cut)),
        ("STATUS_LISTS_CUT", word!(lists_cut)),
        ("STATUS_SWEEPS", word!(sweeps)),
        ("STATUS_PATHS_AGAIN", word!(paths_again)),
        ("STATUS_KEPT", word!(kept)),
    ];
}

/// Where the rows (y) and the third dimension (z) sit among an indirect
/// dispatch's three words (x, y, z, as wgpu reads them): `write_dispatch`
/// in bindings.wgsl writes a triple of `Status` by them.
pub const DISPATCH_Y: u32 = 1;
pub const DISPATCH_Z: u32 = 2;
