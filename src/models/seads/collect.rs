//! Collecting skill episodes: every episode starts from a fresh reset (a board from the pool, the manipulator
//! reset) and runs one skill until the board changes or the step limit. A batch of episodes runs in lockstep so
//! the policy sees all active episodes as one batch of rows per control step.

use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::boards::BoardPool;
use super::memory::{Episode, ObsLayout};
use crate::envs::boards::BoardGame;
use crate::envs::embodiments::embodied::EmbodiedBoard;
use crate::envs::embodiments::{BoardLayout, Embodiment};
use crate::envs::Env;
use crate::error::Result;

/// The policy input: observation ⊕ onehot(k).
pub fn policy_input(obs: &[f32], skill: usize, skills: usize, out: &mut Vec<f32>) {
    out.extend_from_slice(obs);
    out.extend((0..skills).map(|j| if j == skill { 1.0 } else { 0.0 }));
}

pub struct Collector<G: BoardGame> {
    envs: Vec<EmbodiedBoard<G>>,
    pub layout: ObsLayout,
    pub skills: usize,
    /// Step the batch's envs on rayon's threads. Only for a simulator whose step outweighs the hand-off (the
    /// Jaco's millisecond of MuJoCo; a Cursor step is nanoseconds). The envs share nothing and draw nothing
    /// while stepping, so the bytes do not depend on the thread count.
    step_in_parallel: bool,
}

impl<G: BoardGame> Collector<G> {
    pub fn new(game: &G, embodiment: Embodiment, parallel: usize, skills: usize) -> Result<Self> {
        let board = BoardLayout::of(game);
        let envs: Vec<EmbodiedBoard<G>> = (0..parallel.max(1))
            .map(|_| Ok(EmbodiedBoard::new(game.clone(), embodiment.build(&board)?.0, game.goal())))
            .collect::<Result<_>>()?;
        let spec = envs[0].spec();
        let bits = game.symbolic(game.goal()).len();
        let obs_dim = spec.obs_names.len();
        // The observation is manipulator ⊕ board ⊕ remaining time.
        let layout = ObsLayout { obs_dim, action_dim: spec.action_low.len(), bits_offset: obs_dim - 1 - bits, bits };
        let step_in_parallel = embodiment == Embodiment::Jaco;
        Ok(Collector { envs, layout, skills, step_in_parallel })
    }

    pub fn step_limit(&self) -> usize {
        self.envs[0].manipulator().skill_step_limit()
    }

    /// One episode per label, each from a board of `pool` (or the given boards), actions from `policy` (rows of
    /// [`policy_input`] → rows of actions in env units).
    pub fn collect(
        &mut self,
        labels: &[usize],
        starts: Starts<'_, G>,
        rng: &mut ChaCha8Rng,
        mut policy: impl FnMut(&[f32], usize, &mut ChaCha8Rng) -> Vec<f32>,
    ) -> Vec<Episode> {
        let mut done = Vec::with_capacity(labels.len());
        for (chunk_index, chunk) in labels.chunks(self.envs.len()).enumerate() {
            let mut running: Vec<Episode> = Vec::with_capacity(chunk.len());
            for (slot, &label) in chunk.iter().enumerate() {
                let board = match &starts {
                    Starts::Pool(pool) => pool.sample(rng),
                    Starts::Boards(boards) => boards[chunk_index * self.envs.len() + slot],
                };
                let env = &mut self.envs[slot];
                env.set_board(board);
                let obs = env.reset(rng);
                running.push(Episode {
                    label,
                    obs: obs.iter().map(|&x| x as f32).collect(),
                    actions: Vec::new(),
                    performed: None,
                });
            }
            let mut active: Vec<usize> = (0..chunk.len()).collect();
            let mut inputs = Vec::new();
            while !active.is_empty() {
                inputs.clear();
                for &slot in &active {
                    let episode = &running[slot];
                    let last = &episode.obs[episode.obs.len() - self.layout.obs_dim..];
                    policy_input(last, episode.label, self.skills, &mut inputs);
                }
                let actions = policy(&inputs, active.len(), rng);
                let a = self.layout.action_dim;
                let mut slot_actions: Vec<Option<Vec<f64>>> = vec![None; chunk.len()];
                for (row, &slot) in active.iter().enumerate() {
                    slot_actions[slot] = Some(actions[row * a..(row + 1) * a].iter().map(|&x| x as f64).collect());
                }
                let step_one = |(env, action): (&mut EmbodiedBoard<G>, &Option<Vec<f64>>)| {
                    action.as_ref().map(|action| {
                        let before = env.board();
                        let step = env.step(action);
                        let performed = (env.board() != before)
                            .then(|| (0..env.game().num_moves()).find(|&m| env.game().apply(before, m) == env.board()));
                        (step, performed)
                    })
                };
                let envs = &mut self.envs[..chunk.len()];
                let outcomes: Vec<_> = if self.step_in_parallel {
                    envs.par_iter_mut().zip(slot_actions.par_iter()).map(step_one).collect()
                } else {
                    envs.iter_mut().zip(slot_actions.iter()).map(step_one).collect()
                };
                let mut still = Vec::with_capacity(active.len());
                for (slot, (outcome, action)) in outcomes.into_iter().zip(&slot_actions).enumerate() {
                    let (Some((step, performed)), Some(action)) = (outcome, action) else { continue };
                    let episode = &mut running[slot];
                    episode.actions.extend(action.iter().map(|&x| x as f32));
                    episode.obs.extend(step.obs.iter().map(|&x| x as f32));
                    if let Some(performed) = performed {
                        episode.performed = performed;
                    }
                    if !step.done {
                        still.push(slot);
                    }
                }
                active = still;
            }
            done.extend(running);
        }
        done
    }
}

/// Where episodes start.
pub enum Starts<'a, G: BoardGame> {
    /// A fresh board from the pool for every episode.
    Pool(&'a BoardPool<G>),
    /// These boards, one per label.
    Boards(&'a [G::State]),
}

impl<G: BoardGame> Collector<G> {
    pub fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let spec = self.envs[0].spec();
        (spec.action_low, spec.action_high)
    }
}
