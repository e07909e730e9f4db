//! Checking a scene: every value, with the field it came from.

use super::*;

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
        if let Some(why) = dt_too_long(self.settings.dt) {
            return Err(SceneError::invalid("settings.dt", why));
        }
        if let Some(camera) = &self.camera {
            validate_camera(camera)?;
        }
        Ok(())
    }
}

pub(super) fn validate_settings(s: &Settings) -> Result<(), SceneError> {
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
    if let Some(why) = dt_too_short(s.dt, s.substeps) {
        // blame the setting the user moved off its default
        let field = if s.dt == Settings::default().dt { "settings.substeps" } else { "settings.dt" };
        return Err(SceneError::invalid(field, why));
    }
    Ok(())
}

/// Why a step of `dt` s in `substeps` substeps is too short, if it is
/// (`limits::MIN_SUBSTEP`; a part in a million below it is let by, so 3e-5 s
/// in 3 substeps passes).
pub(crate) fn dt_too_short(dt: f32, substeps: u32) -> Option<String> {
    let h = dt as f64 / substeps.max(1) as f64;
    (h < crate::limits::MIN_SUBSTEP as f64 * (1.0 - 1e-6)).then(|| {
        format!(
            "a step of {} s in {substeps} substeps makes substeps of {:.3e} s, shorter than {:e} s: over shorter substeps the \
         rounding of the poses reads as speed (a pyramid placed at rest read 0.35 m/s at 3.3e-7 s), and nothing comes \
         to rest; lengthen dt or take fewer substeps",
            show(dt),
            h,
            crate::limits::MIN_SUBSTEP
        )
    })
}

/// Why a step of `dt` s is too long, if it is (`limits::MAX_DT`).
pub(crate) fn dt_too_long(dt: f32) -> Option<String> {
    use crate::limits::MAX_DT;
    (dt > MAX_DT).then(|| format!("a step of {} s is longer than {MAX_DT} s, the longest a world takes", show(dt)))
}

/// Why a step of `dt` s is refused for `scene` (its settings with that dt),
/// if it is: what the scene loader checks a `settings.dt` by.
pub(crate) fn step_dt_problem(dt: f32, scene: &Scene) -> Option<String> {
    if !(dt.is_finite() && dt > 0.0) {
        return Some(format!("must be a positive finite number of seconds, got {}", show(dt)));
    }
    if let Some(why) = dt_too_short(dt, scene.settings.substeps) {
        return Some(why);
    }
    if scene.ground.is_some() {
        let settings = Settings { dt, ..scene.settings };
        if let Err(SceneError::Invalid { message, .. }) = check_sink(&settings, &scene.bodies) {
            return Some(message);
        }
    }
    dt_too_long(dt)
}

/// Refuses a step so long that bodies would rest visibly inside the ground,
/// or sink through it: each substep gravity presses a body |g| h^2 into what
/// it rests on and the sweeps leave (1 - c_r)^k of that; refused where that
/// passes a tenth of the smallest moving body's bounding radius, or where it
/// pushes in faster than `MAX_DEPENETRATION_SPEED` pushes out (figures in
/// docs/limits.md). Only gravity's part along -y counts.
pub(crate) fn check_sink(s: &Settings, bodies: &[Body]) -> Result<(), SceneError> {
    let Some(smallest) = bodies.iter().filter(|b| b.is_dynamic()).map(|b| b.bounding_radius()).reduce(f32::min) else {
        return Ok(());
    };
    use crate::limits::MAX_DEPENETRATION_SPEED;
    let h = s.dt as f64 / s.substeps as f64;
    let g = (-s.gravity[1] as f64).max(0.0);
    let sweeps = s.sweeps(s.substeps.max(1) - 1);
    let left = (1.0 - s.relaxation as f64).powi(sweeps as i32);
    let sink = left * g * h * h;
    let limit = 0.1 * smallest as f64;
    let speed = left * g * h;
    if sink <= limit && speed <= MAX_DEPENETRATION_SPEED as f64 {
        return Ok(());
    }
    // blame the setting the user moved off its default
    let field = if s.dt != Settings::default().dt || g <= 9.81 { "settings.dt" } else { "settings.gravity" };
    let pressed = format!(
        "gravity into the ground ({g:.3e} m/s^2) moves a body {:.3e} m a substep (dt {} s / {} substeps) and {} sweeps \
         at relaxation {} leave {sink:.3e} m of that inside",
        g * h * h,
        show(s.dt),
        s.substeps,
        sweeps,
        show(s.relaxation)
    );
    let why = if sink > limit {
        format!(
            "a step this long lets bodies rest inside the ground: {pressed}, more than a tenth of the smallest body's \
             bounding radius ({limit:.3e} m); lower dt or gravity, or raise settings.substeps"
        )
    } else {
        format!(
            "bodies would sink through the ground: {pressed} every substep, {speed:.3} m/s, more than the \
             {MAX_DEPENETRATION_SPEED} m/s at which old overlap is pushed out; lower dt or gravity, or raise \
             settings.substeps or settings.iterations"
        )
    };
    Err(SceneError::invalid(field, why))
}

fn length(v: [f32; 3]) -> f64 {
    v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt()
}

/// Why a body placed at `p` (m) is absurd, if it is: farther than
/// `limits::MAX_DISTANCE` from the origin, where the step stops it as a fault.
pub(crate) fn position_problem(p: [f32; 3]) -> Option<String> {
    use crate::limits::MAX_DISTANCE;
    let distance = length(p);
    (distance > MAX_DISTANCE as f64).then(|| {
        format!("lies {distance:.4e} m from the origin; at most {MAX_DISTANCE:e} m is sane (the step stops a body beyond it)")
    })
}

/// Why a body moving at `v` (m/s) is absurd, if it is: faster than
/// `limits::MAX_SPEED`, where the step stops it as a fault.
pub(crate) fn speed_problem(v: [f32; 3]) -> Option<String> {
    use crate::limits::MAX_SPEED;
    let speed = length(v);
    (speed > MAX_SPEED as f64)
        .then(|| format!("moves at {speed:.4e} m/s; at most {MAX_SPEED:e} m/s is sane (the step stops a faster body)"))
}

/// Why an angular velocity `w` (rad/s) is absurd for substeps of `h` s (0:
/// any), if it is: faster than `limits::MAX_SPIN`, or turning more than
/// `limits::MAX_TURN` in one substep, which a pose pair cannot hold (the
/// numerical-fault check of integrate.wgsl would stop the body).
pub(crate) fn spin_problem(w: [f32; 3], h: f32) -> Option<String> {
    use crate::limits::{MAX_SPIN, MAX_TURN};
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

pub(crate) fn validate_body(body: &Body, path: &str, settings: &Settings) -> Result<(), SceneError> {
    check_shape(&body.shape, &format!("{path}.shape"))?;
    check_all_finite(&body.position, &format!("{path}.position"))?;
    check_orientation(body.orientation, &format!("{path}.orientation"))?;
    check_all_finite(&body.linear_velocity, &format!("{path}.linear_velocity"))?;
    check_all_finite(&body.angular_velocity, &format!("{path}.angular_velocity"))?;
    if body.fixed && body.kinematic {
        return Err(SceneError::invalid(
            format!("{path}.kinematic"),
            "a body is fixed or kinematic, not both (a kinematic body at rest stays put as a fixed one does)",
        ));
    }
    // what the step would stop at once as a numerical fault (integrate.wgsl)
    if let Some(why) = position_problem(body.position) {
        return Err(SceneError::invalid(format!("{path}.position"), why));
    }
    if !body.fixed {
        if let Some(why) = speed_problem(body.linear_velocity) {
            return Err(SceneError::invalid(format!("{path}.linear_velocity"), why));
        }
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
    if let Some(why) = inverse_problem(body) {
        return Err(SceneError::invalid(format!("{path}.mass"), why));
    }
    Ok(())
}

/// Why `mass` (kg) is unusable for a movable body of `shape`, if it is (see
/// `inverse_problem`): what an input that makes a body dynamic is checked by.
pub(crate) fn mass_problem(shape: &Shape, mass: f32) -> Option<String> {
    if !(mass.is_finite() && mass > 0.0) {
        return Some(format!("must be a positive finite number of kg, got {}", show(mass)));
    }
    let mut body = Body::new(shape.clone(), [0.0; 3]);
    body.mass = mass;
    inverse_problem(&body)
}

/// Why a movable body's mass and size are unusable, if they are: a valid
/// but extreme mass and size can still overflow f32 in the inverse mass or
/// inertia, and the solver needs those finite and positive.
pub(super) fn inverse_problem(body: &Body) -> Option<String> {
    if !body.is_dynamic() {
        return None;
    }
    let inverse_mass = body.inverse_mass();
    let inverse_inertia = body.inverse_inertia();
    // a GPU reads a subnormal as 0 (a box of 3e38 kg, inverse mass 3.3e-39,
    // turned non-finite at its first contact)
    let usable = |x: f32| x.is_finite() && x >= f32::MIN_POSITIVE;
    if usable(inverse_mass) && inverse_inertia.iter().all(|&x| usable(x)) {
        return None;
    }
    Some(format!(
        "mass {} kg with this shape gives inverse mass {} and inverse inertia {:?}, which are not finite numbers of at \
         least 1.2e-38 (a GPU reads smaller ones as 0)",
        show(body.mass),
        show(inverse_mass),
        inverse_inertia
    ))
}

pub(crate) fn validate_joint(joint: &Joint, body_count: usize, path: &str) -> Result<(), SceneError> {
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
        let at = format!("{path}.anchors[{k}]");
        check_all_finite(anchor, &at)?;
        // a world point, or an offset from the body's centre: beyond what a
        // body may reach (it would be stopped as a fault there)
        use crate::limits::MAX_DISTANCE;
        let distance = length(*anchor);
        if distance > MAX_DISTANCE as f64 {
            let from = if joint.bodies[k] == WORLD { "the origin" } else { "its body's centre" };
            return Err(SceneError::invalid(at, format!("lies {distance:.4e} m from {from}; at most {MAX_DISTANCE:e} m is sane")));
        }
    }
    Ok(())
}

pub(super) fn validate_camera(camera: &Camera) -> Result<(), SceneError> {
    check_all_finite(&camera.position, "camera.position")?;
    check_all_finite(&camera.target, "camera.target")?;
    if camera.position == camera.target {
        return Err(SceneError::invalid(
            "camera.target",
            format!("must differ from camera.position, both are {:?}", camera.position),
        ));
    }
    // a camera beyond where any body may be sees nothing of the scene
    for (field, p) in [("camera.position", camera.position), ("camera.target", camera.target)] {
        if let Some(why) = position_problem(p) {
            return Err(SceneError::invalid(field, why));
        }
    }
    let gap = length(std::array::from_fn(|k| camera.target[k] - camera.position[k]));
    let nearest = crate::limits::MIN_CAMERA_DISTANCE;
    if gap < nearest as f64 {
        return Err(SceneError::invalid(
            "camera.target",
            format!("lies {gap:.4e} m from camera.position; at least {nearest:e} m is needed to see along"),
        ));
    }
    let fov = camera.fov_y;
    check_finite(fov, "camera.fov_y")?;
    if !(fov > 0.0 && fov < std::f32::consts::PI) {
        return Err(SceneError::invalid("camera.fov_y", format!("must be in (0, pi) radians, got {}", show(fov))));
    }
    Ok(())
}

/// The smallest bounding radius (m) a body may have: below about 7.5 mm
/// rounding spins, sinks and over-bounces bodies (docs/limits.md).
pub(crate) const MIN_BOUNDING_RADIUS: f32 = 0.01;

pub(super) fn check_shape(shape: &Shape, path: &str) -> Result<(), SceneError> {
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
        Shape::Capsule { radius, half_height } => {
            check_positive(radius, &format!("{path}.radius"))?;
            check_positive(half_height, &format!("{path}.half_height"))?;
            "radius"
        }
        // checked as it was made (`HullShape::new`)
        Shape::Hull(_) => "points",
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

pub(super) fn check_orientation(q: [f32; 4], path: &str) -> Result<(), SceneError> {
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
pub(super) fn show(x: f32) -> String {
    let text = format!("{x:?}");
    match text.strip_suffix(".0") {
        Some(whole) => whole.to_string(),
        None => text,
    }
}

pub(super) fn check_finite(x: f32, path: &str) -> Result<(), SceneError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be a finite number, got {}", show(x))))
    }
}

pub(super) fn check_all_finite(values: &[f32], path: &str) -> Result<(), SceneError> {
    for (k, &x) in values.iter().enumerate() {
        check_finite(x, &format!("{path}[{k}]"))?;
    }
    Ok(())
}

pub(super) fn check_positive(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be positive, got {}", show(x))))
    }
}

pub(super) fn check_damping(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if (0.0..1.0).contains(&x) {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be in [0, 1), got {}", show(x))))
    }
}

pub(super) fn check_restitution(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if (0.0..=1.0).contains(&x) {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be in [0, 1], got {}", show(x))))
    }
}

pub(super) fn check_friction(x: f32, path: &str) -> Result<(), SceneError> {
    check_finite(x, path)?;
    if x >= 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be >= 0, got {}", show(x))))
    }
}
