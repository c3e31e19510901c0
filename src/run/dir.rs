//! A run directory (`models/<name>/` for training, a report directory for eval): `config.json`,
//! `metrics.jsonl` and the job's outputs.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::monitor::JsonlMonitor;
use crate::error::{Error, Result};
use crate::util::atomic::write_json;

pub const CONFIG_FILE: &str = "config.json";
pub const METRICS_FILE: &str = "metrics.jsonl";

pub struct RunDir {
    path: PathBuf,
}

impl RunDir {
    /// Creates the directory (and parents). An existing directory is reused: its files are replaced.
    pub fn create(path: &Path) -> Result<Self> {
        if path.exists() && !path.is_dir() {
            return Err(Error::bad_file(path, "exists and is not a directory; expected a run directory"));
        }
        std::fs::create_dir_all(path).map_err(|e| Error::io(path, e))?;
        Ok(RunDir { path: path.to_path_buf() })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    pub fn write_config<T: Serialize>(&self, config: &T) -> Result<()> {
        write_json(&self.file(CONFIG_FILE), config)
    }

    pub fn metrics(&self) -> Result<JsonlMonitor> {
        let path = self.file(METRICS_FILE);
        JsonlMonitor::create(&path).map_err(|e| Error::io(&path, e))
    }
}

/// What every run records about how it was started, so a result can be traced back to its command.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct Provenance {
    pub mbrl_version: String,
    pub command_line: String,
    pub seed: u64,
    pub threads: usize,
    /// The commands that trained the run on past the total it was started with (`train --resume DIR --steps
    /// N`), oldest first; absent for runs that kept their total.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub extended_by: Vec<String>,
}

impl Provenance {
    pub fn new(command_line: String, seed: u64, threads: usize) -> Self {
        Provenance { mbrl_version: crate::VERSION.to_string(), command_line, seed, threads, extended_by: Vec::new() }
    }
}
