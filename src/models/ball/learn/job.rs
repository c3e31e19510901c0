//! `mbrl train ball-ekf` on the shared training job: a checkpoint directory with `params.json` (and
//! `spin_net.json`) vouched for by the manifest, periodic checkpoints and `--resume`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::spin_net::SpinNetWeights;
use super::train::TrainSettings;
use super::trainer::BallEkfTrainer;
use crate::data::ball_io::read_recordings;
use crate::error::{Error, Result};
use crate::models::ball::BallModelParams;
use crate::train::{
    loss_history, loss_panel, training_view, DataFile, FitOutcome, Method, Prepared, Request, RunConfig, RunRecord,
    Trained,
};

pub const METHOD: &str = "ball-ekf";
/// Steps between checkpoints; a checkpoint costs a few ms next to steps of ~60 ms.
pub const CHECKPOINT_EVERY: u64 = 100;

/// What a ball-EKF run records beyond the shared fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallDetails {
    pub recordings: usize,
    pub chunks: usize,
}

/// config.json of a ball-EKF checkpoint.
pub type BallRun = RunRecord<BallEkf>;

/// The gray-box ball EKF as the training job drives it. Its seed lives in its settings, as it always has.
pub struct BallEkf;

impl RunConfig for TrainSettings {
    fn total_steps(&self) -> u64 {
        self.steps
    }

    /// One validation, at the end: the EKF holds nothing back, the final parameters are the model.
    fn schedule(&self) -> (u64, u64) {
        (self.steps, CHECKPOINT_EVERY)
    }

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl Method for BallEkf {
    const NAME: &'static str = METHOD;
    const TITLE: &'static str = "ball-EKF";
    type Config = TrainSettings;
    type Variant = ();
    type Details = BallDetails;
    type Trainer = BallEkfTrainer;

    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>> {
        let [path] = request.data.as_slice() else {
            return Err(Error::config(format!(
                "the ball EKF trains on one recordings file, got {}",
                request.data.len()
            )));
        };
        if request.seed != request.config.seed {
            return Err(Error::config(format!(
                "seed {} differs from the settings' seed {}",
                request.seed, request.config.seed
            )));
        }
        let data = DataFile::fingerprint(path)?;
        let recordings = read_recordings(path)?;
        let trainer = BallEkfTrainer::new(&recordings, &request.config)?;
        let t = &request.config;
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
        let details = BallDetails { recordings: recordings.len(), chunks: trainer.chunk_count() };
        Ok(Prepared { env: None, data: vec![data], details, trainer, view })
    }

    fn variant_of(_record: &BallRun) -> Result<()> {
        Ok(())
    }

    fn check_record(record: &BallRun) -> Result<()> {
        if record.data.len() != 1 || record.seed != record.config.seed {
            return Err(Error::config("expected one recordings file and the settings' seed"));
        }
        Ok(())
    }

    /// Runs before the shared record kept the settings under `settings`, one data file as an object, and the
    /// seed only in the settings.
    fn upgrade(record: &mut Value) {
        let Some(fields) = record.as_object_mut() else { return };
        if fields.contains_key("config") {
            return;
        }
        let Some(settings) = fields.remove("settings") else { return };
        if let Some(seed) = settings.get("seed").cloned() {
            fields.entry("seed").or_insert(seed);
        }
        fields.insert("config".into(), settings);
        if let Some(file @ Value::Object(_)) = fields.remove("data") {
            fields.insert("data".into(), Value::Array(vec![file]));
        }
    }
}

/// What `mbrl train ball-ekf` reports of a finished run: the learned parameters beside the thesis' values.
pub struct BallSummary {
    pub record: BallRun,
    pub outcome: FitOutcome,
    pub params: BallModelParams,
    pub spin_net: Option<SpinNetWeights>,
    /// The first and last training loss logged.
    pub losses: Option<(f64, f64)>,
    pub dir: PathBuf,
}

impl BallSummary {
    /// Fails when training ended with parameters no filter can run on.
    pub fn of(trained: &Trained<BallEkf>, dir: &Path) -> Result<Self> {
        let (params, spin_net) = trained.trainer.current();
        params
            .validate()
            .map_err(|e| Error::diverged(format!("ball EKF training ended with unusable parameters: {e}")))?;
        let history = loss_history(&dir.join(crate::run::dir::METRICS_FILE))?;
        let losses = history.first().zip(history.last()).map(|(first, last)| (first.1, last.1));
        Ok(BallSummary {
            record: trained.record.clone(),
            outcome: trained.outcome.clone(),
            params,
            spin_net,
            losses,
            dir: dir.to_path_buf(),
        })
    }
}

impl std::fmt::Display for BallSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (p, run) = (&self.params, &self.record);
        let thesis = BallModelParams::thesis_learned();
        writeln!(
            f,
            "trained on {} chunks of {} frames from {} recordings",
            run.details.chunks, run.config.chunk_len, run.details.recordings
        )?;
        if let Some((first, last)) = self.losses {
            writeln!(f, "loss {first:.3} -> {last:.3}")?;
        }
        writeln!(f, "learned C (thesis eq. 6.26 in brackets):")?;
        for (row, thesis_row) in p.c.iter().zip(&thesis.c) {
            let cells: Vec<String> = row.iter().zip(thesis_row).map(|(v, t)| format!("{v:6.2} [{t:5.2}]")).collect();
            writeln!(f, "  {}", cells.join(" "))?;
        }
        let (k_d, k_m) = p.initial_coefficients();
        writeln!(f, "a_d {:.4} (k_d {k_d:.4}), a_m {:.4} (k_m {k_m:.4})", p.a_d0, p.a_m0)?;
        write!(f, "checkpoint: {}", self.dir.display())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::dir::Provenance;

    fn record() -> BallRun {
        RunRecord {
            method: METHOD.into(),
            env: None,
            data: vec![DataFile { path: "shots.mcap".into(), bytes: 10, crc32: 7 }],
            seed: 4,
            config: TrainSettings { seed: 4, ..TrainSettings::default() },
            details: BallDetails { recordings: 3, chunks: 9 },
            provenance: Provenance::new("mbrl train ball-ekf".into(), 4, 1),
        }
    }

    #[test]
    fn config_json_of_older_runs_reads_as_todays_record() {
        let today = record().to_value().unwrap();
        let mut legacy = today.clone();
        let fields = legacy.as_object_mut().unwrap();
        fields.remove("seed");
        let settings = fields.remove("config").unwrap();
        fields.insert("settings".into(), settings);
        let file = fields["data"][0].clone();
        fields.insert("data".into(), file);
        let read = BallRun::from_value(Path::new("config.json"), legacy).unwrap();
        assert_eq!(read.to_value().unwrap(), today);
    }

    #[test]
    fn unknown_fields_and_a_seed_apart_from_the_settings_are_refused() {
        let mut value = record().to_value().unwrap();
        value.as_object_mut().unwrap().insert("chunk_count".into(), Value::from(3));
        let err = BallRun::from_value(Path::new("config.json"), value).unwrap_err().to_string();
        assert!(err.contains("unknown field `chunk_count`"), "{err}");
        let mut value = record().to_value().unwrap();
        value["seed"] = Value::from(5);
        assert!(BallRun::from_value(Path::new("config.json"), value).is_err());
    }
}
