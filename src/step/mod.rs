//! The compute pipelines of one step, in the order they run:
//!
//! 1. `integrate`   — Verlet prediction of every pose (shaders/integrate.wgsl)
//! 2. `solve`       — `iterations` Jacobi sweeps of corrective snaps (shaders/solve.wgsl)
//! 3. `restitution` — bounce, by rewriting the previous pose (shaders/restitution.wgsl)
//!
//! Every pass reads one state buffer and writes the other, so the current
//! state flips after each dispatch. This type holds only compiled pipelines
//! and their layout; the buffers live in `World`.

use crate::gpu::{shaders, types::*, Gpu};

/// The stages of a step, in order; their names are the WGSL entry points,
/// the shader files and the labels of their compute passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    Integrate,
    Solve,
    Restitution,
}

impl Stage {
    pub const ALL: [Stage; 3] = [Stage::Integrate, Stage::Solve, Stage::Restitution];

    pub fn name(self) -> &'static str {
        match self {
            Stage::Integrate => "integrate",
            Stage::Solve => "solve",
            Stage::Restitution => "restitution",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Stage::Integrate => "step/integrate",
            Stage::Solve => "step/solve",
            Stage::Restitution => "step/restitution",
        }
    }
}

pub struct StepPipelines {
    pub layout: wgpu::BindGroupLayout,
    pipelines: Vec<wgpu::ComputePipeline>,
}

fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl StepPipelines {
    pub fn new(gpu: &Gpu) -> StepPipelines {
        let device = &gpu.device;
        // shaders/bindings.wgsl
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("step"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
                    },
                    count: None,
                },
                storage(1, true),  // props
                storage(2, true),  // state_in
                storage(3, false), // state_out
                storage(4, false), // vel0
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("step"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipelines = Stage::ALL
            .iter()
            .map(|stage| {
                let source = shaders::pass_source(stage.name()).expect("every stage has a shader");
                let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(stage.name()),
                    source: wgpu::ShaderSource::Wgsl(source.into()),
                });
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(stage.label()),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(stage.name()),
                    compilation_options: Default::default(),
                    cache: None,
                })
            })
            .collect();
        StepPipelines { layout, pipelines }
    }

    pub fn pipeline(&self, stage: Stage) -> &wgpu::ComputePipeline {
        &self.pipelines[stage as usize]
    }
}
