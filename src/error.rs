//! Typed library errors: a kind with the data a caller can act on, and the context (the file, the field) the
//! error passed through on its way up. Rendered, an error is a single line that names the file or field at
//! fault, what was expected and the fix, so the binary prints it as it is. Callers match on [`ErrorKind`]: a
//! budget error can be retried with a larger limit, a diverged run with a smaller learning rate, an
//! unfinished run resumed.

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong, with the data a caller can act on.
#[derive(Debug)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The OS refused a read or write.
    Io(std::io::Error),
    /// A file's content is malformed or unsuitable (wrong format, wrong kind, wrong env, bad values).
    Invalid(String),
    /// Settings that cannot work: a flag, a config-file key or value, an unsupported combination.
    Config(String),
    /// Data in memory that a job cannot use (too few rows, missing actions, non-finite values).
    Data(String),
    /// Something of the wrong size: `name` is `found` where `expected` was needed.
    BadShape { name: String, found: String, expected: String },
    /// A checkpoint made by method `found` where one of `supported` was needed.
    WrongMethod { found: String, supported: String },
    /// A training run that stopped at `step` of `total` where a finished one was needed.
    Unfinished { step: u64, total: u64 },
    /// The work would exceed a limit; raising `flag` (to at least `need`, over `limit`) may let it run.
    Budget { flag: String, need: f64, limit: f64, message: String },
    /// Numerics broke down (a non-finite loss, a covariance that lost definiteness), at `step` with `loss`
    /// where a training loop knows them.
    Diverged { step: Option<u64>, loss: Option<f64>, message: String },
    /// The user asked the job to stop.
    Cancelled,
    /// The user stopped a training run, which kept its checkpoint at `step` of `total` and can go on.
    Stopped { step: u64, total: u64 },
}

/// Where an error happened, outermost first: the files and fields it was read from.
#[derive(Debug, Clone, PartialEq)]
enum Context {
    Path(PathBuf),
    Field(String),
}

#[derive(Debug)]
pub struct Error {
    kind: ErrorKind,
    context: Vec<Context>,
}

pub type Result<T> = std::result::Result<T, Error>;

/// Refuses settings that cannot work: `return Err(Error::config(format!(..)))`, the `bail!` of option checks.
#[macro_export]
macro_rules! refuse {
    ($($arg:tt)*) => {
        return Err($crate::Error::config(format!($($arg)*)))
    };
}

impl Error {
    pub fn new(kind: ErrorKind) -> Self {
        Error { kind, context: Vec::new() }
    }

    pub fn kind(&self) -> &ErrorKind {
        &self.kind
    }

    pub fn is_cancelled(&self) -> bool {
        matches!(self.kind, ErrorKind::Cancelled | ErrorKind::Stopped { .. })
    }

    /// The innermost file the error names, if any.
    pub fn path(&self) -> Option<&Path> {
        self.context.iter().rev().find_map(|c| match c {
            Context::Path(p) => Some(p.as_path()),
            Context::Field(_) => None,
        })
    }

    /// The error as it happened in reading `path`.
    pub fn at(mut self, path: &Path) -> Self {
        self.context.insert(0, Context::Path(path.to_path_buf()));
        self
    }

    /// The error as it happened in field `name` (of a config, a record, a flag).
    pub fn field(mut self, name: impl Into<String>) -> Self {
        self.context.insert(0, Context::Field(name.into()));
        self
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::new(ErrorKind::Io(source)).at(path)
    }

    pub fn bad_file(path: &Path, message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Invalid(message.into())).at(path)
    }

    pub fn config(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Config(message.into()))
    }

    pub fn data(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Data(message.into()))
    }

    pub fn cancelled() -> Self {
        Error::new(ErrorKind::Cancelled)
    }

    pub fn stopped(step: u64, total: u64) -> Self {
        Error::new(ErrorKind::Stopped { step, total })
    }

    pub fn diverged(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Diverged { step: None, loss: None, message: message.into() })
    }

    /// A training loop's divergence: the loss went to `loss` at `step`.
    pub fn diverged_at(step: u64, loss: f64, message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Diverged { step: Some(step), loss: Some(loss), message: message.into() })
    }

    pub fn budget(flag: impl Into<String>, need: f64, limit: f64, message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Budget { flag: flag.into(), need, limit, message: message.into() })
    }

    pub fn bad_shape(name: impl Into<String>, found: impl fmt::Display, expected: impl fmt::Display) -> Self {
        Error::new(ErrorKind::BadShape { name: name.into(), found: found.to_string(), expected: expected.to_string() })
    }

    pub fn wrong_method(found: impl Into<String>, supported: impl Into<String>) -> Self {
        Error::new(ErrorKind::WrongMethod { found: found.into(), supported: supported.into() })
    }

    pub fn unfinished(step: u64, total: u64) -> Self {
        Error::new(ErrorKind::Unfinished { step, total })
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for context in &self.context {
            match context {
                Context::Path(path) => write!(f, "{}: ", path.display())?,
                Context::Field(name) => write!(f, "{name}: ")?,
            }
        }
        match &self.kind {
            // The OS error is part of the message, not a `source`: printed with its chain it would appear twice.
            ErrorKind::Io(cause) => write!(f, "{cause}"),
            ErrorKind::Invalid(message) | ErrorKind::Config(message) | ErrorKind::Data(message) => f.write_str(message),
            ErrorKind::BadShape { name, found, expected } => write!(f, "{name} is {found}, expected {expected}"),
            ErrorKind::WrongMethod { found, supported } => {
                write!(f, "is a '{found}' checkpoint; this needs a {supported} run (`mbrl train {supported}`)")
            }
            ErrorKind::Unfinished { step, total } => {
                let dir = self.path().map(|p| p.display().to_string()).unwrap_or_else(|| "DIR".into());
                write!(f, "training stopped at step {step} of {total}; finish it with `mbrl train --resume {dir}`")
            }
            ErrorKind::Budget { message, .. } | ErrorKind::Diverged { message, .. } => f.write_str(message),
            ErrorKind::Cancelled => f.write_str("cancelled by the user"),
            ErrorKind::Stopped { step, total } => {
                let dir = self.path().map(|p| p.display().to_string()).unwrap_or_else(|| "DIR".into());
                write!(f, "stopped at step {step} of {total}; continue with `mbrl train --resume {dir}`")
            }
        }
    }
}

impl std::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn context_reads_outermost_first_and_the_kind_survives_it() {
        let err = Error::bad_shape("weights", "3×4", "4×4").field("model").at(Path::new("run/config.json"));
        assert_eq!(err.to_string(), "run/config.json: model: weights is 3×4, expected 4×4");
        assert!(matches!(err.kind(), ErrorKind::BadShape { found, .. } if found == "3×4"));
        assert_eq!(err.path(), Some(Path::new("run/config.json")));
    }

    #[test]
    fn an_unfinished_run_names_the_command_that_finishes_it() {
        let err = Error::unfinished(20, 30).at(Path::new("models/x"));
        assert_eq!(
            err.to_string(),
            "models/x: training stopped at step 20 of 30; finish it with `mbrl train --resume models/x`"
        );
        assert!(matches!(err.kind(), ErrorKind::Unfinished { step: 20, total: 30 }));
    }
}
