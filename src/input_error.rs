//! Errors of reading model files, with file and line (below `error`, which wraps them, and
//! `io`, which makes them).

/// A model file could not be read or parsed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InputError {
    /// The file could not be read.
    #[error("cannot read {path}: {message}")]
    Read {
        /// File.
        path: String,
        /// OS message.
        message: String,
    },
    /// The extension names no known format.
    #[error("{path}: unknown model format (use .toml, .json or .inp)")]
    UnknownFormat {
        /// File.
        path: String,
    },
    /// A syntax or schema error.
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// File.
        path: String,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// An Abaqus keyword this reader does not support.
    #[error("{path}:{line}: unsupported Abaqus keyword *{keyword}")]
    UnsupportedKeyword {
        /// File.
        path: String,
        /// Line.
        line: usize,
        /// Keyword as written.
        keyword: String,
    },
}
