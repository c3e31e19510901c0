//! The toy system of Explore the Context (thesis 4.5.2, eq. 4.40): a damped linear oscillator whose first
//! state dimension is pushed by α·δ(u). The squashing δ hides α from every transition whose action it maps to
//! zero, which is what makes some actions informative about the hidden parameter and others not.
//!
//! The system has no task: every reward is 0. It exists to study what a context model can infer.

use rand::{Rng, RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::envs::{Dynamics, Env, EnvSpec, Step};
use crate::error::{Error, Result};
use crate::util::suggest::did_you_mean;

/// x' = A x + [α, 0]ᵀ δ(u) + ε.
const A: [[f64; 2]; 2] = [[0.8, 0.2], [-0.2, 0.8]];
const MAX_ACTION: f64 = 2.0;
const NOISE_STD: f64 = 0.01;

/// Which actions reach the system, and so which transitions tell anything about α.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Squash {
    /// δ(u) = max(1 − |u|, 0): only small actions act (δ<1 in the thesis).
    Inner,
    /// δ(u) = max(|u| − 1, 0): only large actions act (δ>1 in the thesis).
    Outer,
}

pub const SQUASH_HELP: &str = "inner (δ = max(1−|u|, 0)), outer (δ = max(|u|−1, 0))";

/// The variants `toy:<name>` takes.
pub const SQUASH_NAMES: [&str; 2] = ["inner", "outer"];

impl Squash {
    pub fn parse(text: &str) -> Result<Self> {
        match text {
            "inner" => Ok(Squash::Inner),
            "outer" => Ok(Squash::Outer),
            "" => Err(Error::config(format!("'toy' needs its squashing: toy:inner or toy:outer ({SQUASH_HELP})"))),
            other => Err(Error::config(format!(
                "unknown toy variant '{other}'{}; expected one of: {SQUASH_HELP}",
                did_you_mean(other, SQUASH_NAMES)
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Squash::Inner => "inner",
            Squash::Outer => "outer",
        }
    }

    /// δ(u) on the clipped action.
    pub fn apply(self, action: f64) -> f64 {
        let u = action.clamp(-MAX_ACTION, MAX_ACTION).abs();
        match self {
            Squash::Inner => (1.0 - u).max(0.0),
            Squash::Outer => (u - 1.0).max(0.0),
        }
    }
}

/// The hidden parameters of one instance, as recorded in datasets: `{"alpha": …, "squash": "inner"}`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ToyParams {
    pub alpha: f64,
    pub squash: Squash,
}

/// The noise-free mean of eq. 4.40.
pub fn mean_step(p: &ToyParams, state: [f64; 2], action: f64) -> [f64; 2] {
    let push = p.alpha * p.squash.apply(action);
    [A[0][0] * state[0] + A[0][1] * state[1] + push, A[1][0] * state[0] + A[1][1] * state[1]]
}

/// The toy system's mean dynamics for planners. The simulator adds N(0, 0.01²) noise per step; a planner
/// gets the expectation, since its own rollouts should not depend on noise draws.
#[derive(Clone, Debug)]
pub struct ToyDynamics {
    pub params: ToyParams,
}

impl Dynamics for ToyDynamics {
    fn state_dim(&self) -> usize {
        2
    }

    fn action_dim(&self) -> usize {
        1
    }

    fn step(&self, state: &mut [f64], action: &[f64]) -> f64 {
        let next = mean_step(&self.params, [state[0], state[1]], action[0]);
        state.copy_from_slice(&next);
        0.0
    }
}

pub struct Toy {
    params: ToyParams,
    state: [f64; 2],
    /// `step` takes no RNG, so the transition noise has its own stream; `reset` reseeds it from the caller's
    /// RNG so that an episode is a function of the seed it was reset with.
    noise: ChaCha8Rng,
}

impl Toy {
    /// An instance with α = 0 (no action reaches the system) until `sample_instance` draws one.
    pub fn new(squash: Squash) -> Self {
        Toy { params: ToyParams { alpha: 0.0, squash }, state: [0.0; 2], noise: ChaCha8Rng::seed_from_u64(0) }
    }

    pub fn toy_params(&self) -> ToyParams {
        self.params
    }

    pub fn set_params(&mut self, params: ToyParams) {
        self.params = params;
    }

    /// Restarts the transition noise, for replays that must repeat a recorded noise sequence.
    pub fn seed_noise(&mut self, seed: u64) {
        self.noise = ChaCha8Rng::seed_from_u64(seed);
    }

    pub fn toy_dynamics(&self) -> ToyDynamics {
        ToyDynamics { params: self.params }
    }
}

impl Env for Toy {
    fn spec(&self) -> EnvSpec {
        let names = vec!["s1".to_string(), "s2".to_string()];
        EnvSpec {
            name: format!("toy:{}", self.params.squash.name()),
            state_names: names.clone(),
            obs_names: names,
            action_low: vec![-MAX_ACTION],
            action_high: vec![MAX_ACTION],
            // A discrete-time system: one step is one unit of time.
            dt: 1.0,
            angular: vec![false, false],
        }
    }

    /// s0 ∼ N(0, I); the noise stream is reseeded from the next draw of `rng`.
    fn reset(&mut self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        self.state = [rng.sample(StandardNormal), rng.sample(StandardNormal)];
        self.seed_noise(rng.next_u64());
        self.observe()
    }

    fn step(&mut self, action: &[f64]) -> Step {
        let mean = mean_step(&self.params, self.state, action[0]);
        for (s, m) in self.state.iter_mut().zip(mean) {
            let e: f64 = self.noise.sample(StandardNormal);
            *s = m + NOISE_STD * e;
        }
        Step { obs: self.observe(), reward: 0.0, done: false }
    }

    fn state(&self) -> Vec<f64> {
        self.state.to_vec()
    }

    fn set_state(&mut self, state: &[f64]) {
        self.state = [state[0], state[1]];
    }

    fn observe(&self) -> Vec<f64> {
        self.state.to_vec()
    }

    fn params(&self) -> serde_json::Value {
        serde_json::to_value(self.params).unwrap_or(serde_json::Value::Null)
    }

    /// α ∼ U(−1, 1).
    fn sample_instance(&mut self, rng: &mut ChaCha8Rng) {
        self.params.alpha = rng.random_range(-1.0..1.0);
    }

    fn dynamics(&self) -> Option<Box<dyn Dynamics>> {
        Some(Box::new(self.toy_dynamics()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn instance(squash: Squash, alpha: f64) -> Toy {
        let mut env = Toy::new(squash);
        env.set_params(ToyParams { alpha, squash });
        env
    }

    #[test]
    fn squashing_hides_alpha_outside_its_informative_region() {
        assert_eq!(Squash::Inner.apply(0.25), 0.75);
        assert_eq!(Squash::Inner.apply(-1.5), 0.0);
        assert_eq!(Squash::Outer.apply(0.5), 0.0);
        assert_eq!(Squash::Outer.apply(-1.5), 0.5);
        assert_eq!(Squash::Outer.apply(5.0), 1.0, "actions are clipped to ±2 first");
    }

    #[test]
    fn mean_step_is_eq_4_40() {
        let p = ToyParams { alpha: 0.5, squash: Squash::Inner };
        let next = mean_step(&p, [1.0, -2.0], 0.5);
        assert!((next[0] - (0.8 - 0.4 + 0.25)).abs() < 1e-15);
        assert!((next[1] - (-0.2 - 1.6)).abs() < 1e-15);
    }

    #[test]
    fn noise_has_the_thesis_scale_and_follows_the_reset_seed() {
        let mut env = instance(Squash::Outer, 0.7);
        let mut residuals = Vec::new();
        env.reset(&mut ChaCha8Rng::seed_from_u64(1));
        for k in 0..2000 {
            let before = env.state();
            let u = if k % 2 == 0 { 1.8 } else { -0.3 };
            let mean = mean_step(&env.toy_params(), [before[0], before[1]], u);
            let after = env.step(&[u]).obs;
            residuals.extend([after[0] - mean[0], after[1] - mean[1]]);
        }
        let var = residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64;
        assert!((var.sqrt() - NOISE_STD).abs() < 0.001, "noise std {}", var.sqrt());

        let run = |seed| {
            let mut env = instance(Squash::Outer, 0.7);
            env.reset(&mut ChaCha8Rng::seed_from_u64(seed));
            (0..5).map(|_| env.step(&[1.5]).obs).collect::<Vec<_>>()
        };
        assert_eq!(run(4), run(4));
        assert_ne!(run(4), run(5));
    }

    #[test]
    fn instances_draw_alpha_in_range_and_record_it() {
        let mut env = Toy::new(Squash::Inner);
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let alphas: Vec<f64> = (0..200)
            .map(|_| {
                env.sample_instance(&mut rng);
                env.toy_params().alpha
            })
            .collect();
        assert!(alphas.iter().all(|a| (-1.0..1.0).contains(a)));
        assert!(alphas.iter().any(|a| *a < -0.5) && alphas.iter().any(|a| *a > 0.5));
        let json = env.params();
        assert_eq!(json["squash"], "inner");
        assert_eq!(json["alpha"].as_f64(), Some(env.toy_params().alpha));
        let back: ToyParams = serde_json::from_value(json).unwrap();
        assert_eq!(back, env.toy_params());
    }

    #[test]
    fn planner_dynamics_are_the_noise_free_mean() {
        let env = instance(Squash::Inner, -0.4);
        let dynamics = env.dynamics().unwrap();
        let mut s = vec![0.3, 0.1];
        assert_eq!(dynamics.step(&mut s, &[0.2]), 0.0);
        assert_eq!(s, mean_step(&env.toy_params(), [0.3, 0.1], 0.2).to_vec());
    }

    #[test]
    fn variants_parse_and_bare_toy_is_explained() {
        assert_eq!(Squash::parse("outer").unwrap(), Squash::Outer);
        let err = Squash::parse("").unwrap_err().to_string();
        assert!(err.contains("toy:inner") && err.contains("toy:outer"), "{err}");
        let err = Squash::parse("middle").unwrap_err().to_string();
        assert!(err.contains("middle") && err.contains("inner"), "{err}");
    }
}
