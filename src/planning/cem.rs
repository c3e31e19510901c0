//! The cross-entropy method for trajectory optimization (thesis Algorithm 1), batched over candidates,
//! with warm starts for MPC and optional colored-noise sampling.

use rand::Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;
use rustfft::num_complex::Complex;
use serde::{Deserialize, Serialize};

use super::colored_noise::ColoredNoise;
use crate::control::Objective;
use crate::error::{Error, Result};
use crate::util::budget;
use crate::util::seeding::rng_for;

/// Candidates that share one random stream. Fixed, so results do not depend on the thread count.
const CANDIDATES_PER_STREAM: usize = 64;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NoiseKind {
    White,
    /// Power spectral density ∝ 1/f^beta along the time axis.
    Colored {
        beta: f64,
    },
}

impl NoiseKind {
    /// As reports name it: `white`, `colored (β = 2)`.
    pub fn describe(&self) -> String {
        match self {
            NoiseKind::White => "white".to_string(),
            NoiseKind::Colored { beta } => format!("colored (β = {beta})"),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CemConfig {
    pub horizon: usize,
    pub candidates: usize,
    pub elites: usize,
    pub iterations: usize,
    pub action_low: Vec<f64>,
    pub action_high: Vec<f64>,
    /// Initial standard deviation per action dimension; Algorithm 1 uses a_max.
    pub init_std: Vec<f64>,
    pub noise: NoiseKind,
    /// Start each MPC step from the previous mean shifted by one step instead of from zero.
    pub warm_start: bool,
    /// Stop iterating once the refit std of every first-step action is at most this (DLGPD's planner stops
    /// at 0.01); `None` runs all iterations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_std: Option<f64>,
}

/// Far beyond what CEM needs to settle; a larger count is a typo that would run for hours.
pub const MAX_ITERATIONS: usize = 10_000;

impl CemConfig {
    /// Algorithm 1 defaults for a box action space: μ = 0, σ = a_max, white noise, warm start on.
    pub fn for_box(action_low: &[f64], action_high: &[f64]) -> Self {
        let init_std = action_low.iter().zip(action_high).map(|(l, h)| l.abs().max(h.abs())).collect();
        CemConfig {
            horizon: 20,
            candidates: 1000,
            elites: 100,
            iterations: 10,
            action_low: action_low.to_vec(),
            action_high: action_high.to_vec(),
            init_std,
            noise: NoiseKind::White,
            warm_start: true,
            stop_std: None,
        }
    }

    pub fn action_dim(&self) -> usize {
        self.action_low.len()
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |msg: String| Err(Error::config(msg));
        if self.horizon == 0 || self.candidates == 0 || self.iterations == 0 {
            return bad("CEM: horizon, candidates and iterations must be at least 1".into());
        }
        if self.elites < 2 || self.elites > self.candidates {
            return bad(format!(
                "CEM: elites must be between 2 and the number of candidates ({}), got {}",
                self.candidates, self.elites
            ));
        }
        let d = self.action_dim();
        if d == 0 || self.action_high.len() != d || self.init_std.len() != d {
            return bad("CEM: action bounds and initial std must have the same nonzero length".into());
        }
        if self.iterations > MAX_ITERATIONS {
            return bad(format!(
                "CEM: {} iterations; at most {MAX_ITERATIONS} (CEM settles within tens)",
                self.iterations
            ));
        }
        // Sampled sequences, their noise and the warm start, plus per-candidate costs and ranks.
        let bytes = budget::times(&[self.candidates, self.horizon, d], 24) + budget::times(&[self.candidates], 64);
        budget::check(
            &format!("CEM with {} candidates (--candidates) × horizon {} (--horizon)", self.candidates, self.horizon),
            bytes,
            "plan with fewer candidates or a shorter horizon",
        )?;
        for i in 0..d {
            let (lo, hi, sd) = (self.action_low[i], self.action_high[i], self.init_std[i]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi && sd.is_finite() && sd > 0.0) {
                return bad(format!("CEM: action dimension {i} needs finite low < high and std > 0"));
            }
        }
        if let Some(s) = self.stop_std {
            if !(s.is_finite() && s >= 0.0) {
                return bad(format!("CEM: the stopping std must be finite and ≥ 0, got {s}"));
            }
        }
        if let NoiseKind::Colored { beta } = self.noise {
            if !beta.is_finite() || beta < 0.0 {
                return bad(format!("CEM: colored-noise exponent must be finite and ≥ 0, got {beta}"));
            }
        }
        Ok(())
    }
}

/// What one optimization iteration achieved (for progress panels and tests).
#[derive(Clone, Debug, PartialEq)]
pub struct CemIteration {
    pub iteration: usize,
    pub best_cost: f64,
    pub elite_mean_cost: f64,
}

/// A CEM optimizer that keeps its mean between calls, for receding-horizon control.
pub struct Cem {
    config: CemConfig,
    seed: u64,
    calls: u64,
    mean: Vec<f64>,
    std: Vec<f64>,
    colored: Option<ColoredNoise>,
}

impl Cem {
    pub fn new(config: CemConfig, seed: u64) -> Result<Self> {
        config.validate()?;
        let colored = match config.noise {
            NoiseKind::Colored { beta } => Some(ColoredNoise::new(beta, config.horizon)),
            NoiseKind::White => None,
        };
        let n = config.horizon * config.action_dim();
        let mut cem = Cem { seed, calls: 0, mean: vec![0.0; n], std: vec![0.0; n], colored, config };
        cem.reset();
        Ok(cem)
    }

    pub fn config(&self) -> &CemConfig {
        &self.config
    }

    /// Forget the previous plan (new episode).
    pub fn reset(&mut self) {
        self.mean.iter_mut().for_each(|m| *m = 0.0);
        self.reset_std();
    }

    fn reset_std(&mut self) {
        let d = self.config.action_dim();
        for (i, s) in self.std.iter_mut().enumerate() {
            *s = self.config.init_std[i % d];
        }
    }

    /// Optimizes a sequence of `horizon` actions. Returns the final mean (row-major `horizon × action_dim`)
    /// and calls `on_iteration` after each refit.
    ///
    /// A candidate whose cost is NaN never becomes an elite. When no candidate of an iteration has a finite
    /// cost, there is nothing to refit to: the objective's model has diverged from every start, and the plan
    /// stops there with `Error::Diverged` naming the iteration rather than returning actions chosen blindly.
    pub fn plan(&mut self, objective: &dyn Objective, mut on_iteration: impl FnMut(&CemIteration)) -> Result<Vec<f64>> {
        let cfg = &self.config;
        let (h, d, n) = (cfg.horizon, cfg.action_dim(), cfg.candidates);
        let per = h * d;
        if cfg.warm_start && self.calls > 0 {
            self.shift_mean();
        } else {
            self.mean.iter_mut().for_each(|m| *m = 0.0);
        }
        self.reset_std();
        let mut candidates = vec![0.0; n * per];
        let mut costs = vec![0.0; n];
        let mut order: Vec<usize> = (0..n).collect();
        for iteration in 0..self.config.iterations {
            self.sample(&mut candidates, iteration as u64);
            objective.costs(&candidates, h, &mut costs);
            // A model that diverges must not win the elite selection.
            costs.iter_mut().filter(|c| c.is_nan()).for_each(|c| *c = f64::INFINITY);
            if !costs.iter().any(|c| c.is_finite()) {
                return Err(Error::diverged(format!(
                    "CEM iteration {} of {}: none of the {n} candidates has a finite cost (the model's \
                     predictions are NaN or infinite from this start)",
                    iteration + 1,
                    self.config.iterations
                )));
            }
            order.iter_mut().enumerate().for_each(|(i, o)| *o = i);
            let elites = self.config.elites;
            order.select_nth_unstable_by(elites - 1, |&a, &b| costs[a].total_cmp(&costs[b]).then(a.cmp(&b)));
            let elite_idx = &mut order[..elites];
            elite_idx.sort_unstable();
            self.refit(&candidates, elite_idx);
            let best_cost = elite_idx.iter().map(|&i| costs[i]).fold(f64::INFINITY, f64::min);
            let elite_mean_cost = elite_idx.iter().map(|&i| costs[i]).sum::<f64>() / elites as f64;
            on_iteration(&CemIteration { iteration, best_cost, elite_mean_cost });
            if self.config.stop_std.is_some_and(|limit| self.std[..d].iter().all(|&s| s <= limit)) {
                break;
            }
        }
        self.calls += 1;
        Ok(self.mean.clone())
    }

    /// Drops the first step of the previous mean and repeats zero at the end.
    fn shift_mean(&mut self) {
        let d = self.config.action_dim();
        self.mean.rotate_left(d);
        let len = self.mean.len();
        self.mean[len - d..].iter_mut().for_each(|m| *m = 0.0);
    }

    fn sample(&self, candidates: &mut [f64], iteration: u64) {
        let cfg = &self.config;
        let (h, d) = (cfg.horizon, cfg.action_dim());
        let per = h * d;
        let (seed, call) = (self.seed, self.calls);
        candidates.par_chunks_mut(per * CANDIDATES_PER_STREAM).enumerate().for_each(|(stream, block)| {
            let mut rng = rng_for(seed, &[call, iteration, stream as u64]);
            let mut scratch = vec![Complex::new(0.0, 0.0); h];
            let mut series = vec![0.0; h];
            for cand in block.chunks_mut(per) {
                match &self.colored {
                    None => cand.iter_mut().for_each(|x| *x = rng.sample(StandardNormal)),
                    Some(noise) => {
                        for j in 0..d {
                            noise.sample_into(&mut rng, &mut scratch, &mut series);
                            for (t, e) in series.iter().enumerate() {
                                cand[t * d + j] = *e;
                            }
                        }
                    }
                }
                for (k, x) in cand.iter_mut().enumerate() {
                    let j = k % d;
                    *x = (self.mean[k] + self.std[k] * *x).clamp(cfg.action_low[j], cfg.action_high[j]);
                }
            }
        });
    }

    /// Mean and unbiased variance of the elite candidates (Algorithm 1, lines 9-10).
    fn refit(&mut self, candidates: &[f64], elites: &[usize]) {
        let per = self.mean.len();
        let count = elites.len() as f64;
        for k in 0..per {
            let mean = elites.iter().map(|&e| candidates[e * per + k]).sum::<f64>() / count;
            let var = elites.iter().map(|&e| (candidates[e * per + k] - mean).powi(2)).sum::<f64>() / (count - 1.0);
            self.mean[k] = mean;
            self.std[k] = var.sqrt();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cost = squared distance of the sequence to a target sequence.
    struct Quadratic {
        target: Vec<f64>,
    }

    impl Objective for Quadratic {
        fn costs(&self, candidates: &[f64], _horizon: usize, costs: &mut [f64]) {
            for (c, seq) in costs.iter_mut().zip(candidates.chunks(self.target.len())) {
                *c = seq.iter().zip(&self.target).map(|(a, b)| (a - b).powi(2)).sum();
            }
        }
    }

    fn config(noise: NoiseKind) -> CemConfig {
        CemConfig {
            horizon: 8,
            candidates: 300,
            elites: 30,
            iterations: 12,
            noise,
            ..CemConfig::for_box(&[-2.0], &[2.0])
        }
    }

    #[test]
    fn stops_early_once_the_first_action_has_settled() {
        let target: Vec<f64> = (0..8).map(|t| (t as f64 * 0.4).sin()).collect();
        let objective = Quadratic { target };
        let run = |stop_std| {
            let mut cem = Cem::new(CemConfig { stop_std, iterations: 40, ..config(NoiseKind::White) }, 3).unwrap();
            let mut iterations = 0;
            cem.plan(&objective, |_| iterations += 1).unwrap();
            iterations
        };
        let (all, stopped) = (run(None), run(Some(0.01)));
        assert_eq!(all, 40);
        assert!(stopped < 40, "stopped after {stopped} iterations");
    }

    #[test]
    fn converges_to_the_minimum_of_a_quadratic() {
        for noise in [NoiseKind::White, NoiseKind::Colored { beta: 0.5 }] {
            let target: Vec<f64> = (0..8).map(|t| 1.5 * ((t as f64) * 0.7).sin()).collect();
            let mut cem = Cem::new(config(noise), 1).unwrap();
            let mut last = f64::INFINITY;
            let plan = cem.plan(&Quadratic { target: target.clone() }, |it| last = it.best_cost).unwrap();
            let err: f64 = plan.iter().zip(&target).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(err < 0.05, "{noise:?}: max error {err}");
            assert!(last < 1e-2, "{noise:?}: best cost {last}");
        }
    }

    #[test]
    fn samples_respect_bounds_even_for_targets_outside() {
        let mut cem = Cem::new(config(NoiseKind::White), 2).unwrap();
        let plan = cem.plan(&Quadratic { target: vec![5.0; 8] }, |_| {}).unwrap();
        assert!(plan.iter().all(|a| (1.9..=2.0).contains(a)), "{plan:?}");
    }

    #[test]
    fn same_seed_same_plan_regardless_of_thread_count() {
        let target = vec![0.3; 8];
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut cem = Cem::new(config(NoiseKind::White), 9).unwrap();
                cem.plan(&Quadratic { target: target.clone() }, |_| {}).unwrap()
            })
        };
        assert_eq!(run(1), run(3));
    }

    #[test]
    fn warm_start_shifts_the_previous_mean() {
        let mut cfg = config(NoiseKind::White);
        cfg.iterations = 1;
        let mut cem = Cem::new(cfg, 4).unwrap();
        cem.mean = (0..8).map(|t| t as f64).collect();
        cem.calls = 1;
        cem.shift_mean();
        assert_eq!(cem.mean, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 0.0]);
    }

    #[test]
    fn nan_costs_never_become_elites() {
        struct NanForPositive;
        impl Objective for NanForPositive {
            fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
                for (c, seq) in costs.iter_mut().zip(candidates.chunks(horizon)) {
                    *c = if seq[0] > 0.0 { f64::NAN } else { -seq[0] };
                }
            }
        }
        let mut cem = Cem::new(config(NoiseKind::White), 5).unwrap();
        let plan = cem.plan(&NanForPositive, |_| {}).unwrap();
        assert!(plan[0] <= 0.0 && plan[0] > -0.2, "{}", plan[0]);
    }

    #[test]
    fn a_model_diverged_from_every_start_stops_the_plan_at_the_first_such_iteration() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        struct DivergesAfter(AtomicUsize);
        impl Objective for DivergesAfter {
            fn costs(&self, _candidates: &[f64], _horizon: usize, costs: &mut [f64]) {
                let calls = self.0.fetch_add(1, Ordering::Relaxed) + 1;
                let value = if calls >= 3 { f64::NAN } else { 1.0 };
                costs.iter_mut().enumerate().for_each(|(i, c)| *c = if i % 2 == 0 { value } else { f64::INFINITY });
            }
        }
        let mut cem = Cem::new(config(NoiseKind::White), 5).unwrap();
        let mut seen = 0;
        let err = cem.plan(&DivergesAfter(AtomicUsize::new(0)), |_| seen += 1).unwrap_err();
        assert_eq!(seen, 2, "the two finite iterations are reported, the third is not");
        let message = err.to_string();
        assert!(message.contains("CEM iteration 3 of") && message.contains("finite cost"), "{message}");
    }

    #[test]
    fn invalid_settings_are_rejected() {
        let mut cfg = config(NoiseKind::White);
        cfg.elites = 1000;
        assert!(Cem::new(cfg, 0).is_err());
        let mut cfg = config(NoiseKind::Colored { beta: f64::NAN });
        cfg.elites = 10;
        assert!(Cem::new(cfg, 0).is_err());
    }
}
