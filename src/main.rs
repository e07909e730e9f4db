//! The `verlet` command line (INTERFACE.md section 2).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use image::RgbaImage;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use verlet::render::{self, Renderer};
use verlet::track::Track;
use verlet::{gpu::Gpu, output, scenes, Error, Scene, World};

#[derive(Parser)]
#[command(name = "verlet", version, about = "GPU rigid-body simulator (quaternion position-Verlet, Kenwright)")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene file (or a built-in scene) and write what was asked.
    Run(RunArgs),
    /// Print a built-in scene as JSON.
    Scene {
        /// One of: drop, sphere, cubes, stack, pyramid, chain, bridge, ragdoll.
        name: String,
        /// Bodies, boxes, rows, links, planks or ragdolls, by scene.
        #[arg(long)]
        count: Option<usize>,
        /// Seed of the random scenes (cubes).
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// The adapter in use, its limits and what a body costs.
    Info,
    /// Throughput benchmark: named cases, per-stage times, scaling, and the
    /// rapier3d peer when built with `--features rapier`.
    Bench(BenchArgs),
}

#[derive(clap::Args)]
struct BenchArgs {
    /// Cases, comma-separated: cubes-1k, cubes-10k, cubes-100k, cubes-1m
    /// (the adapter's maximum when 1M does not fit), pile-1k, pile-10k,
    /// pile-100k, pile-1m (cubes heaped four deep), pyramid, chain, or
    /// SCENE:COUNT. Default: all (with --quick: cubes-1k, cubes-10k, pyramid, chain).
    #[arg(long, value_delimiter = ',')]
    cases: Vec<String>,
    /// Steps per repetition (default 300; 60 with --quick).
    #[arg(long)]
    steps: Option<u64>,
    /// Body-steps per repetition: a case takes min(steps, max(20, this / bodies))
    /// steps, so large cases finish (default 3000000: 300 steps of 10k cubes; 600000 with --quick).
    #[arg(long)]
    body_steps: Option<u64>,
    /// Repetitions per case, each from the initial state; the median is reported (default 3; 2 with --quick).
    #[arg(long)]
    reps: Option<usize>,
    /// A short run: fewer cases, steps and repetitions.
    #[arg(long)]
    quick: bool,
    /// Steps timed stage by stage after the repetitions (default 10; 3 with --quick; 0: none).
    #[arg(long)]
    profile_steps: Option<u64>,
    /// Write the full report as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write one CSV row per case here.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Do not run the rapier3d peer even when it is built in.
    #[arg(long)]
    no_peer: bool,
    /// Run the peer only for cases of at most this many bodies.
    #[arg(long)]
    peer_max_bodies: Option<usize>,
    /// Let bodies sleep, ours and rapier's (off by default in the bench).
    #[arg(long)]
    rapier_sleeping: bool,
    /// rapier's num_solver_iterations (default: rapier's own, 4).
    #[arg(long)]
    rapier_iterations: Option<usize>,
}

#[derive(clap::Args)]
struct RunArgs {
    /// The scene file (JSON, INTERFACE.md section 1). Without it, --builtin.
    scene: Option<PathBuf>,
    /// A built-in scene to run instead of a file (see `verlet scene`).
    #[arg(long, conflicts_with = "scene")]
    builtin: Option<String>,
    /// --count of the built-in scene.
    #[arg(long, requires = "builtin")]
    count: Option<usize>,
    /// --seed of the built-in scene.
    #[arg(long, default_value_t = 1, requires = "builtin")]
    seed: u64,
    /// Steps to take.
    #[arg(long)]
    steps: u64,
    /// A scripted input track (JSON: impulses, explosions, poses,
    /// velocities, fixed switches, wind at given times) applied between
    /// steps. `--builtin blast` plays its own track unless this is given.
    #[arg(long)]
    input: Option<PathBuf>,
    /// Step length in seconds; overrides settings.dt.
    #[arg(long)]
    dt: Option<f32>,
    /// Write the state after the last step here (JSON).
    #[arg(long)]
    state_out: Option<PathBuf>,
    /// Write a CSV trace here: every body at steps 0, K, 2K, ... and the last.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// K for --trace, --frames, --gif and --contact-sheet.
    #[arg(long, default_value_t = 1)]
    every: u64,
    /// Time every stage of every step (GPU timestamps where the adapter has
    /// them) and print the cost per stage; steps are then submitted one by one.
    #[arg(long)]
    profile: bool,
    /// Write PNG frames into this directory (created if missing):
    /// frame_000000.png, frame_000001.png, ... at steps 0, K, 2K, ... and the last.
    #[arg(long)]
    frames: Option<PathBuf>,
    /// Write an animated GIF of the frames here (--frames not needed), played
    /// in real time. To bound memory, frames are scaled to fit 480x480 and at
    /// most 151 are kept, evenly spread over the run, always with the last.
    #[arg(long)]
    gif: Option<PathBuf>,
    /// Write one PNG tiling the frames here (--frames not needed). To bound
    /// memory, tiles are scaled to fit 320x320 and at most 25 are kept,
    /// evenly spread over the run, always with the last.
    #[arg(long)]
    contact_sheet: Option<PathBuf>,
    /// Frame width in pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 480)]
    height: u32,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            // one line: clap's first line names the bad flag and why
            let text = e.render().to_string();
            eprintln!("{}", text.lines().next().unwrap_or("error: bad arguments"));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Run(args) => run(args),
        Command::Scene { name, count, seed } => print_scene(&name, count, seed),
        Command::Info => info(),
        Command::Bench(a) => verlet::bench::run(&verlet::bench::Options {
            cases: a.cases,
            steps: a.steps,
            body_steps: a.body_steps,
            reps: a.reps,
            quick: a.quick,
            profile_steps: a.profile_steps,
            json: a.json,
            csv: a.csv,
            no_peer: a.no_peer,
            peer_max_bodies: a.peer_max_bodies,
            rapier_sleeping: a.rapier_sleeping,
            rapier_iterations: a.rapier_iterations,
            command: std::env::args().collect::<Vec<_>>().join(" "),
        })
        .map(|_| ()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}

fn builtin(name: &str, count: Option<usize>, seed: u64) -> Result<Scene, Error> {
    scenes::by_name(name, count, seed).ok_or_else(|| {
        let names: Vec<&str> = scenes::NAMES.iter().map(|(n, _)| *n).collect();
        Error::Input(format!("unknown scene {name:?}; known: {}", names.join(", ")))
    })
}

fn print_scene(name: &str, count: Option<usize>, seed: u64) -> Result<(), Error> {
    let scene = builtin(name, count, seed)?;
    println!("{}", scene.to_json());
    Ok(())
}

fn run(args: RunArgs) -> Result<(), Error> {
    // Everything the user gave is checked before the GPU is touched.
    let mut scene = match (&args.scene, &args.builtin) {
        (Some(path), _) => Scene::from_path(path)?,
        (None, Some(name)) => builtin(name, args.count, args.seed)?,
        (None, None) => return Err(Error::Input("give a scene file or --builtin NAME".into())),
    };
    if let Some(dt) = args.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::Input(format!("--dt: must be a positive number of seconds, got {dt}")));
        }
        scene.settings.dt = dt;
    }
    if args.every == 0 {
        return Err(Error::Input("--every: must be at least 1".into()));
    }
    let track = match (&args.input, args.builtin.as_deref()) {
        (Some(path), _) => Some(Track::from_path(path)?),
        (None, Some("blast")) if args.scene.is_none() => Some(scenes::blast_track()),
        (None, _) => None,
    };
    if let Some(track) = &track {
        track.check(scene.bodies.len())?;
    }
    // The upper bound is the adapter's; Renderer::new checks it, naming the flag.
    for (flag, v) in [("--width", args.width), ("--height", args.height)] {
        if v == 0 {
            return Err(Error::Input(format!("{flag}: must be at least 1 pixel, got 0")));
        }
    }
    let mut recorder = Recorder::open(&args)?;

    let gpu = Arc::new(Gpu::new()?);
    let started = Instant::now();
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    if recorder.wants_images() {
        recorder.renderer = Some(Renderer::new(&gpu, &scene, args.width, args.height)?);
    }
    let setup = started.elapsed();

    let bar = ProgressBar::with_draw_target(Some(args.steps), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{wide_bar} {pos}/{len} steps, {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let stepped = step_and_record(&args, &mut world, track.as_ref(), &mut recorder, &bar, started);
    // cleared on success and on error alike, so no half-drawn bar precedes the message
    bar.finish_and_clear();
    let stage_ms = stepped?;
    // The GPU flags a non-finite or absurd body every step without a
    // readback; the run reads the flag here once (and read_state, which
    // every trace row calls, reads it too) and fails naming body and step.
    if let Some(fault) = world.faults()? {
        return Err(Error::Diverged(fault.to_string()));
    }
    let bodies = world.read_state()?;
    let wall = started.elapsed();
    let frames_written = recorder.frames_written;
    recorder.finish(args.every, scene.settings.dt)?;
    if let Some(path) = &args.state_out {
        output::write_file(path, &output::state_json(world.step_count(), world.time(), &bodies))?;
    }
    let ms = wall.as_secs_f64() * 1e3 / args.steps.max(1) as f64;
    println!(
        "{} bodies, {} steps of {:.5} s ({:.3} s simulated) on {}",
        bodies.len(),
        world.step_count(),
        scene.settings.dt,
        world.time(),
        gpu.describe()
    );
    println!("set-up {:.2} s, stepping {:.2} s ({ms:.3} ms/step, wall clock)", setup.as_secs_f64(), wall.as_secs_f64());
    if let Some((stage_ms, timed_by_gpu)) = stage_ms {
        let source = if timed_by_gpu { "GPU timestamps" } else { "wall clock per pass" };
        println!("per stage, ms/step ({source}):");
        for (stage, total) in &stage_ms {
            println!("  {:<18} {:>9.3}", stage.name(), total / args.steps.max(1) as f64);
        }
    }
    if let Some(dir) = &args.frames {
        println!("{frames_written} frames in {}", dir.display());
    }
    let report = world.contact_report()?;
    if report.overflowed() {
        eprintln!(
            "warning: the contact pools overflowed: up to {} candidate pairs ({} fit) and {} manifolds ({} fit) \
             were wanted in a step; the pairs beyond were dropped",
            report.pairs_max, report.pair_capacity, report.manifolds_max, report.manifold_capacity
        );
    }
    if let Some((lowest, b)) = bodies.iter().enumerate().min_by(|a, b| a.1.position[1].total_cmp(&b.1.position[1])) {
        let fastest = bodies.iter().map(|b| glam::Vec3::from(b.linear_velocity).length()).fold(0.0, f32::max);
        println!(
            "lowest body {lowest} at y = {:.3} m; fastest body {fastest:.3} m/s",
            b.position[1]
        );
    }
    Ok(())
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
        if done % args.every == 0 || done == args.steps {
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

/// Largest GIF frame: frames are scaled down to fit this box, and at most
/// `GIF_FRAMES + 1` are kept (see [`Reel`]), so a GIF of any run stays a few
/// tens of MB in memory.
const GIF_BOX: u32 = 480;
const GIF_FRAMES: usize = 150;
/// Largest contact-sheet tile, and at most `SHEET_TILES + 1` tiles.
const SHEET_BOX: u32 = 320;
const SHEET_TILES: usize = 24;

/// What `run` records at steps 0, K, 2K, ... and the last: trace rows,
/// PNG frames, and the frames kept for a GIF and a contact sheet.
struct Recorder {
    trace: Option<(PathBuf, BufWriter<File>)>,
    frames_dir: Option<PathBuf>,
    gif: Option<(PathBuf, Reel)>,
    sheet: Option<(PathBuf, Reel)>,
    /// Made once the GPU is up, if any image is wanted.
    renderer: Option<Renderer>,
    frames_written: u64,
}

impl Recorder {
    /// Creates every output file and directory now, so a bad path fails
    /// before the run rather than after it.
    fn open(args: &RunArgs) -> Result<Recorder, Error> {
        let trace = match &args.trace {
            Some(path) => {
                let file = File::create(path).map_err(|source| io_err(path, source))?;
                let mut w = BufWriter::new(file);
                writeln!(w, "{}", output::TRACE_HEADER).map_err(|source| io_err(path, source))?;
                Some((path.clone(), w))
            }
            None => None,
        };
        if let Some(dir) = &args.frames {
            std::fs::create_dir_all(dir).map_err(|e| {
                Error::Input(format!("--frames: cannot create directory {}: {e}", dir.display()))
            })?;
        }
        let probe = |flag: &str, path: &Path| {
            File::create(path).map(drop).map_err(|e| Error::Input(format!("{flag}: cannot write {}: {e}", path.display())))
        };
        let gif = match &args.gif {
            Some(path) => {
                probe("--gif", path)?;
                Some((path.clone(), Reel::new(GIF_FRAMES, GIF_BOX)))
            }
            None => None,
        };
        let sheet = match &args.contact_sheet {
            Some(path) => {
                probe("--contact-sheet", path)?;
                Some((path.clone(), Reel::new(SHEET_TILES, SHEET_BOX)))
            }
            None => None,
        };
        Ok(Recorder { trace, frames_dir: args.frames.clone(), gif, sheet, renderer: None, frames_written: 0 })
    }

    fn wants_images(&self) -> bool {
        self.frames_dir.is_some() || self.gif.is_some() || self.sheet.is_some()
    }

    fn is_active(&self) -> bool {
        self.trace.is_some() || self.wants_images()
    }

    fn record(&mut self, world: &World) -> Result<(), Error> {
        if let Some((path, w)) = self.trace.as_mut() {
            let bodies = world.read_state()?;
            output::write_trace_rows(w, world.step_count(), world.time(), &bodies).map_err(|e| io_err(path, e))?;
        }
        let Some(renderer) = self.renderer.as_mut() else { return Ok(()) };
        let image = renderer.render(world)?;
        if let Some(dir) = &self.frames_dir {
            render::write_png(&image, &dir.join(format!("frame_{:06}.png", self.frames_written)))?;
        }
        self.frames_written += 1;
        for (_, reel) in self.gif.iter_mut().chain(self.sheet.iter_mut()) {
            reel.push(&image);
        }
        Ok(())
    }

    /// Flushes the trace and writes the GIF and the contact sheet.
    fn finish(self, every: u64, dt: f32) -> Result<(), Error> {
        if let Some((path, mut w)) = self.trace {
            w.flush().map_err(|e| io_err(&path, e))?;
        }
        if let Some((path, reel)) = self.gif {
            // real time where GIF allows: browsers slow delays under 20 ms to 100 ms
            let ms = (every * reel.stride) as f64 * dt as f64 * 1e3;
            let frame_ms = ms.round().clamp(20.0, 10_000.0) as u32;
            render::write_gif(&reel.finish(), frame_ms, &path)?;
        }
        if let Some((path, reel)) = self.sheet {
            let tiles = reel.finish();
            let columns = (tiles.len() as f64).sqrt().ceil() as u32;
            render::write_png(&render::contact_sheet(&tiles, columns, None)?, &path)?;
        }
        Ok(())
    }
}

/// A bounded, evenly spread selection of a run's frames, each scaled down
/// to fit a `size` x `size` box. Frames 0, s, 2s, ... are kept (s = stride);
/// when more than `cap` are kept every other one is dropped and s doubles.
/// The latest frame is kept too, so the run's last frame is always there:
/// at most `cap + 1` frames in all.
struct Reel {
    kept: Vec<RgbaImage>,
    /// The latest frame if it is not in `kept`.
    latest: Option<RgbaImage>,
    stride: u64,
    seen: u64,
    cap: usize,
    size: u32,
}

impl Reel {
    fn new(cap: usize, size: u32) -> Reel {
        // an even cap keeps the newest frame when thinning (its index, cap, is even)
        Reel { kept: Vec::new(), latest: None, stride: 1, seen: 0, cap: cap.max(2) & !1, size }
    }

    fn push(&mut self, image: &RgbaImage) {
        let (w, h) = image.dimensions();
        let scale = (self.size as f64 / w.max(h) as f64).min(1.0);
        let small = if scale < 1.0 {
            let (sw, sh) = (((w as f64 * scale).round() as u32).max(1), ((h as f64 * scale).round() as u32).max(1));
            image::imageops::resize(image, sw, sh, image::imageops::FilterType::Triangle)
        } else {
            image.clone()
        };
        if self.seen % self.stride == 0 {
            self.kept.push(small);
            self.latest = None;
            if self.kept.len() > self.cap {
                self.kept = std::mem::take(&mut self.kept).into_iter().step_by(2).collect();
                self.stride *= 2;
            }
        } else {
            self.latest = Some(small);
        }
        self.seen += 1;
    }

    fn finish(self) -> Vec<RgbaImage> {
        let mut frames = self.kept;
        frames.extend(self.latest);
        frames
    }
}

fn io_err(path: &std::path::Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}

fn info() -> Result<(), Error> {
    let gpu = Gpu::new()?;
    let i = &gpu.info;
    let l = &gpu.limits;
    println!("adapter:  {}", i.name);
    println!("backend:  {:?}", i.backend);
    println!("type:     {:?}", i.device_type);
    println!("driver:   {} {}", i.driver, i.driver_info);
    println!("timestamp queries: {}", gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY));
    println!("max storage buffer binding: {} bytes", l.max_storage_buffer_binding_size);
    println!("max buffer size:            {} bytes", l.max_buffer_size);
    println!("max storage buffers/stage:  {}", l.max_storage_buffers_per_shader_stage);
    println!("max workgroups/dimension:   {}", l.max_compute_workgroups_per_dimension);
    println!("GPU memory per body:        {} bytes", verlet::world::bytes_per_body());
    println!("largest scene:              {} bodies", verlet::world::max_bodies(&gpu));
    Ok(())
}
