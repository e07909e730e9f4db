//! What `verlet run` writes besides its summary: the output paths checked
//! before the run, then the trace rows, PNG frames, GIF and contact sheet
//! recorded at steps 0, K, 2K, ... and the last, written at its end or,
//! after a failure, what was kept said on stderr.

use std::io::Write;
use std::path::{Path, PathBuf};

use image::RgbaImage;
use verlet::gpu::Gpu;
use verlet::output::{self, AtomicFile};
use verlet::render::{self, Renderer};
use verlet::{Error, Scene, World};

use crate::cli::RunArgs;
use crate::paths::{self, EndWrite};

/// Checks every output path before anything runs: each can be written
/// (its directory exists and takes files, it is no directory; `--frames`'
/// directory takes files, or can be made), and none is an input or another
/// output.
pub fn check_outputs(args: &RunArgs) -> Result<(), Error> {
    let files = [
        ("--state-out", &args.state_out),
        ("--trace", &args.trace),
        ("--gif", &args.gif),
        ("--contact-sheet", &args.contact_sheet),
    ];
    let mut outputs: Vec<(&str, &Path)> = files.iter().filter_map(|(flag, p)| p.as_deref().map(|p| (*flag, p))).collect();
    if let Some(dir) = &args.frames {
        outputs.push(("--frames", dir));
    }
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    if let Some(scene) = &args.scene {
        inputs.push(("the scene file", scene));
    }
    if let Some(track) = &args.input {
        inputs.push(("the --input track", track));
    }
    paths::check_distinct(&inputs, &outputs)?;
    // a failed run keeps the trace's rows beside it: that name must be no
    // input or output either (an existing file there is never replaced: see
    // `Recorder::abandon`)
    if let Some(trace) = &args.trace {
        let partial = partial_path(trace);
        if let Some((input, _)) = inputs.iter().find(|(_, p)| paths::same_file(&partial, p)) {
            return Err(Error::Input(format!(
                "--trace: a failed run keeps its rows in {}, which is {input}, an input; give --trace another path",
                partial.display()
            )));
        }
        if let Some((other, _)) = outputs.iter().find(|(_, p)| paths::same_file(&partial, p)) {
            return Err(Error::Input(format!(
                "--trace: a failed run keeps its rows in {}, which is {other}'s output; give each its own path",
                partial.display()
            )));
        }
    }
    if let Some(dir) = &args.frames {
        paths::check_output_dir("--frames", dir)?;
        let others: Vec<(&str, &Path)> = outputs.iter().copied().filter(|(flag, _)| *flag != "--frames").collect();
        paths::check_frames_dir(dir, &inputs, &others)?;
    }
    // An output directly in the directory --frames makes (`--frames nd
    // --gif nd/anim.gif`) has no directory to probe yet: --frames' check
    // above stands for it. Nothing is made here: the directory is made last of the set-up (`Recorder::open`),
    // once the GPU, the world and the renderer are, so a run refused for
    // any reason before its first step makes nothing.
    let made = args.frames.as_deref().filter(|dir| std::fs::symlink_metadata(dir).is_err());
    for (flag, path) in files.iter().filter_map(|(flag, p)| p.as_deref().map(|p| (*flag, p))) {
        match made {
            Some(dir) if paths::is_in_dir(path, dir) => {}
            _ => paths::check_output(flag, path)?,
        }
    }
    Ok(())
}

/// Warns when `--frames DIR` holds frame-named files that this run will
/// not replace: an earlier, longer run's frames would stay, unsaid, after
/// this run's, and a video made of DIR would switch runs part way. They are
/// left as they are (they may be wanted); the warning names how many and
/// the first and last.
pub fn warn_stale_frames(args: &RunArgs) {
    let Some(dir) = &args.frames else { return };
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    // this run's frames: steps 0, K, 2K, ... and the last
    let count = (args.steps / args.every).saturating_add(1 + u64::from(!args.steps.is_multiple_of(args.every)));
    let mut stale: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name())
        .filter(|name| paths::is_frame_name(name) && paths::frame_number(name).is_none_or(|k| k >= count))
        .map(|name| name.to_string_lossy().into_owned())
        .collect();
    stale.sort();
    let (Some(first), Some(last)) = (stale.first(), stale.last()) else { return };
    let which = if stale.len() == 1 {
        format!("1 frame file ({first})")
    } else {
        format!("{} frame files ({first} to {last})", stale.len())
    };
    eprintln!(
        "warning: --frames: {} holds {which} that this run, writing {} to {}, will not replace: they stay, mixed with this run's",
        dir.display(),
        output::frame_name(0),
        output::frame_name(count - 1)
    );
}

/// Where a failed run keeps the trace's rows: `TRACE.partial` (or, when a
/// file is there, `TRACE.partial.1`, ...: `AtomicFile::keep_beside`).
fn partial_path(trace: &Path) -> PathBuf {
    let mut partial = trace.as_os_str().to_os_string();
    partial.push(".partial");
    PathBuf::from(partial)
}

/// Largest GIF frame: frames are scaled down to fit this box, and at most
/// `GIF_FRAMES + 1` are kept (see [`Reel`]), so a GIF of any run stays a few
/// tens of MB in memory.
const GIF_BOX: u32 = 480;
const GIF_FRAMES: usize = 150;
/// The shortest delay between a GIF's frames (ms) that viewers keep.
const GIF_MIN_DELAY_MS: f64 = 20.0;
/// Largest contact-sheet tile, and at most `SHEET_TILES + 1` tiles.
const SHEET_BOX: u32 = 320;
const SHEET_TILES: usize = 24;

/// What `run` records at steps 0, K, 2K, ... and the last: trace rows,
/// PNG frames, and the frames kept for a GIF and a contact sheet.
pub struct Recorder {
    /// The trace, written beside its path and renamed there when the run
    /// succeeds (into it, for a device or FIFO: [`AtomicFile`]).
    trace: Option<(PathBuf, AtomicFile)>,
    frames_dir: Option<PathBuf>,
    /// The frames kept for `--gif` and `--contact-sheet`.
    gif: Option<Reel>,
    sheet: Option<Reel>,
    /// Made if any image is wanted.
    renderer: Option<Renderer>,
    frames_written: u64,
    /// The last step recorded (trace rows and frames), if any.
    last_step: Option<u64>,
}

/// Whether the run draws frames: `--frames`, `--gif` or `--contact-sheet`.
pub fn wants_images(args: &RunArgs) -> bool {
    args.frames.is_some() || args.gif.is_some() || args.contact_sheet.is_some()
}

impl Recorder {
    /// Makes the renderer if any image is wanted (refusing a size beyond
    /// the adapter's), then creates the frames directory, then opens the
    /// trace (beside its path, which may be in that directory);
    /// `check_outputs` has checked every path already. Called last of the
    /// set-up, once the GPU and the world are made, so a run refused before
    /// its first step makes nothing. Nothing the user had is touched until
    /// the run succeeds.
    pub fn open(args: &RunArgs, gpu: &Gpu, scene: &Scene) -> Result<Recorder, Error> {
        let renderer = if wants_images(args) {
            Some(
                Renderer::new(gpu, scene, args.width, args.height)
                    .map_err(|e| e.for_flag("width", "--width").for_flag("height", "--height"))?,
            )
        } else {
            None
        };
        if let Some(dir) = &args.frames {
            std::fs::create_dir_all(dir)
                .map_err(|e| Error::Input(format!("--frames: cannot create directory {}: {e}", dir.display())))?;
        }
        let trace = match &args.trace {
            Some(path) => {
                let flagged = |e: Error| Error::Input(format!("--trace: {e}"));
                let mut file = AtomicFile::create(path).map_err(flagged)?;
                writeln!(file.writer(), "{}", output::TRACE_HEADER).map_err(|source| flagged(io_err(path, source)))?;
                Some((path.clone(), file))
            }
            None => None,
        };
        let gif = args.gif.as_ref().map(|_| {
            // browsers play a GIF's delays under 20 ms as 100 ms: frames
            // closer than that are thinned, not shown slower (else 1 s at
            // 60 Hz would play in 1.22 s)
            let mut reel = Reel::new(GIF_FRAMES, GIF_BOX);
            reel.at_least_apart(GIF_MIN_DELAY_MS, args.every, scene.settings.dt);
            reel
        });
        let sheet = args.contact_sheet.as_ref().map(|_| Reel::new(SHEET_TILES, SHEET_BOX));
        Ok(Recorder { trace, frames_dir: args.frames.clone(), gif, sheet, renderer, frames_written: 0, last_step: None })
    }

    /// Frames written to `--frames`, and frames kept for the GIF and the
    /// contact sheet.
    pub fn frame_counts(&self) -> (u64, usize, usize) {
        (self.frames_written, self.gif.as_ref().map_or(0, Reel::len), self.sheet.as_ref().map_or(0, Reel::len))
    }

    fn wants_images(&self) -> bool {
        self.frames_dir.is_some() || self.gif.is_some() || self.sheet.is_some()
    }

    /// Whether anything is recorded: if not, the steps need not stop at
    /// steps K, 2K, ...
    pub fn is_active(&self) -> bool {
        self.trace.is_some() || self.wants_images()
    }

    /// Records the world as it is now: its trace rows and its frame.
    pub fn record(&mut self, world: &World) -> Result<(), Error> {
        if let Some((path, file)) = self.trace.as_mut() {
            let bodies = world.read_state()?;
            output::write_trace_rows(file.writer(), world.step_count(), world.time(), &bodies)
                .map_err(|e| Error::Input(format!("--trace: {}", io_err(path, e))))?;
        }
        if let Some(renderer) = self.renderer.as_mut() {
            let image = renderer.render(world)?;
            if let Some(dir) = &self.frames_dir {
                let path = dir.join(output::frame_name(self.frames_written));
                render::write_png(&image, &path).map_err(|e| Error::Input(format!("--frames: {e}")))?;
            }
            self.frames_written += 1;
            for reel in self.gif.iter_mut().chain(self.sheet.iter_mut()) {
                reel.push(&image);
            }
        }
        self.last_step = Some(world.step_count());
        Ok(())
    }

    /// What commits the trace and writes the GIF and the contact sheet, at
    /// the paths `args` gives (`paths::write_each` runs them, each whatever
    /// became of the others).
    pub fn finish<'a>(self, args: &'a RunArgs, dt: f32) -> Vec<EndWrite<'a>> {
        let mut writes: Vec<EndWrite<'a>> = Vec::new();
        if let (Some((_, file)), Some(path)) = (self.trace, args.trace.as_deref()) {
            writes.push(("--trace", path, Box::new(move || file.commit().map_err(|e| Error::Input(format!("--trace: {e}"))))));
        }
        if let (Some(reel), Some(path)) = (self.gif, args.gif.as_deref()) {
            // real time: the frames are at least GIF_MIN_DELAY_MS apart
            let ms = (args.every * reel.stride) as f64 * dt as f64 * 1e3;
            let frame_ms = ms.clamp(GIF_MIN_DELAY_MS, 10_000.0);
            writes.push((
                "--gif",
                path,
                Box::new(move || {
                    render::write_gif(&reel.finish(), frame_ms, path).map_err(|e| Error::Input(format!("--gif: {e}")))
                }),
            ));
        }
        if let (Some(reel), Some(path)) = (self.sheet, args.contact_sheet.as_deref()) {
            writes.push((
                "--contact-sheet",
                path,
                Box::new(move || {
                    let tiles = reel.finish();
                    let columns = (tiles.len() as f64).sqrt().ceil() as u32;
                    render::write_png(&render::contact_sheet(&tiles, columns, None)?, path)
                        .map_err(|e| Error::Input(format!("--contact-sheet: {e}")))
                }),
            ));
        }
        writes
    }

    /// After a failed run: keeps the trace rows recorded so far beside the
    /// trace's path (`PATH.partial`, or `PATH.partial.1`, ... when a file is
    /// there: none is replaced), never at it, and says on stderr what was
    /// kept and what was not written. A trace into a device or FIFO keeps
    /// its rows nowhere: nothing is written into it, and no file is made
    /// beside it.
    pub fn abandon(self, args: &RunArgs) {
        let upto = match self.last_step {
            Some(step) => format!("steps 0 to {step}"),
            None => "no step".to_string(),
        };
        if let Some((path, file)) = self.trace {
            let partial = partial_path(&path);
            let kept = match self.last_step {
                // a device or FIFO: no file is made beside it (/dev/null.partial)
                Some(_) if file.is_special() => format!("its rows of {upto} were not kept: it is no regular file"),
                Some(_) => match file.keep_beside(&partial) {
                    Ok(kept) if kept == partial => format!("its rows of {upto} are in {}", kept.display()),
                    Ok(kept) => {
                        format!("its rows of {upto} are in {} ({} was there already, and stays)", kept.display(), partial.display())
                    }
                    Err(e) => format!("its rows could not be kept: {e}"),
                },
                None => "no rows were recorded".to_string(),
            };
            eprintln!("note: --trace: {} was left as it was (the run failed); {kept}", path.display());
        }
        match &self.frames_dir {
            Some(dir) if self.frames_written == 0 => eprintln!("note: --frames: no frame was written to {}", dir.display()),
            Some(dir) => eprintln!("note: --frames: {} frames of {upto} were written to {}", self.frames_written, dir.display()),
            None => {}
        }
        for (flag, path) in [("--gif", &args.gif), ("--contact-sheet", &args.contact_sheet), ("--state-out", &args.state_out)] {
            if let Some(path) = path {
                eprintln!("note: {flag}: {} was left as it was (the run failed)", path.display());
            }
        }
    }
}

/// A bounded, evenly spread selection of a run's frames, each scaled down
/// to fit a `size` x `size` box. Frames 0, s, 2s, ... are kept (s = stride);
/// when more than `cap` are kept every other one is dropped and s doubles.
/// The latest frame is kept too, so the run's last frame is always there:
/// at most `cap + 1` frames in all.
struct Reel {
    kept: Vec<RgbaImage>,
    /// The latest frame if it is not in `kept`.
    latest: Option<RgbaImage>,
    stride: u64,
    seen: u64,
    cap: usize,
    size: u32,
}

impl Reel {
    fn new(cap: usize, size: u32) -> Reel {
        // an even cap keeps the newest frame when thinning (its index, cap, is even)
        Reel { kept: Vec::new(), latest: None, stride: 1, seen: 0, cap: cap.max(2) & !1, size }
    }

    fn push(&mut self, image: &RgbaImage) {
        let (w, h) = image.dimensions();
        let scale = (self.size as f64 / w.max(h) as f64).min(1.0);
        let small = if scale < 1.0 {
            let (sw, sh) = (((w as f64 * scale).round() as u32).max(1), ((h as f64 * scale).round() as u32).max(1));
            image::imageops::resize(image, sw, sh, image::imageops::FilterType::Triangle)
        } else {
            image.clone()
        };
        if self.seen.is_multiple_of(self.stride) {
            self.kept.push(small);
            self.latest = None;
            if self.kept.len() > self.cap {
                self.kept = std::mem::take(&mut self.kept).into_iter().step_by(2).collect();
                self.stride *= 2;
            }
        } else {
            self.latest = Some(small);
        }
        self.seen += 1;
    }

    /// Keeps frames at least `ms` apart in simulated time, recorded every
    /// `every` steps of `dt` (before the first frame).
    fn at_least_apart(&mut self, ms: f64, every: u64, dt: f32) {
        self.stride = (ms / (every as f64 * dt as f64 * 1e3)).ceil().max(1.0) as u64;
    }

    /// How many frames `finish` gives.
    fn len(&self) -> usize {
        self.kept.len() + usize::from(self.latest.is_some())
    }

    pub fn finish(self) -> Vec<RgbaImage> {
        let mut frames = self.kept;
        frames.extend(self.latest);
        frames
    }
}

fn io_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}
