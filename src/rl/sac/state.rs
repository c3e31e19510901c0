//! What SAC saves. Weights: the actor and the twin critic under their PyTorch names (`policy.*`, `critic.*`).
//! Training state for a byte-identical resume: `live.<name>` for actor, critic and target critic
//! (`critic_target.*`), `adam.exp_avg.<name>` and `adam.exp_avg_sq.<name>` for actor and critic,
//! `adam.step.policy`, `adam.step.critic` and `updates` (f64, one value each). The caller's RNG is not here.

use super::agent::Sac;
use crate::error::{Error, Result};
use crate::nn::ParamSet;
use crate::train::tensors::{StoredTensor, TensorData};

const POLICY_STEP: &str = "adam.step.policy";
const CRITIC_STEP: &str = "adam.step.critic";
const UPDATES: &str = "updates";

fn f32_tensor(t: &crate::nn::NamedTensor, name: String) -> StoredTensor {
    StoredTensor::f32(name, t.shape.clone(), t.values.clone())
}

/// The f32 values of tensor `name` with exactly `n` finite values.
fn lookup(stored: &[StoredTensor], name: &str, n: usize, what: &str) -> Result<Vec<f32>> {
    let found = stored
        .iter()
        .find(|t| t.name == name)
        .ok_or_else(|| Error::config(format!("{what}: lacks the tensor '{name}'")))?;
    let TensorData::F32(values) = &found.data else {
        return Err(Error::config(format!("{what}: tensor '{name}' is not f32")));
    };
    if values.len() != n || found.shape.iter().product::<usize>() != n {
        return Err(Error::config(format!(
            "{what}: tensor '{name}' has shape {:?} ({} values), expected {n} values",
            found.shape,
            values.len()
        )));
    }
    if values.iter().any(|x| !x.is_finite()) {
        return Err(Error::config(format!("{what}: tensor '{name}' contains NaN or infinite values")));
    }
    Ok(values.clone())
}

fn counter(stored: &[StoredTensor], name: &str, what: &str) -> Result<u64> {
    match stored.iter().find(|t| t.name == name).map(|t| &t.data) {
        Some(TensorData::F64(v)) if v.len() == 1 && v[0] >= 0.0 && v[0].fract() == 0.0 && v[0] < 2f64.powi(53) => {
            Ok(v[0] as u64)
        }
        _ => Err(Error::config(format!("{what}: lacks a valid counter '{name}' (one non-negative whole f64)"))),
    }
}

/// `params` with every tensor's values replaced from `stored` under `prefix + name`.
fn filled(params: &ParamSet, stored: &[StoredTensor], prefix: &str, what: &str) -> Result<ParamSet> {
    let mut out = params.clone();
    for t in &mut out.tensors {
        t.values = lookup(stored, &format!("{prefix}{}", t.name), t.values.len(), what)?;
    }
    Ok(out)
}

fn moments(params: &ParamSet, stored: &[StoredTensor], kind: &str, what: &str) -> Result<Vec<Vec<f32>>> {
    Ok(filled(params, stored, &format!("adam.{kind}."), what)?.tensors.into_iter().map(|t| t.values).collect())
}

fn check_count(stored: &[StoredTensor], expected: usize, what: &str) -> Result<()> {
    if stored.len() != expected {
        return Err(Error::config(format!("{what}: {} tensors, this agent has {expected}", stored.len())));
    }
    Ok(())
}

impl Sac {
    /// The actor and the twin critic, named like the reference `policy.state_dict()` and
    /// `critic.state_dict()` under `policy.` and `critic.`.
    pub fn weights(&self) -> Vec<StoredTensor> {
        self.policy_params
            .tensors
            .iter()
            .chain(&self.critic_params.tensors)
            .map(|t| f32_tensor(t, t.name.clone()))
            .collect()
    }

    /// Everything a byte-identical resume needs except the caller's RNG.
    pub fn state(&self) -> Vec<StoredTensor> {
        let mut out = Vec::new();
        for (params, adam) in [(&self.policy_params, &self.policy_adam), (&self.critic_params, &self.critic_adam)] {
            for (k, t) in params.tensors.iter().enumerate() {
                out.push(f32_tensor(t, format!("live.{}", t.name)));
                out.push(StoredTensor::f32(
                    format!("adam.exp_avg.{}", t.name),
                    t.shape.clone(),
                    adam.exp_avg[k].clone(),
                ));
                out.push(StoredTensor::f32(
                    format!("adam.exp_avg_sq.{}", t.name),
                    t.shape.clone(),
                    adam.exp_avg_sq[k].clone(),
                ));
            }
        }
        out.extend(self.target_params.tensors.iter().map(|t| f32_tensor(t, format!("live.{}", t.name))));
        out.push(StoredTensor::f64(POLICY_STEP, vec![1], vec![self.policy_adam.step as f64]));
        out.push(StoredTensor::f64(CRITIC_STEP, vec![1], vec![self.critic_adam.step as f64]));
        out.push(StoredTensor::f64(UPDATES, vec![1], vec![self.updates as f64]));
        out
    }

    /// Puts a `state()` back. Everything is checked before anything changes, so an error leaves the agent as
    /// it was.
    pub fn restore(&mut self, state: &[StoredTensor]) -> Result<()> {
        let what = "sac training state";
        let (np, nc) = (self.policy_params.len(), self.critic_params.len());
        check_count(state, 3 * np + 4 * nc + 3, what)?;
        let policy = filled(&self.policy_params, state, "live.", what)?;
        let critic = filled(&self.critic_params, state, "live.", what)?;
        let target = filled(&self.target_params, state, "live.", what)?;
        let policy_m = moments(&self.policy_params, state, "exp_avg", what)?;
        let policy_v = moments(&self.policy_params, state, "exp_avg_sq", what)?;
        let critic_m = moments(&self.critic_params, state, "exp_avg", what)?;
        let critic_v = moments(&self.critic_params, state, "exp_avg_sq", what)?;
        let policy_step = counter(state, POLICY_STEP, what)?;
        let critic_step = counter(state, CRITIC_STEP, what)?;
        let updates = counter(state, UPDATES, what)?;
        (self.policy_params, self.critic_params, self.target_params) = (policy, critic, target);
        (self.policy_adam.exp_avg, self.policy_adam.exp_avg_sq, self.policy_adam.step) =
            (policy_m, policy_v, policy_step);
        (self.critic_adam.exp_avg, self.critic_adam.exp_avg_sq, self.critic_adam.step) =
            (critic_m, critic_v, critic_step);
        self.updates = updates;
        self.load_policy()?;
        self.load_targets()
    }

    /// Replaces actor and critics by `weights` (the `weights()` layout); the targets become the critic's copy.
    pub(super) fn load_weights(&mut self, weights: &[StoredTensor]) -> Result<()> {
        let what = "sac weights";
        check_count(weights, self.policy_params.len() + self.critic_params.len(), what)?;
        let policy = filled(&self.policy_params, weights, "", what)?;
        let critic = filled(&self.critic_params, weights, "", what)?;
        self.target_params = super::agent::renamed(&critic, super::networks::CRITIC, super::networks::CRITIC_TARGET);
        (self.policy_params, self.critic_params) = (policy, critic);
        self.load_policy()?;
        self.load_targets()
    }
}
