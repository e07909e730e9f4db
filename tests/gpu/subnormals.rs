//! A software adapter's kernels see subnormal floats flushed to zero, as
//! GPUs do (`src/gpu/subnormals.rs`: lavapipe's slow path for them made a
//! joint grid's solve 2.8 times slower), and the thread that opened the
//! device keeps its own floating-point controls.

use std::hint::black_box;

use wgpu::util::DeviceExt;

use crate::common::gpu;
use verlet::gpu::Gpu;

/// What a kernel computes for 1e-30 x 1e-10 (1e-40, a subnormal) and for
/// 1e-30 / 2 (normal), from a buffer so that nothing is folded at compile time.
fn products_on(gpu: &Gpu) -> [f32; 2] {
    let source = "@group(0) @binding(0) var<storage, read_write> v: array<f32, 4>;\n\
                  @compute @workgroup_size(1) fn main() { v[2] = v[0] * v[1]; v[3] = v[0] * 0.5; }";
    let pipeline = gpu.compute_pipelines("subnormals", source, &["main"], None, &[]).remove(0);
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
    let values = [1e-30f32, 1e-10, 1.0, 1.0];
    let buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("subnormals"),
        contents: bytemuck::cast_slice(&values),
        usage,
    });
    let out = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("subnormals out"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("subnormals"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&buffer, 0, &out, 0, 16);
    gpu.submit(encoder.finish());
    out.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    gpu.wait().unwrap();
    let view = out.slice(..).get_mapped_range().unwrap();
    let read: &[f32] = bytemuck::cast_slice(&view);
    [read[2], read[3]]
}

#[test]
fn a_software_adapters_kernels_flush_subnormals_and_the_opening_thread_keeps_them() {
    let Some(shared) = gpu() else { return };
    // a device opened on this thread, then this thread's own arithmetic
    let own = Gpu::new().unwrap();
    let host = black_box(1e-30f32) * black_box(1e-10f32);
    assert!(host > 0.0, "the thread that opened the device flushes subnormals: {host:e}");
    for g in [&*shared, &own] {
        let [subnormal, normal] = products_on(g);
        eprintln!("{}: 1e-30 x 1e-10 = {subnormal:e}, 1e-30 / 2 = {normal:e}", g.describe());
        assert_eq!(normal, 5e-31, "a normal product");
        if g.info.device_type == wgpu::DeviceType::Cpu {
            assert_eq!(subnormal, 0.0, "a subnormal product on a software adapter");
        }
    }
}
