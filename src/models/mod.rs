pub mod ball;
pub mod pets;

use std::path::Path;

use crate::envs::{BatchDynamics, EnvName};
use crate::error::{Error, Result};
use crate::train::OpenedCheckpoint;

/// How a stochastic learned model is rolled out by planners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RolloutOptions {
    pub propagation: pets::Propagation,
    pub particles: usize,
}

/// The methods whose checkpoints `plan` can plan with.
pub const PLANNING_METHODS: &str = "pets";

/// A trained model from its checkpoint directory, as dynamics for a planner in `env`. Which method made it is
/// read from the checkpoint, so callers never branch on methods.
pub fn load_planning_model(dir: &Path, env: &EnvName, options: RolloutOptions) -> Result<Box<dyn BatchDynamics>> {
    if dir.join("params.json").is_file() && !dir.join(crate::train::checkpoint::MANIFEST_FILE).exists() {
        return Err(Error::bad_file(
            dir,
            format!("is a ball EKF model, a filter without controls; use `mbrl filter`/`mbrl predict`. Planning supports: {PLANNING_METHODS}"),
        ));
    }
    let method = OpenedCheckpoint::open(dir)?.manifest.method;
    match method.as_str() {
        pets::METHOD => Ok(Box::new(pets::load_dynamics(dir, env, options.propagation, options.particles)?)),
        other => Err(Error::bad_file(
            dir,
            format!(
                "is a '{other}' checkpoint, which has no dynamics to plan with; planning supports: {PLANNING_METHODS}"
            ),
        )),
    }
}
