//! The expected information gain of eq. 4.34 as a planning objective: for each candidate action sequence,
//! imagine mean rollouts under β samples from the current belief (one β per rollout, held over the horizon),
//! chop them into transitions, add them to the observed ones and measure the entropy of the resulting belief.
//! H[q(β | T₀)] is the same for every candidate, so minimizing the mean posterior entropy maximizes the EIG.

use rand::Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

use super::fast::{FastContextModel, RolloutScratch};
use crate::control::Objective;
use crate::util::seeding::rng_for;

/// Candidates one worker rolls out together (times the β samples = rows per GEMM). Fixed, so results do not
/// depend on the thread count.
const CANDIDATES_PER_BLOCK: usize = 16;

pub struct EigObjective<'a> {
    model: &'a FastContextModel,
    /// The current state in model space.
    init: Vec<f32>,
    /// Pooled features of the transitions observed so far (zero when none).
    base_pool: Vec<f32>,
    /// β samples from q(β | T₀), [samples, D_β].
    betas: Vec<f32>,
    samples: usize,
}

impl<'a> EigObjective<'a> {
    /// `samples` draws of β from the belief given `base_pool`, keyed by `seed` (the same draws for every
    /// candidate and CEM iteration: common random numbers make candidates comparable).
    pub fn new(model: &'a FastContextModel, init: Vec<f32>, base_pool: Vec<f32>, samples: usize, seed: u64) -> Self {
        let belief = model.belief(&base_pool, 1);
        let mut rng = rng_for(seed, &[]);
        let betas: Vec<f32> = (0..samples)
            .flat_map(|_| {
                belief
                    .mean
                    .iter()
                    .zip(&belief.std)
                    .map(|(m, s)| m + s * rng.sample::<f32, _>(StandardNormal))
                    .collect::<Vec<_>>()
            })
            .collect();
        Self::from_samples(model, init, base_pool, betas)
    }

    /// The objective under given β samples (`betas`, [samples, D_β]).
    pub fn from_samples(model: &'a FastContextModel, init: Vec<f32>, base_pool: Vec<f32>, betas: Vec<f32>) -> Self {
        let samples = betas.len() / model.latent_dim;
        EigObjective { model, init, base_pool, betas, samples }
    }

    /// Mean entropy of the posterior belief after each candidate's imagined rollouts.
    pub fn posterior_entropies(&self, candidates: &[f64], horizon: usize, out: &mut [f64]) {
        let (a, s, k) = (self.model.action_dim, self.model.state_dim, self.samples);
        let per = horizon * a;
        out.par_chunks_mut(CANDIDATES_PER_BLOCK).zip(candidates.par_chunks(per * CANDIDATES_PER_BLOCK)).for_each(
            |(out_block, cand_block)| {
                let n = out_block.len();
                let rows = n * k;
                // Row r = candidate r / k under β sample r % k.
                let mut actions = Vec::with_capacity(rows * per);
                let mut betas = Vec::with_capacity(rows * self.model.latent_dim);
                for cand in cand_block.chunks(per) {
                    for beta in self.betas.chunks(self.model.latent_dim) {
                        actions.extend(cand.iter().map(|x| *x as f32));
                        betas.extend_from_slice(beta);
                    }
                }
                let mut scratch = RolloutScratch::default();
                let mut states = vec![0.0; rows * horizon * s];
                self.model.rollout_means(&self.init, &actions, &betas, rows, horizon, None, &mut states, &mut scratch);
                let mut entropies = vec![0.0; rows];
                self.model.entropy_after(
                    &self.base_pool,
                    &self.init,
                    &actions,
                    &states,
                    rows,
                    horizon,
                    &mut entropies,
                    &mut scratch,
                );
                for (o, e) in out_block.iter_mut().zip(entropies.chunks(k)) {
                    *o = e.iter().sum::<f64>() / k as f64;
                }
            },
        );
    }
}

impl Objective for EigObjective<'_> {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
        self.posterior_entropies(candidates, horizon, costs);
    }
}
