//! What a planner rolls out: the batched-dynamics seam shared by the simulators' own equations and every
//! learned model.

use rayon::prelude::*;

use crate::envs::Dynamics;

/// What a planner rolls out: many candidate action sequences at once from one start state. Implemented by the
/// simulators' own equations (every [`Dynamics`]) and by learned models, which carry their own latent state
/// (ensemble member, particles, hidden state, context) inside `rollout`. The planner never knows which.
pub trait BatchDynamics: Sync + Send {
    fn state_dim(&self) -> usize;
    fn action_dim(&self) -> usize;

    /// Rolls out the candidates in `actions` (back to back, each `horizon × action_dim`) from `init`. Writes each
    /// candidate's return to `returns` and, when `states` is given, its predicted states s_1..s_H
    /// (`[candidate][t][state_dim]`); stochastic models average both over their particles. `seed` keys the
    /// model's own randomness, so the same call gives the same numbers on any thread count.
    fn rollout(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        seed: u64,
        returns: &mut [f64],
        states: Option<&mut [f64]>,
    );

    /// A short description for reports ("ground truth", "PETS ensemble …").
    fn describe(&self) -> String;
}

/// Splits a batch rollout into blocks of `block` candidates run in parallel: each call of `run` gets the blocks'
/// returns, action sequences (`per_actions` values per candidate) and, when asked for, predicted states
/// (`per_states` per candidate). Learned models roll a block out as one matrix batch.
pub fn par_candidate_blocks(
    returns: &mut [f64],
    actions: &[f64],
    states: Option<&mut [f64]>,
    (per_actions, per_states): (usize, usize),
    block: usize,
    run: impl Fn(&mut [f64], &[f64], Option<&mut [f64]>) + Sync,
) {
    let blocks = returns.par_chunks_mut(block).zip(actions.par_chunks(per_actions * block));
    match states {
        None => blocks.for_each(|(ret, cands)| run(ret, cands, None)),
        Some(states) => blocks
            .zip(states.par_chunks_mut(per_states * block))
            .for_each(|((ret, cands), out)| run(ret, cands, Some(out))),
    }
}

impl<T: Dynamics> BatchDynamics for T {
    fn state_dim(&self) -> usize {
        Dynamics::state_dim(self)
    }

    fn action_dim(&self) -> usize {
        Dynamics::action_dim(self)
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
        match states {
            None => self.rollout_returns(init, actions, horizon, returns),
            Some(states) => {
                let (a, d) = (Dynamics::action_dim(self), Dynamics::state_dim(self));
                let per_candidate = horizon * a;
                returns
                    .par_iter_mut()
                    .zip(actions.par_chunks(per_candidate))
                    .zip(states.par_chunks_mut(horizon * d))
                    .for_each(|((ret, seq), out)| {
                        let mut state = init.to_vec();
                        *ret = 0.0;
                        for (action, slot) in seq.chunks(a).zip(out.chunks_mut(d)) {
                            *ret += self.step(&mut state, action);
                            slot.copy_from_slice(&state);
                        }
                    });
            }
        }
    }

    fn describe(&self) -> String {
        "ground truth (the simulator's equations)".into()
    }
}
