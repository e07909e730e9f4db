//! Writing a scene back as JSON in the format it is read in.

use super::*;

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

pub(super) fn settings_json(s: &Settings) -> String {
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

pub(super) fn body_json(body: &Body) -> String {
    let shape = match &body.shape {
        Shape::Box { half_extents } => {
            format!("{{ \"type\": \"box\", \"half_extents\": {} }}", nums(half_extents))
        }
        Shape::Sphere { radius } => {
            format!("{{ \"type\": \"sphere\", \"radius\": {} }}", num(*radius))
        }
        Shape::Capsule { radius, half_height } => {
            format!("{{ \"type\": \"capsule\", \"radius\": {}, \"half_height\": {} }}", num(*radius), num(*half_height))
        }
        Shape::Hull(shape) => {
            let points: Vec<String> = shape.points().iter().map(|p| nums(p)).collect();
            format!("{{ \"type\": \"hull\", \"points\": [{}] }}", points.join(", "))
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
    if body.kinematic {
        fields.push(("kinematic", "true".to_string()));
    }
    if let Some(restitution) = body.restitution {
        fields.push(("restitution", num(restitution)));
    }
    if let Some(friction) = body.friction {
        fields.push(("friction", num(friction)));
    }
    object_json(&fields, 2)
}

pub(super) fn joint_json(joint: &Joint) -> String {
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
pub(super) fn object_json(fields: &[(&str, String)], depth: usize) -> String {
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
pub(super) fn list_json(items: &[String]) -> String {
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
pub(super) fn num(x: f32) -> String {
    serde_json::to_string(&x).unwrap_or_else(|_| "null".to_string())
}

pub(super) fn nums(values: &[f32]) -> String {
    let parts: Vec<String> = values.iter().map(|&x| num(x)).collect();
    format!("[{}]", parts.join(", "))
}
