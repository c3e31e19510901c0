//! Typed library errors. Each message names the file or field at fault and what was expected, so the binary
//! can print it as a single line.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },

    #[error("{path}: {message}")]
    BadFile { path: PathBuf, message: String },

    #[error("{0}")]
    InvalidInput(String),

    #[error("cancelled by the user")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), source }
    }

    pub fn bad_file(path: &Path, message: impl Into<String>) -> Self {
        Error::BadFile { path: path.to_path_buf(), message: message.into() }
    }
}
