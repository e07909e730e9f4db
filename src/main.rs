//! The `verlet` command line (INTERFACE.md section 2).

use std::io::Write;
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

/// `print!` that returns an error (`stdout_error`) instead of panicking
/// when stdout is closed or full; `main` ends quietly on a closed pipe.
macro_rules! out {
    ($($t:tt)*) => {
        std::io::Write::write_fmt(&mut std::io::stdout(), format_args!($($t)*)).map_err($crate::stdout_error)
    };
}

/// `println!` as [`out!`] is `print!`.
macro_rules! outln {
    ($($t:tt)*) => {
        out!("{}\n", format_args!($($t)*))
    };
}

/// `eprintln!` that never panics: std's panics when stderr cannot be
/// written, and with `2>/dev/full` every error became a panic (exit 101)
/// and a run whose only line there was a warning died before its first
/// step. What cannot be said on stderr is dropped; the exit status still
/// says how the command ended. (It shadows std's for this crate's modules.)
macro_rules! eprintln {
    ($($t:tt)*) => {{
        let _ = std::io::Write::write_fmt(&mut std::io::stderr(), format_args!("{}\n", format_args!($($t)*)));
    }};
}

mod harness;
mod plot;

/// What a failed write to stdout becomes: an error naming stdout, or for
/// a reader that closed the pipe, the quiet end `main` gives it.
fn stdout_error(source: std::io::Error) -> Error {
    Error::Io { path: "stdout".into(), source }
}

/// Whether `e` is stdout's reader having gone (`verlet scene ... | head`).
fn is_closed_pipe(e: &Error) -> bool {
    matches!(e, Error::Io { path, source } if path == "stdout" && source.kind() == std::io::ErrorKind::BrokenPipe)
}

/// The exit status after stdout's reader went: 128 + SIGPIPE, as a shell
/// reports a tool that SIGPIPE ended (`yes | head`), so `set -o pipefail`
/// scripts see what they see of any other tool.
const CLOSED_PIPE_EXIT: u8 = 141;

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
        /// A built-in scene (listed below).
        name: String,
        /// Bodies, boxes, rows, links, planks, ragdolls, pyramids or balls per side, by scene.
        #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
        count: Option<usize>,
        /// Seed of the random scenes (cubes, pile); 1 if not given.
        #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
        seed: Option<u64>,
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
    /// pile-100k, pile-1m (cubes heaped four deep), pyramid, chain,
    /// large_pyramid, many_pyramids, joint_grid (Box3D's benchmarks at its
    /// sizes), or SCENE:COUNT. Default: all (with --quick: cubes-1k, cubes-10k, pyramid, chain).
    #[arg(long, value_delimiter = ',')]
    cases: Vec<String>,
    /// Steps per repetition (default 300; 60 with --quick).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    steps: Option<u64>,
    /// Body-steps per repetition: a case takes min(steps, max(20, this / bodies))
    /// steps, so large cases finish (default 3000000: 300 steps of 10k cubes; 600000 with --quick).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    body_steps: Option<u64>,
    /// Repetitions per case, each from the initial state; the median is reported (default 3; 2 with --quick).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    reps: Option<usize>,
    /// A short run: fewer cases, steps and repetitions.
    #[arg(long)]
    quick: bool,
    /// Steps timed stage by stage after the repetitions (default 10; 3 with --quick; 0: none).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    profile_steps: Option<u64>,
    /// Write the full report as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write one CSV row per case here.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Draw the report here, as SVG: ms per step against bodies (ours and
    /// the peer's, log axes) and each case's step split into its parts.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Do not run the rapier3d peer even when it is built in.
    #[arg(long)]
    no_peer: bool,
    /// Run the peer only for cases of at most this many bodies.
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    peer_max_bodies: Option<usize>,
    /// Let bodies sleep, ours and rapier's (off by default in the bench).
    #[arg(long)]
    rapier_sleeping: bool,
    /// rapier's num_solver_iterations (default: rapier's own, 4).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    rapier_iterations: Option<usize>,
    /// Threads of the rapier3d peer's rayon pool (default: LP_NUM_THREADS
    /// when set above 0, else the machine's cores); it also runs on one thread, reported beside.
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    peer_threads: Option<usize>,
    /// Most steps the largest pile case of at most 10k bodies takes to come to
    /// rest, with sleeping on, for the memory of a settled pile (default 1800
    /// with --settle; given alone, it asks for --settle; 0: not settled).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    settle_steps: Option<u64>,
    /// Also bring the largest pile case of at most 10k bodies to rest and
    /// report the memory a settled pile holds.
    #[arg(long)]
    settle: bool,
    /// Also time whole processes starting with Mesa's shader cache disabled
    /// (`verlet run --builtin cubes --count 10 --steps 1`; 3 runs, 1 with --quick).
    #[arg(long)]
    cold_start: bool,
    /// Also time an off-screen render of the 1000-cube scene at 640 x 480.
    #[arg(long)]
    render: bool,
    /// Also time ten cubes' steps over the dispatches of a step: what a
    /// dispatch costs before any work.
    #[arg(long)]
    dispatch_cost: bool,
    /// All of --settle, --cold-start, --render and --dispatch-cost.
    #[arg(long)]
    all: bool,
}

#[derive(clap::Args)]
struct RunArgs {
    /// The scene file (JSON, INTERFACE.md section 1). Without it, --builtin.
    scene: Option<PathBuf>,
    /// A built-in scene to run instead of a file (listed below).
    #[arg(long, conflicts_with = "scene")]
    builtin: Option<String>,
    /// --count of the built-in scene.
    #[arg(long, requires = "builtin", allow_negative_numbers = true, value_parser = whole_usize)]
    count: Option<usize>,
    /// --seed of the built-in scene (1 if not given).
    #[arg(long, requires = "builtin", allow_negative_numbers = true, value_parser = whole_u64)]
    seed: Option<u64>,
    /// Steps to take (required).
    #[arg(long = "steps", value_name = "STEPS", allow_negative_numbers = true, value_parser = whole_u64)]
    steps_given: Option<u64>,
    /// `--steps` once `run` has checked it was given.
    #[arg(skip)]
    steps: u64,
    /// A scripted input track (JSON: impulses, explosions, poses,
    /// velocities, fixed switches, wind at given times) applied between
    /// steps. `--builtin blast` plays its own track unless this is given.
    #[arg(long)]
    input: Option<PathBuf>,
    /// Step length in seconds; overrides settings.dt.
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f32>,
    /// Write the state after the last step here (JSON).
    #[arg(long)]
    state_out: Option<PathBuf>,
    /// Write a CSV trace here: every body at steps 0, K, 2K, ... and the last.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// K for --trace, --frames, --gif and --contact-sheet.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = whole_u64)]
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
    #[arg(long, default_value_t = 640, allow_negative_numbers = true, value_parser = whole_u32)]
    width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 480, allow_negative_numbers = true, value_parser = whole_u32)]
    height: u32,
}

/// The command line as `Cli::try_parse` reads it, with the built-in scenes
/// listed under the help of `verlet`, `verlet scene` and `verlet run`.
fn parse() -> Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let list = scene_list();
    let mut command = Cli::command()
        .after_help(list.clone())
        .mut_subcommand("scene", |c| c.after_help(list.clone()))
        .mut_subcommand("run", |c| c.after_help(list.clone()));
    let mut matches = command.try_get_matches_from_mut(std::env::args_os())?;
    Cli::from_arg_matches_mut(&mut matches).map_err(|e| e.format(&mut command))
}

/// The built-in scenes, a line each, from `scenes::NAMES` (so a scene added
/// there is listed without touching the help).
fn scene_list() -> String {
    let width = scenes::NAMES.iter().map(|(name, _)| name.len()).max().unwrap_or(0);
    let mut list = String::from("Built-in scenes (`verlet scene NAME`, `verlet run --builtin NAME`):");
    for (name, what) in scenes::NAMES {
        list.push_str(&format!("\n  {name:<width$}  {what}"));
    }
    list
}

fn main() -> ExitCode {
    // before any thread starts: it may set an environment variable
    verlet::gpu::quiet_window_system_probe();
    let cli = match parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("{}", clap_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Run(args) => run(args),
        Command::Scene { name, count, seed } => print_scene(&name, count, seed),
        Command::Info => info(),
        Command::Bench(a) => bench(a),
    };
    // what stdout still holds goes out now, so that a full disk is reported
    let result = result.and_then(|()| std::io::stdout().flush().map_err(stdout_error));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_closed_pipe(&e) => ExitCode::from(CLOSED_PIPE_EXIT),
        Err(e) => {
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}

/// `verlet bench`: the library runs and reports; the chart (`--plot`) is
/// drawn here, so the library holds no plotting.
fn bench(a: BenchArgs) -> Result<(), verlet::Error> {
    if let Some(path) = &a.plot {
        if path.extension().is_none_or(|e| !e.eq_ignore_ascii_case("svg")) {
            return Err(verlet::Error::Input(format!(
                "--plot: {} does not end in .svg: the chart is written as SVG",
                path.display()
            )));
        }
        // before the long run, as the library does for --json and --csv
        verlet::output::check_output("--plot", path)?;
        let outputs: Vec<(&str, &Path)> = [("--json", &a.json), ("--csv", &a.csv), ("--plot", &a.plot)]
            .into_iter()
            .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
            .collect();
        verlet::output::check_distinct(&[], &outputs)?;
    }
    let report = harness::run(&harness::Options {
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
        settle_steps: a.settle_steps,
        extras: harness::Extras {
            settle: a.settle || a.all,
            cold_start: a.cold_start || a.all,
            render: a.render || a.all,
            dispatch_cost: a.dispatch_cost || a.all,
        },
        rapier_iterations: a.rapier_iterations,
        peer_threads: a.peer_threads,
        command: std::env::args_os().map(|a| a.to_string_lossy().into_owned()).collect::<Vec<_>>().join(" "),
    })?;
    if let Some(path) = &a.plot {
        let title = format!("{} on {} ({} cores)", report.adapter, report.cpu, report.cores);
        let peer = report.peer.split_whitespace().next().unwrap_or("peer").to_string();
        let chart = plot::svg(&title, &peer, &plot::rows(&report)).map_err(|why| verlet::Error::Input(format!("--plot: {why}")))?;
        verlet::output::write_file(path, &chart)?;
        eprintln!("wrote {}", path.display());
    }
    out!("{}", harness::table(&report))
}

/// One line for a command-line error: clap's first line, or for a value
/// its parser refused, "--flag: what it takes, got VALUE".
fn clap_line(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() == ErrorKind::ValueValidation {
        if let (Some(ContextValue::String(arg)), Some(ContextValue::String(value)), Some(why)) =
            (e.get(ContextKind::InvalidArg), e.get(ContextKind::InvalidValue), std::error::Error::source(e))
        {
            let flag = arg.split_whitespace().next().unwrap_or(arg);
            return format!("error: {flag}: {why}, got {value}");
        }
    }
    // a missing argument: clap names it on the lines after the first
    if e.kind() == ErrorKind::MissingRequiredArgument {
        if let Some(ContextValue::Strings(missing)) = e.get(ContextKind::InvalidArg) {
            return format!("error: missing {}", missing.join(", "));
        }
    }
    // clap's first line names the bad flag and why
    let text = e.render().to_string();
    text.lines().next().unwrap_or("error: bad arguments").to_string()
}

/// A whole number flag's value: digits only, no sign, within the type.
fn whole<T: TryFrom<u128> + std::fmt::Display>(text: &str, max: T) -> Result<T, String> {
    let text = text.strip_prefix('+').unwrap_or(text);
    let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
    let value: Option<u128> = if digits { text.parse().ok() } else { None };
    match value {
        None if !digits => Err("must be a non-negative whole number".into()),
        value => value.and_then(|v| T::try_from(v).ok()).ok_or_else(|| format!("must be at most {max}")),
    }
}

fn whole_u64(text: &str) -> Result<u64, String> {
    whole(text, u64::MAX)
}

fn whole_usize(text: &str) -> Result<usize, String> {
    whole(text, usize::MAX)
}

fn whole_u32(text: &str) -> Result<u32, String> {
    whole(text, u32::MAX)
}

/// The seed of the random built-in scenes when `--seed` is not given.
const DEFAULT_SEED: u64 = 1;

/// Warns when `--seed` is given to a built-in scene that is not random.
fn warn_unused_seed(name: &str, seed: Option<u64>) {
    if seed.is_some() && scenes::body_count(name, None).is_some() && !scenes::RANDOM.contains(&name) {
        eprintln!("warning: --seed: the {name} scene is not random (the random ones: {}); ignored", scenes::RANDOM.join(", "));
    }
}

/// Warns when `--count` is given to a built-in scene that takes none.
fn warn_unused_count(name: &str, count: Option<usize>) {
    if count.is_some() && scenes::body_count(name, None).is_some() && scenes::default_count(name).is_none() {
        eprintln!("warning: --count: the {name} scene takes no count; ignored");
    }
}

fn print_scene(name: &str, count: Option<usize>, seed: Option<u64>) -> Result<(), Error> {
    // bounded before it is built: any adapter's limit (`verlet run` checks this one's)
    let scene = scenes::checked(name, count, seed.unwrap_or(DEFAULT_SEED), scenes::MAX_BODIES)?;
    warn_unused_count(name, count);
    warn_unused_seed(name, seed);
    outln!("{}", scene.to_json())?;
    Ok(())
}

/// Loads the scene file, naming the file in a syntax error (the field
/// errors name the field).
fn load_scene(path: &Path) -> Result<Scene, Error> {
    Scene::from_path(path).map_err(|e| match e {
        verlet::SceneError::Syntax { .. } => Error::Input(format!("{}: {e}", path.display())),
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

/// Checks every output path before anything runs: each can be written
/// (its directory exists and takes files, it is no directory; `--frames`'
/// directory takes files, or can be made), and none is an input or another
/// output.
fn check_outputs(args: &RunArgs) -> Result<(), Error> {
    let files = [
        ("--state-out", &args.state_out),
        ("--trace", &args.trace),
        ("--gif", &args.gif),
        ("--contact-sheet", &args.contact_sheet),
    ];
    let mut outputs: Vec<(&str, &Path)> = files.iter().filter_map(|(flag, p)| p.as_deref().map(|p| (*flag, p))).collect();
    if let Some(dir) = &args.frames {
        outputs.push(("--frames", dir));
    }
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    if let Some(scene) = &args.scene {
        inputs.push(("the scene file", scene));
    }
    if let Some(track) = &args.input {
        inputs.push(("the --input track", track));
    }
    output::check_distinct(&inputs, &outputs)?;
    // a failed run keeps the trace's rows beside it: that name must be no
    // input or output either (an existing file there is never replaced: see
    // `Recorder::abandon`)
    if let Some(trace) = &args.trace {
        let partial = partial_path(trace);
        if let Some((input, _)) = inputs.iter().find(|(_, p)| output::same_file(&partial, p)) {
            return Err(Error::Input(format!(
                "--trace: a failed run keeps its rows in {}, which is {input}, an input; give --trace another path",
                partial.display()
            )));
        }
        if let Some((other, _)) = outputs.iter().find(|(_, p)| output::same_file(&partial, p)) {
            return Err(Error::Input(format!(
                "--trace: a failed run keeps its rows in {}, which is {other}'s output; give each its own path",
                partial.display()
            )));
        }
    }
    if let Some(dir) = &args.frames {
        output::check_output_dir("--frames", dir)?;
        let others: Vec<(&str, &Path)> = outputs.iter().copied().filter(|(flag, _)| *flag != "--frames").collect();
        output::check_frames_dir(dir, &inputs, &others)?;
    }
    // An output directly in the directory --frames makes has no directory
    // to probe yet: --frames' check above stands for it (`--frames nd --gif
    // nd/anim.gif` was refused as "no directory nd"). Nothing is made
    // here: the directory is made last of the set-up (`Recorder::open`),
    // once the GPU, the world and the renderer are, so a run refused for
    // any reason before its first step makes nothing.
    let made = args.frames.as_deref().filter(|dir| std::fs::symlink_metadata(dir).is_err());
    for (flag, path) in files.iter().filter_map(|(flag, p)| p.as_deref().map(|p| (*flag, p))) {
        match made {
            Some(dir) if output::is_in_dir(path, dir) => {}
            _ => output::check_output(flag, path)?,
        }
    }
    Ok(())
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

/// Warns when `--frames DIR` holds frame-named files that this run will
/// not replace: an earlier, longer run's frames stayed, unsaid, after the
/// new run's, and a video made of DIR switched runs part way. They are
/// left as they are (they may be wanted); the warning names how many and
/// the first and last.
fn warn_stale_frames(args: &RunArgs) {
    let Some(dir) = &args.frames else { return };
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    // this run's frames: steps 0, K, 2K, ... and the last
    let count = (args.steps / args.every).saturating_add(1 + u64::from(!args.steps.is_multiple_of(args.every)));
    let mut stale: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name())
        .filter(|name| output::is_frame_name(name) && output::frame_number(name).is_none_or(|k| k >= count))
        .map(|name| name.to_string_lossy().into_owned())
        .collect();
    stale.sort();
    let (Some(first), Some(last)) = (stale.first(), stale.last()) else { return };
    let which = if stale.len() == 1 {
        format!("1 frame file ({first})")
    } else {
        format!("{} frame files ({first} to {last})", stale.len())
    };
    eprintln!(
        "warning: --frames: {} holds {which} that this run, writing {} to {}, will not replace: they stay, mixed with this run's",
        dir.display(),
        output::frame_name(0),
        output::frame_name(count - 1)
    );
}

/// The track's events that acted before the step a fault was found in or
/// the one before (where the state may have gone bad), named for the
/// fault's message: an impulse of 1e30 N s is the input's doing, not the
/// solver's.
fn inputs_before(track: Option<&Track>, fault: &verlet::world::Fault, world: &World) -> String {
    let Some(track) = track else { return String::new() };
    let acting = track.acting_before(fault.step.saturating_sub(1)..=fault.step, world.settings().dt);
    if acting.is_empty() {
        return String::new();
    }
    let named: Vec<String> = acting.iter().take(3).map(|(k, name)| format!("events[{k}] ({name})")).collect();
    let more = if acting.len() > 3 { format!(" and {} more", acting.len() - 3) } else { String::new() };
    format!("; the input track's {}{more} acted just before", named.join(", "))
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

/// Where a failed run keeps the trace's rows: `TRACE.partial` (or, when a
/// file is there, `TRACE.partial.1`, ...: `AtomicFile::keep_beside`).
fn partial_path(trace: &Path) -> PathBuf {
    let mut partial = trace.as_os_str().to_os_string();
    partial.push(".partial");
    PathBuf::from(partial)
}

/// How `verlet run` is called, for an error that finds the scene or
/// `--steps` missing: one round trip to a working command.
const RUN_USAGE: &str = "usage: verlet run SCENE.json --steps N [OPTIONS], or verlet run --builtin NAME --steps N [OPTIONS] \
                         (`verlet run --help` lists the options and the built-in scenes)";

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

/// `n` and the noun, singular for one (`1 body`, `2 bodies`).
fn counted(n: impl Into<u64>, one: &str, many: &str) -> String {
    let n = n.into();
    format!("{n} {}", if n == 1 { one } else { many })
}

fn run(mut args: RunArgs) -> Result<(), Error> {
    check_required(&mut args)?;
    let args = args;
    // Everything the user gave is checked before the GPU is touched, and a
    // built-in scene's size before it is built.
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
    let (file_scene, body_count) = match (&args.scene, &args.builtin) {
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
            (Some(scene), n)
        }
        (None, Some(name)) => {
            warn_unused_count(name, args.count);
            warn_unused_seed(name, args.seed);
            (None, scenes::check(name, args.count, scenes::MAX_BODIES)?)
        }
        (None, None) => return Err(Error::Input(format!("missing a scene: give a scene file or --builtin NAME; {RUN_USAGE}"))),
    };
    let track = match (&args.input, args.builtin.as_deref()) {
        (Some(path), _) => Some(load_track(path)?),
        (None, Some("blast")) if args.scene.is_none() => Some(scenes::blast_track()),
        (None, _) => None,
    };
    if let Some(track) = &track {
        track.check(body_count as usize)?;
    }
    check_outputs(&args)?;
    warn_stale_frames(&args);

    let gpu = Arc::new(Gpu::new()?);
    let started = Instant::now();
    let scene = match (file_scene, &args.builtin) {
        (Some(scene), _) => scene,
        // the adapter's limit, still before the scene is built
        (None, Some(name)) => {
            let seed = args.seed.unwrap_or(DEFAULT_SEED);
            let mut scene = scenes::checked(name, args.count, seed, verlet::world::max_bodies(&gpu))?;
            with_dt(&mut scene, args.dt)?;
            scene
        }
        (None, None) => return Err(Error::Input(format!("missing a scene: give a scene file or --builtin NAME; {RUN_USAGE}"))),
    };
    if let Some(track) = &track {
        track.check_masses(&scene)?;
        warn_late_events(track, args.steps, scene.settings.dt);
    }
    let mut world = World::with_gpu(gpu.clone(), &scene)?;
    // last of the set-up: a run refused before here makes nothing
    let mut recorder = Recorder::open(&args, &gpu, &scene)?;
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
    // The GPU flags a non-finite or absurd body every step without a
    // readback; the run reads the flag here once (and read_state, which
    // every trace row calls, reads it too) and fails naming body and step.
    let outcome = stepped.and_then(|stage_ms| match world.faults()? {
        Some(fault) => Err(Error::Diverged(format!("{fault}{}", inputs_before(track.as_ref(), &fault, &world)))),
        None => Ok((stage_ms, world.read_state()?)),
    });
    let (stage_ms, bodies) = match outcome {
        Ok(done) => done,
        Err(e) => {
            // say what was kept; the run's other outputs are not written
            recorder.abandon(&args);
            return Err(e);
        }
    };
    let wall = started.elapsed();
    let frames_written = recorder.frames_written;
    let (gif_frames, sheet_frames) = (recorder.gif.as_ref().map_or(0, Reel::len), recorder.sheet.as_ref().map_or(0, Reel::len));
    let state_json = args.state_out.as_ref().map(|_| output::state_json(world.step_count(), world.time(), &bodies));
    let mut writes = recorder.finish(&args, scene.settings.dt);
    if let (Some(path), Some(text)) = (&args.state_out, &state_json) {
        writes.push((
            "--state-out",
            path,
            Box::new(move || output::write_file(path, text).map_err(|e| Error::Input(format!("--state-out: {e}")))),
        ));
    }
    output::write_each(writes)?;
    // (no figure a step where none was taken)
    let pace = match args.steps {
        0 => "no step taken".to_string(),
        n => format!("{:.3} ms/step", wall.as_secs_f64() * 1e3 / n as f64),
    };
    outln!(
        "{}, {} of {} s ({} s simulated) on {}",
        counted(bodies.len() as u64, "body", "bodies"),
        counted(world.step_count(), "step", "steps"),
        seconds(scene.settings.dt as f64, 5),
        seconds(world.time(), 3),
        gpu.describe()
    )?;
    outln!("set-up {:.2} s, stepping {:.2} s ({pace}, wall clock)", setup.as_secs_f64(), wall.as_secs_f64())?;
    if let Some((stage_ms, timed_by_gpu)) = stage_ms {
        let source = if timed_by_gpu { "GPU timestamps" } else { "wall clock per pass" };
        outln!("per stage, ms/step ({source}):")?;
        // the longest stage name sets the column (`restitution_contacts` broke a fixed one)
        let width = stage_ms.iter().map(|(stage, _)| stage.name().len()).max().unwrap_or(0);
        for (stage, total) in &stage_ms {
            outln!("  {:<width$}  {:>9.3}", stage.name(), total / args.steps.max(1) as f64)?;
        }
    }
    if let Some(dir) = &args.frames {
        outln!("{} in {}", counted(frames_written, "frame", "frames"), dir.display())?;
    }
    for (what, path, count) in [("GIF", &args.gif, gif_frames), ("contact sheet", &args.contact_sheet, sheet_frames)] {
        if let Some(path) = path {
            outln!("{what} of {} in {}", counted(count as u64, "frame", "frames"), path.display())?;
        }
    }
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
    if let Some((lowest, b)) = bodies.iter().enumerate().min_by(|a, b| a.1.position[1].total_cmp(&b.1.position[1])) {
        let length = |v: [f32; 3]| glam::Vec3::from(v).length();
        let fastest = |of: fn(&verlet::BodyOutput) -> [f32; 3]| {
            bodies.iter().enumerate().map(|(k, b)| (k, length(of(b)))).fold((0, 0.0f32), |a, b| if b.1 > a.1 { b } else { a })
        };
        let (moving, speed) = fastest(|b| b.linear_velocity);
        let (spinning, spin) = fastest(|b| b.angular_velocity);
        // a body is named only where one moves: "(body 0)" of a still scene
        // named a body for nothing
        // (what prints as 0.000 counts as still)
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
    if world.at_rest() {
        outln!("at rest: every body asleep or fixed; steps from then on change nothing and were counted, not run")?;
    }
    Ok(())
}

/// Warns of track events that come after the run's last step: they would
/// act before a step that is never taken.
fn warn_late_events(track: &Track, steps: u64, dt: f32) {
    let late: Vec<f64> = track.events().iter().filter(|e| Track::step_of(e.t, dt) >= steps).map(|e| e.t).collect();
    if let Some(&first) = late.first() {
        // (t = 1e300 printed three hundred digits)
        let first = if first >= 1e6 { format!("{first:e}") } else { format!("{first}") };
        eprintln!(
            "warning: --input: {} of {} events come at t >= {first} s, after the run's last step (it ends at {:.4} s): they do nothing",
            late.len(),
            track.events().len(),
            steps as f64 * dt as f64
        );
    }
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

/// Largest GIF frame: frames are scaled down to fit this box, and at most
/// `GIF_FRAMES + 1` are kept (see [`Reel`]), so a GIF of any run stays a few
/// tens of MB in memory.
const GIF_BOX: u32 = 480;
const GIF_FRAMES: usize = 150;
/// The shortest delay between a GIF's frames (ms) that viewers keep.
const GIF_MIN_DELAY_MS: f64 = 20.0;
/// Largest contact-sheet tile, and at most `SHEET_TILES + 1` tiles.
const SHEET_BOX: u32 = 320;
const SHEET_TILES: usize = 24;

/// What `run` records at steps 0, K, 2K, ... and the last: trace rows,
/// PNG frames, and the frames kept for a GIF and a contact sheet.
struct Recorder {
    /// The trace, written beside its path and renamed there when the run
    /// succeeds (into it, for a device or FIFO: [`output::AtomicFile`]).
    trace: Option<(PathBuf, output::AtomicFile)>,
    frames_dir: Option<PathBuf>,
    /// The frames kept for `--gif` and `--contact-sheet`.
    gif: Option<Reel>,
    sheet: Option<Reel>,
    /// Made if any image is wanted.
    renderer: Option<Renderer>,
    frames_written: u64,
    /// The last step recorded (trace rows and frames), if any.
    last_step: Option<u64>,
}

impl Recorder {
    /// Makes the renderer if any image is wanted (refusing a size beyond
    /// the adapter's), then creates the frames directory, then opens the
    /// trace (beside its path, which may be in that directory);
    /// `check_outputs` has checked every path already. Called last of the
    /// set-up, once the GPU and the world are made, so a run refused before
    /// its first step makes nothing. Nothing the user had is touched until
    /// the run succeeds.
    fn open(args: &RunArgs, gpu: &Gpu, scene: &Scene) -> Result<Recorder, Error> {
        let wants_images = args.frames.is_some() || args.gif.is_some() || args.contact_sheet.is_some();
        let renderer = if wants_images { Some(Renderer::new(gpu, scene, args.width, args.height)?) } else { None };
        if let Some(dir) = &args.frames {
            std::fs::create_dir_all(dir)
                .map_err(|e| Error::Input(format!("--frames: cannot create directory {}: {e}", dir.display())))?;
        }
        let trace = match &args.trace {
            Some(path) => {
                let flagged = |e: Error| Error::Input(format!("--trace: {e}"));
                let mut file = output::AtomicFile::create(path).map_err(flagged)?;
                writeln!(file.writer(), "{}", output::TRACE_HEADER).map_err(|source| flagged(io_err(path, source)))?;
                Some((path.clone(), file))
            }
            None => None,
        };
        let gif = args.gif.as_ref().map(|_| {
            // browsers play a GIF's delays under 20 ms as 100 ms: frames
            // closer than that are thinned, not shown slower (1 s at 60 Hz
            // played in 1.22 s, 0.06 s at dt 1 ms in 1.22 s)
            let mut reel = Reel::new(GIF_FRAMES, GIF_BOX);
            reel.at_least_apart(GIF_MIN_DELAY_MS, args.every, scene.settings.dt);
            reel
        });
        let sheet = args.contact_sheet.as_ref().map(|_| Reel::new(SHEET_TILES, SHEET_BOX));
        Ok(Recorder { trace, frames_dir: args.frames.clone(), gif, sheet, renderer, frames_written: 0, last_step: None })
    }

    fn wants_images(&self) -> bool {
        self.frames_dir.is_some() || self.gif.is_some() || self.sheet.is_some()
    }

    fn is_active(&self) -> bool {
        self.trace.is_some() || self.wants_images()
    }

    fn record(&mut self, world: &World) -> Result<(), Error> {
        if let Some((path, file)) = self.trace.as_mut() {
            let bodies = world.read_state()?;
            output::write_trace_rows(file.writer(), world.step_count(), world.time(), &bodies)
                .map_err(|e| Error::Input(format!("--trace: {}", io_err(path, e))))?;
        }
        if let Some(renderer) = self.renderer.as_mut() {
            let image = renderer.render(world)?;
            if let Some(dir) = &self.frames_dir {
                let path = dir.join(output::frame_name(self.frames_written));
                render::write_png(&image, &path).map_err(|e| Error::Input(format!("--frames: {e}")))?;
            }
            self.frames_written += 1;
            for reel in self.gif.iter_mut().chain(self.sheet.iter_mut()) {
                reel.push(&image);
            }
        }
        self.last_step = Some(world.step_count());
        Ok(())
    }

    /// What commits the trace and writes the GIF and the contact sheet, at
    /// the paths `args` gives (`output::write_each` runs them, each whatever
    /// became of the others).
    fn finish<'a>(self, args: &'a RunArgs, dt: f32) -> Vec<output::EndWrite<'a>> {
        let mut writes: Vec<output::EndWrite<'a>> = Vec::new();
        if let (Some((_, file)), Some(path)) = (self.trace, args.trace.as_deref()) {
            writes.push(("--trace", path, Box::new(move || file.commit().map_err(|e| Error::Input(format!("--trace: {e}"))))));
        }
        if let (Some(reel), Some(path)) = (self.gif, args.gif.as_deref()) {
            // real time: the frames are at least GIF_MIN_DELAY_MS apart
            let ms = (args.every * reel.stride) as f64 * dt as f64 * 1e3;
            let frame_ms = ms.clamp(GIF_MIN_DELAY_MS, 10_000.0);
            writes.push((
                "--gif",
                path,
                Box::new(move || {
                    render::write_gif(&reel.finish(), frame_ms, path).map_err(|e| Error::Input(format!("--gif: {e}")))
                }),
            ));
        }
        if let (Some(reel), Some(path)) = (self.sheet, args.contact_sheet.as_deref()) {
            writes.push((
                "--contact-sheet",
                path,
                Box::new(move || {
                    let tiles = reel.finish();
                    let columns = (tiles.len() as f64).sqrt().ceil() as u32;
                    render::write_png(&render::contact_sheet(&tiles, columns, None)?, path)
                        .map_err(|e| Error::Input(format!("--contact-sheet: {e}")))
                }),
            ));
        }
        writes
    }

    /// After a failed run: keeps the trace rows recorded so far beside the
    /// trace's path (`PATH.partial`, or `PATH.partial.1`, ... when a file is
    /// there: none is replaced), never at it, and says on stderr what was
    /// kept and what was not written. A trace into a device or FIFO keeps
    /// its rows nowhere: nothing is written into it, and no file is made
    /// beside it.
    fn abandon(self, args: &RunArgs) {
        let upto = match self.last_step {
            Some(step) => format!("steps 0 to {step}"),
            None => "no step".to_string(),
        };
        if let Some((path, file)) = self.trace {
            let partial = partial_path(&path);
            let kept = match self.last_step {
                // a device or FIFO: no file is made beside it (/dev/null.partial)
                Some(_) if file.is_special() => format!("its rows of {upto} were not kept: it is no regular file"),
                Some(_) => match file.keep_beside(&partial) {
                    Ok(kept) if kept == partial => format!("its rows of {upto} are in {}", kept.display()),
                    Ok(kept) => {
                        format!("its rows of {upto} are in {} ({} was there already, and stays)", kept.display(), partial.display())
                    }
                    Err(e) => format!("its rows could not be kept: {e}"),
                },
                None => "no rows were recorded".to_string(),
            };
            eprintln!("note: --trace: {} was left as it was (the run failed); {kept}", path.display());
        }
        match &self.frames_dir {
            Some(dir) if self.frames_written == 0 => eprintln!("note: --frames: no frame was written to {}", dir.display()),
            Some(dir) => eprintln!("note: --frames: {} frames of {upto} were written to {}", self.frames_written, dir.display()),
            None => {}
        }
        for (flag, path) in [("--gif", &args.gif), ("--contact-sheet", &args.contact_sheet), ("--state-out", &args.state_out)] {
            if let Some(path) = path {
                eprintln!("note: {flag}: {} was left as it was (the run failed)", path.display());
            }
        }
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
        if self.seen.is_multiple_of(self.stride) {
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

    /// Keeps frames at least `ms` apart in simulated time, recorded every
    /// `every` steps of `dt` (before the first frame).
    fn at_least_apart(&mut self, ms: f64, every: u64, dt: f32) {
        self.stride = (ms / (every as f64 * dt as f64 * 1e3)).ceil().max(1.0) as u64;
    }

    /// How many frames `finish` gives.
    fn len(&self) -> usize {
        self.kept.len() + usize::from(self.latest.is_some())
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
    outln!("adapter:  {}", i.name)?;
    outln!("backend:  {:?}", i.backend)?;
    outln!("type:     {:?}", i.device_type)?;
    outln!("driver:   {} {}", i.driver, i.driver_info)?;
    outln!("timestamp queries: {}", gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY))?;
    outln!("max storage buffer binding: {} bytes", l.max_storage_buffer_binding_size)?;
    outln!("max buffer size:            {} bytes", l.max_buffer_size)?;
    outln!("max storage buffers/stage:  {}", l.max_storage_buffers_per_shader_stage)?;
    outln!("max workgroups/dimension:   {}", l.max_compute_workgroups_per_dimension)?;
    use verlet::world::MANIFOLDS_PER_BODY;
    use verlet::world::{body_bytes, bytes_per_body, manifold_bytes, pair_bytes, PAIRS_PER_BODY, SHRINK_AFTER_STEPS};
    outln!(
        "GPU memory per body:        {} bytes as a world is made: {} its own, {} its share of the contact pools ({PAIRS_PER_BODY} pairs, {MANIFOLDS_PER_BODY} manifolds)",
        bytes_per_body(),
        body_bytes(),
        bytes_per_body() - body_bytes()
    )?;
    outln!(
        "contact pools:              {} bytes a pair, {} a manifold, by need: grown when a step fills three quarters, \
         made twice the need when {SHRINK_AFTER_STEPS} steps in a row fill less than a quarter (sleepers hold none)",
        pair_bytes(),
        manifold_bytes()
    )?;
    let (most_pairs, most_manifolds) = verlet::world::pair_capacities(&gpu, u64::MAX);
    outln!("contact pools at most:      {most_pairs} pairs, {most_manifolds} manifolds")?;
    outln!("largest scene:              {} bodies", verlet::world::max_bodies(&gpu))?;
    if i.name.contains("llvmpipe") {
        // lavapipe hands every dispatch to its worker threads, and that
        // hand-off is most of a small scene's step (docs/lavapipe.md)
        let threads =
            std::env::var("LP_NUM_THREADS").map_or("LP_NUM_THREADS unset: its default".into(), |t| format!("LP_NUM_THREADS={t}"));
        outln!(
            "software adapter:           lavapipe's worker threads take each dispatch ({threads}); \
             LP_NUM_THREADS=0 runs them on the submitting thread, faster for scenes of up to a few hundred bodies"
        )?;
    }
    Ok(())
}
