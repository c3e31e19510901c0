//! What `mbrl train seads` may ask for: the preset for the game (its move count, its embodiment), a config
//! file over it, then each flag given, then each `KEY=VALUE`.

use std::path::PathBuf;

use super::{EmbodiedGame, Preset, SeadsConfig};
use crate::error::Result;
use crate::train::config::apply_config_file;
use crate::train::run_dir::default_out;
use crate::train::settings::{apply_overrides, Override};

#[derive(Clone, Debug, Default)]
pub struct SeadsOptions {
    pub preset: Option<Preset>,
    pub config_file: Option<PathBuf>,
    pub skills: Option<usize>,
    pub env_steps: Option<u64>,
    pub no_relabel: bool,
    pub no_second_best: bool,
    pub no_novelty: bool,
    pub overrides: Vec<Override>,
}

impl SeadsOptions {
    pub fn config(&self, game: &EmbodiedGame) -> Result<SeadsConfig> {
        let mut config = SeadsConfig::preset(self.preset.unwrap_or(Preset::Small), game.moves(), game.embodiment);
        if let Some(path) = &self.config_file {
            config = apply_config_file(&config, path, &[super::METHOD])?;
        }
        if let Some(k) = self.skills {
            config.skills = k;
        }
        if let Some(n) = self.env_steps {
            config.env_steps = n;
        }
        if self.no_relabel {
            config.relabel = false;
        }
        if self.no_second_best {
            config.reward.second_best = false;
        }
        if self.no_novelty {
            config.reward.novelty = false;
        }
        config = apply_overrides(config, &self.overrides)?;
        config.validate()?;
        Ok(config)
    }
}

/// `models/seads-<game>`.
pub fn default_out_for(game: &EmbodiedGame) -> PathBuf {
    default_out(&format!("seads-{}", game.name()))
}
