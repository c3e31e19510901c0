//! A batch of chunks as tensors for the batched filter.

use burn::tensor::{Device, Tensor};

use super::chunks::Chunk;
use super::device::tensor;
use super::rotation::{launch_rotation, motor_actuations};
use crate::error::{Error, Result};

/// What the launcher spin prior needs per sample.
pub struct LauncherInputs {
    /// Motor actuations s_m \[B, 3\].
    pub motors: Tensor<2>,
    /// R_rot \[B, 3, 3\].
    pub rotation: Tensor<3>,
}

pub struct Batch {
    pub size: usize,
    /// Filter slots after the two initializing measurements.
    pub steps: usize,
    pub m1: Tensor<2>,
    pub m2: Tensor<2>,
    /// Per slot \[B, 3\]; zeros where a sample has no measurement (its update is computed and discarded).
    pub measurements: Vec<Tensor<2>>,
    /// Per slot, per sample: whether it was measured.
    pub measured: Vec<Vec<bool>>,
    /// \[B, steps\]: 1 / (measurements in the chunk · B) where measured, 0 elsewhere. −Σ weights ⊙ log-likelihoods is
    /// the batch mean of the per-chunk mean innovation NLL.
    pub weights: Tensor<2>,
    pub after_impact: Vec<bool>,
    pub launcher: Option<LauncherInputs>,
}

impl Batch {
    pub fn new(chunks: &[&Chunk], with_launcher: bool, device: &Device) -> Result<Batch> {
        Batch::part_of(chunks, chunks.len(), with_launcher, device)
    }

    /// `chunks` as one part of a batch of `batch_size` chunks: the weights divide by the whole batch's size, so
    /// the parts' losses (and gradients) add up to the whole batch's.
    pub fn part_of(chunks: &[&Chunk], batch_size: usize, with_launcher: bool, device: &Device) -> Result<Batch> {
        let b = chunks.len();
        let steps = chunks.first().map_or(0, |c| c.slots.len());
        if b == 0 || chunks.iter().any(|c| c.slots.len() != steps) {
            return Err(Error::data("a batch needs at least one chunk, all of one length"));
        }
        let rows = |f: &dyn Fn(&Chunk) -> [f64; 3]| tensor(chunks.iter().flat_map(|c| f(c)).collect(), [b, 3], device);
        let measured: Vec<Vec<bool>> =
            (0..steps).map(|t| chunks.iter().map(|c| c.slots[t].is_some()).collect()).collect();
        let measurements = (0..steps).map(|t| rows(&|c: &Chunk| c.slots[t].unwrap_or([0.0; 3]))).collect();
        let mut weights = Vec::with_capacity(b * steps);
        for c in chunks {
            let share = 1.0 / (c.measured().max(1) * batch_size.max(b)) as f64;
            weights.extend(c.slots.iter().map(|s| if s.is_some() { share } else { 0.0 }));
        }
        let launcher = if with_launcher { Some(launcher_inputs(chunks, device)?) } else { None };
        Ok(Batch {
            size: b,
            steps,
            m1: rows(&|c: &Chunk| c.m1),
            m2: rows(&|c: &Chunk| c.m2),
            measurements,
            measured,
            weights: tensor(weights, [b, steps], device),
            after_impact: chunks.iter().map(|c| c.after_impact).collect(),
            launcher,
        })
    }
}

fn launcher_inputs(chunks: &[&Chunk], device: &Device) -> Result<LauncherInputs> {
    let mut motors = Vec::with_capacity(3 * chunks.len());
    let mut rotation = Vec::with_capacity(9 * chunks.len());
    for c in chunks {
        let side = c.side_info.ok_or_else(|| {
            Error::data(format!(
                "recording {} has no launcher side information; the launcher spin prior needs it on every recording",
                c.recording
            ))
        })?;
        motors.extend(motor_actuations(&side));
        rotation.extend(launch_rotation(&side).iter().flatten());
    }
    let b = chunks.len();
    Ok(LauncherInputs { motors: tensor(motors, [b, 3], device), rotation: tensor(rotation, [b, 3, 3], device) })
}
