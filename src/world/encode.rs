//! Recording steps: the Params slots of a batch, the plan of a step's
//! dispatches, and their encoding into compute passes. What a stage binds,
//! runs over and does to the poses comes from its row of `step::TABLE`.

use std::mem::{offset_of, size_of};

use super::buffers::{indirect, DISPATCH_BYTES};
use super::World;
use crate::gpu::status::Status;
use crate::gpu::types::*;
use crate::limits::NO_FAULT;
use crate::step::{Over, Poses, Runs, Stage};
use crate::Error;

/// Steps encoded into one submission; each substep gets its own `Params`
/// slot (a uniform buffer read at a dynamic offset), so this sizes the
/// Params buffer.
pub(super) const MAX_BATCH: usize = 64;

impl World {
    /// The Params slots a substep takes: its own, then one per colour of
    /// the joint paths (`solve_joints` and the first `solve_paths` read
    /// their colour's paths from it), and where paths are solved directly
    /// one more per colour for the second `solve_paths` (`Params::second`).
    pub(super) fn slots_per_substep(&self) -> usize {
        1 + self.colour_count() * (1 + usize::from(self.path_kinds.1))
    }

    /// The colours of the joint paths.
    fn colour_count(&self) -> usize {
        self.path_colours.len().saturating_sub(1)
    }

    /// The steps a batch holds: as many as the Params buffer has slots for
    /// (`MAX_BATCH`), at least one (the buffer holds one step's).
    pub(super) fn steps_per_batch(&self) -> usize {
        (MAX_BATCH / (self.settings.substeps as usize * self.slots_per_substep())).max(1)
    }

    /// Writes the Params slots of every substep of `dts` (`slots_per_substep`
    /// each) and returns how many.
    pub(super) fn write_params(&mut self, dts: &[f32], substeps: usize) -> usize {
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
                    path_count: self.path_colours.last().copied().unwrap_or(0),
                    ..Params::default()
                };
                // the substep's own, then one per colour of the joint paths,
                // and one per colour for the second solve of the paths solved directly
                let coloured = self.path_colours.windows(2).map(|w| Params { path_first: w[0], path_end: w[1], ..p });
                let second = coloured.clone().filter(|_| self.path_kinds.1).map(|p| Params { second: 1, ..p });
                for p in std::iter::once(p).chain(coloured).chain(second) {
                    let at = slot * PARAMS_STRIDE as usize;
                    slots[at..at + size_of::<Params>()].copy_from_slice(bytemuck::bytes_of(&p));
                    slot += 1;
                }
                dt_prev = h;
            }
        }
        self.gpu.queue.write_buffer(&self.data.params, 0, &slots);
        slot
    }

    /// Records copies of what a batch starts from on the GPU (see
    /// `WorldData::batch_start`).
    pub(super) fn copy_batch_start(&self, encoder: &mut wgpu::CommandEncoder) {
        let [state, status] = &self.data.batch_start;
        encoder.copy_buffer_to_buffer(&self.data.states[self.current], 0, state, 0, state.size());
        encoder.copy_buffer_to_buffer(&self.data.status, 0, status, 0, Status::BYTES);
    }

    /// Records and submits the steps of `dts`, one batch, after the copies
    /// of what it starts from.
    pub(super) fn encode_and_submit(&mut self, dts: &[f32], substeps: usize) {
        let slot = self.write_params(dts, substeps);

        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("step") });
        self.copy_batch_start(&mut encoder);
        let plan = self.step_plan();
        for first in (0..slot).step_by(substeps * self.slots_per_substep()) {
            self.encode_step(&mut encoder, &plan, first);
        }
        self.gpu.submit(encoder.finish());
        self.finish_steps(dts, substeps);
    }

    /// Records one step's dispatches (`plan`, its substeps' Params from batch
    /// slot `first` on) in as few compute passes as the copies of the
    /// indirect dispatch sizes allow (four): on lavapipe every pass costs
    /// as much as a small dispatch (docs/step.md). `encode_pass` gives each
    /// dispatch a pass of its own, for `profile`'s timestamps.
    fn encode_step(&mut self, encoder: &mut wgpu::CommandEncoder, plan: &[(Stage, usize)], first: usize) {
        let mut pass: Option<wgpu::ComputePass<'static>> = None;
        for &(stage, sub) in plan {
            let info = stage.info();
            if !info.copy_before.is_empty() {
                drop(pass.take());
            }
            self.copy_dispatch_sizes(encoder, stage, true);
            let open = pass.get_or_insert_with(|| {
                encoder
                    .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("step"), timestamp_writes: None })
                    .forget_lifetime()
            });
            self.dispatch(open, stage, first + sub);
            if !info.copy_after.is_empty() || !info.clear_after.is_empty() {
                drop(pass.take());
            }
            self.transfers_after(encoder, stage);
        }
    }

    /// The copies of the indirect dispatch sizes around `stage` (`before`
    /// it runs, or after; `StageInfo::copy_before`, `copy_after`), from the
    /// status words its kernels wrote into the `dispatch` buffer. Outside
    /// any compute pass.
    fn copy_dispatch_sizes(&self, encoder: &mut wgpu::CommandEncoder, stage: Stage, before: bool) {
        let info = stage.info();
        // (sizes side by side in both buffers go in one copy)
        let mut runs: Vec<(u64, u64, u64)> = Vec::new();
        for &over in if before { info.copy_before } else { info.copy_after } {
            let (slot, words) = indirect(over).expect("copied sizes are of an indirect dispatch");
            match runs.last_mut() {
                Some((s, w, len)) if *s + *len == slot && *w + *len == words => *len += DISPATCH_BYTES,
                _ => runs.push((slot, words, DISPATCH_BYTES)),
            }
        }
        for (slot, words, len) in runs {
            encoder.copy_buffer_to_buffer(&self.data.status, words, &self.data.dispatch, slot, len);
        }
    }

    /// What follows `stage` outside any compute pass: the copies of the
    /// dispatch sizes it wrote, then the fills with zeros
    /// (`StageInfo::copy_after`, `clear_after`).
    fn transfers_after(&self, encoder: &mut wgpu::CommandEncoder, stage: Stage) {
        self.copy_dispatch_sizes(encoder, stage, false);
        for &buffer in stage.info().clear_after {
            encoder.clear_buffer(self.data.buffer(buffer, self.current), 0, None);
        }
    }

    /// Records `stage`'s dispatch with the Params of batch slot `slot`, bound
    /// to the current state, and flips the current state if it writes.
    fn dispatch(&mut self, pass: &mut wgpu::ComputePass<'_>, stage: Stage, slot: usize) {
        let offset = [(slot as u64 * PARAMS_STRIDE) as u32];
        pass.set_pipeline(self.pipelines.pipeline(stage));
        let groups = &self.data.bind_groups.as_ref().expect("made with the buffers")[stage as usize];
        let group = if stage.poses() == Poses::InPlace { 1 - self.current } else { self.current };
        pass.set_bind_group(0, &groups[group], &offset);
        match indirect(stage.over()) {
            Some((at, _)) => pass.dispatch_workgroups_indirect(&self.data.dispatch, at),
            None => pass.dispatch_workgroups(self.workgroups(stage.over()), 1, 1),
        }
        if stage.poses() == Poses::Flip {
            self.current = 1 - self.current;
        }
    }

    /// The passes of one step, each with the Params slot it uses within the
    /// step (`slots_per_substep` a substep; `solve_joints` one per colour):
    /// the broadphase and narrowphase once (`Runs`), then for every substep
    /// the integration, its share of the `iterations` sweeps of the solve's
    /// two halves (`Settings::sweeps`) and the restitution's two (the
    /// contacts, kept in the bodies' own frames, serve all substeps).
    // For the crate's own tests and the binary's bench, not part of the guide.
    #[doc(hidden)]
    pub fn step_plan(&self) -> Vec<(Stage, usize)> {
        // a scan of one block is finished by its first pass (grid.wgsl)
        let many_blocks = |len: u32| len > SCAN_SPAN;
        let once = |s: &&Stage| match s.info().runs {
            Runs::EachStep => true,
            // where a body is a hull
            Runs::EachStepWithHulls => self.pipelines.contents().hulls,
            Runs::EachStepOverManyBuckets => many_blocks(self.grid.hash_size),
            Runs::EachStepOverManyBodies => many_blocks(self.body_count),
            Runs::InSubsteps => false,
        };
        let mut plan: Vec<(Stage, usize)> = Stage::ALL.iter().filter(once).map(|&s| (s, 0)).collect();
        let per_substep = self.slots_per_substep();
        for sub in 0..self.settings.substeps as usize {
            let at = sub * per_substep;
            plan.push((Stage::Integrate, at));
            let sweeps = self.settings.sweeps(sub as u32);
            let (swept, direct) = self.path_kinds;
            for sweep in 0..sweeps {
                plan.extend([(Stage::SolveContacts, at), (Stage::Solve, at)]);
                if self.island_count > 0 {
                    // islands sleep as one only where bodies sleep at all, shared in a
                    // step's first substep (integrate lets a jointed body fall asleep there alone)
                    if sub == 0 && sweep == 0 && self.settings.sleeping {
                        plan.extend([Stage::JointRestClear, Stage::JointRestGather, Stage::JointRest].map(|s| (s, at)));
                    }
                    let colours = self.colour_count();
                    if swept {
                        plan.extend((1..=colours).map(|c| (Stage::SolveJoints, at + c)));
                    }
                    // the paths solved directly after a substep's first sweep, and
                    // where needed after its last (both after a single one; solve.wgsl's
                    // solve_paths), the second from the slots after the first's
                    if direct && sweep == 0 {
                        plan.extend((1..=colours).map(|c| (Stage::SolvePaths, at + c)));
                    }
                    if direct && sweep + 1 == sweeps {
                        plan.extend((1..=colours).map(|c| (Stage::SolvePaths, at + colours + c)));
                    }
                }
            }
            plan.push((Stage::RestitutionContacts, at));
            // the next substep's integrate applies what it asks (integrate.wgsl)
            if sub + 1 == self.settings.substeps as usize {
                // where no body sleeps every body is listed in every pass, and
                // one that touches nothing holds its pose as integrate wrote it
                let last = if self.settings.sleeping { Stage::Restitution } else { Stage::RestitutionInPlace };
                plan.push((last, at));
            }
        }
        plan
    }

    /// Records one dispatch of `stage` with the Params of batch slot `slot`
    /// in a compute pass of its own, optionally with timestamps, and flips
    /// the current state if it writes.
    pub(super) fn encode_pass(
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
        self.transfers_after(encoder, stage);
    }

    /// Runs `stages` alone, in order, each as a step's first substep runs it,
    /// and leaves the step count as it was: a way to check one kernel
    /// against a known answer (tests/gpu/kernels.rs), not a way to simulate.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn run_stages(&mut self, stages: &[Stage]) -> Result<(), Error> {
        (self.at_rest, self.skipped) = (false, false);
        self.write_params(&[self.settings.dt], self.settings.substeps as usize);
        if !stages.contains(&Stage::ContactLists) {
            let clears = [Stage::GridScatter, Stage::PairsCount];
            let listed = |s: &Stage| matches!(s.over(), Over::Listed | Over::Touching);
            if stages.iter().any(|s| clears.contains(s)) && stages.iter().any(listed) {
                return Err(Error::Input(
                    "run_stages: grid_scatter and pairs_count overwrite the list of bodies that contact_lists makes".into(),
                ));
            }
            // no lists made: the body passes run over every body (solve passes
            // over those with no contacts itself)
            let n = self.body_count;
            let every: Vec<u32> = (0..n).collect();
            let queue = &self.gpu.queue;
            let all = [self.workgroups(Over::Bodies), 1, 1];
            // the runs of `sorted` after the grid's order (`body_in_run` in bindings.wgsl)
            for (k, over, count) in
                [(1, Over::Listed, offset_of!(Status, listed)), (2, Over::Touching, offset_of!(Status, touching))]
            {
                queue.write_buffer(self.data.sorted(), 4 * k * n as u64, bytemuck::cast_slice(&every));
                queue.write_buffer(&self.data.status, count as u64, bytemuck::bytes_of(&n));
                let (slot, _) = indirect(over).expect("dispatched indirectly");
                queue.write_buffer(&self.data.dispatch, slot, bytemuck::cast_slice(&all));
            }
        }
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("stages") });
        for &stage in stages {
            self.encode_pass(&mut encoder, stage, 0, None);
        }
        self.gpu.submit(encoder.finish());
        Ok(self.gpu.wait()?)
    }

    /// Workgroups of a dispatch the host sizes.
    fn workgroups(&self, over: Over) -> u32 {
        let n = match over {
            Over::Bodies => self.body_count.div_ceil(WORKGROUP),
            Over::Islands => self.island_count.div_ceil(WORKGROUP),
            Over::IslandJoints => self.island_joints.div_ceil(WORKGROUP),
            Over::Paths => self.path_colours.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0).div_ceil(PATH_WORKGROUP),
            _ => unreachable!("dispatched indirectly"),
        };
        n.max(1)
    }
}

/// The damping per substep that removes `beta` per step: 1 - (1 - beta)^(1/n).
fn per_substep(beta: f32, substeps: usize) -> f32 {
    1.0 - (1.0 - beta as f64).powf(1.0 / substeps as f64) as f32
}
