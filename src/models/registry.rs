//! Every learning method mbrl trains, by the name its checkpoints carry: what `train --resume DIR` and the
//! planners look a checkpoint's method up in. Adding a method is its folder and one line in [`METHODS`].

use std::fmt::Display;
use std::marker::PhantomData;
use std::path::Path;

use super::{ball, context, dlgpd, pets, seads, tradyn, RolloutOptions};
use crate::control::BatchDynamics;
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::train::job::{carry_out, resume};
use crate::train::run_dir::Decision;
use crate::train::{Extension, Method, OpenedCheckpoint, Request, RunRecord, Trained};

/// The loss plot a run leaves beside its checkpoint, with losses.csv.
#[derive(Clone, Copy, Debug)]
pub struct LossPlot {
    pub title: &'static str,
    pub y_label: &'static str,
    /// The CSV column and axis label of the validation metric when it is another quantity than the training
    /// loss (PETS validates its mean prediction's MSE against an NLL objective): drawn in a panel of its own,
    /// never on the loss axis. `None` when both measure the same objective and share one axis.
    pub separate_validation: Option<(&'static str, &'static str)>,
}

impl LossPlot {
    pub const fn same_objective(title: &'static str, y_label: &'static str) -> Self {
        LossPlot { title, y_label, separate_validation: None }
    }
}

/// What a method adds to the training job's view of it once it is a model: how a finished run reports
/// itself, and whether planners can roll it out.
pub trait ModelMethod: Method {
    /// The loss plot a run leaves beside its checkpoint.
    const LOSS_PLOT: LossPlot;
    type Summary: Display + Send + 'static;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary>;

    /// The checkpoint as a planner's dynamics in `env`; methods without dynamics to plan with refuse.
    fn planning_dynamics(
        opened: &OpenedCheckpoint,
        _record: RunRecord<Self>,
        _env: &EnvName,
        _options: &RolloutOptions,
    ) -> Result<Box<dyn BatchDynamics>> {
        Err(Error::bad_file(
            opened.dir.path(),
            format!(
                "is a '{}' checkpoint, which has no dynamics to plan with; planning supports: {PLANNING_METHODS}",
                Self::NAME
            ),
        ))
    }
}

/// The methods whose checkpoints `plan` can plan with.
pub const PLANNING_METHODS: &str = "pets, context, dlgpd (with --evidence)";

/// A method as the registry holds it, with its types erased.
pub trait RegisteredMethod: Sync {
    fn name(&self) -> &'static str;
    fn extendable(&self) -> bool;
    fn loss_plot(&self) -> LossPlot;
    /// Continues the stopped run in `dir` (to a larger total with `extension`) and reports it.
    fn resume(
        &self,
        dir: &Path,
        extension: Option<&Extension>,
        monitor: &dyn Monitor,
    ) -> Result<Box<dyn Display + Send>>;
    fn planning_dynamics(
        &self,
        opened: &OpenedCheckpoint,
        env: &EnvName,
        options: &RolloutOptions,
    ) -> Result<Box<dyn BatchDynamics>>;
}

struct Entry<M>(PhantomData<fn() -> M>);

impl<M: ModelMethod> RegisteredMethod for Entry<M> {
    fn name(&self) -> &'static str {
        M::NAME
    }

    fn extendable(&self) -> bool {
        M::EXTENDABLE
    }

    fn loss_plot(&self) -> LossPlot {
        M::LOSS_PLOT
    }

    fn resume(
        &self,
        dir: &Path,
        extension: Option<&Extension>,
        monitor: &dyn Monitor,
    ) -> Result<Box<dyn Display + Send>> {
        let trained = resume::<M>(dir, extension, monitor)?;
        Ok(Box::new(M::summary(&trained, dir)?))
    }

    fn planning_dynamics(
        &self,
        opened: &OpenedCheckpoint,
        env: &EnvName,
        options: &RolloutOptions,
    ) -> Result<Box<dyn BatchDynamics>> {
        opened.expect(M::NAME, options.accept)?;
        M::planning_dynamics(opened, RunRecord::<M>::read(opened)?, env, options)
    }
}

/// Every method, by checkpoint name.
pub static METHODS: [&dyn RegisteredMethod; 6] = [
    &Entry::<pets::Pets>(PhantomData),
    &Entry::<context::Context>(PhantomData),
    &Entry::<tradyn::Tradyn>(PhantomData),
    &Entry::<dlgpd::job::Dlgpd>(PhantomData),
    &Entry::<seads::Seads>(PhantomData),
    &Entry::<ball::learn::job::BallEkf>(PhantomData),
];

/// The registered method named `name` (a checkpoint's `method`).
pub fn method(name: &str, dir: &Path) -> Result<&'static dyn RegisteredMethod> {
    METHODS.iter().copied().find(|m| m.name() == name).ok_or_else(|| {
        let known: Vec<&str> = METHODS.iter().map(|m| m.name()).collect();
        Error::wrong_method(name, known.join(", ")).at(dir)
    })
}

/// Starts or continues a run of `M` as decided, and reports it.
pub fn train<M: ModelMethod>(
    out: &Path,
    request: &Request<M>,
    decision: &Decision,
    monitor: &dyn Monitor,
) -> Result<M::Summary> {
    let trained = carry_out(out, request, decision, monitor)?;
    M::summary(&trained, out)
}

impl ModelMethod for pets::Pets {
    const LOSS_PLOT: LossPlot = LossPlot {
        title: "PETS training loss (Gaussian NLL summed over members)",
        y_label: "loss",
        separate_validation: Some(("validation_mse", "validation MSE of the mean (held out)")),
    };
    type Summary = pets::PetsSummary;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary> {
        Ok(pets::PetsSummary::of(trained, dir))
    }

    fn planning_dynamics(
        opened: &OpenedCheckpoint,
        record: RunRecord<Self>,
        env: &EnvName,
        options: &RolloutOptions,
    ) -> Result<Box<dyn BatchDynamics>> {
        if let Some(path) = &options.context {
            return Err(Error::bad_file(
                path,
                format!("--context conditions context models; {} is a PETS ensemble", opened.dir.path().display()),
            ));
        }
        Ok(Box::new(pets::dynamics_from(opened, &record, env, options.propagation, options.particles)?))
    }
}

impl ModelMethod for context::Context {
    const LOSS_PLOT: LossPlot = LossPlot::same_objective("Context-model training loss (eq. 4.32)", "loss");
    type Summary = context::ContextSummary;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary> {
        Ok(context::ContextSummary::of("a context model".to_string(), trained, dir))
    }

    fn planning_dynamics(
        opened: &OpenedCheckpoint,
        record: RunRecord<Self>,
        env: &EnvName,
        options: &RolloutOptions,
    ) -> Result<Box<dyn BatchDynamics>> {
        let model = context::model_from(opened, record, env)?;
        let rows = match &options.context {
            Some(path) => context::calibration::read_context(&model, path)?,
            None => Vec::new(),
        };
        Ok(Box::new(context::dynamics::ContextDynamics::new(model, &rows, env)?))
    }
}

impl ModelMethod for tradyn::Tradyn {
    const LOSS_PLOT: LossPlot = LossPlot::same_objective("TRADYN training loss (eq. 4.32 with terrain input)", "loss");
    type Summary = context::ContextSummary;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary> {
        Ok(tradyn::summary(trained, dir))
    }
}

impl ModelMethod for dlgpd::job::Dlgpd {
    const LOSS_PLOT: LossPlot =
        LossPlot::same_objective("DLGPD training loss (eq. 3.16 with the SNR penalty, per batch)", "loss");
    type Summary = dlgpd::job::DlgpdSummary;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary> {
        Ok(dlgpd::job::DlgpdSummary::of(trained, dir))
    }

    fn planning_dynamics(
        opened: &OpenedCheckpoint,
        _record: RunRecord<Self>,
        _env: &EnvName,
        _options: &RolloutOptions,
    ) -> Result<Box<dyn BatchDynamics>> {
        Err(Error::bad_file(
            opened.dir.path(),
            "is a DLGPD model, which plans from images in latent space: `mbrl plan --env pendulum[:variant] --model \
             DIR --evidence ROLLOUTS.mcap`",
        ))
    }
}

impl ModelMethod for seads::Seads {
    const LOSS_PLOT: LossPlot =
        LossPlot::same_objective("SEADS forward-model NLL per bit on each epoch's new episodes", "nats per bit");
    type Summary = seads::SeadsSummary;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary> {
        Ok(seads::SeadsSummary::of(trained, dir))
    }
}

impl ModelMethod for ball::learn::job::BallEkf {
    const LOSS_PLOT: LossPlot =
        LossPlot::same_objective("Training loss (eq. 6.24, per measurement)", "negative log-likelihood");
    type Summary = ball::learn::job::BallSummary;

    fn summary(trained: &Trained<Self>, dir: &Path) -> Result<Self::Summary> {
        ball::learn::job::BallSummary::of(trained, dir)
    }
}
