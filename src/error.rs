//! Typed library errors. Each message names the file or field at fault and what was expected, so the binary
//! can print it as a single line. The kinds let callers react differently: a budget error can be retried with a
//! larger limit, a diverged run with a smaller learning rate, a config error by fixing a flag or file.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The OS error is part of the message, not a `source`: printed with its chain it would appear twice.
    #[error("{path}: {cause}")]
    Io { path: PathBuf, cause: std::io::Error },

    /// A file whose content is malformed or unsuitable (wrong format, wrong kind, wrong env, bad values).
    #[error("{path}: {message}")]
    BadFile { path: PathBuf, message: String },

    /// Settings that cannot work: a flag, a config-file key or value, an unsupported combination.
    #[error("{0}")]
    Config(String),

    /// Data in memory that a job cannot use (too few rows, missing actions, non-finite values).
    #[error("{0}")]
    Data(String),

    /// The work would exceed a limit on memory, nodes or time; raising the named limit may let it run.
    #[error("{0}")]
    Budget(String),

    /// Numerics broke down (a non-finite loss, a covariance that lost definiteness).
    #[error("{0}")]
    Diverged(String),

    #[error("cancelled by the user")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), cause: source }
    }

    pub fn bad_file(path: &Path, message: impl Into<String>) -> Self {
        Error::BadFile { path: path.to_path_buf(), message: message.into() }
    }

    pub fn config(message: impl Into<String>) -> Self {
        Error::Config(message.into())
    }

    pub fn data(message: impl Into<String>) -> Self {
        Error::Data(message.into())
    }
}
