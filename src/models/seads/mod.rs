//! SEADS (thesis chapter 7): skills learned without reward for board games played through a manipulator, and a
//! symbolic forward model of what each skill does to the board, which breadth-first search plans over.

pub mod boards;
pub mod collect;
pub mod config;
pub mod forward_model;
pub mod memory;
pub mod options;
pub mod planner;
pub mod relabel;
pub mod reward;
pub mod trainer;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use config::{Preset, RewardTerms, SeadsConfig};
pub use trainer::{EpochStats, SeadsTrainer};

use crate::envs::boards::spec::GAME_HELP;
use crate::envs::boards::{BoardGame, GameSpec, LightsOut, TileSwap};
use crate::envs::embodiments::{Embodiment, EMBODIMENT_HELP};
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::run::PanelSpec;
use crate::train::run_dir::Field;
use crate::train::{
    training_view, FitOutcome, Method, Prepared, Request, RunConfig, RunRecord, Trained, TrainingMethod,
};

pub const METHOD: &str = "seads";
pub const ENV_HELP: &str =
    "lightsout:cursor, tileswap:cursor, lightsout:reacher, tileswap:reacher, lightsout:jaco, tileswap:jaco (jaco needs `make mujoco`)";

/// A board game played through a manipulator, as named on the command line (`lightsout:cursor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmbodiedGame {
    pub game: GameSpec,
    pub embodiment: Embodiment,
}

impl EmbodiedGame {
    /// The registry's embodied env names, restricted to the games SEADS plays.
    pub fn parse(name: &str) -> Result<Self> {
        let bad = || {
            let embodied = crate::envs::ENV_NAMES
                .into_iter()
                .filter(|n| n.ends_with(":cursor") || n.ends_with(":reacher") || n.ends_with(":jaco"));
            let hint = crate::util::suggest::did_you_mean(name, embodied);
            Error::config(format!("'{name}' is not an embodied board game{hint}; supported: {ENV_HELP}"))
        };
        let Ok(EnvName::Embodied(game, embodiment)) = crate::envs::parse_env(name) else {
            return Err(bad());
        };
        if game != GameSpec::LightsOut(5) && game != GameSpec::TileSwap {
            return Err(Error::config(format!(
                "SEADS plays lightsout (5x5) and tileswap; '{}' is not supported (games: {GAME_HELP}; embodiments: {EMBODIMENT_HELP})",
                game.name()
            )));
        }
        Ok(EmbodiedGame { game, embodiment })
    }

    /// The board the manipulator plays on.
    pub fn board_layout(&self) -> Result<crate::envs::embodiments::BoardLayout> {
        crate::envs::embodiments::BoardLayout::of_spec(self.game)
    }

    pub fn name(&self) -> String {
        format!("{}:{}", self.game.name(), self.embodiment.name())
    }

    pub fn moves(&self) -> usize {
        match self.game {
            GameSpec::LightsOut(n) => n * n,
            GameSpec::TileSwap => 12,
        }
    }
}

/// What a SEADS run records beyond the shared fields: the sizes its networks are loaded with.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeadsDetails {
    /// Network input (observation ⊕ onehot(k)) and action sizes, for loading the policy.
    pub policy_input: usize,
    pub action_dim: usize,
    pub board_bits: usize,
    pub step_limit: usize,
}

/// config.json of a SEADS checkpoint.
pub type SeadsRun = RunRecord<Seads>;

/// A SEADS trainer of any game, with the figures its summary reports.
pub trait SeadsTraining: TrainingMethod + Send {
    fn last(&self) -> &EpochStats;
    fn env_steps(&self) -> u64;
}

impl<G: BoardGame> SeadsTraining for SeadsTrainer<G> {
    fn last(&self) -> &EpochStats {
        &self.last
    }
    fn env_steps(&self) -> u64 {
        SeadsTrainer::env_steps(self)
    }
}

/// SEADS as the training job drives it. It collects its own episodes, so a request has no data; its env
/// (the game and embodiment) is required.
pub struct Seads;

impl RunConfig for SeadsConfig {
    fn total_steps(&self) -> u64 {
        self.max_epochs()
    }

    /// Nothing is held out: the forward model's loss on each epoch's new episodes is the check.
    fn schedule(&self) -> (u64, u64) {
        (u64::MAX, self.checkpoint_every)
    }

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl Method for Seads {
    const NAME: &'static str = METHOD;
    const TITLE: &'static str = "SEADS";
    type Config = SeadsConfig;
    type Variant = ();
    type Details = SeadsDetails;
    type Trainer = Box<dyn SeadsTraining>;

    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>> {
        let name = request.env.as_deref().ok_or_else(|| Error::config(format!("SEADS needs an env ({ENV_HELP})")))?;
        let env = EmbodiedGame::parse(name)?;
        if !request.data.is_empty() {
            return Err(Error::config("SEADS collects its own episodes; it takes no --data"));
        }
        let (trainer, layout, step_limit): (Box<dyn SeadsTraining>, _, _) = match env.game {
            GameSpec::TileSwap => {
                let t = SeadsTrainer::new(request.config.clone(), TileSwap::new(), env.embodiment, request.seed)?;
                let (layout, limit) = (t.layout(), t.step_limit());
                (Box::new(t), layout, limit)
            }
            GameSpec::LightsOut(n) => {
                let t = SeadsTrainer::new(request.config.clone(), LightsOut::new(n)?, env.embodiment, request.seed)?;
                let (layout, limit) = (t.layout(), t.step_limit());
                (Box::new(t), layout, limit)
            }
        };
        let config = &request.config;
        let details = SeadsDetails {
            policy_input: layout.obs_dim + config.skills,
            action_dim: layout.action_dim,
            board_bits: layout.bits,
            step_limit,
        };
        let panels = vec![
            panel("loss: forward-model NLL per bit", &["train/loss"]),
            panel("distinct moves the skills execute", &["seads/distinct_moves"]),
            panel("intrinsic reward (final steps)", &["seads/intrinsic_reward"]),
            panel("SAC losses", &["sac/critic_loss", "sac/actor_loss"]),
        ];
        let view = training_view(
            &format!("train SEADS on {}", env.name()),
            panels,
            &[
                ("skills", config.skills.to_string()),
                ("env steps", config.env_steps.to_string()),
                ("episodes", format!("{} per epoch", config.episodes_per_epoch)),
                ("model", format!("lr {}, batch {}", config.model_learning_rate, config.model_batch)),
                ("SAC", format!("lr {}, batch {}", config.sac_learning_rate, config.sac_batch)),
            ],
        );
        Ok(Prepared { env: Some(env.name()), data: Vec::new(), details, trainer, view })
    }

    fn variant_of(_record: &SeadsRun) -> Result<()> {
        Ok(())
    }

    fn check_record(record: &SeadsRun) -> Result<()> {
        EmbodiedGame::parse(record.env()).map(|_| ())
    }

    fn fixed_fields(request: &Request<Self>) -> Vec<Field> {
        vec![Field::new("--env", "/env", serde_json::Value::from(request.env.clone()))]
    }
}

fn panel(title: &str, series: &[&str]) -> PanelSpec {
    PanelSpec {
        title: title.into(),
        x_label: "epoch".into(),
        series: series.iter().map(|s| s.to_string()).collect(),
        restart_on_rewind: false,
        path: None,
    }
}

/// What `mbrl train seads` reports of a finished run.
pub struct SeadsSummary {
    pub record: SeadsRun,
    pub outcome: FitOutcome,
    pub last: EpochStats,
    pub env_steps: u64,
    pub dir: PathBuf,
}

impl SeadsSummary {
    pub fn of(trained: &Trained<Seads>, dir: &Path) -> Self {
        SeadsSummary {
            record: trained.record.clone(),
            outcome: trained.outcome.clone(),
            last: trained.trainer.last().clone(),
            env_steps: trained.trainer.env_steps(),
            dir: dir.to_path_buf(),
        }
    }
}

impl std::fmt::Display for SeadsSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = &self.record.config;
        writeln!(
            f,
            "trained SEADS on {}: {} skills, {} epochs, {} env steps (budget {}), SAC hidden layers {}, forward model {} units",
            self.record.env(),
            c.skills,
            self.outcome.steps,
            self.env_steps,
            c.env_steps,
            c.sac_hidden.iter().map(usize::to_string).collect::<Vec<_>>().join(" × "),
            c.model_hidden
        )?;
        let last = &self.last;
        writeln!(
            f,
            "last epoch: the skills execute {} distinct game moves; forward-model NLL {:.4} nats per bit{}",
            last.distinct_moves,
            last.model_loss,
            last.mean_final_reward.map(|r| format!("; mean intrinsic reward {r:.3}")).unwrap_or_default()
        )?;
        write!(f, "checkpoint: {}", self.dir.display())
    }
}

#[cfg(test)]
mod tests;
