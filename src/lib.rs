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

pub mod bench;
pub mod gpu;
mod json;
pub mod limits;
pub mod load_error;
pub mod output;
pub mod reference;
pub mod render;
pub mod scene;
pub mod scenes;
pub mod step;
pub mod track;
pub mod world;

pub use scene::{Body, Ground, Joint, Scene, SceneError, Settings, Shape};
pub use world::{BodyOutput, World};

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
