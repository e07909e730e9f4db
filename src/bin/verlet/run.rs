//! `verlet run`: a scene stepped on the GPU, what was asked recorded
//! (`record`), and a summary printed.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use verlet::gpu::Gpu;
use verlet::output;
use verlet::track::Track;
use verlet::{scenes, BodyOutput, Error, Scene, World};

use crate::cli::RunArgs;
use crate::record::{self, Recorder};
use crate::{lavapipe, paths, scene};

/// `verlet run`: every flag and input checked before the GPU is touched
/// (a built-in scene's size before it is built), then the world made,
/// stepped and recorded, the outputs written and the summary printed.
pub fn run(mut args: RunArgs) -> Result<(), Error> {
    check_required(&mut args)?;
    let args = args;
    check_values(&args)?;
    let (file_scene, body_count) = first_look(&args)?;
    let track = match (&args.input, args.builtin.as_deref()) {
        (Some(path), _) => Some(load_track(path)?),
        (None, Some("blast")) if args.scene.is_none() => Some(scenes::blast_track()),
        (None, _) => None,
    };
    if let Some(track) = &track {
        track.check(body_count as usize)?;
    }
    record::check_outputs(&args)?;
    record::warn_stale_frames(&args);

    // before any thread starts (the progress bar's): `lavapipe::open` may set
    // the environment while it opens the adapter
    let (gpu, dispatch) = lavapipe::open(lavapipe::suits_inline(body_count, record::wants_images(&args)))?;
    let gpu = Arc::new(gpu);
    let started = Instant::now();
    let scene = match file_scene {
        Some(scene) => scene,
        None => build_builtin(&args, &gpu)?,
    };
    if let Some(track) = &track {
        track.check_masses(&scene)?;
        warn_late_events(track, args.steps, scene.settings.dt);
    }
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    // last of the set-up: a run refused before here makes nothing
    let mut recorder = Recorder::open(&args, &gpu, &scene)?;
    let setup = started.elapsed();

    let (stages, bodies, wall) = match step_to_end(&args, &mut world, track.as_ref(), &mut recorder) {
        Ok(done) => done,
        Err(e) => {
            // say what was kept; the run's other outputs are not written
            recorder.abandon(&args);
            return Err(e);
        }
    };
    let frames = recorder.frame_counts();
    write_outputs(&args, recorder, &world, &bodies, scene.settings.dt)?;
    print_times(&args, &world, &gpu, (bodies.len(), scene.settings.dt), Timings { setup, wall, stages, dispatch })?;
    print_recorded(&args, frames)?;
    report_contacts(&args, &world, &gpu)?;
    print_motion(&bodies)?;
    if world.at_rest() {
        outln!("at rest: every body asleep or fixed; steps from then on change nothing and were counted, not run")?;
    }
    Ok(())
}

/// `--steps` and the scene, both of which a run needs, named together
/// when either is missing, with the usage.
fn check_required(args: &mut RunArgs) -> Result<(), Error> {
    let scene = args.scene.is_some() || args.builtin.is_some();
    match (args.steps_given, scene) {
        (Some(steps), true) => {
            args.steps = steps;
            Ok(())
        }
        (None, false) => Err(Error::Input(format!("missing a scene (SCENE.json or --builtin NAME) and --steps N; {RUN_USAGE}"))),
        (None, true) => Err(Error::Input(format!("missing --steps N, the number of steps to take; {RUN_USAGE}"))),
        (Some(_), false) => Err(Error::Input(format!("missing a scene: give a scene file or --builtin NAME; {RUN_USAGE}"))),
    }
}

/// How `verlet run` is called, for an error that finds the scene or
/// `--steps` missing: one round trip to a working command.
const RUN_USAGE: &str = "usage: verlet run SCENE.json --steps N [OPTIONS], or verlet run --builtin NAME --steps N [OPTIONS] \
                         (`verlet run --help` lists the options and the built-in scenes)";

/// The values `--dt`, `--every`, `--width` and `--height` must have
/// whatever the scene.
fn check_values(args: &RunArgs) -> Result<(), Error> {
    if let Some(dt) = args.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::Input(format!("--dt: must be a positive number of seconds, got {dt}")));
        }
    }
    if args.every == 0 {
        return Err(Error::Input("--every: must be at least 1".into()));
    }
    // The upper bound is the adapter's; Renderer::new checks it, naming the flag.
    for (flag, v) in [("--width", args.width), ("--height", args.height)] {
        if v == 0 {
            return Err(Error::Input(format!("{flag}: must be at least 1 pixel, got 0")));
        }
    }
    Ok(())
}

/// The scene before the GPU is open: a scene file loaded and checked with
/// `--dt`, or a built-in scene's size checked against any adapter's limit
/// (it is built once the adapter's is known: [`build_builtin`]). Returns
/// the loaded file, if any, and the bodies.
fn first_look(args: &RunArgs) -> Result<(Option<Scene>, u64), Error> {
    match (&args.scene, &args.builtin) {
        (Some(path), _) => {
            if args.count.is_some() {
                eprintln!("warning: --count: a scene file gives its own bodies (--count is for --builtin); ignored");
            }
            if args.seed.is_some() {
                eprintln!("warning: --seed: a scene file gives its own bodies (--seed is for --builtin); ignored");
            }
            let mut scene = load_scene(path)?;
            with_dt(&mut scene, args.dt)?;
            let n = scene.bodies.len() as u64;
            Ok((Some(scene), n))
        }
        (None, Some(name)) => {
            scene::warn_unused_count(name, args.count);
            scene::warn_unused_seed(name, args.seed);
            Ok((None, scenes::check(name, args.count, scenes::MAX_BODIES).map_err(scene::count_flag)?))
        }
        (None, None) => Err(Error::Input(format!("missing a scene: give a scene file or --builtin NAME; {RUN_USAGE}"))),
    }
}

/// Loads the scene file, naming the file in a syntax error (the field
/// errors name the field).
fn load_scene(path: &Path) -> Result<Scene, Error> {
    Scene::from_path(path).map_err(|e| match e {
        verlet::SceneError::Syntax { .. } => Error::Input(format!("{}: {e}", path.display())),
        e => e.into(),
    })
}

/// Gives the scene the step `--dt` asks for, if any, and checks the scene
/// with it: a step too short for its substeps, or so long that bodies sink
/// into the ground, names `--dt` (the scene's own `settings.dt` was fine).
fn with_dt(scene: &mut Scene, dt: Option<f32>) -> Result<(), Error> {
    let Some(dt) = dt else { return Ok(()) };
    scene.settings.dt = dt;
    scene.validate().map_err(|e| match e {
        verlet::load_error::LoadError::Invalid { field, message } if field == "settings.dt" => {
            Error::Input(format!("--dt: {message}"))
        }
        e => e.into(),
    })
}

/// Loads the `--input` track, naming the file and the flag.
fn load_track(path: &Path) -> Result<Track, Error> {
    use verlet::track::TrackError;
    Track::from_path(path).map_err(|e| match e {
        TrackError::Io { path, error, .. } => Error::Input(format!(
            "{}: cannot read input track given as --input: {}",
            path.display(),
            error.to_string().replace('\n', " ")
        )),
        e @ (TrackError::Syntax { .. } | TrackError::SceneGiven(_)) => Error::Input(format!("--input {}: {e}", path.display())),
        e => e.into(),
    })
}

/// The `--builtin` scene, built within the adapter's limit, with `--dt`.
fn build_builtin(args: &RunArgs, gpu: &Gpu) -> Result<Scene, Error> {
    let Some(name) = &args.builtin else {
        return Err(Error::Input(format!("missing a scene: give a scene file or --builtin NAME; {RUN_USAGE}")));
    };
    let seed = args.seed.unwrap_or(scene::DEFAULT_SEED);
    let mut scene = scenes::checked(name, args.count, seed, verlet::world::max_bodies(gpu)).map_err(scene::count_flag)?;
    with_dt(&mut scene, args.dt)?;
    Ok(scene)
}

/// Warns of track events that come after the run's last step: they would
/// act before a step that is never taken.
fn warn_late_events(track: &Track, steps: u64, dt: f32) {
    let late: Vec<f64> = track.events().iter().filter(|e| Track::step_of(e.t, dt) >= steps).map(|e| e.t).collect();
    if let Some(&first) = late.first() {
        // in scientific notation from 1e6: t = 1e300 would print three hundred digits
        let first = if first >= 1e6 { format!("{first:e}") } else { format!("{first}") };
        eprintln!(
            "warning: --input: {} of {} events come at t >= {first} s, after the run's last step (it ends at {:.4} s): they do nothing",
            late.len(),
            track.events().len(),
            steps as f64 * dt as f64
        );
    }
}

/// Takes the run's steps under a progress bar ([`step_and_record`]), then
/// checks the GPU's fault flag and reads the final state: the per-stage
/// times if `--profile`, every body, and the wall clock of it all.
fn step_to_end(
    args: &RunArgs,
    world: &mut World,
    track: Option<&Track>,
    recorder: &mut Recorder,
) -> Result<(Option<StageTotals>, Vec<BodyOutput>, Duration), Error> {
    let bar = ProgressBar::with_draw_target(Some(args.steps), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{wide_bar} {pos}/{len} steps, {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let stepped = step_and_record(args, world, track, recorder, &bar, started);
    // cleared on success and on error alike, so no half-drawn bar precedes the message
    bar.finish_and_clear();
    // The GPU flags a non-finite or absurd body every step without a
    // readback; the run reads the flag here once (and read_state, which
    // every trace row calls, reads it too) and fails naming body and step.
    let stages = stepped?;
    if let Some(fault) = world.faults()? {
        return Err(Error::Diverged(format!("{fault}{}", inputs_before(track, &fault, world))));
    }
    let bodies = world.read_state()?;
    Ok((stages, bodies, started.elapsed()))
}

/// Per-stage totals (ms over the whole run) and whether GPU timestamps timed them.
type StageTotals = (Vec<(verlet::step::Stage, f64)>, bool);

/// Takes `args.steps` steps, recording at steps 0, K, 2K, ... and the last.
///
/// Steps go in chunks, each waited for, so the progress bar follows the GPU
/// rather than the submissions; a chunk grows while it takes under 0.1 s, so
/// the waits cost little. Nothing is read back unless a recording asks for it.
/// With an input track, a chunk ends at the next step the track acts
/// before, and the track's inputs for a step go in just before it.
fn step_and_record(
    args: &RunArgs,
    world: &mut World,
    track: Option<&Track>,
    recorder: &mut Recorder,
    bar: &ProgressBar,
    started: Instant,
) -> Result<Option<StageTotals>, Error> {
    let mut stage_ms: Vec<(verlet::step::Stage, f64)> = Vec::new();
    let mut timed_by_gpu = false;
    let mut chunk = 1u64;
    let mut bar_shown = false;
    recorder.record(world)?;
    while world.step_count() < args.steps {
        let done = world.step_count();
        let mut stop = if recorder.is_active() { (done / args.every + 1).saturating_mul(args.every) } else { u64::MAX };
        if let Some(track) = track {
            track.apply(world)?;
            let dt = world.settings().dt;
            stop = stop.min(track.next_input_step(done + 1, dt).unwrap_or(u64::MAX));
        }
        let n = chunk.min(stop.min(args.steps) - done);
        let t = Instant::now();
        if args.profile {
            let times = world.profile(n)?;
            timed_by_gpu = times.gpu_timestamps;
            for (k, (stage, ms)) in times.ms_per_step.into_iter().enumerate() {
                match stage_ms.get_mut(k) {
                    Some(entry) => entry.1 += ms * n as f64,
                    None => stage_ms.push((stage, ms * n as f64)),
                }
            }
        } else {
            world.step(n)?;
            world.gpu().wait()?;
        }
        let took = t.elapsed();
        if took < Duration::from_millis(100) {
            chunk = chunk.saturating_mul(2);
        } else if took > Duration::from_millis(500) {
            chunk = (chunk / 2).max(1);
        }
        let done = world.step_count();
        if done.is_multiple_of(args.every) || done == args.steps {
            recorder.record(world)?;
        }
        bar.set_position(done);
        // Short runs draw nothing. The stderr target hides itself when
        // stderr is not a terminal (or TERM is dumb), so logs stay clean.
        if !bar_shown && started.elapsed() > Duration::from_secs(2) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            bar_shown = true;
        }
    }
    Ok(args.profile.then_some((stage_ms, timed_by_gpu)))
}

/// The track's events that acted before the step a fault was found in or
/// the one before (where the state may have gone bad), named for the
/// fault's message: an impulse of 1e30 N s is the input's doing, not the
/// solver's.
fn inputs_before(track: Option<&Track>, fault: &verlet::Fault, world: &World) -> String {
    let Some(track) = track else { return String::new() };
    let acting = track.acting_before(fault.step.saturating_sub(1)..=fault.step, world.settings().dt);
    if acting.is_empty() {
        return String::new();
    }
    let named: Vec<String> = acting.iter().take(3).map(|(k, name)| format!("events[{k}] ({name})")).collect();
    let more = if acting.len() > 3 { format!(" and {} more", acting.len() - 3) } else { String::new() };
    format!("; the input track's {}{more} acted just before", named.join(", "))
}

/// Commits the trace, writes the GIF, the contact sheet and `--state-out`,
/// each whatever became of the others.
fn write_outputs(args: &RunArgs, recorder: Recorder, world: &World, bodies: &[BodyOutput], dt: f32) -> Result<(), Error> {
    let state_json = args.state_out.as_ref().map(|_| output::state_json(world.step_count(), world.time(), bodies));
    let mut writes = recorder.finish(args, dt);
    if let (Some(path), Some(text)) = (&args.state_out, &state_json) {
        writes.push((
            "--state-out",
            path,
            Box::new(move || paths::write_file(path, text).map_err(|e| Error::Input(format!("--state-out: {e}")))),
        ));
    }
    paths::write_each(writes)
}

/// How long a run took: its set-up and its steps (wall clock), and each
/// stage's share where `--profile` timed them.
struct Timings {
    setup: Duration,
    wall: Duration,
    stages: Option<StageTotals>,
    /// Where lavapipe ran the dispatches.
    dispatch: lavapipe::Dispatch,
}

/// The summary's first lines: the bodies and steps of `dt` run, on what,
/// and how long it took.
fn print_times(args: &RunArgs, world: &World, gpu: &Gpu, (bodies, dt): (usize, f32), t: Timings) -> Result<(), Error> {
    // (no figure a step where none was taken)
    let pace = match args.steps {
        0 => "no step taken".to_string(),
        n => format!("{:.3} ms/step", t.wall.as_secs_f64() * 1e3 / n as f64),
    };
    outln!(
        "{}, {} of {} s ({} s simulated) on {}",
        counted(bodies as u64, "body", "bodies"),
        counted(world.step_count(), "step", "steps"),
        seconds(dt as f64, 5),
        seconds(world.time(), 3),
        gpu.describe()
    )?;
    outln!("set-up {:.2} s, stepping {:.2} s ({pace}, wall clock)", t.setup.as_secs_f64(), t.wall.as_secs_f64())?;
    if let Some(line) = t.dispatch.describe() {
        outln!("lavapipe: {line}")?;
    }
    if let Some((stage_ms, timed_by_gpu)) = t.stages {
        let source = if timed_by_gpu { "GPU timestamps" } else { "wall clock per pass" };
        outln!("per stage, ms/step ({source}):")?;
        // the longest stage name sets the column
        let width = stage_ms.iter().map(|(stage, _)| stage.name().len()).max().unwrap_or(0);
        for (stage, total) in &stage_ms {
            outln!("  {:<width$}  {:>9.3}", stage.name(), total / args.steps.max(1) as f64)?;
        }
    }
    Ok(())
}

/// Where the frames, the GIF and the contact sheet went, and how many
/// frames each holds (`Recorder::frame_counts`).
fn print_recorded(args: &RunArgs, (frames_written, gif_frames, sheet_frames): (u64, usize, usize)) -> Result<(), Error> {
    if let Some(dir) = &args.frames {
        outln!("{} in {}", counted(frames_written, "frame", "frames"), dir.display())?;
    }
    for (what, path, count) in [("GIF", &args.gif, gif_frames), ("contact sheet", &args.contact_sheet, sheet_frames)] {
        if let Some(path) = path {
            outln!("{what} of {} in {}", counted(count as u64, "frame", "frames"), path.display())?;
        }
    }
    Ok(())
}

/// With `--profile`, the contact pools' use; and whatever they or the
/// driver cut short, as warnings.
fn report_contacts(args: &RunArgs, world: &World, gpu: &Gpu) -> Result<(), Error> {
    let report = world.contact_report()?;
    if args.profile {
        // the pools shrink after busy steps, so the busiest step may have
        // wanted more than they hold now without anything lost
        outln!("contacts, last step:    {} candidate pairs, {} manifolds", report.pairs, report.manifolds)?;
        outln!("contacts, busiest step: {} candidate pairs, {} manifolds", report.pairs_max, report.manifolds_max)?;
        outln!(
            "contact pools now:      room for {} candidate pairs, {} manifolds (they grow when a step nearly fills them and shrink after quiet steps{})",
            report.pair_capacity,
            report.manifold_capacity,
            if report.overflowed() { "; some overflowed: see the warning" } else { "; none overflowed" }
        )?;
    }
    if report.overflowed() {
        eprintln!(
            "warning: the contact pools overflowed: up to {} candidate pairs ({} fit) and {} manifolds ({} fit) \
             were wanted in a step; the pairs beyond were dropped",
            report.pairs_max, report.pair_capacity, report.manifolds_max, report.manifold_capacity
        );
    }
    if report.lists_cut {
        eprintln!(
            "warning: a body's contact list was long enough that {} may have cut its sort short (it ends an \
             invocation's loops after 65535 trips): a body touching thousands of others may move differently \
             from run to run",
            gpu.info.name
        );
    }
    if report.walks_cut {
        eprintln!(
            "warning: a body's pair walk was long enough that {} may have cut it short (it ends an invocation's \
             loops after 65535 trips): a body far faster than its neighbours, in a scene of about 65 000 bodies or \
             more, may have missed contacts",
            gpu.info.name
        );
    }
    Ok(())
}

/// The lowest body, and the fastest moving and spinning ones where any
/// moves.
fn print_motion(bodies: &[BodyOutput]) -> Result<(), Error> {
    if let Some((lowest, b)) = bodies.iter().enumerate().min_by(|a, b| a.1.position[1].total_cmp(&b.1.position[1])) {
        let length = |v: [f32; 3]| glam::Vec3::from(v).length();
        let fastest = |of: fn(&BodyOutput) -> [f32; 3]| {
            bodies.iter().enumerate().map(|(k, b)| (k, length(of(b)))).fold((0, 0.0f32), |a, b| if b.1 > a.1 { b } else { a })
        };
        let (moving, speed) = fastest(|b| b.linear_velocity);
        let (spinning, spin) = fastest(|b| b.angular_velocity);
        // a body is named only where one moves (what prints as 0.000 counts as still)
        let motion = match (speed >= 0.0005, spin >= 0.0005) {
            (false, false) => "nothing moves (fastest body 0.000 m/s, fastest spin 0.000 rad/s)".to_string(),
            (true, false) => format!("fastest body {speed:.3} m/s (body {moving}); no body spins (fastest spin 0.000 rad/s)"),
            (false, true) => format!("no body moves (fastest body 0.000 m/s); fastest spin {spin:.3} rad/s (body {spinning})"),
            (true, true) => {
                format!("fastest body {speed:.3} m/s (body {moving}); fastest spin {spin:.3} rad/s (body {spinning})")
            }
        };
        outln!("lowest body {lowest} at y = {:.3} m; {motion}", b.position[1])?;
    }
    Ok(())
}

/// `s` seconds with `places` decimals, or in scientific notation where
/// those would show nothing (two steps of 3e-5 s simulate 6.000e-5 s, not
/// "0.000 s").
fn seconds(s: f64, places: usize) -> String {
    if s != 0.0 && s.abs() < 10f64.powi(-(places as i32)) {
        format!("{s:.3e}")
    } else {
        format!("{s:.places$}")
    }
}

/// `n` and the noun, singular for one (`1 body`, `2 bodies`).
fn counted(n: impl Into<u64>, one: &str, many: &str) -> String {
    let n = n.into();
    format!("{n} {}", if n == 1 { one } else { many })
}
