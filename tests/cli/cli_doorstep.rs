//! What a new user meets first: a usage line on a bare `verlet run`, a
//! guess for a mistyped scene, a summary in plain words, the files named
//! where they were written, a bench that reports without grading, a library
//! that prints nothing of Mesa's window-system probe, and a README that
//! stays short and in step with CI.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::{no_adapter, temp_path, verlet};

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A refusal: non-zero exit, no panic, its last stderr line an error
/// containing each of `wanted`.
fn assert_refused(args: &[&str], wanted: &[&str]) {
    let out = verlet(args);
    let err = stderr(&out);
    assert!(!out.status.success(), "{args:?}: exit status 0; {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    let line = err.trim_end().lines().last().unwrap_or_default();
    assert!(line.starts_with("error: "), "{args:?}: {line:?}");
    for w in wanted {
        assert!(line.contains(w), "{args:?}: expected {w:?} in {line:?}");
    }
}

fn repo_file(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn a_bare_run_names_what_is_missing_with_the_usage() {
    let usage = "usage: verlet run SCENE.json --steps N";
    assert_refused(&["run"], &["missing a scene (SCENE.json or --builtin NAME) and --steps N", usage, "--builtin NAME --steps N"]);
    assert_refused(&["run", "--builtin", "drop"], &["missing --steps N", usage]);
    assert_refused(&["run", "--steps", "3"], &["missing a scene", usage]);
}

#[test]
fn a_mistyped_scene_name_gets_a_suggestion() {
    assert_refused(
        &["run", "--builtin", "pyramd", "--steps", "1"],
        &["unknown scene \"pyramd\"; did you mean pyramid?", "known: drop"],
    );
    assert_refused(&["scene", "ragdol"], &["did you mean ragdoll?"]);
    assert_refused(&["bench", "--cases", "pyle-10k"], &["unknown case \"pyle-10k\" (did you mean pile-10k?)"]);
    // nothing near: the names, no guess
    let out = verlet(&["scene", "teapot"]);
    assert!(!stderr(&out).contains("did you mean"), "{}", stderr(&out));
}

#[test]
fn the_summary_counts_in_words_and_says_when_nothing_moves() {
    let out = verlet(&["run", "--builtin", "drop", "--steps", "1"]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.starts_with("1 body, 1 step of "), "{text}");
    assert!(text.contains("fastest body ") && text.contains("(body 0)"), "a falling box moves: {text}");

    // one box floating with no gravity: nothing moves, and no body is named for it
    let dir = temp_path("still");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("still.json");
    std::fs::write(&scene, r#"{"settings": {"gravity": [0, 0, 0]}, "bodies": [{"shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]}, "position": [0, 2, 0]}, {"shape": {"type": "sphere", "radius": 0.5}, "position": [3, 2, 0]}]}"#).unwrap();
    let out = verlet(&["run", scene.to_str().unwrap(), "--steps", "3"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.starts_with("2 bodies, 3 steps of "), "{text}");
    let line = text.lines().find(|l| l.starts_with("lowest body")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.ends_with("nothing moves (fastest body 0.000 m/s, fastest spin 0.000 rad/s)"), "{line}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn gif_and_contact_sheet_say_where_they_were_written() {
    let dir = temp_path("where");
    std::fs::create_dir_all(&dir).unwrap();
    let (gif, sheet) = (dir.join("run.gif"), dir.join("sheet.png"));
    let out = verlet(&[
        "run",
        "--builtin",
        "sphere",
        "--steps",
        "4",
        "--every",
        "2",
        "--width",
        "64",
        "--height",
        "48",
        "--gif",
        gif.to_str().unwrap(),
        "--contact-sheet",
        sheet.to_str().unwrap(),
    ]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains(&format!("GIF of 3 frames in {}", gif.display())), "{text}");
    assert!(text.contains(&format!("contact sheet of 3 frames in {}", sheet.display())), "{text}");
    assert!(gif.is_file() && sheet.is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn profile_lines_up_its_stages_and_words_its_pools() {
    let out = verlet(&["run", "--builtin", "pyramid", "--count", "3", "--steps", "3", "--profile"]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let stages: Vec<&str> =
        text.lines().skip_while(|l| !l.starts_with("per stage")).skip(1).take_while(|l| l.starts_with("  ")).collect();
    assert!(stages.len() > 10, "{text}");
    assert!(stages.iter().any(|l| l.trim_start().starts_with("restitution_contacts")), "{text}");
    let ends: Vec<usize> = stages.iter().map(|l| l.len()).collect();
    assert!(ends.iter().all(|&e| e == ends[0]), "the stage times end in different columns: {text}");
    assert!(text.contains("contacts, last step:    "), "{text}");
    assert!(text.contains("contacts, busiest step: "), "{text}");
    let pools = text.lines().find(|l| l.starts_with("contact pools now:")).unwrap_or_else(|| panic!("{text}"));
    assert!(pools.contains("room for ") && pools.contains("none overflowed"), "{pools}");
    assert!(!text.contains("most in a step"), "{text}");
}

#[test]
fn a_short_bench_reports_measurements_only() {
    let dir = temp_path("bench-short");
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("report.json");
    let out =
        verlet(&["bench", "--no-peer", "--cases", "cubes:10", "--steps", "3", "--reps", "1", "--json", json.to_str().unwrap()]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let (text, err) = (stdout(&out), stderr(&out));
    // (the command line, echoed, may hold any path)
    let text: String = text.lines().filter(|l| !l.starts_with("command:")).map(|l| format!("{l}\n")).collect();
    for word in ["target", "MISSED", "floor", "goal", "issue", "**", "|"] {
        assert!(!text.contains(word), "{word:?} in {text}");
    }
    assert!(text.lines().any(|l| l.starts_with("cubes-10 ") && l.contains("3 x 1")), "{text}");
    assert!(text.contains("per stage, ms a step"), "{text}");
    // asked for nothing more: no settling, cold start, render or dispatch timing
    for (said, what) in
        [("settled:", "settling"), ("cold start:", "cold start"), ("render:", "render"), ("dispatches:", "dispatch")]
    {
        assert!(!text.contains(said), "{what} in a short run: {text}");
        assert!(!err.contains(said) && !err.contains("settling"), "{what} in a short run: {err}");
    }
    assert!(text.contains("not measured in this run: --settle, --cold-start, --render, --dispatch-cost (or --all)"), "{text}");
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert!(report.get("targets").is_none(), "{report}");
    assert!(report["cases"][0]["median_ms_per_step"].as_f64().is_some_and(|ms| ms > 0.0), "{report}");
    assert_eq!((report["cases"][0]["iterations"].as_u64(), report["cases"][0]["substeps"].as_u64()), (Some(9), Some(3)));
    // --iterations sets every case's sweeps, the substeps as for a scene that gives iterations alone
    let (args, path) = (["--steps", "2", "--reps", "1", "--profile-steps", "0", "--iterations"], json.to_str().unwrap());
    let out = verlet(&[&["bench", "--no-peer", "--cases", "cubes:10"][..], &args, &["8", "--json", path]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("ours: 8 Jacobi sweeps per step in 2 substeps in every case (--iterations)"), "{}", stdout(&out));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!((report["cases"][0]["iterations"].as_u64(), report["cases"][0]["substeps"].as_u64()), (Some(8), Some(2)));

    // asked: the settled pile and the dispatches are measured
    let out = verlet(&["bench", "--no-peer", "--cases", "pile:64", "--steps", "3", "--reps", "1", "--settle", "--dispatch-cost"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("settled: pile-64 with sleeping on:"), "{text}");
    assert!(text.contains("dispatches: "), "{text}");
    assert!(text.contains("not measured in this run: --cold-start, --render (or --all)"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A program using the library prints nothing of Mesa's window-system
/// probe with no display: this test binary runs itself as such a program
/// (which never calls `quiet_window_system_probe`), without
/// `XDG_RUNTIME_DIR` or `WAYLAND_DISPLAY`.
#[test]
fn a_program_using_the_library_is_quiet_without_a_display() {
    if std::env::var_os("VERLET_QUIET_CHILD").is_some() {
        let mut world = verlet::World::new(&verlet::scenes::drop()).expect("a world on the adapter");
        world.step(2).expect("two steps");
        println!("stepped, bodies read back: {}", world.read_state().expect("a readback").len());
        return;
    }
    if crate::common::gpu().is_none() {
        return;
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([
            "cli_doorstep::a_program_using_the_library_is_quiet_without_a_display",
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("VERLET_QUIET_CHILD", "1")
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(stdout(&out).contains("stepped, bodies read back: 1"), "the child did not run: {}", stdout(&out));
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
}

/// The README stays a front door: short, free of the project's own
/// history, with the install line, and its test command the one CI runs.
#[test]
fn the_readme_is_short_and_its_test_command_is_cis() {
    let readme = repo_file("README.md");
    let lines = readme.lines().count();
    assert!(lines <= 200, "README.md has {lines} lines");
    for word in ["issue ", "issues ", "before:", "session", "commit "] {
        assert!(!readme.to_lowercase().contains(word), "README.md says {word:?}");
    }
    assert!(readme.contains("cargo install --path ."), "README.md: no install line");
    assert!(readme.contains("```rust") && readme.contains("fn main()"), "README.md: no complete Rust example");
    let ci = repo_file(".ci/run");
    let command = ci
        .lines()
        .skip_while(|l| !l.starts_with("# The README's test command, verbatim"))
        .nth(1)
        .unwrap_or_else(|| panic!(".ci/run: no README test command: {ci}"));
    assert!(readme.lines().any(|l| l == command), "README.md lacks .ci/run's test command {command:?}");
    // what the README's commands and the examples write stays out of git
    let ignored = repo_file(".gitignore");
    for dir in ["/frames/", "/out/"] {
        assert!(ignored.lines().any(|l| l == dir), ".gitignore lacks {dir}");
    }
}
