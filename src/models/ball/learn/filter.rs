//! The batched, differentiable EKF over a batch of chunks and the training loss of eq. 6.24.

use burn::tensor::{Device, Tensor};

use super::batch::Batch;
use super::device::{eye, row_mask, zeros};
use super::flight::Consts;
use super::init::initial_belief;
use super::linalg::diag_embed;
use super::params::BallParamsModule;
use super::predict::{predict, PredictInputs};
use super::update::update;
use crate::error::Result;
use crate::models::ball::{BallPhysics, Phase};

/// log N(m_n | μ_n|1:n−1, S_n) \[B, steps\] for every slot, 0 where a slot has no measurement.
pub fn log_likelihoods(
    model: &BallParamsModule,
    batch: &Batch,
    physics: &BallPhysics,
    device: &Device,
) -> Result<Tensor<2>> {
    let b = batch.size;
    let p = model.resolve();
    let consts = Consts::new(b, physics, device);
    let inputs = PredictInputs {
        consts: &consts,
        c_full: impact_map(p.c.clone(), device),
        q: diag_embed(p.q.clone().reshape([1, 11])),
        physics,
        device,
    };
    let r = diag_embed(p.r.clone().reshape([1, 3]));
    let (mut mean, mut cov) = initial_belief(batch, &p, model.spin_net.as_ref(), physics, device)?;
    let mut phases: Vec<Phase> =
        batch.after_impact.iter().map(|&a| if a { Phase::AfterImpact } else { Phase::BeforeImpact }).collect();
    let mut per_slot = Vec::with_capacity(batch.steps);
    for (m, measured) in batch.measurements.iter().zip(&batch.measured) {
        (mean, cov) = predict(mean, cov, &mut phases, &inputs);
        if !measured.contains(&true) {
            per_slot.push(zeros([b], device));
            continue;
        }
        let (mean_u, cov_u, ll) = update(mean.clone(), cov.clone(), m.clone(), &r);
        if measured.contains(&false) {
            // A missing measurement is a prediction alone.
            mean = mean.mask_where(row_mask(measured, [b, 11], device), mean_u);
            cov = cov.mask_where(row_mask(measured, [b, 11, 11], device), cov_u);
            let missing: Vec<bool> = measured.iter().map(|m| !m).collect();
            per_slot.push(ll.mask_fill(row_mask(&missing, [b], device), 0.0));
        } else {
            (mean, cov) = (mean_u, cov_u);
            per_slot.push(ll);
        }
    }
    Ok(Tensor::stack(per_slot, 1))
}

/// −log p(m_3:N | m_1, m_2) per measurement, averaged over each chunk's measurements and then over the batch.
pub fn chunk_loss(
    model: &BallParamsModule,
    batch: &Batch,
    physics: &BallPhysics,
    device: &Device,
) -> Result<Tensor<1>> {
    Ok((log_likelihoods(model, batch, physics, device)? * batch.weights.clone()).sum().neg())
}

/// C' = blockdiag(I₃, C, 1, 1).
pub(super) fn impact_map(c: Tensor<2>, device: &Device) -> Tensor<2> {
    Tensor::cat(
        vec![
            Tensor::cat(vec![eye(3, device), zeros([3, 8], device)], 1),
            Tensor::cat(vec![zeros([6, 3], device), c, zeros([6, 2], device)], 1),
            Tensor::cat(vec![zeros([2, 9], device), eye(2, device)], 1),
        ],
        0,
    )
}
