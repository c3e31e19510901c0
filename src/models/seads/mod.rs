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
use crate::run::dir::Provenance;
use crate::run::{Monitor, PanelSpec};
use crate::train::{run_training, training_view, FitOutcome, FitSettings, OpenedCheckpoint, Start};

pub const METHOD: &str = "seads";
pub const ENV_HELP: &str = "lightsout:cursor, tileswap:cursor, lightsout:reacher, tileswap:reacher";

/// A board game played through a manipulator, as named on the command line (`lightsout:cursor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmbodiedGame {
    pub game: GameSpec,
    pub embodiment: Embodiment,
}

impl EmbodiedGame {
    /// The registry's embodied env names, restricted to the games SEADS plays.
    pub fn parse(name: &str) -> Result<Self> {
        let bad = || Error::config(format!("'{name}' is not an embodied board game; supported: {ENV_HELP}"));
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

/// config.json of a SEADS checkpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeadsRun {
    pub method: String,
    pub env: String,
    pub seed: u64,
    pub config: SeadsConfig,
    /// Network input (observation ⊕ onehot(k)) and action sizes, for loading the policy.
    pub policy_input: usize,
    pub action_dim: usize,
    pub board_bits: usize,
    pub step_limit: usize,
    pub provenance: Provenance,
}

pub struct TrainRequest {
    pub out: PathBuf,
    pub env: EmbodiedGame,
    pub config: SeadsConfig,
    pub seed: u64,
    pub provenance: Provenance,
}

pub struct TrainReport {
    pub run: SeadsRun,
    pub outcome: FitOutcome,
    pub last: EpochStats,
    pub env_steps: u64,
}

/// Trains (or, with `resume`, continues) SEADS into `request.out`.
pub fn train(request: &TrainRequest, resume: bool, monitor: &dyn Monitor) -> Result<TrainReport> {
    match request.env.game {
        GameSpec::TileSwap => train_game(TileSwap::new(), request, resume, monitor),
        GameSpec::LightsOut(n) => train_game(LightsOut::new(n)?, request, resume, monitor),
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

fn train_game<G: BoardGame>(
    game: G,
    request: &TrainRequest,
    resume: bool,
    monitor: &dyn Monitor,
) -> Result<TrainReport> {
    let config = &request.config;
    config.validate()?;
    let mut trainer = SeadsTrainer::new(config.clone(), game, request.env.embodiment, request.seed)?;
    let layout = trainer.layout();
    let run = SeadsRun {
        method: METHOD.into(),
        env: request.env.name(),
        seed: request.seed,
        config: config.clone(),
        policy_input: layout.obs_dim + config.skills,
        action_dim: layout.action_dim,
        board_bits: layout.bits,
        step_limit: trainer.step_limit(),
        provenance: request.provenance.clone(),
    };
    let settings = FitSettings {
        method: METHOD.into(),
        env: Some(run.env.clone()),
        total_steps: config.max_epochs(),
        // Nothing is held out: the forward model's loss on each epoch's new episodes is the check.
        validate_every: u64::MAX,
        checkpoint_every: config.checkpoint_every,
    };
    let json = serde_json::to_value(&run).map_err(|e| Error::config(e.to_string()))?;
    let title = format!("train SEADS on {}", run.env);
    let panels = vec![
        panel("loss: forward-model NLL per bit", &["train/loss"]),
        panel("distinct moves the skills execute", &["seads/distinct_moves"]),
        panel("intrinsic reward (final steps)", &["seads/intrinsic_reward"]),
        panel("SAC losses", &["sac/critic_loss", "sac/actor_loss"]),
    ];
    let view = training_view(
        &title,
        panels,
        &[
            ("skills", config.skills.to_string()),
            ("env steps", config.env_steps.to_string()),
            ("episodes", format!("{} per epoch", config.episodes_per_epoch)),
            ("model", format!("lr {}, batch {}", config.model_learning_rate, config.model_batch)),
            ("SAC", format!("lr {}, batch {}", config.sac_learning_rate, config.sac_batch)),
        ],
    );
    let outcome = run_training(&request.out, &json, &settings, &mut trainer, Start::resuming(resume), &view, monitor)?;
    Ok(TrainReport { run, outcome, last: trainer.last.clone(), env_steps: trainer.env_steps() })
}

pub fn read_run(opened: &OpenedCheckpoint) -> Result<SeadsRun> {
    serde_json::from_value(opened.config.clone())
        .map_err(|e| Error::bad_file(&opened.dir.file("config.json"), format!("not a SEADS run config: {e}")))
}

/// Continues the run in `dir` from its last checkpoint.
pub fn resume(dir: &Path, monitor: &dyn Monitor) -> Result<TrainReport> {
    let opened = OpenedCheckpoint::open(dir)?;
    let run = read_run(&opened)?;
    opened.expect_total_steps(run.config.max_epochs() as u64)?;
    let request = TrainRequest {
        out: dir.to_path_buf(),
        env: EmbodiedGame::parse(&run.env)?,
        config: run.config.clone(),
        seed: run.seed,
        provenance: run.provenance.clone(),
    };
    train(&request, true, monitor)
}

#[cfg(test)]
mod tests;
