//! What the host reads of the status record (`gpu::status::Status`): how
//! full the contact pools got, and the first numerical fault.

use std::mem::offset_of;

use super::World;
use crate::gpu::status::Status;
use crate::limits::{Fault, NO_FAULT};
use crate::Error;

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

impl ContactReport {
    /// Whether any step so far found more pairs or manifolds than fit.
    pub fn overflowed(&self) -> bool {
        self.dropped
    }
}

impl World {
    /// How full the pair list and the manifold pool got (a blocking readback).
    pub fn contact_report(&self) -> Result<ContactReport, Error> {
        let batch = self.batch_report_of(&self.read_status()?);
        // a step skipped at rest listed nothing, whatever the pools still hold
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

    /// The status record as the GPU left it (a blocking readback, for tests
    /// and debugging).
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn read_status(&self) -> Result<Status, Error> {
        let bytes = self.gpu.read_buffer(&self.data.status, Status::BYTES)?;
        Ok(bytemuck::pod_read_unaligned(&bytes))
    }

    /// The status record's report: the maxima since `fit_pools` last
    /// cleared them (the last batch, or the one under way).
    pub(super) fn batch_report_of(&self, status: &Status) -> ContactReport {
        let (pair_capacity, manifold_capacity) = self.capacities();
        ContactReport {
            pairs: status.pairs,
            pairs_max: status.pairs_max,
            pair_capacity,
            manifolds: status.manifolds,
            manifolds_max: status.manifolds_max,
            manifold_capacity,
            dropped: status.pairs_max > pair_capacity || status.manifolds_max > manifold_capacity,
            walks_cut: status.walks_cut != 0,
            lists_cut: status.lists_cut != 0,
        }
    }

    /// The first numerical fault since the world was made or
    /// [`World::clear_faults`], if any (a blocking readback; the step loop
    /// never reads it).
    pub fn faults(&self) -> Result<Option<Fault>, Error> {
        let status = self.read_status()?;
        Ok(Fault::decode(status.fault, status.fault_step))
    }

    /// Forgets the recorded fault, so that the next one is reported (the
    /// faulted body stays where it was stopped).
    pub fn clear_faults(&mut self) -> Result<(), Error> {
        self.gpu.check()?;
        for at in [offset_of!(Status, fault), offset_of!(Status, fault_step)] {
            self.gpu.queue.write_buffer(&self.data.status, at as u64, bytemuck::bytes_of(&NO_FAULT));
        }
        Ok(())
    }
}
