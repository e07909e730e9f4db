//! What an adapter can hold: the most bodies, the contact pools' sizes and
//! their parts, and the bytes a body costs. Pure functions of the adapter's
//! limits and the record sizes, checked before anything is allocated.

use std::mem::size_of;

use super::records::JointLists;
use crate::gpu::{types::*, Gpu};
use crate::step::storage_buffers;
use crate::Error;

/// Candidate pairs the list holds per body at first (pairs a body owns; see
/// shaders/pairs.wgsl): a settled pile of cubes owns about 2.5 a body, and
/// the list grows when a step fills three quarters (`World::fit_pools`).
pub const PAIRS_PER_BODY: u64 = 6;

/// Manifolds the pool holds per body at first (pairs with contact points;
/// about 2.5 in a settled pile, fewer while bodies fall).
pub const MANIFOLDS_PER_BODY: u64 = 3;

/// The fewest entries a pool is made with.
pub(super) const MIN_POOL: u64 = 64;

/// Most pairs, and most manifolds, whatever the bindings hold: a pair's
/// index keeps the top bit free (`list_order` in narrowphase.wgsl), and a
/// manifold's contact references (2 x slot + 1) fit 32 bits.
const MAX_INDEX: u64 = 1 << 31;

/// The pair list's and the manifold pool's sizes for `n` bodies on `gpu`:
/// per body as above; the pair list (and the bodies' lists, two words a
/// pair) within one storage binding, the pool within its parts'
/// (`pool_parts`). The passes over them are dispatched indirectly, in rows
/// (`write_dispatch` in bindings.wgsl), and wgpu's check of an indirect
/// dispatch's size is off (see `Gpu::new`).
pub fn pair_capacities(gpu: &Gpu, n: u64) -> (u64, u64) {
    let binding = binding_limit(gpu);
    let pair_bytes = size_of::<Pair>().max(2 * 4) as u64;
    let pairs = n.saturating_mul(PAIRS_PER_BODY).max(MIN_POOL).min(binding / pair_bytes).min(MAX_INDEX);
    let (points_per_part, snaps_per_part) = pool_part_lengths(gpu);
    let manifolds = n
        .saturating_mul(MANIFOLDS_PER_BODY)
        .max(MIN_POOL)
        .min(binding / size_of::<ContactManifold>() as u64)
        .min(4 * points_per_part)
        .min(2 * snaps_per_part / 2)
        .min(MAX_INDEX);
    (pairs, manifolds)
}

/// Most entries a part of the pool's points and of its snaps holds: one
/// storage binding's worth (bindings.wgsl's `point_of`, `snap_of`).
fn pool_part_lengths(gpu: &Gpu) -> (u64, u64) {
    let binding = binding_limit(gpu);
    (binding / size_of::<ManifoldPoints>() as u64, binding / size_of::<EndSnap>() as u64)
}

/// Whether a pool of `manifolds` slots takes more than one part (the first
/// part of the snaps holds twice the slots of the first part of the points).
pub(super) fn pool_in_parts(gpu: &Gpu, manifolds: u64) -> bool {
    manifolds > pool_part_lengths(gpu).0
}

/// The sizes (bytes) of a pool of `manifolds` slots: its headers, its
/// points' four parts and its snaps' two. Every part but the last used is
/// full; a part not used holds one entry, never read.
pub(super) fn pool_parts(gpu: &Gpu, manifolds: u64) -> (u64, [u64; 4], [u64; 2]) {
    let (points_per_part, snaps_per_part) = pool_part_lengths(gpu);
    let part = |k: u64, total: u64, per: u64| total.saturating_sub(k * per).min(per).max(1);
    let points = size_of::<ManifoldPoints>() as u64;
    let snap = size_of::<EndSnap>() as u64;
    (
        manifolds * size_of::<ContactManifold>() as u64,
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
/// their counts and starts), its places in the lists of bodies the body
/// passes run over, and the copy of the pose a batch of steps starts from.
pub fn body_bytes() -> u64 {
    let state = size_of::<BodyState>() as u64;
    let meta = size_of::<PairMeta>() as u64;
    let grid = 3 * 4 + size_of::<CellBound>() as u64 + 2 * 8;
    3 * state + size_of::<BodyProps>() as u64 + size_of::<Velocity>() as u64 + meta + grid
}

/// Bytes a candidate pair takes: its entry in the pair list and in its two
/// bodies' lists.
pub fn pair_bytes() -> u64 {
    size_of::<Pair>() as u64 + 2 * 4
}

/// Bytes a manifold takes: its slot in the pool and its two snaps.
pub fn manifold_bytes() -> u64 {
    (size_of::<ContactManifold>() + size_of::<ManifoldPoints>() + 2 * size_of::<EndSnap>()) as u64
}

/// The most bodies this GPU can hold: the poses must fit one storage
/// binding, the hash table (up to four buckets per body after rounding to a
/// power of two) too, and a dispatch has a workgroup limit. The pair list
/// and the manifold pool grow within their bindings (see
/// `pair_capacities`); a pool too small for a scene is reported. A body's
/// index must also fit the bits `CellBound::body` keeps for it.
pub fn max_bodies(gpu: &Gpu) -> u64 {
    let per_binding = binding_limit(gpu);
    let by_state = per_binding / size_of::<BodyState>() as u64;
    let by_hash = per_binding / 16;
    let by_groups = gpu.limits.max_compute_workgroups_per_dimension as u64 * WORKGROUP as u64 / 4;
    by_state.min(by_hash).min(by_groups).min(BODY_BITS as u64 + 1)
}

/// Refuses a scene of `n` bodies the adapter cannot hold, or an adapter
/// that cannot bind a pass's buffers, before anything is allocated.
pub(super) fn check_capacity(gpu: &Gpu, n: usize) -> Result<(), Error> {
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
            size_of::<BodyState>(),
            binding_limit(gpu)
        )));
    }
    Ok(())
}

/// Whether `joint_rest` can keep every joint island's rest time (where
/// bodies sleep; it runs only then): its passes take one invocation per
/// joint of the islands, in one row of workgroups.
pub(super) fn check_islands(gpu: &Gpu, joints: &JointLists, bodies: usize) -> Result<(), Error> {
    let most = u64::from(gpu.limits.max_compute_workgroups_per_dimension) * u64::from(WORKGROUP);
    let joined = u64::from(joints.island_joints(bodies));
    if joined > most {
        return Err(Error::Capacity(format!(
            "joints: {joined} joints keep their islands asleep or awake as one, one invocation each, but {} \
             dispatches at most {most} invocations in a row (with settings.sleeping off there is no such limit)",
            gpu.info.name
        )));
    }
    Ok(())
}

/// The most bytes one storage binding of the step may span.
pub(super) fn binding_limit(gpu: &Gpu) -> u64 {
    gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size)
}
