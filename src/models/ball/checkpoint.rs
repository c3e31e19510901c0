//! Where ball-model parameters come from: a trained checkpoint directory (`params.json` + `config.json`)
//! or one of the built-in parameter sets.

use std::path::Path;

use super::learn::SpinNetWeights;
use super::{BallModel, BallModelParams, SpinPrior};
use crate::data::ball_io::Recording;
use crate::error::{Error, Result};
use crate::util::atomic::write_json;

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
    /// are there, the broad prior otherwise.
    pub fn prior(&self, recording: &Recording) -> SpinPrior {
        match (&self.spin_net, recording.info.side_info) {
            (Some(net), Some(side_info)) => net.prior(&side_info),
            _ => SpinPrior::Uninformed,
        }
    }
}

/// Parses `--model`: a built-in name or a directory written by `mbrl train --method ball-ekf`.
pub fn load_ball_model(spec: &str) -> Result<LoadedBallModel> {
    let spin_net_file = Path::new(spec).join(SPIN_NET_FILE);
    let spin_net = if Path::new(spec).is_dir() && spin_net_file.is_file() {
        let text = std::fs::read_to_string(&spin_net_file).map_err(|e| Error::io(&spin_net_file, e))?;
        Some(
            serde_json::from_str(&text)
                .map_err(|e| Error::bad_file(&spin_net_file, format!("not spin-network weights: {e}")))?,
        )
    } else {
        None
    };
    Ok(LoadedBallModel { model: load_params(spec)?, spin_net })
}

fn load_params(spec: &str) -> Result<BallModel> {
    let params = match spec {
        "thesis" => BallModelParams::thesis_learned(),
        "initial" => BallModelParams::initial(),
        path => {
            let dir = Path::new(path);
            let file = if dir.is_dir() { dir.join(PARAMS_FILE) } else { dir.to_path_buf() };
            if !file.is_file() {
                return Err(Error::bad_file(
                    &file,
                    format!("no ball model here; --model takes {BUILTIN_HELP} holding {PARAMS_FILE}"),
                ));
            }
            let text = std::fs::read_to_string(&file).map_err(|e| Error::io(&file, e))?;
            serde_json::from_str(&text)
                .map_err(|e| Error::bad_file(&file, format!("not ball-model parameters: {e}")))?
        }
    };
    BallModel::new(params).map_err(|e| Error::config(format!("--model {spec}: {e}")))
}

pub fn save_ball_params(dir: &Path, params: &BallModelParams) -> Result<()> {
    write_json(&dir.join(PARAMS_FILE), params)
}
