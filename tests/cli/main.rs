//! The command line as a user meets it: each test runs the `verlet` binary.
//! A binary of its own, apart from the in-process GPU tests, so that timings
//! of refusals are not disturbed by them.

#[path = "../gpu/common/mod.rs"]
mod common;

mod cli_capacity;
mod cli_doorstep;
mod cli_frames;
mod cli_hostile;
mod cli_info;
mod cli_lavapipe;
mod cli_run;
mod cli_scene;
