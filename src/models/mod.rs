pub mod ball;
pub mod context;
pub mod context_net;
pub mod dlgpd;
pub mod gp;
pub mod pets;
pub mod registry;
pub mod seads;
pub mod tradyn;

use std::path::Path;

use crate::control::BatchDynamics;
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::train::OpenedCheckpoint;

/// How a stochastic learned model is rolled out by planners.
#[derive(Clone, Debug, PartialEq)]
pub struct RolloutOptions {
    pub propagation: pets::Propagation,
    pub particles: usize,
    /// Calibration transitions to condition a context model on (`None`: the empty context, the prior mean).
    pub context: Option<std::path::PathBuf>,
    /// Whether a run still in training is taken (its best-validation weights so far).
    pub accept: crate::train::Accept,
}

pub use registry::PLANNING_METHODS;

/// A trained model from its checkpoint directory, as dynamics for a planner in `env`. Which method made it is
/// read from the checkpoint, which is opened once, so callers never branch on methods.
pub fn load_planning_model(dir: &Path, env: &EnvName, options: RolloutOptions) -> Result<Box<dyn BatchDynamics>> {
    if dir.join("params.json").is_file() && !dir.join(crate::train::checkpoint::MANIFEST_FILE).exists() {
        return Err(Error::bad_file(
            dir,
            format!("is a ball EKF model, a filter without controls; use `mbrl filter`/`mbrl predict`. Planning supports: {PLANNING_METHODS}"),
        ));
    }
    let opened = OpenedCheckpoint::open(dir)?;
    registry::method(&opened.manifest.method, dir)?.planning_dynamics(&opened, env, &options)
}
