//! One case of `verlet bench`, timed: start-up, repetitions (the peer's
//! between them), then the stages of the last repetition's world.

use std::sync::Arc;
use std::time::Instant;

use verlet::bench::{Case, CopyKernel, SEED};
use verlet::gpu::Gpu;
use verlet::scene::{Scene, Shape};
use verlet::world::{self, World};
use verlet::{scenes, Error};

use super::peer::PeerReps;
use super::results::{CaseResult, Stages};
use super::{mean_height, median, Options, MIN_STEPS};

/// A case's result before anything is measured.
pub fn blank(case: &Case, scene: &Scene, steps: u64, reps: usize) -> CaseResult {
    let n = scene.bodies.len();
    CaseResult {
        case: case.name.clone(),
        scene: case.scene.clone(),
        bodies: n,
        joints: scene.joints.len(),
        iterations: scene.settings.iterations,
        substeps: scene.settings.substeps,
        skipped: None,
        note: None,
        lavapipe: None,
        steps,
        reps,
        startup_s: f64::NAN,
        first_step_ms: f64::NAN,
        setup_s: f64::NAN,
        ms_per_step: Vec::new(),
        median_ms_per_step: f64::NAN,
        body_steps_per_s: f64::NAN,
        gpu_bytes_estimate: world::bytes_per_body() * n as u64,
        gpu_bytes_at_start: 0,
        gpu_bytes: 0,
        gpu_bytes_per_body: f64::NAN,
        stages: None,
        readback_ms: f64::NAN,
        render_setup_s: None,
        render_ms: None,
        integrate_ms_per_pass: None,
        copy_ms_per_pass: None,
        max_contacts: 0,
        contacts_overflowed: false,
        mean_height: f64::NAN,
        load_avg: None,
        peer: None,
    }
}

/// Runs one case: its start-up, its repetitions (the peer's between
/// them), then its stages, readback and copy kernel on the last world.
/// A case beyond the adapter runs as the most cubes that fit, or is
/// skipped.
pub fn run_case(
    gpu: &Arc<Gpu>,
    case: &Case,
    (steps, body_steps): (u64, u64),
    reps: usize,
    profile_steps: u64,
    max: u64,
    opts: &Options,
) -> Result<CaseResult, Error> {
    let mut case = case.clone();
    let mut note = None;
    // counted before it is built: a case beyond the adapter is not made
    let bodies = scenes::body_count(&case.scene, case.count).unwrap_or(0);
    if bodies > max {
        let why = scenes::check(&case.scene, case.count, max)
            .err()
            .map_or_else(|| format!("{bodies} bodies exceed max_bodies = {max}"), |e| e.to_string());
        if case.scene != "cubes" || max == 0 {
            progress!("warning: {}: does not fit, skipped: {why}", case.name);
            let empty = scenes::by_name(&case.scene, Some(0), SEED).unwrap_or_default();
            // estimated from the count: the scene is not built
            let estimate = world::bytes_per_body().saturating_mul(bodies);
            return Ok(CaseResult {
                skipped: Some(why),
                bodies: bodies as usize,
                gpu_bytes_estimate: estimate,
                gpu_bytes_at_start: estimate,
                gpu_bytes: estimate,
                gpu_bytes_per_body: world::bytes_per_body() as f64,
                ..blank(&case, &empty, steps, reps)
            });
        }
        let n = max as usize;
        progress!("warning: {}: does not fit ({why}); running {n} cubes, the adapter's maximum, instead", case.name);
        note = Some(format!("{bodies} cubes do not fit ({why}); run at the adapter's maximum, {n}"));
        case.count = Some(n);
        case.name = format!("cubes-max ({n})");
    }
    let mut scene = case.scene();
    // both engines sleep, or neither (the peer's default: off)
    scene.settings.sleeping = opts.rapier_sleeping;
    if let Some(k) = opts.iterations {
        scene.settings.iterations = k;
        scene.settings.substeps = verlet::Settings::substeps_for(k);
    }
    let n = scene.bodies.len();
    let steps = steps.min((body_steps / n.max(1) as u64).max(MIN_STEPS));
    let profile_steps = profile_steps.min((body_steps / 10 / n.max(1) as u64).max(3));
    let mut out = CaseResult { note, ..blank(&case, &scene, steps, reps) };

    // 1. start-up, apart
    let t = Instant::now();
    let mut world = match World::with_gpu(gpu.clone(), &scene) {
        Ok(world) => world,
        // a limit found only on building (a joint island lavapipe cannot
        // close) skips the case, as too many bodies do, not the whole run
        Err(Error::Capacity(why)) => {
            progress!("warning: {}: does not fit, skipped: {why}", case.name);
            return Ok(CaseResult { skipped: Some(why), ..out });
        }
        // a shape this build does not simulate yet (hulls, until their
        // contacts are on the GPU) skips the case, not the whole run
        Err(Error::Input(why)) if scene.bodies.iter().any(|b| matches!(b.shape, Shape::Hull(_))) => {
            progress!("warning: {}: not simulated by this build, skipped: {why}", case.name);
            return Ok(CaseResult { skipped: Some(why), ..out });
        }
        Err(e) => return Err(e),
    };
    gpu.wait()?;
    let upload = t.elapsed().as_secs_f64();
    out.gpu_bytes_at_start = world.gpu_bytes();
    let t = Instant::now();
    world.step(1)?;
    gpu.wait()?;
    out.first_step_ms = t.elapsed().as_secs_f64() * 1e3;
    out.startup_s = upload + out.first_step_ms * 1e-3;
    drop(world);
    progress!(
        "{}: {n} bodies, start-up {:.2} s (first step {:.1} ms); {steps} steps per rep",
        case.name,
        out.startup_s,
        out.first_step_ms
    );

    // 2. repetitions from the same initial state, each followed by one of
    // the peer's (so that a machine whose speed drifts during the case
    // weighs on both engines alike)
    let mut peer = PeerReps::new(&case, &scene, steps, reps, opts)?;
    let mut setups = Vec::new();
    let mut last = None;
    for r in 0..reps {
        let t = Instant::now();
        let mut world = World::with_gpu(gpu.clone(), &scene)?;
        // lavapipe loads (or, with its shader cache off, compiles) a world's
        // pipelines at their first dispatch: keep that out of the timing
        world.step(1)?;
        gpu.wait()?;
        setups.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        world.step(steps)?;
        gpu.wait()?;
        let ms = t.elapsed().as_secs_f64() * 1e3 / steps as f64;
        out.ms_per_step.push(ms);
        progress!("{}: rep {}/{reps}: {ms:.3} ms/step", case.name, r + 1);
        last = Some(world);
        if let Some(p) = peer.as_mut() {
            p.rep(r);
        }
    }
    let mut world = last.expect("reps >= 1");
    out.setup_s = median(&setups);
    out.median_ms_per_step = median(&out.ms_per_step);
    out.body_steps_per_s = n as f64 / (out.median_ms_per_step * 1e-3);

    // 3. the state, a readback, the stages and the copy kernel
    let mut readbacks = Vec::new();
    let mut bodies = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        bodies = world.read_state()?;
        readbacks.push(t.elapsed().as_secs_f64() * 1e3);
    }
    out.readback_ms = median(&readbacks);
    out.mean_height = mean_height(bodies.iter().zip(&scene.bodies).filter(|(_, b)| !b.fixed).map(|(o, _)| o.position[1]));
    let report = world.contact_report()?;
    out.max_contacts = report.manifolds_max;
    out.contacts_overflowed = report.overflowed();
    out.gpu_bytes = world.gpu_bytes();
    out.gpu_bytes_per_body = out.gpu_bytes as f64 / n.max(1) as f64;
    if profile_steps > 0 {
        let times = world.profile(profile_steps)?;
        let stages = Stages::from_times(&times, profile_steps);
        out.integrate_ms_per_pass = Some(stages.integrate / scene.settings.substeps.max(1) as f64);
        out.stages = Some(stages);
        let copy = CopyKernel::new(gpu, n)?;
        copy.time(gpu, 3)?; // compile and warm
        out.copy_ms_per_pass = Some(median(&copy.time(gpu, 20)?));
    }
    drop(world);
    progress!(
        "{}: median {:.3} ms/step, {:.3e} body-steps/s, {:.0} B/body",
        case.name,
        out.median_ms_per_step,
        out.body_steps_per_s,
        out.gpu_bytes_per_body
    );

    // 4. the peer's repetitions, taken between ours
    out.peer = peer.map(|p| p.result(out.median_ms_per_step));
    Ok(out)
}
