//! The contact pools following the need: the pair list and the manifold
//! pool grow when a batch of steps fills three quarters of either, and
//! shrink when they stay under a quarter, so that contact memory tracks
//! what the scene touches (docs/performance.md, "Contact pools").

use std::mem::{offset_of, size_of};

use super::buffers::storage_buffer;
use super::capacity::{pair_capacities, pool_in_parts, pool_parts, MIN_POOL};
use super::World;
use crate::gpu::status::Status;
use crate::gpu::types::{ContactManifold, Pair};
use crate::Error;

/// A pool that no step of this many in a row filled a quarter of is made
/// twice what the most of them wanted (and no smaller than `MIN_POOL`)
/// before the next batch: a pile that has settled and sleeps (no contacts
/// between sleepers) then holds little more than its bodies. Twice the need
/// sits midway between the quarter and the three quarters that grow it
/// again.
pub const SHRINK_AFTER_STEPS: u64 = 120;

/// The pools' use as the host follows it from batch to batch: the GPU's
/// maxima (`Status::pairs_max`, `Status::manifolds_max`) are cleared after
/// each batch is read, so that they tell what that batch wanted. Index 0:
/// the pair list, 1: the manifold pool.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PoolWatch {
    /// Most any step wanted so far.
    pub peak: [u32; 2],
    /// Whether a step wanted more than its pool held, even once grown.
    pub dropped: bool,
    /// Steps in a row whose wants stayed under a quarter of the pool, and
    /// the most they wanted.
    quiet_steps: [u64; 2],
    quiet_most: [u32; 2],
    /// What to make the pool before the next batch (`World::shrink_pools`).
    shrink_to: [Option<u64>; 2],
}

impl World {
    /// After a batch of `steps` steps (a blocking readback of the status
    /// record): grows a pool that a step filled past three quarters to 1.5
    /// times the most a step used. Returns whether the batch must be taken
    /// again: a step wanted more than a pool held and the pool has grown
    /// (which contacts found room depended on thread timing). A pool at its
    /// limit (`pair_capacities`) stays, its overflow reported by
    /// `contact_report`. Otherwise the batch stands: its wants go to
    /// `pools`, which may mark a pool to shrink, and the GPU's maxima are
    /// cleared for the next batch.
    pub(super) fn fit_pools(&mut self, steps: usize) -> Result<bool, Error> {
        let status = self.read_status()?;
        let report = self.batch_report_of(&status);
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
        let queue = &self.gpu.queue;
        queue.write_buffer(&self.data.status, offset_of!(Status, pairs_max) as u64, bytemuck::bytes_of(&0u32));
        queue.write_buffer(&self.data.status, offset_of!(Status, manifolds_max) as u64, bytemuck::bytes_of(&0u32));
        self.at_rest = status.moving == 0;
        Ok(false)
    }

    /// Adds a batch of `steps` steps that wanted at most `wanted` pairs and
    /// manifolds to `pools`: the peaks, and whether a pool (as it is now, grown
    /// or not) has stayed under a quarter for `SHRINK_AFTER_STEPS` (then it is
    /// marked to shrink to twice the most those steps wanted).
    pub(super) fn note_wants(&mut self, wanted: [u32; 2], steps: usize) {
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

    /// Makes the pools `fit_pools` marked smaller, before a batch: no copy,
    /// since the batch rebuilds them (and nothing reads them before it).
    pub(super) fn shrink_pools(&mut self) -> Result<(), Error> {
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
            remake(&mut self.data.pairs, "pairs", pairs * size_of::<Pair>() as u64);
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
        self.gpu.submit(encoder.finish());
        if pool_in_parts(&self.gpu, manifolds) && !self.pipelines.pool_split {
            // once, for the largest scenes: the passes read and write the parts
            self.pipelines.split_pool(&self.gpu);
        }
        self.data.bind_groups = Some(self.data.step_bind_groups(device, &self.pipelines));
        self.gpu.check()?;
        Ok(())
    }

    /// The pair list's and the manifold pool's capacities now.
    pub(super) fn capacities(&self) -> (u32, u32) {
        let size = |b: &wgpu::Buffer, each: usize| (b.size() / each as u64) as u32;
        (size(&self.data.pairs, size_of::<Pair>()), size(&self.data.manifolds, size_of::<ContactManifold>()))
    }
}
