//! What `mbrl train pets` may ask for, and the defaults that turn it into a run: the preset's config, a config
//! file over it, then each flag given, then each `KEY=VALUE`; the reward and the output directory follow the
//! data's env.

use std::path::PathBuf;

use super::{PetsConfig, Preset, RewardSource};
use crate::envs::parse_env;
use crate::error::Result;
use crate::train::config::apply_config_file;
use crate::train::run_dir::default_out;
use crate::train::settings::{apply_overrides, Override};

#[derive(Clone, Debug, Default)]
pub struct PetsOptions {
    pub preset: Option<Preset>,
    pub config_file: Option<PathBuf>,
    pub ensemble: Option<usize>,
    pub steps: Option<u64>,
    pub batch_size: Option<usize>,
    pub learning_rate: Option<f64>,
    pub reward: Option<RewardSource>,
    pub overrides: Vec<Override>,
}

/// A new run's config and directory.
pub struct Planned {
    pub config: PetsConfig,
    pub out: PathBuf,
}

impl PetsOptions {
    /// The config for data of `data_env` (the dataset's env, asked only when the default needs it) written to
    /// `out` (default `models/pets-<env>`). A reward neither asked for (flag or `reward=`) nor set by a file is
    /// the env's closed form where it has one, else learned.
    pub fn plan(
        &self,
        env: Option<&str>,
        data_env: impl FnOnce() -> Result<String>,
        out: Option<PathBuf>,
    ) -> Result<Planned> {
        let mut config = self.config()?;
        let env = match env {
            Some(env) => env.to_string(),
            None => data_env()?,
        };
        let asked = self.reward.is_some() || self.overrides.iter().any(|o| o.sets("reward"));
        if !asked && self.config_file.is_none() && parse_env(&env)?.known_reward().is_none() {
            config.reward = RewardSource::Learned;
        }
        let out = out.unwrap_or_else(|| default_out(&format!("pets-{env}")));
        Ok(Planned { config, out })
    }

    fn config(&self) -> Result<PetsConfig> {
        let mut config = PetsConfig::preset(self.preset.unwrap_or(Preset::Small));
        if let Some(path) = &self.config_file {
            config = apply_config_file(&config, path, &[super::METHOD])?;
        }
        if let Some(n) = self.ensemble {
            config.ensemble = n;
        }
        if let Some(n) = self.steps {
            config.steps = n;
        }
        if let Some(n) = self.batch_size {
            config.batch_size = n;
        }
        if let Some(lr) = self.learning_rate {
            config.optimizer.learning_rate = lr;
        }
        if let Some(reward) = self.reward {
            config.reward = reward;
        }
        config = apply_overrides(config, &self.overrides)?;
        config.validate()?;
        Ok(config)
    }
}
