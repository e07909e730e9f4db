//! Scripted input tracks: loading and refusing
//! track files naming the field, events applied at their step and not
//! before, `verlet run --input`, and the built-in `blast` scene with its
//! default track.

use verlet::scenes::{self, sphere_body};
use verlet::track::{Action, Event, Track, TrackError};
use verlet::world::input::Wind;
use verlet::{Scene, Settings};

const FULL: &str = r#"{ "events": [
  { "t": 2.0, "explode": { "centre": [0, 1, -1], "strength": 900, "radius": 6, "falloff": 2 } },
  { "t": 1.0, "impulse": { "body": 7, "impulse": [0, 0, 400], "point": [0.1, 2.0, 0] } },
  { "t": 2.5, "set_pose": { "body": 3, "position": [0, 4, 0], "orientation": [0, 0, 0, 2] } },
  { "t": 2.0, "set_velocity": { "body": 3, "linear": [1, 0, 0] } },
  { "t": 3.0, "fixed": { "body": 0, "fixed": false, "mass": 12.5 } },
  { "t": 0.0, "wind": { "velocity": [8, 0, 0], "duration": 2.0, "gust": 0.3 } },
  { "t": 1.0, "impulse": { "body": 2, "impulse": [1, 0, 0] } }
] }"#;

#[test]
fn a_track_loads_sorted_stably_and_round_trips() {
    let track = Track::from_json_str(FULL).expect("the example loads");
    let times: Vec<f64> = track.events().iter().map(|e| e.t).collect();
    assert_eq!(times, [0.0, 1.0, 1.0, 2.0, 2.0, 2.5, 3.0]);
    let names: Vec<&str> = track.events().iter().map(|e| e.action.name()).collect();
    // equal times keep their file order
    assert_eq!(names, ["wind", "impulse", "impulse", "explode", "set_velocity", "set_pose", "fixed"]);
    assert_eq!(track.events()[1].action, Action::Impulse { body: 7, impulse: [0.0, 0.0, 400.0], point: Some([0.1, 2.0, 0.0]) });
    assert_eq!(track.events()[2].action, Action::Impulse { body: 2, impulse: [1.0, 0.0, 0.0], point: None });
    assert_eq!(track.events()[4].action, Action::SetVelocity { body: 3, linear: [1.0, 0.0, 0.0], angular: [0.0; 3] });
    assert_eq!(track.events()[6].action, Action::Fixed { body: 0, fixed: false, mass: Some(12.5) });
    match &track.events()[0].action {
        Action::Wind { wind, duration } => {
            assert_eq!(*duration, 2.0);
            assert_eq!(*wind, Wind { velocity: [8.0, 0.0, 0.0], gust: 0.3, ..Wind::default() });
        }
        other => panic!("expected the wind first, got {other:?}"),
    }
    assert!(track.check(8).is_ok());
    let again = Track::from_json_str(&track.to_json()).expect("to_json reads back");
    assert_eq!(again.events(), track.events());
    // an empty track is fine
    assert!(Track::from_json_str(r#"{"events": []}"#).unwrap().is_empty());
}

/// Each malformed track and the start of its one-line error.
const BAD: &[(&str, &str)] = &[
    (
        r#"{"events": [{"t": -1, "explode": {"centre": [0,0,0], "strength": 1, "radius": 1}}]}"#,
        "events[0].t: must be a finite time >= 0 s, got -1",
    ),
    (r#"{"events": [{"explode": {"centre": [0,0,0], "strength": 1, "radius": 1}}]}"#, "events[0].t: is required but missing"),
    (
        r#"{"events": [{"t": 1, "impulse": {"body": 0, "impulse": [1, 2]}}]}"#,
        "events[0].impulse.impulse: must have exactly 3 elements, got 2",
    ),
    (r#"{"events": [{"t": 1, "impulse": {"body": 0}}]}"#, "events[0].impulse.impulse: is required but missing"),
    (
        r#"{"events": [{"t": 1, "impulse": {"body": 0, "impulse": [0, 1e39, 0]}}]}"#,
        "events[0].impulse.impulse[1]: must be a finite number",
    ),
    (
        r#"{"events": [{"t": 1, "fixed": {"body": 0, "fixed": true}}, {"t": 1, "explode": {"centre": [0,0,0], "strength": 1e400, "radius": 1}}]}"#,
        "events[1].explode.strength: number out of range",
    ),
    (r#"{"events": [{"t": 1e400, "fixed": {"body": 0, "fixed": true}}]}"#, "events[0].t: number out of range"),
    (
        r#"{"events": [{"t": 1, "explode": {"centre": [0,0,0], "strength": 1, "radius": 0}}]}"#,
        "events[0].explode.radius: must be > 0",
    ),
    (
        r#"{"events": [{"t": 1, "explode": {"centre": [0,0,0], "strength": 1, "radius": 1, "falloff": -1}}]}"#,
        "events[0].explode.falloff: must be >= 0",
    ),
    (r#"{"events": [{"t": 1, "impulse": {"body": -1, "impulse": [0,0,0]}}]}"#, "events[0].impulse.body: invalid value"),
    (
        r#"{"events": [{"t": 1, "impulse": {"body": 0, "impulse": [0,0,0], "spin": 2}}]}"#,
        "events[0].impulse.spin: unknown field `spin`",
    ),
    (r#"{"events": [{"t": 1, "push": {}}]}"#, "events[0].push: unknown field `push`"),
    (r#"{"events": [{"t": 1}]}"#, "events[0]: must have exactly one of impulse, explode"),
    (
        r#"{"events": [{"t": 1, "fixed": {"body": 0, "fixed": true}, "set_velocity": {"body": 0}}]}"#,
        "events[0]: must have exactly one of",
    ),
    (
        r#"{"events": [{"t": 1, "set_pose": {"body": 0, "position": [0,0,0], "orientation": [0,0,0,0]}}]}"#,
        "events[0].set_pose.orientation: must be a non-zero quaternion",
    ),
    // what the step would stop at once as a fault (the scene's own limits)
    (
        r#"{"events": [{"t": 1, "set_pose": {"body": 0, "position": [0,1e7,0], "orientation": [0,0,0,1]}}]}"#,
        "events[0].set_pose.position: lies 1.0000e7 m from the origin; at most 1e6 m",
    ),
    (
        r#"{"events": [{"t": 1, "impulse": {"body": 0, "impulse": [0,1,0], "point": [1e30,0,0]}}]}"#,
        "events[0].impulse.point: lies 1.0000e30 m from the origin",
    ),
    (
        r#"{"events": [{"t": 1, "set_velocity": {"body": 0, "linear": [2e4,0,0]}}]}"#,
        "events[0].set_velocity.linear: moves at 2.0000e4 m/s; at most 1e4 m/s",
    ),
    (
        r#"{"events": [{"t": 1, "wind": {"velocity": [0,0,1e30], "duration": 1}}]}"#,
        "events[0].wind.velocity: moves at 1.0000e30 m/s",
    ),
    (r#"{"events": [{"t": 1, "fixed": {"body": 0, "fixed": "yes"}}]}"#, "events[0].fixed.fixed: invalid type"),
    (r#"{"events": [{"t": 1, "fixed": {"body": 0, "fixed": false, "mass": 0}}]}"#, "events[0].fixed.mass: must be > 0"),
    (r#"{"events": [{"t": 1, "wind": {"velocity": [1,0,0]}}]}"#, "events[0].wind.duration: is required but missing"),
    (r#"{"events": [{"t": 1, "wind": {"velocity": [1,0,0], "duration": 0}}]}"#, "events[0].wind.duration: must be > 0"),
    (
        r#"{"events": [{"t": 1, "wind": {"velocity": [1,0,0], "duration": 1, "gust_period": 0}}]}"#,
        "events[0].wind.gust_period: must be > 0",
    ),
    (r#"{"events": [{"t": 1, "wind": {"velocity": [1,0,0], "duration": 1, "drag": -1}}]}"#, "events[0].wind.drag: must be >= 0"),
    (r#"{"events": [[1, {}]]}"#, "events[0]: invalid type: sequence, expected a JSON object"),
    (r#"{}"#, "events: is required but missing"),
    (r#"{"events": [], "scene": 1}"#, "scene: unknown field `scene`"),
    (r#"[]"#, "track: invalid type: sequence, expected a JSON object"),
    (r#"{"events": [{"t": 1, "fixed": {"body": 0, "fixed": true}}"#, "input track, line 1, column "),
    (r#"{"events": []} {}"#, "input track, line 1, column "),
    ("", "input track, line 1, column 0: malformed JSON"),
];

#[test]
fn malformed_tracks_are_refused_naming_the_field() {
    for (text, want) in BAD {
        let err = Track::from_json_str(text).expect_err(text).to_string();
        assert!(err.starts_with(want), "{text}\n  gave  {err}\n  wanted {want}...");
        assert!(!err.contains('\n'), "not one line: {err}");
    }
}

#[test]
fn bad_body_indices_are_refused_against_the_scene_in_file_order() {
    let text = r#"{"events": [
        {"t": 3, "impulse": {"body": 1, "impulse": [0, 0, 1]}},
        {"t": 2, "fixed": {"body": 41, "fixed": true}},
        {"t": 1, "impulse": {"body": 40, "impulse": [0, 0, 1]}}
    ]}"#;
    let track = Track::from_json_str(text).expect("loads: the body count is the scene's to judge");
    let err = track.check(12).unwrap_err();
    assert_eq!(err.field(), Some("events[1].fixed.body"));
    assert_eq!(err.to_string(), "events[1].fixed.body: no body 41 (the scene has 12 bodies)");
    let err = Track::from_json_str(&text.replace("\"body\": 41", "\"body\": 4")).unwrap().check(12).unwrap_err();
    assert_eq!(err.to_string(), "events[2].impulse.body: no body 40 (the scene has 12 bodies)");
    assert!(track.check(42).is_ok());
    // events built in Rust get the same checks
    let e = Track::new(vec![
        Event { t: 0.0, action: Action::SetVelocity { body: 0, linear: [0.0; 3], angular: [0.0; 3] } },
        Event { t: f64::NAN, action: Action::Fixed { body: 0, fixed: true, mass: None } },
    ])
    .unwrap_err();
    assert_eq!(e.field(), Some("events[1].t"));
    let missing = Track::from_path("/nonexistent/track.json".as_ref()).unwrap_err();
    assert!(matches!(missing, TrackError::Io { .. }), "{missing}");
}

#[test]
fn event_times_map_to_the_step_that_starts_there() {
    let dt = 1.0f32 / 60.0;
    assert_eq!(Track::step_of(0.0, dt), 0);
    assert_eq!(Track::step_of(0.5, dt), 30);
    assert_eq!(Track::step_of(1.0, dt), 60); // 60 x 0.016666668 is a hair above 1
    assert_eq!(Track::step_of(1.0 + 0.9 * dt as f64, dt), 60);
    assert_eq!(Track::step_of(2.0, 0.1), 20);
    let track = Track::from_json_str(
        r#"{"events": [{"t": 0.5, "impulse": {"body": 0, "impulse": [1, 0, 0]}},
                       {"t": 1.0, "wind": {"velocity": [1, 0, 0], "duration": 0.25}}]}"#,
    )
    .unwrap();
    assert_eq!(track.next_input_step(0, dt), Some(30));
    assert_eq!(track.next_input_step(30, dt), Some(30));
    assert_eq!(track.next_input_step(31, dt), Some(60));
    assert_eq!(track.next_input_step(64, dt), Some(64)); // the wind blows over steps 60..75
    assert_eq!(track.next_input_step(74, dt), Some(74));
    assert_eq!(track.next_input_step(75, dt), None);
}

fn free_scene() -> Scene {
    let mut b = sphere_body(0.5, [0.0, 2.0, 0.0]);
    b.linear_velocity = [0.5, 0.0, 0.0];
    Scene {
        settings: Settings { gravity: [0.0; 3], ..Settings::default() },
        ground: None,
        bodies: vec![b],
        joints: vec![],
        camera: None,
    }
}

#[test]
fn an_impulse_event_at_half_a_second_acts_at_step_30_and_not_before() {
    let scene = free_scene();
    let mass = scene.bodies[0].mass;
    let track = Track::from_json_str(r#"{"events": [{"t": 0.5, "impulse": {"body": 0, "impulse": [0, 0, 100]}}]}"#).unwrap();
    track.check(scene.bodies.len()).unwrap();
    let Some(mut world) = crate::common::world(&scene) else { return };
    let mut v_prev = world.read_state().unwrap()[0].linear_velocity;
    for step in 0..40u64 {
        assert_eq!(world.step_count(), step);
        let acted = track.apply(&mut world).unwrap();
        world.step(1).unwrap();
        let v = world.read_state().unwrap()[0].linear_velocity;
        let dvz = v[2] - v_prev[2];
        if step == 30 {
            assert_eq!(acted, 1);
            let want = 100.0 / mass;
            assert!((dvz - want).abs() < 0.01 * want, "step 30: dv_z {dvz}, want {want}");
            eprintln!("impulse event: step 30 (t = {:.4} s), dv_z {dvz:.5} m/s (J/m = {want:.5})", 30.0 / 60.0);
        } else {
            assert_eq!(acted, 0, "step {step}");
            assert!(dvz.abs() < 1e-5, "step {step}: dv_z {dvz} with no event due");
        }
        assert!((v[0] - 0.5).abs() < 1e-4, "step {step}: v_x {}", v[0]);
        v_prev = v;
    }
}

#[test]
fn a_wind_event_blows_over_its_duration_only() {
    let scene = free_scene();
    let track = Track::from_json_str(r#"{"events": [{"t": 0.1, "wind": {"velocity": [0, 0, 20], "duration": 0.25}}]}"#).unwrap();
    let Some(mut world) = crate::common::world(&scene) else { return };
    let mut v_prev = world.read_state().unwrap()[0].linear_velocity;
    let mut pushed = Vec::new();
    for step in 0..30u64 {
        track.apply(&mut world).unwrap();
        world.step(1).unwrap();
        let v = world.read_state().unwrap()[0].linear_velocity;
        if v[2] - v_prev[2] > 1e-5 {
            pushed.push(step);
        }
        v_prev = v;
    }
    // 0.1 s is step 6; 0.35 s is step 21
    assert_eq!(pushed, (6..21).collect::<Vec<u64>>());
}

// ---------------------------------------------------------------------------
// The command line
// ---------------------------------------------------------------------------

use crate::common::{no_adapter, temp_path, verlet};

/// Positions after `steps` steps of `verlet run --builtin blast [extra...]`,
/// or None when there is no adapter.
fn blast_positions(name: &str, steps: u32, extra: &[&str]) -> Option<Vec<[f32; 3]>> {
    let state = temp_path(name);
    let steps = steps.to_string();
    let mut args = vec!["run", "--builtin", "blast", "--steps", &steps, "--state-out", state.to_str().unwrap()];
    args.extend_from_slice(extra);
    let out = verlet(&args);
    if no_adapter(&out) {
        return None;
    }
    assert!(out.status.success(), "verlet {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).unwrap();
    let _ = std::fs::remove_file(&state);
    let bodies = doc["bodies"].as_array().unwrap();
    Some(
        bodies
            .iter()
            .map(|b| {
                let p = b["position"].as_array().unwrap();
                [0, 1, 2].map(|k| p[k].as_f64().unwrap() as f32)
            })
            .collect(),
    )
}

fn dist(a: [f32; 3], b: [f32; 3]) -> f32 {
    glam::Vec3::from(a).distance(glam::Vec3::from(b))
}

#[test]
fn blast_stands_for_a_second_then_its_default_track_blows_it_outward() {
    let start: Vec<[f32; 3]> = scenes::blast(10).bodies.iter().map(|b| b.position).collect();
    assert_eq!(start.len(), 60);
    let centre = match scenes::blast_track().events() {
        [Event { t, action: Action::Explode { centre, .. } }] => {
            assert_eq!(*t, 1.0);
            *centre
        }
        other => panic!("blast's track: {other:?}"),
    };
    let Some(before) = blast_positions("55", 55, &[]) else { return };
    let Some(after) = blast_positions("120", 120, &[]) else { return };
    assert_eq!((before.len(), after.len()), (60, 60));
    // at 0.92 s the wall still stands where it was built
    let settled = start.iter().zip(&before).map(|(a, b)| dist(*a, *b)).fold(0.0f32, f32::max);
    eprintln!("blast: largest move in the first 55 steps {settled:.4} m");
    assert!(settled < 0.02, "the wall moved {settled} m before the explosion");
    // at 2 s every box is farther from the explosion, the wall blown back
    let mut mean_back = 0.0;
    for (k, (b, a)) in before.iter().zip(&after).enumerate() {
        let out = dist(*a, centre) - dist(*b, centre);
        assert!(out > 0.3, "box {k} moved only {out} m away from the explosion: {b:?} -> {a:?}");
        assert!(a[2] > b[2] + 0.3, "box {k} was not blown back (z {} -> {})", b[2], a[2]);
        mean_back += (a[2] - b[2]) / 60.0;
    }
    eprintln!("blast: boxes blown back {mean_back:.2} m on average by 2 s");
    assert!(mean_back > 1.0, "mean push back {mean_back} m");
}

#[test]
fn an_input_file_replaces_blasts_default_track() {
    let track = temp_path("calm.json");
    std::fs::write(&track, r#"{"events": [{"t": 0.5, "impulse": {"body": 59, "impulse": [0, 0, 200]}}]}"#).unwrap();
    let start: Vec<[f32; 3]> = scenes::blast(10).bodies.iter().map(|b| b.position).collect();
    let Some(after) = blast_positions("calm", 90, &["--input", track.to_str().unwrap()]) else { return };
    let _ = std::fs::remove_file(&track);
    // no explosion at 1 s: only the pushed top corner box (and its column,
    // dragged by friction) moves; the other nine columns stand
    let moved: Vec<usize> = (0..60).filter(|&k| dist(start[k], after[k]) > 0.05).collect();
    eprintln!("calm track: boxes moved {moved:?}");
    assert!(moved.contains(&59), "the pushed box did not move: {:?} -> {:?}", start[59], after[59]);
    assert!(moved.iter().all(|&k| k % 10 == 9), "boxes outside the pushed column moved: {moved:?}");
}

#[test]
fn the_command_line_refuses_a_bad_track_before_running() {
    let track = temp_path("bad.json");
    for (text, want) in [
        (
            r#"{"events": [{"t": 1, "explode": {"centre": [0, 0], "strength": 1, "radius": 1}}]}"#,
            "error: events[0].explode.centre: must have exactly 3 elements, got 2",
        ),
        (
            r#"{"events": [{"t": 1, "impulse": {"body": 60, "impulse": [0, 0, 1]}}]}"#,
            "error: events[0].impulse.body: no body 60 (the scene has 60 bodies)",
        ),
    ] {
        std::fs::write(&track, text).unwrap();
        let state = temp_path("never.json");
        let out = verlet(&[
            "run",
            "--builtin",
            "blast",
            "--steps",
            "10",
            "--input",
            track.to_str().unwrap(),
            "--state-out",
            state.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "a bad track ran");
        assert_eq!(stderr.trim_end().lines().count(), 1, "not one line: {stderr}");
        assert!(stderr.starts_with(want), "stderr {stderr:?}, wanted {want}...");
        assert!(!state.exists(), "a state was written from a bad track");
    }
    let out = verlet(&["run", "--builtin", "drop", "--steps", "1", "--input", "/nonexistent/track.json"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("error: /nonexistent/track.json: cannot read input track"), "{stderr}");
    let _ = std::fs::remove_file(&track);
}
