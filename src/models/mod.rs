pub mod ball;
pub mod context;
pub mod dlgpd;
pub mod gp;
pub mod pets;
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

/// The methods whose checkpoints `plan` can plan with.
pub const PLANNING_METHODS: &str = "pets, context, dlgpd (with --evidence)";

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
        pets::METHOD => {
            if let Some(path) = &options.context {
                return Err(Error::bad_file(
                    path,
                    format!("--context conditions context models; {} is a PETS ensemble", dir.display()),
                ));
            }
            Ok(Box::new(pets::load_dynamics(dir, env, options.propagation, options.particles, options.accept)?))
        }
        context::METHOD => {
            let model = context::load_accepting(dir, env, options.accept)?;
            let rows = match &options.context {
                Some(path) => context::calibration::read_context(&model, path)?,
                None => Vec::new(),
            };
            Ok(Box::new(context::dynamics::ContextDynamics::new(model, &rows, env)?))
        }
        dlgpd::job::METHOD => Err(Error::bad_file(
            dir,
            "is a DLGPD model, which plans from images in latent space: `mbrl plan --env pendulum[:variant] --model \
             DIR --evidence ROLLOUTS.mcap`",
        )),
        other => Err(Error::bad_file(
            dir,
            format!(
                "is a '{other}' checkpoint, which has no dynamics to plan with; planning supports: {PLANNING_METHODS}"
            ),
        )),
    }
}
