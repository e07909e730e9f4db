//! `World`: a scene's bodies living on the GPU, stepped by the passes of
//! `step`, read back only on request.

use std::sync::Arc;

use glam::{DQuat, DVec3};

use crate::gpu::{types::*, Gpu};
use crate::scene::{Body, Scene, Settings, Shape};
use crate::step::{Stage, StepPipelines};
use crate::Error;

/// Steps encoded into one submission; each gets its own `Params` slot.
const MAX_BATCH: usize = 64;

/// The state of one body as a user sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyOutput {
    pub position: [f32; 3],
    /// Unit quaternion (x, y, z, w).
    pub orientation: [f32; 4],
    /// Velocities implied by Verlet: (current - previous) / dt (m/s).
    pub linear_velocity: [f32; 3],
    /// World frame (rad/s).
    pub angular_velocity: [f32; 3],
}

/// The GPU buffers of a world. Nothing here is created after start-up.
struct WorldData {
    #[allow(dead_code)]
    props: wgpu::Buffer,
    states: [wgpu::Buffer; 2],
    #[allow(dead_code)]
    vel0: wgpu::Buffer,
    params: wgpu::Buffer,
    /// `bind_groups[k]` reads `states[k]` and writes `states[1 - k]`.
    bind_groups: [wgpu::BindGroup; 2],
}

/// Bytes of GPU memory per body, by buffer.
pub fn bytes_per_body() -> u64 {
    let state = std::mem::size_of::<BodyState>() as u64;
    2 * state + std::mem::size_of::<BodyProps>() as u64 + std::mem::size_of::<Velocity>() as u64
}

pub struct World {
    gpu: Arc<Gpu>,
    pipelines: StepPipelines,
    data: WorldData,
    settings: Settings,
    ground: Option<f32>,
    body_count: u32,
    /// Which of `data.states` holds the current state.
    current: usize,
    step: u64,
    time: f64,
    /// Length of the last (sub)step taken (s): what `pos - prev_pos` spans.
    dt_prev: f32,
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
        check_capacity(&gpu, n)?;
        let settings = scene.settings;
        let device = &gpu.device;
        let count = n.max(1); // wgpu buffers may not be empty

        let props: Vec<BodyProps> = scene.bodies.iter().map(|b| body_props(b, &settings)).collect();
        let states: Vec<BodyState> = scene.bodies.iter().map(|b| initial_state(b, &settings)).collect();
        let props_buf = storage_buffer(&gpu, "props", &props, count, std::mem::size_of::<BodyProps>());
        let make_state = |label| storage_buffer(&gpu, label, &states, count, std::mem::size_of::<BodyState>());
        let state_bufs = [make_state("state A"), make_state("state B")];
        let vel0 = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vel0"),
            size: (count * std::mem::size_of::<Velocity>()) as u64,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: PARAMS_STRIDE * MAX_BATCH as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let pipelines = StepPipelines::new(&gpu);
        let bind_group = |from: usize| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(if from == 0 { "step A->B" } else { "step B->A" }),
                layout: &pipelines.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &params,
                            offset: 0,
                            size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
                        }),
                    },
                    wgpu::BindGroupEntry { binding: 1, resource: props_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: state_bufs[from].as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: state_bufs[1 - from].as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: vel0.as_entire_binding() },
                ],
            })
        };
        let bind_groups = [bind_group(0), bind_group(1)];
        let data = WorldData { props: props_buf, states: state_bufs, vel0, params, bind_groups };
        let substep_dt = settings.dt / settings.substeps as f32;
        Ok(World {
            gpu,
            pipelines,
            data,
            settings,
            ground: scene.ground.as_ref().map(|g| g.height),
            body_count: n as u32,
            current: 0,
            step: 0,
            time: 0.0,
            dt_prev: substep_dt,
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

    /// The buffer holding the current poses (for drawing without readback).
    pub fn current_state_buffer(&self) -> &wgpu::Buffer {
        &self.data.states[self.current]
    }

    /// Takes `steps` steps of `settings.dt`.
    pub fn step(&mut self, steps: u64) -> Result<(), Error> {
        let dt = self.settings.dt;
        let mut left = steps;
        while left > 0 {
            let batch = left.min((MAX_BATCH / self.settings.substeps as usize).max(1) as u64);
            let dts = vec![dt; batch as usize];
            self.step_with(&dts)?;
            left -= batch;
        }
        Ok(())
    }

    /// Takes one step per entry of `dts`, each of that length (s); Verlet's
    /// time correction (eq. 11) carries the motion across changes of dt.
    pub fn step_with(&mut self, dts: &[f32]) -> Result<(), Error> {
        for (k, &dt) in dts.iter().enumerate() {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(Error::Input(format!("dt[{k}]: must be a positive finite number of seconds, got {dt}")));
            }
        }
        let substeps = self.settings.substeps as usize;
        let per_batch = (MAX_BATCH / substeps).max(1);
        for chunk in dts.chunks(per_batch) {
            self.encode_and_submit(chunk, substeps);
        }
        Ok(())
    }

    fn encode_and_submit(&mut self, dts: &[f32], substeps: usize) {
        let s = &self.settings;
        // one Params slot per substep of the batch
        let mut slots = vec![0u8; PARAMS_STRIDE as usize * dts.len() * substeps];
        let mut dt_prev = self.dt_prev;
        let mut slot = 0;
        for &dt in dts {
            let h = dt / substeps as f32;
            for _ in 0..substeps {
                let p = Params {
                    gravity: [s.gravity[0], s.gravity[1], s.gravity[2], self.ground.unwrap_or(0.0)],
                    dt: h,
                    dt_prev,
                    relaxation: s.relaxation,
                    linear_damping: s.linear_damping,
                    angular_damping: s.angular_damping,
                    body_count: self.body_count,
                    has_ground: self.ground.is_some() as u32,
                    ground_restitution: s.restitution,
                    ground_friction: s.friction,
                    ..Default::default()
                };
                let at = slot * PARAMS_STRIDE as usize;
                slots[at..at + std::mem::size_of::<Params>()].copy_from_slice(bytemuck::bytes_of(&p));
                dt_prev = h;
                slot += 1;
            }
        }
        self.gpu.queue.write_buffer(&self.data.params, 0, &slots);

        let groups = self.body_count.div_ceil(WORKGROUP).max(1);
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("step") });
        for slot in 0..slot {
            let offset = [(slot as u64 * PARAMS_STRIDE) as u32];
            let mut run = |stage: Stage, current: &mut usize| {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(stage.label()),
                    timestamp_writes: None,
                });
                pass.set_pipeline(self.pipelines.pipeline(stage));
                pass.set_bind_group(0, &self.data.bind_groups[*current], &offset);
                pass.dispatch_workgroups(groups, 1, 1);
                *current = 1 - *current;
            };
            let mut current = self.current;
            run(Stage::Integrate, &mut current);
            for _ in 0..self.settings.iterations {
                run(Stage::Solve, &mut current);
            }
            run(Stage::Restitution, &mut current);
            self.current = current;
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.dt_prev = dt_prev;
        self.step += dts.len() as u64;
        self.time += dts.iter().map(|&d| d as f64).sum::<f64>();
    }

    /// Reads every body's pose back and derives its velocities.
    pub fn read_raw(&self) -> Result<Vec<BodyState>, Error> {
        let size = (self.body_count.max(1) as usize * std::mem::size_of::<BodyState>()) as u64;
        let bytes = self.gpu.read_buffer(&self.data.states[self.current], size)?;
        let mut states: Vec<BodyState> = bytemuck::pod_collect_to_vec(&bytes);
        states.truncate(self.body_count as usize);
        Ok(states)
    }

    /// Reads every body's state back (a blocking readback).
    pub fn read_state(&self) -> Result<Vec<BodyOutput>, Error> {
        let dt = self.dt_prev as f64;
        let states = self.read_raw()?;
        let out: Vec<BodyOutput> = states.iter().map(|s| body_output(s, dt)).collect();
        if let Some(k) = out.iter().position(|b| !finite_output(b)) {
            return Err(Error::Diverged(format!(
                "body {k} has a non-finite state after step {} (time {:.4} s)",
                self.step, self.time
            )));
        }
        Ok(out)
    }
}

fn finite_output(b: &BodyOutput) -> bool {
    b.position.iter().chain(&b.orientation).chain(&b.linear_velocity).chain(&b.angular_velocity).all(|v| v.is_finite())
}

fn dvec(v: [f32; 4]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

fn dquat(v: [f32; 4]) -> DQuat {
    DQuat::from_xyzw(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64)
}

/// Velocities the Verlet state implies: (current - previous) / dt.
pub fn body_output(s: &BodyState, dt: f64) -> BodyOutput {
    let v = (dvec(s.pos) - dvec(s.prev_pos)) / dt;
    let mut dq = dquat(s.rot) * dquat(s.prev_rot).conjugate();
    if dq.w < 0.0 {
        dq = -dq;
    }
    let w = dq.to_scaled_axis() / dt;
    BodyOutput {
        position: [s.pos[0], s.pos[1], s.pos[2]],
        orientation: s.rot,
        linear_velocity: v.as_vec3().to_array(),
        angular_velocity: w.as_vec3().to_array(),
    }
}

/// The GPU record of a body's shape, mass and material.
pub fn body_props(b: &Body, settings: &Settings) -> BodyProps {
    let (half, shape) = match b.shape {
        Shape::Box { half_extents: h } => ([h[0], h[1], h[2]], SHAPE_BOX),
        Shape::Sphere { radius } => ([radius, radius, radius], SHAPE_SPHERE),
    };
    let ii = b.inverse_inertia();
    BodyProps {
        half_extents: [half[0], half[1], half[2], b.bounding_radius()],
        inv_inertia: [ii[0], ii[1], ii[2], b.inverse_mass()],
        material: [
            b.restitution.unwrap_or(settings.restitution),
            b.friction.unwrap_or(settings.friction),
            0.0,
            0.0,
        ],
        kind: [shape, if b.fixed { FLAG_FIXED } else { 0 }, 0, 0],
    }
}

/// The starting pose, with the previous pose set so that the first Verlet
/// step reproduces the initial velocities exactly: x_prev = x0 - v0 h + g h^2/2
/// makes x1 = x0 + v0 h + g h^2/2, and Verlet then stays on the parabola.
pub fn initial_state(b: &Body, settings: &Settings) -> BodyState {
    let x0 = DVec3::from_array(b.position.map(|v| v as f64));
    let o = b.orientation;
    let q0 = DQuat::from_xyzw(o[0] as f64, o[1] as f64, o[2] as f64, o[3] as f64).normalize();
    let (prev, prev_q) = if b.fixed {
        (x0, q0)
    } else {
        let h = (settings.dt / settings.substeps as f32) as f64;
        let v0 = DVec3::from_array(b.linear_velocity.map(|v| v as f64));
        let w0 = DVec3::from_array(b.angular_velocity.map(|v| v as f64));
        let g = DVec3::from_array(settings.gravity.map(|v| v as f64));
        (x0 - v0 * h + 0.5 * g * h * h, (DQuat::from_scaled_axis(-w0 * h) * q0).normalize())
    };
    let v4 = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
    let q4 = |q: DQuat| [q.x as f32, q.y as f32, q.z as f32, q.w as f32];
    BodyState { pos: v4(x0), prev_pos: v4(prev), rot: q4(q0), prev_rot: q4(prev_q) }
}

fn check_capacity(gpu: &Gpu, n: usize) -> Result<(), Error> {
    let per_binding = gpu.limits.max_storage_buffer_binding_size as u64;
    let largest = std::mem::size_of::<BodyState>().max(std::mem::size_of::<BodyProps>()) as u64;
    let max_by_binding = per_binding / largest;
    let max_by_groups = gpu.limits.max_compute_workgroups_per_dimension as u64 * WORKGROUP as u64;
    let max = max_by_binding.min(max_by_groups);
    if n as u64 > max {
        return Err(Error::Capacity(format!(
            "the scene has {n} bodies but this adapter holds at most {max} \
             (storage binding limit {per_binding} bytes at {largest} bytes per body, \
             {} workgroups of {WORKGROUP} per dispatch)",
            gpu.limits.max_compute_workgroups_per_dimension
        )));
    }
    Ok(())
}

fn storage_buffer<T: bytemuck::Pod>(gpu: &Gpu, label: &str, data: &[T], count: usize, stride: usize) -> wgpu::Buffer {
    let buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (count * stride) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    if !data.is_empty() {
        gpu.queue.write_buffer(&buf, 0, bytemuck::cast_slice(data));
    }
    buf
}
