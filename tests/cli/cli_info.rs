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

/// `verlet info` says how many pairs and manifolds the contact pools can
/// grow to; on lavapipe the manifold pool's parts (four bindings of 128 MiB
/// for the points) hold more than two per body of the largest scene, as a
/// settled heap of a million cubes wants.
#[test]
fn info_names_the_pools_limits() {
    let out = verlet(&["info"]);
    if no_adapter(&out) {
        return;
    }
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let number = |prefix: &str, word: &str| -> u64 {
        let line = text.lines().find(|l| l.starts_with(prefix)).unwrap_or_else(|| panic!("no '{prefix}' line: {text}"));
        let words: Vec<&str> = line.split_whitespace().collect();
        let at = words.iter().position(|w| w.trim_end_matches(',') == word).unwrap_or_else(|| panic!("{line}"));
        words[at - 1].parse().unwrap_or_else(|_| panic!("{line}"))
    };
    let manifolds = number("contact pools at most:", "manifolds");
    let pairs = number("contact pools at most:", "pairs");
    let bodies = number("largest scene:", "bodies");
    assert!(pairs > 0 && manifolds > 0, "{text}");
    if text.contains("llvmpipe") {
        assert!(manifolds > 2 * bodies, "{manifolds} manifolds for {bodies} bodies: {text}");
    }
}
