//! Training data of the context model: per hidden-parameter instance a target rollout A and a context-source
//! rollout B, and the batches of appendix B.2.1 drawn from them (a 50-state chunk of A, a context set of
//! U{0..C_max} transitions drawn with replacement from A with probability p_ctx-from-A, else from B).

use rand::seq::SliceRandom;
use rand::Rng;
use rand_distr::StandardNormal;

use crate::data::Rollout;
use crate::error::{Error, Result};
use crate::nn::features::features;
use crate::util::seeding::rng_for;

/// One rollout in model space: states as features (angles as cos/sin), row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Episode {
    /// (len + 1) × state_dim.
    pub states: Vec<f32>,
    /// len × action_dim.
    pub actions: Vec<f32>,
    pub len: usize,
}

impl Episode {
    pub fn from_rollout(rollout: &Rollout, angular: &[bool]) -> Self {
        let mut states = Vec::new();
        for s in &rollout.states {
            features(s, &[], angular, &mut states);
        }
        let actions = rollout.actions.iter().flatten().map(|&a| a as f32).collect();
        Episode { states, actions, len: rollout.len() }
    }

    /// The rollout's observations as they are (TRADYN models the unicycle's observation, terrain included).
    pub fn from_observations(rollout: &Rollout) -> Self {
        let states = rollout.observations.iter().flatten().map(|&x| x as f32).collect();
        let actions = rollout.actions.iter().flatten().map(|&a| a as f32).collect();
        Episode { states, actions, len: rollout.len() }
    }

    /// Transition `t` as the context encoder reads it: [s_t, a_t, s_{t+1}].
    pub fn transition(&self, t: usize, state_dim: usize, action_dim: usize, out: &mut Vec<f32>) {
        out.extend_from_slice(&self.states[t * state_dim..(t + 1) * state_dim]);
        out.extend_from_slice(&self.actions[t * action_dim..(t + 1) * action_dim]);
        out.extend_from_slice(&self.states[(t + 1) * state_dim..(t + 2) * state_dim]);
    }
}

/// The target rollout A and the context-source rollout B of one instance.
#[derive(Clone, Debug, PartialEq)]
pub struct InstancePair {
    pub target: Episode,
    pub source: Episode,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ContextData {
    pub state_dim: usize,
    pub action_dim: usize,
    /// Trailing state features the model reads from the world instead of predicting (TRADYN's terrain).
    pub local_dim: usize,
    pub pairs: Vec<InstancePair>,
}

/// One training batch, row-major, plus the noise of its β samples.
#[derive(Clone, Debug)]
pub struct Batch {
    pub size: usize,
    /// States per chunk (N); the chunk has N − 1 transitions.
    pub chunk: usize,
    /// The states' trailing features that are model input, not prediction targets.
    pub local_dim: usize,
    /// [B, N, S].
    pub states: Vec<f32>,
    /// [B, N − 1, A].
    pub actions: Vec<f32>,
    /// The chunk's own transitions for the encoder: [B, N − 1, 2S + A].
    pub chunk_transitions: Vec<f32>,
    pub context_max: usize,
    /// [B, C_max, 2S + A]; rows past a set's size are zero and absent.
    pub context: Vec<f32>,
    /// [B, C_max].
    pub present: Vec<bool>,
    /// Standard normal noise of the sequence's one β sample: [B, D_β].
    pub noise_sequence: Vec<f32>,
    /// Fresh noise per single-step prediction: [B, N − 1, D_β].
    pub noise_single: Vec<f32>,
}

impl ContextData {
    pub fn transition_dim(&self) -> usize {
        2 * self.state_dim + self.action_dim
    }

    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// The chunk length the data allows: `wanted`, or fewer states when target rollouts are shorter.
    pub fn chunk_states(&self, wanted: usize) -> Result<usize> {
        let shortest = self.pairs.iter().map(|p| p.target.len + 1).min().unwrap_or(0);
        let chunk = wanted.min(shortest);
        if chunk < 3 {
            return Err(Error::data(format!(
                "target rollouts have {} transitions at the shortest; a training chunk needs at least 2",
                shortest.saturating_sub(1)
            )));
        }
        if self.pairs.iter().any(|p| p.source.len == 0) {
            return Err(Error::data("a context-source rollout has no transitions"));
        }
        Ok(chunk)
    }

    /// Splits whole instances (a seeded shuffle) into training and validation data.
    pub fn split(self, validation_fraction: f64, seed: u64) -> (ContextData, ContextData) {
        let mut order: Vec<usize> = (0..self.pairs.len()).collect();
        order.shuffle(&mut rng_for(seed, &[super::SPLIT_STREAM]));
        let n_valid = ((self.pairs.len() as f64 * validation_fraction).round() as usize).min(self.pairs.len() - 1);
        let mut valid_mask = vec![false; self.pairs.len()];
        order[..n_valid].iter().for_each(|&i| valid_mask[i] = true);
        let (mut train, mut valid) = (Vec::new(), Vec::new());
        for (pair, is_valid) in self.pairs.into_iter().zip(valid_mask) {
            if is_valid {
                valid.push(pair)
            } else {
                train.push(pair)
            }
        }
        let (s, a, l) = (self.state_dim, self.action_dim, self.local_dim);
        (
            ContextData { state_dim: s, action_dim: a, local_dim: l, pairs: train },
            ContextData { state_dim: s, action_dim: a, local_dim: l, pairs: valid },
        )
    }

    pub fn sample_batch<R: Rng>(
        &self,
        rng: &mut R,
        size: usize,
        chunk: usize,
        context_max: usize,
        from_target: f64,
        latent_dim: usize,
    ) -> Batch {
        let (s, a) = (self.state_dim, self.action_dim);
        let tdim = self.transition_dim();
        let transitions = chunk - 1;
        let mut batch = Batch {
            size,
            chunk,
            local_dim: self.local_dim,
            states: Vec::with_capacity(size * chunk * s),
            actions: Vec::with_capacity(size * transitions * a),
            chunk_transitions: Vec::with_capacity(size * transitions * tdim),
            context_max,
            context: Vec::with_capacity(size * context_max * tdim),
            present: Vec::with_capacity(size * context_max),
            noise_sequence: Vec::new(),
            noise_single: Vec::new(),
        };
        for _ in 0..size {
            let pair = &self.pairs[rng.random_range(0..self.pairs.len())];
            let target = &pair.target;
            let start = rng.random_range(0..=target.len + 1 - chunk);
            batch.states.extend_from_slice(&target.states[start * s..(start + chunk) * s]);
            batch.actions.extend_from_slice(&target.actions[start * a..(start + transitions) * a]);
            for t in start..start + transitions {
                target.transition(t, s, a, &mut batch.chunk_transitions);
            }
            let set_size = rng.random_range(0..=context_max);
            for k in 0..context_max {
                if k < set_size {
                    let episode = if rng.random_bool(from_target) { &pair.target } else { &pair.source };
                    episode.transition(rng.random_range(0..episode.len), s, a, &mut batch.context);
                    batch.present.push(true);
                } else {
                    batch.context.extend(std::iter::repeat_n(0.0, tdim));
                    batch.present.push(false);
                }
            }
        }
        batch.noise_sequence = (0..size * latent_dim).map(|_| rng.sample::<f32, _>(StandardNormal)).collect();
        batch.noise_single =
            (0..size * transitions * latent_dim).map(|_| rng.sample::<f32, _>(StandardNormal)).collect();
        batch
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn episode(offset: f32, len: usize) -> Episode {
        Episode {
            states: (0..=len).flat_map(|t| [offset + t as f32, -(t as f32)]).collect(),
            actions: (0..len).map(|t| offset + 0.5 + t as f32).collect(),
            len,
        }
    }

    #[test]
    fn batches_take_contiguous_chunks_and_contexts_from_the_right_rollout() {
        let data = ContextData {
            state_dim: 2,
            action_dim: 1,
            local_dim: 0,
            pairs: vec![InstancePair { target: episode(0.0, 20), source: episode(1000.0, 20) }],
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let b = data.sample_batch(&mut rng, 8, 5, 6, 0.0, 3);
        assert_eq!(b.states.len(), 8 * 5 * 2);
        for chunk in b.states.chunks(10) {
            for t in 1..5 {
                assert_eq!(chunk[2 * t], chunk[0] + t as f32, "chunks are contiguous");
            }
        }
        // p_ctx-from-A = 0: every context transition comes from the source rollout (states ≥ 1000).
        for (row, present) in b.context.chunks(5).zip(&b.present) {
            if *present {
                assert!(row[0] >= 1000.0 && row[3] == row[0] + 1.0 && row[2] == row[0] + 0.5, "{row:?}");
            } else {
                assert!(row.iter().all(|x| *x == 0.0));
            }
        }
        assert_eq!(b.noise_single.len(), 8 * 4 * 3);
        let from_a = data.sample_batch(&mut rng, 8, 5, 6, 1.0, 3);
        assert!(from_a.context.chunks(5).zip(&from_a.present).all(|(r, p)| !p || r[0] < 1000.0));
    }
}
