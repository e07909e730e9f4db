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
use std::path::{Path, PathBuf};

use serde::Deserialize;

/// Density used when a body gives neither `density` nor `mass`: 1000 kg/m³,
/// the density of water, so a 1 m cube weighs a tonne.
pub const DEFAULT_DENSITY: f32 = 1000.0;

/// The joint body index that stands for the static world.
pub const WORLD: i32 = -1;

/// Identity rotation, `[x, y, z, w]`.
pub const IDENTITY_ORIENTATION: [f32; 4] = [0.0, 0.0, 0.0, 1.0];

/// The most relaxation iterations a step may ask for.
pub const MAX_ITERATIONS: u32 = 256;

/// The most substeps a step may ask for.
pub const MAX_SUBSTEPS: u32 = 64;

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
    /// Relaxation iterations of the constraint solver per step, 1..=256.
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
    /// taken as `substeps` steps of `dt / substeps`. 1..=64, default 3.
    pub substeps: u32,
    /// Whether bodies at rest sleep (extension to the contract), default
    /// true: a body slower than 5 cm/s at every point for `SLEEP_AFTER`
    /// seconds while touching something is held still until an awake body
    /// touching it moves faster than 20 cm/s or lies more than 1 cm inside
    /// it, or any input or edit wakes all. The paper has no sleeping and
    /// lists that as a weakness.
    pub sleeping: bool,
}

/// Seconds at rest before a body sleeps (Box2D's time to sleep).
pub const SLEEP_AFTER: f32 = 0.5;

impl Default for Settings {
    /// The values shown in `INTERFACE.md`:
    ///
    /// - `dt` 1/60 s: one step per frame of a 60 Hz display.
    /// - `gravity` [0, -9.81, 0] m/s²: Earth's, with +Y up.
    /// - `iterations` 3 with `substeps` 3: nine solver sweeps per step, about
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
            iterations: 3,
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
/// In JSON: `{"type": "box", "half_extents": [x, y, z]}` or
/// `{"type": "sphere", "radius": r}`.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A box with the given half extents in metres (all > 0).
    Box { half_extents: [f32; 3] },
    /// A sphere with the given radius in metres (> 0).
    Sphere { radius: f32 },
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
        }
    }

    /// Principal moments of inertia (kg·m²) of a solid shape of mass `mass`,
    /// in the body frame, computed in f64.
    fn inertia_f64(&self, mass: f32) -> [f64; 3] {
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
            restitution: None,
            friction: None,
        }
    }

    /// 1 / mass in 1/kg; 0 for a fixed body.
    pub fn inverse_mass(&self) -> f32 {
        if self.fixed {
            0.0
        } else {
            (1.0 / self.mass as f64) as f32
        }
    }

    /// Inverse principal moments of inertia in 1/(kg·m²), in the body frame
    /// (the diagonal of the inverse inertia tensor); zeros for a fixed body.
    ///
    /// Solid box with half extents a, b, c: I = m/3 · (b² + c², a² + c²,
    /// a² + b²). Solid sphere: I = 2/5 · m · r² about every axis.
    pub fn inverse_inertia(&self) -> [f32; 3] {
        if self.fixed {
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

/// Why a scene could not be loaded. The message fits on one line: the
/// offending field's path, then why.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read (missing, unreadable, not UTF-8).
    #[error("{}: cannot read scene file: {}", one_line(&.path.display().to_string()), one_line(&.error.to_string()))]
    Io {
        /// The file that was being read.
        path: PathBuf,
        /// What went wrong.
        error: std::io::Error,
    },
    /// The text is not valid JSON.
    #[error("line {line}, column {column}: malformed JSON: {message}")]
    Syntax {
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error (0 when the text is empty).
        column: usize,
        /// What the parser expected, and in which field if known.
        message: String,
    },
    /// A field is unknown, missing, of the wrong type or has a bad value.
    #[error("{field}: {message}")]
    Invalid {
        /// Path of the field, e.g. `bodies[3].shape.half_extents[1]`.
        field: String,
        /// Why it is refused, including the offending value.
        message: String,
    },
}

impl SceneError {
    /// The path of the offending field, when the error has one.
    pub fn field(&self) -> Option<&str> {
        match self {
            SceneError::Invalid { field, .. } => Some(field),
            _ => None,
        }
    }

    fn invalid(field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid { field: field.into(), message: message.into() }
    }

    fn missing(field: impl Into<String>) -> SceneError {
        SceneError::invalid(field, "is required but missing")
    }
}

// ---------------------------------------------------------------------------
// Loading
// ---------------------------------------------------------------------------

impl Scene {
    /// Parses and validates a scene from JSON text.
    pub fn from_json_str(text: &str) -> Result<Scene, SceneError> {
        if let Some((line, column, message)) = text_problem(text) {
            return Err(SceneError::Syntax { line, column, message });
        }
        let mut deserializer = serde_json::Deserializer::from_str(text);
        let Obj(raw): Obj<RawScene> = serde_path_to_error::deserialize(&mut deserializer)
            .map_err(|error| json_error(path_string(error.path()), error.into_inner()))?;
        // Refuse anything after the scene object, as serde_json::from_str does.
        deserializer.end().map_err(|error| json_error(None, error))?;
        let scene = raw.into_scene()?;
        scene.validate()?;
        Ok(scene)
    }

    /// Reads, parses and validates a scene file.
    pub fn from_path(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|error| SceneError::Io { path: path.to_path_buf(), error })?;
        Scene::from_json_str(&text)
    }
}

/// What is wrong with JSON text that serde_json would report obscurely: a
/// UTF-8 byte-order mark, or no text at all. (line, column, message).
pub(crate) fn text_problem(text: &str) -> Option<(usize, usize, String)> {
    if text.starts_with('\u{feff}') {
        let message = "the text starts with a byte-order mark (U+FEFF), which JSON does not allow: save it as UTF-8 without one";
        return Some((1, 1, message.into()));
    }
    if text.trim().is_empty() {
        // where serde_json stops, in its words, and why
        let (line, column) = (text.matches('\n').count() + 1, text.rsplit('\n').next().map_or(0, |l| l.chars().count()));
        return Some((line, column, "EOF while parsing a value: the text is empty (or only blanks); expected an object".into()));
    }
    None
}

/// Turns a serde_json error, and the path of the field it happened in (as
/// tracked by serde_path_to_error), into a [`SceneError`].
fn json_error(field: Option<String>, inner: serde_json::Error) -> SceneError {
    match classify_json_error(field, inner, "scene") {
        JsonFault::Invalid { field, message } => SceneError::Invalid { field, message },
        JsonFault::Syntax { line, column, message } => SceneError::Syntax { line, column, message },
    }
}

/// A serde_json error as the JSON loaders (scenes, input tracks) report it.
pub(crate) enum JsonFault {
    /// A field is unknown, of the wrong type, or a number beyond any float.
    Invalid { field: String, message: String },
    /// The text is not JSON.
    Syntax { line: usize, column: usize, message: String },
}

/// Classifies a serde_json error raised in `field` (None: the top level,
/// named `top` in the message).
pub(crate) fn classify_json_error(field: Option<String>, inner: serde_json::Error, top: &str) -> JsonFault {
    let (line, column) = (inner.line(), inner.column());
    // serde_json's message ends with " at line L column C"; we place the
    // position ourselves.
    let full = inner.to_string();
    let suffix = format!(" at line {line} column {column}");
    let message = one_line(full.strip_suffix(&suffix).unwrap_or(&full));

    use serde_json::error::Category;
    let number_out_of_range = message.starts_with("number out of range");
    match (inner.classify(), field) {
        // A number too large for any float (like 1e999) is valid JSON
        // grammar but not a usable value: blame the field it is in.
        (Category::Syntax, Some(field)) if number_out_of_range => {
            JsonFault::Invalid { field, message: format!("number out of range, must be finite (line {line}, column {column})") }
        }
        // Unknown field, wrong type, out-of-range integer, ...
        (Category::Data, field) => JsonFault::Invalid {
            field: field.unwrap_or_else(|| top.to_string()),
            message: format!("{message} (line {line}, column {column})"),
        },
        (Category::Syntax | Category::Eof | Category::Io, field) => JsonFault::Syntax {
            line,
            column,
            message: match field {
                Some(field) => format!("{message} (in {field})"),
                None => message,
            },
        },
    }
}

/// Writes a serde_path_to_error path as `bodies[3].shape.half_extents[1]`;
/// `None` for the top level.
pub(crate) fn path_string(path: &serde_path_to_error::Path) -> Option<String> {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for segment in path.iter() {
        match segment {
            Segment::Seq { index } => {
                let _ = write!(out, "[{index}]");
            }
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(&one_line(key));
            }
            // A map key not read yet (say, a syntax error right after a
            // comma): the enclosing path is all there is to say.
            Segment::Unknown => {}
        }
    }
    if out.is_empty() {
        None
    } else {
        Some(out)
    }
}

/// Escapes control characters (newlines in a field name, say) so that an
/// error message stays on one line.
pub(crate) fn one_line(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

// The raw file representation. Required fields are `Option` too, so that
// "missing" errors can name the field itself rather than its parent, and
// fixed-size arrays are `Vec` so that a wrong length gets a clear message.
// As serde does for `Option`, `null` counts as absent: the contract says so
// for `ground`, and it is the same everywhere.

/// Deserializes `T` from a JSON object only. Serde's derived structs also
/// accept an array of field values in declaration order, which a scene file
/// never means; this refuses it with "expected a JSON object".
pub(crate) struct Obj<T>(pub(crate) T);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Obj<T> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ObjectVisitor<T>(std::marker::PhantomData<T>);

        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for ObjectVisitor<T> {
            type Value = T;

            fn expecting(&self, formatter: &mut std::fmt::Formatter) -> std::fmt::Result {
                formatter.write_str("a JSON object")
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
                T::deserialize(serde::de::value::MapAccessDeserializer::new(map))
            }
        }

        deserializer.deserialize_map(ObjectVisitor(std::marker::PhantomData)).map(Obj)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    settings: Option<Obj<RawSettings>>,
    ground: Option<Obj<RawGround>>,
    bodies: Option<Vec<Obj<RawBody>>>,
    joints: Option<Vec<Obj<RawJoint>>>,
    camera: Option<Obj<RawCamera>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    dt: Option<f32>,
    gravity: Option<Vec<f32>>,
    iterations: Option<u32>,
    relaxation: Option<f32>,
    linear_damping: Option<f32>,
    angular_damping: Option<f32>,
    restitution: Option<f32>,
    friction: Option<f32>,
    substeps: Option<u32>,
    sleeping: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGround {
    height: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBody {
    shape: Option<Obj<RawShape>>,
    position: Option<Vec<f32>>,
    orientation: Option<Vec<f32>>,
    linear_velocity: Option<Vec<f32>>,
    angular_velocity: Option<Vec<f32>>,
    density: Option<f32>,
    mass: Option<f32>,
    fixed: Option<bool>,
    restitution: Option<f32>,
    friction: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShape {
    #[serde(rename = "type")]
    kind: Option<String>,
    half_extents: Option<Vec<f32>>,
    radius: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJoint {
    #[serde(rename = "type")]
    kind: Option<String>,
    bodies: Option<Vec<i32>>,
    anchors: Option<Vec<Vec<f32>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    position: Option<Vec<f32>>,
    target: Option<Vec<f32>>,
    fov_y: Option<f32>,
}

impl RawScene {
    fn into_scene(self) -> Result<Scene, SceneError> {
        let settings = match self.settings {
            Some(Obj(raw)) => raw.into_settings()?,
            None => Settings::default(),
        };
        let ground = match self.ground {
            Some(Obj(raw)) => Some(Ground { height: raw.height.ok_or_else(|| SceneError::missing("ground.height"))? }),
            None => None,
        };
        let bodies = self
            .bodies
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(i, Obj(raw))| raw.into_body(&format!("bodies[{i}]")))
            .collect::<Result<Vec<_>, _>>()?;
        let joints = self
            .joints
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(i, Obj(raw))| raw.into_joint(&format!("joints[{i}]")))
            .collect::<Result<Vec<_>, _>>()?;
        let camera = match self.camera {
            Some(Obj(raw)) => Some(raw.into_camera()?),
            None => None,
        };
        Ok(Scene { settings, ground, bodies, joints, camera })
    }
}

impl RawSettings {
    fn into_settings(self) -> Result<Settings, SceneError> {
        let d = Settings::default();
        Ok(Settings {
            dt: self.dt.unwrap_or(d.dt),
            gravity: match self.gravity {
                Some(v) => exact(v, "settings.gravity")?,
                None => d.gravity,
            },
            iterations: self.iterations.unwrap_or(d.iterations),
            relaxation: self.relaxation.unwrap_or(d.relaxation),
            linear_damping: self.linear_damping.unwrap_or(d.linear_damping),
            angular_damping: self.angular_damping.unwrap_or(d.angular_damping),
            restitution: self.restitution.unwrap_or(d.restitution),
            friction: self.friction.unwrap_or(d.friction),
            substeps: self.substeps.unwrap_or(d.substeps),
            sleeping: self.sleeping.unwrap_or(d.sleeping),
        })
    }
}

impl RawBody {
    fn into_body(self, path: &str) -> Result<Body, SceneError> {
        let shape_path = format!("{path}.shape");
        let shape = self.shape.ok_or_else(|| SceneError::missing(&shape_path))?.0.into_shape(&shape_path)?;

        let position_path = format!("{path}.position");
        let position = exact(self.position.ok_or_else(|| SceneError::missing(&position_path))?, &position_path)?;

        let orientation = match self.orientation {
            Some(v) => {
                let q_path = format!("{path}.orientation");
                let q = exact(v, &q_path)?;
                check_orientation(q, &q_path)?;
                normalise(q)
            }
            None => IDENTITY_ORIENTATION,
        };

        let mass = match (self.density, self.mass) {
            (Some(density), Some(mass)) => {
                return Err(SceneError::invalid(
                    format!("{path}.mass"),
                    format!("give either density or mass, not both (got mass {} and density {})", show(mass), show(density)),
                ))
            }
            (None, Some(mass)) => mass,
            (density, None) => {
                let density_path = format!("{path}.density");
                let density = density.unwrap_or(DEFAULT_DENSITY);
                check_positive(density, &density_path)?;
                check_shape(&shape, &shape_path)?;
                mass_from_density(density, &shape, &density_path)?
            }
        };

        Ok(Body {
            shape,
            position,
            orientation,
            linear_velocity: optional_vec3(self.linear_velocity, &format!("{path}.linear_velocity"))?,
            angular_velocity: optional_vec3(self.angular_velocity, &format!("{path}.angular_velocity"))?,
            mass,
            fixed: self.fixed.unwrap_or(false),
            restitution: self.restitution,
            friction: self.friction,
        })
    }
}

impl RawShape {
    fn into_shape(self, path: &str) -> Result<Shape, SceneError> {
        let type_path = format!("{path}.type");
        let kind = self.kind.ok_or_else(|| SceneError::missing(&type_path))?;
        match kind.as_str() {
            "box" => {
                if let Some(radius) = self.radius {
                    return Err(SceneError::invalid(
                        format!("{path}.radius"),
                        format!("is not used by a box (got {}); a box takes half_extents", show(radius)),
                    ));
                }
                let he_path = format!("{path}.half_extents");
                let half_extents = exact(self.half_extents.ok_or_else(|| SceneError::missing(&he_path))?, &he_path)?;
                Ok(Shape::Box { half_extents })
            }
            "sphere" => {
                if self.half_extents.is_some() {
                    return Err(SceneError::invalid(
                        format!("{path}.half_extents"),
                        "is not used by a sphere; a sphere takes radius",
                    ));
                }
                let radius = self.radius.ok_or_else(|| SceneError::missing(format!("{path}.radius")))?;
                Ok(Shape::Sphere { radius })
            }
            other => Err(SceneError::invalid(type_path, format!("unknown shape type {other:?}, expected \"box\" or \"sphere\""))),
        }
    }
}

impl RawJoint {
    fn into_joint(self, path: &str) -> Result<Joint, SceneError> {
        let type_path = format!("{path}.type");
        let kind = self.kind.ok_or_else(|| SceneError::missing(&type_path))?;
        if kind != "ball" {
            return Err(SceneError::invalid(type_path, format!("unknown joint type {kind:?}, expected \"ball\"")));
        }

        let bodies_path = format!("{path}.bodies");
        let bodies = exact(self.bodies.ok_or_else(|| SceneError::missing(&bodies_path))?, &bodies_path)?;

        let anchors_path = format!("{path}.anchors");
        let [a, b]: [Vec<f32>; 2] = exact(self.anchors.ok_or_else(|| SceneError::missing(&anchors_path))?, &anchors_path)?;
        let anchors = [exact(a, &format!("{anchors_path}[0]"))?, exact(b, &format!("{anchors_path}[1]"))?];
        Ok(Joint { bodies, anchors })
    }
}

impl RawCamera {
    fn into_camera(self) -> Result<Camera, SceneError> {
        let position = exact(self.position.ok_or_else(|| SceneError::missing("camera.position"))?, "camera.position")?;
        let target = exact(self.target.ok_or_else(|| SceneError::missing("camera.target"))?, "camera.target")?;
        Ok(Camera { position, target, fov_y: self.fov_y.unwrap_or(DEFAULT_FOV_Y) })
    }
}

/// Turns a list into a fixed-size array, refusing any other length.
fn exact<T, const N: usize>(values: Vec<T>, path: &str) -> Result<[T; N], SceneError> {
    let len = values.len();
    values.try_into().map_err(|_| SceneError::invalid(path, format!("must have exactly {N} elements, got {len}")))
}

fn optional_vec3(values: Option<Vec<f32>>, path: &str) -> Result<[f32; 3], SceneError> {
    match values {
        Some(v) => exact(v, path),
        None => Ok([0.0; 3]),
    }
}

/// Mass in kg of `shape` filled at `density`, refused if it does not fit a
/// positive finite f32 (absurdly large or small sizes or densities).
fn mass_from_density(density: f32, shape: &Shape, path: &str) -> Result<f32, SceneError> {
    let volume = shape.volume_f64();
    let mass = (density as f64 * volume) as f32;
    if mass.is_finite() && mass > 0.0 {
        Ok(mass)
    } else {
        Err(SceneError::invalid(
            path,
            format!(
                "density {} kg/m³ times volume {} m³ gives mass {} kg, which is not a positive finite number",
                show(density),
                show(volume as f32),
                show(mass)
            ),
        ))
    }
}

/// A quaternion scaled to unit length. One already of unit length to within
/// f32 rounding is returned unchanged, so that normalising is idempotent and
/// a scene written by [`Scene::to_json`] loads back bit for bit.
fn normalise(q: [f32; 4]) -> [f32; 4] {
    let norm = quaternion_norm(q);
    if (norm - 1.0).abs() <= 4.0 * f32::EPSILON as f64 {
        return q;
    }
    q.map(|c| (c as f64 / norm) as f32)
}

/// Length of a quaternion, in f64 so that large components do not overflow.
fn quaternion_norm(q: [f32; 4]) -> f64 {
    q.iter().map(|&c| (c as f64) * (c as f64)).sum::<f64>().sqrt()
}

// ---------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------

impl Scene {
    /// Checks every value of the scene, returning the first problem found.
    ///
    /// [`Scene::from_json_str`] calls this; call it yourself on scenes built
    /// in Rust.
    pub fn validate(&self) -> Result<(), SceneError> {
        validate_settings(&self.settings)?;
        if let Some(ground) = &self.ground {
            check_finite(ground.height, "ground.height")?;
        }
        for (i, body) in self.bodies.iter().enumerate() {
            validate_body(body, &format!("bodies[{i}]"), &self.settings)?;
        }
        for (i, joint) in self.joints.iter().enumerate() {
            validate_joint(joint, self.bodies.len(), &format!("joints[{i}]"))?;
        }
        if self.ground.is_some() {
            check_sink(&self.settings, &self.bodies)?;
        }
        if let Some(camera) = &self.camera {
            validate_camera(camera)?;
        }
        Ok(())
    }
}

fn validate_settings(s: &Settings) -> Result<(), SceneError> {
    check_positive(s.dt, "settings.dt")?;
    check_all_finite(&s.gravity, "settings.gravity")?;
    if !(1..=MAX_ITERATIONS).contains(&s.iterations) {
        return Err(SceneError::invalid(
            "settings.iterations",
            format!("must be between 1 and {MAX_ITERATIONS}, got {}", s.iterations),
        ));
    }
    check_finite(s.relaxation, "settings.relaxation")?;
    if !(s.relaxation > 0.0 && s.relaxation <= 1.0) {
        return Err(SceneError::invalid("settings.relaxation", format!("must be in (0, 1], got {}", show(s.relaxation))));
    }
    check_damping(s.linear_damping, "settings.linear_damping")?;
    check_damping(s.angular_damping, "settings.angular_damping")?;
    check_restitution(s.restitution, "settings.restitution")?;
    check_friction(s.friction, "settings.friction")?;
    if !(1..=MAX_SUBSTEPS).contains(&s.substeps) {
        return Err(SceneError::invalid("settings.substeps", format!("must be between 1 and {MAX_SUBSTEPS}, got {}", s.substeps)));
    }
    Ok(())
}

/// Refuses a step so long that bodies would rest visibly inside the ground.
/// Gravity moves a body |g| h^2 into whatever it rests on every substep of
/// h, and `iterations` Jacobi sweeps relaxed by c_r take back all but
/// (1 - c_r)^iterations of it, so that much stays inside, every substep,
/// and a body rests (and falls asleep) there: measured, unit cubes came to
/// rest 6 mm inside the ground at dt 0.2 s, 39 mm at 0.5 s and 156 mm at
/// 1 s (3 substeps, 3 sweeps, c_r 0.5), as the formula says. The limit is a
/// tenth of the smallest moving body's bounding radius.
fn check_sink(s: &Settings, bodies: &[Body]) -> Result<(), SceneError> {
    let Some(smallest) = bodies.iter().filter(|b| !b.fixed).map(|b| b.bounding_radius()).reduce(f32::min) else {
        return Ok(());
    };
    let h = s.dt as f64 / s.substeps as f64;
    let g = s.gravity.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
    let left = (1.0 - s.relaxation as f64).powi(s.iterations as i32);
    let sink = left * g * h * h;
    let limit = 0.1 * smallest as f64;
    if sink <= limit {
        return Ok(());
    }
    // blame the setting the user moved off its default
    let field = if s.dt != Settings::default().dt || g <= 9.81 { "settings.dt" } else { "settings.gravity" };
    Err(SceneError::invalid(
        field,
        format!(
            "a step this long lets bodies rest inside the ground: gravity ({g:.3e} m/s^2) moves a body {:.3e} m a substep \
             (dt {} s / {} substeps) and {} sweeps at relaxation {} leave {sink:.3e} m of that inside, more than a tenth of \
             the smallest body's bounding radius ({limit:.3e} m); lower dt or gravity, or raise settings.substeps",
            g * h * h,
            show(s.dt),
            s.substeps,
            s.iterations,
            show(s.relaxation)
        ),
    ))
}

/// Why an angular velocity `w` (rad/s) is absurd for substeps of `h` s (0:
/// any), if it is: faster than `world::MAX_SPIN`, or turning more than
/// `world::MAX_TURN` in one substep, which a pose pair cannot hold (the
/// numerical-fault check of integrate.wgsl would stop the body).
pub fn spin_problem(w: [f32; 3], h: f32) -> Option<String> {
    use crate::world::{MAX_SPIN, MAX_TURN};
    let rate = w.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
    if rate > MAX_SPIN as f64 {
        return Some(format!("spins at {rate:.4e} rad/s; at most {MAX_SPIN:e} rad/s is sane"));
    }
    let turn = rate * h as f64;
    if turn > MAX_TURN as f64 {
        return Some(format!(
            "spins at {rate:.1} rad/s, {turn:.2} rad per substep of {h:.3e} s; a body turns at most {MAX_TURN} rad \
             in one substep (a pose pair holds under half a turn): lower the spin, or raise settings.substeps or lower dt"
        ));
    }
    None
}

fn validate_body(body: &Body, path: &str, settings: &Settings) -> Result<(), SceneError> {
    check_shape(&body.shape, &format!("{path}.shape"))?;
    check_all_finite(&body.position, &format!("{path}.position"))?;
    check_orientation(body.orientation, &format!("{path}.orientation"))?;
    check_all_finite(&body.linear_velocity, &format!("{path}.linear_velocity"))?;
    check_all_finite(&body.angular_velocity, &format!("{path}.angular_velocity"))?;
    if !body.fixed {
        if let Some(why) = spin_problem(body.angular_velocity, settings.dt / settings.substeps as f32) {
            return Err(SceneError::invalid(format!("{path}.angular_velocity"), why));
        }
    }
    check_positive(body.mass, &format!("{path}.mass"))?;
    if let Some(restitution) = body.restitution {
        check_restitution(restitution, &format!("{path}.restitution"))?;
    }
    if let Some(friction) = body.friction {
        check_friction(friction, &format!("{path}.friction"))?;
    }
    // A valid but extreme mass and size can still overflow f32 in the
    // inverse mass or inertia; the solver needs those finite and positive.
    if !body.fixed {
        let inverse_mass = body.inverse_mass();
        let inverse_inertia = body.inverse_inertia();
        let usable = |x: f32| x.is_finite() && x > 0.0;
        if !usable(inverse_mass) || !inverse_inertia.iter().all(|&x| usable(x)) {
            return Err(SceneError::invalid(
                format!("{path}.mass"),
                format!(
                    "mass {} kg with this shape gives inverse mass {} and inverse inertia {:?}, which are not positive finite numbers",
                    show(body.mass),
                    show(inverse_mass),
                    inverse_inertia
                ),
            ));
        }
    }
    Ok(())
}

fn validate_joint(joint: &Joint, body_count: usize, path: &str) -> Result<(), SceneError> {
    for (k, &index) in joint.bodies.iter().enumerate() {
        let in_range = index == WORLD || (index >= 0 && (index as i64) < body_count as i64);
        if !in_range {
            let valid = if body_count == 0 {
                "only -1 (the world), as the scene has no bodies".to_string()
            } else {
                format!("0..={} or -1 for the world", body_count - 1)
            };
            return Err(SceneError::invalid(
                format!("{path}.bodies[{k}]"),
                format!("names body {index}, but the scene has {body_count} bodies (valid: {valid})"),
            ));
        }
    }
    let [a, b] = joint.bodies;
    if a == b {
        let message = if a == WORLD {
            "both sides are the world (-1); a joint needs at least one body".to_string()
        } else {
            format!("joins body {a} to itself; the two sides must differ")
        };
        return Err(SceneError::invalid(format!("{path}.bodies"), message));
    }
    for (k, anchor) in joint.anchors.iter().enumerate() {
        check_all_finite(anchor, &format!("{path}.anchors[{k}]"))?;
    }
    Ok(())
}

fn validate_camera(camera: &Camera) -> Result<(), SceneError> {
    check_all_finite(&camera.position, "camera.position")?;
    check_all_finite(&camera.target, "camera.target")?;
    if camera.position == camera.target {
        return Err(SceneError::invalid(
            "camera.target",
            format!("must differ from camera.position, both are {:?}", camera.position),
        ));
    }
    let fov = camera.fov_y;
    check_finite(fov, "camera.fov_y")?;
    if !(fov > 0.0 && fov < std::f32::consts::PI) {
        return Err(SceneError::invalid("camera.fov_y", format!("must be in (0, pi) radians, got {}", show(fov))));
    }
    Ok(())
}

/// The smallest bounding radius (m) a body may have. Measured on lavapipe,
/// dropped from 1 m with restitution 0.5 at three tilts and the default
/// settings: spheres of radius 6 mm and less sank more than their radius
/// into the ground and spun up to 270-320 rad/s from rounding (their inverse
/// inertia is huge, so a lever arm off by a rounding error turns them), a
/// cube of half extent 5 mm sank 1.1 cm, and a tilted 2.5 mm cube bounced to
/// 0.34 m where 0.25 m is the most restitution allows; from 7.5 mm up every
/// one landed, bounced at most 0.25 m and stopped turning.
pub const MIN_BOUNDING_RADIUS: f32 = 0.01;

fn check_shape(shape: &Shape, path: &str) -> Result<(), SceneError> {
    let field = match *shape {
        Shape::Box { half_extents } => {
            for (k, &h) in half_extents.iter().enumerate() {
                check_positive(h, &format!("{path}.half_extents[{k}]"))?;
            }
            "half_extents"
        }
        Shape::Sphere { radius } => {
            check_positive(radius, &format!("{path}.radius"))?;
            "radius"
        }
    };
    let r = shape.bounding_radius();
    if r < MIN_BOUNDING_RADIUS {
        return Err(SceneError::invalid(
            format!("{path}.{field}"),
            format!(
                "the body is too small: its bounding radius is {} m, the solver handles {} m and up \
                 (smaller bodies sink into what they land on and spin up from rounding)",
                show(r),
                show(MIN_BOUNDING_RADIUS)
            ),
        ));
    }
    Ok(())
}

fn check_orientation(q: [f32; 4], path: &str) -> Result<(), SceneError> {
    check_all_finite(&q, path)?;
    let norm = quaternion_norm(q);
    if norm <= MIN_ORIENTATION_NORM {
        return Err(SceneError::invalid(
            path,
            format!("must be a non-zero quaternion [x, y, z, w], got {q:?} (length {})", show(norm as f32)),
        ));
    }
    Ok(())
}

/// A number for an error message: `-1` rather than `-1.0`, `1e38` rather
/// than 39 digits.
fn show(x: f32) -> String {
    let text = format!("{x:?}");
    match text.strip_suffix(".0") {
        Some(whole) => whole.to_string(),
        None => text,
    }
}

fn check_finite(x: f32, path: &str) -> Result<(), SceneError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be a finite number, got {}", show(x))))
    }
}

fn check_all_finite(values: &[f32], path: &str) -> Result<(), SceneError> {
    for (k, &x) in values.iter().enumerate() {
        check_finite(x, &format!("{path}[{k}]"))?;
    }
    Ok(())
}

fn check_positive(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be positive, got {}", show(x))))
    }
}

fn check_damping(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if (0.0..1.0).contains(&x) {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be in [0, 1), got {}", show(x))))
    }
}

fn check_restitution(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if (0.0..=1.0).contains(&x) {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be in [0, 1], got {}", show(x))))
    }
}

fn check_friction(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if x >= 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be >= 0, got {}", show(x))))
    }
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

impl Scene {
    /// The scene as pretty JSON in the format of `INTERFACE.md`, which
    /// [`Scene::from_json_str`] loads back to an equal scene. Like
    /// `serde_json::to_string_pretty`, it has no final newline.
    ///
    /// Bodies are written with their resolved `mass` (never `density`);
    /// `None` optionals are left out. Numbers are written in
    /// the shortest form that reads back to the same f32. A non-finite
    /// number, possible only in a scene that fails [`Scene::validate`], is
    /// written as `null` and so refused on loading.
    pub fn to_json(&self) -> String {
        let mut top: Vec<(&str, String)> = vec![("settings", settings_json(&self.settings))];
        if let Some(ground) = &self.ground {
            top.push(("ground", format!("{{ \"height\": {} }}", num(ground.height))));
        }
        let bodies: Vec<String> = self.bodies.iter().map(body_json).collect();
        top.push(("bodies", list_json(&bodies)));
        let joints: Vec<String> = self.joints.iter().map(joint_json).collect();
        top.push(("joints", list_json(&joints)));
        if let Some(camera) = &self.camera {
            top.push((
                "camera",
                format!(
                    "{{ \"position\": {}, \"target\": {}, \"fov_y\": {} }}",
                    nums(&camera.position),
                    nums(&camera.target),
                    num(camera.fov_y)
                ),
            ));
        }
        object_json(&top, 0)
    }
}

fn settings_json(s: &Settings) -> String {
    let mut fields = vec![
        ("dt", num(s.dt)),
        ("gravity", nums(&s.gravity)),
        ("iterations", s.iterations.to_string()),
        ("relaxation", num(s.relaxation)),
        ("linear_damping", num(s.linear_damping)),
        ("angular_damping", num(s.angular_damping)),
        ("restitution", num(s.restitution)),
        ("friction", num(s.friction)),
    ];
    fields.push(("substeps", s.substeps.to_string()));
    fields.push(("sleeping", s.sleeping.to_string()));
    object_json(&fields, 1)
}

fn body_json(body: &Body) -> String {
    let shape = match body.shape {
        Shape::Box { half_extents } => {
            format!("{{ \"type\": \"box\", \"half_extents\": {} }}", nums(&half_extents))
        }
        Shape::Sphere { radius } => {
            format!("{{ \"type\": \"sphere\", \"radius\": {} }}", num(radius))
        }
    };
    let mut fields = vec![
        ("shape", shape),
        ("position", nums(&body.position)),
        ("orientation", nums(&body.orientation)),
        ("linear_velocity", nums(&body.linear_velocity)),
        ("angular_velocity", nums(&body.angular_velocity)),
        ("mass", num(body.mass)),
        ("fixed", body.fixed.to_string()),
    ];
    if let Some(restitution) = body.restitution {
        fields.push(("restitution", num(restitution)));
    }
    if let Some(friction) = body.friction {
        fields.push(("friction", num(friction)));
    }
    object_json(&fields, 2)
}

fn joint_json(joint: &Joint) -> String {
    format!(
        "{{ \"type\": \"ball\", \"bodies\": [{}, {}], \"anchors\": [{}, {}] }}",
        joint.bodies[0],
        joint.bodies[1],
        nums(&joint.anchors[0]),
        nums(&joint.anchors[1])
    )
}

/// A multi-line JSON object whose fields are indented one level past
/// `depth` (two spaces a level).
fn object_json(fields: &[(&str, String)], depth: usize) -> String {
    let inner = "  ".repeat(depth + 1);
    let mut out = String::with_capacity(fields.iter().map(|(k, v)| inner.len() + k.len() + v.len() + 6).sum::<usize>() + 8);
    out.push('{');
    if fields.is_empty() {
        out.push('\n');
    }
    for (k, (key, value)) in fields.iter().enumerate() {
        out.push_str(if k == 0 { "\n" } else { ",\n" });
        let _ = write!(out, "{inner}\"{key}\": ");
        out.push_str(value);
    }
    let _ = write!(out, "\n{}}}", "  ".repeat(depth));
    out
}

/// A JSON list of already formatted items at depth 1, one item per line.
fn list_json(items: &[String]) -> String {
    if items.is_empty() {
        return "[]".to_string();
    }
    // one string, not a copy per line: a scene of a million bodies is 350 MB of text
    let mut out = String::with_capacity(items.iter().map(|item| item.len() + 6).sum::<usize>() + 4);
    out.push('[');
    for (k, item) in items.iter().enumerate() {
        out.push_str(if k == 0 { "\n    " } else { ",\n    " });
        out.push_str(item);
    }
    out.push_str("\n  ]");
    out
}

/// One number, in the shortest form that reads back to the same f32.
fn num(x: f32) -> String {
    serde_json::to_string(&x).unwrap_or_else(|_| "null".to_string())
}

fn nums(values: &[f32]) -> String {
    let parts: Vec<String> = values.iter().map(|&x| num(x)).collect();
    format!("[{}]", parts.join(", "))
}

// ---------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;

    /// The example scene of INTERFACE.md, verbatim.
    const INTERFACE_EXAMPLE: &str = r#"{
  "settings": {
    "dt": 0.016666668,
    "gravity": [0.0, -9.81, 0.0],
    "iterations": 8,
    "relaxation": 0.5,
    "linear_damping": 0.0,
    "angular_damping": 0.0,
    "restitution": 0.2,
    "friction": 0.5
  },
  "ground": { "height": 0.0 },
  "bodies": [
    { "shape": { "type": "box", "half_extents": [0.5, 0.5, 0.5] },
      "position": [0.0, 3.0, 0.0],
      "orientation": [0.0, 0.0, 0.0, 1.0],
      "linear_velocity": [0.0, 0.0, 0.0],
      "angular_velocity": [0.0, 0.0, 0.0],
      "density": 1000.0 },
    { "shape": { "type": "sphere", "radius": 0.25 },
      "position": [1.0, 3.0, 0.0], "mass": 2.0 },
    { "shape": { "type": "box", "half_extents": [5.0, 0.1, 1.0] },
      "position": [0.0, 1.0, 4.0], "orientation": [0.0, 0.0, 0.13, 0.99],
      "fixed": true }
  ],
  "joints": [
    { "type": "ball", "bodies": [0, 1],
      "anchors": [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] },
    { "type": "ball", "bodies": [0, -1],
      "anchors": [[-0.5, 0.5, 0.0], [-0.5, 3.5, 0.0]] }
  ]
}"#;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-5 * a.abs().max(b.abs()).max(1.0)
    }

    fn error_of(text: &str) -> String {
        match Scene::from_json_str(text) {
            Ok(scene) => panic!("scene should be refused, loaded {scene:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn interface_example_loads() {
        let scene = Scene::from_json_str(INTERFACE_EXAMPLE).expect("example loads");
        // the example spells out the contract's suggested 8 iterations
        assert_eq!(scene.settings, Settings { iterations: 8, ..Settings::default() });
        assert_eq!(scene.ground, Some(Ground { height: 0.0 }));
        assert_eq!(scene.bodies.len(), 3);
        assert_eq!(scene.joints.len(), 2);
        assert_eq!(scene.camera, None);
        assert!(close(scene.bodies[0].mass, 1000.0));
        assert_eq!(scene.bodies[1].mass, 2.0);
        // Fixed body: mass from the default density, but immovable.
        assert!(close(scene.bodies[2].mass, 1000.0 * 8.0 * 5.0 * 0.1 * 1.0));
        assert_eq!(scene.bodies[2].inverse_mass(), 0.0);
        assert_eq!(scene.bodies[2].inverse_inertia(), [0.0; 3]);
        assert_eq!(scene.joints[1].bodies, [0, WORLD]);
    }

    #[test]
    fn empty_object_is_an_empty_scene_with_defaults() {
        let scene = Scene::from_json_str("{}").unwrap();
        assert_eq!(scene, Scene::default());
        let scene = Scene::from_json_str(r#"{"ground": null, "settings": {}}"#).unwrap();
        assert_eq!(scene.ground, None);
        assert_eq!(scene.settings, Settings::default());
    }

    #[test]
    fn default_dt_is_one_sixtieth() {
        assert_eq!(Settings::default().dt, 0.016666668);
    }

    #[test]
    fn box_mass_and_inertia() {
        // 1 x 2 x 3 m box of density 500: volume 6 m³, mass 3000 kg.
        let text = r#"{"bodies": [{"shape": {"type": "box", "half_extents": [0.5, 1.0, 1.5]},
                       "position": [0, 0, 0], "density": 500}]}"#;
        let body = Scene::from_json_str(text).unwrap().bodies.remove(0);
        assert!(close(body.mass, 3000.0));
        assert!(close(body.inverse_mass(), 1.0 / 3000.0));
        // I = m/3 (b² + c², a² + c², a² + b²) with half extents a, b, c.
        let m = 3000.0f32;
        let expected = [m / 3.0 * (1.0 + 2.25), m / 3.0 * (0.25 + 2.25), m / 3.0 * (0.25 + 1.0)];
        let inv = body.inverse_inertia();
        for k in 0..3 {
            assert!(close(inv[k], 1.0 / expected[k]), "axis {k}: {inv:?}");
        }
        assert!(close(body.bounding_radius(), (0.25f32 + 1.0 + 2.25).sqrt()));
    }

    #[test]
    fn sphere_mass_and_inertia() {
        let text = r#"{"bodies": [{"shape": {"type": "sphere", "radius": 0.5},
                       "position": [0, 0, 0]}]}"#;
        let body = Scene::from_json_str(text).unwrap().bodies.remove(0);
        // Default density 1000 kg/m³: m = 1000 · 4/3 π r³.
        let m = 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.125;
        assert!(close(body.mass, m));
        let i = 0.4 * m * 0.25;
        assert!(body.inverse_inertia().iter().all(|&x| close(x, 1.0 / i)));
        assert_eq!(body.bounding_radius(), 0.5);

        // Given mass wins over the shape's volume.
        let text = r#"{"bodies": [{"shape": {"type": "sphere", "radius": 2},
                       "position": [0, 0, 0], "mass": 10}]}"#;
        let body = Scene::from_json_str(text).unwrap().bodies.remove(0);
        assert_eq!(body.mass, 10.0);
        assert!(body.inverse_inertia().iter().all(|&x| close(x, 1.0 / 16.0)));
    }

    #[test]
    fn body_new_uses_default_density() {
        let body = Body::new(Shape::Box { half_extents: [0.5; 3] }, [0.0, 1.0, 0.0]);
        assert_eq!(body.mass, 1000.0);
        assert_eq!(body.orientation, IDENTITY_ORIENTATION);
        assert!(Scene { bodies: vec![body], ..Scene::default() }.validate().is_ok());
    }

    #[test]
    fn orientation_is_normalised() {
        let text = r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1},
                       "position": [0, 0, 0], "orientation": [0, 0, 2, 2]}]}"#;
        let q = Scene::from_json_str(text).unwrap().bodies[0].orientation;
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!(close(q[0], 0.0) && close(q[1], 0.0) && close(q[2], h) && close(q[3], h), "{q:?}");

        // The example's [0, 0, 0.13, 0.99] is not quite unit length.
        let q = Scene::from_json_str(INTERFACE_EXAMPLE).unwrap().bodies[2].orientation;
        assert!((quaternion_norm(q) - 1.0).abs() < 1e-6);
        assert!(close(q[2] / q[3], 0.13 / 0.99));

        // Normalising twice changes nothing, bit for bit.
        for raw in [[0.0, 0.0, 0.13, 0.99], [1.0, 2.0, 3.0, 4.0], [1e-3, 0.0, 0.0, 0.0], [3e38, 3e38, 0.0, 0.0]] {
            let once = normalise(raw);
            assert_eq!(normalise(once), once, "{raw:?}");
            assert!((quaternion_norm(once) - 1.0).abs() < 1e-6, "{raw:?}");
        }
    }

    #[test]
    fn zero_orientation_is_refused() {
        let text = r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1},
                       "position": [0, 0, 0], "orientation": [0, 0, 0, 0]}]}"#;
        assert!(error_of(text).starts_with("bodies[0].orientation: "));
    }

    #[test]
    fn errors_name_the_field() {
        let body = |extra: &str| {
            format!(
                r#"{{"bodies": [{{"shape": {{"type": "box", "half_extents": [1, 1, 1]}}, "position": [0, 0, 0]}},
                   {{"shape": {{"type": "box", "half_extents": [1, 1, 1]}}, "position": [0, 0, 0] {extra}}}]}}"#
            )
        };
        let cases = [
            (body(r#", "colour": "red""#), "bodies[1].colour: unknown field"),
            (body(r#", "mass": -1"#), "bodies[1].mass: must be positive, got -1"),
            (body(r#", "density": 0"#), "bodies[1].density: must be positive, got 0"),
            (body(r#", "mass": 1, "density": 1"#), "bodies[1].mass: "),
            (body(r#", "friction": -0.5"#), "bodies[1].friction: must be >= 0, got -0.5"),
            (body(r#", "restitution": 1.5"#), "bodies[1].restitution: must be in [0, 1], got 1.5"),
            (body(r#", "linear_velocity": [0, 1e39, 0]"#), "bodies[1].linear_velocity[1]: must be a finite number, got inf"),
            (body(r#", "angular_velocity": [0, 1e999, 0]"#), "bodies[1].angular_velocity[1]: number out of range"),
            (body(r#", "fixed": 1"#), "bodies[1].fixed: invalid type"),
            (r#"{"settings": {"dt": -0.1}}"#.to_string(), "settings.dt: must be positive, got -0.1"),
            (r#"{"settings": {"iterations": 0}}"#.to_string(), "settings.iterations: must be between 1 and 256, got 0"),
            (r#"{"settings": {"iterations": -3}}"#.to_string(), "settings.iterations: invalid value"),
            (r#"{"settings": {"substeps": 65}}"#.to_string(), "settings.substeps: must be between 1 and 64, got 65"),
            (r#"{"settings": {"relaxation": 0}}"#.to_string(), "settings.relaxation: must be in (0, 1], got 0"),
            (r#"{"settings": {"linear_damping": 1}}"#.to_string(), "settings.linear_damping: must be in [0, 1), got 1"),
            (r#"{"settings": {"gravity": [0, -9.81]}}"#.to_string(), "settings.gravity: must have exactly 3 elements, got 2"),
            (r#"{"ground": {}}"#.to_string(), "ground.height: is required but missing"),
            (r#"{"ground": {"height": 1, "normal": [0, 1, 0]}}"#.to_string(), "ground.normal: unknown field"),
            (r#"{"camera": {"position": [1, 1, 1], "target": [1, 1, 1]}}"#.to_string(), "camera.target: must differ"),
            (
                r#"{"camera": {"position": [1, 1, 1], "target": [0, 0, 0], "fov_y": 3.2}}"#.to_string(),
                "camera.fov_y: must be in (0, pi)",
            ),
            (r#"{"camera": {"target": [0, 0, 0]}}"#.to_string(), "camera.position: is required"),
            (
                r#"{"joints": [{"type": "hinge", "bodies": [0, -1], "anchors": [[0,0,0],[0,0,0]]}]}"#.to_string(),
                "joints[0].type: unknown joint type \"hinge\"",
            ),
            (
                r#"{"joints": [{"type": "ball", "bodies": [-1, -1], "anchors": [[0,0,0],[0,0,0]]}]}"#.to_string(),
                "joints[0].bodies: both sides are the world",
            ),
            (
                r#"{"joints": [{"type": "ball", "bodies": [0, -1], "anchors": [[0,0,0],[0,0,0]]}]}"#.to_string(),
                "joints[0].bodies[0]: names body 0, but the scene has 0 bodies",
            ),
            (
                r#"{"joints": [{"type": "ball", "bodies": [0, -1], "anchors": [[0,0,0]]}]}"#.to_string(),
                "joints[0].anchors: must have exactly 2 elements, got 1",
            ),
            (r#"[]"#.to_string(), "scene: invalid type: sequence, expected a JSON object"),
            (r#"{"settings": [0.1]}"#.to_string(), "settings: invalid type: sequence, expected a JSON object"),
            (body(r#", "shape": 3"#), "bodies[1]: duplicate field `shape`"),
            (
                r#"{"bodies": [{"shape": [], "position": [0, 0, 0]}]}"#.to_string(),
                "bodies[0].shape: invalid type: sequence, expected a JSON object",
            ),
            (r#"{"bodies": {}}"#.to_string(), "bodies: invalid type: map, expected a sequence"),
            (r#"{} {}"#.to_string(), "line 1, column 4: malformed JSON: trailing characters"),
            (r#""#.to_string(), "line 1, column 0: malformed JSON: EOF while parsing a value"),
            (r#"{"settings": {"dt": 0.1,}}"#.to_string(), "line 1, column 25: malformed JSON: trailing comma (in settings)"),
        ];
        for (text, expected) in cases {
            let message = error_of(&text);
            assert!(message.starts_with(expected), "for {text}\n  got      {message}\n  expected {expected}…");
            assert!(!message.contains('\n'), "{message}");
        }
    }

    #[test]
    fn control_characters_in_names_stay_on_one_line() {
        let message = error_of(r#"{"settings": {"d\nt": 1}}"#);
        assert!(message.starts_with("settings"), "{message}");
        assert!(!message.contains('\n'), "{message}");
        let message = error_of(r#"{"bodies": [{"shape": {"type": "co\nne"}, "position": [0,0,0]}]}"#);
        assert!(message.starts_with("bodies[0].shape.type: unknown shape type"), "{message}");
        assert!(!message.contains('\n'), "{message}");
    }

    #[test]
    fn validate_checks_scenes_built_in_rust() {
        let mut scene = Scene::default();
        scene.bodies.push(Body::new(Shape::Sphere { radius: 1.0 }, [0.0; 3]));
        assert!(scene.validate().is_ok());
        scene.bodies[0].orientation = [0.0, f32::NAN, 0.0, 1.0];
        let e = scene.validate().unwrap_err();
        assert_eq!(e.field(), Some("bodies[0].orientation[1]"));
        assert!(e.to_string().contains("got NaN"), "{e}");

        // Extreme but individually valid values that overflow the inverse
        // inertia (a body that small is refused for its size first).
        let mut scene = Scene::default();
        let mut body = Body::new(Shape::Box { half_extents: [0.5; 3] }, [0.0; 3]);
        body.mass = 1e-44;
        scene.bodies.push(body);
        assert_eq!(scene.validate().unwrap_err().field(), Some("bodies[0].mass"));
    }

    #[test]
    fn to_json_round_trips() {
        let scene = Scene::from_json_str(INTERFACE_EXAMPLE).unwrap();
        let text = scene.to_json();
        let again = Scene::from_json_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(again, scene);
        assert!(text.contains("\"mass\""));
        assert!(!text.contains("density"));
        assert!(!text.contains("null"));
        assert!(text.contains("\"substeps\": 3"));
        assert!(!text.contains("camera"));
        // It is also plain JSON to any other reader.
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value["settings"]["iterations"], 8);

        let empty = Scene::default();
        assert_eq!(Scene::from_json_str(&empty.to_json()).unwrap(), empty);
    }

    #[test]
    fn no_panic_on_truncated_or_mangled_input() {
        let text = INTERFACE_EXAMPLE;
        for end in 0..text.len() {
            let _ = Scene::from_json_str(&text[..end]);
        }
        let replacements = ["-1", "0", "1e999", "null", "[]", "{}", "\"x\"", "true", "-2147483649", "1e-45"];
        let number_starts: Vec<usize> = text
            .char_indices()
            .filter(|&(i, c)| c.is_ascii_digit() && !text[..i].ends_with(|p: char| p.is_ascii_digit() || p == '.' || p == '-'))
            .map(|(i, _)| i)
            .collect();
        for &start in &number_starts {
            let end = text[start..].find(|c: char| !(c.is_ascii_digit() || c == '.')).map_or(text.len(), |n| start + n);
            for r in replacements {
                let mangled = format!("{}{}{}", &text[..start], r, &text[end..]);
                if let Err(e) = Scene::from_json_str(&mangled) {
                    assert!(!e.to_string().contains('\n'));
                }
            }
        }
    }
}
