//! A property test of the scene loader: arbitrary bytes,
//! and arbitrary mutations of a valid scene (of its text and of its JSON
//! tree), never make `Scene::from_json_str` panic. Each input either loads
//! into a scene that passes `validate()` and survives a write/read round
//! trip, or is refused with one line that starts with a field path
//! (`bodies[3].shape.half_extents[1]: ...`) or with the JSON position
//! (`line L, column C: ...`).

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use serde_json::{Map, Value};
use verlet::scene::{Scene, SceneError};

/// Uses every field of the format, optional ones included.
const VALID: &str = r#"{
  "settings": { "dt": 0.016666668, "gravity": [0.0, -9.81, 0.0], "iterations": 8,
    "relaxation": 0.5, "linear_damping": 0.0, "angular_damping": 0.0,
    "restitution": 0.2, "friction": 0.5, "substeps": 2 },
  "ground": { "height": 0.0 },
  "bodies": [
    { "shape": { "type": "box", "half_extents": [0.5, 0.5, 0.5] },
      "position": [0.0, 3.0, 0.0], "orientation": [0.0, 0.0, 0.0, 1.0],
      "linear_velocity": [0.0, 0.0, 0.0], "angular_velocity": [0.0, 0.0, 0.0],
      "density": 1000.0, "restitution": 0.3, "friction": 0.4 },
    { "shape": { "type": "sphere", "radius": 0.25 }, "position": [1.0, 3.0, 0.0], "mass": 2.0 },
    { "shape": { "type": "box", "half_extents": [5.0, 0.1, 1.0] },
      "position": [0.0, 1.0, 4.0], "orientation": [0.0, 0.0, 0.13, 0.99], "fixed": true }
  ],
  "joints": [
    { "type": "ball", "bodies": [0, 1], "anchors": [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] },
    { "type": "ball", "bodies": [0, -1], "anchors": [[-0.5, 0.5, 0.0], [-0.5, 3.5, 0.0]] }
  ],
  "camera": { "position": [6.0, 4.0, 8.0], "target": [0.0, 1.0, 0.0], "fov_y": 0.8 }
}"#;

/// The top-level names a field path can start with; `scene` is the whole
/// document (a top-level value that is not an object, say).
const ROOTS: &[&str] = &["scene", "settings", "ground", "bodies", "joints", "camera"];

/// Names and tokens that steer mutations towards what the loader knows.
const KEYS: &[&str] = &[
    "settings",
    "dt",
    "gravity",
    "iterations",
    "relaxation",
    "linear_damping",
    "angular_damping",
    "restitution",
    "friction",
    "substeps",
    "sleeping",
    "ground",
    "height",
    "bodies",
    "shape",
    "type",
    "box",
    "sphere",
    "half_extents",
    "radius",
    "position",
    "orientation",
    "linear_velocity",
    "angular_velocity",
    "density",
    "mass",
    "fixed",
    "joints",
    "ball",
    "anchors",
    "camera",
    "target",
    "fov_y",
    "",
    "x",
    "\n",
    "bodies[0]",
];

const TOKENS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "\\",
    "-",
    ".",
    "e",
    "E",
    "0",
    "1",
    "-1",
    "1e400",
    "-1e400",
    "1e39",
    "NaN",
    "Infinity",
    "null",
    "true",
    "false",
    "4294967296",
    "18446744073709551616",
    "-0",
    "1e-45",
    "\"box\"",
    "\"ball\"",
    "\"sphere\"",
    "\u{0}",
    "\u{feff}",
    "é",
    "\n",
    " ",
];

/// Whether an error message has the form the contract asks for.
fn well_formed(error: &SceneError) -> Result<(), String> {
    let message = error.to_string();
    if message.contains('\n') || message.contains('\r') {
        return Err(format!("message is not one line: {message:?}"));
    }
    match error {
        SceneError::Invalid { field, .. } => {
            let root_ok = ROOTS.iter().any(|root| {
                field.strip_prefix(root).is_some_and(|rest| rest.is_empty() || rest.starts_with('[') || rest.starts_with('.'))
            });
            // an unknown top-level key is itself the path: `frobnicate: unknown field ...`
            let unknown_key = message.starts_with(&format!("{field}: unknown field `"));
            if !root_ok && !unknown_key {
                return Err(format!("field path {field:?} does not start at the top of the scene: {message:?}"));
            }
            if !message.starts_with(&format!("{field}: ")) {
                return Err(format!("message does not start with its field path {field:?}: {message:?}"));
            }
        }
        SceneError::Syntax { line, column, .. } => {
            if !message.starts_with(&format!("line {line}, column {column}: ")) {
                return Err(format!("syntax error does not start with its position: {message:?}"));
            }
        }
        SceneError::Io { .. } => return Err(format!("an I/O error from text: {message:?}")),
        SceneError::SceneGiven(_) => return Err(format!("a track's error from a scene: {message:?}")),
    }
    Ok(())
}

/// The property: no panic, and a valid scene or a well-formed refusal.
fn check(text: &str) -> Result<Outcome, TestCaseError> {
    let outcome = std::panic::catch_unwind(|| Scene::from_json_str(text));
    let result = outcome.map_err(|_| TestCaseError::fail(format!("from_json_str panicked on {text:?}")))?;
    match result {
        Ok(scene) => {
            if let Err(e) = scene.validate() {
                return Err(TestCaseError::fail(format!("loaded a scene that validate() refuses ({e}) from {text:?}")));
            }
            let written = scene.to_json();
            match Scene::from_json_str(&written) {
                Ok(again) if again == scene => {}
                Ok(_) => return Err(TestCaseError::fail(format!("round trip changed the scene of {text:?}: {written}"))),
                Err(e) => return Err(TestCaseError::fail(format!("written scene does not load ({e}): {written}"))),
            }
            Ok(Outcome::Loaded)
        }
        Err(e) => {
            well_formed(&e).map_err(|why| TestCaseError::fail(format!("{why} (input {text:?})")))?;
            Ok(if e.field().is_some() { Outcome::Field } else { Outcome::Position })
        }
    }
}

/// How an input ended: loaded, refused naming a field, refused naming a
/// position in the text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    Loaded,
    Field,
    Position,
}

fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() })
}

/// Runs the property on `cases` inputs; returns how many ended each way
/// (loaded, refused naming a field, refused naming a position).
fn run(cases: u32, strategy: impl Strategy<Value = String>) -> [usize; 3] {
    let counts: [std::sync::atomic::AtomicUsize; 3] = Default::default();
    runner(cases)
        .run(&strategy, |text| {
            let outcome = check(&text)?;
            counts[outcome as usize].fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let counts = counts.map(|c| c.into_inner());
    eprintln!("loaded {}, refused naming a field {}, refused naming a position {}", counts[0], counts[1], counts[2]);
    counts
}

#[test]
fn the_valid_scene_loads() {
    assert_eq!(check(VALID).unwrap(), Outcome::Loaded);
    assert_eq!(Scene::from_json_str(VALID).unwrap().bodies.len(), 3);
}

#[test]
fn arbitrary_bytes_never_panic() {
    run(1000, proptest::collection::vec(any::<u8>(), 0..300).prop_map(|b| String::from_utf8_lossy(&b).into_owned()));
}

/// Files of arbitrary bytes, most not UTF-8: `from_path` refuses them
/// naming the file, or the field or position, on one line.
#[test]
fn arbitrary_files_never_panic() {
    let dir = std::env::temp_dir().join(format!("verlet-scene-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("garbage.json");
    runner(100)
        .run(&proptest::collection::vec(any::<u8>(), 0..200), |bytes| {
            std::fs::write(&file, &bytes).unwrap();
            let outcome = std::panic::catch_unwind(|| Scene::from_path(&file));
            let result = outcome.map_err(|_| TestCaseError::fail(format!("from_path panicked on {bytes:?}")))?;
            match result {
                Ok(scene) => prop_assert!(scene.validate().is_ok()),
                Err(e @ SceneError::Io { .. }) => {
                    let message = e.to_string();
                    prop_assert!(message.contains("garbage.json") && !message.contains('\n'), "{}", message);
                }
                Err(e) => prop_assert!(well_formed(&e).is_ok(), "{:?}", well_formed(&e)),
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn arbitrary_strings_never_panic() {
    run(500, any::<String>());
}

/// One edit of a text: at a position (a fraction of its length, so it always
/// lands inside), delete a span, insert a token, overwrite a byte, duplicate
/// a span, or cut the rest.
#[derive(Clone, Debug)]
enum TextEdit {
    Delete(f64, usize),
    Insert(f64, &'static str),
    Byte(f64, u8),
    Duplicate(f64, usize),
    Truncate(f64),
}

fn text_edit() -> impl Strategy<Value = TextEdit> {
    let at = 0.0..1.0f64;
    prop_oneof![
        (at.clone(), 1..20usize).prop_map(|(a, n)| TextEdit::Delete(a, n)),
        (at.clone(), proptest::sample::select(TOKENS)).prop_map(|(a, t)| TextEdit::Insert(a, t)),
        (at.clone(), any::<u8>()).prop_map(|(a, b)| TextEdit::Byte(a, b)),
        (at.clone(), 1..40usize).prop_map(|(a, n)| TextEdit::Duplicate(a, n)),
        at.prop_map(TextEdit::Truncate),
    ]
}

fn apply_text(text: &str, edits: &[TextEdit]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    let pos = |len: usize, a: f64| ((len as f64 * a) as usize).min(len);
    for edit in edits {
        let len = bytes.len();
        match *edit {
            TextEdit::Delete(a, n) => {
                let p = pos(len, a);
                bytes.drain(p..(p + n).min(len));
            }
            TextEdit::Insert(a, t) => {
                let p = pos(len, a);
                bytes.splice(p..p, t.bytes());
            }
            TextEdit::Byte(a, b) => {
                if len > 0 {
                    let p = pos(len - 1, a);
                    bytes[p] = b;
                }
            }
            TextEdit::Duplicate(a, n) => {
                let p = pos(len, a);
                let span: Vec<u8> = bytes[p..(p + n).min(len)].to_vec();
                bytes.splice(p..p, span);
            }
            TextEdit::Truncate(a) => bytes.truncate(pos(len, a)),
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

#[test]
fn text_mutations_of_a_valid_scene_never_panic() {
    let [loaded, field, position] =
        run(1500, proptest::collection::vec(text_edit(), 1..6).prop_map(|edits| apply_text(VALID, &edits)));
    assert!(field > 0 && position > 0, "the edits should reach both kinds of refusal ({loaded} loaded)");
}

/// JSON values with a bias to what breaks a loader: extreme and
/// non-integral numbers where integers belong, negative indices, huge
/// counts, wrong types, short and long vectors.
fn json_value() -> impl Strategy<Value = Value> {
    let number = prop_oneof![
        proptest::sample::select(vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            2.0,
            3.0,
            1e-45,
            1e-300,
            3.5e38,
            1e39,
            1e300,
            -1e300,
            4294967296.0,
            0.1,
            256.0,
            257.0,
            65.0,
            1e6,
            -2.0,
        ])
        .prop_map(|x: f64| serde_json::json!(x)),
        any::<f64>().prop_map(|x| serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)),
        any::<i64>().prop_map(|x| serde_json::json!(x)),
        any::<u64>().prop_map(|x| serde_json::json!(x)),
        (-3i64..5).prop_map(|x| serde_json::json!(x)),
    ];
    let leaf = prop_oneof![
        4 => number,
        1 => Just(Value::Null),
        1 => any::<bool>().prop_map(Value::Bool),
        2 => proptest::sample::select(KEYS).prop_map(|s| Value::String(s.to_string())),
        1 => any::<String>().prop_map(Value::String),
    ];
    leaf.prop_recursive(3, 24, 5, |inner| {
        prop_oneof![
            proptest::collection::vec(inner.clone(), 0..6).prop_map(Value::Array),
            proptest::collection::vec((proptest::sample::select(KEYS), inner), 0..4)
                .prop_map(|kv| Value::Object(kv.into_iter().map(|(k, v)| (k.to_string(), v)).collect::<Map<_, _>>())),
        ]
    })
}

/// One edit of the JSON tree at the node a list of choices leads to.
#[derive(Clone, Debug)]
enum TreeEdit {
    Replace(Vec<usize>, Value),
    Remove(Vec<usize>),
    AddKey(Vec<usize>, &'static str, Value),
    DuplicateElement(Vec<usize>),
}

fn choices() -> impl Strategy<Value = Vec<usize>> {
    proptest::collection::vec(any::<usize>(), 0..6)
}

fn tree_edit() -> impl Strategy<Value = TreeEdit> {
    prop_oneof![
        4 => (choices(), json_value()).prop_map(|(p, v)| TreeEdit::Replace(p, v)),
        2 => choices().prop_map(TreeEdit::Remove),
        2 => (choices(), proptest::sample::select(KEYS), json_value()).prop_map(|(p, k, v)| TreeEdit::AddKey(p, k, v)),
        1 => choices().prop_map(TreeEdit::DuplicateElement),
    ]
}

/// The node the choices lead to, descending while there are choices left
/// and the node has children.
fn node<'a>(v: &'a mut Value, path: &[usize]) -> &'a mut Value {
    let Some((&c, rest)) = path.split_first() else { return v };
    let n = match &*v {
        Value::Object(map) => map.len(),
        Value::Array(items) => items.len(),
        _ => 0,
    };
    if n == 0 {
        return v;
    }
    match v {
        Value::Object(map) => node(map.values_mut().nth(c % n).unwrap(), rest),
        Value::Array(items) => node(&mut items[c % n], rest),
        _ => unreachable!(),
    }
}

fn apply_tree(edits: &[TreeEdit]) -> String {
    let mut doc: Value = serde_json::from_str(VALID).unwrap();
    for edit in edits {
        match edit {
            TreeEdit::Replace(path, value) => *node(&mut doc, path) = value.clone(),
            TreeEdit::Remove(path) => {
                // remove a child of the node the path leads to
                let (head, last) = path.split_at(path.len().saturating_sub(1));
                let c = last.first().copied().unwrap_or(0);
                match node(&mut doc, head) {
                    Value::Object(map) if !map.is_empty() => {
                        let key = map.keys().nth(c % map.len()).unwrap().clone();
                        map.remove(&key);
                    }
                    Value::Array(items) if !items.is_empty() => {
                        let n = items.len();
                        items.remove(c % n);
                    }
                    _ => {}
                }
            }
            TreeEdit::AddKey(path, key, value) => {
                if let Value::Object(map) = node(&mut doc, path) {
                    map.insert(key.to_string(), value.clone());
                }
            }
            TreeEdit::DuplicateElement(path) => {
                if let Value::Array(items) = node(&mut doc, path) {
                    if let Some(first) = items.first().cloned() {
                        items.push(first);
                    }
                }
            }
        }
    }
    serde_json::to_string_pretty(&doc).unwrap()
}

#[test]
fn tree_mutations_of_a_valid_scene_never_panic() {
    let [loaded, field, position] = run(2000, proptest::collection::vec(tree_edit(), 1..4).prop_map(|edits| apply_tree(&edits)));
    assert!(loaded > 0 && field > 1000, "the edits should mostly reach the checks of values");
    assert_eq!(position, 0, "a tree written by serde_json is always well-formed JSON");
}

/// Values the tree mutations cannot write (serde_json holds no NaN, no
/// infinity and no number beyond f64), spliced in as text at every number
/// of the valid scene in turn.
#[test]
fn every_number_replaced_by_an_unusable_literal_is_refused() {
    let literals = ["NaN", "Infinity", "-Infinity", "1e400", "-1e400", "1e39", "\"1\"", "[]", "{}", "null", "true"];
    let number = |b: u8| b.is_ascii_digit() || b == b'-' || b == b'.' || b == b'e' || b == b'E';
    let bytes = VALID.as_bytes();
    let mut spans = Vec::new();
    let mut k = 0;
    while k < bytes.len() {
        if number(bytes[k]) && (bytes[k].is_ascii_digit() || bytes[k] == b'-') && !bytes[k - 1].is_ascii_alphabetic() {
            let start = k;
            while k < bytes.len() && number(bytes[k]) {
                k += 1;
            }
            spans.push(start..k);
        } else {
            k += 1;
        }
    }
    assert!(spans.len() > 60, "found only {} numbers", spans.len());
    let mut loaded = 0;
    for span in &spans {
        for literal in literals {
            let text = format!("{}{literal}{}", &VALID[..span.start], &VALID[span.end..]);
            check(&text).unwrap_or_else(|e| panic!("{e}"));
            if Scene::from_json_str(&text).is_ok() {
                // `null` for an optional field means absent; nothing else may load
                assert_eq!(literal, "null", "{text}");
                loaded += 1;
            }
        }
    }
    assert!(loaded < spans.len(), "{loaded} of {} nulls loaded", spans.len());
}
