//! The one error type of the JSON files a user gives verlet, a scene or an
//! input track (`SceneError` and `TrackError` are this type): each message
//! fits on one line and names the file, the line and column of malformed
//! JSON, or the offending field's path, then why.

use std::path::PathBuf;

use crate::scene::{classify_json_error, one_line, text_problem, JsonFault};

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

    /// The text of a file of kind `file`, or why it cannot be read.
    pub(crate) fn read(file: FileKind, path: &std::path::Path) -> Result<String, LoadError> {
        std::fs::read_to_string(path).map_err(|error| LoadError::Io { file, path: path.to_path_buf(), error })
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
