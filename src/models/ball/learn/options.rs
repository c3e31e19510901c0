//! What `mbrl train ball-ekf` may ask for over the thesis' optimizer settings (Adam, lr 5e-3, batch 64,
//! chunks of 50 frames, 1000 steps): a config file over them, then each flag given, then each `KEY=VALUE`.

use std::path::PathBuf;

use super::job::METHOD;
use super::TrainSettings;
use crate::error::Result;
use crate::train::config::apply_config_file;
use crate::train::run_dir::default_out;
use crate::train::settings::{apply_overrides, Override};

#[derive(Clone, Debug, Default)]
pub struct BallOptions {
    pub config_file: Option<PathBuf>,
    pub steps: Option<u64>,
    pub batch_size: Option<usize>,
    pub chunk_len: Option<usize>,
    pub learning_rate: Option<f64>,
    pub launcher_prior: bool,
    pub overrides: Vec<Override>,
}

impl BallOptions {
    pub fn settings(&self, seed: u64) -> Result<TrainSettings> {
        let mut settings = TrainSettings { seed, ..TrainSettings::default() };
        if let Some(path) = &self.config_file {
            settings = apply_config_file(&settings, path, &[METHOD])?;
        }
        if let Some(n) = self.steps {
            settings.steps = n;
        }
        if let Some(n) = self.batch_size {
            settings.batch_size = n;
        }
        if let Some(n) = self.chunk_len {
            settings.chunk_len = n;
        }
        if let Some(lr) = self.learning_rate {
            settings.learning_rate = lr;
        }
        if self.launcher_prior {
            settings.launcher_prior = true;
        }
        settings = apply_overrides(settings, &self.overrides)?;
        settings.validate()?;
        Ok(settings)
    }
}

/// The ball EKF models one setup, so one default directory serves.
pub fn default_out_dir() -> PathBuf {
    default_out("ball-ekf")
}
