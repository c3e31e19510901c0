//! CEM flags shared by `plan` and `eval pendulum-swingup`.

use super::finite_f64;
use crate::planning::{CemConfig, NoiseKind};
use clap::{Args, ValueEnum};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum NoiseChoice {
    /// Independent Gaussian samples (thesis Algorithm 1).
    White,
    /// Power spectral density ∝ 1/f^β along time (iCEM).
    Colored,
}

/// Defaults are the task's planner: pendulum swing-up 20 / 1000 / 100 / 10, white, warm start; unicycle
/// navigation (TRADYN) 30 / 1000 / 50 / 20, colored β 0.5, initial std 0.5, no warm start.
#[derive(Args, Clone, Debug)]
pub struct CemOptions {
    /// Planning horizon in steps (pendulum 20; unicycle 30, shrinking to the steps left).
    #[arg(long)]
    pub horizon: Option<usize>,
    /// Candidate action sequences per iteration (1000).
    #[arg(long)]
    pub candidates: Option<usize>,
    /// Elite candidates used to refit the sampling distribution (pendulum 100; unicycle 50).
    #[arg(long)]
    pub elites: Option<usize>,
    /// CEM iterations per planning call (pendulum 10; unicycle 20).
    #[arg(long)]
    pub iters: Option<usize>,
    /// Sampling noise (pendulum white; unicycle colored).
    #[arg(long, value_enum)]
    pub noise: Option<NoiseChoice>,
    /// Exponent β of colored noise (0.5; used with --noise colored).
    #[arg(long, value_parser = finite_f64)]
    pub beta: Option<f64>,
    /// Start every planning call from zero instead of the previous plan shifted by one step.
    #[arg(long)]
    pub no_warm_start: bool,
}

impl CemOptions {
    /// The pendulum planner (Algorithm 1 defaults) over these flags.
    pub fn config(&self, action_low: &[f64], action_high: &[f64]) -> CemConfig {
        self.over(CemConfig::for_box(action_low, action_high))
    }

    /// `base` with the flags given applied.
    pub fn over(&self, base: CemConfig) -> CemConfig {
        let beta = self.beta.unwrap_or(match base.noise {
            NoiseKind::Colored { beta } => beta,
            NoiseKind::White => 0.5,
        });
        let noise = match self.noise {
            Some(NoiseChoice::White) => NoiseKind::White,
            Some(NoiseChoice::Colored) => NoiseKind::Colored { beta },
            None => match base.noise {
                NoiseKind::Colored { .. } => NoiseKind::Colored { beta },
                white => white,
            },
        };
        CemConfig {
            horizon: self.horizon.unwrap_or(base.horizon),
            candidates: self.candidates.unwrap_or(base.candidates),
            elites: self.elites.unwrap_or(base.elites),
            iterations: self.iters.unwrap_or(base.iterations),
            noise,
            warm_start: base.warm_start && !self.no_warm_start,
            ..base
        }
    }
}
