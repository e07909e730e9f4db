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
    // the example spells out the contract's suggested 8 iterations, and no substeps
    assert_eq!(scene.settings, Settings { iterations: 8, substeps: 2, ..Settings::default() });
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

/// A capsule's mass is its cylinder's and its two caps' (one ball); its
/// moments are the cylinder's and the caps' about the centre, the caps'
/// centroids 3r/8 beyond the cylinder's ends.
#[test]
fn capsule_mass_and_inertia() {
    let text = r#"{"bodies": [{"shape": {"type": "capsule", "radius": 0.5, "half_height": 1},
                   "position": [0, 0, 0]}]}"#;
    let body = Scene::from_json_str(text).unwrap().bodies.remove(0);
    let pi = std::f64::consts::PI;
    let (mc, ms) = (1000.0 * pi * 0.25 * 2.0, 1000.0 * 4.0 / 3.0 * pi * 0.125);
    assert!(close(body.mass, (mc + ms) as f32));
    let across = mc * (0.25 / 4.0 + 1.0 / 3.0) + ms * (0.4 * 0.25 + 1.0 + 0.75 * 0.5);
    let along = mc * 0.25 / 2.0 + ms * 0.4 * 0.25;
    let inv = body.inverse_inertia();
    assert!(close(inv[0], (1.0 / across) as f32) && close(inv[2], (1.0 / across) as f32), "{inv:?}");
    assert!(close(inv[1], (1.0 / along) as f32), "{inv:?}");
    assert_eq!(body.bounding_radius(), 1.5);
    let scene = Scene { bodies: vec![body], ..Scene::default() };
    let text = scene.to_json();
    assert!(text.contains(r#""type": "capsule", "radius": 0.5, "half_height": 1.0 "#), "{text}");
    assert_eq!(Scene::from_json_str(&text).unwrap(), scene);
}

/// A kinematic body keeps its mass but has none to contacts (infinite),
/// and is written back as kinematic; others are written without the field.
#[test]
fn kinematic_bodies_load_and_round_trip() {
    let text = r#"{"bodies": [{"shape": {"type": "box", "half_extents": [1, 0.1, 1]}, "position": [0, 1, 0],
                   "kinematic": true, "angular_velocity": [0, 1, 0]},
                  {"shape": {"type": "sphere", "radius": 0.5}, "position": [0, 3, 0]}]}"#;
    let scene = Scene::from_json_str(text).unwrap();
    let table = &scene.bodies[0];
    assert!(table.kinematic && !table.fixed && !table.is_dynamic());
    assert_eq!(table.mass, 800.0);
    assert_eq!((table.inverse_mass(), table.inverse_inertia()), (0.0, [0.0; 3]));
    let written = scene.to_json();
    assert_eq!(written.matches("\"kinematic\": true").count(), 1, "{written}");
    assert!(!written.contains("\"kinematic\": false"));
    assert_eq!(Scene::from_json_str(&written).unwrap(), scene);
}

/// A hull's mass is its volume's at the density; its moments are about
/// its principal axes; it is written back with its points as given; points
/// that make no solid are refused naming them.
#[test]
fn hull_shapes_load_and_round_trip() {
    let text = r#"{"bodies": [{"shape": {"type": "hull", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.1, 0.1, 0.1]]},
                   "position": [0, 1, 0]}]}"#;
    let scene = Scene::from_json_str(text).unwrap();
    let body = &scene.bodies[0];
    assert!(close(body.mass, 1000.0 / 6.0), "{}", body.mass);
    let Shape::Hull(ref h) = body.shape else { panic!("{:?}", body.shape) };
    assert_eq!((h.points().len(), h.hull().vertices.len()), (5, 4));
    let written = scene.to_json();
    assert_eq!(Scene::from_json_str(&written).unwrap(), scene);
    let flat = r#"{"bodies": [{"shape": {"type": "hull", "points": [[0, 0, 0], [1, 0, 0], [0, 0, 1], [1, 0, 1]]},
                   "position": [0, 1, 0]}]}"#;
    let e = error_of(flat);
    assert!(e.contains("bodies[0].shape.points") && e.contains("span a volume"), "{e}");
    let short = r#"{"bodies": [{"shape": {"type": "hull", "points": [[0, 0, 0], [1, 0]]}, "position": [0, 1, 0]}]}"#;
    assert!(error_of(short).contains("bodies[0].shape.points[1]"), "{}", error_of(short));
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

/// Gravity sideways or upward presses nothing into the ground: the check
/// that refuses a step letting bodies sink counts only its part along -y
/// (1e5 m/s^2 along x was refused as resting inside the ground).
#[test]
fn only_gravity_into_the_ground_is_checked_for_sinking() {
    for g in ["[100000, 0, 0]", "[0, 100000, 0]"] {
        let text = format!(
            r#"{{"settings": {{"gravity": {g}}}, "ground": {{"height": 0}},
               "bodies": [{{"shape": {{"type": "box", "half_extents": [0.5, 0.5, 0.5]}}, "position": [0, 3, 0]}}]}}"#
        );
        assert!(Scene::from_json_str(&text).is_ok(), "gravity {g} refused");
    }
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
        (
            r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}, "position": [0, 1e7, 0], "fixed": true}]}"#.to_string(),
            "bodies[0].position: lies 1.0000e7 m from the origin; at most 1e6 m",
        ),
        (body(r#", "linear_velocity": [3e4, 0, 0]"#), "bodies[1].linear_velocity: moves at 3.0000e4 m/s; at most 1e4 m/s"),
        (
            r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1e30}, "position": [0, 3, 0]}]}"#.to_string(),
            "bodies[0].shape: density 1000 kg/m³ times volume inf m³",
        ),
        // a mass f32 cannot invert, from the density the user gave
        (body(r#", "density": 1e-44"#), "bodies[1].density: density 1e-44: mass "),
        (body(r#", "mass": 1e-39"#), "bodies[1].mass: mass 1e-39 kg with this shape gives inverse mass inf"),
        // subnormal inverses: a GPU reads them as 0 (this box turned
        // non-finite at its first contact)
        (body(r#", "mass": 3e38"#), "bodies[1].mass: mass 3e38 kg with this shape gives inverse mass 3.333333e-39"),
        (body(r#", "fixed": 1"#), "bodies[1].fixed: invalid type"),
        (
            r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}, "position": [0, 3, 0]}],
                "joints": [{"type": "ball", "bodies": [0, -1], "anchors": [[0, 0, 0], [0, 1e7, 0]]}]}"#
                .to_string(),
            "joints[0].anchors[1]: lies 1.0000e7 m from the origin; at most 1e6 m",
        ),
        (r#"{"settings": {"dt": -0.1}}"#.to_string(), "settings.dt: must be positive, got -0.1"),
        (r#"{"settings": {"dt": 1e-9}}"#.to_string(), "settings.dt: a step of 1e-9 s in 3 substeps makes substeps of 3.333e-10 s"),
        (r#"{"settings": {"substeps": 64, "dt": 5e-4}}"#.to_string(), "settings.dt: a step of 0.0005 s in 64 substeps"),
        (r#"{"settings": {"substeps": 64, "dt": 3e-5}}"#.to_string(), "settings.dt: "),
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
    assert!(text.contains("\"substeps\": 2"));
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

#[test]
fn iterations_are_the_sweeps_of_a_step_spread_over_its_substeps() {
    let with = |iterations, substeps| Settings { iterations, substeps, ..Settings::default() };
    let sweeps = |s: Settings| (0..s.substeps).map(|k| s.sweeps(k)).collect::<Vec<_>>();
    // the defaults: nine sweeps in three substeps of three
    assert_eq!(sweeps(Settings::default()), [3, 3, 3]);
    // the first substeps take one more where they do not divide
    assert_eq!(sweeps(with(8, 3)), [3, 3, 2]);
    assert_eq!(sweeps(with(5, 4)), [2, 1, 1, 1]);
    // at least one a substep
    assert_eq!(sweeps(with(2, 4)), [1, 1, 1, 1]);
    assert_eq!(with(2, 4).sweeps_per_step(), 4);
    assert_eq!(with(8, 3).sweeps_per_step(), 8);
}

#[test]
fn a_scene_that_gives_iterations_alone_gets_four_sweeps_a_substep() {
    let substeps = |json: &str| Scene::from_json_str(json).expect("loads").settings.substeps;
    assert_eq!(substeps(r#"{"settings": {"iterations": 8}}"#), 2);
    assert_eq!(substeps(r#"{"settings": {"iterations": 9}}"#), 3);
    assert_eq!(substeps(r#"{"settings": {"iterations": 24}}"#), 6);
    assert_eq!(substeps(r#"{"settings": {"iterations": 1}}"#), 1);
    assert_eq!(substeps(r#"{"settings": {"iterations": 256}}"#), 64);
    // a scene's own substeps stand; none at all: the default
    assert_eq!(substeps(r#"{"settings": {"iterations": 8, "substeps": 8}}"#), 8);
    assert_eq!(substeps(r#"{"settings": {}}"#), Settings::default().substeps);
}
