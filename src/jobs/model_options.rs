//! Which dynamics a planner uses: `--model true` (the simulator's own equations) or a trained checkpoint, and
//! how a stochastic learned model is rolled out.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};

use super::warn;
use crate::control::BatchDynamics;
use crate::envs::EnvName;
use crate::models::pets::Propagation;
use crate::models::{load_planning_model, RolloutOptions};
use crate::train::{Accept, OpenedCheckpoint, TrainingProgress};
use crate::{refuse, Result};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum PropagationChoice {
    /// TS-1: each particle draws an ensemble member anew at every step.
    Ts1,
    /// TS-∞: each particle keeps one member for the whole horizon.
    Tsinf,
    /// Each member's mean prediction, no sampling.
    Expectation,
}

#[derive(Args, Clone, Debug)]
pub struct ModelOptions {
    /// Dynamics the planner uses: `true` (the simulator's equations) or a checkpoint directory written by
    /// `mbrl train` (e.g. models/pets-pendulum).
    #[arg(long)]
    pub model: String,
    /// Particles per candidate for stochastic learned models (PETS: trajectory sampling).
    #[arg(long, default_value_t = 20)]
    pub particles: usize,
    /// How particles use the ensemble members.
    #[arg(long, value_enum, default_value_t = PropagationChoice::Tsinf)]
    pub propagation: PropagationChoice,
    /// Calibration transitions (`mbrl calibrate --out`) a context model is conditioned on; without it the
    /// model plans with its prior mean context.
    #[arg(long)]
    pub context: Option<PathBuf>,
    /// Take a run still in training (its best-validation weights so far); the output says how far it got.
    #[arg(long)]
    pub allow_incomplete: bool,
}

impl ModelOptions {
    /// `None` for the ground truth.
    pub fn load(&self, env: &EnvName) -> Result<Option<Box<dyn BatchDynamics>>> {
        if self.model == "true" {
            if self.context.is_some() {
                refuse!("--context conditions a learned context model; `--model true` plans with the simulator itself");
            }
            return Ok(None);
        }
        if !(1..=10_000).contains(&self.particles) {
            refuse!("--particles must be 1..=10000, got {}", self.particles);
        }
        let propagation = match self.propagation {
            PropagationChoice::Ts1 => Propagation::Ts1,
            PropagationChoice::Tsinf => Propagation::TsInf,
            PropagationChoice::Expectation => Propagation::Expectation,
        };
        let dir = PathBuf::from(&self.model);
        if !dir.exists() {
            refuse!(
                "--model '{}': no such checkpoint directory; expected `true` or a directory written by `mbrl train`",
                self.model
            );
        }
        let model = load_planning_model(
            &dir,
            env,
            RolloutOptions {
                propagation,
                particles: self.particles,
                context: self.context.clone(),
                accept: self.accept(),
            },
        )?;
        warn_if_unfinished(&dir)?;
        Ok(Some(model))
    }

    /// The checkpoints `--allow-incomplete` lets a command take.
    pub fn accept(&self) -> Accept {
        accepting(self.allow_incomplete)
    }
}

/// The checkpoints `--allow-incomplete` lets a command take.
pub fn accepting(allow_incomplete: bool) -> Accept {
    if allow_incomplete {
        Accept::InProgress
    } else {
        Accept::Finished
    }
}

/// A one-line warning on stderr when a loaded model's training is unfinished (only `--allow-incomplete` lets
/// such a model load).
pub fn warn_if_unfinished(model: &Path) -> Result<()> {
    report_unfinished(model, &OpenedCheckpoint::open(model)?.progress());
    Ok(())
}

/// As [`warn_if_unfinished`], for a caller that holds the loaded model's progress.
pub fn report_unfinished(model: &Path, progress: &TrainingProgress) {
    if !progress.complete {
        warn(&format!("{}: {}", model.display(), progress.describe()));
    }
}
