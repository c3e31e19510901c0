//! CEM flags shared by `plan` and `eval pendulum-swingup`.

use clap::{Args, ValueEnum};
use mbrl::planning::{CemConfig, NoiseKind};

use crate::common::finite_f64;

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum NoiseChoice {
    /// Independent Gaussian samples (thesis Algorithm 1).
    White,
    /// Power spectral density ∝ 1/f^β along time (iCEM).
    Colored,
}

#[derive(Args, Clone, Debug)]
pub struct CemArgs {
    /// Planning horizon in steps.
    #[arg(long, default_value_t = 20)]
    pub horizon: usize,
    /// Candidate action sequences per iteration.
    #[arg(long, default_value_t = 1000)]
    pub candidates: usize,
    /// Elite candidates used to refit the sampling distribution.
    #[arg(long, default_value_t = 100)]
    pub elites: usize,
    /// CEM iterations per planning call.
    #[arg(long, default_value_t = 10)]
    pub iters: usize,
    /// Sampling noise.
    #[arg(long, value_enum, default_value_t = NoiseChoice::White)]
    pub noise: NoiseChoice,
    /// Exponent β of colored noise (used with --noise colored).
    #[arg(long, default_value_t = 0.5, value_parser = finite_f64)]
    pub beta: f64,
    /// Start every planning call from zero instead of the previous plan shifted by one step.
    #[arg(long)]
    pub no_warm_start: bool,
}

impl CemArgs {
    pub fn config(&self, action_low: &[f64], action_high: &[f64]) -> CemConfig {
        CemConfig {
            horizon: self.horizon,
            candidates: self.candidates,
            elites: self.elites,
            iterations: self.iters,
            noise: match self.noise {
                NoiseChoice::White => NoiseKind::White,
                NoiseChoice::Colored => NoiseKind::Colored { beta: self.beta },
            },
            warm_start: !self.no_warm_start,
            ..CemConfig::for_box(action_low, action_high)
        }
    }
}
