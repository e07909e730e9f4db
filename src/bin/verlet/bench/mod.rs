//! `verlet bench`: the throughput benchmark's harness, in the binary so
//! that the library holds no peer engine; the workloads (the named cases,
//! the copy kernel) are the library's `verlet::bench`.
//!
//! Named cases (built-in scenes at fixed sizes, shared with `benches/step.rs`)
//! are each run as:
//!
//! 1. **start-up**: the first `World::with_gpu` of the case (pipelines
//!    compiled — slow on lavapipe, which JIT-compiles every kernel with LLVM —
//!    and buffers uploaded) and its first step, timed apart from everything
//!    else and then thrown away;
//! 2. **repetitions**: `reps` fresh worlds of the same scene, each taking one
//!    untimed step (lavapipe loads a world's pipelines at first dispatch) and
//!    then timed over the same `steps` steps (wall clock from the first
//!    submission to the GPU going idle); the median is reported;
//! 3. **per stage**: `World::profile` over a few more steps of the last
//!    repetition's world (GPU timestamp queries where the adapter has them,
//!    else the wall clock around each pass), a blocking readback of the whole
//!    state, and a memory-bound copy of the state buffer (an inline WGSL
//!    kernel reading and writing 64 bytes per body, timed like the passes)
//!    to set the integration pass beside;
//! 4. **peer** (feature `rapier`): the identical scene stepped the same
//!    number of steps by rapier3d on the CPU, timed the same way, one of
//!    its repetitions after each of ours (a machine whose speed drifts
//!    during a case weighs on both engines alike): rapier's parallel
//!    pipeline in a rayon pool of `--peer-threads` threads (default: as
//!    many as lavapipe runs, `LP_NUM_THREADS` or the machine's cores) and
//!    in a pool of one thread, the two taken in turns.
//!
//! Only when asked (`--settle`, `--cold-start`, `--render`,
//! `--dispatch-cost`, or `--all`): a pile brought to rest for its memory, a
//! whole process started with no shader cache, a rendered frame, and what
//! a dispatch costs before any work. A short run stays short.
//!
//! Here: the options and the run over the cases; `case` times one case,
//! `peer` runs rapier3d beside it, `extras` takes the measurements made only
//! when asked, `results` holds the figures, `report` prints them as a table
//! and CSV, and `plot` draws them.

macro_rules! progress {
    ($($t:tt)*) => {{ eprintln!($($t)*); }};
}

mod case;
mod extras;
mod peer;
mod plot;
mod report;
mod results;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use verlet::bench::{Case, CASES, QUICK_CASES};
use verlet::{scenes, world, Error};

use crate::cli::BenchArgs;
use crate::lavapipe::{self, Dispatch};
use crate::paths;
use case::run_case;
use extras::{cold_start, dispatch_cost, render_cubes, settle};
use peer::peer_description;
use report::csv;
use results::{scaling, Report};

/// Steps per repetition unless `--steps` says: 5 s of simulated time at
/// 60 Hz, long enough for a pile of 10 000 cubes to land.
pub const DEFAULT_STEPS: u64 = 300;
pub const QUICK_STEPS: u64 = 60;
/// Body-steps per repetition unless `--body-steps` says: a case takes
/// `min(steps, max(MIN_STEPS, body_steps / bodies))` steps, so the large
/// cases finish (300 steps of 10 000 cubes; 30 of 100 000).
pub const DEFAULT_BODY_STEPS: u64 = 3_000_000;
pub const QUICK_BODY_STEPS: u64 = 600_000;
/// The fewest steps a repetition takes, whatever the budget.
pub const MIN_STEPS: u64 = 20;
pub const DEFAULT_REPS: usize = 3;
pub const QUICK_REPS: usize = 2;
/// Steps timed stage by stage after the repetitions.
pub const PROFILE_STEPS: u64 = 10;
/// Most steps the settled pile takes to come to rest (`settle`): 30 s at
/// 60 Hz; pile-10k sleeps in about 900.
pub const SETTLE_STEPS: u64 = 1800;
/// The largest pile `settle` brings to rest.
pub const SETTLE_MAX_BODIES: usize = 10_000;

/// What `verlet bench` was asked to do.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Case names or `SCENE:COUNT`; empty: all of `CASES` (`QUICK_CASES` with `quick`).
    pub cases: Vec<String>,
    pub steps: Option<u64>,
    /// Body-steps per repetition (caps the steps of large cases).
    pub body_steps: Option<u64>,
    pub reps: Option<usize>,
    pub quick: bool,
    pub profile_steps: Option<u64>,
    pub json: Option<PathBuf>,
    pub csv: Option<PathBuf>,
    /// Skip the rapier3d peer even when it is built in (without the
    /// `rapier` feature there is none, and the peer's options go unread).
    #[cfg_attr(not(feature = "rapier"), allow(dead_code))]
    pub no_peer: bool,
    /// The peer only for cases of at most this many bodies.
    #[cfg_attr(not(feature = "rapier"), allow(dead_code))]
    pub peer_max_bodies: Option<usize>,
    /// Let bodies sleep, ours and rapier's (off by default in the bench, so
    /// that every body is simulated every step in both).
    pub rapier_sleeping: bool,
    /// Our relaxation sweeps a step for every case, its substeps as a scene
    /// that gives `iterations` alone gets; `None`: each case's own.
    pub iterations: Option<u32>,
    /// rapier's `num_solver_iterations`; `None`: rapier's default (4).
    #[cfg_attr(not(feature = "rapier"), allow(dead_code))]
    pub rapier_iterations: Option<usize>,
    /// Threads of the peer's parallel run; `None`: lavapipe's (`peer_threads`).
    pub peer_threads: Option<usize>,
    /// Most steps the settled pile takes (`SETTLE_STEPS` unless given; 0: not settled).
    pub settle_steps: Option<u64>,
    /// Measure what a short run leaves out: a settled pile's memory, cold
    /// starts, a rendered frame, the cost of a dispatch.
    pub extras: Extras,
    /// The command line, recorded in the outputs.
    pub command: String,
}

/// The measurements a run takes only when asked, each slow or apart from
/// the cases' own figures.
#[derive(Clone, Copy, Debug, Default)]
pub struct Extras {
    /// Bring the largest pile case of at most `SETTLE_MAX_BODIES` bodies to
    /// rest with sleeping on, for the memory a settled pile holds.
    pub settle: bool,
    /// Start this binary as a whole process with Mesa's shader cache off.
    pub cold_start: bool,
    /// Render the 1000-cube scene at 640 x 480.
    pub render: bool,
    /// Time ten cubes' steps over the dispatches of a step.
    pub dispatch_cost: bool,
}

/// `verlet bench`: checks `--plot` before the long run, runs the cases
/// ([`run`]), draws the chart, and prints the report.
pub fn command(a: BenchArgs) -> Result<(), Error> {
    if let Some(path) = &a.plot {
        if path.extension().is_none_or(|e| !e.eq_ignore_ascii_case("svg")) {
            return Err(Error::Input(format!("--plot: {} does not end in .svg: the chart is written as SVG", path.display())));
        }
        // before the long run, as `run` does for --json and --csv
        paths::check_output("--plot", path)?;
        let outputs: Vec<(&str, &Path)> = [("--json", &a.json), ("--csv", &a.csv), ("--plot", &a.plot)]
            .into_iter()
            .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
            .collect();
        paths::check_distinct(&[], &outputs)?;
    }
    let report = run(&Options {
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
        extras: Extras {
            settle: a.settle || a.all,
            cold_start: a.cold_start || a.all,
            render: a.render || a.all,
            dispatch_cost: a.dispatch_cost || a.all,
        },
        iterations: a.iterations,
        rapier_iterations: a.rapier_iterations,
        peer_threads: a.peer_threads,
        command: std::env::args_os().map(|a| a.to_string_lossy().into_owned()).collect::<Vec<_>>().join(" "),
    })?;
    if let Some(path) = &a.plot {
        let title = format!("{} on {} ({} cores)", report.adapter, report.cpu, report.cores);
        let peer = report.peer.split_whitespace().next().unwrap_or("peer").to_string();
        let chart = plot::svg(&title, &peer, &plot::rows(&report)).map_err(|why| Error::Input(format!("--plot: {why}")))?;
        paths::write_file(path, &chart)?;
        eprintln!("wrote {}", path.display());
    }
    out!("{}", report::table(&report))
}

/// Runs the benchmark; writes `--json` and `--csv`. The caller prints the
/// report (`table`) once every file is written, so a closed stdout costs
/// no file.
pub fn run(opts: &Options) -> Result<Report, Error> {
    let steps = opts.steps.unwrap_or(if opts.quick { QUICK_STEPS } else { DEFAULT_STEPS });
    let reps = opts.reps.unwrap_or(if opts.quick { QUICK_REPS } else { DEFAULT_REPS });
    let profile_steps = opts.profile_steps.unwrap_or(if opts.quick { 3 } else { PROFILE_STEPS });
    let body_steps = opts.body_steps.unwrap_or(if opts.quick { QUICK_BODY_STEPS } else { DEFAULT_BODY_STEPS });
    if steps == 0 {
        return Err(Error::Input("--steps: must be at least 1".into()));
    }
    if reps == 0 {
        return Err(Error::Input("--reps: must be at least 1".into()));
    }
    if opts.peer_threads == Some(0) {
        return Err(Error::Input("--peer-threads: must be at least 1".into()));
    }
    if let Some(k) = opts.iterations.filter(|k| !(1..=verlet::scene::MAX_ITERATIONS).contains(k)) {
        return Err(Error::Input(format!("--iterations: must be between 1 and {}, got {k}", verlet::scene::MAX_ITERATIONS)));
    }
    let cases = cases(opts)?;
    // fail on unwritable or clashing outputs before the long run, not after it
    let outputs: Vec<(&str, &Path)> = [("--json", &opts.json), ("--csv", &opts.csv)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    for (flag, path) in &outputs {
        paths::check_output(flag, path)?;
    }
    paths::check_distinct(&[], &outputs)?;

    let started = Instant::now();
    // Both adapters before any thread starts (the peer's pools): opening one
    // may set the environment. On lavapipe the larger cases and the extras
    // run on its workers, the small cases on the submitting thread.
    let (gpu, workers) = lavapipe::open(false)?;
    let gpu = Arc::new(gpu);
    let gpu_open_s = started.elapsed().as_secs_f64();
    let small = |case: &Case| scenes::body_count(&case.scene, case.count).is_some_and(|n| lavapipe::suits_inline(n, false));
    let inline = match cases.iter().any(small) || opts.extras.dispatch_cost {
        true => lavapipe::open_inline()?.map(Arc::new),
        false => None,
    };
    let max = world::max_bodies(&gpu);
    let timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    progress!("bench: {} (up to {steps} steps, at most {body_steps} body-steps, x {reps} reps per case)", gpu.describe());
    let mesa_cache = std::env::var("MESA_SHADER_CACHE_DISABLE").is_ok_and(|v| v == "true" || v == "1");

    let settings = verlet::Settings::default();
    let (peer_name, iterations) = peer_description(opts, &settings);
    let mut results = Vec::new();
    for case in &cases {
        let before = load_avg();
        let (case_gpu, dispatch) = match &inline {
            Some(g) if small(case) => (g, Dispatch::Inline),
            _ => (&gpu, workers),
        };
        let mut r = run_case(case_gpu, case, (steps, body_steps), reps, profile_steps, max, opts)?;
        r.lavapipe = (dispatch != Dispatch::AsSet).then_some(dispatch);
        r.load_avg = before.zip(load_avg()).map(|(a, b)| [a, b]);
        results.push(r);
    }
    // Rendering comes last: on lavapipe (Mesa 22.3) compute-pass timestamps
    // taken after a render pass on the same device come out near zero, so a
    // render before a profile would corrupt the per-stage table.
    let extras = opts.extras;
    let dispatch = if extras.dispatch_cost { Some(dispatch_cost(&gpu, inline.as_ref())?) } else { None };
    let render = if extras.render { Some(render_cubes(&gpu)?) } else { None };
    let cold_start_s = if extras.cold_start { cold_start(if opts.quick { 1 } else { 3 }) } else { Vec::new() };
    // `--settle-steps N` alone asks for it too
    let settle_steps = match opts.settle_steps {
        Some(n) => n,
        None if extras.settle => SETTLE_STEPS,
        None => 0,
    };
    let to_settle = cases
        .iter()
        .zip(&results)
        .filter(|(_, r)| r.scene == "pile" && r.skipped.is_none() && r.bodies <= SETTLE_MAX_BODIES)
        .max_by_key(|(_, r)| r.bodies);
    let settled = match to_settle {
        Some((case, r)) if settle_steps > 0 => Some(settle(&gpu, case, &r.case, settle_steps)?),
        _ => None,
    };
    if let (Some((setup, ms)), Some(r)) = (render, results.iter_mut().find(|r| r.case == "cubes-1k")) {
        r.render_setup_s = Some(setup);
        r.render_ms = Some(ms);
    }
    let report = Report {
        command: opts.command.clone(),
        cpu: cpu_model(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        adapter: gpu.describe(),
        gpu_timestamps: timestamps,
        max_bodies: max,
        max_storage_buffer_binding_size: gpu.limits.max_storage_buffer_binding_size,
        bytes_per_body: world::bytes_per_body(),
        iterations,
        peer: peer_name,
        gpu_open_s,
        render_setup_s: render.map(|r| r.0),
        render_ms: render.map(|r| r.1),
        sleeping: opts.rapier_sleeping,
        shader_cache: if mesa_cache { "disabled (MESA_SHADER_CACHE_DISABLE)" } else { "Mesa's default (on-disk cache on)" }.into(),
        scaling: scaling(&results, "cubes"),
        pile_scaling: scaling(&results, "pile"),
        cold_start_s,
        settled,
        dispatch,
        cases: results,
    };
    if let Some(path) = &opts.json {
        let text = serde_json::to_string_pretty(&report).expect("the report serialises");
        paths::write_file(path, &text)?;
    }
    if let Some(path) = &opts.csv {
        paths::write_file(path, &csv(&report))?;
    }
    Ok(report)
}

/// The cases `--cases` names (comma-separated, in one flag or several),
/// or by default all of `CASES` (`QUICK_CASES` with `--quick`).
fn cases(opts: &Options) -> Result<Vec<Case>, Error> {
    let specs: Vec<String> = if opts.cases.is_empty() {
        if opts.quick {
            QUICK_CASES.iter().map(|s| s.to_string()).collect()
        } else {
            CASES.iter().map(|c| c.0.to_string()).collect()
        }
    } else {
        opts.cases.iter().flat_map(|s| s.split(',')).map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect()
    };
    let blanks = opts.cases.iter().flat_map(|s| s.split(',')).filter(|s| s.trim().is_empty()).count();
    if !opts.cases.is_empty() && specs.is_empty() {
        return Err(Error::Input(format!("--cases: names no case (got {:?}); give names, comma-separated", opts.cases.join(","))));
    }
    if blanks > 0 && !opts.cases.is_empty() {
        progress!("warning: --cases: {blanks} empty name(s) between commas skipped");
    }
    specs.iter().map(|s| Case::parse(s).map_err(|e| e.for_flag("spec", "--cases"))).collect()
}

fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

/// The processor's model name (Linux), else "unknown".
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split_once(':')).map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// The 1-minute load average (Linux).
pub fn load_avg() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

fn mean_height(bodies: impl Iterator<Item = f32>) -> f64 {
    let (sum, count) = bodies.fold((0.0f64, 0usize), |(s, c), y| (s + y as f64, c + 1));
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
