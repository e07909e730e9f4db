//! What `verlet run` reports about the run.

use crate::common::{no_adapter, verlet};

/// `verlet run` says when the world ended at rest (its later steps were
/// counted, not run), and not before.
#[test]
fn run_says_when_the_world_came_to_rest() {
    let run = |steps: &str| verlet(&["run", "--builtin", "drop", "--steps", steps]);
    let early = run("10");
    if no_adapter(&early) {
        return;
    }
    let late = run("300");
    assert!(early.status.success() && late.status.success());
    let says = |out: &std::process::Output| String::from_utf8_lossy(&out.stdout).contains("at rest: every body asleep");
    assert!(!says(&early), "a box still falling after 10 steps was said to be at rest");
    assert!(says(&late), "the box asleep on the ground after 300 steps was not said to be at rest");
}
