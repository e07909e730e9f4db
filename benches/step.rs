//! Criterion benchmarks of the step, on the cases of `verlet::bench`
//! (`cargo bench --bench step`; `verlet bench` is the full harness).
//!
//! - `step/cubes-1k`, `step/cubes-10k`: one step of the named case, submitted
//!   and waited for (wall clock), on a world that has already taken 60 steps
//!   (the cubes have landed), so every sample times a pile at rest-ish.
//! - `integrate/cubes-10k`: the integrate pass alone, per pass, from
//!   `World::profile` (GPU timestamp queries where the adapter has them).
//! - `copy/cubes-10k`: the memory-bound limit for that pass: a kernel copying
//!   the same number of 64-byte states, timed the same way.
//!
//! On lavapipe the first world compiles every pipeline (seconds); that is
//! done before criterion starts timing. Under `cargo test --benches` criterion
//! runs each benchmark once, as a smoke test.

use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use verlet::bench::{case, CopyKernel};
use verlet::gpu::Gpu;
use verlet::step::Stage;
use verlet::World;

fn gpu() -> Arc<Gpu> {
    Arc::new(Gpu::new().expect("a GPU adapter (lavapipe will do)"))
}

fn landed(gpu: &Arc<Gpu>, name: &str) -> World {
    let scene = case(name).scene();
    let mut world = World::with_gpu(gpu.clone(), &scene).expect("the case fits");
    world.step(60).expect("steps");
    gpu.wait().expect("the GPU finishes");
    world
}

fn step(c: &mut Criterion) {
    let gpu = gpu();
    let mut group = c.benchmark_group("step");
    group.sample_size(10).measurement_time(Duration::from_secs(5)).warm_up_time(Duration::from_secs(1));
    for name in ["cubes-1k", "cubes-10k"] {
        let mut world = landed(&gpu, name);
        group.throughput(Throughput::Elements(world.body_count() as u64));
        group.bench_function(name, |b| {
            b.iter(|| {
                world.step(1).expect("steps");
                world.gpu().wait().expect("the GPU finishes");
            })
        });
    }
    group.finish();
}

/// One integrate pass and one copy pass over the same bodies, from GPU
/// timestamps (or wall clock per pass where the adapter has none).
fn integrate(c: &mut Criterion) {
    let gpu = gpu();
    let name = "cubes-10k";
    let mut world = landed(&gpu, name);
    let n = world.body_count();
    let substeps = world.settings().substeps.max(1) as f64;
    let mut group = c.benchmark_group("integrate");
    group.sample_size(10).measurement_time(Duration::from_secs(5)).warm_up_time(Duration::from_secs(1));
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let t = world.profile(iters).expect("profiles");
            let ms = t.ms_per_step.iter().find(|(s, _)| *s == Stage::Integrate).map_or(0.0, |x| x.1) / substeps;
            Duration::from_secs_f64(ms * 1e-3 * iters as f64)
        })
    });
    group.finish();

    let copy = CopyKernel::new(&gpu, n).expect("the copy kernel");
    copy.time(&gpu, 3).expect("warm-up");
    let mut group = c.benchmark_group("copy");
    group.sample_size(10).measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    group.throughput(Throughput::Bytes(copy.bytes_per_pass()));
    group.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let ms: f64 = copy.time(&gpu, iters as usize).expect("times").iter().sum();
            Duration::from_secs_f64(ms * 1e-3)
        })
    });
    group.finish();
}

criterion_group!(benches, step, integrate);
criterion_main!(benches);
