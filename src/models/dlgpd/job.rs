//! `mbrl train dlgpd` as a job: datasets in, a checkpoint directory out (config.json, the VAE's weights
//! with the GPs' hyperparameters and the frozen latent standardization in model.safetensors, the optimizers'
//! state), resumable; and loading a finished checkpoint for planning.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use super::config::DlgpdConfig;
use super::data::{ObservationKind, Windows};
use super::latent_gp::LatentScale;
use super::train::{f64_tensor, gps_from_stored, DlgpdTrainer, SCALE_MEAN, SCALE_STD};
use super::vae::VaeNet;
use crate::error::{Error, Result};
use crate::models::gp::GpHypers;
use crate::nn::tensor::inference_device;
use crate::train::datasets::{env_of, load_datasets, TransitionCounts};
use crate::train::tensors::TensorData;
use crate::train::{
    loss_panel, open_run, training_view, Accept, FitOutcome, Method, Prepared, Request, RunConfig, RunRecord, Trained,
    TrainingProgress, MODEL_FILE,
};
use crate::util::seeding::rng_for;

pub const METHOD: &str = "dlgpd";
const SPLIT_STREAM: u64 = u64::from_be_bytes(*b"dlgpdval");

/// What a DLGPD run records beyond the shared fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DlgpdDetails {
    pub observation: ObservationKind,
    pub action_dim: usize,
    pub transitions: TransitionCounts,
}

/// config.json of a DLGPD checkpoint.
pub type DlgpdRun = RunRecord<Dlgpd>;

/// DLGPD as the training job drives it.
pub struct Dlgpd;

/// Rows of held-out and training transitions: whole rollouts, a seeded share held out.
fn split_rows(windows: &Windows, fraction: f64, seed: u64) -> (Vec<usize>, Vec<usize>, TransitionCounts) {
    let ids: Vec<u32> = windows.rollout.iter().copied().collect::<BTreeSet<_>>().into_iter().collect();
    let mut order = ids.clone();
    order.shuffle(&mut rng_for(seed, &[SPLIT_STREAM]));
    let held_out = if fraction > 0.0 && ids.len() >= 2 {
        ((ids.len() as f64 * fraction).round() as usize).clamp(1, ids.len() - 1)
    } else {
        0
    };
    let valid_ids: BTreeSet<u32> = order[..held_out].iter().copied().collect();
    let train = windows.rows_where(|r| !valid_ids.contains(&r));
    let valid = windows.rows_where(|r| valid_ids.contains(&r));
    let counts = TransitionCounts {
        train: train.len(),
        valid: valid.len(),
        train_rollouts: ids.len() - held_out,
        valid_rollouts: held_out,
    };
    (train, valid, counts)
}

impl RunConfig for DlgpdConfig {
    fn total_steps(&self) -> u64 {
        self.steps
    }

    fn schedule(&self) -> (u64, u64) {
        (self.validate_every, self.checkpoint_every)
    }

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl Method for Dlgpd {
    const NAME: &'static str = METHOD;
    const TITLE: &'static str = "DLGPD";
    const EXTENDABLE: bool = true;
    type Config = DlgpdConfig;
    type Variant = ();
    type Details = DlgpdDetails;
    type Trainer = DlgpdTrainer;

    fn with_total_steps(config: &DlgpdConfig, steps: u64) -> DlgpdConfig {
        DlgpdConfig { steps, ..config.clone() }
    }

    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>> {
        let (dataset, files) = load_datasets(&request.data)?;
        let first = &request.data[0];
        let env = env_of(&dataset, request.env.as_deref(), first)?;
        if !env.canonical().starts_with("pendulum") {
            return Err(Error::bad_file(
                first,
                format!(
                    "holds '{}' rollouts; DLGPD learns the pendulum (pendulum[:variant] datasets)",
                    env.canonical()
                ),
            ));
        }
        let c = &request.config;
        let kind = ObservationKind::of(&dataset, c.images).map_err(|e| e.at(first))?;
        let windows = Windows::from_dataset(&dataset, kind, request.seed).map_err(|e| e.at(first))?;
        drop(dataset);
        let (train_rows, valid_rows, counts) = split_rows(&windows, c.validation_fraction, request.seed);
        let details = DlgpdDetails { observation: kind, action_dim: windows.action_dim, transitions: counts };
        let trainer = DlgpdTrainer::new(c.clone(), request.seed, windows, train_rows, valid_rows)?;
        let observed = match kind {
            ObservationKind::Images { side } => format!("{side}×{side} frames"),
            ObservationKind::Angles => "pole angles".to_string(),
        };
        let t = &details.transitions;
        let view = training_view(
            &format!("train DLGPD on {}", env.canonical()),
            vec![
                loss_panel("loss: −ELBO (train, held-out)", true),
                crate::run::PanelSpec {
                    title: format!(
                        "reward RMSE on held-out rollouts every {} steps (open loop 5, 10; constant)",
                        c.validate_every
                    ),
                    x_label: "step".into(),
                    series: ["valid/reward_rmse_h5", "valid/reward_rmse_h10", "valid/reward_rmse_constant"]
                        .map(String::from)
                        .to_vec(),
                    restart_on_rewind: false,
                    path: None,
                },
                crate::run::PanelSpec {
                    title: "GP action lengthscale (min; actions span 4)".into(),
                    x_label: "step".into(),
                    series: vec!["dlgpd/action_lengthscale".into()],
                    restart_on_rewind: false,
                    path: None,
                },
            ],
            &[
                ("observations", observed),
                ("transitions", format!("{} train / {} valid", t.train, t.valid)),
                ("batch", format!("{} (= GP evidence)", c.batch_size)),
                ("learning rate", format!("{} (VAE, GPs)", c.learning_rate)),
                ("latent size", c.latent_dim.to_string()),
                ("parameters", trainer.parameter_count().to_string()),
            ],
        );
        Ok(Prepared { env: Some(env.canonical()), data: files, details, trainer, view })
    }

    fn variant_of(_record: &DlgpdRun) -> Result<()> {
        Ok(())
    }
}

/// What `mbrl train dlgpd` reports of a finished run.
pub struct DlgpdSummary {
    pub record: DlgpdRun,
    pub outcome: FitOutcome,
    pub parameters: usize,
    pub dir: PathBuf,
}

impl DlgpdSummary {
    pub fn of(trained: &Trained<Dlgpd>, dir: &Path) -> Self {
        DlgpdSummary {
            record: trained.record.clone(),
            outcome: trained.outcome.clone(),
            parameters: trained.trainer.parameter_count(),
            dir: dir.to_path_buf(),
        }
    }
}

impl std::fmt::Display for DlgpdSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (run, c) = (&self.record, &self.record.config);
        let observed = match run.details.observation {
            ObservationKind::Images { side } => format!("{side}×{side} frames (conv VAE)"),
            ObservationKind::Angles => "pole angles (MLP VAE, small preset)".to_string(),
        };
        let t = &run.details.transitions;
        writeln!(
            f,
            "trained DLGPD ({} parameters, latent {}) on {} transitions of {} from {observed} ({} rollouts; {} held out), batch {}",
            self.parameters,
            c.latent_dim,
            t.train,
            run.env(),
            t.train_rollouts,
            t.valid_rollouts,
            c.batch_size
        )?;
        let o = &self.outcome;
        if let Some(loss) = o.last_train_loss {
            writeln!(f, "final training loss {loss:.3} after {} steps", o.steps)?;
        }
        if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
            writeln!(f, "best validation loss {v:.3} at step {step} (saved as model.safetensors)")?;
        }
        write!(f, "checkpoint: {}", self.dir.display())
    }
}

/// A finished DLGPD checkpoint: the VAE on the inference device, the GPs' trained hyperparameters and the
/// frozen standardization.
pub struct TrainedDlgpd {
    pub run: DlgpdRun,
    pub vae: VaeNet,
    pub transition: Vec<GpHypers>,
    pub reward: GpHypers,
    pub scale: LatentScale,
    pub progress: TrainingProgress,
}

/// A DLGPD run, finished or (with [`Accept::InProgress`]) still training: then its best-validation weights
/// so far.
pub fn load(dir: &Path, accept: Accept) -> Result<TrainedDlgpd> {
    let (opened, run) = open_run::<Dlgpd>(dir, accept)?;
    let stored = opened.tensors(MODEL_FILE)?;
    let path = opened.dir.file(MODEL_FILE);
    let bad = |what: String| Error::bad_file(&path, what);
    let latent = run.config.latent_dim;
    let device = inference_device();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(0);
    let vae = VaeNet::init(run.details.observation, latent, run.config.hidden_units, &device, &mut rng)
        .map_err(|e| bad(e.to_string()))?;
    let mut params = vae.params();
    for t in &mut params.tensors {
        match stored.iter().find(|s| s.name == t.name).map(|s| &s.data) {
            Some(TensorData::F32(v)) if v.len() == t.values.len() && v.iter().all(|x| x.is_finite()) => {
                t.values.clone_from(v)
            }
            _ => return Err(bad(format!("lacks '{}' with {} finite f32 values", t.name, t.values.len()))),
        }
    }
    let vae = vae.with_params(&params, &device)?;
    let (transition, reward) =
        gps_from_stored(&stored, "", latent, run.details.action_dim).map_err(|e| bad(e.to_string()))?;
    let part = |name: &str| {
        f64_tensor(&stored, name, latent)
            .cloned()
            .ok_or_else(|| bad(format!("lacks '{name}' with {latent} finite f64 values")))
    };
    let scale = LatentScale { mean: part(SCALE_MEAN)?, std: part(SCALE_STD)? };
    if scale.std.iter().any(|s| *s <= 0.0) {
        return Err(bad(format!("'{SCALE_STD}' must be positive, got {:?}", scale.std)));
    }
    Ok(TrainedDlgpd { run, vae, transition, reward, scale, progress: opened.progress() })
}
