//! A calibrated context model as a planner's dynamics: mean rollouts under the context mean β of the
//! calibration transitions, states mapped back from model space (cos/sin → angle) for the reward.

use super::fast::RolloutScratch;
use super::LoadedModel;
use crate::control::{par_candidate_blocks, BatchDynamics, RewardFn};
use crate::envs::pendulum::dynamics::{NominalPendulumReward, PendulumReward};
use crate::envs::EnvName;
use crate::error::{Error, Result};

const CANDIDATES_PER_BLOCK: usize = 64;

pub struct ContextDynamics {
    model: LoadedModel,
    beta: Vec<f32>,
    reward: Box<dyn RewardFn>,
    reward_name: String,
    context_size: usize,
}

/// The swing-up reward a planner on a learned pendulum model uses: gym's closed form where the variant has one,
/// else gym's cost of the commanded action per simulator step (see [`NominalPendulumReward`]).
pub fn planning_reward(env: &EnvName) -> Result<(Box<dyn RewardFn>, String)> {
    let EnvName::Pendulum(variant) = env else {
        return Err(Error::config(format!(
            "planning with a context model needs a task reward; supported: pendulum variants, not '{}'",
            env.canonical()
        )));
    };
    let params = variant.fixed_params();
    Ok(match PendulumReward::for_params(&params) {
        Some(r) => (Box::new(r), "gym pendulum reward".into()),
        None => (
            Box::new(NominalPendulumReward { max_torque: params.max_torque, action_repeat: params.action_repeat }),
            "gym pendulum cost of the commanded torque (nominal actuators)".into(),
        ),
    })
}

impl ContextDynamics {
    /// Conditions `model` on `context` (model-space rows [s, a, s']): β = the mean of q(β | context).
    pub fn new(model: LoadedModel, context: &[f32], env: &EnvName) -> Result<Self> {
        let (reward, reward_name) = planning_reward(env)?;
        let rows = context.len() / model.fast.transition_dim();
        let pooled = model.fast.pool(context);
        let beta = model.fast.belief(&pooled, 1).mean;
        Ok(ContextDynamics { model, beta, reward, reward_name, context_size: rows })
    }

    pub fn beta(&self) -> &[f32] {
        &self.beta
    }

    fn to_state(&self, features: &[f32], out: &mut [f64]) {
        let mut k = 0;
        for (slot, angular) in out.iter_mut().zip(&self.model.run.details.model.angular) {
            if *angular {
                *slot = (features[k + 1] as f64).atan2(features[k] as f64);
                k += 2;
            } else {
                *slot = features[k] as f64;
                k += 1;
            }
        }
    }
}

impl BatchDynamics for ContextDynamics {
    fn state_dim(&self) -> usize {
        self.model.run.details.model.angular.len()
    }

    fn action_dim(&self) -> usize {
        self.model.run.details.model.action_dim
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
        let fast = &self.model.fast;
        let (a, d, f) = (self.action_dim(), self.state_dim(), fast.state_dim);
        let per = horizon * a;
        let init_features = self.model.features(init);
        let run_block = |ret: &mut [f64], cands: &[f64], mut out_states: Option<&mut [f64]>| {
            let rows = ret.len();
            let actions32: Vec<f32> = cands.iter().map(|x| *x as f32).collect();
            let betas = self.beta.repeat(rows);
            let mut predicted = vec![0.0; rows * horizon * f];
            let mut scratch = RolloutScratch::default();
            fast.rollout_means(&init_features, &actions32, &betas, rows, horizon, None, &mut predicted, &mut scratch);
            let mut prev = vec![0.0; d];
            let mut next = vec![0.0; d];
            for r in 0..rows {
                prev.copy_from_slice(init);
                ret[r] = 0.0;
                for t in 0..horizon {
                    self.to_state(&predicted[(r * horizon + t) * f..(r * horizon + t + 1) * f], &mut next);
                    let action = &cands[r * per + t * a..r * per + (t + 1) * a];
                    ret[r] += self.reward.reward(&prev, action, &next);
                    if let Some(out) = out_states.as_deref_mut() {
                        out[(r * horizon + t) * d..(r * horizon + t + 1) * d].copy_from_slice(&next);
                    }
                    std::mem::swap(&mut prev, &mut next);
                }
            }
        };
        par_candidate_blocks(returns, actions, states, (per, horizon * d), CANDIDATES_PER_BLOCK, run_block);
    }

    fn describe(&self) -> String {
        format!(
            "context model {} conditioned on {} calibration transitions (context mean), planning reward: {}{}",
            self.model.dir.display(),
            self.context_size,
            self.reward_name,
            self.model.progress.unfinished_note()
        )
    }
}
