//! The `verlet` command line (INTERFACE.md section 2).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use clap::{Parser, Subcommand};
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
    /// Step length in seconds; overrides settings.dt.
    #[arg(long)]
    dt: Option<f32>,
    /// Write the state after the last step here (JSON).
    #[arg(long)]
    state_out: Option<PathBuf>,
    /// Write a CSV trace here: every body at steps 0, K, 2K, ... and the last.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// K for --trace and --frames.
    #[arg(long, default_value_t = 1)]
    every: u64,
    /// Time every stage of every step (GPU timestamps where the adapter has
    /// them) and print the cost per stage; steps are then submitted one by one.
    #[arg(long)]
    profile: bool,
    /// Write PNG frames into this directory.
    #[arg(long)]
    frames: Option<PathBuf>,
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
    if args.frames.is_some() {
        return Err(Error::Input("--frames: off-screen rendering is not built yet".into()));
    }
    let mut trace = match &args.trace {
        Some(path) => {
            let file = std::fs::File::create(path).map_err(|source| Error::Io { path: path.display().to_string(), source })?;
            let mut w = std::io::BufWriter::new(file);
            writeln!(w, "{}", output::TRACE_HEADER).map_err(|source| io_err(path, source))?;
            Some((path.clone(), w))
        }
        None => None,
    };

    let gpu = Arc::new(Gpu::new()?);
    let started = Instant::now();
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    let setup = started.elapsed();
    let started = Instant::now();
    let chunk = if trace.is_some() { args.every } else { args.steps.max(1) };
    let profile = args.profile;
    let mut stage_ms: Vec<(verlet::step::Stage, f64)> = Vec::new();
    let mut timed_by_gpu = false;
    let mut record = |world: &World| -> Result<(), Error> {
        if let Some((path, w)) = trace.as_mut() {
            let bodies = world.read_state()?;
            output::write_trace_rows(w, world.step_count(), world.time(), &bodies).map_err(|e| io_err(path, e))?;
        }
        Ok(())
    };
    record(&world)?;
    while world.step_count() < args.steps {
        let n = chunk.min(args.steps - world.step_count());
        if profile {
            let t = world.profile(n)?;
            timed_by_gpu = t.gpu_timestamps;
            for (k, (stage, ms)) in t.ms_per_step.into_iter().enumerate() {
                match stage_ms.get_mut(k) {
                    Some(entry) => entry.1 += ms * n as f64,
                    None => stage_ms.push((stage, ms * n as f64)),
                }
            }
        } else {
            world.step(n)?;
        }
        record(&world)?;
    }
    drop(record);
    let bodies = world.read_state()?;
    let wall = started.elapsed();
    if let Some((path, mut w)) = trace.take() {
        w.flush().map_err(|e| io_err(&path, e))?;
    }
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
    if profile {
        let source = if timed_by_gpu { "GPU timestamps" } else { "wall clock per pass" };
        println!("per stage, ms/step ({source}):");
        for (stage, total) in &stage_ms {
            println!("  {:<18} {:>9.3}", stage.name(), total / args.steps.max(1) as f64);
        }
    }
    let report = world.contact_report()?;
    if report.overflowed() {
        eprintln!(
            "warning: contact lists overflowed: a body wanted {} contact points, {} fit; the farthest were dropped",
            report.run_max, report.capacity
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
    Ok(())
}
