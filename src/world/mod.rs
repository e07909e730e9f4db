//! `World`: a scene's bodies living on the GPU, stepped by the passes of
//! `step` in batches, read back only on request.
//!
//! The type and its stepping API are here; the rest of the world is split
//! by job: `buffers` (the GPU buffers and bind groups), `capacity` (what an
//! adapter holds), `pools` (the contact pools following the need),
//! `encode` (a step's plan and dispatches), `status` (what the GPU
//! reports), `readback`, `profile`, and the scene's records, inputs, edits
//! and snapshots.

use std::sync::Arc;

use crate::gpu::status::Status;
use crate::gpu::{types::*, Gpu};
use crate::scene::{Scene, Settings};
use crate::step::{Contents, StepPipelines};
use crate::Error;

mod buffers;
mod capacity;
mod edit;
mod encode;
#[allow(dead_code)] // read by the hull narrowphase to come
mod hull_records;
pub mod input;
mod pools;
mod profile;
mod readback;
mod records;
pub mod snapshot;
mod status;

use buffers::{Statics, WorldData};
use pools::PoolWatch;

pub use capacity::{
    body_bytes, bytes_per_body, manifold_bytes, max_bodies, pair_bytes, pair_capacities, MANIFOLDS_PER_BODY, PAIRS_PER_BODY,
};
pub(crate) use hull_records::hull_key;
pub use pools::SHRINK_AFTER_STEPS;
pub use profile::StageTimes;
pub use readback::BodyOutput;
pub use records::{initial_state, joint_gaps, plan_grid, GridLayout};
pub(crate) use records::{joint_lists, local_anchor, scene_props};
pub use status::ContactReport;

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
    /// The joints of the islands' lists: `joint_rest` runs one invocation
    /// for each.
    island_joints: u32,
    /// Where each colour of the joint paths begins, and after the last its
    /// end (`JointLists::colours`): `solve_joints` and `solve_paths` run once per colour.
    path_colours: Vec<u32>,
    /// Whether some paths are swept (`solve_joints` runs), and whether some
    /// are solved directly (`solve_paths` runs): `JointLists::path_kinds`.
    path_kinds: (bool, bool),
    /// Whether the bodies' speed limits (`BodyProps::speed_limit`, from the
    /// scene's energy) still hold: no input, edit or restore since.
    speed_limits: bool,
    /// Which of `data.states` holds the current state.
    current: usize,
    step: u64,
    time: f64,
    /// Length of the last (sub)step taken (s): what `disp` spans.
    dt_prev: f32,
    /// The user-input kernels' buffers and bind groups (`input.rs`), made
    /// on the first input and again on the first after an edit.
    input: Option<input::InputGpu>,
    /// The scene as loaded or last edited (`edit.rs` edits it).
    scene: Scene,
    /// How full the contact pools got (`World::fit_pools`).
    pools: PoolWatch,
    /// Nothing moved in the last step taken and no sleeper is due to wake
    /// (`Status::moving`, read by `fit_pools`), and no input, edit or
    /// restore came since: every body is asleep or fixed, and each step
    /// would leave every pose as it is, so `step_with` only counts the steps.
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
        capacity::check_capacity(&gpu, n)?;
        let joints = joint_lists(scene);
        if scene.settings.sleeping {
            capacity::check_islands(&gpu, &joints, n)?;
        }
        let settings = scene.settings;
        let (props, large, grid, hulls) = scene_props(scene);
        let states: Vec<BodyState> = scene.bodies.iter().map(|b| initial_state(b, &settings)).collect();
        let mut data =
            WorldData::new(&gpu, n, &props, &states, &Statics { large: &large, hulls: &hulls, joints: &joints }, settings.substeps);
        let (_, manifold_capacity) = pair_capacities(&gpu, n.max(1) as u64);
        let pipelines = StepPipelines::new(&gpu, capacity::pool_in_parts(&gpu, manifold_capacity), Contents::of(scene));
        data.bind_groups = Some(data.step_bind_groups(&gpu.device, &pipelines));
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
            island_joints: joints.island_joints(n),
            path_colours: joints.colours.clone(),
            path_kinds: joints.path_kinds(),
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

    /// The grid the broadphase uses.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn grid(&self) -> GridLayout {
        self.grid
    }

    /// The buffer holding the current poses (for drawing without readback).
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn current_state_buffer(&self) -> &wgpu::Buffer {
        &self.data.states[self.current]
    }

    /// Bytes of GPU memory the world's buffers hold now: what `with_gpu`
    /// allocated, with the pair list and the manifold pool as they have
    /// grown, and the input kernels' buffers once an input was given.
    pub fn gpu_bytes(&self) -> u64 {
        self.data.bytes() + self.input.as_ref().map_or(0, |i| i.gpu_bytes())
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

    /// Takes `steps` steps of `settings.dt`. Refuses a count that would take
    /// the world past `limits::MAX_STEPS` steps or `limits::MAX_TIME`
    /// seconds, before taking any.
    pub fn step(&mut self, steps: u64) -> Result<(), Error> {
        let dt = self.settings.dt;
        self.check_steps("steps", steps, steps as f64 * dt as f64)?;
        let mut left = steps;
        while left > 0 {
            if self.at_rest {
                // nothing moves: count the steps at once, not a batch at a
                // time (a count near u64::MAX must not loop)
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
        // each dt as the scene loader checks a scene's (a run of equal ones once:
        // the check walks the bodies)
        for (k, &dt) in dts.iter().enumerate() {
            if k > 0 && dt.to_bits() == dts[k - 1].to_bits() {
                continue;
            }
            if let Some(why) = crate::scene::step_dt_problem(dt, &self.scene) {
                return Err(Error::Input(format!("dts[{k}]: {why}")));
            }
        }
        self.check_steps("dts", dts.len() as u64, dts.iter().map(|&d| d as f64).sum())?;
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
            // a batch whose pools overflowed is taken again once they grew:
            // which contacts found room depended on thread timing
            while self.fit_pools(chunk.len())? {
                self.restore_batch_start(start);
                self.encode_and_submit(chunk, substeps);
            }
        }
        Ok(())
    }

    /// Refuses `steps` more steps lasting `seconds` in all where they would
    /// take the step count past `MAX_STEPS` or the time past `MAX_TIME`
    /// (`name` is the argument that gave them).
    fn check_steps(&self, name: &str, steps: u64, seconds: f64) -> Result<(), Error> {
        use crate::limits::{MAX_STEPS, MAX_TIME};
        if steps > MAX_STEPS - self.step.min(MAX_STEPS) {
            return Err(Error::Input(format!(
                "{name}: {steps} more steps would take the world ({} steps so far) past {MAX_STEPS}, the most it counts",
                self.step
            )));
        }
        if self.time + seconds > MAX_TIME {
            return Err(Error::Input(format!(
                "{name}: {steps} more steps ({seconds:e} s) would take the world ({:e} s so far) past {MAX_TIME:e} s, the \
                 latest it reaches",
                self.time
            )));
        }
        Ok(())
    }

    /// Where the next batch starts from, on the host's side: which state
    /// buffer is current, the step count, the time and the last substep's
    /// length (the GPU's side is copied by `copy_batch_start`).
    fn batch_start(&self) -> BatchStart {
        BatchStart { current: self.current, step: self.step, time: self.time, dt_prev: self.dt_prev }
    }

    /// Puts the world back where a batch started (`batch_start` and the
    /// copies `copy_batch_start` made), to take the batch again.
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
        encoder.copy_buffer_to_buffer(status, 0, &self.data.status, 0, Status::BYTES);
        self.gpu.submit(encoder.finish());
        // the grid and the bounds the walks saw are the batch's later ones: walk again
        let walk = std::mem::offset_of!(Status, walk) as u64;
        self.gpu.queue.write_buffer(&self.data.status, walk, bytemuck::bytes_of(&1u32));
    }

    /// Counts `steps` steps of `dt` of a world at rest (`at_rest`): what
    /// `step_with` does for each batch of them, in one go.
    fn skip_at_rest(&mut self, steps: u64, dt: f32) -> Result<(), Error> {
        self.skipped = true;
        self.note_wants([0, 0], usize::try_from(steps).unwrap_or(usize::MAX));
        self.shrink_pools()?;
        self.dt_prev = dt / self.settings.substeps as f32;
        self.step += steps;
        self.time += steps as f64 * dt as f64;
        Ok(())
    }

    /// Advances the host's step count, time and last substep past `dts`.
    fn finish_steps(&mut self, dts: &[f32], substeps: usize) {
        self.dt_prev = dts.last().map_or(self.dt_prev, |&dt| dt / substeps as f32);
        self.step += dts.len() as u64;
        self.time += dts.iter().map(|&d| d as f64).sum::<f64>();
    }
}
