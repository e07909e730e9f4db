//! What `verlet info` reports.

use crate::common::{no_adapter, verlet};

/// On lavapipe, `verlet info` says which `LP_NUM_THREADS` is in use and
/// what setting it to 0 does (a dispatch's hand-off to lavapipe's threads
/// is most of a small scene's step).
#[test]
fn info_on_lavapipe_names_its_thread_setting() {
    let out = verlet(&["info"]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    if !text.contains("llvmpipe") {
        return; // a real GPU, or another software adapter
    }
    let line = |text: &str| text.lines().find(|l| l.starts_with("software adapter:")).map(str::to_string);
    let default = line(&text).expect("no software adapter line on lavapipe");
    assert!(default.contains("LP_NUM_THREADS=0 runs them on the submitting thread"), "{default}");
    let zero = std::process::Command::new(env!("CARGO_BIN_EXE_verlet")).arg("info").env("LP_NUM_THREADS", "0").output().unwrap();
    assert!(zero.status.success());
    let set = line(&String::from_utf8_lossy(&zero.stdout)).expect("no software adapter line with LP_NUM_THREADS=0");
    assert!(set.contains("(LP_NUM_THREADS=0)"), "{set}");
}
