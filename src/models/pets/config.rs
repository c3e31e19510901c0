//! PETS hyperparameters: presets, validation, and what is saved in config.json.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::nn::{Activation, AdamConfig};

/// Where the model's reward comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RewardSource {
    /// The env's reward in closed form (pendulum: gym's cost of the pre-step state and action).
    Known,
    /// An extra output of every member, trained on the dataset's rewards (for envs without a closed form, such as
    /// `pendulum:quadrant`, whose hidden actuators scale the torque cost).
    Learned,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// 3 × 64 SiLU, 2000 steps: trains in seconds on 2 cores; plenty for the pendulum.
    Small,
    /// 4 × 200 SiLU, 5000 steps: mbrl-lib's PETS pendulum network.
    Medium,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PetsConfig {
    pub ensemble: usize,
    pub hidden_layers: usize,
    pub hidden_units: usize,
    pub activation: Activation,
    pub reward: RewardSource,
    /// Optimizer steps; each step takes `batch_size` transitions for every member.
    pub steps: u64,
    pub batch_size: usize,
    pub optimizer: AdamConfig,
    /// Each member trains on its own bootstrap resample of the training transitions (PETS' aleatoric/epistemic
    /// split); off = every member sees all data in its own random order.
    pub bootstrap: bool,
    /// Share of rollouts held out for validation (whole rollouts, so held-out steps are not neighbours of
    /// training steps).
    pub validation_fraction: f64,
    pub validate_every: u64,
    pub checkpoint_every: u64,
    /// Initial soft bounds of the predicted log-variance (mbrl-lib: −10 and 0.5).
    pub min_logvar: f64,
    pub max_logvar: f64,
}

impl std::str::FromStr for Preset {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "small" => Ok(Preset::Small),
            "medium" => Ok(Preset::Medium),
            _ => Err(Error::config(format!(
                "unknown preset '{s}'{}; presets: small, medium",
                crate::util::suggest::did_you_mean(s, ["small", "medium"])
            ))),
        }
    }
}

impl PetsConfig {
    pub fn preset(preset: Preset) -> Self {
        let (hidden_layers, hidden_units, steps) = match preset {
            Preset::Small => (3, 64, 2000),
            Preset::Medium => (4, 200, 5000),
        };
        PetsConfig {
            ensemble: 5,
            hidden_layers,
            hidden_units,
            activation: Activation::Silu,
            reward: RewardSource::Known,
            steps,
            batch_size: 256,
            // mbrl-lib's pendulum PETS: Adam lr 1e-3, weight decay 5e-5; PyTorch's β and ε.
            optimizer: AdamConfig {
                learning_rate: 1e-3,
                beta1: 0.9,
                beta2: 0.999,
                epsilon: 1e-8,
                weight_decay: 5e-5,
                clip_grad_norm: None,
            },
            bootstrap: true,
            validation_fraction: 0.1,
            validate_every: 100,
            checkpoint_every: 500,
            min_logvar: -10.0,
            max_logvar: 0.5,
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(format!("pets config: {m}")));
        if !(1..=64).contains(&self.ensemble) {
            return bad(format!("ensemble must be 1..=64 members, got {}", self.ensemble));
        }
        if !(1..=16).contains(&self.hidden_layers) || !(1..=4096).contains(&self.hidden_units) {
            return bad(format!(
                "hidden_layers must be 1..=16 and hidden_units 1..=4096, got {} and {}",
                self.hidden_layers, self.hidden_units
            ));
        }
        if self.steps == 0 {
            return bad("steps must be at least 1".into());
        }
        if !(1..=65536).contains(&self.batch_size) {
            return bad(format!("batch_size must be 1..=65536, got {}", self.batch_size));
        }
        if !(0.0..0.9).contains(&self.validation_fraction) {
            return bad(format!("validation_fraction must lie in [0, 0.9), got {}", self.validation_fraction));
        }
        if self.validate_every == 0 || self.checkpoint_every == 0 {
            return bad("validate_every and checkpoint_every must be at least 1".into());
        }
        if !(self.min_logvar.is_finite() && self.max_logvar.is_finite() && self.min_logvar < self.max_logvar) {
            return bad(format!(
                "need finite min_logvar < max_logvar, got {} and {}",
                self.min_logvar, self.max_logvar
            ));
        }
        self.optimizer.validate()
    }
}
