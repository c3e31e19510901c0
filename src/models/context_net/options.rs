//! What `mbrl train context` (and TRADYN, the same model) may ask for, and the defaults that turn it into a
//! run: the preset of the env's family, a config file over it, then each flag given, then each `KEY=VALUE`.

use std::path::{Path, PathBuf};

use super::{family_of, ContextConfig, Preset};
use crate::envs::{parse_env, EnvName};
use crate::error::{Error, Result};
use crate::train::config::apply_config_file;
use crate::train::run_dir::default_out;
use crate::train::settings::{apply_overrides, Override};

#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    pub preset: Option<Preset>,
    pub config_file: Option<PathBuf>,
    pub steps: Option<u64>,
    pub batch_size: Option<usize>,
    pub learning_rate: Option<f64>,
    pub overrides: Vec<Override>,
}

/// A new run's config and directory.
pub struct Planned {
    pub config: ContextConfig,
    pub out: PathBuf,
}

impl ContextOptions {
    /// The config for data of `env`. The p_ctx-from-A schedule is a share of the run (B.2.1: 30 % and 60 % of
    /// it), so a run made longer or shorter keeps those shares unless the schedule itself is set.
    pub fn config(&self, env: &EnvName) -> Result<ContextConfig> {
        let preset_config = ContextConfig::preset(self.preset.unwrap_or(Preset::Small), family_of(env));
        let mut config = preset_config.clone();
        if let Some(path) = &self.config_file {
            // TRADYN's runs record this same config.
            config = apply_config_file(&config, path, &[super::METHOD, "tradyn"])?;
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
        config = apply_overrides(config, &self.overrides)?;
        if config.context_from_target == preset_config.context_from_target {
            config.context_from_target = preset_config.context_from_target.rescaled(preset_config.steps, config.steps);
        }
        config.validate()?;
        Ok(config)
    }

    /// A context run on `data` (of `data_env`, the dataset's env, asked only without `env`), written to `out`
    /// (default `models/context-<env>`). Unicycle data is TRADYN's, whose model reads the terrain.
    pub fn plan(
        &self,
        data: &Path,
        env: Option<&str>,
        data_env: impl FnOnce() -> Result<String>,
        out: Option<PathBuf>,
    ) -> Result<Planned> {
        let env_name = match env {
            Some(env) => env.to_string(),
            None => data_env()?,
        };
        let env = parse_env(&env_name)?;
        if matches!(env, EnvName::Unicycle(_)) {
            return Err(Error::bad_file(
                data,
                "unicycle data trains TRADYN, which reads the terrain: `mbrl train tradyn`",
            ));
        }
        let config = self.config(&env)?;
        Ok(Planned { config, out: out.unwrap_or_else(|| default_out(&format!("context-{env_name}"))) })
    }
}
