//! Where lavapipe runs a scene's dispatches: `verlet run` and `verlet
//! bench` run a small scene's on the submitting thread (a hand-off to
//! lavapipe's workers costs more than it gives there), a larger one's, or
//! one whose frames are drawn, on the workers, and leave the choice to
//! `LP_NUM_THREADS` when it is set. Where they run changes no bit.

use crate::common::{no_adapter, temp_path};

/// `verlet ARGS` with `LP_NUM_THREADS` as given (`None`: unset).
fn verlet_with(threads: Option<&str>, args: &[&str]) -> std::process::Output {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_verlet"));
    command.args(args);
    match threads {
        Some(t) => command.env("LP_NUM_THREADS", t),
        None => command.env_remove("LP_NUM_THREADS"),
    };
    command.output().expect("the verlet binary runs")
}

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).to_string()
}

fn lavapipe_line(text: &str) -> Option<&str> {
    text.lines().find(|l| l.starts_with("lavapipe:"))
}

#[test]
fn a_small_scene_runs_on_the_submitting_thread_to_the_same_bits() {
    let dir = temp_path("lavapipe-threads");
    std::fs::create_dir_all(&dir).unwrap();
    let (inline, workers) = (dir.join("inline.json"), dir.join("workers.json"));
    // ragdolls on a pile: contacts, joints along paths and sleeping
    let run = |threads, path: &std::path::Path| {
        let args = ["run", "--builtin", "ragdoll", "--count", "3", "--steps", "90", "--state-out", path.to_str().unwrap()];
        verlet_with(threads, &args)
    };
    let out = run(None, &inline);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = stdout(&out);
    if !text.contains("llvmpipe") {
        assert!(lavapipe_line(&text).is_none(), "{text}");
        return; // a real GPU: nothing to choose
    }
    let line = lavapipe_line(&text).unwrap_or_else(|| panic!("no lavapipe line: {text}"));
    assert!(line.contains("each dispatch on the submitting thread"), "{line}");
    let out = run(Some("2"), &workers);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(lavapipe_line(&stdout(&out)).is_none(), "LP_NUM_THREADS set, yet the run says it chose: {}", stdout(&out));
    assert!(std::fs::read(&inline).unwrap() == std::fs::read(&workers).unwrap(), "the state differs by where lavapipe ran");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `verlet ARGS` with `LP_NUM_THREADS` unset succeeds and, on lavapipe,
/// its `lavapipe:` line says `ran`.
fn assert_ran(args: &[&str], ran: &str) {
    let out = verlet_with(None, args);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = stdout(&out);
    if text.contains("llvmpipe") {
        let line = lavapipe_line(&text).unwrap_or_else(|| panic!("no lavapipe line: {text}"));
        assert!(line.contains(ran), "{line}");
    }
}

#[test]
fn a_larger_scene_runs_on_lavapipe_s_workers() {
    assert_ran(&["run", "--builtin", "cubes", "--count", "513", "--steps", "1"], "each dispatch on lavapipe's worker threads");
}

/// Lavapipe draws frames on the same threads, and a frame is far more work
/// than a dispatch's hand-off: a run that draws keeps the workers.
#[test]
fn a_small_scene_that_draws_frames_runs_on_lavapipe_s_workers() {
    let dir = temp_path("lavapipe-frames");
    let args = ["run", "--builtin", "chain", "--steps", "2", "--frames", dir.to_str().unwrap()];
    assert_ran(&args, "each dispatch on lavapipe's worker threads");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_bench_says_where_each_case_ran() {
    let dir = temp_path("lavapipe-bench");
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("report.json");
    let args = [
        "bench",
        "--no-peer",
        "--cases",
        "cubes:10,cubes:600",
        "--steps",
        "2",
        "--reps",
        "1",
        "--profile-steps",
        "0",
        "--dispatch-cost",
    ];
    let out = verlet_with(None, &[&args[..], &["--json", json.to_str().unwrap()]].concat());
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let text = stdout(&out);
    if !text.contains("llvmpipe") {
        return;
    }
    let ran = |k: usize| report["cases"][k]["lavapipe"].as_str().map(str::to_string);
    assert_eq!((ran(0).as_deref(), ran(1).as_deref()), (Some("submitting_thread"), Some("worker_threads")), "{report}");
    let line = lavapipe_line(&text).unwrap_or_else(|| panic!("no lavapipe line: {text}"));
    assert!(line.starts_with("lavapipe: cubes-10 ran each dispatch on the submitting thread"), "{line}");
    // what a dispatch costs, both ways (measured, not judged)
    let cost = &report["dispatch"];
    assert!(cost["us_per_dispatch"].as_f64().is_some_and(|us| us > 0.0), "{report}");
    assert!(cost["inline"]["us_per_dispatch"].as_f64().is_some_and(|us| us > 0.0), "{report}");
    assert!(text.contains("on lavapipe's submitting thread (LP_NUM_THREADS=0"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}
