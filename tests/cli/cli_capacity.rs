//! A scene beyond the adapter's limits given to the
//! command line: a non-zero exit and a one-line reason, no panic.

use std::process::Command;

use verlet::world::max_bodies;

#[test]
fn verlet_run_refuses_a_scene_beyond_the_adapters_limits() {
    let Some(gpu) = crate::common::gpu() else { return };
    let count = max_bodies(&gpu) + 1;
    let output = Command::new(env!("CARGO_BIN_EXE_verlet"))
        .args(["run", "--builtin", "cubes", "--count", &count.to_string(), "--steps", "1"])
        .output()
        .expect("verlet binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "a scene of {count} bodies ran; stderr {stderr:?}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // the last line: Mesa's own warnings (XDG_RUNTIME_DIR unset) may come first
    let reason = stderr.trim_end().lines().last().unwrap_or_default();
    assert!(reason.starts_with("error: "), "{stderr:?}");
    assert!(reason.contains("too large") && reason.contains(&count.to_string()), "{reason}");
}
