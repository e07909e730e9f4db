//! The physics limits a world checks every body against, and the faults it
//! reports when one is passed. A leaf: the shaders' shared constants
//! (`gpu::shaders`), the scene's validation and the world all read it.

/// `Status::fault` and `Status::fault_step` before any fault: the GPU keeps
/// the lowest with `atomicMin`, so "none" is the largest word.
pub const NO_FAULT: u32 = u32::MAX;

/// The speed (m/s) beyond which a body's state is absurd: it is stopped
/// as a fault rather than left to wreck the scene.
pub const MAX_SPEED: f32 = 1e4;

/// The distance from the origin (m) beyond which a body's state is absurd.
pub const MAX_DISTANCE: f32 = 1e6;

/// The spin (rad/s) beyond which a body's state is absurd.
pub const MAX_SPIN: f32 = 1e4;

/// The most a body may turn in one substep (rad): a pose pair holds under
/// half a turn (pi), and past it the velocity read from the pair is wrong.
pub const MAX_TURN: f32 = 3.0;

/// The shortest substep (s, dt / substeps) a world takes. Velocities are
/// displacements over the substep, and over shorter ones the rounding of the
/// poses reads as speed (docs/limits.md has the measurements).
pub const MIN_SUBSTEP: f32 = 1e-5;

/// The longest step (s) a world takes (`settings.dt`, `World::step_with`):
/// a step is one frame of a real-time simulation, and at 1 s unit cubes
/// already rest 156 mm inside the ground (docs/limits.md).
pub const MAX_DT: f32 = 1.0;

/// The most steps a world counts: up to 2^53 the count and the time summed
/// from it stay exact in f64, and nothing that counts steps overflows.
pub const MAX_STEPS: u64 = 1 << 53;

/// The latest simulated time (s) a world reaches, a track event comes at or
/// a snapshot holds: 1e12 s (32 000 years) is 1e17 of the shortest steps,
/// within a u64 step count with room to spare.
pub const MAX_TIME: f64 = 1e12;

/// The largest impulse (N s) an input gives a body or an explosion gives
/// each body: it throws a thousand tonnes at `MAX_SPEED`. What a smaller one
/// does depends on the mass, and a body it throws too fast is a fault.
pub const MAX_IMPULSE: f32 = 1e10;

/// The largest force (N) an input applies: over the longest step it gives
/// `MAX_IMPULSE`.
pub const MAX_FORCE: f32 = MAX_IMPULSE / MAX_DT;

/// The densest air (kg/m^3) a wind blows with: denser than any matter
/// (osmium is 22 590), so only a mistake is refused.
pub const MAX_AIR_DENSITY: f32 = 1e5;

/// The largest drag coefficient a wind takes: no shape drags more than
/// about 2; 1e3 is only a bound on mistakes.
pub const MAX_DRAG: f32 = 1e3;

/// The nearest a camera may be to its target (m): nearer, the view's
/// direction is lost to rounding and the frame comes out blank.
pub const MIN_CAMERA_DISTANCE: f32 = 1e-3;

/// Fastest speed (m/s) at which the solve pushes apart bodies that already
/// overlapped at their previous poses (as Box2D's contact push speed);
/// joints close an old gap no faster.
pub const MAX_DEPENETRATION_SPEED: f32 = 3.0;

/// The gap (m) within which two bodies get contacts whatever their speed: it
/// covers what the step's own snaps bring them nearer by, since contacts are
/// found once a step. What their motion brings them nearer by within the
/// step comes on top of it (pairs.wgsl's `pair_margin`).
pub const CONTACT_MARGIN: f32 = 0.01;

/// Points closer than this (m) still touch when restitution is decided
/// after the solve; a hull's contact points this near the deepest count as
/// deep as it (`reduce`).
pub const CONTACT_SLOP: f32 = 0.002;

/// What was wrong with a faulted body: the low three bits of `Status::fault`
/// (`FAULT_*` in the shaders).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// An infinity or a NaN in its pose.
    NonFinite = 0,
    /// Farther than `MAX_DISTANCE` from the origin.
    TooFar = 1,
    /// Faster than `MAX_SPEED`.
    TooFast = 2,
    /// Spinning faster than `MAX_SPIN`, or turning more than `MAX_TURN` in a substep.
    SpinsTooFast = 3,
    /// Faster than the scene's energy can move it (`BodyProps::speed_limit`):
    /// thrown by the solver.
    FasterThanItsEnergy = 4,
}

/// The first numerical fault the GPU found: the lowest body found bad in the
/// first step that found any. The integration checks every body's state
/// every substep (no readback); a bad body is stopped, parked at rest at
/// its last sane pose, and the run goes on (see shaders/integrate.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    pub body: usize,
    /// The step (0-based: the world's step count as it began) whose
    /// integration found the bad state: the state went bad during it
    /// (between substeps), during the step before, or through the scene or
    /// an input given before it.
    pub step: u64,
    pub kind: FaultKind,
}

impl Fault {
    /// The fault the GPU's two words describe (`Status::fault`: 8 x body +
    /// kind; `Status::fault_step`), if any.
    pub(crate) fn decode(code: u32, step: u32) -> Option<Fault> {
        if step == NO_FAULT || code == NO_FAULT {
            return None;
        }
        let kind = match code & 7 {
            0 => FaultKind::NonFinite,
            1 => FaultKind::TooFar,
            2 => FaultKind::TooFast,
            3 => FaultKind::SpinsTooFast,
            _ => FaultKind::FasterThanItsEnergy,
        };
        Some(Fault { body: (code / 8) as usize, step: step as u64, kind })
    }
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.kind {
            FaultKind::NonFinite => "non-finite".to_string(),
            FaultKind::TooFar => format!("absurd (farther than {MAX_DISTANCE:e} m from the origin)"),
            FaultKind::TooFast => format!("absurd (faster than {MAX_SPEED:e} m/s)"),
            FaultKind::SpinsTooFast => {
                format!("absurd (spinning faster than {MAX_SPIN:e} rad/s or {MAX_TURN} rad in one substep)")
            }
            FaultKind::FasterThanItsEnergy => "absurd (faster than all the energy of the scene could move it: \
                                               the solver threw it)"
                .to_string(),
        };
        write!(f, "body {} became {what} at step {}; it was stopped at its last sane pose", self.body, self.step)
    }
}
