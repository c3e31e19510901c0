//! Where ball-model parameters come from: a trained checkpoint directory (`params.json` + `config.json`)
//! or one of the built-in parameter sets.

use std::path::Path;

use super::{BallModel, BallModelParams};
use crate::error::{Error, Result};
use crate::run::atomic::write_json;

pub const PARAMS_FILE: &str = "params.json";
pub const BUILTIN_HELP: &str =
    "thesis (the learned values of thesis eq. 6.26 / Table C.2), initial (Table C.1), or a checkpoint directory";

/// Parses `--model`: a built-in name or a directory written by `mbrl train --method ball-ekf`.
pub fn load_ball_model(spec: &str) -> Result<BallModel> {
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
    BallModel::new(params).map_err(|e| Error::InvalidInput(format!("--model {spec}: {e}")))
}

pub fn save_ball_params(dir: &Path, params: &BallModelParams) -> Result<()> {
    write_json(&dir.join(PARAMS_FILE), params)
}
