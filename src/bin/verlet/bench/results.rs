//! What `verlet bench` measured: the report, a row per case, and the
//! fit of time per step against bodies.

use serde::Serialize;
use verlet::step::Part;
use verlet::world::StageTimes;

use crate::lavapipe::Dispatch;

/// Per-stage cost of a step (ms per step, summed over substeps and iterations).
#[derive(Clone, Debug, Serialize)]
pub struct Stages {
    /// "GPU timestamps" or "wall clock per pass".
    pub source: String,
    pub steps: u64,
    /// The seven grid passes together.
    pub broadphase: f64,
    /// The pair list (`pairs_*`), the narrowphase and its dispatch.
    pub narrowphase: f64,
    pub integrate: f64,
    /// Both halves of every sweep (`solve_contacts`, `solve`).
    pub solve: f64,
    /// Both halves (`restitution_contacts`, `restitution`).
    pub restitution: f64,
    /// Sum of the above.
    pub total: f64,
    /// Every pass by its entry point.
    pub passes: Vec<(String, f64)>,
}

impl Stages {
    pub fn from_times(t: &StageTimes, steps: u64) -> Stages {
        let part = |p: Part| t.ms_per_step.iter().filter(|(s, _)| s.part() == p).map(|x| x.1).sum::<f64>();
        let (broadphase, narrowphase, integrate, solve, restitution) =
            (part(Part::Broadphase), part(Part::Narrowphase), part(Part::Integrate), part(Part::Solve), part(Part::Restitution));
        Stages {
            source: if t.gpu_timestamps { "GPU timestamps" } else { "wall clock per pass" }.into(),
            steps,
            broadphase,
            narrowphase,
            integrate,
            solve,
            restitution,
            total: broadphase + narrowphase + integrate + solve + restitution,
            passes: t.ms_per_step.iter().map(|(s, ms)| (s.name().to_string(), *ms)).collect(),
        }
    }
}

/// The CPU peer's figures for one case: those of its run on `thread_count`
/// threads, and beside them those of its run on one.
#[derive(Clone, Debug, Serialize)]
pub struct PeerResult {
    pub engine: String,
    /// `thread_count` as text.
    pub threads: String,
    /// Threads of the rayon pool the figures below were taken in.
    pub thread_count: usize,
    pub sleeping: bool,
    pub num_solver_iterations: usize,
    pub setup_s: f64,
    pub ms_per_step: Vec<f64>,
    pub median_ms_per_step: f64,
    pub body_steps_per_s: f64,
    /// Peer ms/step over ours: above 1, verlet is faster.
    pub speedup: f64,
    /// Mean height of the movable bodies after the last repetition (m).
    pub mean_height: f64,
    /// The same scene in a pool of one thread: each repetition (ms/step),
    /// their median, body-steps/s and the median over ours (above 1, we
    /// are faster).
    pub one_thread_ms_per_step: Vec<f64>,
    pub one_thread_median_ms_per_step: f64,
    pub one_thread_body_steps_per_s: f64,
    pub one_thread_speedup: f64,
}

/// One case's figures.
#[derive(Clone, Debug, Serialize)]
pub struct CaseResult {
    pub case: String,
    pub scene: String,
    pub bodies: usize,
    pub joints: usize,
    /// The scene's relaxation sweeps per step and substeps per step.
    pub iterations: u32,
    pub substeps: u32,
    /// Why the case did not run (it does not fit the adapter), if it did not.
    pub skipped: Option<String>,
    /// A note on the case (run at a smaller size than named, and why).
    pub note: Option<String>,
    pub steps: u64,
    pub reps: usize,
    /// The case's first `World::with_gpu` and first step, waited for (s):
    /// upload, and on lavapipe the JIT compilation of every pipeline, which
    /// happens at first use (fast when Mesa's on-disk shader cache has them).
    pub startup_s: f64,
    /// Of which the first step (ms).
    pub first_step_ms: f64,
    /// Median `World::with_gpu` and untimed first step of the repetitions (s).
    pub setup_s: f64,
    pub ms_per_step: Vec<f64>,
    pub median_ms_per_step: f64,
    pub body_steps_per_s: f64,
    /// `world::bytes_per_body() * bodies`.
    pub gpu_bytes_estimate: u64,
    /// What the world's buffers hold as `World::with_gpu` made them.
    pub gpu_bytes_at_start: u64,
    /// What the world's buffers hold after the last repetition
    /// (`World::gpu_bytes`: the pair list and the manifold pool as they grew).
    pub gpu_bytes: u64,
    pub gpu_bytes_per_body: f64,
    pub stages: Option<Stages>,
    /// `World::read_state` of every body (ms, median of 3).
    pub readback_ms: f64,
    /// `Renderer::new` for the 1000-cube scene at 640 x 480 (s), on the cubes-1k row.
    pub render_setup_s: Option<f64>,
    /// `Renderer::render` at 640 x 480 including its image readback (ms, median of 3).
    pub render_ms: Option<f64>,
    /// One integrate pass (ms): the profile's integrate time over substeps.
    pub integrate_ms_per_pass: Option<f64>,
    /// One pass of the copy kernel over the same number of bodies (ms).
    pub copy_ms_per_pass: Option<f64>,
    /// Most contact manifolds (pairs with contact points) in any step, and
    /// whether the pair list or the manifold pool overflowed.
    pub max_contacts: u32,
    pub contacts_overflowed: bool,
    /// Mean height of the movable bodies after the last repetition (m).
    pub mean_height: f64,
    /// The machine's 1-minute load average when the case started and ended
    /// (Linux): above the core count, other work shared the CPU (and so
    /// lavapipe) and the times are inflated.
    pub load_avg: Option<[f64; 2]>,
    /// On lavapipe, where it ran each dispatch: on the submitting thread
    /// for a case of at most `lavapipe::INLINE_MAX_BODIES` bodies, else on
    /// its worker threads (`LP_NUM_THREADS` unset; `None` when the user
    /// set it or the adapter is not lavapipe).
    pub lavapipe: Option<Dispatch>,
    pub peer: Option<PeerResult>,
}

/// Exponent of time per step against bodies.
#[derive(Clone, Debug, Serialize)]
pub struct Scaling {
    /// The cubes cases fitted: (bodies, ms/step).
    pub points: Vec<(usize, f64)>,
    /// Least-squares slope of ln(ms/step) on ln(bodies).
    pub exponent: f64,
    /// Largest over smallest cost per body-step among the points.
    pub spread: f64,
}

/// Everything `verlet bench` measured.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub command: String,
    pub cpu: String,
    pub cores: usize,
    pub adapter: String,
    pub gpu_timestamps: bool,
    pub max_bodies: u64,
    pub max_storage_buffer_binding_size: u64,
    pub bytes_per_body: u64,
    /// How our iteration counts compare with the peer's, in words.
    pub iterations: String,
    pub peer: String,
    pub gpu_open_s: f64,
    /// `Renderer::new` for the 1000-cube scene at 640 x 480 (s).
    pub render_setup_s: Option<f64>,
    /// `Renderer::render` of it, landed (60 steps), image read back included (ms, median of 3).
    pub render_ms: Option<f64>,
    /// Whether start-up times had Mesa's shader cache to draw on.
    pub shader_cache: String,
    /// Whether the cases ran with sleeping on (`--rapier-sleeping`).
    pub sleeping: bool,
    pub cases: Vec<CaseResult>,
    /// Over the cubes cases.
    pub scaling: Option<Scaling>,
    /// Over the pile cases.
    pub pile_scaling: Option<Scaling>,
    /// Whole `verlet run --builtin cubes --count 10 --steps 1` processes
    /// with Mesa's shader cache disabled (s; `cold_start`), when measured.
    pub cold_start_s: Vec<f64>,
    /// The largest pile case of at most `SETTLE_MAX_BODIES` bodies, brought
    /// to rest with sleeping on (the memory a settled pile holds), when measured.
    pub settled: Option<Settled>,
    /// What a dispatch costs before any work (`dispatch_cost`), when measured.
    pub dispatch: Option<DispatchCost>,
}

/// The step's dispatches at the default settings, and what each costs
/// before any work: ten cubes falling side by side (sleeping off), stepped
/// 120 times after a first untimed step, the wall clock a step over the
/// dispatches of a step.
#[derive(Clone, Debug, Serialize)]
pub struct DispatchCost {
    pub dispatches_per_step: usize,
    pub ten_cubes_ms_per_step: f64,
    pub us_per_dispatch: f64,
    /// The same on lavapipe's submitting thread (`LP_NUM_THREADS=0`), where
    /// the bench opened that adapter too (`LP_NUM_THREADS` unset).
    pub inline: Option<InlineDispatchCost>,
}

/// `DispatchCost`'s step and dispatch on lavapipe's submitting thread.
#[derive(Clone, Debug, Serialize)]
pub struct InlineDispatchCost {
    pub ten_cubes_ms_per_step: f64,
    pub us_per_dispatch: f64,
}

/// A pile stepped until it rests, with sleeping on (the default setting,
/// whatever the bench's `--rapier-sleeping`), in chunks of 60 steps: until
/// 99% of its bodies sleep and the contact pools have had
/// `SHRINK_AFTER_STEPS` more to follow the need, or `settle_steps`.
#[derive(Clone, Debug, Serialize)]
pub struct Settled {
    pub case: String,
    pub bodies: usize,
    pub steps: u64,
    /// Bodies asleep after the last step.
    pub asleep: usize,
    /// Candidate pairs and manifolds in the last step, and the pools' sizes.
    pub pairs: u32,
    pub manifolds: u32,
    pub pair_capacity: u32,
    pub manifold_capacity: u32,
    /// `World::gpu_bytes` after the last step.
    pub gpu_bytes: u64,
    pub gpu_bytes_per_body: f64,
    /// Wall clock per step over the last chunk (ms).
    pub last_ms_per_step: f64,
}

/// Fits the exponent over the cases of `scene` with 10 000 bodies and more.
pub fn scaling(results: &[CaseResult], scene: &str) -> Option<Scaling> {
    let mut points: Vec<(usize, f64)> = results
        .iter()
        .filter(|r| r.scene == scene && r.skipped.is_none() && r.bodies >= 10_000 && r.median_ms_per_step.is_finite())
        .map(|r| (r.bodies, r.median_ms_per_step))
        .collect();
    points.sort_by_key(|p| p.0);
    points.dedup_by_key(|p| p.0);
    if points.len() < 2 {
        return None;
    }
    let xs: Vec<f64> = points.iter().map(|p| (p.0 as f64).ln()).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1.ln()).collect();
    let k = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / k, ys.iter().sum::<f64>() / k);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    let per: Vec<f64> = points.iter().map(|p| p.1 / p.0 as f64).collect();
    let spread = per.iter().cloned().fold(f64::MIN, f64::max) / per.iter().cloned().fold(f64::MAX, f64::min);
    Some(Scaling { points, exponent: sxy / sxx, spread })
}
