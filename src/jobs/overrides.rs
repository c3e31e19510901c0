//! The trailing `KEY=VALUE` arguments of `train <method>` and `eval <protocol>`: any key of the config a run
//! or report records in its config.json, set last, over the preset, `--config` and the flags.

use clap::Args;

use crate::train::settings::{apply_overrides, Override};
use crate::Result;

/// Trailing positionals rather than a repeatable `--set`: they read as Hydra's and sb3-zoo's overrides
/// (`mbrl train pets --data d.mcap steps=500 optimizer.learning_rate=3e-4`), and no flag of ours takes a
/// value with '=' in it, so a mistyped one is still refused as "not KEY=VALUE".
#[derive(Args, Debug, Default)]
pub struct Overrides {
    /// Set a key of the config that config.json records (a run's `config` table, a report's `settings`
    /// table), nested keys joined by '.' (optimizer.learning_rate=3e-4). Applied after the preset, --config
    /// and the flags, so it wins over all three; an unknown key lists the valid ones.
    #[arg(value_name = "KEY=VALUE")]
    pub set: Vec<Override>,
}

impl Overrides {
    pub fn apply<T: serde::Serialize + serde::de::DeserializeOwned>(&self, config: T) -> Result<T> {
        apply_overrides(config, &self.set)
    }
}
