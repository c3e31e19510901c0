//! What `mbrl train dlgpd` may ask for: the preset, a config file over it, then each flag given, then each
//! `KEY=VALUE`.

use std::path::PathBuf;

use super::config::{DlgpdConfig, Preset};
use crate::error::Result;
use crate::train::config::apply_config_file;
use crate::train::run_dir::default_out;
use crate::train::settings::{apply_overrides, Override};

#[derive(Clone, Debug, Default)]
pub struct DlgpdOptions {
    pub preset: Option<Preset>,
    pub config_file: Option<PathBuf>,
    pub steps: Option<u64>,
    pub batch_size: Option<usize>,
    pub learning_rate: Option<f64>,
    pub overrides: Vec<Override>,
}

impl DlgpdOptions {
    pub fn config(&self) -> Result<DlgpdConfig> {
        let mut config = DlgpdConfig::preset(self.preset.unwrap_or(Preset::Small));
        if let Some(path) = &self.config_file {
            config = apply_config_file(&config, path, &[super::job::METHOD])?;
        }
        if let Some(n) = self.steps {
            config.steps = n;
        }
        if let Some(n) = self.batch_size {
            config.batch_size = n;
        }
        if let Some(lr) = self.learning_rate {
            config.learning_rate = lr;
        }
        config = apply_overrides(config, &self.overrides)?;
        config.validate()?;
        Ok(config)
    }
}

/// The pendulum is DLGPD's only env, so one default directory serves.
pub fn default_out_dir() -> PathBuf {
    default_out("dlgpd-pendulum")
}
