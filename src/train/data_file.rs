//! Data files as a run saw them (size and CRC-32), so `--resume` can refuse data that changed underneath.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::checkpoint::read_bounded;
use crate::error::{Error, Result};

/// Training data files larger than this are refused before reading.
pub const MAX_DATA_BYTES: u64 = 4 << 30;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataFile {
    pub path: PathBuf,
    pub bytes: u64,
    pub crc32: u32,
}

impl DataFile {
    pub fn fingerprint(path: &Path) -> Result<Self> {
        let bytes = read_bounded(path, MAX_DATA_BYTES)?;
        Ok(DataFile { path: path.to_path_buf(), bytes: bytes.len() as u64, crc32: crc32fast::hash(&bytes) })
    }

    pub fn verify_unchanged(&self) -> Result<()> {
        if DataFile::fingerprint(&self.path)? != *self {
            return Err(Error::bad_file(
                &self.path,
                "changed since the run started; resuming would not continue the same run",
            ));
        }
        Ok(())
    }
}

/// The `train/loss` values a run logged, by step, from its metrics file (for loss tables and plots).
pub fn loss_history(metrics: &Path) -> Result<Vec<(u64, f64)>> {
    scalar_history(metrics, "train/loss")
}

/// Every (step, value) a metrics log holds for scalar `name`, in the order logged.
pub fn scalar_history(metrics: &Path, name: &str) -> Result<Vec<(u64, f64)>> {
    let bytes = read_bounded(metrics, 1 << 30)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut out = Vec::new();
    for line in text.lines() {
        if let Ok(crate::run::Event::Scalar { name: logged, step, value }) = serde_json::from_str(line) {
            if logged == name {
                out.push((step, value));
            }
        }
    }
    Ok(out)
}
