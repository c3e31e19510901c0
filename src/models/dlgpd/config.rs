//! DLGPD hyperparameters: presets, validation, and what is saved in config.json.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// MLP VAE on pole directions (cos θ, sin θ) instead of images, batch 256, 3000 steps: minutes on 2 cores.
    Small,
    /// The paper's conv VAE on 64 × 64 frames at batch 128 for 3000 steps (about 25 minutes on one core).
    Medium,
    /// The paper: batch 1024, 2000 epochs of 14 000 transitions = 28 000 steps (about a day on one core).
    Paper,
}

impl std::str::FromStr for Preset {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "small" => Ok(Preset::Small),
            "medium" => Ok(Preset::Medium),
            "paper" => Ok(Preset::Paper),
            _ => Err(Error::config(format!(
                "unknown preset '{s}'{}; presets: small, medium, paper",
                crate::util::suggest::did_you_mean(s, ["small", "medium", "paper"])
            ))),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DlgpdConfig {
    /// Learn from the dataset's frames (the paper) or from the pendulum's angle (the small preset).
    pub images: bool,
    pub latent_dim: usize,
    /// Width of the angle VAE's two hidden layers (unused with images).
    pub hidden_units: usize,
    pub steps: u64,
    /// Transitions per step; they are also the GPs' training set (subset of data, thesis 3.3).
    pub batch_size: usize,
    /// The three Adams' (VAE, transition GPs, reward GP) learning rate; the authors' β = (0.9, 0.999).
    pub learning_rate: f64,
    /// Share of rollouts held out for validation (whole rollouts).
    pub validation_fraction: f64,
    pub validate_every: u64,
    pub checkpoint_every: u64,
}

impl DlgpdConfig {
    pub fn preset(preset: Preset) -> Self {
        let (images, steps, batch_size, validate_every, checkpoint_every) = match preset {
            Preset::Small => (false, 3000, 256, 100, 500),
            Preset::Medium => (true, 3000, 128, 100, 100),
            Preset::Paper => (true, 28_000, 1024, 500, 100),
        };
        DlgpdConfig {
            images,
            latent_dim: 3,
            hidden_units: 64,
            steps,
            batch_size,
            learning_rate: 1e-3,
            validation_fraction: 0.1,
            validate_every,
            checkpoint_every,
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(format!("dlgpd config: {m}")));
        if !(1..=16).contains(&self.latent_dim) {
            return bad(format!("latent_dim must be 1..=16, got {}", self.latent_dim));
        }
        if !(1..=4096).contains(&self.hidden_units) {
            return bad(format!("hidden_units must be 1..=4096, got {}", self.hidden_units));
        }
        if self.steps == 0 {
            return bad("steps must be at least 1".into());
        }
        // The GPs' exact Cholesky on the batch costs batch³; 4096 is 4 × the paper's and already minutes a step.
        if !(2..=4096).contains(&self.batch_size) {
            return bad(format!(
                "batch_size must be 2..=4096 (the GPs factor a batch × batch matrix), got {}",
                self.batch_size
            ));
        }
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0 && self.learning_rate < 1.0) {
            return bad(format!("learning_rate must lie in (0, 1), got {}", self.learning_rate));
        }
        if !(0.0..0.9).contains(&self.validation_fraction) {
            return bad(format!("validation_fraction must lie in [0, 0.9), got {}", self.validation_fraction));
        }
        if self.validate_every == 0 || self.checkpoint_every == 0 {
            return bad("validate_every and checkpoint_every must be at least 1".into());
        }
        Ok(())
    }
}
