//! The one error type of the JSON files a user gives verlet, a scene or an
//! input track (`SceneError` and `TrackError` are this type): each message
//! fits on one line and names the file, the line and column of malformed
//! JSON, or the offending field's path, then why.

use std::path::PathBuf;

use crate::json::{classify_json_error, one_line, text_problem, JsonFault};

/// The most bodies any world holds: `scenes::MAX_BODIES`, which checks
/// that the two agree. Kept here too so that the loaders depend on nothing
/// above them (the built-in scenes build on the scene types).
const MAX_BODIES: u64 = 1 << 20;

/// The most bytes a scene or track file may hold: 1 KiB for each of the
/// most bodies any world holds; a scene as `verlet scene` writes it takes
/// about 340 bytes a body, a chain link with its joint about 380. 1 GiB: a
/// bound on memory, not a format limit.
pub const MAX_FILE_BYTES: u64 = 1024 * MAX_BODIES;

/// Which kind of file an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Scene,
    Track,
}

impl FileKind {
    /// The file as an I/O error names it.
    fn noun(self) -> &'static str {
        match self {
            FileKind::Scene => "scene file",
            FileKind::Track => "input track",
        }
    }

    /// What precedes the line and column of malformed JSON.
    fn syntax_prefix(self) -> &'static str {
        match self {
            FileKind::Scene => "",
            FileKind::Track => "input track, ",
        }
    }

    /// The name of the file's top level, for errors outside any field.
    fn top(self) -> &'static str {
        match self {
            FileKind::Scene => "scene",
            FileKind::Track => "track",
        }
    }
}

/// Why a scene or an input track could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("{}: cannot read {}: {}", one_line(&.path.display().to_string()), .file.noun(), one_line(&.error.to_string()))]
    Io {
        file: FileKind,
        /// The file that was being read.
        path: PathBuf,
        /// What went wrong.
        error: std::io::Error,
    },
    /// The text is not valid JSON.
    #[error("{}line {line}, column {column}: malformed JSON: {message}", .file.syntax_prefix())]
    Syntax {
        file: FileKind,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error (0 when the text is empty).
        column: usize,
        /// What the parser expected, and in which field if known.
        message: String,
    },
    /// A field is unknown, missing, of the wrong type or has a bad value.
    #[error("{field}: {message}")]
    Invalid {
        /// Path of the field, e.g. `bodies[3].shape.half_extents[1]`.
        field: String,
        /// Why it is refused, including the offending value.
        message: String,
    },
    /// A scene was given where an input track was expected (it has this
    /// top-level key).
    #[error("this looks like a scene file (it has {0:?}), not an input track ({{\"events\": [...]}}): a scene goes first, `verlet run SCENE.json --input TRACK.json`")]
    SceneGiven(String),
}

impl LoadError {
    /// The path of the offending field, when the error has one.
    pub fn field(&self) -> Option<&str> {
        match self {
            LoadError::Invalid { field, .. } => Some(field),
            _ => None,
        }
    }

    pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> LoadError {
        LoadError::Invalid { field: field.into(), message: message.into() }
    }

    pub(crate) fn missing(field: impl Into<String>) -> LoadError {
        LoadError::invalid(field, "is required but missing")
    }

    /// The text of a file of kind `file`, or why it cannot be read. Read
    /// in chunks so that garbage fails fast: a NUL byte (no JSON text holds
    /// one; `/dev/zero`) is refused with its line and column where it is
    /// met, and a file over [`MAX_FILE_BYTES`] as soon as that shows,
    /// before it takes the machine's memory.
    pub(crate) fn read(file: FileKind, path: &std::path::Path) -> Result<String, LoadError> {
        use std::io::Read;
        let io = |error| LoadError::Io { file, path: path.to_path_buf(), error };
        let too_large = || {
            io(std::io::Error::other(format!(
                "it is larger than {MAX_FILE_BYTES} bytes, more than a {} for the most bodies a world holds ({}) needs",
                file.noun(),
                MAX_BODIES
            )))
        };
        let mut from = std::fs::File::open(path).map_err(io)?;
        if from.metadata().is_ok_and(|m| m.is_file() && m.len() > MAX_FILE_BYTES) {
            return Err(too_large());
        }
        let mut bytes = Vec::new();
        let mut chunk = vec![0u8; 1 << 16];
        loop {
            let n = match from.read(&mut chunk) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(io(e)),
            };
            if let Some(k) = chunk[..n].iter().position(|&b| b == 0) {
                bytes.extend_from_slice(&chunk[..k]);
                let start = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
                let line = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
                let column = String::from_utf8_lossy(&bytes[start..]).chars().count() + 1;
                let message = "a NUL byte (0x00), which no JSON text holds: this is not a text file".to_string();
                return Err(LoadError::Syntax { file, line, column, message });
            }
            if (bytes.len() + n) as u64 > MAX_FILE_BYTES {
                return Err(too_large());
            }
            bytes.extend_from_slice(&chunk[..n]);
        }
        // as std::fs::read_to_string says it
        String::from_utf8(bytes)
            .map_err(|_| io(std::io::Error::new(std::io::ErrorKind::InvalidData, "stream did not contain valid UTF-8")))
    }

    /// Refuses text that is no JSON before parsing it (empty, a byte order
    /// mark, ...: see `text_problem`), with its line and column.
    pub(crate) fn check_text(file: FileKind, text: &str) -> Result<(), LoadError> {
        match text_problem(text) {
            Some((line, column, message)) => Err(LoadError::Syntax { file, line, column, message }),
            None => Ok(()),
        }
    }

    /// A serde_json error raised in `field` (as serde_path_to_error tracks
    /// it; None: the top level) of a file of kind `file`.
    pub(crate) fn from_json(file: FileKind, field: Option<String>, inner: serde_json::Error) -> LoadError {
        match classify_json_error(field, inner, file.top()) {
            JsonFault::Invalid { field, message } => LoadError::Invalid { field, message },
            JsonFault::Syntax { line, column, message } => LoadError::Syntax { file, line, column, message },
        }
    }
}
