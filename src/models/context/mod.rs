//! Explore the Context (thesis chapter 4): a GRU dynamics model conditioned on a latent context β, a context
//! encoder that turns observed transitions into a belief q(β | C) whose variance never grows as transitions are
//! added, and calibration that picks actions by the expected information gain about β. The network and its
//! training are shared with TRADYN in `models::context_net`; this folder adds calibration and planning.

pub mod calibration;
pub mod dynamics;
pub mod eig;

use std::path::Path;

pub use crate::models::context_net::{
    check_details, config, data, family_of, fast, grad, instance_pairs, model_from, net, options, prepare_model, train,
    Context, ContextConfig, ContextDetails, ContextRun, ContextSummary, ContextTrainer, EnvFamily, FastContextModel,
    InstanceCounts, LoadedModel, ModelSpec, Preset, StateSpace, METHOD,
};

use crate::envs::EnvName;
use crate::error::Result;
use crate::train::{open_run, Accept};

/// A context model of `env`, finished or (with [`Accept::InProgress`]) still training: then its
/// best-validation weights so far.
pub fn load(dir: &Path, env: &EnvName, accept: Accept) -> Result<LoadedModel> {
    let (opened, run) = open_run::<Context>(dir, accept)?;
    model_from(&opened, run, env)
}

#[cfg(test)]
mod golden;
#[cfg(test)]
mod tests;
