//! User input between steps: impulses and forces at a point,
//! poses, velocities, fixed/dynamic switches and radial explosions.
//!
//! Nothing is read back. Every call validates its arguments on the host
//! (a bad body index, a non-finite number or one beyond the limits the
//! scene loader uses, `crate::limits`, is an [`Error::Input`] naming the
//! argument, and nothing is applied), then writes a small list of ops and dispatches a kernel of
//! `shaders/input.wgsl` that rewrites the affected bodies' slots of the
//! current state buffer in place. The queue orders it after the steps
//! already submitted and before the next one, so the host never waits.
//!
//! Why a kernel and not `queue.write_buffer` of a 64-byte slot: the
//! velocity of a Verlet body is implicit in its previous pose, and an
//! impulse, or a new pose that keeps the body's velocity, must start from
//! the current state, which only the GPU holds. A kernel reads it where it
//! is; the alternative, a 64-byte readback per call, would stall the host
//! until every submitted step has run. A batch of inputs ([`World::apply_inputs`])
//! is one dispatch: ops are sorted by body (in call order within a body) and
//! one thread applies each body's run of ops in order, so any number of
//! inputs to the same body compose without races. Explosions and winds
//! given together go the same way ([`World::apply_winds`]): one thread per
//! body applies each in order.
//!
//! Velocity changes rewrite the previous pose: with h the substep that
//! produced the current pose, v = disp / h (disp = pos - prev_pos, kept
//! instead of prev_pos, see `BodyState`) and the world-frame
//! turn rot * prev_rot^* = exp(w h), which is what the next `integrate`
//! repeats.
//!
//! The kernel's resources (two pipelines, one bind group per state buffer, a
//! uniform header and a growing op list) are built on first use and kept in
//! `World::input`.

use bytemuck::{Pod, Zeroable};

use super::World;
use crate::gpu::shaders::{shared_constants, wgsl_u32, BINDINGS, COMMON};
use crate::gpu::types::WORKGROUP;
use crate::Error;

/// `shaders/input.wgsl`, the kernels of this module.
pub(crate) const INPUT: &str = include_str!("../../shaders/input.wgsl");

/// Entry points of the input module.
pub const ENTRY_POINTS: [&str; 4] = ["apply_inputs", "explode", "wind", "wake_all"];

/// Indices into `ENTRY_POINTS` and `InputGpu::pipelines`.
const APPLY: usize = 0;
const EXPLODE: usize = 1;
const WIND: usize = 2;
const WAKE_ALL: usize = 3;

/// The assembled WGSL module: the shared constants (with the input ops'
/// kinds), common.wgsl, bindings.wgsl (for the declarations its helpers
/// name; only the state and properties are bound), input.wgsl.
pub fn source() -> String {
    let mut constants = shared_constants();
    for (name, kind) in [
        ("INPUT_IMPULSE", INPUT_IMPULSE),
        ("INPUT_POSE", INPUT_POSE),
        ("INPUT_VELOCITY", INPUT_VELOCITY),
        ("INPUT_FIXED", INPUT_FIXED),
    ] {
        constants += &wgsl_u32(name, kind);
    }
    [constants.as_str(), COMMON, BINDINGS, INPUT].concat()
}

/// Where an impulse or force acts on a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Point {
    /// At the centre of mass: no change of spin.
    Centre,
    /// At a point in world coordinates (m).
    World([f32; 3]),
    /// At a point in the body's own frame, relative to its centre (m).
    Local([f32; 3]),
}

/// One input to one body, for [`World::apply_inputs`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BodyInput {
    /// Changes the velocity by J / m and the spin by I^-1 (r x J), with I
    /// the world-frame inertia at the current orientation and r from the
    /// centre of mass to the point. No effect on a fixed body.
    Impulse { body: usize, impulse: [f32; 3], point: Point },
    /// Moves the body to this pose, keeping its velocities (world frame).
    /// The orientation is normalised.
    Pose { body: usize, position: [f32; 3], orientation: [f32; 4] },
    /// Sets the velocities (world frame); from here the body follows
    /// x + v t + g t^2 / 2, as a body loaded with these velocities does. No
    /// effect on a fixed body.
    Velocity { body: usize, linear: [f32; 3], angular: [f32; 3] },
    /// `fixed: true` makes the body immovable (infinite mass, at rest);
    /// `false` makes a fixed body dynamic again, at rest, with `mass` (kg)
    /// and the inertia of a solid of its shape, or with `mass: None` the mass
    /// it had when it was made fixed; a body loaded as fixed then gets the
    /// mass its scene gave it (its `mass`, or its density times its volume;
    /// 1 kg where that mass is one its shape cannot move with). On a body
    /// already dynamic, `mass` sets its mass and inertia, keeping its
    /// velocities (`None`: nothing changes). A mass whose inverse mass or
    /// inertia f32 cannot hold is refused, as a scene's is.
    Fixed { body: usize, fixed: bool, mass: Option<f32> },
}

impl BodyInput {
    fn body(&self) -> usize {
        match *self {
            BodyInput::Impulse { body, .. }
            | BodyInput::Pose { body, .. }
            | BodyInput::Velocity { body, .. }
            | BodyInput::Fixed { body, .. } => body,
        }
    }
}

/// A uniform wind with optional gusts, for [`World::apply_wind`]: quadratic
/// drag F = rho Cd A |u| u / 2 on every dynamic body, with u the wind's
/// velocity relative to the body's and A the body's area seen along u (a
/// box's projection, a sphere's disc), through the centre of mass (no
/// torque).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wind {
    /// Mean wind velocity (m/s, world frame).
    pub velocity: [f32; 3],
    /// Air density (kg/m^3); 1.225 at sea level.
    pub air_density: f32,
    /// Drag coefficient; 1.05 for a cube face on, 0.47 for a sphere.
    pub drag: f32,
    /// Gust strength: the wind is `velocity * (1 + gust * s(t))`, where
    /// s(t) in [-1, 1] is a fixed sum of two incommensurate sines of
    /// period `gust_period` and `gust_period / 2.71`. 0: steady.
    pub gust: f32,
    /// Seconds (> 0).
    pub gust_period: f32,
}

impl Default for Wind {
    fn default() -> Wind {
        Wind { velocity: [0.0; 3], air_density: 1.225, drag: 1.0, gust: 0.0, gust_period: 4.0 }
    }
}

impl Wind {
    /// A steady wind of this velocity (m/s).
    pub fn steady(velocity: [f32; 3]) -> Wind {
        Wind { velocity, ..Wind::default() }
    }

    /// The gust profile s(t), in [-1, 1].
    fn gust_profile(&self, t: f64) -> f64 {
        let phase = std::f64::consts::TAU * t / self.gust_period as f64;
        0.6 * phase.sin() + 0.4 * (2.71 * phase + 1.3).sin()
    }

    /// The wind velocity at time `t` (s).
    pub fn at(&self, t: f64) -> [f32; 3] {
        let scale = 1.0 + self.gust as f64 * self.gust_profile(t);
        self.velocity.map(|v| (v as f64 * scale) as f32)
    }

    fn validate(&self, at: &str) -> Result<(), Error> {
        let name = |field: &str| format!("{at}{field}");
        check_finite(&name("velocity"), &self.velocity)?;
        // the drag pulls a body toward the wind's velocity
        check_sane(&name("velocity"), crate::scene::speed_problem(self.velocity))?;
        for (field, v) in [("air_density", self.air_density), ("drag", self.drag), ("gust", self.gust)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Input(format!("{}: must be a finite number >= 0, got {v}", name(field))));
            }
        }
        check_sane(&name("gust"), gust_problem(self.velocity, self.gust))?;
        check_sane(&name("air_density"), air_density_problem(self.air_density))?;
        check_sane(&name("drag"), drag_problem(self.drag))?;
        if !(self.gust_period.is_finite() && self.gust_period > 0.0) {
            return Err(Error::Input(format!(
                "{}: must be a positive finite number of seconds, got {}",
                name("gust_period"),
                self.gust_period
            )));
        }
        Ok(())
    }
}

/// Host twin of `InputHeader` in shaders/input.wgsl (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InputHeader {
    /// settings.gravity (m/s^2).
    pub gravity: [f32; 3],
    /// h, the last substep (s).
    pub substep_dt: f32,
    pub counts: [u32; 4],
}

/// Host twin of `InputOp` in shaders/input.wgsl (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InputOp {
    pub body: u32,
    pub kind: u32,
    pub run: u32,
    pub _pad0: u32,
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub c: [f32; 4],
}

/// `InputOp::kind` (input.wgsl reads them from here: `source`).
const INPUT_IMPULSE: u32 = 0;
const INPUT_POSE: u32 = 1;
const INPUT_VELOCITY: u32 = 2;
const INPUT_FIXED: u32 = 3;

/// Bindings of shaders/input.wgsl (group 0).
const BIND_STATE: u32 = 3;
const BIND_HEADER: u32 = 20;
const BIND_OPS: u32 = 21;
const BIND_PROPS: u32 = 22;

/// The input kernels' pipelines and buffers, built on a world's first input.
pub(super) struct InputGpu {
    layout: wgpu::BindGroupLayout,
    /// One per entry point, in the order of `ENTRY_POINTS`.
    pipelines: [wgpu::ComputePipeline; ENTRY_POINTS.len()],
    header: wgpu::Buffer,
    ops: wgpu::Buffer,
    /// Ops `ops` holds.
    capacity: usize,
    /// `bind_groups[k]` rewrites `states[k]`.
    bind_groups: [wgpu::BindGroup; 2],
}

impl InputGpu {
    /// Bytes of its buffers.
    pub(super) fn gpu_bytes(&self) -> u64 {
        self.header.size() + self.ops.size()
    }
}

/// The most ops one dispatch of `apply_inputs` takes: the longest run of one
/// body's ops is one invocation's loop, within lavapipe's 65535 trips with
/// room to spare (ARCHITECTURE.md, Adding a stage, 8).
const INPUT_BATCH: usize = 32_768;

fn check_finite(name: &str, values: &[f32]) -> Result<(), Error> {
    for (k, v) in values.iter().enumerate() {
        if !v.is_finite() {
            let at = if values.len() > 1 { format!("{name}[{k}]") } else { name.to_string() };
            return Err(Error::Input(format!("{at}: must be a finite number, got {v}")));
        }
    }
    Ok(())
}

/// Refuses what `problem` found wrong (scene::position_problem, ...).
fn check_sane(name: &str, problem: Option<String>) -> Result<(), Error> {
    problem.map_or(Ok(()), |why| Err(Error::Input(format!("{name}: {why}"))))
}

fn length(v: [f32; 3]) -> f64 {
    v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt()
}

/// Why an impulse `j` (N s) is absurd, if it is (`limits::MAX_IMPULSE`).
pub(crate) fn impulse_problem(j: [f32; 3]) -> Option<String> {
    use crate::limits::MAX_IMPULSE;
    let size = length(j);
    (size > MAX_IMPULSE as f64).then(|| format!("is {size:.4e} N s; at most {MAX_IMPULSE:e} N s is sane"))
}

/// Why an explosion's `strength` (N s, either sign) is absurd, if it is.
pub(crate) fn strength_problem(strength: f32) -> Option<String> {
    impulse_problem([strength, 0.0, 0.0])
}

/// Why a force `f` (N) is absurd, if it is (`limits::MAX_FORCE`).
pub(crate) fn force_problem(f: [f32; 3]) -> Option<String> {
    use crate::limits::MAX_FORCE;
    let size = length(f);
    (size > MAX_FORCE as f64).then(|| format!("is {size:.4e} N; at most {MAX_FORCE:e} N is sane"))
}

/// Why an explosion's `radius` (m) is absurd, if it is (`limits::MAX_DISTANCE`).
pub(crate) fn radius_problem(radius: f32) -> Option<String> {
    use crate::limits::MAX_DISTANCE;
    (radius > MAX_DISTANCE).then(|| format!("is {radius:e} m; at most {MAX_DISTANCE:e} m is sane"))
}

/// Why an input acting `duration` s before the next step is absurd, if it is:
/// longer than the longest step (`limits::MAX_DT`).
pub(crate) fn duration_problem(duration: f32) -> Option<String> {
    use crate::limits::MAX_DT;
    (duration > MAX_DT).then(|| format!("is {duration:e} s, longer than the longest step ({MAX_DT} s)"))
}

/// Why gusts of strength `gust` on a wind of `velocity` are absurd, if they
/// are: their peak, |velocity| (1 + gust), past `limits::MAX_SPEED`.
pub(crate) fn gust_problem(velocity: [f32; 3], gust: f32) -> Option<String> {
    use crate::limits::MAX_SPEED;
    let peak = length(velocity) * (1.0 + gust as f64);
    (peak > MAX_SPEED as f64)
        .then(|| format!("gusts of {gust:e} blow the wind at up to {peak:.4e} m/s; at most {MAX_SPEED:e} m/s is sane"))
}

/// Why a wind's air density (kg/m^3) is absurd, if it is.
pub(crate) fn air_density_problem(rho: f32) -> Option<String> {
    use crate::limits::MAX_AIR_DENSITY;
    (rho > MAX_AIR_DENSITY).then(|| format!("is {rho:e} kg/m^3; at most {MAX_AIR_DENSITY:e} kg/m^3 is sane"))
}

/// Why a wind's drag coefficient is absurd, if it is.
pub(crate) fn drag_problem(drag: f32) -> Option<String> {
    use crate::limits::MAX_DRAG;
    (drag > MAX_DRAG).then(|| format!("is {drag:e}; at most {MAX_DRAG:e} is sane"))
}

/// Refuses a `duration` (s) that is not finite, negative or too long.
fn check_duration(name: &str, duration: f32) -> Result<(), Error> {
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(Error::Input(format!("{name}: must be a finite number of seconds >= 0, got {duration}")));
    }
    check_sane(name, duration_problem(duration))
}

/// The op of an explosion (see `World::explode`), its arguments checked and
/// named after `at` (`explosions[2].`, or nothing).
fn explosion_op(centre: [f32; 3], strength: f32, radius: f32, falloff: f32, at: &str) -> Result<InputOp, Error> {
    let name = |field: &str| format!("{at}{field}");
    check_finite(&name("centre"), &centre)?;
    check_sane(&name("centre"), crate::scene::position_problem(centre))?;
    check_finite(&name("strength"), &[strength])?;
    check_sane(&name("strength"), strength_problem(strength))?;
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::Input(format!("{}: must be a positive finite number of metres, got {radius}", name("radius"))));
    }
    check_sane(&name("radius"), radius_problem(radius))?;
    if !(falloff.is_finite() && falloff >= 0.0) {
        return Err(Error::Input(format!("{}: must be a finite exponent >= 0, got {falloff}", name("falloff"))));
    }
    Ok(InputOp { a: [centre[0], centre[1], centre[2], strength], b: [radius, falloff, 0.0, 0.0], ..Default::default() })
}

/// Inverse inertia (xyz) and inverse mass (w) of a dynamic body of `shape`
/// and `mass`, worked out as the scene's bodies' are.
fn inverse_props(shape: &crate::Shape, mass: f32) -> [f32; 4] {
    let body = crate::Body { mass, fixed: false, ..crate::Body::new(shape.clone(), [0.0; 3]) };
    let ii = body.inverse_inertia();
    [ii[0], ii[1], ii[2], body.inverse_mass()]
}

impl World {
    /// Applies an impulse (N s) at `point` (world coordinates; `None`: the
    /// centre of mass) before the next step: the velocity changes by J / m,
    /// the spin by I^-1 (r x J) with I in the world frame. No effect on a
    /// fixed body.
    pub fn apply_impulse(&mut self, body: usize, impulse: [f32; 3], point: Option<[f32; 3]>) -> Result<(), Error> {
        let point = point.map_or(Point::Centre, Point::World);
        self.input_ops(&[BodyInput::Impulse { body, impulse, point }], "")
    }

    /// [`World::apply_impulse`] at a point in the body's own frame
    /// (relative to its centre of mass).
    pub fn apply_impulse_local(&mut self, body: usize, impulse: [f32; 3], local_point: [f32; 3]) -> Result<(), Error> {
        self.input_ops(&[BodyInput::Impulse { body, impulse, point: Point::Local(local_point) }], "")
    }

    /// A force (N) acting for `duration` seconds, applied as the impulse
    /// F * duration before the next step (to push over one step, give the
    /// step's dt).
    pub fn apply_force(&mut self, body: usize, force: [f32; 3], point: Option<[f32; 3]>, duration: f32) -> Result<(), Error> {
        check_finite("force", &force)?;
        check_sane("force", force_problem(force))?;
        check_duration("duration", duration)?;
        self.apply_impulse(body, force.map(|f| f * duration), point)
    }

    /// Moves a body to a pose (orientation `[x, y, z, w]`, normalised here),
    /// keeping its velocities. Called before every step on a fixed body, it
    /// drives that body along a path as a kinematic one (a paddle, a door):
    /// the body is static within each step and the solve pushes whatever it
    /// reaches out of it; it carries no velocity of its own into friction
    /// and restitution.
    pub fn set_pose(&mut self, body: usize, position: [f32; 3], orientation: [f32; 4]) -> Result<(), Error> {
        self.input_ops(&[BodyInput::Pose { body, position, orientation }], "")
    }

    /// Sets a body's velocities (m/s and rad/s, world frame): from here it
    /// moves as a body loaded with them does, x + v t + g t^2 / 2 (a
    /// kinematic one x + v t), and `read_state` before the next step shows
    /// v. No effect on a fixed body.
    pub fn set_velocity(&mut self, body: usize, linear: [f32; 3], angular: [f32; 3]) -> Result<(), Error> {
        self.input_ops(&[BodyInput::Velocity { body, linear, angular }], "")
    }

    /// Makes a body immovable (`true`, at rest where it is) or dynamic again
    /// (`false`, at rest, with the mass it had when it was made fixed); see
    /// [`BodyInput::Fixed`] for a body loaded as fixed.
    pub fn set_fixed(&mut self, body: usize, fixed: bool) -> Result<(), Error> {
        self.input_ops(&[BodyInput::Fixed { body, fixed, mass: None }], "")
    }

    /// Makes a body dynamic, at rest, with `mass` (kg) and the inertia of a
    /// solid of its shape; on a body already dynamic, sets its mass and
    /// inertia and keeps its velocities.
    pub fn set_dynamic(&mut self, body: usize, mass: f32) -> Result<(), Error> {
        self.input_ops(&[BodyInput::Fixed { body, fixed: false, mass: Some(mass) }], "")
    }

    /// Applies a batch of inputs in one dispatch, in order within each body.
    /// Nothing is applied if any input is bad; the error names it
    /// (`inputs[2].impulse[1]: ...`).
    pub fn apply_inputs(&mut self, inputs: &[BodyInput]) -> Result<(), Error> {
        self.input_ops(inputs, "inputs")
    }

    /// A radial explosion: every dynamic body whose centre of mass lies
    /// strictly within `radius` (m) of `centre` gets the impulse `strength`
    /// (N s) through its centre, along the direction from `centre` to it
    /// (up for a body exactly at the centre), scaled by
    /// `(1 - d / radius) ^ falloff`: its velocity changes by that over its
    /// mass, its spin not at all. `falloff` 0 is uniform, 1 linear, 2
    /// quadratic. A negative strength pulls inward. Bodies outside the radius
    /// are not touched.
    pub fn explode(&mut self, centre: [f32; 3], strength: f32, radius: f32, falloff: f32) -> Result<(), Error> {
        let op = explosion_op(centre, strength, radius, falloff, "")?;
        self.dispatch_list(&[op], EXPLODE)
    }

    /// Explosions as [`World::explode`] takes them (centre, strength,
    /// radius, falloff), applied in order in one dispatch; nothing is
    /// applied if any is bad, and the error names it (`explosions[2].radius`).
    pub(crate) fn explode_all(&mut self, explosions: &[([f32; 3], f32, f32, f32)]) -> Result<(), Error> {
        let mut ops = Vec::with_capacity(explosions.len());
        for (k, &(centre, strength, radius, falloff)) in explosions.iter().enumerate() {
            ops.push(explosion_op(centre, strength, radius, falloff, &format!("explosions[{k}]."))?);
        }
        self.dispatch_list(&ops, EXPLODE)
    }

    /// Blows `wind` on every dynamic body for `duration` seconds, as an
    /// impulse before the next step: call it before each step with the
    /// step's dt (the wind is taken at the world's current time, gusts
    /// included). The drag is integrated implicitly enough never to push a
    /// body past the wind's own velocity. This is the between-steps form; a
    /// wind that acts within every substep needs `integrate` to add it.
    pub fn apply_wind(&mut self, wind: &Wind, duration: f32) -> Result<(), Error> {
        wind.validate("wind.")?;
        check_duration("duration", duration)?;
        if duration == 0.0 {
            return Ok(()); // blows nothing
        }
        let op = self.wind_op(wind, duration);
        self.dispatch_list(&[op], WIND)
    }

    /// Blows each `(wind, duration)` in order, as [`World::apply_wind`]
    /// does one, in one dispatch (a batch of `INPUT_BATCH` at a time);
    /// nothing is applied if any is bad, and the error names it
    /// (`winds[2].wind.gust`, `winds[2].duration`).
    pub fn apply_winds(&mut self, winds: &[(Wind, f32)]) -> Result<(), Error> {
        for (k, (wind, duration)) in winds.iter().enumerate() {
            wind.validate(&format!("winds[{k}].wind."))?;
            check_duration(&format!("winds[{k}].duration"), *duration)?;
        }
        // a wind of no duration blows nothing (and a drag too large for f32
        // times 0 would be NaN)
        let ops: Vec<InputOp> =
            winds.iter().filter(|(_, d)| *d > 0.0).map(|(wind, duration)| self.wind_op(wind, *duration)).collect();
        self.dispatch_list(&ops, WIND)
    }

    /// The op of a wind at the world's current time (a duration of 0 blows nothing).
    fn wind_op(&self, wind: &Wind, duration: f32) -> InputOp {
        let u = wind.at(self.time);
        InputOp { a: [u[0], u[1], u[2], 0.5 * wind.air_density * wind.drag], b: [duration, 0.0, 0.0, 0.0], ..Default::default() }
    }

    /// Dispatches `kernel` (explode or wind) over a list of its ops, in
    /// batches of at most `INPUT_BATCH`, each one loop of every body's
    /// thread (lavapipe ends an invocation's loops at 65535 trips).
    fn dispatch_list(&mut self, ops: &[InputOp], kernel: usize) -> Result<(), Error> {
        for batch in ops.chunks(INPUT_BATCH) {
            let header = self.input_header(batch.len());
            self.dispatch_input(&header, batch, kernel)?;
        }
        Ok(())
    }

    fn input_header(&self, ops: usize) -> InputHeader {
        let g = self.settings.gravity;
        InputHeader { gravity: g, substep_dt: self.dt_prev, counts: [self.body_count, ops as u32, 0, 0] }
    }

    /// Validates `inputs` (naming bad ones after `list`, or plainly when it
    /// is empty), sorts them into runs per body and dispatches them.
    fn input_ops(&mut self, inputs: &[BodyInput], list: &str) -> Result<(), Error> {
        let mut ops = Vec::with_capacity(inputs.len());
        for (k, input) in inputs.iter().enumerate() {
            let at = |name: &str| if list.is_empty() { name.to_string() } else { format!("{list}[{k}].{name}") };
            let body = input.body();
            if body >= self.body_count as usize {
                return Err(Error::Input(format!("{}: no body {body} (the world has {} bodies)", at("body"), self.body_count)));
            }
            let mut op = InputOp { body: body as u32, ..Default::default() };
            match *input {
                BodyInput::Impulse { impulse, point, .. } => {
                    check_finite(&at("impulse"), &impulse)?;
                    check_sane(&at("impulse"), impulse_problem(impulse))?;
                    op.kind = INPUT_IMPULSE;
                    op.a = [impulse[0], impulse[1], impulse[2], 0.0];
                    let (mode, p) = match point {
                        Point::Centre => (0.0, [0.0; 3]),
                        Point::World(p) => (1.0, p),
                        Point::Local(p) => (2.0, super::records::to_mass_frame(&self.scene.bodies[body], p)),
                    };
                    check_finite(&at("point"), &p)?;
                    check_sane(&at("point"), crate::scene::position_problem(p))?;
                    op.a[3] = mode;
                    op.b = [p[0], p[1], p[2], 0.0];
                }
                BodyInput::Pose { position, orientation, .. } => {
                    check_finite(&at("position"), &position)?;
                    check_sane(&at("position"), crate::scene::position_problem(position))?;
                    check_finite(&at("orientation"), &orientation)?;
                    let q = orientation.map(|v| v as f64);
                    let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
                    if !(norm > 0.0 && norm.is_finite()) {
                        return Err(Error::Input(format!("{}: must be a non-zero quaternion", at("orientation"))));
                    }
                    op.kind = INPUT_POSE;
                    // a hull's pose is kept at its centre of mass, on its principal axes
                    let (pos, rot) = super::records::to_mass_pose(&self.scene.bodies[body], position, q.map(|v| (v / norm) as f32));
                    op.a = [pos[0], pos[1], pos[2], 0.0];
                    op.b = rot;
                }
                BodyInput::Velocity { linear, angular, .. } => {
                    check_finite(&at("linear"), &linear)?;
                    check_sane(&at("linear"), crate::scene::speed_problem(linear))?;
                    check_finite(&at("angular"), &angular)?;
                    let substep = self.settings.dt / self.settings.substeps as f32;
                    if let Some(why) = crate::scene::spin_problem(angular, substep) {
                        return Err(Error::Input(format!("{}: {why}", at("angular"))));
                    }
                    op.kind = INPUT_VELOCITY;
                    op.a = [linear[0], linear[1], linear[2], 0.0];
                    op.b = [angular[0], angular[1], angular[2], 0.0];
                }
                BodyInput::Fixed { fixed, mass, .. } => {
                    let scene = &self.scene.bodies[body];
                    if scene.kinematic {
                        return Err(Error::Input(format!(
                            "{}: body {body} is kinematic: it moves by the velocities set on it (set it to none to hold it still)",
                            at("body")
                        )));
                    }
                    if let Some(m) = mass {
                        // what the scene's own mass is checked by, for the body's shape
                        check_sane(&at("mass"), crate::scene::mass_problem(&scene.shape, m))?;
                    }
                    // for a body loaded fixed (no mass kept on the GPU), the
                    // mass its scene gave it, where its shape can move with it
                    let loaded = if crate::scene::mass_problem(&scene.shape, scene.mass).is_none() { scene.mass } else { 1.0 };
                    op.kind = INPUT_FIXED;
                    op.a = [fixed as u32 as f32, mass.unwrap_or(0.0), loaded, 0.0];
                    // worked out here as the scene's are, so that a body made
                    // fixed and dynamic again gets its own properties back
                    op.b = mass.map_or([0.0; 4], |m| inverse_props(&scene.shape, m));
                    op.c = inverse_props(&scene.shape, loaded);
                }
            }
            ops.push(op);
        }
        // in batches of at most INPUT_BATCH, one after the other: a body's
        // run of ops is one loop of one invocation, and lavapipe ends such a
        // loop at 65535 trips (70 000 impulses on one body gave 65 573 of
        // their worth, unsaid)
        for batch in ops.chunks_mut(INPUT_BATCH) {
            // runs per body, in call order within each (the sort is stable)
            batch.sort_by_key(|op| op.body);
            let mut start = 0;
            while start < batch.len() {
                let end = start + batch[start..].iter().take_while(|op| op.body == batch[start].body).count();
                batch[start].run = (end - start) as u32;
                start = end;
            }
            let header = self.input_header(batch.len());
            self.dispatch_input(&header, batch, APPLY)?;
        }
        Ok(())
    }

    fn dispatch_input(&mut self, header: &InputHeader, ops: &[InputOp], kernel: usize) -> Result<(), Error> {
        if self.body_count == 0 || ops.is_empty() {
            return Ok(());
        }
        self.ensure_input_gpu(ops.len());
        // an input adds energy the bodies' speed limits do not count, and
        // wakes every body
        self.speed_limits = false;
        self.at_rest = false;
        let gpu = self.gpu.clone();
        let input = self.input.as_ref().expect("built above");
        gpu.queue.write_buffer(&input.header, 0, bytemuck::bytes_of(header));
        if !ops.is_empty() {
            gpu.queue.write_buffer(&input.ops, 0, bytemuck::cast_slice(ops));
        }
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("input") });
        {
            let mut pass = encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(ENTRY_POINTS[kernel]), timestamp_writes: None });
            let threads = if kernel == APPLY { ops.len() } else { self.body_count as usize };
            pass.set_bind_group(0, &input.bind_groups[self.current], &[]);
            pass.set_pipeline(&input.pipelines[kernel]);
            pass.dispatch_workgroups((threads as u32).div_ceil(WORKGROUP).max(1), 1, 1);
            // any input wakes every body (each dispatch sees the last one's writes)
            pass.set_pipeline(&input.pipelines[WAKE_ALL]);
            pass.dispatch_workgroups(self.body_count.div_ceil(WORKGROUP).max(1), 1, 1);
        }
        gpu.submit(encoder.finish());
        gpu.check()?;
        Ok(())
    }

    /// Builds the input kernels on first use, and grows the op list to hold
    /// `ops` (rebuilding the bind groups).
    fn ensure_input_gpu(&mut self, ops: usize) {
        let device = &self.gpu.device;
        let op_size = std::mem::size_of::<InputOp>();
        let ops_buffer = |capacity: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("input/ops"),
                size: (capacity * op_size) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let props = &self.data.props;
        debug_assert_eq!(props.size(), (self.body_count.max(1) as u64 * 64).max(64));
        let states = &self.data.states;
        let bind_groups = |layout: &wgpu::BindGroupLayout, header: &wgpu::Buffer, list: &wgpu::Buffer| {
            [0, 1].map(|k| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(if k == 0 { "input A" } else { "input B" }),
                    layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: BIND_STATE, resource: states[k].as_entire_binding() },
                        wgpu::BindGroupEntry { binding: BIND_HEADER, resource: header.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: BIND_OPS, resource: list.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: BIND_PROPS, resource: props.as_entire_binding() },
                    ],
                })
            })
        };
        match &mut self.input {
            Some(input) => {
                if input.capacity < ops {
                    let capacity = ops.next_power_of_two();
                    input.ops = ops_buffer(capacity);
                    input.capacity = capacity;
                    input.bind_groups = bind_groups(&input.layout, &input.header, &input.ops);
                }
            }
            None => {
                let entry = |binding: u32, ty: wgpu::BufferBindingType| wgpu::BindGroupLayoutEntry {
                    binding,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
                    count: None,
                };
                let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
                // the device's own, so that its kernels are found compiled
                let layout = self.gpu.bind_group_layout(
                    "input",
                    &[
                        entry(BIND_STATE, storage(false)),
                        entry(BIND_HEADER, wgpu::BufferBindingType::Uniform),
                        entry(BIND_OPS, storage(true)),
                        entry(BIND_PROPS, storage(false)),
                    ],
                );
                let pipelines = self.gpu.compute_pipelines("input", &source(), &ENTRY_POINTS, Some(&[&layout]), &[]);
                let header = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("input/header"),
                    size: std::mem::size_of::<InputHeader>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let capacity = ops.next_power_of_two().max(64);
                let list = ops_buffer(capacity);
                let groups = bind_groups(&layout, &header, &list);
                self.input = Some(InputGpu {
                    pipelines: pipelines.try_into().expect("a pipeline per entry point"),
                    layout,
                    header,
                    ops: list,
                    capacity,
                    bind_groups: groups,
                });
            }
        }
    }
}
