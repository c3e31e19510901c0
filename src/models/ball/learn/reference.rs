//! The training loss evaluated with the fast nalgebra filter: for validation, and the yardstick the batched
//! tensor filter is tested against.

use super::chunks::Chunk;
use super::spin_net::SpinNetWeights;
use crate::error::{Error, Result};
use crate::filtering::filter_belief;
use crate::models::ball::{initial_belief, BallModel, BallModelParams, SpinPrior};

/// Mean innovation NLL per measurement of one chunk; `spin` selects the launcher prior.
pub fn chunk_nll(model: &BallModel, spin: Option<&SpinNetWeights>, chunk: &Chunk) -> Result<f64> {
    let prior = match (spin, &chunk.side_info) {
        (None, _) => SpinPrior::Uninformed,
        (Some(net), Some(side)) => net.prior(side),
        (Some(_), None) => {
            return Err(Error::data(format!(
                "recording {} has no launcher side information for the launcher spin prior",
                chunk.recording
            )))
        }
    };
    let at = |e: &dyn std::fmt::Display| format!("recording {} frame {}: {e}", chunk.recording, chunk.start_frame);
    let start = initial_belief(model.params(), chunk.m1, chunk.m2, 1, chunk.after_impact, &prior)
        .map_err(|e| Error::data(at(&e)))?;
    let out = filter_belief(model, &start, &chunk.slots).map_err(|e| Error::diverged(at(&e)))?;
    Ok(-out.log_likelihood / chunk.measured().max(1) as f64)
}

/// The loss of eq. 6.24 as the trainer defines it: the mean over chunks of [`chunk_nll`].
pub fn reference_loss(params: &BallModelParams, spin: Option<&SpinNetWeights>, chunks: &[Chunk]) -> Result<f64> {
    let model = BallModel::new(params.clone()).map_err(|e| Error::data(format!("ball model: {e}")))?;
    let mut total = 0.0;
    for chunk in chunks {
        total += chunk_nll(&model, spin, chunk)?;
    }
    Ok(total / chunks.len().max(1) as f64)
}
