//! What one update consumes and reports.

use crate::error::{Error, Result};

/// `rows` transitions, row-major. Actions are in env units (as the env took them); the update maps them to the
/// networks' [−1, 1].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TransitionBatch {
    pub rows: usize,
    pub obs: Vec<f32>,
    pub actions: Vec<f32>,
    pub rewards: Vec<f32>,
    pub next_obs: Vec<f32>,
    /// 1.0 = do not bootstrap from `next_obs` (SEADS: symbolic change or timeout), 0.0 = bootstrap.
    pub done: Vec<f32>,
}

/// Figures of one update, for logging.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SacLosses {
    /// mean(α log π − min(Q1, Q2)) over the batch, with the critics as updated in the same call.
    pub actor: f64,
    /// MSE(Q1, y) + MSE(Q2, y), before the critic step (torch's `qf1_loss + qf2_loss`).
    pub critic: f64,
    /// Mean of Q1 and Q2 at the batch's (obs, action), before the critic step.
    pub mean_q: f64,
    /// −mean log π of the actions sampled for the actor loss (in the networks' [−1, 1] action space).
    pub entropy: f64,
}

impl TransitionBatch {
    /// Checks sizes and finiteness against the networks' dimensions.
    pub fn check(&self, obs_dim: usize, action_dim: usize) -> Result<()> {
        if self.rows == 0 {
            return Err(Error::data("sac update: the batch has no rows"));
        }
        let n = self.rows;
        let fields: [(&str, &[f32], usize); 5] = [
            ("obs", &self.obs, obs_dim),
            ("actions", &self.actions, action_dim),
            ("rewards", &self.rewards, 1),
            ("next_obs", &self.next_obs, obs_dim),
            ("done", &self.done, 1),
        ];
        for (name, values, width) in fields {
            if Some(values.len()) != n.checked_mul(width) {
                let found = format!("{} values", values.len());
                return Err(Error::bad_shape(format!("batch '{name}'"), found, format!("{n} rows × {width}"))
                    .field("sac update"));
            }
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(Error::data(format!(
                    "sac update: batch '{name}' has a non-finite value at row {}",
                    i / width
                )));
            }
        }
        Ok(())
    }
}
