//! Hyperparameters of the context model and its training: presets per env family, validation, and what goes
//! into config.json.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::nn::AdamConfig;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// Narrow networks, short training. Toy: 32 units, 20-state chunks, learning rate 3e-3, 1200 steps (about
    /// 25 s on one core, and enough for calibration to beat random; `eval quick` uses it). Pendulum and
    /// MountainCar: 64 units, 5000 steps (minutes).
    Small,
    /// The thesis architecture (200 units) for a tenth of its steps.
    Medium,
    /// Table B.1: the thesis architecture and step counts (toy 50k, pendulum and MountainCar 100k).
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

/// Which column of Table B.1 an env falls into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvFamily {
    /// The toy system: homoscedastic noise (a learned constant variance), D_β 1, D_F 32, batch 64, C_max 10,
    /// contexts from the second rollout only.
    Toy,
    /// Pendulum and MountainCar: variance decoder, D_β 16, D_F 128, batch 512, C_max 50, p_ctx-from-A schedule.
    Control,
}

/// The share of context transitions drawn from the target chunk's own rollout A (appendix B.2.1): `start` until
/// `decay_from`, then linearly down to 0 at `zero_at`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextFromTarget {
    pub start: f64,
    pub decay_from: u64,
    pub zero_at: u64,
}

impl ContextFromTarget {
    /// The same schedule over a run of `to_steps` instead of `from_steps` (its switch points scaled).
    pub fn rescaled(&self, from_steps: u64, to_steps: u64) -> Self {
        let scale = |s: u64| ((s as u128 * to_steps as u128) / from_steps.max(1) as u128) as u64;
        ContextFromTarget { start: self.start, decay_from: scale(self.decay_from), zero_at: scale(self.zero_at) }
    }

    pub fn at(&self, step: u64) -> f64 {
        if step < self.decay_from {
            self.start
        } else if step >= self.zero_at {
            0.0
        } else {
            let span = (self.zero_at - self.decay_from) as f64;
            self.start * (1.0 - (step - self.decay_from) as f64 / span)
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextConfig {
    /// D_E: state, action and context embeddings and the GRU state (200 in the thesis).
    pub embedding: usize,
    /// Hidden units of every two-layer MLP (encoders, decoders, context heads; 200 in the thesis).
    pub hidden_units: usize,
    /// D_F: transition embedding that is max-pooled over the context set.
    pub transition_features: usize,
    /// D_β: latent context.
    pub latent_dim: usize,
    /// One learned variance vector instead of a variance decoder (the toy system's homoscedastic noise).
    pub constant_variance: bool,
    /// States per target chunk (50: 49 transitions).
    pub chunk_states: usize,
    /// C_max: context sets have U{0..C_max} transitions, drawn with replacement.
    pub context_max: usize,
    pub batch_size: usize,
    pub steps: u64,
    /// λ_KL of eq. 4.31.
    pub kl_weight: f64,
    /// Per-dimension floor of KL(q(β|C∪D) ‖ q(β|C)) (thesis 4.4.4: avoids the constant-belief local minimum).
    pub kl_floor: f64,
    pub context_from_target: ContextFromTarget,
    pub optimizer: AdamConfig,
    /// Share of instances held out for validation (whole instances: both rollouts).
    pub validation_fraction: f64,
    /// Validation batches (appendix B.2.2: 5), drawn once with a fixed seed and p_ctx-from-A = 0.
    pub validation_batches: usize,
    pub validate_every: u64,
    pub checkpoint_every: u64,
}

impl ContextConfig {
    pub fn preset(preset: Preset, family: EnvFamily) -> Self {
        let toy = family == EnvFamily::Toy;
        let paper_steps = if toy { 50_000 } else { 100_000 };
        let small_toy = toy && preset == Preset::Small;
        let (width, steps, batch) = match preset {
            Preset::Small => (if toy { 32 } else { 64 }, if toy { 1_200 } else { 5_000 }, 64),
            Preset::Medium => (200, paper_steps / 10, if toy { 64 } else { 128 }),
            Preset::Paper => (200, paper_steps, if toy { 64 } else { 512 }),
        };
        // The thesis' schedule (0.5 until 30k, zero from 60k) scaled to the run's length.
        let context_from_target = if toy {
            ContextFromTarget { start: 0.0, decay_from: 0, zero_at: 0 }
        } else {
            ContextFromTarget { start: 0.5, decay_from: steps * 3 / 10, zero_at: steps * 6 / 10 }
        };
        ContextConfig {
            embedding: width,
            hidden_units: width,
            transition_features: if toy { 32 } else { 128 },
            latent_dim: if toy { 1 } else { 16 },
            constant_variance: toy,
            // The toy's state has no memory beyond one step, so short chunks lose nothing and train faster.
            chunk_states: if small_toy { 20 } else { 50 },
            context_max: if toy { 10 } else { 50 },
            batch_size: batch,
            steps,
            kl_weight: 5.0,
            kl_floor: 0.1,
            context_from_target,
            // Thesis 4.5.1: Adam 1e-3, β (0.9, 0.999), ε 1e-4, global gradient norm ≤ 1000.
            // A higher rate for the short toy run: at 1e-3 a 1000-step run leaves the context uninformative.
            optimizer: AdamConfig {
                learning_rate: if small_toy { 3e-3 } else { 1e-3 },
                beta1: 0.9,
                beta2: 0.999,
                epsilon: 1e-4,
                weight_decay: 0.0,
                clip_grad_norm: Some(1000.0),
            },
            validation_fraction: 0.1,
            validation_batches: 5,
            validate_every: if small_toy {
                200
            } else if toy {
                250
            } else {
                500
            },
            checkpoint_every: 500,
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(format!("context config: {m}")));
        for (name, v, max) in [
            ("embedding", self.embedding, 4096),
            ("hidden_units", self.hidden_units, 4096),
            ("transition_features", self.transition_features, 4096),
            ("latent_dim", self.latent_dim, 256),
            ("batch_size", self.batch_size, 65_536),
            ("context_max", self.context_max, 10_000),
            ("validation_batches", self.validation_batches, 1000),
        ] {
            if v == 0 || v > max {
                return bad(format!("{name} must be 1..={max}, got {v}"));
            }
        }
        if !(3..=10_000).contains(&self.chunk_states) {
            return bad(format!(
                "chunk_states must be 3..=10000 (two transitions at least), got {}",
                self.chunk_states
            ));
        }
        if self.steps == 0 || self.validate_every == 0 || self.checkpoint_every == 0 {
            return bad("steps, validate_every and checkpoint_every must be at least 1".into());
        }
        if !(self.kl_weight.is_finite() && self.kl_weight >= 0.0 && self.kl_floor.is_finite() && self.kl_floor >= 0.0) {
            return bad(format!(
                "kl_weight and kl_floor must be finite and ≥ 0, got {} and {}",
                self.kl_weight, self.kl_floor
            ));
        }
        let c = &self.context_from_target;
        if !(0.0..=1.0).contains(&c.start) || c.zero_at < c.decay_from {
            return bad(format!(
                "context_from_target needs start in [0, 1] and decay_from ≤ zero_at, got {} / {} / {}",
                c.start, c.decay_from, c.zero_at
            ));
        }
        if !(0.0..0.9).contains(&self.validation_fraction) {
            return bad(format!("validation_fraction must lie in [0, 0.9), got {}", self.validation_fraction));
        }
        self.optimizer.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_preset_is_table_b1() {
        let toy = ContextConfig::preset(Preset::Paper, EnvFamily::Toy);
        assert_eq!((toy.steps, toy.latent_dim, toy.transition_features, toy.batch_size), (50_000, 1, 32, 64));
        let control = ContextConfig::preset(Preset::Paper, EnvFamily::Control);
        assert_eq!(
            (control.steps, control.latent_dim, control.transition_features, control.batch_size, control.context_max),
            (100_000, 16, 128, 512, 50)
        );
        let s = control.context_from_target;
        assert_eq!((s.at(0), s.at(30_000), s.at(45_000), s.at(60_000)), (0.5, 0.5, 0.25, 0.0));
        let short = s.rescaled(100_000, 4000);
        assert_eq!((short.decay_from, short.zero_at, short.start), (1200, 2400, 0.5));
        assert!(toy.validate().is_ok() && control.validate().is_ok());
    }
}
