//! On lavapipe, where a scene's dispatches run: lavapipe hands each one to
//! its worker threads and waits for them, about 40 us a dispatch on two
//! cores, most of a small scene's step; with `LP_NUM_THREADS=0` the thread
//! that submits runs it (docs/lavapipe.md). `run` and `bench` pick this for
//! small scenes that render nothing, unless the user set `LP_NUM_THREADS`.

use serde::Serialize;
use verlet::gpu::Gpu;
use verlet::Error;

/// The most bodies a scene may have to run on the submitting thread: below
/// about 600 (a pile four deep) to 1000 (cubes side by side) the hand-off
/// costs more than the second core gives (docs/lavapipe.md).
pub const INLINE_MAX_BODIES: u64 = 512;

/// Whether a run of `bodies` bodies suits the submitting thread: a small
/// scene, and no frames drawn (lavapipe rasterises on the same threads, and
/// a frame is far more work than a dispatch's hand-off).
pub fn suits_inline(bodies: u64, renders: bool) -> bool {
    bodies <= INLINE_MAX_BODIES && !renders
}

/// Where an adapter opened by `open` runs its dispatches (in the bench's
/// JSON, a case's `lavapipe`: `"worker_threads"`, `"submitting_thread"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Dispatch {
    /// Lavapipe's worker threads: `LP_NUM_THREADS` unset and a scene larger than `INLINE_MAX_BODIES`.
    #[serde(rename = "worker_threads")]
    Workers,
    /// The submitting thread: `LP_NUM_THREADS` unset and a scene of at most `INLINE_MAX_BODIES`.
    #[serde(rename = "submitting_thread")]
    Inline,
    /// As the user's `LP_NUM_THREADS` says, or not lavapipe at all.
    AsSet,
}

impl Dispatch {
    /// What `run` says of it after the time per step (lavapipe only).
    pub fn describe(self) -> Option<String> {
        match self {
            Dispatch::Inline => Some(format!(
                "each dispatch on the submitting thread, as for any scene of at most {INLINE_MAX_BODIES} bodies (LP_NUM_THREADS, when set, decides)"
            )),
            Dispatch::Workers => Some(format!(
                "each dispatch on lavapipe's worker threads, as for any scene of more than {INLINE_MAX_BODIES} bodies or any run that draws frames (LP_NUM_THREADS, when set, decides)"
            )),
            Dispatch::AsSet => None,
        }
    }
}

/// Whether the user left lavapipe's thread count to us.
fn unset() -> bool {
    std::env::var_os("LP_NUM_THREADS").is_none()
}

/// Opens the adapter (`Gpu::new`), with `LP_NUM_THREADS=0` while it is made
/// when `inline` (`suits_inline`) and the user left the variable unset, so
/// that lavapipe runs each dispatch on the submitting thread (it reads the
/// variable as an instance enumerates its adapters; other drivers ignore
/// it). The environment is as the user gave it when this returns.
///
/// Call it before the process starts any thread: the environment is the
/// whole process's, and another thread reading it while it changes is
/// undefined behaviour in C (`std::env::set_var`).
pub fn open(inline: bool) -> Result<(Gpu, Dispatch), Error> {
    if !unset() {
        return Ok((Gpu::new()?, Dispatch::AsSet));
    }
    if inline {
        std::env::set_var("LP_NUM_THREADS", "0");
    }
    let gpu = Gpu::new();
    if inline {
        std::env::remove_var("LP_NUM_THREADS");
    }
    let gpu = gpu?;
    let dispatch = match (is_lavapipe(&gpu), inline) {
        (false, _) => Dispatch::AsSet,
        (true, true) => Dispatch::Inline,
        (true, false) => Dispatch::Workers,
    };
    Ok((gpu, dispatch))
}

/// The adapter on lavapipe's submitting thread, for the bench's small
/// cases beside `open`'s for the others; `None` where the user set
/// `LP_NUM_THREADS` or the adapter is not lavapipe. Before any thread
/// starts, as `open`.
pub fn open_inline() -> Result<Option<Gpu>, Error> {
    if !unset() {
        return Ok(None);
    }
    let (gpu, dispatch) = open(true)?;
    Ok((dispatch == Dispatch::Inline).then_some(gpu))
}

/// Whether `gpu` is lavapipe (Mesa's llvmpipe as a Vulkan driver).
pub fn is_lavapipe(gpu: &Gpu) -> bool {
    gpu.info.name.contains("llvmpipe")
}
