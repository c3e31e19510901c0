//! The trained ensemble as a planner's [`BatchDynamics`]: particles propagated with trajectory sampling
//! (Chua et al. 2018) on the fast f32 inference path.

use rand::Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::config::{PetsConfig, RewardSource};
use crate::control::{BatchDynamics, RewardFn};
use crate::error::{Error, Result};
use crate::nn::activation::{fast_exp, fast_softplus};
use crate::nn::fast::{FastEnsembleMlp, Scratch};
use crate::nn::features::{feature_dim, features};
use crate::nn::{Normalizer, ParamSet};
use crate::util::seeding::rng_for;

/// Candidates whose particles one task propagates; fixed, so the random streams (one per block) and hence the
/// plans do not depend on the thread count.
const CANDIDATES_PER_BLOCK: usize = 64;

/// How particles pick ensemble members.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Propagation {
    /// TS-1: every particle draws a member anew at every step.
    Ts1,
    /// TS-∞: every particle keeps one member for the whole horizon (particle p uses member p mod E).
    TsInf,
    /// No sampling: each member's mean prediction, one particle per member.
    Expectation,
}

impl std::str::FromStr for Propagation {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "ts1" => Ok(Propagation::Ts1),
            "tsinf" => Ok(Propagation::TsInf),
            "expectation" => Ok(Propagation::Expectation),
            _ => Err(Error::config(format!(
                "unknown propagation '{s}'{}; supported: ts1, tsinf, expectation",
                crate::util::suggest::did_you_mean(s, ["ts1", "tsinf", "expectation"])
            ))),
        }
    }
}

impl Propagation {
    pub fn name(self) -> &'static str {
        match self {
            Propagation::Ts1 => "TS-1",
            Propagation::TsInf => "TS-∞",
            Propagation::Expectation => "expectation",
        }
    }
}

pub struct PetsDynamics {
    net: FastEnsembleMlp,
    normalizer: Normalizer,
    /// Soft bounds of the log-variance, [out].
    min_logvar: Vec<f32>,
    max_logvar: Vec<f32>,
    angular: Vec<bool>,
    action_dim: usize,
    reward: Option<Box<dyn RewardFn>>,
    propagation: Propagation,
    particles: usize,
    label: String,
}

impl PetsDynamics {
    /// Appends to the one-line description (how far training went, for a run still in progress).
    pub fn with_note(mut self, note: &str) -> Self {
        self.label.push_str(note);
        self
    }

    /// From a checkpoint's weights. `reward` is the env's closed-form reward when the model was trained with
    /// `reward = known` (it must then be given).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        config: &PetsConfig,
        weights: &ParamSet,
        normalizer: Normalizer,
        angular: Vec<bool>,
        action_dim: usize,
        reward: Option<Box<dyn RewardFn>>,
        propagation: Propagation,
        particles: usize,
    ) -> Result<Self> {
        normalizer.validate()?;
        let state_dim = angular.len();
        let out_dim = state_dim + usize::from(config.reward == RewardSource::Learned);
        if config.reward == RewardSource::Known && reward.is_none() {
            return Err(Error::config("this model was trained without a reward head; the env must provide its reward"));
        }
        let mut layers = Vec::new();
        for i in 0..config.hidden_layers {
            layers.push(format!("hidden_layers.{i}.0.weight"));
            layers.push(format!("hidden_layers.{i}.0.bias"));
        }
        layers.push("mean_and_logvar.weight".into());
        layers.push("mean_and_logvar.bias".into());
        let tensors = layers
            .iter()
            .map(|name| weights.get(name).ok_or_else(|| Error::config(format!("weights lack '{name}'"))))
            .collect::<Result<Vec<_>>>()?;
        let net = FastEnsembleMlp::from_tensors(&tensors, config.activation)?;
        let bound = |name: &str| -> Result<Vec<f32>> {
            let t = weights.get(name).ok_or_else(|| Error::config(format!("weights lack '{name}'")))?;
            if t.values.len() != out_dim {
                return Err(Error::config(format!("'{name}' has {} values; expected {out_dim}", t.values.len())));
            }
            Ok(t.values.clone())
        };
        let (min_logvar, max_logvar) = (bound("min_logvar")?, bound("max_logvar")?);
        let din = feature_dim(&angular, action_dim);
        if net.d_input() != din
            || net.d_output() != 2 * out_dim
            || normalizer.dim() != din
            || net.members() != config.ensemble
        {
            return Err(Error::config(format!(
                "weights take {} inputs and give {} outputs for {} members; this env and config need {din}, {} and {}",
                net.d_input(),
                net.d_output(),
                net.members(),
                2 * out_dim,
                config.ensemble
            )));
        }
        let particles = if propagation == Propagation::Expectation { config.ensemble } else { particles };
        if particles == 0 || particles > 10_000 {
            return Err(Error::config(format!("particles must be 1..=10000, got {particles}")));
        }
        let label = format!(
            "PETS ensemble of {} ({}×{} {}), {} with {particles} particles",
            config.ensemble,
            config.hidden_layers,
            config.hidden_units,
            config.activation.name(),
            propagation.name()
        );
        Ok(PetsDynamics {
            net,
            normalizer,
            min_logvar,
            max_logvar,
            angular,
            action_dim,
            reward,
            propagation,
            particles,
            label,
        })
    }

    fn members(&self) -> usize {
        self.net.members()
    }

    /// Rolls out one block of candidates; `returns` and `states` are the block's slices.
    #[allow(clippy::too_many_arguments)]
    fn rollout_block(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        seed: u64,
        block: usize,
        returns: &mut [f64],
        mut states: Option<&mut [f64]>,
    ) {
        let (sd, ad, p, e) = (self.angular.len(), self.action_dim, self.particles, self.members());
        let candidates = returns.len();
        let rows = candidates * p;
        let din = self.normalizer.dim();
        let dout = self.net.d_output() / 2;
        let mut rng = rng_for(seed, &[block as u64]);
        let mut state: Vec<f64> = init.iter().copied().cycle().take(rows * sd).collect();
        let mut row_return = vec![0.0f64; rows];
        let mut member_of: Vec<usize> = (0..rows).map(|r| (r % p) % e).collect();
        let mut scratch = Scratch::default();
        let mut input = Vec::with_capacity(rows * din);
        let mut output = vec![0.0f32; rows * 2 * dout];
        let mut next = vec![0.0f64; sd];
        let mut member_rows: Vec<Vec<usize>> = vec![Vec::new(); e];
        let (mut gathered_in, mut gathered_out) = (Vec::new(), Vec::new());
        for t in 0..horizon {
            if self.propagation == Propagation::Ts1 {
                member_of.iter_mut().for_each(|m| *m = rng.random_range(0..e));
            }
            member_rows.iter_mut().for_each(Vec::clear);
            for (r, m) in member_of.iter().enumerate() {
                member_rows[*m].push(r);
            }
            input.clear();
            for r in 0..rows {
                let c = r / p;
                let action = &actions[(c * horizon + t) * ad..(c * horizon + t + 1) * ad];
                features(&state[r * sd..(r + 1) * sd], action, &self.angular, &mut input);
            }
            self.normalizer.apply(&mut input);
            for (m, rows_of_m) in member_rows.iter().enumerate() {
                if rows_of_m.is_empty() {
                    continue;
                }
                gathered_in.clear();
                for &r in rows_of_m {
                    gathered_in.extend_from_slice(&input[r * din..(r + 1) * din]);
                }
                gathered_out.resize(rows_of_m.len() * 2 * dout, 0.0);
                self.net.forward(m, &gathered_in, rows_of_m.len(), &mut gathered_out, &mut scratch);
                for (k, &r) in rows_of_m.iter().enumerate() {
                    output[r * 2 * dout..(r + 1) * 2 * dout]
                        .copy_from_slice(&gathered_out[k * 2 * dout..(k + 1) * 2 * dout]);
                }
            }
            for r in 0..rows {
                let c = r / p;
                let action = &actions[(c * horizon + t) * ad..(c * horizon + t + 1) * ad];
                let out = &output[r * 2 * dout..(r + 1) * 2 * dout];
                let s = &state[r * sd..(r + 1) * sd];
                for j in 0..sd {
                    let mut delta = out[j] as f64;
                    if self.propagation != Propagation::Expectation {
                        let z: f64 = rng.sample(StandardNormal);
                        delta += self.predicted_std(j, out[dout + j]) * z;
                    }
                    next[j] = s[j] + delta;
                }
                row_return[r] += match &self.reward {
                    Some(reward) => reward.reward(s, action, &next),
                    None => out[sd] as f64,
                };
                state[r * sd..(r + 1) * sd].copy_from_slice(&next);
            }
            if let Some(states) = states.as_deref_mut() {
                for c in 0..candidates {
                    let slot = &mut states[(c * horizon + t) * sd..(c * horizon + t + 1) * sd];
                    slot.iter_mut().for_each(|x| *x = 0.0);
                    for r in c * p..(c + 1) * p {
                        for j in 0..sd {
                            slot[j] += state[r * sd + j] / p as f64;
                        }
                    }
                }
            }
        }
        for (c, ret) in returns.iter_mut().enumerate() {
            *ret = row_return[c * p..(c + 1) * p].iter().sum::<f64>() / p as f64;
        }
    }

    /// The standard deviation the member predicts for output `j`: the soft log-variance bounds, as in training,
    /// in f32 without libm calls (this runs for every particle, step and dimension).
    fn predicted_std(&self, j: usize, raw_logvar: f32) -> f64 {
        let (lo, hi) = (self.min_logvar[j], self.max_logvar[j]);
        let upper = hi - fast_softplus(hi - raw_logvar);
        let logvar = lo + fast_softplus(upper - lo);
        fast_exp(0.5 * logvar) as f64
    }
}

impl BatchDynamics for PetsDynamics {
    fn state_dim(&self) -> usize {
        self.angular.len()
    }

    fn action_dim(&self) -> usize {
        self.action_dim
    }

    fn rollout(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        seed: u64,
        returns: &mut [f64],
        states: Option<&mut [f64]>,
    ) {
        let per_candidate = horizon * self.action_dim;
        let sd = self.angular.len();
        let blocks =
            returns.par_chunks_mut(CANDIDATES_PER_BLOCK).zip(actions.par_chunks(per_candidate * CANDIDATES_PER_BLOCK));
        match states {
            None => blocks.enumerate().for_each(|(block, (ret, acts))| {
                self.rollout_block(init, acts, horizon, seed, block, ret, None);
            }),
            Some(states) => blocks
                .zip(states.par_chunks_mut(horizon * sd * CANDIDATES_PER_BLOCK))
                .enumerate()
                .for_each(|(block, ((ret, acts), st))| {
                    self.rollout_block(init, acts, horizon, seed, block, ret, Some(st));
                }),
        }
    }

    fn describe(&self) -> String {
        self.label.clone()
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::envs::pendulum::dynamics::PendulumReward;
    use crate::models::pets::config::Preset;
    use crate::models::pets::net::{torch_name, PetsNet};
    use crate::nn::tensor::inference_device;

    fn model(propagation: Propagation) -> PetsDynamics {
        let mut config = PetsConfig::preset(Preset::Small);
        config.hidden_units = 8;
        let net = PetsNet::init(&config, 4, 2, &inference_device(), &mut ChaCha8Rng::seed_from_u64(1));
        let weights = ParamSet::<f32>::from_module(&net, torch_name);
        let reward = Box::new(PendulumReward { max_torque: 2.0 });
        PetsDynamics::new(
            &config,
            &weights,
            Normalizer::identity(4),
            vec![true, false],
            1,
            Some(reward),
            propagation,
            6,
        )
        .unwrap()
    }

    fn returns(m: &PetsDynamics, seed: u64, threads: usize) -> Vec<f64> {
        let actions: Vec<f64> = (0..100 * 7).map(|k| ((k as f64) * 0.37).sin() * 2.0).collect();
        let mut out = vec![0.0; 100];
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| m.rollout(&[3.0, 0.1], &actions, 7, seed, &mut out, None));
        out
    }

    #[test]
    fn rollouts_depend_on_the_seed_and_not_on_the_thread_count() {
        for propagation in [Propagation::Ts1, Propagation::TsInf] {
            let m = model(propagation);
            assert_eq!(returns(&m, 4, 1), returns(&m, 4, 3), "{propagation:?}");
            assert_ne!(returns(&m, 4, 2), returns(&m, 5, 2), "{propagation:?}: particles must be sampled");
        }
        let mean = model(Propagation::Expectation);
        assert_eq!(returns(&mean, 4, 2), returns(&mean, 5, 2), "expectation draws nothing");
    }

    #[test]
    fn predicted_states_average_the_particles_and_returns_match_without_them() {
        let m = model(Propagation::TsInf);
        let actions = vec![0.5; 3 * 4];
        let (mut a, mut b) = (vec![0.0; 3], vec![0.0; 3]);
        let mut states = vec![0.0; 3 * 4 * 2];
        m.rollout(&[1.0, 0.0], &actions, 4, 9, &mut a, Some(&mut states));
        m.rollout(&[1.0, 0.0], &actions, 4, 9, &mut b, None);
        assert_eq!(a, b);
        assert!(states.iter().all(|x| x.is_finite()) && states[0] != 1.0);
        assert!(a.iter().all(|r| r.is_finite() && *r < 0.0));
    }
}
