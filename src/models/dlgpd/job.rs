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
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::train::datasets::{env_of, load_datasets, TransitionCounts};
use crate::train::tensors::TensorData;
use crate::train::{
    continuation, loss_panel, run_training, training_view, Accept, DataFile, Extension, FitOutcome, FitSettings,
    OpenedCheckpoint, Start, TrainingProgress, MODEL_FILE,
};
use crate::util::seeding::rng_for;

pub const METHOD: &str = "dlgpd";
const SPLIT_STREAM: u64 = u64::from_be_bytes(*b"dlgpdval");

/// config.json of a DLGPD checkpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DlgpdRun {
    pub method: String,
    pub env: String,
    pub data: Vec<DataFile>,
    pub seed: u64,
    pub observation: ObservationKind,
    pub action_dim: usize,
    pub config: DlgpdConfig,
    pub transitions: TransitionCounts,
    pub provenance: Provenance,
}

pub struct TrainRequest {
    pub out: PathBuf,
    pub data: Vec<PathBuf>,
    pub env: Option<String>,
    pub config: DlgpdConfig,
    pub seed: u64,
    pub provenance: Provenance,
}

pub struct TrainReport {
    pub run: DlgpdRun,
    pub outcome: FitOutcome,
    pub parameters: usize,
}

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

/// Trains DLGPD into `request.out`, fresh or continuing the run there (see [`Start`]).
pub fn train(request: &TrainRequest, start: Start, monitor: &dyn Monitor) -> Result<TrainReport> {
    request.config.validate()?;
    let (dataset, files) = load_datasets(&request.data)?;
    let env = env_of(&dataset, request.env.as_deref(), &request.data[0])?;
    if !env.canonical().starts_with("pendulum") {
        return Err(Error::bad_file(
            &request.data[0],
            format!("holds '{}' rollouts; DLGPD learns the pendulum (pendulum[:variant] datasets)", env.canonical()),
        ));
    }
    let kind = ObservationKind::of(&dataset, request.config.images)
        .map_err(|e| Error::bad_file(&request.data[0], e.to_string()))?;
    let windows = Windows::from_dataset(&dataset, kind, request.seed)
        .map_err(|e| Error::bad_file(&request.data[0], e.to_string()))?;
    drop(dataset);
    let (train_rows, valid_rows, counts) = split_rows(&windows, request.config.validation_fraction, request.seed);
    let run = DlgpdRun {
        method: METHOD.into(),
        env: env.canonical(),
        data: files,
        seed: request.seed,
        observation: kind,
        action_dim: windows.action_dim,
        config: request.config.clone(),
        transitions: counts,
        provenance: request.provenance.clone(),
    };
    let mut trainer = DlgpdTrainer::new(request.config.clone(), request.seed, windows, train_rows, valid_rows)?;
    let parameters = trainer.parameter_count();
    let settings = FitSettings {
        method: METHOD.into(),
        env: Some(run.env.clone()),
        total_steps: request.config.steps,
        validate_every: request.config.validate_every,
        checkpoint_every: request.config.checkpoint_every,
    };
    let config = serde_json::to_value(&run).map_err(|e| Error::config(e.to_string()))?;
    let observed = match kind {
        ObservationKind::Images { side } => format!("{side}×{side} frames"),
        ObservationKind::Angles => "pole angles".to_string(),
    };
    let c = &request.config;
    let view = training_view(
        &format!("train DLGPD on {}", run.env),
        vec![
            loss_panel("loss: −ELBO (train, held-out)", true),
            crate::run::PanelSpec {
                title: "reward RMSE on held-out rollouts (open loop 5, 10 steps; constant)".into(),
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
            ("transitions", format!("{} train / {} valid", run.transitions.train, run.transitions.valid)),
            ("batch", format!("{} (= GP evidence)", c.batch_size)),
            ("learning rate", format!("{} (VAE, GPs)", c.learning_rate)),
            ("latent size", c.latent_dim.to_string()),
            ("parameters", parameters.to_string()),
        ],
    );
    let outcome = run_training(&request.out, &config, &settings, &mut trainer, start, &view, monitor)?;
    Ok(TrainReport { run, outcome, parameters })
}

fn read_run(opened: &OpenedCheckpoint) -> Result<DlgpdRun> {
    let path = opened.dir.file("config.json");
    let run: DlgpdRun = serde_json::from_value(opened.config.clone())
        .map_err(|e| Error::bad_file(&path, format!("not a DLGPD run config: {e}")))?;
    run.config.validate().map_err(|e| Error::bad_file(&path, e.to_string()))?;
    Ok(run)
}

/// Continues the run in `dir` from its last checkpoint, with the config and data it was started with; with
/// `extend_to`, on to that many steps in total (the run may be finished: its training does not depend on the
/// total, so its weights end as those of a run started with that total, provided its old total fell on a
/// validation).
pub fn resume(dir: &Path, extend_to: Option<&Extension>, monitor: &dyn Monitor) -> Result<TrainReport> {
    let opened = OpenedCheckpoint::open(dir)?;
    let run = read_run(&opened)?;
    opened.expect_total_steps(run.config.steps as u64)?;
    let next = continuation(&opened, run.config.steps, &run.provenance, extend_to)?;
    for file in &run.data {
        file.verify_unchanged()?;
    }
    let request = TrainRequest {
        out: dir.to_path_buf(),
        data: run.data.iter().map(|f| f.path.clone()).collect(),
        env: Some(run.env.clone()),
        config: DlgpdConfig { steps: next.steps, ..run.config.clone() },
        seed: run.seed,
        provenance: next.provenance,
    };
    train(&request, next.start, monitor)
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

/// A finished DLGPD run.
pub fn load(dir: &Path) -> Result<TrainedDlgpd> {
    load_accepting(dir, Accept::Finished)
}

/// A DLGPD run, finished or (with [`Accept::InProgress`]) still training: then its best-validation weights
/// so far.
pub fn load_accepting(dir: &Path, accept: Accept) -> Result<TrainedDlgpd> {
    let opened = OpenedCheckpoint::open(dir)?;
    opened.expect(METHOD, accept)?;
    let run = read_run(&opened)?;
    let stored = opened.tensors(MODEL_FILE)?;
    let path = opened.dir.file(MODEL_FILE);
    let bad = |what: String| Error::bad_file(&path, what);
    let latent = run.config.latent_dim;
    let device = inference_device();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(0);
    let vae = VaeNet::init(run.observation, latent, run.config.hidden_units, &device, &mut rng)
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
    let (transition, reward) = gps_from_stored(&stored, "", latent, run.action_dim).map_err(|e| bad(e.to_string()))?;
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
