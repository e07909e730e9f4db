//! Careless and hostile use: every case is refused with a
//! non-zero exit, no panic, a message naming the flag, field or file, and
//! nothing of the user's destroyed or half-written. Refusals that must come
//! before any scene is built are timed (a generous bound: it asserts that no
//! work was done, not a speed). Every child runs under a 4 GB address-space
//! cap, so a regression cannot take the machine's memory.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::common::{no_adapter, temp_path, verlet};
use verlet::scene::Scene;
use verlet::scenes;

/// Refusals that must happen before anything is built finish within this.
const QUICK: Duration = Duration::from_secs(5);

/// Runs `verlet args` under `ulimit -v` (4 GB), with `env` set; returns the
/// output and how long it took.
fn capped_env(args: &[&str], env: &[(&str, &str)]) -> (Output, Duration) {
    capped_env_without(args, env, &[])
}

/// As `capped_env`, with the variables named in `unset` removed.
fn capped_env_without(args: &[&str], env: &[(&str, &str)], unset: &[&str]) -> (Output, Duration) {
    let started = Instant::now();
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg("ulimit -v 4000000 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_verlet"))
        .args(args)
        .envs(env.iter().copied());
    for var in unset {
        command.env_remove(var);
    }
    let out = command.output().expect("sh runs verlet");
    (out, started.elapsed())
}

fn capped(args: &[&str]) -> (Output, Duration) {
    capped_env(args, &[])
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The last line of stderr (Mesa may warn first), which must be the error.
fn reason(out: &Output) -> String {
    stderr(out).trim_end().lines().last().unwrap_or_default().to_string()
}

/// A refusal: non-zero exit, no panic, an `error:` line containing every
/// one of `wanted`.
fn assert_refused(args: &[&str], out: &Output, wanted: &[&str]) {
    let err = stderr(out);
    assert!(!out.status.success(), "{args:?}: exit status 0; stderr {err:?}");
    assert!(!err.contains("panicked"), "{args:?}: panicked: {err}");
    let line = reason(out);
    assert!(line.starts_with("error: "), "{args:?}: last line {line:?}");
    for w in wanted {
        assert!(line.contains(w), "{args:?}: expected {w:?} in {line:?}");
    }
}

/// A refusal that must come before anything is built.
fn assert_refused_quickly(args: &[&str], wanted: &[&str]) {
    let (out, took) = capped(args);
    assert_refused(args, &out, wanted);
    assert!(took < QUICK, "{args:?}: refused only after {took:?}");
}

fn s(p: &Path) -> &str {
    p.to_str().expect("temp paths are UTF-8")
}

/// A directory under the temp dir holding the drop scene as `scene.json`.
fn workdir(name: &str) -> (PathBuf, PathBuf, Vec<u8>) {
    let dir = temp_path(name);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.json");
    let text = scenes::drop().to_json().into_bytes();
    std::fs::write(&scene, &text).unwrap();
    (dir, scene, text)
}

/// A bench of `cases` as short as it runs: no peer, 2 steps, 1 repetition,
/// no profile, no settling.
fn quick_bench(cases: &str) -> [&str; 12] {
    ["bench", "--no-peer", "--cases", cases, "--steps", "2", "--reps", "1", "--profile-steps", "0", "--settle-steps", "0"]
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

// ---------------------------------------------------------------------------
// 1. No crash or memory blow-up from a flag
// ---------------------------------------------------------------------------

#[test]
fn huge_counts_are_refused_before_anything_is_built() {
    for args in [
        &["run", "--builtin", "cubes", "--count", "4294967296", "--steps", "1"][..],
        &["run", "--builtin", "pyramid", "--count", "100000", "--steps", "1"],
        &["run", "--builtin", "cubes", "--count", "10000000", "--steps", "1"],
        &["run", "--builtin", "ragdoll", "--count", "18446744073709551615", "--steps", "1"],
        &["scene", "pyramid", "--count", "100000"],
        &["scene", "cubes", "--count", "4294967296"],
        &["scene", "blast", "--count", "18446744073709551615"],
    ] {
        assert_refused_quickly(args, &["--count", "1048576"]);
    }
    // the body count, worked out without building, is named
    assert_refused_quickly(&["scene", "pyramid", "--count", "100000"], &["5000050000 bodies"]);
    assert_refused_quickly(
        &["bench", "--cases", "pyramid:100000", "--steps", "1", "--reps", "1", "--profile-steps", "0"],
        &["--cases", "pyramid:100000", "5000050000"],
    );
}

#[test]
fn body_counts_are_worked_out_exactly_without_building() {
    for &name in scenes::NAMES {
        for count in [None, Some(1), Some(2), Some(3), Some(7), Some(30)] {
            let Some(scene) = scenes::by_name(name, count, 1) else { panic!("{name}") };
            assert_eq!(scenes::body_count(name, count), Some(scene.bodies.len() as u64), "{name} {count:?}");
        }
    }
    assert_eq!(scenes::body_count("pyramid", Some(usize::MAX)), Some(u64::MAX / 2), "saturates");
    assert_eq!(scenes::body_count("nonsense", Some(3)), None);
}

#[test]
fn a_count_beyond_the_adapter_is_refused_before_the_scene_is_built() {
    let Some(gpu) = crate::common::gpu() else { return };
    let max = verlet::world::max_bodies(&gpu);
    let count = (max + 1).to_string();
    let args = ["run", "--builtin", "chain", "--count", &count, "--steps", "1"];
    let (out, took) = capped(&args);
    assert_refused(&args, &out, &["--count", &count, &max.to_string(), "too large"]);
    assert!(took < QUICK, "refused only after {took:?}");
}

#[test]
fn built_in_scenes_refuse_counts_they_cannot_make() {
    for (args, wanted) in [
        (&["scene", "chain", "--count", "0"][..], "--count"),
        (&["scene", "hanging", "--count", "1"], "--count"),
        (&["scene", "cubes", "--count", "0"], "--count"),
        (&["run", "--builtin", "bridge", "--count", "0", "--steps", "1"], "--count"),
        (&["bench", "--cases", "chain:0"], "--cases"),
        (&["bench", "--cases", "chain", "--iterations", "0"], "--iterations"),
        (&["bench", "--cases", "chain", "--iterations", "257"], "--iterations"),
    ] {
        assert_refused_quickly(args, &[wanted]);
    }
    // what `verlet scene` prints, `verlet run` takes: every scene at its smallest count loads
    for &name in scenes::NAMES {
        let (out, _) = capped(&["scene", name, "--count", if name == "hanging" { "2" } else { "1" }]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        Scene::from_json_str(&String::from_utf8_lossy(&out.stdout)).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

// ---------------------------------------------------------------------------
// 2. A user's files are never destroyed
// ---------------------------------------------------------------------------

#[test]
fn outputs_that_are_inputs_or_each_other_are_refused() {
    let (dir, scene, original) = workdir("clash");
    let track = dir.join("track.json");
    let track_text = br#"{"events": []}"#;
    std::fs::write(&track, track_text).unwrap();
    let dot_scene = format!("{}/./scene.json", s(&dir));
    let out_csv = dir.join("out.csv");
    let (sc, tr, oc) = (s(&scene), s(&track), s(&out_csv));
    let plot = format!("{}/out.svg", s(&dir));
    let before = listing(&dir);
    for (args, wanted) in [
        (vec!["run", sc, "--steps", "1", "--state-out", sc], vec!["--state-out", "scene file"]),
        (vec!["run", sc, "--steps", "1", "--trace", &dot_scene], vec!["--trace", "scene file"]),
        (vec!["run", sc, "--steps", "1", "--gif", sc], vec!["--gif", "scene file"]),
        (vec!["run", sc, "--steps", "1", "--input", tr, "--trace", tr], vec!["--trace", "--input"]),
        (vec!["run", sc, "--steps", "1", "--trace", oc, "--state-out", oc], vec!["--state-out", "--trace"]),
        (vec!["run", sc, "--steps", "1", "--gif", oc, "--contact-sheet", oc], vec!["--contact-sheet", "--gif"]),
        (vec!["bench", "--cases", "chain", "--json", oc, "--csv", oc], vec!["--csv", "--json"]),
        (vec!["bench", "--cases", "chain", "--csv", &plot, "--plot", &plot], vec!["--plot", "--csv"]),
    ] {
        assert_refused_quickly(&args, &wanted.iter().map(|w| &**w).collect::<Vec<_>>());
        assert_eq!(std::fs::read(&scene).unwrap(), original, "{args:?}: the scene changed");
        assert_eq!(std::fs::read(&track).unwrap(), track_text, "{args:?}: the track changed");
        assert_eq!(listing(&dir), before, "{args:?}: files were left behind");
    }
    // a symbolic link to the scene is the scene
    #[cfg(unix)]
    {
        let link = dir.join("link.json");
        std::os::unix::fs::symlink(&scene, &link).unwrap();
        assert_refused_quickly(&["run", sc, "--steps", "1", "--state-out", s(&link)], &["--state-out", "scene file"]);
        assert_eq!(std::fs::read(&scene).unwrap(), original);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unusable_output_paths_are_refused_before_the_first_step() {
    let (dir, _, _) = workdir("paths");
    let file = dir.join("scene.json");
    let inside_file = format!("{}/x.json", s(&file));
    let missing = format!("{}/no/such/dir/x.json", s(&dir));
    let missing_svg = format!("{}/no/such/dir/x.svg", s(&dir));
    // a long run: refused at once, not after it
    let long = ["run", "--builtin", "cubes", "--count", "1000", "--steps", "1000000"];
    for (flag, path, why) in [
        ("--state-out", missing.as_str(), "no directory"),
        ("--trace", s(&dir), "directory"),
        ("--gif", inside_file.as_str(), "no directory"),
        ("--contact-sheet", missing.as_str(), "no directory"),
    ] {
        let mut args = long.to_vec();
        args.extend([flag, path]);
        assert_refused_quickly(&args, &[flag, path, why]);
    }
    for (flag, args) in [
        ("--json", vec!["bench", "--cases", "chain", "--json", &missing]),
        ("--csv", vec!["bench", "--cases", "chain", "--csv", s(&dir)]),
        ("--plot", vec!["bench", "--cases", "chain", "--plot", &missing_svg]),
    ] {
        assert_refused_quickly(&args, &[flag]);
        assert!(!Path::new(&missing).exists());
    }
    // the chart is SVG: another name is refused, not written as SVG under it
    let png = format!("{}/chart.png", s(&dir));
    assert_refused_quickly(&["bench", "--cases", "chain", "--plot", &png], &["--plot", "chart.png", ".svg"]);
    assert_eq!(listing(&dir), ["scene.json"], "nothing created");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene whose run fails a few steps in: body 1 of a row, placed 999 km
/// out and flying outward at 9 km/s (each within what a scene may ask),
/// passes 1000 km (`limits::MAX_DISTANCE`) at about step 6, and the
/// numerical fault stops the run.
fn flying_scene() -> String {
    let mut scene = scenes::stack(0);
    scene.bodies = (0..3).map(|k| scenes::box_body([0.5; 3], [10.0 * k as f32, 0.5, 0.0])).collect();
    scene.bodies[1].position = [0.0, 0.5, 999_000.0];
    scene.bodies[1].linear_velocity = [0.0, 0.0, 9_000.0];
    scene.to_json()
}

#[test]
fn a_failed_run_keeps_the_old_outputs_and_says_what_it_kept() {
    let (dir, _, _) = workdir("failed");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, flying_scene()).unwrap();
    let (trace, state, frames) = (dir.join("trace.csv"), dir.join("state.json"), dir.join("frames"));
    std::fs::write(&trace, "an old trace\n").unwrap();
    std::fs::write(&state, "an old state\n").unwrap();
    let args = [
        "run",
        s(&bad),
        "--steps",
        "30",
        "--every",
        "10",
        "--trace",
        s(&trace),
        "--state-out",
        s(&state),
        "--frames",
        s(&frames),
        "--width",
        "32",
        "--height",
        "24",
    ];
    let (out, _) = capped(&args);
    if no_adapter(&out) {
        return;
    }
    let err = stderr(&out);
    assert_refused(&args, &out, &["body 1 became absurd"]);
    assert_eq!(std::fs::read_to_string(&trace).unwrap(), "an old trace\n", "the old trace was replaced");
    assert_eq!(std::fs::read_to_string(&state).unwrap(), "an old state\n", "the old state was replaced");
    let partial = dir.join("trace.csv.partial");
    let rows = std::fs::read_to_string(&partial).expect("the rows before the fault are kept");
    assert!(rows.starts_with(verlet::output::TRACE_HEADER), "{rows}");
    assert!(err.contains("note: --trace") && err.contains(s(&partial)), "{err}");
    assert!(err.contains("note: --frames: 1 frames") && err.contains("note: --state-out"), "{err}");
    // no half-written or temporary file anywhere
    assert_eq!(listing(&dir), ["bad.json", "frames", "scene.json", "state.json", "trace.csv", "trace.csv.partial"]);
    assert_eq!(listing(&frames), ["frame_000000.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_partial_trace_of_a_failed_run_replaces_no_file() {
    let (dir, _, _) = workdir("partial");
    // the scene, or another output, where the partial rows would go: refused before anything runs
    let scene = dir.join("t.csv.partial");
    let text = flying_scene();
    std::fs::write(&scene, &text).unwrap();
    let (sc, trace) = (s(&scene), dir.join("t.csv"));
    let other = dir.join("o.csv");
    let other_partial = format!("{}.partial", s(&other));
    for (args, wanted) in [
        (vec!["run", sc, "--steps", "30", "--trace", s(&trace)], vec!["--trace", sc, "scene file"]),
        (
            vec!["run", "--builtin", "drop", "--steps", "30", "--trace", s(&other), "--state-out", &other_partial],
            vec!["--trace", &other_partial, "--state-out"],
        ),
        (
            vec!["run", "--builtin", "drop", "--steps", "30", "--trace", s(&other), "--frames", &other_partial],
            vec!["--trace", "--frames"],
        ),
    ] {
        let (out, _) = capped(&args);
        assert_refused(&args, &out, &wanted);
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), text, "{args:?}: the scene changed");
        assert_eq!(listing(&dir), ["scene.json", "t.csv.partial"], "{args:?}: files were made");
    }
    // a user's file there stays; the rows go to the next free name
    let bad = dir.join("bad.json");
    std::fs::write(&bad, &text).unwrap();
    let mine = dir.join("u.csv.partial");
    std::fs::write(&mine, "USERDATA\n").unwrap();
    let trace = dir.join("u.csv");
    let args = ["run", s(&bad), "--steps", "30", "--trace", s(&trace)];
    let (out, _) = capped(&args);
    if no_adapter(&out) {
        return;
    }
    assert_refused(&args, &out, &["body 1 became absurd"]);
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "USERDATA\n", "the user's file was replaced");
    let kept = dir.join("u.csv.partial.1");
    let rows = std::fs::read_to_string(&kept).expect("the rows go to the next free name");
    assert!(rows.starts_with(verlet::output::TRACE_HEADER), "{rows}");
    assert!(stderr(&out).contains(s(&kept)), "{}", stderr(&out));
    assert_eq!(listing(&dir), ["bad.json", "scene.json", "t.csv.partial", "u.csv.partial", "u.csv.partial.1"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn frames_would_overwrite_no_input_or_output() {
    let (dir, _, text) = workdir("frames-clash");
    let frame_scene = dir.join("frame_000001.png");
    std::fs::write(&frame_scene, &text).unwrap();
    let (d, fs) = (s(&dir), s(&frame_scene));
    let (gif, state) = (format!("{d}/frame_000002.png"), format!("{d}/frame_000003.png"));
    let small = ["--width", "8", "--height", "8"];
    for (args, wanted) in [
        (vec!["run", fs, "--steps", "2", "--frames", d], vec!["--frames", fs, "scene file"]),
        (vec!["run", "--builtin", "drop", "--steps", "2", "--frames", d, "--gif", &gif], vec!["--frames", &gif, "--gif"]),
        (vec!["run", "--builtin", "drop", "--steps", "2", "--frames", d, "--state-out", &state], vec!["--frames", "--state-out"]),
    ] {
        let args: Vec<&str> = args.into_iter().chain(small).collect();
        let (out, _) = capped(&args);
        assert_refused(&args, &out, &wanted);
        assert_eq!(std::fs::read(&frame_scene).unwrap(), text, "{args:?}: the scene changed");
        assert_eq!(listing(&dir), ["frame_000001.png", "scene.json"], "{args:?}: files were made");
    }
    // a frame-named link in the directory to an input elsewhere: the frame would go through it
    #[cfg(unix)]
    {
        let (other, scene, _) = workdir("frames-link");
        std::os::unix::fs::symlink(&scene, other.join("frame_000000.png")).unwrap();
        let args = ["run", s(&scene), "--steps", "2", "--frames", s(&other), "--width", "8", "--height", "8"];
        let (out, _) = capped(&args);
        assert_refused(&args, &out, &["--frames", "frame_000000.png", "scene file"]);
        assert_eq!(std::fs::read(&scene).unwrap(), text);
        let _ = std::fs::remove_dir_all(&other);
    }
    // the scene in the frames directory under another name is no clash
    let scene = dir.join("scene.json");
    std::fs::remove_file(&frame_scene).unwrap();
    let (out, _) = capped(&["run", s(&scene), "--steps", "2", "--frames", d, "--width", "8", "--height", "8"]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read(&scene).unwrap(), text);
    assert_eq!(listing(&dir), ["frame_000000.png", "frame_000001.png", "frame_000002.png", "scene.json"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_good_run_replaces_old_outputs_whole() {
    let (dir, scene, original) = workdir("good");
    let (trace, state) = (dir.join("trace.csv"), dir.join("state.json"));
    std::fs::write(&trace, "an old trace\n").unwrap();
    std::fs::write(&state, "an old state\n").unwrap();
    let (out, _) = capped(&["run", s(&scene), "--steps", "4", "--every", "2", "--trace", s(&trace), "--state-out", s(&state)]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = std::fs::read_to_string(&trace).unwrap();
    assert_eq!(rows.lines().count(), 1 + 3, "header and steps 0, 2, 4: {rows}");
    let text = std::fs::read_to_string(&state).unwrap();
    assert_eq!(serde_json::from_str::<serde_json::Value>(&text).unwrap()["step"], 4);
    assert_eq!(std::fs::read(&scene).unwrap(), original);
    assert_eq!(listing(&dir), ["scene.json", "state.json", "trace.csv"], "no temporary file left");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Makes a FIFO at `path` and opens both its ends here (Linux opens a
/// FIFO read-write at once): a writer's open finds its reader, and
/// [`drain_fifo`] reads what came through.
#[cfg(unix)]
fn held_fifo(path: &Path) -> std::fs::File {
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success(), "mkfifo {}", path.display());
    std::fs::OpenOptions::new().read(true).write(true).open(path).unwrap()
}

/// The bytes a [`held_fifo`] holds, without waiting for more: a marker is
/// written last and read up to.
#[cfg(unix)]
fn drain_fifo(held: &mut std::fs::File) -> String {
    use std::io::{Read, Write};
    held.write_all(b"<end>").unwrap();
    let (mut got, mut buf) = (Vec::new(), [0u8; 4096]);
    while !got.ends_with(b"<end>") {
        let n = held.read(&mut buf).unwrap();
        got.extend_from_slice(&buf[..n]);
    }
    got.truncate(got.len() - b"<end>".len());
    String::from_utf8(got).unwrap()
}

#[cfg(unix)]
#[test]
fn a_device_or_fifo_output_is_written_into_never_replaced() {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let (dir, scene, _) = workdir("special");
    let fifo = dir.join("fifo");
    let mut held = held_fifo(&fifo);
    // a null device of our own (never the system's /dev/null), where root may make one
    let null = dir.join("null");
    let root = std::fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0);
    let null_made = root && Command::new("mknod").arg(&null).args(["c", "1", "3"]).status().unwrap().success();
    let mut args = vec!["run", s(&scene), "--steps", "2", "--trace", s(&fifo)];
    if null_made {
        args.extend(["--state-out", s(&null)]);
    }
    let (out, _) = capped(&args);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = drain_fifo(&mut held);
    assert!(rows.starts_with(verlet::output::TRACE_HEADER), "{rows}");
    assert_eq!(rows.lines().count(), 1 + 3, "header and steps 0, 1, 2: {rows}");
    if null_made {
        assert!(std::fs::metadata(&null).unwrap().file_type().is_char_device(), "the device was replaced");
        // bench's outputs too
        let mut args = quick_bench("cubes:3").to_vec();
        args.extend(["--json", s(&null), "--csv", s(&fifo)]);
        let (out, _) = capped(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(drain_fifo(&mut held).starts_with("case,"), "bench's CSV came through the FIFO");
        assert!(std::fs::metadata(&null).unwrap().file_type().is_char_device(), "the device was replaced");
    }
    // a failed run writes nothing into it and makes no TRACE.partial beside it
    let bad = dir.join("bad.json");
    std::fs::write(&bad, flying_scene()).unwrap();
    let before = listing(&dir);
    let args = ["run", s(&bad), "--steps", "30", "--trace", s(&fifo)];
    let (out, _) = capped(&args);
    assert_refused(&args, &out, &["body 1 became absurd"]);
    assert_eq!(drain_fifo(&mut held), "", "a failed run wrote into the FIFO");
    assert!(stderr(&out).contains("note: --trace") && stderr(&out).contains("not kept"), "{}", stderr(&out));
    assert_eq!(listing(&dir), before, "a file was made beside the FIFO");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn an_output_through_a_link_to_nothing_makes_the_links_target() {
    let (dir, scene, _) = workdir("dangling");
    let (link, target) = (dir.join("state.json"), dir.join("made.json"));
    std::os::unix::fs::symlink("made.json", &link).unwrap();
    // the link and its target are one output
    assert_refused_quickly(
        &["run", s(&scene), "--steps", "2", "--state-out", s(&link), "--trace", s(&target)],
        &["--trace", "--state-out"],
    );
    let (out, _) = capped(&["run", s(&scene), "--steps", "2", "--state-out", s(&link)]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link was replaced");
    let text = std::fs::read_to_string(&target).expect("the link's target is made");
    assert_eq!(serde_json::from_str::<serde_json::Value>(&text).unwrap()["step"], 2);
    assert_eq!(listing(&dir), ["made.json", "scene.json", "state.json"]);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// 3. Spin is checked
// ---------------------------------------------------------------------------

fn spinning(w: [f32; 3]) -> Scene {
    let mut scene = scenes::drop();
    scene.settings.gravity = [0.0; 3];
    scene.bodies[0].angular_velocity = w;
    scene
}

#[test]
fn absurd_spins_are_refused_naming_the_field() {
    let (dir, _, _) = workdir("spin");
    for (w, why) in [([0.0, 1e30, 0.0], "rad/s"), ([2e4, 0.0, 0.0], "rad/s"), ([0.0, 0.0, 600.0], "substeps")] {
        let mut scene = scenes::drop();
        scene.bodies[0].angular_velocity = w;
        // to_json writes what validation would refuse; the loader refuses it
        let err = Scene::from_json_str(&scene.to_json()).unwrap_err().to_string();
        assert!(err.contains("bodies[0].angular_velocity") && err.contains(why), "{w:?}: {err}");
        let file = dir.join("spin.json");
        std::fs::write(&file, scene.to_json()).unwrap();
        assert_refused_quickly(&["run", s(&file), "--steps", "1"], &["bodies[0].angular_velocity"]);
    }
    // a spin a substep holds is fine; more substeps hold more
    assert!(Scene::from_json_str(&spinning([0.0, 500.0, 0.0]).to_json()).is_ok());
    let mut fast = spinning([0.0, 2000.0, 0.0]);
    fast.settings.substeps = 16;
    assert!(Scene::from_json_str(&fast.to_json()).is_ok());
    // a track's set_velocity too
    let track = dir.join("track.json");
    std::fs::write(&track, r#"{"events": [{"t": 0, "set_velocity": {"body": 0, "angular": [0, 1e30, 0]}}]}"#).unwrap();
    assert_refused_quickly(
        &["run", "--builtin", "drop", "--steps", "1", "--input", s(&track)],
        &["events[0].set_velocity.angular"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_summary_reports_speed_and_spin_apart() {
    let (dir, _, _) = workdir("summary");
    let file = dir.join("spin.json");
    std::fs::write(&file, spinning([0.0, 212.0, 0.0]).to_json()).unwrap();
    let (out, _) = capped(&["run", s(&file), "--steps", "10"]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.contains("fastest spin")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("fastest body 0.000 m/s"), "{line}");
    let spin: f32 = line.split("fastest spin ").nth(1).and_then(|r| r.split(' ').next()).unwrap().parse().unwrap();
    assert!((spin - 212.0).abs() < 1.0, "{line}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run whose body faults (here one falling past 1e4 m/s, the fastest a
/// body may move) fails naming the fault and keeps the old state file.
#[test]
fn a_run_with_a_fault_fails_and_keeps_the_old_state() {
    let (dir, _, _) = workdir("fault");
    let mut scene = scenes::stack(0);
    scene.ground = None;
    scene.settings.gravity = [0.0, -100.0, 0.0];
    let mut body = scenes::box_body([0.5; 3], [0.0, 3.0, 0.0]);
    body.linear_velocity = [0.0, -9990.0, 0.0];
    scene.bodies = vec![body];
    let falling = dir.join("falling.json");
    std::fs::write(&falling, scene.to_json()).unwrap();
    let state = dir.join("state.json");
    std::fs::write(&state, "an old state\n").unwrap();
    let args = ["run", s(&falling), "--steps", "60", "--state-out", s(&state)];
    let (out, _) = capped(&args);
    if no_adapter(&out) {
        return;
    }
    assert_refused(&args, &out, &["became absurd", "faster than 1e4 m/s", "body 0"]);
    assert_eq!(std::fs::read_to_string(&state).unwrap(), "an old state\n", "the old state was replaced");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_body_turning_more_than_a_substep_holds_is_faulted() {
    use verlet::{Fault, FaultKind};
    let mut scene = scenes::stack(0);
    scene.settings.gravity = [0.0; 3];
    scene.bodies = (0..3).map(|k| scenes::box_body([0.5; 3], [10.0 * k as f32, 5.0, 0.0])).collect();
    let Some(mut world) = crate::common::world(&scene) else { return };
    world.step(2).unwrap();
    // turn body 1's previous rotation 3.1 rad away from its current one
    let mut state = world.read_raw().unwrap()[1];
    let half = 3.1f32 / 2.0;
    state.prev_rot = [0.0, half.sin(), 0.0, half.cos()];
    state.rot = [0.0, 0.0, 0.0, 1.0];
    let at = std::mem::size_of_val(&state) as u64;
    world.gpu().queue.write_buffer(world.current_state_buffer(), at, bytemuck::bytes_of(&state));
    world.step(3).unwrap();
    let fault = world.faults().unwrap().expect("the spin is flagged");
    assert_eq!(fault, Fault { body: 1, step: 2, kind: FaultKind::SpinsTooFast });
    assert!(fault.to_string().contains("rad/s"), "{fault}");
    // parked: it no longer turns
    let after = world.read_raw().unwrap()[1];
    let q = |a: [f32; 4]| glam::Quat::from_array(a);
    assert!(q(after.rot).angle_between(q(after.prev_rot)) < 1e-3, "{after:?}");
}

// ---------------------------------------------------------------------------
// 4. Clear errors everywhere
// ---------------------------------------------------------------------------

#[test]
fn negative_numbers_are_refused_saying_what_the_flag_takes() {
    for (flag, args) in [
        ("--steps", vec!["run", "--builtin", "drop", "--steps", "-1"]),
        ("--dt", vec!["run", "--builtin", "drop", "--steps", "1", "--dt", "-1"]),
        ("--seed", vec!["run", "--builtin", "cubes", "--steps", "1", "--seed", "-1"]),
        ("--count", vec!["run", "--builtin", "cubes", "--steps", "1", "--count", "-5"]),
        ("--every", vec!["run", "--builtin", "drop", "--steps", "1", "--every", "-2"]),
        ("--count", vec!["scene", "cubes", "--count", "-1"]),
        ("--seed", vec!["scene", "cubes", "--seed", "-1"]),
        ("--reps", vec!["bench", "--reps", "-1"]),
        ("--steps", vec!["bench", "--steps", "-3"]),
        ("--peer-threads", vec!["bench", "--peer-threads", "-2"]),
    ] {
        let (out, took) = capped(&args);
        assert_refused(&args, &out, &[flag, "-"]);
        let line = reason(&out);
        assert!(!line.contains("unexpected argument"), "{line}");
        assert!(line.contains("must be"), "{args:?}: says not what the flag takes: {line}");
        assert!(took < QUICK);
    }
    assert_refused_quickly(
        &["run", "--builtin", "drop", "--steps", "-1"],
        &["--steps: must be a non-negative whole number, got -1"],
    );
    // a pool of no threads would run nothing
    assert_refused_quickly(&["bench", "--peer-threads", "0"], &["--peer-threads: must be at least 1"]);
}

#[test]
fn steps_too_short_for_the_poses_are_refused_naming_the_field() {
    // 1e-9 s ran a step and stopped a pile at rest as thrown by the solver;
    // 1e-45 as non-finite; 1e-6 s (3 substeps) left a pyramid at rest
    // moving at 0.35 m/s
    let (dir, scene, _) = workdir("short-dt");
    for dt in ["1e-45", "1e-9", "2.9e-5"] {
        assert_refused_quickly(&["run", s(&scene), "--steps", "1", "--dt", dt], &["--dt", "shorter than 1e-5 s", dt]);
        let args = ["run", "--builtin", "pyramid", "--steps", "1", "--dt", dt];
        let (out, _) = capped(&args);
        if no_adapter(&out) {
            return;
        }
        assert_refused(&args, &out, &["--dt", "shorter than 1e-5 s"]);
    }
    let mut short = scenes::drop();
    short.settings.dt = 1e-9;
    std::fs::write(&scene, short.to_json()).unwrap();
    assert_refused_quickly(&["run", s(&scene), "--steps", "1"], &["settings.dt", "shorter than 1e-5 s"]);
    short.settings.dt = scenes::drop().settings.dt;
    short.settings.substeps = 64;
    short.settings.dt = 5e-4;
    std::fs::write(&scene, short.to_json()).unwrap();
    assert_refused_quickly(&["run", s(&scene), "--steps", "1"], &["settings.dt", "64 substeps", "7.813e-6 s"]);
    // a flag that makes a step too long names the flag, not the scene's field
    std::fs::write(&scene, scenes::drop().to_json()).unwrap();
    assert_refused_quickly(&["run", s(&scene), "--steps", "1", "--dt", "10"], &["--dt: ", "inside the ground"]);
    // the shortest step runs, and the summary shows it
    let out = verlet(&["run", "--builtin", "drop", "--steps", "2", "--dt", "3e-5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("2 steps of 0.00003 s (6.000e-5 s simulated)"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A track's `fixed` mass is checked as the scene's own masses are, for
/// the body's shape, before the first step: 3e38 kg gives a unit box an
/// inverse mass a GPU reads as 0 (it turned non-finite at step 43).
#[test]
fn a_track_mass_the_shape_cannot_hold_is_refused_naming_the_event() {
    let (dir, scene, _) = workdir("track-mass");
    let track = dir.join("track.json");
    for mass in ["3e38", "1e-40"] {
        let text = format!(r#"{{"events": [{{"t": 0, "fixed": {{"body": 0, "fixed": false, "mass": {mass}}}}}]}}"#);
        std::fs::write(&track, text).unwrap();
        let args = ["run", s(&scene), "--steps", "60", "--input", s(&track)];
        let (out, _) = capped(&args);
        if no_adapter(&out) {
            return;
        }
        assert_refused(&args, &out, &["events[0].fixed.mass", mass, "a GPU reads smaller ones as 0"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--steps 0` takes no step and says so, with no figure a step (it
/// printed the set-up's time as "0.448 ms/step").
#[test]
fn zero_steps_give_no_figure_a_step() {
    let out = verlet(&["run", "--builtin", "drop", "--steps", "0"]);
    if no_adapter(&out) {
        return;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("0 steps of") && text.contains("(no step taken, wall clock)"), "{text}");
    assert!(!text.contains("ms/step"), "{text}");
}

#[test]
fn malformed_scene_files_are_named_with_the_line() {
    let (dir, _, _) = workdir("malformed");
    let bom = dir.join("bom.json");
    std::fs::write(&bom, b"\xef\xbb\xbf{\"bodies\": []}").unwrap();
    let empty = dir.join("empty.json");
    std::fs::write(&empty, b"").unwrap();
    for (file, why) in [(s(&bom), "byte-order mark"), (s(&empty), "is empty"), ("/dev/null", "is empty")] {
        assert_refused_quickly(&["run", file, "--steps", "1"], &[file, "line 1", why]);
    }
    assert_refused_quickly(&["run", "--builtin", "drop", "--steps", "1", "--input", s(&empty)], &["--input", s(&empty), "line 1"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn endless_or_huge_files_are_refused_without_reading_them_whole() {
    let (dir, _, _) = workdir("endless");
    // a NUL byte is no JSON: /dev/zero fails at its first byte, not at the OOM killer
    for args in [&["run", "/dev/zero", "--steps", "1"][..], &["run", "--builtin", "drop", "--steps", "1", "--input", "/dev/zero"]] {
        let (out, _) = capped(args);
        assert_refused(args, &out, &["/dev/zero", "line 1, column 1", "NUL byte"]);
    }
    let nul = dir.join("nul.json");
    std::fs::write(&nul, b"{\n  \"bodies\": [\0").unwrap();
    let args = ["run", s(&nul), "--steps", "1"];
    let (out, _) = capped(&args);
    assert_refused(&args, &out, &[s(&nul), "line 2, column 14", "NUL byte"]);
    // a file over the cap (sparse: it takes no disk) is refused by its size, naming it
    let huge = dir.join("huge.json");
    std::fs::File::create(&huge).unwrap().set_len(verlet::load_error::MAX_FILE_BYTES + 1).unwrap();
    let args = ["run", s(&huge), "--steps", "1"];
    let (out, _) = capped(&args);
    assert_refused(&args, &out, &[s(&huge), "scene file", &verlet::load_error::MAX_FILE_BYTES.to_string()]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scene_given_as_a_track_is_called_a_scene() {
    let (dir, scene, original) = workdir("scene-as-track");
    assert_refused_quickly(&["run", "--builtin", "drop", "--steps", "1", "--input", s(&scene)], &["--input", "scene"]);
    assert_eq!(std::fs::read(&scene).unwrap(), original);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_wgpu_backend_names_the_variable_and_its_values() {
    // (a backend this build lacks found no adapter, and the error said to
    // install a Vulkan driver)
    for (var, value, valid) in [
        ("WGPU_BACKEND", "nonsense", "vulkan"),
        ("WGPU_POWER_PREF", "fastest", "high"),
        ("WGPU_BACKEND", "gl", "a backend this build has"),
    ] {
        let (out, took) = capped_env(&["info"], &[(var, value)]);
        assert_refused(&["info"], &out, &[var, value, valid]);
        assert!(!stderr(&out).contains("mesa-vulkan-drivers"), "{}", stderr(&out));
        assert!(took < QUICK);
    }
    // a value that is not UTF-8 was read as unset
    #[cfg(unix)]
    for var in ["WGPU_BACKEND", "WGPU_POWER_PREF"] {
        use std::os::unix::ffi::OsStrExt;
        let out =
            Command::new(env!("CARGO_BIN_EXE_verlet")).arg("info").env(var, std::ffi::OsStr::from_bytes(b"\xff")).output().unwrap();
        assert_refused(&["info"], &out, &[var, "not UTF-8"]);
    }
}

#[test]
fn bench_says_aloud_what_it_skips() {
    assert_refused_quickly(&["bench", "--cases", ",,,"], &["--cases", "no case"]);
    let Some(gpu) = crate::common::gpu() else { return };
    let count = verlet::world::max_bodies(&gpu) + 1;
    let case = format!("chain:{count}");
    let (out, _) = capped(&["bench", "--cases", &format!("{case},,"), "--steps", "1", "--reps", "1", "--profile-steps", "0"]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("warning: --cases: 2 empty"), "{err}");
    assert!(err.contains(&format!("warning: chain-{count}: does not fit, skipped")), "{err}");
}

#[test]
fn track_events_after_the_last_step_are_warned_of() {
    let (dir, _, _) = workdir("late");
    let track = dir.join("track.json");
    std::fs::write(&track, r#"{"events": [{"t": 0, "impulse": {"body": 0, "impulse": [0, 1, 0]}}, {"t": 100, "impulse": {"body": 0, "impulse": [0, 1, 0]}}]}"#)
        .unwrap();
    let (out, _) = capped(&["run", "--builtin", "drop", "--steps", "3", "--input", s(&track)]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("warning: --input: 1 of 2 events"), "{}", stderr(&out));
    // a far time in a few digits (1e11 printed as twelve)
    std::fs::write(&track, r#"{"events": [{"t": 1e11, "impulse": {"body": 0, "impulse": [0, 1, 0]}}]}"#).unwrap();
    let (out, _) = capped(&["run", "--builtin", "drop", "--steps", "3", "--input", s(&track)]);
    assert!(stderr(&out).contains("events come at t >= 1e11 s"), "{}", stderr(&out));
    // past the latest time a world reaches, refused
    std::fs::write(&track, r#"{"events": [{"t": 1e300, "impulse": {"body": 0, "impulse": [0, 1, 0]}}]}"#).unwrap();
    let (out, _) = capped(&["run", "--builtin", "drop", "--steps", "3", "--input", s(&track)]);
    assert!(!out.status.success() && stderr(&out).contains("events[0].t: is 1e300 s"), "{}", stderr(&out));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--count` or `--seed` with a scene file (it gives its own bodies), or
/// `--seed` with a scene that is not random, is warned of, not silently
/// ignored.
#[test]
fn a_count_given_with_a_scene_file_is_warned_of() {
    let (dir, scene, _) = workdir("count");
    let (out, _) = capped(&["run", s(&scene), "--count", "5", "--steps", "1"]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("warning: --count: a scene file gives its own bodies"), "{}", stderr(&out));
    // --seed too, and for a built-in scene that is not random
    let (out, _) = capped(&["run", s(&scene), "--seed", "5", "--steps", "1"]);
    assert!(stderr(&out).contains("warning: --seed: a scene file gives its own bodies"), "{}", stderr(&out));
    for args in [&["run", "--builtin", "drop", "--seed", "9", "--steps", "1"][..], &["scene", "stack", "--seed", "3"]] {
        let (out, _) = capped(args);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(stderr(&out).contains("warning: --seed: the "), "{args:?}: {}", stderr(&out));
    }
    let (out, _) = capped(&["scene", "cubes", "--count", "3", "--seed", "3"]);
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `verlet args` under the 4 GB cap with stdout going to `stdout`.
fn capped_to(args: &[&str], stdout: std::process::Stdio) -> std::process::Child {
    Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 4000000 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_verlet"))
        .args(args)
        .stdout(stdout)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("sh runs verlet")
}

#[test]
fn a_closed_stdout_ends_quietly_and_a_full_one_is_an_error() {
    // the reader goes before the scene (3 MB, more than a pipe holds) is written
    let mut child = capped_to(&["scene", "cubes", "--count", "10000"], std::process::Stdio::piped());
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(141), "128 + SIGPIPE, as a shell reports `yes | head`: {}", stderr(&out));
    assert_eq!(stderr(&out), "", "a closed pipe is no error to report");
    #[cfg(target_os = "linux")]
    for args in [&["scene", "cubes", "--count", "3"][..], &["info"], &["run", "--builtin", "drop", "--steps", "2"]] {
        let full = std::fs::File::create("/dev/full").unwrap();
        let out = capped_to(args, full.into()).wait_with_output().unwrap();
        if no_adapter(&out) {
            continue;
        }
        assert_refused(args, &out, &["stdout", "No space left"]);
    }
}

/// A stderr that cannot be written (full) is no panic: errors keep their
/// exit status, and a run whose only stderr line is a warning goes on and
/// writes its outputs. Before, each was exit 101, and the warned run wrote
/// nothing.
#[cfg(target_os = "linux")]
#[test]
fn a_full_stderr_changes_no_exit_status_and_stops_no_run() {
    let (dir, scene, _) = workdir("full-stderr");
    let state = dir.join("state.json");
    let with_full_stderr = |args: &[&str]| {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_verlet")).args(args).stderr(full).output().unwrap();
        out.status.code()
    };
    assert_eq!(with_full_stderr(&["run", s(&scene), "--steps", "-1"]), Some(2), "a bad flag");
    assert_eq!(with_full_stderr(&["run", "/no/such/scene.json", "--steps", "1"]), Some(1), "a missing scene");
    let warned = ["run", s(&scene), "--count", "3", "--steps", "2", "--state-out", s(&state)];
    let code = with_full_stderr(&warned);
    if code == Some(1) && !state.exists() {
        // no adapter: the error could not be seen; the run says so when stderr works
        assert!(no_adapter(&verlet(&warned)));
        return;
    }
    assert_eq!(code, Some(0), "a run with a warning");
    assert!(std::fs::read_to_string(&state).unwrap().contains("\"bodies\""), "its state written");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn bench_takes_an_output_path_that_is_not_utf8() {
    use std::os::unix::ffi::OsStrExt;
    let (dir, _, _) = workdir("bench-bytes");
    let json = dir.join(std::ffi::OsStr::from_bytes(b"x\xff.json"));
    let out = Command::new(env!("CARGO_BIN_EXE_verlet")).args(quick_bench("cubes:10")).arg("--json").arg(&json).output().unwrap();
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert!(report["command"].as_str().unwrap().contains("x\u{fffd}.json"), "{}", report["command"]);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// 5. A quiet doorstep
// ---------------------------------------------------------------------------

/// Variables set, and variables removed, for a child.
type Env = (&'static [(&'static str, &'static str)], &'static [&'static str]);

/// Environments in which libwayland, asked by Mesa's device-select layer
/// for the display's GPU, would print `error: XDG_RUNTIME_DIR is invalid or
/// not set in the environment.`.
const NO_RUNTIME_DIR: &[Env] = &[
    (&[], &["XDG_RUNTIME_DIR", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]),
    (&[("WAYLAND_DISPLAY", "wayland-0")], &["XDG_RUNTIME_DIR", "WAYLAND_SOCKET"]),
    (&[("XDG_RUNTIME_DIR", "not/absolute")], &["WAYLAND_DISPLAY", "WAYLAND_SOCKET"]),
];

#[test]
fn a_headless_run_prints_only_its_own_lines() {
    for (set, unset) in NO_RUNTIME_DIR {
        for args in [&["info"][..], &["run", "--builtin", "drop", "--steps", "2"]] {
            let (out, _) = capped_env_without(args, set, unset);
            if no_adapter(&out) {
                return;
            }
            let err = stderr(&out);
            assert!(out.status.success(), "{args:?} with {set:?}, without {unset:?}: {err}");
            assert!(!err.contains("XDG_RUNTIME_DIR"), "{args:?} with {set:?}, without {unset:?}: {err}");
            assert!(!err.lines().any(|l| l.starts_with("error")), "{args:?} with {set:?}, without {unset:?}: {err}");
            assert!(!String::from_utf8_lossy(&out.stdout).is_empty(), "{args:?}: printed nothing");
        }
    }
}

#[test]
fn without_a_runtime_dir_real_errors_still_show() {
    // fails after the adapters were enumerated (the probe ran): the error
    // must be there, and alone
    for (set, unset) in NO_RUNTIME_DIR {
        let wanted = ("WGPU_ADAPTER_NAME", "no-such-adapter-anywhere");
        let env: Vec<(&str, &str)> = set.iter().copied().chain([wanted]).collect();
        let (out, _) = capped_env_without(&["info"], &env, unset);
        assert_refused(&["info"], &out, &["WGPU_ADAPTER_NAME", "no-such-adapter-anywhere", "matches no adapter"]);
        assert!(!stderr(&out).contains("XDG_RUNTIME_DIR"), "{}", stderr(&out));
    }
}

#[test]
fn help_lists_every_built_in_scene() {
    for args in [&["--help"][..], &["scene", "--help"], &["run", "--help"], &["help", "scene"]] {
        let (out, took) = capped(args);
        let help = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        for scene in scenes::SCENES {
            let (name, what) = (scene.name, scene.help_with("--count", "--seed"));
            let line = help.lines().find(|l| l.split_whitespace().next() == Some(name));
            let line = line.unwrap_or_else(|| panic!("{args:?}: no line for the {name} scene in {help}"));
            assert!(line.contains(&what), "{args:?}: {line:?} lacks {what:?}");
        }
        assert!(took < QUICK, "{args:?}: took {took:?}");
    }
}

#[test]
fn two_bodies_placed_in_one_spot_separate_no_faster_than_promised() {
    // docs/defaults.md's promise ("Contacts"): old overlap between two bodies is pushed out at
    // most 3 m/s. (Many bodies in one spot add their pairs' speeds up: ten
    // boxes spread at 13 m/s.)
    let cube = || scenes::box_body([0.5; 3], [0.0, 2.0, 0.0]);
    for (name, second) in [("two boxes", cube()), ("a box and a ball", scenes::sphere_body(0.5, [0.0, 2.0, 0.0]))] {
        let mut scene = scenes::stack(0);
        scene.ground = None;
        scene.settings.gravity = [0.0; 3];
        scene.bodies = vec![cube(), second];
        let Some(mut w) = crate::common::world(&scene) else { return };
        let mut fastest = 0.0f32;
        for _ in 0..120 {
            w.step(1).unwrap();
            let state = w.read_state().unwrap();
            fastest = state.iter().map(|b| crate::common::v3(b.linear_velocity).length()).fold(fastest, f32::max);
        }
        let state = w.read_state().unwrap();
        let apart = (crate::common::v3(state[0].position) - crate::common::v3(state[1].position)).length();
        eprintln!("{name}: fastest {fastest:.2} m/s, centres {apart:.3} m apart after 2 s");
        assert!(fastest <= 3.0, "{name}: separated at {fastest} m/s");
        assert!(apart > 1.0, "{name}: still overlapping after 2 s, centres {apart} m apart");
    }
}
