//! Where ball-model parameters come from: a trained checkpoint directory (`params.json` + `config.json`)
//! or one of the built-in parameter sets.

use std::path::Path;

use super::learn::job::BallEkf;
use super::learn::SpinNetWeights;
use super::{BallModel, BallModelParams, SpinPrior};
use crate::data::ball_io::Recording;
use crate::error::{Error, Result};
use crate::train::checkpoint::read_bounded;
use crate::train::{open_run, Accept};

pub const PARAMS_FILE: &str = "params.json";
pub const SPIN_NET_FILE: &str = "spin_net.json";
pub const BUILTIN_HELP: &str =
    "thesis (the learned values of thesis eq. 6.26 / Table C.2), initial (Table C.1), or a checkpoint directory";

/// A ball model as loaded from `--model`: the EKF parameters, and the launcher spin network when the
/// checkpoint was trained with `--launcher-prior`.
pub struct LoadedBallModel {
    pub model: BallModel,
    pub spin_net: Option<SpinNetWeights>,
}

impl LoadedBallModel {
    /// The spin prior for a recording: from its launcher settings when both the network and the settings
    /// are there (the frame's yaw read off the first two measurements, thesis 6.4.3), the broad prior
    /// otherwise.
    pub fn prior(&self, recording: &Recording) -> SpinPrior {
        match (&self.spin_net, super::learn::observed_side_info(recording)) {
            (Some(net), Some(side_info)) => net.prior(&side_info),
            _ => SpinPrior::Uninformed,
        }
    }
}

/// Parses `--model`: a built-in name or a directory written by `mbrl train ball-ekf`.
/// How reports name a model given as `spec`: the built-in `thesis` parameters (Table C.1) are the very
/// constants the simulator generates its shots with, so on simulated shots that model is an oracle, not a
/// competitor, and is named so.
pub fn report_name(spec: &str) -> String {
    match spec {
        "thesis" => ORACLE_NAME.to_string(),
        other => other.to_string(),
    }
}

pub const ORACLE_NAME: &str = "oracle (simulator's constants)";

pub fn load_ball_model(spec: &str) -> Result<LoadedBallModel> {
    let (params, spin_net) = match spec {
        "thesis" => (BallModelParams::thesis_learned(), None),
        "initial" => (BallModelParams::initial(), None),
        path if Path::new(path).is_dir() => load_checkpoint(Path::new(path))?,
        path => {
            let file = Path::new(path);
            if !file.is_file() {
                return Err(Error::bad_file(file, format!("no ball model here; --model takes {BUILTIN_HELP}")));
            }
            (parse_params(file, &read_bounded(file, MAX_JSON_BYTES)?)?, None)
        }
    };
    let model = BallModel::new(params).map_err(|e| Error::config(format!("--model {spec}: {e}")))?;
    Ok(LoadedBallModel { model, spin_net })
}

const MAX_JSON_BYTES: u64 = 16 << 20;

/// A directory written by `mbrl train ball-ekf`: every file checked against the manifest.
fn load_checkpoint(dir: &Path) -> Result<(BallModelParams, Option<SpinNetWeights>)> {
    let (opened, _record) = open_run::<BallEkf>(dir, Accept::Finished)?;
    let params_bytes = opened
        .file_bytes(PARAMS_FILE)?
        .ok_or_else(|| Error::bad_file(dir, format!("the checkpoint lists no {PARAMS_FILE}")))?;
    let params = parse_params(&dir.join(PARAMS_FILE), &params_bytes)?;
    let spin_net = match opened.file_bytes(SPIN_NET_FILE)? {
        None => None,
        Some(bytes) => {
            let path = dir.join(SPIN_NET_FILE);
            let net: SpinNetWeights = serde_json::from_slice(&bytes)
                .map_err(|e| Error::bad_file(&path, format!("not spin-network weights: {e}")))?;
            net.check().map_err(|e| e.at(&path))?;
            Some(net)
        }
    };
    Ok((params, spin_net))
}

fn parse_params(path: &Path, bytes: &[u8]) -> Result<BallModelParams> {
    serde_json::from_slice(bytes).map_err(|e| Error::bad_file(path, format!("not ball-model parameters: {e}")))
}
