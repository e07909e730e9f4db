//! Scene files: the types a simulation starts from, loading them from JSON,
//! checking them, their mass properties, and writing them back as JSON.
//!
//! The file format is the contract in `INTERFACE.md`, section 1. Units are SI
//! (metres, seconds, kilograms, radians unless a name says degrees),
//! right-handed with +Y up, and quaternions are `[x, y, z, w]`.
//!
//! Loading happens in three steps:
//!
//! 1. JSON is parsed into private "raw" structs that mirror the file exactly
//!    and refuse unknown fields. `serde_path_to_error` tells which field a
//!    parse error belongs to.
//! 2. The raw structs are turned into [`Scene`]: defaults are filled in,
//!    required fields are checked to be present, array lengths are checked,
//!    the mass is resolved from `density` or `mass`, and orientations are
//!    normalised.
//! 3. [`Scene::validate`] checks every value (finite numbers, positive sizes,
//!    parameter ranges, joint indices). It is public so that scenes built in
//!    Rust get the same checks.
//!
//! Every error names the offending field in the form
//! `bodies[3].shape.half_extents[1]`, says why it is wrong, and fits on one
//! line. No input makes this module panic.

use std::fmt::Write as _;
use std::path::Path;

use serde::Deserialize;

/// Density used when a body gives neither `density` nor `mass`: 1000 kg/m³,
/// the density of water, so a 1 m cube weighs a tonne.
pub const DEFAULT_DENSITY: f32 = 1000.0;

/// The joint body index that stands for the static world.
pub const WORLD: i32 = -1;

/// Identity rotation, `[x, y, z, w]`.
pub(crate) const IDENTITY_ORIENTATION: [f32; 4] = [0.0, 0.0, 0.0, 1.0];

/// The most relaxation iterations a step may ask for.
pub const MAX_ITERATIONS: u32 = 256;

/// The most substeps a step may ask for.
pub const MAX_SUBSTEPS: u32 = 64;

/// The sweeps a substep takes when the solver picks the substeps
/// ([`Settings::substeps_for`]). The Jacobi sweeps carry a stack's support
/// up one body a sweep, and their Chebyshev weights grow within a
/// substep, so a substep needs a few of its own: a 20-row pyramid placed
/// imperfectly falls with four substeps of two, and Box3D's
/// `large_pyramid` at the suggested 8 sweeps creeps less in two of four
/// than in 3 + 3 + 2, for a substep's passes less (docs/decisions/contacts.md,
/// "The suggested 8 sweeps, split otherwise").
pub const SWEEPS_PER_SUBSTEP: u32 = 4;

/// Camera vertical field of view (radians) used when a `camera` block gives
/// no `fov_y`: 45 degrees, a natural-looking lens that neither distorts nor
/// flattens much.
pub const DEFAULT_FOV_Y: f32 = std::f32::consts::FRAC_PI_4;

/// A quaternion whose length is below this is refused: it has no direction
/// to normalise to.
const MIN_ORIENTATION_NORM: f64 = 1e-6;

// ---------------------------------------------------------------------------
// Public types
// ---------------------------------------------------------------------------

/// A whole scene: global settings, an optional ground plane, the bodies, the
/// joints between them and an optional camera.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// Global simulation parameters.
    pub settings: Settings,
    /// The ground plane, if any.
    pub ground: Option<Ground>,
    /// The rigid bodies. Joints refer to them by index in this list.
    pub bodies: Vec<Body>,
    /// Ball joints between bodies, or between a body and the world.
    pub joints: Vec<Joint>,
    /// Where to look from when rendering frames (extension to the contract).
    /// `None` lets the renderer choose a camera that frames the scene.
    pub camera: Option<Camera>,
}

/// Global simulation parameters: the `settings` block. Every field is
/// optional in the file; [`Settings::default`] gives the values used for
/// missing ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Time step in seconds. Must be finite and > 0.
    pub dt: f32,
    /// Gravitational acceleration in m/s², world frame.
    pub gravity: [f32; 3],
    /// Relaxation iterations of the constraint solver per step, 1..=256: the
    /// sweeps a step runs in all, spread over its substeps as evenly as they
    /// go (the first substeps take one more where they do not divide), at
    /// least one a substep ([`Settings::sweeps`]).
    pub iterations: u32,
    /// The paper's relaxation coefficient c_r: the fraction of each
    /// constraint error corrected per iteration, in (0, 1].
    pub relaxation: f32,
    /// The paper's β for linear motion: the fraction of linear velocity lost
    /// per step, in [0, 1).
    pub linear_damping: f32,
    /// The paper's β for angular motion: the fraction of angular velocity
    /// lost per step, in [0, 1).
    pub angular_damping: f32,
    /// Coefficient of restitution for contacts, in [0, 1]. Bodies may
    /// override it.
    pub restitution: f32,
    /// Coulomb friction coefficient for contacts, >= 0. Bodies may override
    /// it.
    pub friction: f32,
    /// Substeps per step (extension to the contract): each step of `dt` is
    /// taken as `substeps` steps of `dt / substeps`. 1..=64, default 3. A
    /// scene file that gives `iterations` and no `substeps` gets
    /// [`Settings::substeps_for`] its iterations.
    pub substeps: u32,
    /// Whether bodies at rest sleep (extension to the contract), default
    /// true: a body slower than 5 cm/s at every point for `SLEEP_AFTER`
    /// seconds while touching something (faster moments below 20 cm/s, off
    /// a joint, take that time back rather than all of it: jitter in place
    /// does not keep a body awake) is held still until an awake body
    /// touching it moves faster than 20 cm/s or lies more than 1 cm inside
    /// it, or any input or edit wakes all. The paper has no sleeping and
    /// lists that as a weakness.
    pub sleeping: bool,
}

impl Settings {
    /// The substeps a step of `iterations` sweeps takes when the scene does
    /// not say: `SWEEPS_PER_SUBSTEP` sweeps each, rounded up, within
    /// 1..=`MAX_SUBSTEPS` (the contract's suggested 8 take two substeps of
    /// 4 sweeps; the default 9 three of 3).
    pub fn substeps_for(iterations: u32) -> u32 {
        iterations.div_ceil(SWEEPS_PER_SUBSTEP).clamp(1, MAX_SUBSTEPS)
    }

    /// The relaxation sweeps of substep `substep` (from 0): `iterations`
    /// spread over the substeps, the first ones taking one more where they
    /// do not divide, and at least one each (a substep without a sweep
    /// would leave its contacts unresolved).
    pub fn sweeps(&self, substep: u32) -> u32 {
        let substeps = self.substeps.max(1);
        (self.iterations / substeps + u32::from(substep < self.iterations % substeps)).max(1)
    }

    /// The sweeps a whole step runs: `iterations`, or `substeps` where
    /// there are more substeps than iterations.
    pub fn sweeps_per_step(&self) -> u32 {
        self.iterations.max(self.substeps)
    }
}

/// Seconds at rest before a body sleeps (Box2D's time to sleep).
pub const SLEEP_AFTER: f32 = 0.5;

impl Default for Settings {
    /// The values shown in `INTERFACE.md`:
    ///
    /// - `dt` 1/60 s: one step per frame of a 60 Hz display.
    /// - `gravity` [0, -9.81, 0] m/s²: Earth's, with +Y up.
    /// - `iterations` 9 in `substeps` 3: nine solver sweeps per step, about
    ///   the contract's suggested 8, spent as three substeps of three
    ///   (Macklin et al. 2019, "Small Steps"): gravity's push per substep is
    ///   a ninth, and contacts are found once per step, so the cost is about
    ///   that of 8 sweeps in one substep.
    /// - `relaxation` 0.5: corrects half of each error per sweep, which
    ///   converges steadily without overshooting when constraints fight.
    ///   Measured on piles placed imperfectly (every box shifted up to 1 cm
    ///   and turned up to 1 degree), 10 s at 60 Hz: no box of a 20-row
    ///   pyramid moves more than 3.9 cm with 3 x 3, 5.6 m with 4 x 2, and
    ///   it collapses with 2 x 4; c_r 0.65 made a perfect 10-row pyramid
    ///   creep 4.5 cm (1.1 cm at 0.5).
    /// - dampings 0: no energy is removed unless a scene asks for it.
    /// - `restitution` 0.2: contacts bounce a little, as wood or plastic do.
    /// - `friction` 0.5: a common everyday value (wood on wood).
    /// - `sleeping` on: Jacobi sweeps converge slowly through a pile several
    ///   bodies deep, and what they leave over creeps (1000 cubes dropped
    ///   in four layers: a quarter still move 1 cm a second after 15 s with
    ///   sleeping off, none with it on). Box2D, rapier and PhysX sleep too.
    fn default() -> Self {
        Settings {
            dt: 1.0 / 60.0,
            gravity: [0.0, -9.81, 0.0],
            iterations: 9,
            relaxation: 0.5,
            linear_damping: 0.0,
            angular_damping: 0.0,
            restitution: 0.2,
            friction: 0.5,
            substeps: 3,
            sleeping: true,
        }
    }
}

/// An infinite static plane `y = height` with normal +Y.
#[derive(Clone, Debug, PartialEq)]
pub struct Ground {
    /// Height of the plane in metres.
    pub height: f32,
}

/// The collision and mass shape of a body, in the body's local frame and
/// centred on its centre of mass.
///
/// In JSON: `{"type": "box", "half_extents": [x, y, z]}`,
/// `{"type": "sphere", "radius": r}` or
/// `{"type": "capsule", "radius": r, "half_height": h}`.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A box with the given half extents in metres (all > 0).
    Box { half_extents: [f32; 3] },
    /// A sphere with the given radius in metres (> 0).
    Sphere { radius: f32 },
    /// The segment from (0, -half_height, 0) to (0, half_height, 0) swept by
    /// `radius` (metres, both > 0): a cylinder capped by two half spheres.
    Capsule { radius: f32, half_height: f32 },
    /// The convex hull of 4 to 64 points in the body's frame (see
    /// [`HullShape`]).
    Hull(HullShape),
}

/// A hull shape: the points as given, and the hull they make with its mass
/// properties (worked out once, as the shape is made).
#[derive(Clone, Debug, PartialEq)]
pub struct HullShape {
    points: Vec<[f32; 3]>,
    hull: std::sync::Arc<hull::Hull>,
    /// Its principal moments per unit density and the turn from its
    /// principal axes to the body's frame (`hull::Hull::principal`).
    principal: ([f64; 3], glam::DQuat),
}

impl HullShape {
    /// The hull of `points`, or why they make none (see [`hull::Hull::new`]).
    pub fn new(points: Vec<[f32; 3]>) -> Result<HullShape, String> {
        let hull = hull::Hull::new(&points)?;
        let principal = hull.principal();
        Ok(HullShape { points, hull: std::sync::Arc::new(hull), principal })
    }

    /// The points as given.
    pub fn points(&self) -> &[[f32; 3]] {
        &self.points
    }

    /// The hull: its corners, faces and mass properties, in the body's frame.
    pub fn hull_arc(&self) -> std::sync::Arc<hull::Hull> {
        self.hull.clone()
    }

    pub fn hull(&self) -> &hull::Hull {
        &self.hull
    }
}

impl Shape {
    /// Volume in m³.
    pub fn volume(&self) -> f32 {
        self.volume_f64() as f32
    }

    fn volume_f64(&self) -> f64 {
        match *self {
            Shape::Box { half_extents: [a, b, c] } => 8.0 * a as f64 * b as f64 * c as f64,
            Shape::Sphere { radius } => {
                let r = radius as f64;
                4.0 / 3.0 * std::f64::consts::PI * r * r * r
            }
            Shape::Capsule { radius, half_height } => {
                let (r, h) = (radius as f64, half_height as f64);
                std::f64::consts::PI * r * r * (2.0 * h + 4.0 / 3.0 * r)
            }
            Shape::Hull(ref shape) => shape.hull.volume,
        }
    }

    /// Radius in metres of the smallest sphere around the centre that holds
    /// the shape.
    pub fn bounding_radius(&self) -> f32 {
        match *self {
            Shape::Box { half_extents: [a, b, c] } => {
                let (a, b, c) = (a as f64, b as f64, c as f64);
                (a * a + b * b + c * c).sqrt() as f32
            }
            Shape::Sphere { radius } => radius,
            Shape::Capsule { radius, half_height } => radius + half_height,
            // about the centre of mass, where the body's pose is kept
            Shape::Hull(ref shape) => shape.hull.radius_about(shape.hull.centroid) as f32,
        }
    }

    /// Principal moments of inertia (kg·m²) of a solid shape of mass `mass`,
    /// in the body frame, computed in f64.
    pub(crate) fn inertia_f64(&self, mass: f32) -> [f64; 3] {
        let m = mass as f64;
        match *self {
            Shape::Box { half_extents: [a, b, c] } => {
                let (a2, b2, c2) = ((a as f64).powi(2), (b as f64).powi(2), (c as f64).powi(2));
                [m / 3.0 * (b2 + c2), m / 3.0 * (a2 + c2), m / 3.0 * (a2 + b2)]
            }
            Shape::Sphere { radius } => {
                let i = 0.4 * m * (radius as f64).powi(2);
                [i, i, i]
            }
            Shape::Capsule { radius, half_height } => {
                // the cylinder, and the two caps as one ball whose halves sit
                // half_height from the centre (their centroids 3r/8 further)
                let (r, h) = (radius as f64, half_height as f64);
                let cylinder = 2.0 * h;
                let ball = 4.0 / 3.0 * r;
                let (mc, ms) = (m * cylinder / (cylinder + ball), m * ball / (cylinder + ball));
                let across = mc * (r * r / 4.0 + h * h / 3.0) + ms * (0.4 * r * r + h * h + 0.75 * h * r);
                let along = mc * r * r / 2.0 + ms * 0.4 * r * r;
                [across, along, across]
            }
            // about its principal axes (see `HullShape`), at the density of `mass`
            Shape::Hull(ref shape) => shape.principal.0.map(|i| i * m / shape.hull.volume),
        }
    }
}

/// One rigid body.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Shape, centred on the body's centre of mass.
    pub shape: Shape,
    /// Position of the centre of mass in metres, world frame.
    pub position: [f32; 3],
    /// Rotation from body to world frame, `[x, y, z, w]`. Loading normalises
    /// it; scenes built in Rust should give a unit quaternion.
    pub orientation: [f32; 4],
    /// Initial velocity of the centre of mass in m/s, world frame.
    pub linear_velocity: [f32; 3],
    /// Initial angular velocity in rad/s, world frame.
    pub angular_velocity: [f32; 3],
    /// Mass in kg: the file's `mass`, or its `density` (default 1000 kg/m³)
    /// times the shape's volume. Fixed bodies keep the resolved value too;
    /// [`Body::inverse_mass`] is what makes them immovable.
    pub mass: f32,
    /// An immovable body (infinite mass): its inverse mass and inverse
    /// inertia are zero.
    pub fixed: bool,
    /// A body that moves by its own velocities alone (`linear_velocity`,
    /// `angular_velocity`, or what inputs set), as if of infinite mass:
    /// gravity, contacts and joints never move it, and it pushes what it
    /// meets, friction included. Not also `fixed`.
    pub kinematic: bool,
    /// Overrides [`Settings::restitution`] for contacts of this body.
    pub restitution: Option<f32>,
    /// Overrides [`Settings::friction`] for contacts of this body.
    pub friction: Option<f32>,
}

impl Body {
    /// A movable body at rest with identity orientation and the default
    /// density of 1000 kg/m³.
    pub fn new(shape: Shape, position: [f32; 3]) -> Body {
        let mass = (DEFAULT_DENSITY as f64 * shape.volume_f64()) as f32;
        Body {
            shape,
            position,
            orientation: IDENTITY_ORIENTATION,
            linear_velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            mass,
            fixed: false,
            kinematic: false,
            restitution: None,
            friction: None,
        }
    }

    /// Where the simulation keeps the body's pose, in the body's own frame:
    /// a hull's centre of mass and the turn from its principal axes to the
    /// frame (the GPU holds one diagonal inertia a body). None where it is
    /// the frame itself: the other shapes, and a kinematic body, which
    /// turns about its frame's origin.
    pub fn mass_frame(&self) -> Option<(glam::DVec3, glam::DQuat)> {
        match &self.shape {
            Shape::Hull(h) if !self.kinematic => Some((h.hull.centroid, h.principal.1)),
            _ => None,
        }
    }

    /// Whether contacts, joints and gravity move the body: neither fixed
    /// nor kinematic.
    pub fn is_dynamic(&self) -> bool {
        !self.fixed && !self.kinematic
    }

    /// 1 / mass in 1/kg; 0 for a fixed or kinematic body.
    pub fn inverse_mass(&self) -> f32 {
        if !self.is_dynamic() {
            0.0
        } else {
            (1.0 / self.mass as f64) as f32
        }
    }

    /// Inverse principal moments of inertia in 1/(kg·m²), in the body frame
    /// (the diagonal of the inverse inertia tensor); zeros for a fixed or
    /// kinematic body.
    ///
    /// Solid box with half extents a, b, c: I = m/3 · (b² + c², a² + c²,
    /// a² + b²). Solid sphere: I = 2/5 · m · r² about every axis.
    pub fn inverse_inertia(&self) -> [f32; 3] {
        if !self.is_dynamic() {
            return [0.0; 3];
        }
        let i = self.shape.inertia_f64(self.mass);
        [(1.0 / i[0]) as f32, (1.0 / i[1]) as f32, (1.0 / i[2]) as f32]
    }

    /// Radius in metres of the smallest sphere around the centre of mass
    /// that holds the body.
    pub fn bounding_radius(&self) -> f32 {
        self.shape.bounding_radius()
    }
}

/// A ball joint: pins `anchors[0]` of `bodies[0]` to `anchors[1]` of
/// `bodies[1]`.
///
/// In JSON: `{"type": "ball", "bodies": [a, b], "anchors": [[..], [..]]}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Indices into [`Scene::bodies`]; [`WORLD`] (-1) stands for the world.
    /// The two must differ and at most one may be the world.
    pub bodies: [i32; 2],
    /// Anchor points in metres: in the body's local frame, or in world
    /// coordinates for the world side.
    pub anchors: [[f32; 3]; 2],
}

/// A fixed camera for rendering frames (extension to the contract).
///
/// In JSON: `{"position": [..], "target": [..], "fov_y": 0.785}`, where
/// `fov_y` (radians, like every angle of the contract) is optional.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position in metres, world frame.
    pub position: [f32; 3],
    /// The point looked at, world frame. Must differ from `position`.
    pub target: [f32; 3],
    /// Vertical field of view in radians, in (0, pi); default `DEFAULT_FOV_Y`.
    pub fov_y: f32,
}

/// Why a scene could not be loaded: the error type it shares with input
/// tracks (`crate::load_error`).
pub type SceneError = crate::load_error::LoadError;

pub mod hull;
mod load;
#[cfg(test)]
mod tests;
mod validate;
mod write;

use load::*;
use validate::*;

pub(crate) use validate::{
    check_sink, mass_problem, position_problem, speed_problem, spin_problem, step_dt_problem, validate_body, validate_joint,
};
