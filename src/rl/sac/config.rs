//! SAC's hyperparameters. Defaults are the SEADS code's (hidden [256, 256]; the thesis table says 512).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Widths and dimensions above this are a typo, not a network this CPU trainer could hold.
const MAX_DIM: usize = 1 << 16;
/// A batch this large would allocate gigabytes per update.
const MAX_BATCH: usize = 1 << 20;
/// Bounds beyond this lose f32 resolution when the tanh output is rescaled to them.
const MAX_BOUND: f64 = 1e6;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SacConfig {
    /// The full network input; SEADS passes obs ⊕ onehot(k) already concatenated.
    pub obs_dim: usize,
    pub action_dim: usize,
    /// Env bounds: the policy's tanh output in [−1, 1] is rescaled to them.
    pub action_low: Vec<f64>,
    pub action_high: Vec<f64>,
    /// Hidden widths of the actor and of each Q network (ReLU after each).
    pub hidden: Vec<usize>,
    pub gamma: f64,
    /// Polyak factor of the target critics, applied after every update.
    pub tau: f64,
    /// Adam's step size for the actor and the critics (β 0.9/0.999, ε 1e-8 as torch.optim.Adam).
    pub learning_rate: f64,
    /// Fixed entropy temperature (0.1 Cursor, 0.01 Reacher/Jaco); no automatic tuning.
    pub alpha: f64,
    /// Rows per update the caller should sample; `Sac::update` takes any positive number of rows.
    pub batch_size: usize,
}

impl SacConfig {
    /// The SEADS settings for a network input of `obs_dim` and actions in `[low, high]`, with α = 0.1.
    pub fn new(obs_dim: usize, action_low: Vec<f64>, action_high: Vec<f64>) -> Self {
        SacConfig {
            obs_dim,
            action_dim: action_low.len(),
            action_low,
            action_high,
            hidden: vec![256, 256],
            gamma: 0.99,
            tau: 0.005,
            learning_rate: 3e-4,
            alpha: 0.1,
            batch_size: 128,
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(format!("sac: {m}")));
        for (name, d) in [("obs_dim", self.obs_dim), ("action_dim", self.action_dim), ("batch_size", self.batch_size)] {
            let max = if name == "batch_size" { MAX_BATCH } else { MAX_DIM };
            if d == 0 || d > max {
                return bad(format!("{name} must lie in 1..={max}, got {d}"));
            }
        }
        if self.hidden.is_empty() {
            return bad("hidden needs at least one layer width".into());
        }
        if let Some(&w) = self.hidden.iter().find(|&&w| w == 0 || w > MAX_DIM) {
            return bad(format!("hidden widths must lie in 1..={MAX_DIM}, got {w}"));
        }
        for (name, b) in [("action_low", &self.action_low), ("action_high", &self.action_high)] {
            if b.len() != self.action_dim {
                return bad(format!("{name} has {} values, action_dim is {}", b.len(), self.action_dim));
            }
            if let Some(x) = b.iter().find(|x| !(x.is_finite() && x.abs() <= MAX_BOUND)) {
                return bad(format!("{name} values must be finite and within ±{MAX_BOUND:e}, got {x}"));
            }
        }
        for (i, (lo, hi)) in self.action_low.iter().zip(&self.action_high).enumerate() {
            if lo >= hi {
                return bad(format!("action dimension {i}: low {lo} must be below high {hi}"));
            }
        }
        if !(0.0..=1.0).contains(&self.gamma) {
            return bad(format!("gamma must lie in [0, 1], got {}", self.gamma));
        }
        if !(self.tau > 0.0 && self.tau <= 1.0) {
            return bad(format!("tau must lie in (0, 1], got {}", self.tau));
        }
        if !(self.learning_rate > 0.0 && self.learning_rate <= 1.0) {
            return bad(format!("learning_rate must lie in (0, 1], got {}", self.learning_rate));
        }
        if !(self.alpha >= 0.0 && self.alpha <= 1e3) {
            return bad(format!("alpha must lie in [0, 1000], got {}", self.alpha));
        }
        Ok(())
    }

    /// Half the range per action dimension: env action = tanh output · scale + bias.
    pub(crate) fn action_scale(&self) -> Vec<f32> {
        self.action_low.iter().zip(&self.action_high).map(|(l, h)| ((h - l) / 2.0) as f32).collect()
    }

    pub(crate) fn action_bias(&self) -> Vec<f32> {
        self.action_low.iter().zip(&self.action_high).map(|(l, h)| ((h + l) / 2.0) as f32).collect()
    }
}
