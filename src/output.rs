//! The output files of INTERFACE.md section 3 (the final state as JSON,
//! the trace as CSV, the frames' names) and [`AtomicFile`], which writes
//! an output file whole or not at all (the renderer's PNG and GIF files
//! too). Checking the command line's output paths before a run is the
//! binary's.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::world::BodyOutput;
use crate::Error;

/// `--state-out`: the state after the last step.
pub fn state_json(step: u64, time: f64, bodies: &[BodyOutput]) -> String {
    let bodies: Vec<serde_json::Value> = bodies
        .iter()
        .map(|b| {
            serde_json::json!({
                "position": b.position,
                "orientation": b.orientation,
                "linear_velocity": b.linear_velocity,
                "angular_velocity": b.angular_velocity,
            })
        })
        .collect();
    let doc = serde_json::json!({ "step": step, "time": time, "bodies": bodies });
    serde_json::to_string_pretty(&doc).expect("plain JSON values always serialise")
}

/// The header line of a `--trace` CSV.
pub const TRACE_HEADER: &str = "step,time,body,px,py,pz,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz";

/// Writes one recorded step of a trace: a row per body.
pub fn write_trace_rows(out: &mut impl Write, step: u64, time: f64, bodies: &[BodyOutput]) -> std::io::Result<()> {
    for (i, b) in bodies.iter().enumerate() {
        let [px, py, pz] = b.position;
        let [qx, qy, qz, qw] = b.orientation;
        let [vx, vy, vz] = b.linear_velocity;
        let [wx, wy, wz] = b.angular_velocity;
        writeln!(out, "{step},{time},{i},{px},{py},{pz},{qx},{qy},{qz},{qw},{vx},{vy},{vz},{wx},{wy},{wz}")?;
    }
    Ok(())
}

/// The name of the `k`-th PNG frame that `--frames DIR` writes into DIR.
pub fn frame_name(k: u64) -> String {
    format!("frame_{k:06}.png")
}

fn io_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}

/// An output file written beside its destination under a hidden temporary
/// name (`.NAME.verlet-PID.tmp`, or `.NAME.verlet-PID-K.tmp` where that is
/// taken: `hidden_name`), created new, and renamed over the destination
/// only when complete ([`AtomicFile::commit`]): a failed or killed run never
/// leaves a half-written file where a whole one was expected, nor destroys
/// the file that was there. Dropped uncommitted, the temporary file is
/// removed (a killed process leaves it behind, under its hidden name).
///
/// A destination that exists and is no regular file (a device such as
/// `/dev/null`, a FIFO, `/dev/fd/N` of a pipe; see [`is_special`]) is never
/// renamed over: that replaced the device node with a regular file (as
/// root, `--state-out /dev/null` left `/dev/null` a 477-byte file). Its
/// bytes wait in a file of the temporary directory (`$TMPDIR`, else `/tmp`),
/// unlinked as soon as it is made so that nothing stays there even after a
/// kill, and are written into the destination at the commit, opened for
/// writing as it is (never created, never truncated). So a failed run
/// writes nothing into it either.
pub struct AtomicFile {
    dest: PathBuf,
    /// The hidden file beside `dest`, renamed over it at the commit; `None`
    /// where `dest` is special and the bytes are copied into it instead.
    temp: Option<PathBuf>,
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Creates the temporary file beside `dest` (a symbolic link's target,
    /// if `dest` is one, so the link stays: [`destination`]), or for a
    /// special `dest`, in the temporary directory.
    pub fn create(dest: &Path) -> Result<AtomicFile, Error> {
        if is_special(dest) {
            let dir = std::env::temp_dir();
            let name = dest.file_name().unwrap_or("output".as_ref());
            let (temp, file) = create_hidden(&dir, name, "tmp").map_err(|e| {
                Error::Input(format!(
                    "{}: its bytes wait in {} until the run ends, and no file can be made there: {e}",
                    dest.display(),
                    dir.display()
                ))
            })?;
            // the open file stays; its name goes now, so none is left behind
            let _ = std::fs::remove_file(&temp);
            return Ok(AtomicFile { dest: dest.to_path_buf(), temp: None, writer: Some(BufWriter::new(file)) });
        }
        let dest = destination(dest).ok_or_else(|| Error::Input(format!("{}: {LINK_LOOP}", dest.display())))?;
        let name = dest.file_name().ok_or_else(|| Error::Input(format!("{}: names a directory, not a file", dest.display())))?;
        let (temp, file) = create_hidden(&parent_dir(&dest), name, "tmp").map_err(|source| io_err(&dest, source))?;
        Ok(AtomicFile { dest, temp: Some(temp), writer: Some(BufWriter::new(file)) })
    }

    /// Where the bytes go until the commit.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.writer.as_mut().expect("only commit and keep_as take the writer, and they consume self")
    }

    /// Whether the destination is special ([`is_special`]): the bytes go
    /// into it at the commit, and a failed run's are kept nowhere.
    pub fn is_special(&self) -> bool {
        self.temp.is_none()
    }

    /// Flushes the file and renames it over the destination (or, for a
    /// special destination, writes its bytes into it).
    pub fn commit(mut self) -> Result<(), Error> {
        let Some(temp) = self.temp.clone() else {
            return self.copy_into_dest();
        };
        let dest = self.dest.clone();
        self.finish_as(&temp, &dest)
    }

    /// Flushes what was written and keeps it under `first`, or when a file
    /// (or anything) is there, under the first of `first.1`, `first.2`, ...
    /// that is free (a run's partial output, kept apart from the
    /// destination). Never replaces a file: the name is taken by a hard link
    /// (or, where the file system has none, a file created new), both of
    /// which fail on an existing name. Returns the path kept. A special
    /// destination's bytes have no file to keep: refused.
    pub fn keep_beside(mut self, first: &Path) -> Result<PathBuf, Error> {
        let writer = self.writer.take().expect("finished once");
        let Some(temp) = self.temp.clone() else {
            return Err(Error::Input(format!("{}: no regular file: no partial output is kept beside it", self.dest.display())));
        };
        let kept = match writer.into_inner() {
            Ok(file) => {
                drop(file);
                keep_new(&temp, first)
            }
            // the bytes were on their way to `first`, not to the destination
            Err(e) => Err(io_err(first, e.into_error())),
        };
        let _ = std::fs::remove_file(&temp);
        kept
    }

    /// Flushes and renames; on any failure (a full disk shows first at the
    /// flush) the temporary file is removed, so none stays behind.
    fn finish_as(&mut self, temp: &Path, path: &Path) -> Result<(), Error> {
        let writer = self.writer.take().expect("finished once");
        let done = match writer.into_inner() {
            Ok(file) => {
                drop(file);
                std::fs::rename(temp, path).map_err(|source| io_err(path, source))
            }
            Err(e) => Err(io_err(&self.dest, e.into_error())),
        };
        if done.is_err() {
            let _ = std::fs::remove_file(temp);
        }
        done
    }

    /// Writes the bytes held so far into the special destination, opened
    /// as it is: no file is created there and none truncated (a FIFO's
    /// open waits for its reader, as a shell's `>` does).
    fn copy_into_dest(&mut self) -> Result<(), Error> {
        use std::io::{Seek, SeekFrom};
        let writer = self.writer.take().expect("finished once");
        let dest = self.dest.clone();
        let mut held = writer.into_inner().map_err(|e| io_err(&dest, e.into_error()))?;
        held.seek(SeekFrom::Start(0)).map_err(|source| io_err(&dest, source))?;
        let mut out = std::fs::OpenOptions::new().write(true).open(&dest).map_err(|source| io_err(&dest, source))?;
        // a regular file put there during the run would keep its old tail
        // past the bytes written, untruncated: not written
        if out.metadata().is_ok_and(|m| m.is_file()) {
            return Err(Error::Input(format!("{}: became a regular file during the run; not written", dest.display())));
        }
        std::io::copy(&mut held, &mut out).and_then(|_| out.flush()).map_err(|source| io_err(&dest, source))?;
        Ok(())
    }
}

/// Whether `path` exists (through links) and is neither a regular file nor
/// a directory: a character or block device, a FIFO, a socket. Such a
/// destination is written into, never replaced ([`AtomicFile`]).
pub fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// The most numbered names [`AtomicFile::keep_beside`] tries.
const KEEP_TRIES: usize = 1000;

/// Gives `temp`'s bytes the first free name of `first`, `first.1`, ...;
/// `temp` itself stays (the caller removes it).
fn keep_new(temp: &Path, first: &Path) -> Result<PathBuf, Error> {
    for k in 0..KEEP_TRIES {
        let path = if k == 0 {
            first.to_path_buf()
        } else {
            let mut name = first.as_os_str().to_os_string();
            name.push(format!(".{k}"));
            PathBuf::from(name)
        };
        match std::fs::hard_link(temp, &path) {
            Ok(()) => return Ok(path),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            // no hard links here (or across devices): copy into a file made new
            Err(_) => match std::fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut out) => {
                    let copied =
                        File::open(temp).and_then(|mut from| std::io::copy(&mut from, &mut out)).and_then(|_| out.sync_all());
                    return match copied {
                        Ok(()) => Ok(path),
                        Err(source) => {
                            // the file is this run's own: no half copy stays
                            let _ = std::fs::remove_file(&path);
                            Err(io_err(&path, source))
                        }
                    };
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(source) => return Err(io_err(&path, source)),
            },
        }
    }
    Err(Error::Input(format!("{} and {} more numbered names beside it are all taken", first.display(), KEEP_TRIES - 1)))
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if let (Some(_), Some(temp)) = (self.writer.take(), &self.temp) {
            let _ = std::fs::remove_file(temp);
        }
    }
}

/// The most hidden names [`create_hidden`] tries for one file.
pub(crate) const HIDDEN_TRIES: u32 = 100;

/// The `k`-th name [`create_hidden`] tries in `dir` for a file of this
/// process beside `name`: `.NAME.verlet-PID.EXT`, then
/// `.NAME.verlet-PID-K.EXT` for k = 1, 2, ...
pub(crate) fn hidden_name(dir: &Path, name: &std::ffi::OsStr, k: u32, ext: &str) -> PathBuf {
    let pid = std::process::id();
    let name = name.to_string_lossy();
    match k {
        0 => dir.join(format!(".{name}.verlet-{pid}.{ext}")),
        k => dir.join(format!(".{name}.verlet-{pid}-{k}.{ext}")),
    }
}

/// Creates a new file in `dir` under the first free `hidden_name`,
/// opened for reading and writing. Each name is created new (`O_EXCL`),
/// which refuses any name already taken, a symbolic link included, so a
/// link planted at the predictable name is never followed: the temporary
/// file was opened with `O_TRUNC` through such a link, and the link's
/// target (any file the user could write) was overwritten.
pub fn create_hidden(dir: &Path, name: &std::ffi::OsStr, ext: &str) -> std::io::Result<(PathBuf, File)> {
    for k in 0..HIDDEN_TRIES {
        let path = hidden_name(dir, name, k, ext);
        match std::fs::OpenOptions::new().read(true).write(true).create_new(true).open(&path) {
            Ok(file) => return Ok((path, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::AlreadyExists,
        format!(
            "{} and the {} hidden names after it are all taken by files this run did not make",
            hidden_name(dir, name, 0, ext).display(),
            HIDDEN_TRIES - 1
        ),
    ))
}

/// Where a write to `path` lands: its canonical form if something is
/// there, else the path itself, or for a symbolic link to nothing (a
/// dangling link), the name its links lead to, each read relative to its
/// own directory. The write goes to that name, as a shell's `>` writes
/// there, and the link stays: the link was replaced by a regular file and
/// its target never made. `None` for links that lead round in a loop (or
/// more than `MAX_LINKS` deep).
pub fn destination(path: &Path) -> Option<PathBuf> {
    if let Ok(real) = std::fs::canonicalize(path) {
        return Some(real);
    }
    let mut at = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        // not a link, or nothing there: the write lands here
        let Ok(next) = std::fs::read_link(&at) else { return Some(at) };
        at = match at.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir.join(next),
            _ => next,
        };
    }
    None
}

/// The most symbolic links [`destination`] follows, as Linux's path walk
/// (past 40 it fails with `ELOOP`).
const MAX_LINKS: usize = 40;

/// Why a path of links that leads round in a loop is not written.
pub const LINK_LOOP: &str = "it is a symbolic link that leads round in a loop (or more than 40 links deep)";

/// The directory a path's file is in (`.` for a bare name).
pub fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh empty directory under the temp dir.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("verlet-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    /// `text` written to `path` through an [`AtomicFile`].
    fn write_file(path: &Path, text: &str) -> Result<(), Error> {
        let mut file = AtomicFile::create(path)?;
        file.writer().write_all(text.as_bytes()).map_err(|source| io_err(path, source))?;
        file.commit()
    }

    #[test]
    fn a_failed_commit_or_keep_leaves_no_temporary_file() {
        let dir = scratch("failed-commit");
        // the destination turns into a directory with a file in it: the rename fails
        let dest = dir.join("out.csv");
        let mut file = AtomicFile::create(&dest).unwrap();
        file.writer().write_all(b"rows\n").unwrap();
        std::fs::create_dir(&dest).unwrap();
        std::fs::write(dest.join("inside"), b"x").unwrap();
        assert!(file.commit().is_err());
        assert_eq!(listing(&dir), ["out.csv"]);
        // no directory for the kept rows: the keep fails, naming where they were to go
        let dest = dir.join("t.csv");
        let mut file = AtomicFile::create(&dest).unwrap();
        file.writer().write_all(b"rows\n").unwrap();
        let nowhere = dir.join("no").join("t.csv.partial");
        let err = file.keep_beside(&nowhere).unwrap_err().to_string();
        assert!(err.contains("t.csv.partial"), "{err}");
        assert_eq!(listing(&dir), ["out.csv"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn kept_rows_take_the_first_free_name() {
        let dir = scratch("keep");
        let first = dir.join("t.csv.partial");
        std::fs::write(&first, b"mine").unwrap();
        std::fs::write(dir.join("t.csv.partial.1"), b"mine too").unwrap();
        let mut file = AtomicFile::create(&dir.join("t.csv")).unwrap();
        file.writer().write_all(b"rows\n").unwrap();
        assert_eq!(file.keep_beside(&first).unwrap(), dir.join("t.csv.partial.2"));
        assert_eq!(std::fs::read(&first).unwrap(), b"mine");
        assert_eq!(std::fs::read(dir.join("t.csv.partial.2")).unwrap(), b"rows\n");
        assert_eq!(listing(&dir), ["t.csv.partial", "t.csv.partial.1", "t.csv.partial.2"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_the_temporary_name_is_not_followed() {
        let dir = scratch("planted");
        let victim = dir.join("victim.txt");
        std::fs::write(&victim, b"precious user data\n").unwrap();
        // the first two names the run tries, each a link to the victim
        let dest = dir.join("out.json");
        let first = dir.join(format!(".out.json.verlet-{}.tmp", std::process::id()));
        std::os::unix::fs::symlink("victim.txt", &first).unwrap();
        std::os::unix::fs::symlink("victim.txt", hidden_name(&dir, "out.json".as_ref(), 1, "tmp")).unwrap();
        write_file(&dest, "{}").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious user data\n", "the link's target was overwritten");
        assert!(std::fs::symlink_metadata(&dest).unwrap().is_file(), "out.json is a file of its own");
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "{}");
        // every name taken: a clear error, and still nothing overwritten
        for k in 2..HIDDEN_TRIES {
            std::os::unix::fs::symlink("victim.txt", hidden_name(&dir, "out.json".as_ref(), k, "tmp")).unwrap();
        }
        let err = write_file(&dest, "[]").unwrap_err().to_string();
        assert!(err.contains("out.json") && err.contains("all taken"), "{err}");
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious user data\n");
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "{}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
