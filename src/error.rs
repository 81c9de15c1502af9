//! Crate-wide error type. Every error carries enough context (file, line, key,
//! what was expected) for a user to fix the input without reading the code.
//! Must never: panic, or lose the original cause.

use std::path::PathBuf;

/// Convenience alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in tyrekit, outside the FMI boundary
/// (which maps these to `fmi2Error` with the message logged).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A `.tir` property file could not be read or understood.
    #[error("{file}:{line}: {key}: {message}")]
    Tir {
        /// The file's name or path, as given by the caller.
        file: String,
        /// 1-based line of the offending entry (0 when the problem is not on one line).
        line: usize,
        /// The `.tir` key concerned, e.g. `FNOMIN` ("" when it concerns no key).
        key: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A recording (TTC .mat/.dat, TYDEX, CSV) could not be read.
    #[error("{file}: {location}: {message}")]
    Recording {
        /// The recording's name or path, as given by the caller.
        file: String,
        /// Where in it, in the format's own terms (e.g. "line 12", "channel 'FZ'", "gzip").
        location: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// An input value is outside what the model can evaluate.
    #[error("invalid input: {0}")]
    Input(String),
    /// A numerical procedure (fit, root search) failed.
    #[error("numerical failure: {0}")]
    Numeric(String),
    /// I/O on a named path.
    #[error("{path}: {source}")]
    Io {
        /// The path that was being read or written.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Anything else, with a message.
    #[error("{0}")]
    Other(String),
}

impl Error {
    /// Wrap an `std::io::Error` with the path it concerns.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}
