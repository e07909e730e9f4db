//! The command line's output paths: each checked before any work (it can
//! be written, and it is no input and no other output), and written at the
//! end of a run whatever became of the others.

use std::io::Write;
use std::path::{Path, PathBuf};

use verlet::output::{create_hidden, destination, frame_name, is_special, parent_dir, AtomicFile, LINK_LOOP};
use verlet::Error;

/// Writes `text` to `path` atomically ([`AtomicFile`]), naming the path on
/// failure.
pub fn write_file(path: &Path, text: &str) -> Result<(), Error> {
    let mut file = AtomicFile::create(path)?;
    file.writer().write_all(text.as_bytes()).map_err(|source| io_err(path, source))?;
    file.commit()
}

fn io_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}

/// Checks, before any work, that `path` can be written as the output `flag`
/// names: it is not a directory, and its directory exists and takes new
/// files (probed by creating and removing a hidden file there). Creates
/// nothing that stays. A special destination ([`is_special`]) is checked
/// by [`check_special`] instead.
pub fn check_output(flag: &str, path: &Path) -> Result<(), Error> {
    let refuse = |why: String| Err(Error::Input(format!("{flag}: cannot write {}: {why}", path.display())));
    if path.is_dir() {
        return refuse("it is a directory".into());
    }
    if is_special(path) {
        return check_special(path).or_else(refuse);
    }
    let Some(target) = destination(path) else {
        return refuse(LINK_LOOP.into());
    };
    let Some(name) = target.file_name() else {
        return refuse("it names a directory, not a file".into());
    };
    let dir = parent_dir(&target);
    if !dir.is_dir() {
        let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
        let to = if link { format!(" (it is a symbolic link to {})", target.display()) } else { String::new() };
        return refuse(format!("no directory {}{to}", dir.display()));
    }
    match create_hidden(&dir, name, "probe") {
        Ok((probe, _)) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => refuse(format!("cannot create files in {}: {e}", dir.display())),
    }
}

/// Checks, before any work, that `dir` can take the files the output
/// `flag` writes into it (`--frames`): where it exists, it is a directory
/// and takes new files (probed as [`check_output`] probes, so that one
/// such as `/proc/self` is refused before the run, not at its first
/// frame); where it does not, the nearest directory above it that exists
/// takes them, so that it can be made there. Creates nothing that stays.
pub fn check_output_dir(flag: &str, dir: &Path) -> Result<(), Error> {
    let refuse = |why: String| Err(Error::Input(format!("{flag}: cannot create directory {}: {why}", dir.display())));
    let probe = |at: &Path| {
        let (probe, _) = create_hidden(at, "frames".as_ref(), "probe")?;
        std::fs::remove_file(probe)
    };
    if dir.exists() {
        if !dir.is_dir() {
            return refuse("a file is there".into());
        }
        return probe(dir)
            .map_err(|e| Error::Input(format!("{flag}: cannot write into {}: cannot create files there: {e}", dir.display())));
    }
    if std::fs::symlink_metadata(dir).is_ok() {
        return refuse("it is a symbolic link to nothing".into());
    }
    // made with every missing directory above it: the nearest one there must take them
    let mut above = dir.ancestors().skip(1).map(|a| if a.as_os_str().is_empty() { Path::new(".") } else { a });
    let Some(above) = above.find(|a| std::fs::symlink_metadata(a).is_ok()) else {
        return refuse("no directory above it exists".into());
    };
    if !above.is_dir() {
        return refuse(format!("{} is not a directory", above.display()));
    }
    probe(above).or_else(|e| refuse(format!("cannot create files in {}: {e}", above.display())))
}

/// Checks a special destination ([`is_special`]): no file is made beside
/// it, so its directory need not take files, but the temporary directory
/// where its bytes wait must. A socket takes no `open` and is refused. A
/// device is opened for writing and closed, as a shell's `>` would open it
/// (nothing is written). A FIFO is not opened: opening and closing its
/// writing end would hand a reader already waiting an end of file, and
/// its open at the end waits for a reader as a shell's `>` does.
fn check_special(path: &Path) -> Result<(), String> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = std::fs::metadata(path).map_err(|e| e.to_string())?.file_type();
        if kind.is_socket() {
            return Err("it is a socket, which cannot be opened for writing".into());
        }
        if !kind.is_fifo() {
            std::fs::OpenOptions::new().write(true).open(path).map_err(|e| format!("cannot open it for writing: {e}"))?;
        }
    }
    let dir = std::env::temp_dir();
    let name = path.file_name().unwrap_or("output".as_ref());
    match create_hidden(&dir, name, "probe") {
        Ok((probe, _)) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(format!("its bytes wait in {} until the run ends, and no file can be made there: {e}", dir.display())),
    }
}

/// The file a path names, for comparing paths: its canonical form if it
/// exists, else its directory's [`canonical_dir`] joined with its name (a
/// dangling link's: the name a write through it makes, [`destination`]).
fn resolve(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let path = destination(path).unwrap_or_else(|| path.to_path_buf());
    match path.file_name() {
        Some(name) => canonical_dir(&parent_dir(&path)).join(name),
        None => path,
    }
}

/// A directory's canonical form, or where it is not there (yet: one that
/// `--frames` makes), its nearest existing parent's joined with the rest,
/// so that `nd` and `./nd` compare equal before `nd` is made.
fn canonical_dir(dir: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(dir) {
        return p;
    }
    match dir.file_name() {
        // the parent is shorter: this ends
        Some(name) => canonical_dir(&parent_dir(dir)).join(name),
        None => dir.to_path_buf(),
    }
}

/// Whether `path` names a file directly in `dir`, compared as files
/// through links; neither need exist yet.
pub fn is_in_dir(path: &Path, dir: &Path) -> bool {
    resolve(path).parent().is_some_and(|p| same_file(p, dir))
}

/// Whether two paths name one file (the same inode, through links too).
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    resolve(a) == resolve(b)
}

/// Whether a frame written by `--frames` may take this name
/// (`frame_` then six or more digits, `.png`; see [`frame_name`]).
pub fn is_frame_name(name: &std::ffi::OsStr) -> bool {
    let name = name.as_encoded_bytes();
    let digits = name.strip_prefix(b"frame_").and_then(|rest| rest.strip_suffix(b".png"));
    digits.is_some_and(|d| d.len() >= 6 && d.iter().all(u8::is_ascii_digit))
}

/// The `k` of a name [`frame_name`] gives (`frame_000012.png`: 12); `None`
/// for any other name, frame-named ones included (`frame_0000012.png`,
/// which no run writes).
pub fn frame_number(name: &std::ffi::OsStr) -> Option<u64> {
    let k: u64 = name.to_str()?.strip_prefix("frame_")?.strip_suffix(".png")?.parse().ok()?;
    (name == frame_name(k).as_str()).then_some(k)
}

/// Refuses, for `--frames DIR`, an input or another output that a frame
/// would replace: a file in DIR under a frame's name (compared as files,
/// through links), or a frame-named link in DIR to one.
pub fn check_frames_dir(dir: &Path, inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<(), Error> {
    let named = |path: &Path| {
        inputs
            .iter()
            .find(|(_, p)| same_file(path, p))
            .map(|(input, _)| format!("{input}, an input"))
            .or_else(|| outputs.iter().find(|(_, p)| same_file(path, p)).map(|(flag, _)| format!("{flag}'s output")))
    };
    let refuse = |path: &Path, what: String| {
        Err(Error::Input(format!(
            "--frames: a frame written into {} would overwrite {}, which is {what}; give another directory",
            dir.display(),
            path.display()
        )))
    };
    for (_, path) in inputs.iter().chain(outputs) {
        if is_in_dir(path, dir) && resolve(path).file_name().is_some_and(is_frame_name) {
            return refuse(path, named(path).unwrap_or_default());
        }
    }
    // a frame-named link in DIR to a file elsewhere: the frame would be written through it
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            if is_frame_name(&entry.file_name()) {
                if let Some(what) = named(&entry.path()) {
                    return refuse(&entry.path(), what);
                }
            }
        }
    }
    Ok(())
}

/// Refuses an output that names an input, or the same file as another
/// output: `(flag, path)` pairs, the flag as the user gave it (a scene
/// file given without a flag is named "the scene").
pub fn check_distinct(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<(), Error> {
    for (k, (flag, out)) in outputs.iter().enumerate() {
        if let Some((input, _)) = inputs.iter().find(|(_, p)| same_file(out, p)) {
            return Err(Error::Input(format!(
                "{flag}: {} is {input}, an input: writing it would destroy it; give another path",
                out.display()
            )));
        }
        if let Some((other, _)) = outputs[..k].iter().find(|(_, p)| same_file(out, p)) {
            return Err(Error::Input(format!(
                "{flag}: {} is also {other}'s output: one would overwrite the other; give each its own path",
                out.display()
            )));
        }
    }
    Ok(())
}

/// One output of a run to write at its end: its flag, its path, and what
/// writes it.
pub type EndWrite<'a> = (&'a str, &'a Path, Box<dyn FnOnce() -> Result<(), Error> + 'a>);

/// Writes each of a run's outputs whatever became of the others: a GIF that
/// could not be written once left `--state-out` unwritten too, unsaid. On a
/// failure the error is the first one's, and says which outputs were
/// written all the same and which others failed.
pub fn write_each(writes: Vec<EndWrite<'_>>) -> Result<(), Error> {
    let mut failed: Vec<String> = Vec::new();
    let mut written: Vec<String> = Vec::new();
    for (flag, path, write) in writes {
        match write() {
            Ok(()) => written.push(format!("{flag} {}", path.display())),
            Err(e) => failed.push(e.to_string()),
        }
    }
    let Some((first, others)) = failed.split_first() else {
        return Ok(());
    };
    let mut message = first.clone();
    if !written.is_empty() {
        message.push_str(&format!(" (written all the same: {})", written.join(", ")));
    }
    for other in others {
        message.push_str(&format!("; and {other}"));
    }
    Err(Error::Input(message))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs::File;

    /// A fresh empty directory under the temp dir.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("verlet-paths-{name}-{}", std::process::id()));
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

    #[test]
    fn every_output_is_written_whatever_became_of_the_others() {
        let dir = scratch("write-each");
        // a GIF and a sheet whose destinations turned into directories with
        // a file in them during the run: their renames fail
        let (gif, sheet, state) = (dir.join("run.gif"), dir.join("sheet.png"), dir.join("state.json"));
        for blocked in [&gif, &sheet] {
            std::fs::create_dir(blocked).unwrap();
            std::fs::write(blocked.join("inside"), b"x").unwrap();
        }
        let write = |flag: &'static str, path: &'static Path| -> Box<dyn FnOnce() -> Result<(), Error>> {
            Box::new(move || write_file(path, "{}").map_err(|e| Error::Input(format!("{flag}: {e}"))))
        };
        let leak = |p: &PathBuf| -> &'static Path { Box::leak(p.clone().into_boxed_path()) };
        let (gif_at, sheet_at, state_at) = (leak(&gif), leak(&sheet), leak(&state));
        let err = write_each(vec![
            ("--gif", gif_at, write("--gif", gif_at)),
            ("--state-out", state_at, write("--state-out", state_at)),
            ("--contact-sheet", sheet_at, write("--contact-sheet", sheet_at)),
        ])
        .unwrap_err()
        .to_string();
        assert!(err.starts_with("--gif: "), "{err}");
        assert!(err.contains(&format!("(written all the same: --state-out {})", state.display())), "{err}");
        assert!(err.contains("; and --contact-sheet: "), "{err}");
        assert_eq!(std::fs::read_to_string(&state).unwrap(), "{}");
        assert_eq!(listing(&dir), ["run.gif", "sheet.png", "state.json"], "no temporary file left");
        // all written: no error
        assert!(write_each(vec![("--state-out", state_at, write("--state-out", state_at))]).is_ok());
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Whether this process runs as root (it owns its `/proc/self`).
    #[cfg(unix)]
    fn is_root() -> bool {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0)
    }

    /// What `held` (both ends of a FIFO) has to read, up to a marker
    /// written last: the FIFO's bytes so far, without waiting for more.
    #[cfg(unix)]
    fn drain(held: &mut File) -> Vec<u8> {
        use std::io::Read;
        held.write_all(b"<end>").unwrap();
        let mut got = Vec::new();
        let mut buf = [0u8; 4096];
        while !got.ends_with(b"<end>") {
            let n = held.read(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        got.truncate(got.len() - b"<end>".len());
        got
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_or_device_is_written_into_never_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("special");
        let fifo = dir.join("fifo");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        // both ends held here (Linux opens a FIFO read-write at once): the
        // commit's open finds a reader, and what came through can be read
        let mut held = std::fs::OpenOptions::new().read(true).write(true).open(&fifo).unwrap();
        check_output("--trace", &fifo).unwrap();
        let mut file = AtomicFile::create(&fifo).unwrap();
        file.writer().write_all(b"rows\n").unwrap();
        file.writer().flush().unwrap();
        assert_eq!(drain(&mut held), b"", "bytes reached the FIFO before the commit");
        file.commit().unwrap();
        assert_eq!(drain(&mut held), b"rows\n");
        // a failed run's: nothing reaches it
        let mut file = AtomicFile::create(&fifo).unwrap();
        file.writer().write_all(b"half\n").unwrap();
        drop(file);
        assert_eq!(drain(&mut held), b"");
        write_file(&fifo, "{}").unwrap();
        assert_eq!(drain(&mut held), b"{}");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
        assert_eq!(listing(&dir), ["fifo"], "no file made beside it");
        // a socket takes no open: refused before the run, by name
        let socket = dir.join("socket");
        let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
        let err = check_output("--state-out", &socket).unwrap_err().to_string();
        assert!(err.starts_with("--state-out: cannot write") && err.contains("socket"), "{err}");
        // device nodes of our own (never the system's /dev/null): root only
        if is_root() {
            let (null, full) = (dir.join("null"), dir.join("full"));
            for (node, minor) in [(&null, "3"), (&full, "7")] {
                let made = std::process::Command::new("mknod").arg(node).args(["c", "1", minor]).status().unwrap();
                assert!(made.success(), "mknod {}", node.display());
            }
            check_output("--state-out", &null).unwrap();
            write_file(&null, "{}").unwrap();
            let err = write_file(&full, "{}").unwrap_err().to_string();
            assert!(err.contains("full") && err.contains("No space left"), "{err}");
            for node in [&null, &full] {
                assert!(std::fs::metadata(node).unwrap().file_type().is_char_device(), "{} was replaced", node.display());
            }
            assert_eq!(listing(&dir), ["fifo", "full", "null", "socket"]);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_to_nothing_is_written_through_to_its_target() {
        use std::os::unix::fs::symlink;
        let dir = scratch("dangling");
        let is_link = |p: &Path| std::fs::symlink_metadata(p).unwrap().file_type().is_symlink();
        // a link to a name not there, and a chain of two: the target is made, the links stay
        let (dangling, target) = (dir.join("dangling"), dir.join("target.json"));
        symlink("target.json", &dangling).unwrap();
        let (first, second, end) = (dir.join("first"), dir.join("second"), dir.join("sub").join("end.csv"));
        std::fs::create_dir(dir.join("sub")).unwrap();
        symlink("second", &first).unwrap();
        symlink(&end, &second).unwrap();
        for (link, to) in [(&dangling, &target), (&first, &end)] {
            check_output("--state-out", link).unwrap();
            assert!(same_file(link, to), "{} and {} are one output", link.display(), to.display());
            write_file(link, "{}").unwrap();
            assert!(is_link(link), "{} was replaced", link.display());
            assert_eq!(std::fs::read_to_string(to).unwrap(), "{}");
        }
        assert!(is_link(&second));
        // a link into a directory not there, and a loop: refused, and nothing changes
        let (lost, round, about) = (dir.join("lost"), dir.join("round"), dir.join("about"));
        symlink("no/such/dir/x.json", &lost).unwrap();
        symlink("about", &round).unwrap();
        symlink("round", &about).unwrap();
        for (link, why) in [(&lost, "no directory"), (&round, "loop")] {
            let err = check_output("--trace", link).unwrap_err().to_string();
            assert!(err.starts_with("--trace: cannot write") && err.contains(why), "{err}");
            assert!(write_file(link, "{}").is_err(), "{}", link.display());
            assert!(is_link(link), "{} was replaced", link.display());
        }
        assert_eq!(listing(&dir), ["about", "dangling", "first", "lost", "round", "second", "sub", "target.json"]);
        assert_eq!(listing(&dir.join("sub")), ["end.csv"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn frame_names_are_recognised() {
        assert!(is_frame_name(frame_name(0).as_ref()));
        assert!(is_frame_name(frame_name(12_345_678).as_ref()));
        for name in ["frame_1.png", "frame_000001.PNG", "frame_00000a.png", "xframe_000001.png", "frame_000001.png.tmp"] {
            assert!(!is_frame_name(name.as_ref()), "{name}");
        }
        for k in [0, 12, 999_999, 1_000_000, u64::MAX] {
            assert_eq!(frame_number(frame_name(k).as_ref()), Some(k));
        }
        for name in ["frame_0000012.png", "frame_+00012.png", "frame_99999999999999999999.png", "frame_1.png"] {
            assert_eq!(frame_number(name.as_ref()), None, "{name}");
        }
    }
}
