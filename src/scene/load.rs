//! Loading a scene: JSON into private raw structs that mirror the file
//! exactly, then into [`Scene`] with defaults filled in and masses resolved.

use super::*;
use crate::json::{path_string, Obj};
use crate::load_error::FileKind;

impl Scene {
    /// Parses and validates a scene from JSON text.
    pub fn from_json_str(text: &str) -> Result<Scene, SceneError> {
        SceneError::check_text(FileKind::Scene, text)?;
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
        Scene::from_json_str(&SceneError::read(FileKind::Scene, path)?)
    }
}

/// A serde_json error in a scene (see `LoadError::from_json`).
pub(super) fn json_error(field: Option<String>, inner: serde_json::Error) -> SceneError {
    SceneError::from_json(FileKind::Scene, field, inner)
}

// The raw file representation. Required fields are `Option` too, so that
// "missing" errors can name the field itself rather than its parent, and
// fixed-size arrays are `Vec` so that a wrong length gets a clear message.
// As serde does for `Option`, `null` counts as absent: the contract says so
// for `ground`, and it is the same everywhere.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    settings: Option<Obj<RawSettings>>,
    ground: Option<Obj<RawGround>>,
    bodies: Option<Vec<Obj<RawBody>>>,
    joints: Option<Vec<Obj<RawJoint>>>,
    camera: Option<Obj<RawCamera>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSettings {
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
pub(super) struct RawGround {
    height: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBody {
    shape: Option<Obj<RawShape>>,
    position: Option<Vec<f32>>,
    orientation: Option<Vec<f32>>,
    linear_velocity: Option<Vec<f32>>,
    angular_velocity: Option<Vec<f32>>,
    density: Option<f32>,
    mass: Option<f32>,
    fixed: Option<bool>,
    kinematic: Option<bool>,
    restitution: Option<f32>,
    friction: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawShape {
    #[serde(rename = "type")]
    kind: Option<String>,
    half_extents: Option<Vec<f32>>,
    radius: Option<f32>,
    half_height: Option<f32>,
    points: Option<Vec<Vec<f32>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawJoint {
    #[serde(rename = "type")]
    kind: Option<String>,
    bodies: Option<Vec<i32>>,
    anchors: Option<Vec<Vec<f32>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCamera {
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
            substeps: match (self.substeps, self.iterations) {
                (Some(n), _) => n,
                // the solver picks the split of the sweeps a scene asks for
                (None, Some(iterations)) => Settings::substeps_for(iterations),
                (None, None) => d.substeps,
            },
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

        // where a mass worked out from the density is blamed (the density
        // given, or the shape's size when none was)
        let mut blame = None;
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
                let path = if self.density.is_some() { density_path } else { shape_path.clone() };
                let mass = mass_from_density(density, &shape, &path)?;
                blame = Some(path);
                mass
            }
        };

        let body = Body {
            shape,
            position,
            orientation,
            linear_velocity: optional_vec3(self.linear_velocity, &format!("{path}.linear_velocity"))?,
            angular_velocity: optional_vec3(self.angular_velocity, &format!("{path}.angular_velocity"))?,
            mass,
            fixed: self.fixed.unwrap_or(false),
            kinematic: self.kinematic.unwrap_or(false),
            restitution: self.restitution,
            friction: self.friction,
        };
        // a density so small that the inverse mass overflows is the
        // density's fault, not a mass the user never gave
        if let (Some(path), Some(why)) = (blame, inverse_problem(&body)) {
            return Err(SceneError::invalid(path, format!("density {}: {why}", show(self.density.unwrap_or(DEFAULT_DENSITY)))));
        }
        Ok(body)
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
                refuse_half_height(self.half_height, path, "a box takes half_extents")?;
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
                refuse_half_height(self.half_height, path, "a sphere takes radius")?;
                let radius = self.radius.ok_or_else(|| SceneError::missing(format!("{path}.radius")))?;
                Ok(Shape::Sphere { radius })
            }
            "hull" => {
                for (field, given) in [("half_extents", self.half_extents.is_some()), ("radius", self.radius.is_some())] {
                    if given {
                        return Err(SceneError::invalid(format!("{path}.{field}"), "is not used by a hull; a hull takes points"));
                    }
                }
                refuse_half_height(self.half_height, path, "a hull takes points")?;
                let points_path = format!("{path}.points");
                let raw = self.points.ok_or_else(|| SceneError::missing(&points_path))?;
                let points = raw.into_iter().enumerate().map(|(k, p)| exact(p, &format!("{points_path}[{k}]"))).collect::<Result<
                    Vec<[f32; 3]>,
                    _,
                >>(
                )?;
                let shape = super::HullShape::new(points).map_err(|why| SceneError::invalid(points_path, why))?;
                Ok(Shape::Hull(shape))
            }
            "capsule" => {
                if self.half_extents.is_some() {
                    return Err(SceneError::invalid(
                        format!("{path}.half_extents"),
                        "is not used by a capsule; a capsule takes radius and half_height",
                    ));
                }
                let radius = self.radius.ok_or_else(|| SceneError::missing(format!("{path}.radius")))?;
                let half_height = self.half_height.ok_or_else(|| SceneError::missing(format!("{path}.half_height")))?;
                Ok(Shape::Capsule { radius, half_height })
            }
            other => Err(SceneError::invalid(
                type_path,
                format!("unknown shape type {other:?}, expected \"box\", \"sphere\", \"capsule\" or \"hull\""),
            )),
        }
    }
}

/// Refuses `half_height` on a shape other than a capsule.
fn refuse_half_height(half_height: Option<f32>, path: &str, takes: &str) -> Result<(), SceneError> {
    match half_height {
        Some(h) => {
            Err(SceneError::invalid(format!("{path}.half_height"), format!("is only used by a capsule (got {}); {takes}", show(h))))
        }
        None => Ok(()),
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
pub(super) fn exact<T, const N: usize>(values: Vec<T>, path: &str) -> Result<[T; N], SceneError> {
    let len = values.len();
    values.try_into().map_err(|_| SceneError::invalid(path, format!("must have exactly {N} elements, got {len}")))
}

pub(super) fn optional_vec3(values: Option<Vec<f32>>, path: &str) -> Result<[f32; 3], SceneError> {
    match values {
        Some(v) => exact(v, path),
        None => Ok([0.0; 3]),
    }
}

/// Mass in kg of `shape` filled at `density`, refused if it does not fit a
/// positive finite f32 (absurdly large or small sizes or densities).
pub(super) fn mass_from_density(density: f32, shape: &Shape, path: &str) -> Result<f32, SceneError> {
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
pub(super) fn normalise(q: [f32; 4]) -> [f32; 4] {
    let norm = quaternion_norm(q);
    if (norm - 1.0).abs() <= 4.0 * f32::EPSILON as f64 {
        return q;
    }
    q.map(|c| (c as f64 / norm) as f32)
}

/// Length of a quaternion, in f64 so that large components do not overflow.
pub(super) fn quaternion_norm(q: [f32; 4]) -> f64 {
    q.iter().map(|&c| (c as f64) * (c as f64)).sum::<f64>().sqrt()
}
