//! The measurements `verlet bench` takes only when asked, each slow or
//! apart from the cases' own figures: what a dispatch costs, a rendered
//! frame, a pile brought to rest, whole processes started cold.

use std::sync::Arc;
use std::time::Instant;

use verlet::bench::{case, Case, SEED};
use verlet::gpu::Gpu;
use verlet::render::Renderer;
use verlet::world::{self, World};
use verlet::{scenes, Error};

use super::median;
use super::results::{DispatchCost, InlineDispatchCost, Settled};

/// Measures `DispatchCost` on `gpu`, and on `inline` (lavapipe's
/// submitting thread) where the bench opened it.
pub fn dispatch_cost(gpu: &Arc<Gpu>, inline: Option<&Arc<Gpu>>) -> Result<DispatchCost, Error> {
    let (dispatches, ms) = ten_cubes(gpu)?;
    let us = |ms: f64| ms * 1e3 / dispatches as f64;
    progress!("dispatches: {dispatches} a step; 10 cubes step in {ms:.2} ms: {:.0} us a dispatch", us(ms));
    let inline = match inline {
        Some(gpu) => {
            let (_, ms) = ten_cubes(gpu)?;
            progress!("dispatches on the submitting thread: 10 cubes step in {ms:.2} ms: {:.0} us a dispatch", us(ms));
            Some(InlineDispatchCost { ten_cubes_ms_per_step: ms, us_per_dispatch: us(ms) })
        }
        None => None,
    };
    Ok(DispatchCost { dispatches_per_step: dispatches, ten_cubes_ms_per_step: ms, us_per_dispatch: us(ms), inline })
}

/// Ten cubes stepped 120 times after a first untimed step, sleeping off:
/// the dispatches of a step and the wall clock a step (ms).
fn ten_cubes(gpu: &Arc<Gpu>) -> Result<(usize, f64), Error> {
    let mut scene = scenes::cubes(10, SEED);
    // asleep, the world would come to rest and skip its steps
    scene.settings.sleeping = false;
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    world.step(1)?;
    gpu.wait()?;
    let steps = 120;
    let t = Instant::now();
    world.step(steps)?;
    gpu.wait()?;
    Ok((world.step_plan().len(), t.elapsed().as_secs_f64() * 1e3 / steps as f64))
}

/// Renders the 1000-cube scene after 60 steps at 640 x 480: (set-up s, ms per frame).
pub fn render_cubes(gpu: &Arc<Gpu>) -> Result<(f64, f64), Error> {
    let scene = case("cubes-1k").scene();
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    world.step(60)?;
    gpu.wait()?;
    let t = Instant::now();
    let mut renderer = Renderer::new(gpu, &scene, 640, 480)?;
    let setup = t.elapsed().as_secs_f64();
    renderer.render(&world)?; // the first frame compiles the raster pipelines
    let mut frames = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        renderer.render(&world)?;
        frames.push(t.elapsed().as_secs_f64() * 1e3);
    }
    progress!("render: cubes-1k at 640x480: {:.1} ms/frame (set-up {setup:.2} s)", median(&frames));
    Ok((setup, median(&frames)))
}

/// Brings a pile case (named `case` in the report) to rest with sleeping
/// on (see `Settled`).
pub fn settle(gpu: &Arc<Gpu>, pile: &Case, case: &str, most_steps: u64) -> Result<Settled, Error> {
    let mut scene = pile.scene();
    scene.settings.sleeping = true;
    let bodies = scene.bodies.len();
    progress!("{case}: settling with sleeping on (at most {most_steps} steps)");
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    let (mut steps, mut asleep, mut resting_since, mut last_ms) = (0, 0, None, f64::NAN);
    while steps < most_steps {
        let chunk = 60.min(most_steps - steps);
        let t = Instant::now();
        world.step(chunk)?;
        gpu.wait()?;
        last_ms = t.elapsed().as_secs_f64() * 1e3 / chunk as f64;
        steps += chunk;
        asleep = world.read_state()?.iter().filter(|b| b.asleep).count();
        if 100 * asleep < 99 * bodies {
            resting_since = None;
        } else if steps - *resting_since.get_or_insert(steps) >= world::SHRINK_AFTER_STEPS {
            break;
        }
    }
    let report = world.contact_report()?;
    let gpu_bytes = world.gpu_bytes();
    let out = Settled {
        case: case.to_string(),
        bodies,
        steps,
        asleep,
        pairs: report.pairs,
        manifolds: report.manifolds,
        pair_capacity: report.pair_capacity,
        manifold_capacity: report.manifold_capacity,
        gpu_bytes,
        gpu_bytes_per_body: gpu_bytes as f64 / bodies.max(1) as f64,
        last_ms_per_step: last_ms,
    };
    progress!(
        "{case}: {asleep} of {bodies} asleep after {steps} steps, {:.0} B/body, {:.3} ms/step",
        out.gpu_bytes_per_body,
        last_ms
    );
    Ok(out)
}

/// Times `runs` whole processes of this binary running `run --builtin
/// cubes --count 10 --steps 1` with Mesa's shader cache disabled (a cold
/// start: every kernel compiled from nothing), each from its start to
/// its exit (s). Empty, with a warning, if one cannot be run or fails.
pub fn cold_start(runs: usize) -> Vec<f64> {
    use std::process::{Command, Stdio};
    let exe = match std::env::current_exe() {
        Ok(exe) => exe,
        Err(e) => {
            progress!("warning: cold start not measured: this program's path is unknown: {e}");
            return Vec::new();
        }
    };
    let mut out = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let status = Command::new(&exe)
            .args(["run", "--builtin", "cubes", "--count", "10", "--steps", "1"])
            .env("MESA_SHADER_CACHE_DISABLE", "true")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status();
        match status {
            Ok(s) if s.success() => out.push(t.elapsed().as_secs_f64()),
            Ok(s) => {
                progress!(
                    "warning: cold start not measured: `{} run --builtin cubes --count 10 --steps 1` exited with {s}",
                    exe.display()
                );
                return Vec::new();
            }
            Err(e) => {
                progress!("warning: cold start not measured: could not start {}: {e}", exe.display());
                return Vec::new();
            }
        }
    }
    progress!("cold start (10 cubes, Mesa's shader cache disabled): {:.2} s (median of {runs})", median(&out));
    out
}
