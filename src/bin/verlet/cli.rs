//! The command line's schema (clap): the commands, their flags and the
//! checks of their values, and the one line a refused command line gets.

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use verlet::scenes;

#[derive(Parser)]
#[command(name = "verlet", version, about = "GPU rigid-body simulator (quaternion position-Verlet, Kenwright)")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
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
pub struct BenchArgs {
    /// Cases, comma-separated: cubes-1k, cubes-10k, cubes-100k, cubes-1m
    /// (the adapter's maximum when 1M does not fit), pile-1k, pile-10k,
    /// pile-100k, pile-1m (cubes heaped four deep), capsules-1k, capsules-10k
    /// (capsules heaped likewise), hulls-1k, hulls-10k (convex rocks dropped
    /// likewise), pyramid, chain, large_pyramid, many_pyramids, joint_grid,
    /// washer (Box3D's benchmarks at its sizes), or SCENE:COUNT. Default:
    /// all (with --quick: cubes-1k, cubes-10k, pyramid, chain).
    #[arg(long, value_delimiter = ',')]
    pub cases: Vec<String>,
    /// Steps per repetition (default 300; 60 with --quick).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    pub steps: Option<u64>,
    /// Body-steps per repetition: a case takes min(steps, max(20, this / bodies))
    /// steps, so large cases finish (default 3000000: 300 steps of 10k cubes; 600000 with --quick).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    pub body_steps: Option<u64>,
    /// Repetitions per case, each from the initial state; the median is reported (default 3; 2 with --quick).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    pub reps: Option<usize>,
    /// A short run: fewer cases, steps and repetitions.
    #[arg(long)]
    pub quick: bool,
    /// Steps timed stage by stage after the repetitions (default 10; 3 with --quick; 0: none).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    pub profile_steps: Option<u64>,
    /// Write the full report as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write one CSV row per case here.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Draw the report here, as SVG: ms per step against bodies (ours and
    /// the peer's, log axes) and each case's step split into its parts.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Do not run the rapier3d peer even when it is built in.
    #[arg(long)]
    pub no_peer: bool,
    /// Run the peer only for cases of at most this many bodies.
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    pub peer_max_bodies: Option<usize>,
    /// Let bodies sleep, ours and rapier's (off by default in the bench).
    #[arg(long)]
    pub rapier_sleeping: bool,
    /// Relaxation sweeps a step for every case of ours, as a scene's
    /// `settings.iterations` without `substeps` (default: each case's own;
    /// the contract suggests 8).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u32)]
    pub iterations: Option<u32>,
    /// rapier's num_solver_iterations (default: rapier's own, 4).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    pub rapier_iterations: Option<usize>,
    /// Threads of the rapier3d peer's rayon pool (default: LP_NUM_THREADS
    /// when set above 0, else the machine's cores); it also runs on one thread, reported beside.
    #[arg(long, allow_negative_numbers = true, value_parser = whole_usize)]
    pub peer_threads: Option<usize>,
    /// Most steps the largest pile case of at most 10k bodies takes to come to
    /// rest, with sleeping on, for the memory of a settled pile (default 1800
    /// with --settle; given alone, it asks for --settle; 0: not settled).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_u64)]
    pub settle_steps: Option<u64>,
    /// Also bring the largest pile case of at most 10k bodies to rest and
    /// report the memory a settled pile holds.
    #[arg(long)]
    pub settle: bool,
    /// Also time whole processes starting with Mesa's shader cache disabled
    /// (`verlet run --builtin cubes --count 10 --steps 1`; 3 runs, 1 with --quick).
    #[arg(long)]
    pub cold_start: bool,
    /// Also time an off-screen render of the 1000-cube scene at 640 x 480.
    #[arg(long)]
    pub render: bool,
    /// Also time ten cubes' steps over the dispatches of a step: what a
    /// dispatch costs before any work.
    #[arg(long)]
    pub dispatch_cost: bool,
    /// All of --settle, --cold-start, --render and --dispatch-cost.
    #[arg(long)]
    pub all: bool,
}

#[derive(clap::Args)]
pub struct RunArgs {
    /// The scene file (JSON, INTERFACE.md section 1). Without it, --builtin.
    pub scene: Option<PathBuf>,
    /// A built-in scene to run instead of a file (listed below).
    #[arg(long, conflicts_with = "scene")]
    pub builtin: Option<String>,
    /// --count of the built-in scene.
    #[arg(long, requires = "builtin", allow_negative_numbers = true, value_parser = whole_usize)]
    pub count: Option<usize>,
    /// --seed of the built-in scene (1 if not given).
    #[arg(long, requires = "builtin", allow_negative_numbers = true, value_parser = whole_u64)]
    pub seed: Option<u64>,
    /// Steps to take (required).
    #[arg(long = "steps", value_name = "STEPS", allow_negative_numbers = true, value_parser = whole_u64)]
    pub steps_given: Option<u64>,
    /// `--steps` once `run` has checked it was given.
    #[arg(skip)]
    pub steps: u64,
    /// A scripted input track (JSON: impulses, explosions, poses,
    /// velocities, fixed switches, wind at given times) applied between
    /// steps. `--builtin blast` plays its own track unless this is given.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Step length in seconds; overrides settings.dt.
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f32>,
    /// Write the state after the last step here (JSON).
    #[arg(long)]
    pub state_out: Option<PathBuf>,
    /// Write a CSV trace here: every body at steps 0, K, 2K, ... and the last.
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// K for --trace, --frames, --gif and --contact-sheet.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = whole_u64)]
    pub every: u64,
    /// Time every stage of every step (GPU timestamps where the adapter has
    /// them) and print the cost per stage; steps are then submitted one by one.
    #[arg(long)]
    pub profile: bool,
    /// Write PNG frames into this directory (created if missing):
    /// frame_000000.png, frame_000001.png, ... at steps 0, K, 2K, ... and the last.
    #[arg(long)]
    pub frames: Option<PathBuf>,
    /// Write an animated GIF of the frames here (--frames not needed), played
    /// in real time. To bound memory, frames are scaled to fit 480x480 and at
    /// most 151 are kept, evenly spread over the run, always with the last.
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Write one PNG tiling the frames here (--frames not needed). To bound
    /// memory, tiles are scaled to fit 320x320 and at most 25 are kept,
    /// evenly spread over the run, always with the last.
    #[arg(long)]
    pub contact_sheet: Option<PathBuf>,
    /// Frame width in pixels.
    #[arg(long, default_value_t = 640, allow_negative_numbers = true, value_parser = whole_u32)]
    pub width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 480, allow_negative_numbers = true, value_parser = whole_u32)]
    pub height: u32,
}

/// The command line as `Cli::try_parse` reads it, with the built-in scenes
/// listed under the help of `verlet`, `verlet scene` and `verlet run`.
pub fn parse() -> Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let list = scene_list();
    let mut command = Cli::command()
        .after_help(list.clone())
        .mut_subcommand("scene", |c| c.after_help(list.clone()))
        .mut_subcommand("run", |c| c.after_help(list.clone()));
    let mut matches = command.try_get_matches_from_mut(std::env::args_os())?;
    Cli::from_arg_matches_mut(&mut matches).map_err(|e| e.format(&mut command))
}

/// The built-in scenes, a line each, from `scenes::SCENES` (so a scene added
/// there is listed without touching the help).
fn scene_list() -> String {
    let width = scenes::SCENES.iter().map(|s| s.name.len()).max().unwrap_or(0);
    let mut list = String::from("Built-in scenes (`verlet scene NAME`, `verlet run --builtin NAME`):");
    for s in scenes::SCENES {
        list.push_str(&format!("\n  {:<width$}  {}", s.name, s.help_with("--count", "--seed")));
    }
    list
}

/// One line for a command-line error: clap's first line, or for a value
/// its parser refused, "--flag: what it takes, got VALUE".
pub fn clap_line(e: &clap::Error) -> String {
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
