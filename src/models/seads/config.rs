//! Hyperparameters of SEADS (thesis 7.3, appendix D.2 and the authors' `train_seads.py`): presets, validation and
//! what goes into config.json.

use serde::{Deserialize, Serialize};

use crate::envs::embodiments::Embodiment;
use crate::error::{Error, Result};
use crate::rl::sac::SacConfig;

/// The Jaco's `small` budget.
pub const JACO_SMALL_STEPS: u64 = 2_000_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// A short budget for tests and `eval quick` (about a minute for a Cursor game on 2 cores): SAC of 64 units,
    /// the paper's forward model (256 units) with 16 instead of 4 Adam steps per epoch, because the few epochs
    /// of a short budget leave the model with too few steps to predict every swap (measured on tileswap:cursor:
    /// at 4 steps 4/10 depth-5 test boards solved, at 16 steps 10/10).
    Small,
    /// The paper's networks (256 units) on a fifth of the Cursor budget.
    Medium,
    /// The paper's networks and budgets (500k env steps for the Cursor, 10M for the Reacher and the Jaco).
    Paper,
}

/// Which reward terms of thesis 7.3.5 are on (the ablations of Fig. 7.11).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RewardTerms {
    /// Subtract the second-largest clipped log q(k'|z0,zT).
    pub second_best: bool,
    /// Add the novelty bonus −max_k' log q(zT|z0,k'), capped at log K.
    pub novelty: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeadsConfig {
    /// K: one skill per intended game move (25 LightsOut, 12 TileSwap).
    pub skills: usize,
    /// Budget of environment steps; training stops after the epoch that reaches it.
    pub env_steps: u64,
    /// Episodes collected per epoch (one skill execution each, from a fresh reset).
    pub episodes_per_epoch: usize,
    /// Capacity of the episode memory.
    pub episode_memory: usize,
    /// Episodes drawn from the memory per update, and the number of most recent episodes added to them; updates
    /// start once the memory holds this many.
    pub sampled_episodes: usize,
    /// Solution depths of the boards episodes start from: uniform in 1..=max_board_depth, then a uniform board
    /// of that depth from the train split.
    pub max_board_depth: u8,
    pub relabel: bool,
    /// Share of episodes relabelled for the forward model (1.0) and for SAC (0.5).
    pub relabel_model: f64,
    pub relabel_sac: f64,
    pub reward: RewardTerms,
    pub model_hidden: usize,
    pub model_learning_rate: f64,
    pub model_batch: usize,
    pub model_updates: usize,
    pub sac_hidden: Vec<usize>,
    pub sac_learning_rate: f64,
    pub sac_batch: usize,
    pub sac_updates: usize,
    pub gamma: f64,
    pub tau: f64,
    /// SAC's fixed temperature (0.1 Cursor, 0.01 Reacher and Jaco).
    pub alpha: f64,
    /// Epochs between checkpoints.
    pub checkpoint_every: u64,
}

impl SeadsConfig {
    /// `skills` = the game's move count; the embodiment sets the budgets, α and the checkpoint interval.
    pub fn preset(preset: Preset, skills: usize, embodiment: Embodiment) -> Self {
        let cursor = embodiment == Embodiment::Cursor;
        let paper_steps = if cursor { 500_000 } else { 10_000_000 };
        let small_steps = match embodiment {
            Embodiment::Cursor => 60_000,
            Embodiment::Reacher => 200_000,
            // A Jaco step costs about a millisecond of MuJoCo (benches/jaco.rs): 2M steps take about 75 min
            // on 2 cores (440 steps/s measured with this preset).
            Embodiment::Jaco => JACO_SMALL_STEPS,
        };
        let (width, env_steps, sampled, model_updates) = match preset {
            // The Jaco's small run keeps the paper's SAC width (42 observations and 9 joints).
            Preset::Small if embodiment == Embodiment::Jaco => (256, small_steps, 128, 16),
            Preset::Small => (64, small_steps, 128, 16),
            Preset::Medium => (256, paper_steps / 5, 256, 4),
            Preset::Paper => (256, paper_steps, 256, 4),
        };
        // An epoch's ~1,000 Jaco steps take about a second of MuJoCo, far more than SAC updates of batch 128, so
        // the small run makes four times the paper's updates per epoch to get more out of each costly step.
        let sac_updates = if preset == Preset::Small && embodiment == Embodiment::Jaco { 64 } else { 16 };
        SeadsConfig {
            skills,
            env_steps,
            episodes_per_epoch: 32,
            episode_memory: 2048,
            sampled_episodes: sampled,
            max_board_depth: 5,
            relabel: true,
            relabel_model: 1.0,
            relabel_sac: 0.5,
            reward: RewardTerms { second_best: true, novelty: true },
            model_hidden: 256,
            model_learning_rate: 1e-3,
            model_batch: 32,
            model_updates,
            sac_hidden: vec![width, width],
            sac_learning_rate: 3e-4,
            sac_batch: 128,
            sac_updates,
            gamma: 0.99,
            tau: 0.005,
            alpha: if cursor { 0.1 } else { 0.01 },
            checkpoint_every: if cursor { 100 } else { 500 },
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(format!("seads config: {m}")));
        if !(2..=1024).contains(&self.skills) {
            return bad(format!("skills must be 2..=1024 (the reward compares the best two), got {}", self.skills));
        }
        for (name, v, max) in [
            ("episodes_per_epoch", self.episodes_per_epoch, 65_536),
            ("episode_memory", self.episode_memory, 1 << 20),
            ("sampled_episodes", self.sampled_episodes, 1 << 16),
            ("model_hidden", self.model_hidden, 4096),
            ("model_batch", self.model_batch, 1 << 16),
            ("model_updates", self.model_updates, 10_000),
            ("sac_batch", self.sac_batch, 1 << 16),
            ("sac_updates", self.sac_updates, 10_000),
        ] {
            if v == 0 || v > max {
                return bad(format!("{name} must be 1..={max}, got {v}"));
            }
        }
        if self.sampled_episodes > self.episode_memory {
            return bad(format!(
                "sampled_episodes ({}) must not exceed episode_memory ({})",
                self.sampled_episodes, self.episode_memory
            ));
        }
        if self.env_steps == 0 || self.env_steps > 1_000_000_000 {
            return bad(format!("env_steps must be 1..=1e9, got {}", self.env_steps));
        }
        if !(1..=20).contains(&self.max_board_depth) {
            return bad(format!("max_board_depth must be 1..=20, got {}", self.max_board_depth));
        }
        for (name, p) in [("relabel_model", self.relabel_model), ("relabel_sac", self.relabel_sac)] {
            if !(0.0..=1.0).contains(&p) {
                return bad(format!("{name} must lie in [0, 1], got {p}"));
            }
        }
        // The thesis' networks have two hidden layers; sixteen is far past any SAC network, and a list read
        // from a file may claim millions.
        let layers = self.sac_hidden.len();
        if !(1..=16).contains(&layers) || self.sac_hidden.iter().any(|&h| h == 0 || h > 4096) {
            let shown = if layers <= 16 { format!("{:?}", self.sac_hidden) } else { format!("{layers} layers") };
            return bad(format!("sac_hidden must list 1-16 layers of 1..=4096 units each, got {shown}"));
        }
        for (name, v) in [
            ("model_learning_rate", self.model_learning_rate),
            ("sac_learning_rate", self.sac_learning_rate),
            ("alpha", self.alpha),
        ] {
            if !(v.is_finite() && v > 0.0 && v < 10.0) {
                return bad(format!("{name} must be finite, > 0 and < 10, got {v}"));
            }
        }
        if !((0.0..=1.0).contains(&self.gamma) && self.tau > 0.0 && self.tau <= 1.0) {
            return bad(format!("gamma must lie in [0, 1] and tau in (0, 1], got {} and {}", self.gamma, self.tau));
        }
        if self.checkpoint_every == 0 {
            return bad("checkpoint_every must be at least 1".into());
        }
        Ok(())
    }

    /// The skill policy's SAC settings for a network input of `policy_input` values and actions in [low, high].
    pub fn sac_config(&self, policy_input: usize, action_low: Vec<f64>, action_high: Vec<f64>) -> SacConfig {
        SacConfig {
            hidden: self.sac_hidden.clone(),
            gamma: self.gamma,
            tau: self.tau,
            learning_rate: self.sac_learning_rate,
            alpha: self.alpha,
            batch_size: self.sac_batch,
            ..SacConfig::new(policy_input, action_low, action_high)
        }
    }

    /// Epochs the budget allows at most (every episode takes at least one step); the run ends after the epoch
    /// in which the counted steps reach the budget, usually far earlier.
    pub fn max_epochs(&self) -> u64 {
        self.env_steps.div_ceil(self.episodes_per_epoch as u64).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_follow_the_authors_code() {
        for preset in [Preset::Small, Preset::Medium, Preset::Paper] {
            for (skills, embodiment) in
                [(25, Embodiment::Cursor), (12, Embodiment::Cursor), (25, Embodiment::Reacher), (12, Embodiment::Jaco)]
            {
                SeadsConfig::preset(preset, skills, embodiment).validate().unwrap();
            }
        }
        let paper = SeadsConfig::preset(Preset::Paper, 25, Embodiment::Cursor);
        assert_eq!((paper.env_steps, paper.sac_batch, paper.sac_updates, paper.model_batch), (500_000, 128, 16, 32));
        assert_eq!(SeadsConfig::preset(Preset::Paper, 25, Embodiment::Reacher).alpha, 0.01);
        let jaco = SeadsConfig::preset(Preset::Paper, 25, Embodiment::Jaco);
        assert_eq!((jaco.env_steps, jaco.alpha, jaco.sac_updates), (10_000_000, 0.01, 16));
        let small = SeadsConfig::preset(Preset::Small, 25, Embodiment::Jaco);
        assert_eq!((small.env_steps, small.sac_hidden.as_slice(), small.sac_updates), (2_000_000, &[256, 256][..], 64));
        let mut bad = paper.clone();
        bad.skills = 1;
        assert!(bad.validate().unwrap_err().to_string().contains("skills"));
    }

    /// A config file's million hidden layers of eight units each aborted on allocation before this check.
    #[test]
    fn a_network_of_absurd_depth_is_refused_without_listing_it() {
        let mut deep = SeadsConfig::preset(Preset::Small, 25, Embodiment::Cursor);
        deep.sac_hidden = vec![8; 1_000_000];
        let err = deep.validate().unwrap_err().to_string();
        assert!(err.contains("sac_hidden must list 1-16 layers") && err.contains("got 1000000 layers"), "{err}");
        assert!(err.len() < 300, "{err}");
    }
}
