//! Scene loading against the contract of INTERFACE.md section 1: every file
//! in `tests/bad_scenes/` is refused, by the library and by `verlet run`,
//! with an error naming the field listed for it in `expected.json`; and a
//! scene using every optional field loads and survives a write/read round
//! trip.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use verlet::scene::{Scene, Shape, WORLD};

fn bad_scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_scenes")
}

/// File name → the field path its error must name (`"line"` for JSON syntax
/// errors, which name a line and column instead).
fn expected_paths() -> BTreeMap<String, String> {
    let path = bad_scenes_dir().join("expected.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Whether `message` names `path` as a whole field path: `bodies[1]` must
/// not be satisfied by `bodies[1].shape` or `bodies[10]`.
fn names_field(message: &str, path: &str) -> bool {
    message.match_indices(path).any(|(start, _)| {
        let next = message[start + path.len()..].chars().next();
        !matches!(next, Some(c) if c == '[' || c == '.' || c == '_' || c.is_alphanumeric())
    })
}

#[test]
fn every_bad_scene_file_is_listed() {
    let expected = expected_paths();
    let mut unlisted = Vec::new();
    for entry in std::fs::read_dir(bad_scenes_dir()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name != "expected.json" && !expected.contains_key(&name) {
            unlisted.push(name);
        }
    }
    assert!(unlisted.is_empty(), "not in expected.json: {unlisted:?}");
}

#[test]
fn bad_scenes_are_refused_naming_the_field() {
    let mut failures = Vec::new();
    for (name, path) in expected_paths() {
        let file = bad_scenes_dir().join(&name);
        let text = std::fs::read_to_string(&file).unwrap();
        match Scene::from_json_str(&text) {
            Ok(_) => failures.push(format!("{name}: loaded, should have been refused")),
            Err(e) => {
                let message = e.to_string();
                if !names_field(&message, &path) {
                    failures.push(format!("{name}: expected {path:?} in {message:?}"));
                }
                if message.contains('\n') {
                    failures.push(format!("{name}: message is not one line: {message:?}"));
                }
            }
        }
        // from_path gives the same error as from_json_str.
        if let Err(e) = Scene::from_path(&file) {
            if !e.to_string().contains(&path) {
                failures.push(format!("{name}: from_path: expected {path:?} in {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn verlet_run_refuses_bad_scenes() {
    let mut failures = Vec::new();
    for (name, path) in expected_paths() {
        let file = bad_scenes_dir().join(&name);
        let output = Command::new(env!("CARGO_BIN_EXE_verlet"))
            .args(["run".as_ref(), file.as_os_str(), "--steps".as_ref(), "1".as_ref()])
            .output()
            .expect("verlet binary runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        if output.status.success() {
            failures.push(format!("{name}: exit status 0"));
        }
        if !stderr.contains(&path) {
            failures.push(format!("{name}: expected {path:?} in stderr {stderr:?}"));
        }
        if stderr.contains("panicked") {
            failures.push(format!("{name}: panicked: {stderr:?}"));
        }
        if stderr.trim_end().contains('\n') || stderr.trim().is_empty() {
            failures.push(format!("{name}: stderr is not one line: {stderr:?}"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn missing_file_error_names_the_file() {
    let file = bad_scenes_dir().join("no_such_scene.json");
    let message = Scene::from_path(&file).unwrap_err().to_string();
    assert!(message.contains("no_such_scene.json"), "{message}");
}

/// Uses every field the format has, optional ones included.
const FULL_SCENE: &str = r#"{
  "settings": {
    "dt": 0.01,
    "gravity": [0.5, -9.81, 0.25],
    "iterations": 12,
    "relaxation": 0.75,
    "linear_damping": 0.01,
    "angular_damping": 0.02,
    "restitution": 0.3,
    "friction": 0.6,
    "substeps": 4,
    "sleeping": false
  },
  "ground": { "height": -0.5 },
  "bodies": [
    { "shape": { "type": "box", "half_extents": [0.5, 0.25, 1.0] },
      "position": [0.0, 3.0, 0.0],
      "orientation": [0.1, 0.2, 0.3, 0.9],
      "linear_velocity": [1.0, 0.0, -1.0],
      "angular_velocity": [0.0, 2.0, 0.0],
      "density": 500.0,
      "restitution": 0.9,
      "friction": 0.1 },
    { "shape": { "type": "sphere", "radius": 0.25 },
      "position": [1.0, 3.0, 0.0], "mass": 2.0, "fixed": false },
    { "shape": { "type": "box", "half_extents": [5.0, 0.1, 1.0] },
      "position": [0.0, 1.0, 4.0], "orientation": [0.0, 0.0, 0.13, 0.99],
      "fixed": true }
  ],
  "joints": [
    { "type": "ball", "bodies": [0, 1],
      "anchors": [[0.5, 0.0, 0.0], [-0.25, 0.0, 0.0]] },
    { "type": "ball", "bodies": [-1, 0],
      "anchors": [[-0.5, 3.5, 0.0], [-0.5, 0.25, 0.0]] }
  ],
  "camera": { "position": [6.0, 4.0, 8.0], "target": [0.0, 1.0, 0.0], "fov_y": 1.0 }
}"#;

#[test]
fn full_scene_loads() {
    let scene = Scene::from_json_str(FULL_SCENE).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.settings.substeps, 4);
    assert!(!scene.settings.sleeping);
    assert!(Scene::from_json_str(r#"{"bodies": []}"#).unwrap().settings.sleeping, "sleeping is on by default");
    assert_eq!(scene.settings.iterations, 12);
    assert_eq!(scene.ground.map(|g| g.height), Some(-0.5));
    assert_eq!(scene.bodies.len(), 3);
    // density 500 kg/m³ × 1 × 0.5 × 2 m³.
    assert!((scene.bodies[0].mass - 500.0).abs() < 1e-3);
    assert_eq!(scene.bodies[0].restitution, Some(0.9));
    assert_eq!(scene.bodies[0].friction, Some(0.1));
    assert_eq!(scene.bodies[1].shape, Shape::Sphere { radius: 0.25 });
    assert_eq!(scene.bodies[1].mass, 2.0);
    assert_eq!(scene.bodies[1].restitution, None);
    assert!(scene.bodies[2].fixed);
    assert_eq!(scene.bodies[2].inverse_mass(), 0.0);
    for body in &scene.bodies {
        let q = body.orientation;
        let norm = (q.iter().map(|c| c * c).sum::<f32>()).sqrt();
        assert!((norm - 1.0).abs() < 1e-6, "{q:?}");
    }
    assert_eq!(scene.joints[1].bodies, [WORLD, 0]);
    let camera = scene.camera.expect("camera");
    assert_eq!(camera.fov_y, 1.0);
}

#[test]
fn full_scene_round_trips() {
    let scene = Scene::from_json_str(FULL_SCENE).unwrap();
    let text = scene.to_json();
    let again = Scene::from_json_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(again, scene, "\n{text}");
    assert_eq!(again.to_json(), text, "writing is stable");
    assert!(!text.contains("density"), "{text}");
    assert!(!text.contains("null"), "{text}");
}
