//! `verlet`: a GPU-first rigid-body simulator after Kenwright's "A
//! Lightweight Rigid-Body Verlet Simulator for Real-Time Environments".
//!
//! Quaternion position-Verlet integration, contacts enforced by corrective
//! snaps of pose relaxed iteratively, all in WGSL compute kernels; the host
//! sets up, steps, and reads back only on request.
//!
//! ```no_run
//! use verlet::{scenes, World};
//! let scene = scenes::drop();
//! let mut world = World::new(&scene)?;
//! world.step(120)?;
//! let bodies = world.read_state()?;
//! println!("box at {:?}", bodies[0].position);
//! # Ok::<(), verlet::Error>(())
//! ```
//!
//! Where to start:
//!
//! - A [`Scene`] (its [`Body`]s with their [`Shape`]s, [`Joint`]s, the
//!   [`Ground`], [`Settings`] and [`Camera`]) is built in code, loaded with
//!   [`Scene::from_path`], or taken from the built-in [`scenes`].
//! - [`World::new`] puts a scene on the GPU ([`World::with_gpu`] shares one
//!   [`Gpu`]); [`World::step`] steps it and [`World::read_state`] reads each
//!   body back as a [`BodyOutput`]. Every call fails with one [`Error`].
//! - Inputs act between steps: [`World::apply_impulse`], [`World::set_pose`],
//!   [`World::explode`], [`World::apply_wind`] with a [`Wind`], or a list of
//!   [`BodyInput`]s; a [`Track`] of timed [`Event`]s replays them.
//! - [`World::snapshot`] and [`World::restore`] save and resume a run
//!   bit for bit ([`Snapshot`]).
//! - [`render::Renderer`] draws a world off-screen into an image.
//! - What a world reports: [`World::faults`] ([`Fault`]),
//!   [`World::contact_report`] ([`ContactReport`]), [`World::profile`]
//!   ([`StageTimes`]), [`World::read_contacts`] ([`BodyContact`]).
//!
//! The [`output`] module writes the state and trace formats of the command
//! line; [`limits`] holds the physics limits a world checks bodies against.

// The modules a user reaches by path; their main types are also re-exported
// below.
pub mod gpu;
pub mod limits;
pub mod load_error;
pub mod output;
pub mod render;
pub mod scene;
pub mod scenes;
pub mod track;

mod json;

// For the binary's `bench` command and the benches, not part of the guide.
#[doc(hidden)]
pub mod bench;
// For the crate's own tests: CPU twins of the kernels.
#[doc(hidden)]
pub mod reference;
// For the crate's own tests and the binary: the step's stages and buffers.
#[doc(hidden)]
pub mod step;
// For the crate's own tests and the binary: the world's internals by path;
// users reach its types at the crate root.
#[doc(hidden)]
pub mod world;

pub use gpu::types::BodyContact;
pub use gpu::{Gpu, GpuError};
pub use limits::{Fault, FaultKind};
pub use load_error::LoadError;
pub use render::{RenderOptions, Renderer};
pub use scene::{Body, Camera, Ground, Joint, Scene, SceneError, Settings, Shape, WORLD};
pub use track::{Action, Event, Track, TrackError};
pub use world::input::{BodyInput, Point, Wind};
pub use world::snapshot::Snapshot;
pub use world::{max_bodies, BodyOutput, ContactReport, StageTimes, World};

/// Everything that can go wrong, each with a one-line reason.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene file or an input track (`--input`) that did not load whole.
    #[error("{0}")]
    Load(#[from] load_error::LoadError),
    #[error("{0}")]
    Gpu(#[from] gpu::GpuError),
    /// The scene does not fit the adapter's limits; nothing was allocated.
    #[error("scene too large: {0}")]
    Capacity(String),
    /// A bad argument to the library or the command line.
    #[error("{0}")]
    Input(String),
    /// A bad argument to a library call, named as the function names it
    /// (the command line names its own flag instead, [`Error::for_flag`]).
    #[error("{name}: {reason}")]
    Argument { name: &'static str, reason: String },
    /// The simulation produced a non-finite number.
    #[error("simulation diverged: {0}")]
    Diverged(String),
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
}

impl Error {
    /// The same error with its argument named as the command line's `flag`
    /// where it is an [`Error::Argument`] named `name`.
    pub fn for_flag(self, name: &str, flag: &str) -> Error {
        match self {
            Error::Argument { name: n, reason } if n == name => Error::Input(format!("{flag}: {reason}")),
            e => e,
        }
    }
}

/// The README's Rust example, compiled by `cargo test` as a doctest so that
/// it stays true to the library.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// `docs/library.md`'s program, compiled as the README's is.
#[cfg(doctest)]
#[doc = include_str!("../docs/library.md")]
pub struct LibraryDoctests;
