//! What `mbrl train ball-ekf` may ask for over the thesis' optimizer settings (Adam, lr 5e-3, batch 64,
//! chunks of 50 frames, 1000 steps).

use std::path::PathBuf;

use super::TrainSettings;
use crate::train::run_dir::default_out;

#[derive(Clone, Debug, Default)]
pub struct BallOptions {
    pub steps: Option<u64>,
    pub batch_size: Option<usize>,
    pub chunk_len: Option<usize>,
    pub learning_rate: Option<f64>,
    pub launcher_prior: bool,
}

impl BallOptions {
    pub fn settings(&self, seed: u64) -> TrainSettings {
        let defaults = TrainSettings::default();
        TrainSettings {
            steps: self.steps.unwrap_or(defaults.steps),
            batch_size: self.batch_size.unwrap_or(defaults.batch_size),
            chunk_len: self.chunk_len.unwrap_or(defaults.chunk_len),
            learning_rate: self.learning_rate.unwrap_or(defaults.learning_rate),
            seed,
            launcher_prior: self.launcher_prior,
            ..defaults
        }
    }
}

/// The ball EKF models one setup, so one default directory serves.
pub fn default_out_dir() -> PathBuf {
    default_out("ball-ekf")
}
