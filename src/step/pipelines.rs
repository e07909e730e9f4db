//! The step's compiled pipelines and their bind group layouts.

use super::{Buffer, Stage};
use crate::gpu::{types::Params, Gpu};
use crate::scene::{Scene, Shape};

/// What a world holds or does that some of the passes' code is for
/// (HAS_ROUND, HAS_HULLS, HAS_JOINTS and SLEEPING in common.wgsl). The
/// passes are compiled without the code for what the world lacks: lavapipe
/// runs every instruction of a kernel, whatever branch its invocations
/// take, so a pile of boxes paid for the spheres', capsules' and hulls'
/// code in every pass (docs/lavapipe.md). The results are the same bits
/// either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Contents {
    /// Spheres or capsules.
    pub round: bool,
    pub hulls: bool,
    pub joints: bool,
    /// `settings.sleeping`.
    pub sleeping: bool,
}

impl Contents {
    pub(crate) fn of(scene: &Scene) -> Contents {
        let shapes = || scene.bodies.iter().map(|b| &b.shape);
        Contents {
            round: shapes().any(|s| matches!(s, Shape::Sphere { .. } | Shape::Capsule { .. })),
            hulls: shapes().any(|s| matches!(s, Shape::Hull(_))),
            joints: !scene.joints.is_empty(),
            sleeping: scene.settings.sleeping,
        }
    }
}

/// The most storage buffers any stage binds; the device must allow this
/// many per shader stage.
pub(crate) fn storage_buffers() -> u32 {
    Stage::ALL.iter().map(|s| s.buffers().iter().filter(|b| **b != Buffer::Params).count() as u32).max().unwrap_or(0)
}

/// The step's compiled pipelines, each with its own bind group layout (the
/// buffers its entry point uses: every pass of the step binds fewer than
/// the 16 storage buffers an adapter is asked for, though the step has
/// more).
pub(crate) struct StepPipelines {
    layouts: Vec<wgpu::BindGroupLayout>,
    pipelines: Vec<wgpu::ComputePipeline>,
    /// Compiled for a manifold pool in parts (POOL_SPLIT in bindings.wgsl).
    pub pool_split: bool,
    /// Compiled for a world holding these.
    contents: Contents,
}

fn entry(buffer: Buffer) -> wgpu::BindGroupLayoutEntry {
    let ty = match buffer {
        // one Params slot per substep, chosen by the dynamic offset
        Buffer::Params => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
        },
        // read-only where no stage writes (props, state_in, the joints)
        _ => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: buffer.read_only() },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    };
    wgpu::BindGroupLayoutEntry { binding: buffer.binding(), visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

/// One pass for its layout (the override constants: POOL_SPLIT, what the
/// world holds, DISPATCH_ROW from the device's limits, the stage's own from
/// its row, LOOP_TRIPS where the driver limits loops), compiled once per
/// device for each set of them.
fn compile(gpu: &Gpu, stage: Stage, layout: &wgpu::BindGroupLayout, pool_split: bool, contents: Contents) -> wgpu::ComputePipeline {
    let flag = |on: bool| f64::from(u8::from(on));
    let mut constants = vec![
        ("POOL_SPLIT", flag(pool_split)),
        ("HAS_ROUND", flag(contents.round)),
        ("HAS_HULLS", flag(contents.hulls)),
        ("HAS_JOINTS", flag(contents.joints)),
        ("SLEEPING", flag(contents.sleeping)),
        ("DISPATCH_ROW", f64::from(gpu.limits.max_compute_workgroups_per_dimension)),
    ];
    constants.extend_from_slice(stage.info().constants);
    if let Some(trips) = gpu.loop_trips() {
        constants.push(("LOOP_TRIPS", f64::from(trips)));
    }
    let mut one = gpu.compute_pipelines(stage.name(), &stage.source(), &[stage.entry_point()], Some(&[layout]), &constants);
    one.remove(0)
}

impl StepPipelines {
    /// The step's passes, for a manifold pool in parts where `pool_split`
    /// (see `World::make_pools`) and a world holding `contents`: compiled on
    /// the device's first such world, and found again
    /// (`Gpu::compute_pipelines`) by every other and every edit.
    pub(crate) fn new(gpu: &Gpu, pool_split: bool, contents: Contents) -> StepPipelines {
        let layouts: Vec<wgpu::BindGroupLayout> = Stage::ALL
            .iter()
            .map(|stage| {
                let entries: Vec<wgpu::BindGroupLayoutEntry> = stage.buffers().into_iter().map(entry).collect();
                gpu.bind_group_layout(stage.name(), &entries)
            })
            .collect();
        let pipelines =
            Stage::ALL.iter().map(|&stage| compile(gpu, stage, &layouts[stage as usize], pool_split, contents)).collect();
        StepPipelines { layouts, pipelines, pool_split, contents }
    }

    /// The passes for a world that now holds `contents` (an edit added or
    /// removed bodies or joints), where that differs: the layouts stay, so
    /// the bind groups do.
    pub(crate) fn hold(&mut self, gpu: &Gpu, contents: Contents) {
        if contents != self.contents {
            for stage in Stage::ALL {
                self.pipelines[stage as usize] = compile(gpu, stage, &self.layouts[stage as usize], self.pool_split, contents);
            }
            self.contents = contents;
        }
    }

    /// The passes that touch the manifold pool's parts, compiled for a pool
    /// in parts (POOL_SPLIT on; see `World::make_pools`), once per device.
    pub(crate) fn split_pool(&mut self, gpu: &Gpu) {
        for stage in Stage::ALL {
            let buffers = stage.buffers();
            if buffers.contains(&Buffer::Points) || buffers.contains(&Buffer::Snaps1) {
                self.pipelines[stage as usize] = compile(gpu, stage, &self.layouts[stage as usize], true, self.contents);
            }
        }
        self.pool_split = true;
    }

    /// What the passes are compiled for (what the world holds).
    pub(crate) fn contents(&self) -> Contents {
        self.contents
    }

    pub(crate) fn pipeline(&self, stage: Stage) -> &wgpu::ComputePipeline {
        &self.pipelines[stage as usize]
    }

    pub(crate) fn layout(&self, stage: Stage) -> &wgpu::BindGroupLayout {
        &self.layouts[stage as usize]
    }
}
