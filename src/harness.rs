//! `verlet bench`: the throughput benchmark's harness, in the binary so
//! that the library holds no peer engine; the workloads (the
//! named cases, the copy kernel) are the library's `verlet::bench`.
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

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use verlet::bench::{case, Case, CopyKernel, CASES, QUICK_CASES, SEED};
use verlet::gpu::Gpu;
use verlet::render::Renderer;
use verlet::scene::Scene;
use verlet::step::Part;
use verlet::world::{self, StageTimes, World};
use verlet::{scenes, Error};

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
    fn from_times(t: &StageTimes, steps: u64) -> Stages {
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

// ---------------------------------------------------------------------------

/// The identical scene in rapier3d: same bodies (shapes, sizes, masses,
/// poses, velocities), friction combined as our geometric mean and
/// restitution as our max, the ground as a fixed half-space, the same dt,
/// gravity and damping (our β per step as rapier's coefficient
/// `-ln(1 - β) / dt`), ball joints as spherical impulse joints whose bodies
/// do not collide (as ours do not), world-pinned ends on a fixed body at the
/// origin. Bodies never sleep unless asked; CCD is off as rapier's default.
#[cfg(feature = "rapier")]
pub mod peer {
    use std::sync::Arc;

    use rapier3d::na::Unit;
    use rapier3d::prelude::*;
    use rapier3d::rayon::{ThreadPool, ThreadPoolBuilder};

    use verlet::scene::{Scene, Shape};

    /// The peer's name as reported.
    pub const ENGINE: &str = "rapier3d 0.36";

    /// A rayon pool of `threads` threads for `RapierWorld::new`.
    pub fn pool(threads: usize) -> Result<Arc<ThreadPool>, String> {
        ThreadPoolBuilder::new().num_threads(threads).build().map(Arc::new).map_err(|e| e.to_string())
    }

    pub struct RapierWorld {
        pub world: PhysicsWorld,
    }

    impl RapierWorld {
        /// The scene, stepped in `pool` (rapier's parallel pipeline runs
        /// its whole step there).
        pub fn new(scene: &Scene, sleeping: bool, iterations: Option<usize>, pool: Arc<ThreadPool>) -> RapierWorld {
            let s = &scene.settings;
            let mut w = PhysicsWorld { gravity: Vector::new(s.gravity[0], s.gravity[1], s.gravity[2]), ..Default::default() };
            w.set_thread_pool(Some(pool));
            w.integration_parameters.dt = s.dt;
            if let Some(k) = iterations {
                w.integration_parameters.num_solver_iterations = k.max(1);
            }
            let damping = |beta: f32| -((1.0 - beta as f64).ln() / s.dt as f64) as f32;
            let material = |c: ColliderBuilder, friction: f32, restitution: f32| {
                c.friction(friction)
                    .friction_combine_rule(CoefficientCombineRule::GeometricMean)
                    .restitution(restitution)
                    .restitution_combine_rule(CoefficientCombineRule::Max)
            };
            if let Some(g) = &scene.ground {
                let ground =
                    ColliderBuilder::halfspace(Unit::new_unchecked(Vector::Y)).translation(Vector::new(0.0, g.height, 0.0));
                w.insert_collider(material(ground, s.friction, s.restitution), None);
            }
            let mut handles = Vec::with_capacity(scene.bodies.len());
            for b in &scene.bodies {
                let o = b.orientation;
                let pose = Pose::from_parts(
                    Vector::new(b.position[0], b.position[1], b.position[2]),
                    Rotation::from_xyzw(o[0], o[1], o[2], o[3]).normalize(),
                );
                let body = if b.fixed { RigidBodyBuilder::fixed() } else { RigidBodyBuilder::dynamic() }
                    .pose(pose)
                    .linvel(Vector::new(b.linear_velocity[0], b.linear_velocity[1], b.linear_velocity[2]))
                    .angvel(Vector::new(b.angular_velocity[0], b.angular_velocity[1], b.angular_velocity[2]))
                    .linear_damping(damping(s.linear_damping))
                    .angular_damping(damping(s.angular_damping))
                    .can_sleep(sleeping);
                let shape = match b.shape {
                    Shape::Box { half_extents: h } => ColliderBuilder::cuboid(h[0], h[1], h[2]),
                    Shape::Sphere { radius } => ColliderBuilder::ball(radius),
                };
                let collider =
                    material(shape.mass(b.mass), b.friction.unwrap_or(s.friction), b.restitution.unwrap_or(s.restitution));
                handles.push(w.insert(body, collider).0);
            }
            let mut anchor_body = None;
            for j in &scene.joints {
                let mut side = |k: usize| -> RigidBodyHandle {
                    if j.bodies[k] >= 0 {
                        handles[j.bodies[k] as usize]
                    } else {
                        *anchor_body.get_or_insert_with(|| w.insert_body(RigidBodyBuilder::fixed()))
                    }
                };
                let (h1, h2) = (side(0), side(1));
                let a = |k: usize| Vector::new(j.anchors[k][0], j.anchors[k][1], j.anchors[k][2]);
                let joint = SphericalJointBuilder::new().local_anchor1(a(0)).local_anchor2(a(1)).contacts_enabled(false);
                w.impulse_joints.insert(h1, h2, joint, true);
            }
            RapierWorld { world: w }
        }

        pub fn step(&mut self, steps: u64) {
            for _ in 0..steps {
                self.world.step();
            }
        }

        pub fn num_solver_iterations(&self) -> usize {
            self.world.integration_parameters.num_solver_iterations
        }

        /// Mean height of the dynamic bodies (m).
        pub fn mean_height(&self) -> f64 {
            super::mean_height(self.world.bodies.iter().filter(|(_, b)| b.is_dynamic()).map(|(_, b)| b.translation().y))
        }
    }
}

// ---------------------------------------------------------------------------
// Running
// ---------------------------------------------------------------------------

macro_rules! progress {
    ($($t:tt)*) => {{ eprintln!($($t)*); }};
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
    let cases: Vec<Case> = specs.iter().map(|s| Case::parse(s)).collect::<Result<_, _>>()?;
    // fail on unwritable or clashing outputs before the long run, not after it
    let outputs: Vec<(&str, &std::path::Path)> = [("--json", &opts.json), ("--csv", &opts.csv)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    for (flag, path) in &outputs {
        verlet::output::check_output(flag, path)?;
    }
    verlet::output::check_distinct(&[], &outputs)?;

    let started = Instant::now();
    let gpu = Arc::new(Gpu::new()?);
    let gpu_open_s = started.elapsed().as_secs_f64();
    let max = world::max_bodies(&gpu);
    let timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    progress!("bench: {} (up to {steps} steps, at most {body_steps} body-steps, x {reps} reps per case)", gpu.describe());
    let mesa_cache = std::env::var("MESA_SHADER_CACHE_DISABLE").is_ok_and(|v| v == "true" || v == "1");

    let settings = verlet::Settings::default();
    let (peer_name, iterations) = peer_description(opts, &settings);
    let mut results = Vec::new();
    for case in &cases {
        let before = load_avg();
        let mut r = run_case(&gpu, case, (steps, body_steps), reps, profile_steps, max, opts)?;
        r.load_avg = before.zip(load_avg()).map(|(a, b)| [a, b]);
        results.push(r);
    }
    // Rendering comes last: on lavapipe (Mesa 22.3) compute-pass timestamps
    // taken after a render pass on the same device come out near zero, so a
    // render before a profile would corrupt the per-stage table.
    let extras = opts.extras;
    let dispatch = if extras.dispatch_cost { Some(dispatch_cost(&gpu)?) } else { None };
    let render = if extras.render { Some(render_cubes(&gpu)?) } else { None };
    let cold_start_s = if extras.cold_start { cold_start(if opts.quick { 1 } else { 3 }) } else { Vec::new() };
    // `--settle-steps N` alone asks for it too, as it always did
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
        verlet::output::write_file(path, &text)?;
    }
    if let Some(path) = &opts.csv {
        verlet::output::write_file(path, &csv(&report))?;
    }
    Ok(report)
}

/// Measures `DispatchCost`.
fn dispatch_cost(gpu: &Arc<Gpu>) -> Result<DispatchCost, Error> {
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
    let ms = t.elapsed().as_secs_f64() * 1e3 / steps as f64;
    let dispatches = world.step_plan().len();
    let out =
        DispatchCost { dispatches_per_step: dispatches, ten_cubes_ms_per_step: ms, us_per_dispatch: ms * 1e3 / dispatches as f64 };
    progress!("dispatches: {dispatches} a step; 10 cubes step in {ms:.2} ms: {:.0} us a dispatch", out.us_per_dispatch);
    Ok(out)
}

/// Renders the 1000-cube scene after 60 steps at 640 x 480: (set-up s, ms per frame).
fn render_cubes(gpu: &Arc<Gpu>) -> Result<(f64, f64), Error> {
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

fn peer_description(opts: &Options, settings: &verlet::Settings) -> (String, String) {
    let ours = format!(
        "ours: {} Jacobi sweeps per step in {} substeps by default (each case's own in its row), contacts found once per step",
        settings.sweeps_per_step(),
        settings.substeps
    );
    #[cfg(feature = "rapier")]
    {
        let k = opts.rapier_iterations.unwrap_or_else(|| rapier3d::prelude::IntegrationParameters::default().num_solver_iterations);
        let threads = peer_threads(opts);
        let name = format!(
            "{} (its parallel pipeline in a rayon pool of {threads} thread{}, and of 1), sleeping {}, CCD off, \
             num_solver_iterations = {k}{}",
            peer::ENGINE,
            if threads == 1 { "" } else { "s" },
            if opts.rapier_sleeping { "on" } else { "off" },
            if opts.rapier_iterations.is_some() { "" } else { " (its default)" },
        );
        let its = format!(
            "{ours}; rapier: num_solver_iterations = {k} (TGS-soft substeps, each 1 PGS velocity iteration + 1 stabilisation \
             iteration, Gauss-Seidel), contacts found once per step"
        );
        (if opts.no_peer { "none (--no-peer)".into() } else { name }, its)
    }
    #[cfg(not(feature = "rapier"))]
    {
        let _ = opts;
        ("none (built without --features rapier)".into(), ours)
    }
}

/// Threads of the peer's parallel run: `--peer-threads`, else as many as
/// lavapipe runs (`LP_NUM_THREADS` when it is a positive number; its
/// default is the machine's cores), so that both engines have the same CPU.
#[cfg_attr(not(feature = "rapier"), allow(dead_code))]
fn peer_threads(opts: &Options) -> usize {
    let lavapipe = std::env::var("LP_NUM_THREADS").ok().and_then(|t| t.trim().parse::<usize>().ok()).filter(|&n| n > 0);
    opts.peer_threads.or(lavapipe).unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// A case's result before anything is measured.
fn blank(case: &Case, scene: &Scene, steps: u64, reps: usize) -> CaseResult {
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

fn run_case(
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

    // 3. the state, a readback, the stages, a render
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

    // 5. the peer's repetitions, taken between ours
    out.peer = peer.map(|p| p.result(out.median_ms_per_step));
    Ok(out)
}

/// The peer's repetitions of one case (feature `rapier`), taken one at a
/// time between ours: each a fresh rapier3d world of the same scene, its
/// first step untimed, then the same steps timed; one in each pool.
#[cfg(feature = "rapier")]
struct PeerReps<'a> {
    case: &'a Case,
    scene: &'a Scene,
    steps: u64,
    reps: usize,
    opts: &'a Options,
    /// The `--peer-threads` pool's runs, then the one-thread pool's (none
    /// when `--peer-threads` is 1: the first are its figures).
    runs: Vec<PeerRun>,
}

/// One pool's repetitions of a case.
#[cfg(feature = "rapier")]
struct PeerRun {
    threads: usize,
    pool: Arc<rapier3d::rayon::ThreadPool>,
    times: Vec<f64>,
    setups: Vec<f64>,
    /// The last repetition's solver iterations and mean height (its world
    /// is dropped at once: ours are stepped and profiled meanwhile).
    last: Option<(usize, f64)>,
}

#[cfg(feature = "rapier")]
impl<'a> PeerReps<'a> {
    /// None when the peer is not run (`--no-peer`, or more bodies than
    /// `--peer-max-bodies`).
    fn new(case: &'a Case, scene: &'a Scene, steps: u64, reps: usize, opts: &'a Options) -> Result<Option<PeerReps<'a>>, Error> {
        if opts.no_peer || opts.peer_max_bodies.is_some_and(|m| scene.bodies.len() > m) {
            return Ok(None);
        }
        let threads = peer_threads(opts);
        let mut runs = Vec::new();
        for n in if threads == 1 { vec![1] } else { vec![threads, 1] } {
            let pool = peer::pool(n).map_err(|e| Error::Input(format!("--peer-threads: no pool of {n} threads: {e}")))?;
            runs.push(PeerRun { threads: n, pool, times: Vec::new(), setups: Vec::new(), last: None });
        }
        Ok(Some(PeerReps { case, scene, steps, reps, opts, runs }))
    }

    /// Repetition `r` (from 0) in each pool, the pools in turns (so that
    /// neither always follows ours).
    fn rep(&mut self, r: usize) {
        let count = self.runs.len();
        for k in 0..count {
            let run = &mut self.runs[(k + r) % count];
            let t = Instant::now();
            let mut w =
                peer::RapierWorld::new(self.scene, self.opts.rapier_sleeping, self.opts.rapier_iterations, run.pool.clone());
            w.step(1); // as ours: the first step untimed, the same steps timed
            run.setups.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            w.step(self.steps);
            let ms = t.elapsed().as_secs_f64() * 1e3 / self.steps as f64;
            progress!("{}: rapier ({} threads) rep {}/{}: {ms:.3} ms/step", self.case.name, run.threads, r + 1, self.reps);
            run.times.push(ms);
            run.last = Some((w.num_solver_iterations(), w.mean_height()));
        }
    }

    /// The peer's result against our median `ours_ms`.
    fn result(self, ours_ms: f64) -> PeerResult {
        let bodies = self.scene.bodies.len() as f64;
        let one = self.runs.last().map_or_else(Vec::new, |r| r.times.clone());
        let one_m = median(&one);
        let run = self.runs.into_iter().next().expect("PeerReps::new makes a run");
        let m = median(&run.times);
        let (iterations, height) = run.last.unwrap_or((0, f64::NAN));
        PeerResult {
            engine: peer::ENGINE.into(),
            threads: run.threads.to_string(),
            thread_count: run.threads,
            sleeping: self.opts.rapier_sleeping,
            num_solver_iterations: iterations,
            setup_s: median(&run.setups),
            ms_per_step: run.times,
            median_ms_per_step: m,
            body_steps_per_s: bodies / (m * 1e-3),
            speedup: m / ours_ms,
            mean_height: height,
            one_thread_ms_per_step: one,
            one_thread_median_ms_per_step: one_m,
            one_thread_body_steps_per_s: bodies / (one_m * 1e-3),
            one_thread_speedup: one_m / ours_ms,
        }
    }
}

/// Without the feature there is no peer: no value of this type exists.
#[cfg(not(feature = "rapier"))]
enum PeerReps {}

#[cfg(not(feature = "rapier"))]
impl PeerReps {
    fn new(_: &Case, _: &Scene, _: u64, _: usize, _: &Options) -> Result<Option<PeerReps>, Error> {
        Ok(None)
    }

    fn rep(&mut self, _: usize) {
        match *self {}
    }

    fn result(self, _: f64) -> PeerResult {
        match self {}
    }
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

/// The peer's time over ours for each of our repetitions and the peer's
/// taken right after it (`PeerReps`), when there are several: how far the
/// ratio moves from one repetition to the next.
fn by_repetition(ours: &[f64], peer: &[f64]) -> String {
    if ours.len() < 2 || ours.len() != peer.len() {
        return String::new();
    }
    let each: Vec<String> = ours.iter().zip(peer).map(|(o, p)| format!("{:.2}x", p / o)).collect();
    each.join(", ")
}

/// Brings a pile case (named `case` in the report) to rest with sleeping
/// on (see `Settled`).
fn settle(gpu: &Arc<Gpu>, pile: &Case, case: &str, most_steps: u64) -> Result<Settled, Error> {
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
fn cold_start(runs: usize) -> Vec<f64> {
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

fn fmt_ms(v: f64) -> String {
    if !v.is_finite() {
        "-".into()
    } else if v >= 100.0 {
        format!("{v:.1}")
    } else if v >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

fn fmt_rate(v: f64) -> String {
    if !v.is_finite() {
        "-".into()
    } else if v >= 1e6 {
        format!("{:.2} M", v / 1e6)
    } else {
        format!("{:.0} k", v / 1e3)
    }
}

/// Plain-text columns: the first left-aligned, the rest right-aligned
/// (numbers), two spaces apart.
fn columns(rows: &[Vec<String>]) -> String {
    let count = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> =
        (0..count).map(|k| rows.iter().filter_map(|r| r.get(k)).map(|c| c.chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for row in rows {
        let mut line = String::new();
        for (k, cell) in row.iter().enumerate() {
            let w = widths[k];
            if k == 0 {
                line.push_str(&format!("{cell:<w$}"));
            } else {
                line.push_str(&format!("  {cell:>w$}"));
            }
        }
        s.push_str(line.trim_end());
        s.push('\n');
    }
    s
}

/// The peer on its threads and on one, each against ours (empty without a peer).
fn peer_threads_table(r: &Report) -> String {
    use std::fmt::Write as _;
    let peers: Vec<(&CaseResult, &PeerResult)> = r.cases.iter().filter_map(|c| c.peer.as_ref().map(|p| (c, p))).collect();
    let mut s = String::new();
    if peers.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\nrapier3d by threads (ms / ours: its ms/step over ours)\n");
    let mut rows = vec![["case", "ours ms/step", "threads", "rapier3d ms/step", "ms / ours", "1 thread ms/step", "ms / ours"]
        .map(String::from)
        .to_vec()];
    for (c, p) in peers {
        rows.push(vec![
            c.case.clone(),
            fmt_ms(c.median_ms_per_step),
            p.thread_count.to_string(),
            fmt_ms(p.median_ms_per_step),
            format!("{:.2}x", p.speedup),
            fmt_ms(p.one_thread_median_ms_per_step),
            format!("{:.2}x", p.one_thread_speedup),
        ]);
    }
    let _ = write!(s, "{}", columns(&rows));
    s
}

/// The report as plain text for a terminal: what was measured, in the
/// user's terms.
pub fn table(r: &Report) -> String {
    use std::fmt::Write as _;
    let cells = |v: &[&str]| v.iter().map(|c| c.to_string()).collect::<Vec<String>>();
    let peer = r.peer.split_whitespace().next().filter(|_| r.cases.iter().any(|c| c.peer.is_some()));
    let mut s = String::new();
    let _ = writeln!(s, "\nmachine:  {} ({} cores)", r.cpu, r.cores);
    let _ = writeln!(s, "adapter:  {}", r.adapter);
    let _ = writeln!(
        s,
        "limits:   largest scene {} bodies (storage binding {} B), {} B a body as a world is made; GPU opened in {:.2} s",
        r.max_bodies, r.max_storage_buffer_binding_size, r.bytes_per_body, r.gpu_open_s
    );
    let _ = writeln!(s, "shaders:  {}", r.shader_cache);
    let _ = writeln!(s, "peer:     {}", r.peer);
    let _ = writeln!(s, "solver:   {}", r.iterations);
    let _ = writeln!(s, "command:  {}", r.command);
    let busiest = r.cases.iter().filter_map(|c| c.load_avg).flatten().fold(0.0f64, f64::max);
    if busiest > r.cores as f64 + 0.5 {
        let _ = writeln!(
            s,
            "warning: the machine was busy (1-minute load average up to {busiest:.1} on {} cores): other work shared the CPU, so every time below is inflated",
            r.cores
        );
    }

    let mut head = cells(&["case", "bodies", "steps x reps", "start-up s", "ms/step", "body-steps/s", "GPU MiB", "B/body"]);
    if let Some(peer) = peer {
        head.extend([format!("{peer} ms/step"), format!("{peer} body-steps/s"), format!("{peer} ms / ours")]);
    }
    let mut rows = vec![head];
    for c in &r.cases {
        if let Some(why) = &c.skipped {
            rows.push(cells(&[&c.case, &c.bodies.to_string(), "skipped", "-", "-", "-", "-", "-"]));
            rows.push(vec![format!("  ({why})")]);
            continue;
        }
        let mut row = vec![
            c.case.clone(),
            c.bodies.to_string(),
            format!("{} x {}", c.steps, c.reps),
            format!("{:.2}", c.startup_s),
            fmt_ms(c.median_ms_per_step),
            fmt_rate(c.body_steps_per_s),
            format!("{:.1}", c.gpu_bytes as f64 / (1u64 << 20) as f64),
            format!("{:.0}", c.gpu_bytes_per_body),
        ];
        if peer.is_some() {
            row.extend(match &c.peer {
                Some(p) => [fmt_ms(p.median_ms_per_step), fmt_rate(p.body_steps_per_s), format!("{:.2}x", p.speedup)],
                None => ["-".into(), "-".into(), "-".into()],
            });
        }
        rows.push(row);
    }
    let _ = writeln!(s, "\nms/step: median of the repetitions, wall clock; B/body: GPU memory after the run, over the bodies");
    if let Some(peer) = peer {
        let _ = writeln!(s, "{peer} ms / ours: above 1x verlet is faster, below it {peer} is");
    }
    let _ = writeln!(s, "\n{}", columns(&rows).trim_end());
    for c in &r.cases {
        if let Some(p) = &c.peer {
            let each = by_repetition(&c.ms_per_step, &p.ms_per_step);
            if !each.is_empty() {
                let _ = writeln!(s, "{}: {} ms / ours by repetition (each after ours): {each}", c.case, peer.unwrap_or("peer"));
            }
        }
    }

    s.push_str(&peer_threads_table(r));
    let source = r.cases.iter().find_map(|c| c.stages.as_ref().map(|st| st.source.clone()));
    if let Some(source) = source {
        let mut rows = vec![cells(&[
            "case",
            "broadphase",
            "narrowphase",
            "integrate",
            "solve",
            "restitution",
            "sum of stages",
            "wall",
            "readback",
        ])];
        for c in &r.cases {
            let Some(st) = &c.stages else { continue };
            rows.push(vec![
                c.case.clone(),
                fmt_ms(st.broadphase),
                fmt_ms(st.narrowphase),
                fmt_ms(st.integrate),
                fmt_ms(st.solve),
                fmt_ms(st.restitution),
                fmt_ms(st.total),
                fmt_ms(c.median_ms_per_step),
                fmt_ms(c.readback_ms),
            ]);
        }
        let _ = writeln!(
            s,
            "\nper stage, ms a step ({source}, each pass timed on its own; wall: the repetitions' median; readback: every body's state read back once)\n"
        );
        let _ = write!(s, "{}", columns(&rows));
    }

    let mut rows = vec![cells(&["case", "sweeps in substeps", "first step ms", "later set-up s", "mean height m"])];
    if let Some(peer) = peer {
        rows[0].push(format!("{peer} mean height m"));
    }
    rows[0].extend(cells(&["most manifolds", "pools overflowed", "load avg start / end"]));
    for c in r.cases.iter().filter(|c| c.skipped.is_none()) {
        let mut row = vec![
            c.case.clone(),
            format!("{} in {}", c.iterations, c.substeps),
            fmt_ms(c.first_step_ms),
            format!("{:.2}", c.setup_s),
            format!("{:.3}", c.mean_height),
        ];
        if peer.is_some() {
            row.push(c.peer.as_ref().map_or("-".into(), |p| format!("{:.3}", p.mean_height)));
        }
        row.extend([
            c.max_contacts.to_string(),
            if c.contacts_overflowed { "yes" } else { "no" }.to_string(),
            c.load_avg.map_or("-".into(), |[a, b]| format!("{a:.1} / {b:.1}")),
        ]);
        rows.push(row);
    }
    let _ = writeln!(s, "\neach case after its last repetition\n");
    let _ = write!(s, "{}", columns(&rows));

    for c in &r.cases {
        if let Some(n) = &c.note {
            let _ = writeln!(s, "\nnote: {}: {n}", c.case);
        }
    }
    for (family, scaling) in [("cubes", &r.scaling), ("piles", &r.pile_scaling)] {
        if let Some(sc) = scaling {
            let pts: Vec<String> =
                sc.points.iter().map(|(n, ms)| format!("{n}: {:.1} ns/body-step", ms * 1e6 / *n as f64)).collect();
            let _ = writeln!(
                s,
                "\nscaling ({family}): time per step ~ bodies^{:.2} (log-log least squares over {}); cost per body-step spread {:.2}x",
                sc.exponent,
                pts.join(", "),
                sc.spread
            );
        }
    }
    if let Some(st) = &r.settled {
        let _ = writeln!(
            s,
            "\nsettled: {} with sleeping on: {} of {} bodies asleep after {} steps, {:.0} B/body (pools for {} pairs and {} manifolds), {} ms/step over the last 60",
            st.case,
            st.asleep,
            st.bodies,
            st.steps,
            st.gpu_bytes_per_body,
            st.pair_capacity,
            st.manifold_capacity,
            fmt_ms(st.last_ms_per_step)
        );
    }
    if !r.cold_start_s.is_empty() {
        let runs: Vec<String> = r.cold_start_s.iter().map(|t| format!("{t:.2}")).collect();
        let _ = writeln!(
            s,
            "\ncold start: `verlet run --builtin cubes --count 10 --steps 1`, whole process, MESA_SHADER_CACHE_DISABLE=true: {:.2} s (median of {} s)",
            median(&r.cold_start_s),
            runs.join(", ")
        );
    }
    if let (Some(setup), Some(ms)) = (r.render_setup_s, r.render_ms) {
        let _ = writeln!(
            s,
            "\nrender: the 1000-cube scene, landed, at 640 x 480 (4x MSAA, shadow map, image read back): {} ms a frame; renderer set-up {setup:.2} s",
            fmt_ms(ms)
        );
    }
    if let Some(d) = &r.dispatch {
        let _ = writeln!(
            s,
            "\ndispatches: {} a step for ten cubes at the default settings (two more above 1024 bodies, three above 2048, more with joints); they step in {} ms: about {:.0} us a dispatch before any work",
            d.dispatches_per_step,
            fmt_ms(d.ten_cubes_ms_per_step),
            d.us_per_dispatch
        );
    }
    let asked: Vec<&str> = [
        (r.settled.is_none(), "--settle"),
        (r.cold_start_s.is_empty(), "--cold-start"),
        (r.render_ms.is_none(), "--render"),
        (r.dispatch.is_none(), "--dispatch-cost"),
    ]
    .into_iter()
    .filter_map(|(left_out, flag)| left_out.then_some(flag))
    .collect();
    if !asked.is_empty() {
        let _ = writeln!(s, "\nnot measured in this run: {} (or --all)", asked.join(", "));
    }
    s
}

/// One row per case.
pub fn csv(r: &Report) -> String {
    use std::fmt::Write as _;
    let mut s = String::from(
        "case,scene,bodies,steps,reps,skipped,startup_s,first_step_ms,setup_s,median_ms_per_step,body_steps_per_s,\
         gpu_bytes,gpu_bytes_per_body,stage_source,broadphase_ms,narrowphase_ms,integrate_ms,solve_ms,restitution_ms,\
         readback_ms,render_ms,integrate_ms_per_pass,copy_ms_per_pass,peer,peer_median_ms_per_step,peer_body_steps_per_s,speedup,adapter,\
         peer_one_thread_median_ms_per_step,one_thread_speedup\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x}"));
    let quote = |t: &str| format!("\"{}\"", t.replace('"', "\"\""));
    for c in &r.cases {
        let st = c.stages.as_ref();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            quote(&c.case),
            c.scene,
            c.bodies,
            c.steps,
            c.reps,
            quote(c.skipped.as_deref().unwrap_or("")),
            c.startup_s,
            c.first_step_ms,
            c.setup_s,
            c.median_ms_per_step,
            c.body_steps_per_s,
            c.gpu_bytes,
            c.gpu_bytes_per_body,
            st.map_or(String::new(), |x| x.source.clone()),
            opt(st.map(|x| x.broadphase)),
            opt(st.map(|x| x.narrowphase)),
            opt(st.map(|x| x.integrate)),
            opt(st.map(|x| x.solve)),
            opt(st.map(|x| x.restitution)),
            c.readback_ms,
            opt(c.render_ms),
            opt(c.integrate_ms_per_pass),
            opt(c.copy_ms_per_pass),
            quote(&c.peer.as_ref().map_or(String::new(), |p| format!("{} threads={}", p.engine, p.threads))),
            opt(c.peer.as_ref().map(|p| p.median_ms_per_step)),
            opt(c.peer.as_ref().map(|p| p.body_steps_per_s)),
            opt(c.peer.as_ref().map(|p| p.speedup)),
            quote(&r.adapter),
            opt(c.peer.as_ref().map(|p| p.one_thread_median_ms_per_step)),
            opt(c.peer.as_ref().map(|p| p.one_thread_speedup)),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_repetition_against_the_peers_after_it() {
        assert_eq!(by_repetition(&[40.0, 50.0, 42.0], &[44.0, 45.0, 42.0]), "1.10x, 0.90x, 1.00x");
        assert_eq!(by_repetition(&[40.0], &[44.0]), "", "one repetition: the speed-up says it all");
        assert_eq!(by_repetition(&[40.0, 41.0], &[44.0]), "", "not paired");
    }

    #[test]
    fn exponent_of_a_power_law() {
        let mk = |n: usize, ms: f64| CaseResult { scene: "cubes".into(), bodies: n, median_ms_per_step: ms, ..result_stub() };
        let rs = vec![mk(10_000, 2.0), mk(100_000, 20.0), mk(1_000_000, 200.0), mk(1_000, 99.0)];
        let s = scaling(&rs, "cubes").unwrap();
        assert!((s.exponent - 1.0).abs() < 1e-9, "{}", s.exponent);
        assert!((s.spread - 1.0).abs() < 1e-9);
        assert_eq!(s.points.len(), 3);
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    /// A pile case with a peer at `speedup` and, for 10k, a profile.
    fn pile(n: usize, ms: f64, speedup: f64, bytes_per_body: f64) -> CaseResult {
        let peer = PeerResult {
            engine: "rapier3d".into(),
            threads: "1".into(),
            thread_count: 1,
            sleeping: false,
            num_solver_iterations: 4,
            setup_s: 0.0,
            ms_per_step: vec![ms * speedup],
            median_ms_per_step: ms * speedup,
            body_steps_per_s: n as f64 / (ms * speedup * 1e-3),
            speedup,
            mean_height: 1.0,
            one_thread_ms_per_step: vec![ms * speedup],
            one_thread_median_ms_per_step: ms * speedup,
            one_thread_body_steps_per_s: n as f64 / (ms * speedup * 1e-3),
            one_thread_speedup: speedup,
        };
        let stages = (n == 10_000).then(|| Stages {
            source: "GPU timestamps".into(),
            steps: 10,
            broadphase: 2.0,
            narrowphase: 20.0,
            integrate: 2.0,
            solve: 30.0,
            restitution: 6.0,
            total: 60.0,
            passes: vec![
                ("pairs_count".into(), 8.0),
                ("pairs_write".into(), 1.0),
                ("narrowphase".into(), 6.0),
                ("narrowphase_ground".into(), 0.5),
                ("contact_lists".into(), 2.0),
                ("narrowphase_clip".into(), 2.5),
                ("solve_contacts".into(), 22.0),
            ],
        });
        CaseResult {
            case: format!("pile-{n}"),
            scene: "pile".into(),
            bodies: n,
            steps: 60,
            median_ms_per_step: ms,
            gpu_bytes_per_body: bytes_per_body,
            gpu_bytes_at_start: 1204 * n as u64,
            stages,
            peer: Some(peer),
            ..result_stub()
        }
    }

    fn report_of(cases: Vec<CaseResult>, max_bodies: u64, cold_start_s: Vec<f64>) -> Report {
        Report {
            command: String::new(),
            cpu: String::new(),
            cores: 2,
            adapter: String::new(),
            gpu_timestamps: true,
            max_bodies,
            max_storage_buffer_binding_size: 1 << 27,
            bytes_per_body: 1204,
            iterations: String::new(),
            peer: String::new(),
            gpu_open_s: 0.3,
            render_setup_s: None,
            render_ms: None,
            shader_cache: String::new(),
            sleeping: false,
            scaling: scaling(&cases, "cubes"),
            pile_scaling: scaling(&cases, "pile"),
            cold_start_s,
            settled: None,
            dispatch: None,
            cases,
        }
    }

    /// pile-10k brought to rest: `asleep` of its bodies, `bytes_per_body`.
    fn settled(asleep: usize, bytes_per_body: f64) -> Settled {
        Settled {
            case: "pile-10k".into(),
            bodies: 10_000,
            steps: 960,
            asleep,
            pairs: 12,
            manifolds: 9,
            pair_capacity: 64,
            manifold_capacity: 64,
            gpu_bytes: (bytes_per_body * 1e4) as u64,
            gpu_bytes_per_body: bytes_per_body,
            last_ms_per_step: 12.0,
        }
    }

    /// The terminal report: measurements in plain text, the peer's ratio,
    /// the settled pile and the cold start when measured, and nothing that
    /// grades the run.
    #[test]
    fn the_report_measures_and_does_not_grade() {
        let r = Report {
            settled: Some(settled(9_990, 448.0)),
            peer: "rapier3d 0.36 (single-threaded)".into(),
            ..report_of(vec![pile(1_000, 8.0, 0.65, 1241.0), pile(10_000, 60.0, 1.5, 1359.0)], 1_048_560, vec![1.9, 1.8, 2.4])
        };
        let text = table(&r);
        for word in ["target", "MISSED", "floor", "goal", "issue", "**", "|---"] {
            assert!(!text.contains(word), "{word:?} in {text}");
        }
        let row = text.lines().find(|l| l.starts_with("pile-10000 ")).unwrap_or_else(|| panic!("no pile-10k row: {text}"));
        assert!(row.contains("60.00") && row.contains("1.50x"), "{row}");
        assert!(text.contains("rapier3d ms / ours: above 1x verlet is faster"), "{text}");
        assert!(text.contains("settled: pile-10k with sleeping on: 9990 of 10000 bodies asleep"), "{text}");
        assert!(text.contains("1.90 s (median of 1.90, 1.80, 2.40 s)"), "{text}");
        assert!(text.contains("not measured in this run: --render, --dispatch-cost (or --all)"), "{text}");
        let json = serde_json::to_value(&r).unwrap();
        assert!(json.get("targets").is_none(), "{json}");
        assert!(!json.to_string().contains("issue"), "{json}");
    }

    #[test]
    fn columns_line_up() {
        let rows = vec![vec!["case".to_string(), "ms/step".into()], vec!["pile-1000".into(), "4.54".into()]];
        assert_eq!(columns(&rows), "case       ms/step\npile-1000     4.54\n");
    }

    fn result_stub() -> CaseResult {
        let c = case("pyramid");
        blank(&c, &c.scene(), 1, 1)
    }
}
