//! What the examples share: where they write, and how they end.
// each example uses only part of this
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The output directory: the first argument, else a fresh one under the
/// system's temp directory (never the source tree). Created if missing.
pub fn out_dir(example: &str) -> Result<PathBuf, verlet::Error> {
    let dir = match std::env::args_os().nth(1) {
        Some(arg) if arg.to_string_lossy().starts_with('-') => {
            return Err(verlet::Error::Input(format!(
                "usage: cargo run --example {example} [-- OUT_DIR] (default: a new directory under {})",
                std::env::temp_dir().display()
            )))
        }
        Some(arg) => PathBuf::from(arg),
        None => std::env::temp_dir().join(format!("verlet-{example}-{}", std::process::id())),
    };
    std::fs::create_dir_all(&dir).map_err(|source| io_error(&dir, source))?;
    Ok(dir)
}

/// Writes `contents` to `path`, naming the path in an error.
pub fn write(path: &Path, contents: impl AsRef<[u8]>) -> Result<(), verlet::Error> {
    std::fs::write(path, contents).map_err(|source| io_error(path, source))
}

fn io_error(path: &Path, source: std::io::Error) -> verlet::Error {
    verlet::Error::Io { path: path.display().to_string(), source }
}

/// Runs `example` and prints its error, if any, as `verlet` does: one
/// line, a failure exit status.
pub fn main(example: impl FnOnce() -> Result<(), verlet::Error>) -> ExitCode {
    match example() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
