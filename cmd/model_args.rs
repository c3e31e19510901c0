//! Which dynamics a planner uses: `--model true` (the simulator's own equations) or a trained checkpoint, and
//! how a stochastic learned model is rolled out.

use std::path::PathBuf;

use anyhow::bail;
use clap::{Args, ValueEnum};
use mbrl::envs::{BatchDynamics, EnvName};
use mbrl::models::pets::Propagation;
use mbrl::models::{load_planning_model, RolloutOptions};

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
pub struct ModelArgs {
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
}

impl ModelArgs {
    /// `None` for the ground truth.
    pub fn load(&self, env: &EnvName) -> anyhow::Result<Option<Box<dyn BatchDynamics>>> {
        if self.model == "true" {
            if self.context.is_some() {
                bail!("--context conditions a learned context model; `--model true` plans with the simulator itself");
            }
            return Ok(None);
        }
        if !(1..=10_000).contains(&self.particles) {
            bail!("--particles must be 1..=10000, got {}", self.particles);
        }
        let propagation = match self.propagation {
            PropagationChoice::Ts1 => Propagation::Ts1,
            PropagationChoice::Tsinf => Propagation::TsInf,
            PropagationChoice::Expectation => Propagation::Expectation,
        };
        let dir = PathBuf::from(&self.model);
        if !dir.exists() {
            bail!(
                "--model '{}': no such checkpoint directory; expected `true` or a directory written by `mbrl train`",
                self.model
            );
        }
        Ok(Some(load_planning_model(
            &dir,
            env,
            RolloutOptions { propagation, particles: self.particles, context: self.context.clone() },
        )?))
    }
}
