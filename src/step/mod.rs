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
//! 5. `solve_contacts`, `solve`, `joint_rest_*`, `solve_joints`, `solve_paths` — the
//!    substep's share of the `iterations` sweeps of corrective snaps: per manifold what it
//!    asks of its bodies, then per body the sum (Jacobi), then (only in scenes with joints;
//!    `joint_rest` in a step's first substep) per colour of joint paths the joints of each island with
//!    a branch or a loop in turn (Gauss-Seidel), and after the substep's first and last
//!    sweeps each chain, or path cut from a larger island, solved directly
//!    (shaders/solve.wgsl)
//! 6. `restitution_contacts`, `restitution` — bounce and dynamic friction, by
//!    rewriting the previous pose, in the same two halves (shaders/restitution.wgsl);
//!    the body half as a pass only after the last substep (the next `integrate`
//!    applies it after the others)
//!
//! Passes 1-3 only read the state; `integrate`, `solve` and `restitution`
//! read one state buffer and write the other, so the current state flips
//! after each of them; the `*_contacts` passes write only the manifolds'
//! snaps and friction budgets. Each stage is one row of `stages::TABLE`;
//! this module holds only the table, the compiled pipelines and their
//! layouts; the buffers live in `World`.

mod buffers;
mod pipelines;
mod stages;

pub use buffers::Buffer;
pub(crate) use pipelines::{storage_buffers, Contents, StepPipelines};
pub(crate) use stages::{Over, Poses, Runs};
pub use stages::{Part, Stage};
