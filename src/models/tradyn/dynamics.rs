//! A TRADYN model conditioned on a context as a planner's dynamics: mean rollouts under the context mean β, in
//! the unicycle's state [x, y, v, φ], with the terrain read from the task's map at every predicted position
//! (+T) or predicted (−T).

use std::sync::Arc;

use super::{MapLookup, TradynModel};
use crate::control::{par_candidate_blocks, BatchDynamics};
use crate::envs::terrain::TerrainMap;
use crate::envs::unicycle::{clip_action, observation, MAX_SPEED};
use crate::models::context_net::fast::{LocalFeatures, RolloutScratch};

const CANDIDATES_PER_BLOCK: usize = 64;

pub struct TradynDynamics {
    model: TradynModel,
    map: Arc<TerrainMap>,
    lookup: MapLookup,
    beta: Vec<f32>,
    context_size: usize,
}

impl TradynDynamics {
    /// Conditions `model` on `context` (observation rows [o, a, o']; empty: the prior's mean) for a robot on `map`.
    pub fn new(model: TradynModel, map: Arc<TerrainMap>, context: &[f32]) -> Self {
        let fast = &model.loaded.fast;
        let context_size = context.len() / fast.transition_dim();
        let beta = fast.belief(&fast.pool(context), 1).mean;
        TradynDynamics { lookup: MapLookup(map.clone()), model, map, beta, context_size }
    }

    pub fn beta(&self) -> &[f32] {
        &self.beta
    }

    /// The model's predicted observations o_1..o_H of `rows` candidates (`rows × H × 8`).
    pub fn predict_observations(&self, init: &[f64], actions: &[f32], rows: usize, horizon: usize, out: &mut [f32]) {
        let fast = &self.model.loaded.fast;
        let start: Vec<f32> = observation(init, &self.map).iter().map(|x| *x as f32).collect();
        let betas = self.beta.repeat(rows);
        let lookup: Option<&dyn LocalFeatures> = if fast.local_dim > 0 { Some(&self.lookup) } else { None };
        fast.rollout_means(&start, actions, &betas, rows, horizon, lookup, out, &mut RolloutScratch::default());
    }
}

/// [x, y, v, φ] from a predicted observation [x, y, v/5, cos φ, sin φ, …].
fn state_of(o: &[f32], out: &mut [f64]) {
    out[0] = o[0] as f64;
    out[1] = o[1] as f64;
    out[2] = o[2] as f64 * MAX_SPEED;
    out[3] = (o[4] as f64).atan2(o[3] as f64);
}

impl BatchDynamics for TradynDynamics {
    fn state_dim(&self) -> usize {
        4
    }

    fn action_dim(&self) -> usize {
        2
    }

    fn rollout(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        _seed: u64,
        returns: &mut [f64],
        states: Option<&mut [f64]>,
    ) {
        let per = horizon * 2;
        let width = self.model.loaded.fast.state_dim;
        let run_block = |ret: &mut [f64], cands: &[f64], mut out_states: Option<&mut [f64]>| {
            let rows = ret.len();
            for (r, value) in ret.iter_mut().enumerate() {
                // The simulator's reward: the energy term of eq. 5.13 on the clipped throttle.
                *value = (0..horizon).map(|t| -0.5 * clip_action(cands[r * per + t * 2]).powi(2)).sum();
            }
            if let Some(out) = out_states.as_deref_mut() {
                let actions32: Vec<f32> = cands.iter().map(|x| *x as f32).collect();
                let mut predicted = vec![0.0; rows * horizon * width];
                self.predict_observations(init, &actions32, rows, horizon, &mut predicted);
                for (o, slot) in predicted.chunks(width).zip(out.chunks_mut(4)) {
                    state_of(o, slot);
                }
            }
        };
        par_candidate_blocks(returns, actions, states, (per, horizon * 4), CANDIDATES_PER_BLOCK, run_block);
    }

    fn describe(&self) -> String {
        format!(
            "TRADYN model {} ({}) conditioned on {} calibration transitions (context mean){}",
            self.model.loaded.dir.display(),
            self.model.variant_name(),
            self.context_size,
            self.model.loaded.progress.unfinished_note()
        )
    }
}
