//! A rollout in memory, and its flat form as a sequence of timestep messages.

use serde::{Deserialize, Serialize};

/// One transition as stored in a dataset (one MCAP message).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timestep {
    pub rollout: u32,
    pub t: u32,
    pub state: Vec<f64>,
    pub action: Vec<f64>,
    pub reward: f64,
    pub next_state: Vec<f64>,
    /// The observation before the step, for environments whose observation differs from the state.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obs: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub next_obs: Option<Vec<f64>>,
}

/// States s_0..s_T, actions a_0..a_{T−1}, rewards r_0..r_{T−1}, observations o_0..o_T.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Rollout {
    pub states: Vec<Vec<f64>>,
    pub actions: Vec<Vec<f64>>,
    pub rewards: Vec<f64>,
    pub observations: Vec<Vec<f64>>,
}

impl Rollout {
    pub fn start(state: Vec<f64>, obs: Vec<f64>) -> Self {
        Rollout { states: vec![state], observations: vec![obs], ..Default::default() }
    }

    pub fn push(&mut self, action: Vec<f64>, reward: f64, next_state: Vec<f64>, next_obs: Vec<f64>) {
        self.actions.push(action);
        self.rewards.push(reward);
        self.states.push(next_state);
        self.observations.push(next_obs);
    }

    pub fn len(&self) -> usize {
        self.actions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    /// The first step t whose outcome (reward, next state or observation) holds a non-finite number.
    pub fn first_non_finite_step(&self) -> Option<usize> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        (0..self.len()).find(|&t| {
            !(self.rewards[t].is_finite() && finite(&self.states[t + 1]) && finite(&self.observations[t + 1]))
        })
    }

    pub fn total_reward(&self) -> f64 {
        self.rewards.iter().sum()
    }

    pub fn timesteps(&self, rollout_id: u32) -> impl Iterator<Item = Timestep> + '_ {
        (0..self.len()).map(move |t| Timestep {
            rollout: rollout_id,
            t: t as u32,
            state: self.states[t].clone(),
            action: self.actions[t].clone(),
            reward: self.rewards[t],
            next_state: self.states[t + 1].clone(),
            obs: self.observations.get(t).cloned(),
            next_obs: self.observations.get(t + 1).cloned(),
        })
    }

    /// Rebuilds rollouts from timesteps sorted by (rollout, t). Returns `Err(position)` at the first
    /// timestep that does not continue its rollout (gap in t, or a state that does not match the previous
    /// next_state).
    pub fn group(steps: &[Timestep]) -> Result<Vec<(u32, Rollout)>, usize> {
        let mut out: Vec<(u32, Rollout)> = Vec::new();
        for (i, step) in steps.iter().enumerate() {
            let continues = matches!(out.last(), Some((id, r)) if *id == step.rollout);
            if continues {
                let (_, r) = out.last_mut().expect("checked above");
                if step.t as usize != r.len() || r.states.last() != Some(&step.state) {
                    return Err(i);
                }
            } else {
                if step.t != 0 {
                    return Err(i);
                }
                let mut r = Rollout::start(step.state.clone(), step.obs.clone().unwrap_or_default());
                r.observations.retain(|o| !o.is_empty());
                out.push((step.rollout, r));
            }
            let (_, r) = out.last_mut().expect("pushed above");
            r.actions.push(step.action.clone());
            r.rewards.push(step.reward);
            r.states.push(step.next_state.clone());
            if let Some(o) = &step.next_obs {
                r.observations.push(o.clone());
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Rollout {
        let mut r = Rollout::start(vec![0.0, 1.0], vec![1.0]);
        r.push(vec![0.5], -1.0, vec![0.1, 1.1], vec![2.0]);
        r.push(vec![-0.5], -2.0, vec![0.2, 1.2], vec![3.0]);
        r
    }

    #[test]
    fn the_first_step_with_a_non_finite_outcome_is_found() {
        let mut r = sample();
        assert_eq!(r.first_non_finite_step(), None);
        r.push(vec![0.0], 0.0, vec![f64::NAN, 0.0], vec![0.0]);
        r.push(vec![0.0], f64::INFINITY, vec![0.0, 0.0], vec![0.0]);
        assert_eq!(r.first_non_finite_step(), Some(2));
        r.observations[2][0] = f64::NEG_INFINITY;
        assert_eq!(r.first_non_finite_step(), Some(1));
    }

    #[test]
    fn timesteps_round_trip_through_group() {
        let r = sample();
        let steps: Vec<Timestep> = r.timesteps(4).collect();
        assert_eq!(steps.len(), 2);
        assert_eq!(steps[1].state, vec![0.1, 1.1]);
        let grouped = Rollout::group(&steps).unwrap();
        assert_eq!(grouped, vec![(4, r)]);
    }

    #[test]
    fn group_reports_broken_continuity() {
        let mut steps: Vec<Timestep> = sample().timesteps(0).collect();
        steps[1].state = vec![9.0, 9.0];
        assert_eq!(Rollout::group(&steps), Err(1));
    }
}
