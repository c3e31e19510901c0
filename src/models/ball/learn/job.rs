//! `mbrl train ball-ekf` on the shared training loop: a checkpoint directory with `params.json`
//! (and `spin_net.json`) vouched for by the manifest, periodic checkpoints and `--resume`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::spin_net::SpinNetWeights;
use super::train::TrainSettings;
use super::trainer::BallEkfTrainer;
use crate::data::ball_io::read_recordings;
use crate::error::{Error, Result};
use crate::models::ball::BallModelParams;
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::train::{
    loss_panel, run_training, training_view, DataFile, FitOutcome, FitSettings, OpenedCheckpoint, Start,
};

pub const METHOD: &str = "ball-ekf";
/// Steps between checkpoints; a checkpoint costs a few ms next to steps of ~60 ms.
pub const CHECKPOINT_EVERY: u64 = 100;

/// config.json of a ball-EKF checkpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallRun {
    pub method: String,
    pub data: DataFile,
    pub recordings: usize,
    pub chunks: usize,
    pub settings: TrainSettings,
    pub provenance: Provenance,
}

pub struct BallTrainRequest {
    pub out: PathBuf,
    pub data: PathBuf,
    pub settings: TrainSettings,
    pub provenance: Provenance,
}

pub struct BallTrainReport {
    pub run: BallRun,
    pub outcome: FitOutcome,
    pub params: BallModelParams,
    pub spin_net: Option<SpinNetWeights>,
}

pub fn train_checkpointed(request: &BallTrainRequest, resume: bool, monitor: &dyn Monitor) -> Result<BallTrainReport> {
    let data = DataFile::fingerprint(&request.data)?;
    let recordings = read_recordings(&request.data)?;
    let mut trainer = BallEkfTrainer::new(&recordings, &request.settings)?;
    let run = BallRun {
        method: METHOD.into(),
        data,
        recordings: recordings.len(),
        chunks: trainer.chunk_count(),
        settings: request.settings.clone(),
        provenance: request.provenance.clone(),
    };
    let settings = FitSettings {
        method: METHOD.into(),
        env: None,
        total_steps: request.settings.steps,
        validate_every: request.settings.steps,
        checkpoint_every: CHECKPOINT_EVERY,
    };
    let config = serde_json::to_value(&run).map_err(|e| Error::config(e.to_string()))?;
    let t = &request.settings;
    let view = training_view(
        "train ball EKF",
        vec![loss_panel("loss: NLL per measurement", false)],
        &[
            ("recordings", recordings.len().to_string()),
            ("batch", format!("{} chunks × {} frames", t.batch_size, t.chunk_len)),
            ("learning rate", format!("{}", t.learning_rate)),
            ("spin prior", if t.launcher_prior { "launcher net (C.1.3)" } else { "broad" }.to_string()),
        ],
    );
    let outcome =
        run_training(&request.out, &config, &settings, &mut trainer, Start::resuming(resume), &view, monitor)?;
    let (params, spin_net) = trainer.current();
    params.validate().map_err(|e| Error::Diverged(format!("ball EKF training ended with unusable parameters: {e}")))?;
    Ok(BallTrainReport { run, outcome, params, spin_net })
}

/// Continues the stopped run in `dir` with the settings and recordings it was started with.
pub fn resume(dir: &Path, monitor: &dyn Monitor) -> Result<BallTrainReport> {
    let opened = OpenedCheckpoint::open(dir)?;
    let run: BallRun = serde_json::from_value(opened.config.clone())
        .map_err(|e| Error::bad_file(&opened.dir.file("config.json"), format!("not a ball-EKF run config: {e}")))?;
    opened.expect_total_steps(run.settings.steps as u64)?;
    run.data.verify_unchanged()?;
    let request = BallTrainRequest {
        out: dir.to_path_buf(),
        data: run.data.path.clone(),
        settings: run.settings.clone(),
        provenance: run.provenance.clone(),
    };
    train_checkpointed(&request, true, monitor)
}
