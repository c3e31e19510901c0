//! The batched initial belief p(z_τ(2) | m_τ(1), m_τ(2)) (6.4.3), the tensor counterpart of
//! `models::ball::initial_belief` with chunks that start one frame apart.

use burn::tensor::{Device, Tensor};

use super::batch::{Batch, LauncherInputs};
use super::device::{row_mask, zeros};
use super::linalg::{diag_embed, symmetrize};
use super::params::Resolved;
use super::spin_net::SpinNet;
use crate::error::{Error, Result};
use crate::models::ball::BallPhysics;

/// Mean \[B, 11\] and covariance \[B, 11, 11\] at m_2: p = m_2, v by finite difference, a_d, a_m at their learned
/// means, and the spin from the broad prior (no network) or from the launcher network.
pub fn initial_belief(
    batch: &Batch,
    p: &Resolved,
    spin_net: Option<&SpinNet>,
    physics: &BallPhysics,
    device: &Device,
) -> Result<(Tensor<2>, Tensor<3>)> {
    let b = batch.size;
    let per_sample = |t: Tensor<1>| {
        let n = t.dims()[0];
        t.reshape([1, n]).repeat_dim(0, b)
    };
    let velocity = (batch.m2.clone() - batch.m1.clone()).div_scalar(physics.dt);
    let coefficients = per_sample(Tensor::cat(vec![p.a_d0.clone(), p.a_m0.clone()], 0));
    let position_velocity = Tensor::cat(vec![p.init_pos.clone(), p.init_vel.clone()], 0);
    let coefficient_vars = Tensor::cat(vec![p.a_d_var.clone(), p.a_m_var.clone()], 0);

    let (spin_mean, cov) = match (spin_net, &batch.launcher) {
        (None, _) => {
            // Broad prior: ω ~ N(0, diag([σ_ω]⊕)) whether or not the chunk starts after the bounce.
            let vars = Tensor::cat(vec![position_velocity, p.init_spin.clone(), coefficient_vars], 0);
            (zeros([b, 3], device), diag_embed(per_sample(vars)))
        }
        (Some(net), Some(launcher)) => {
            let (mean, spin_cov) = launcher_spin(net, launcher, batch, p, device);
            let vars = Tensor::cat(vec![position_velocity, zeros([3], device), coefficient_vars], 0);
            let padded = Tensor::cat(
                vec![
                    zeros([b, 6, 11], device),
                    Tensor::cat(vec![zeros([b, 3, 6], device), spin_cov, zeros([b, 3, 2], device)], 2),
                    zeros([b, 2, 11], device),
                ],
                1,
            );
            (mean, diag_embed(per_sample(vars)) + padded)
        }
        (Some(_), None) => {
            return Err(Error::data("the launcher spin prior needs a batch built with side information"))
        }
    };
    let mean = Tensor::cat(vec![batch.m2.clone(), velocity, spin_mean, coefficients], 1);
    Ok((mean, cov))
}

/// ω = R ω→x, Σ_ω = R Σ→x Rᵀ before the bounce; ω = 0, Σ_ω = R diag(\[σ_ω,ai\]⊕) Rᵀ after it (rotated as in the
/// authors' release, see `SpinPrior::Launcher`).
fn launcher_spin(
    net: &SpinNet,
    launcher: &LauncherInputs,
    batch: &Batch,
    p: &Resolved,
    device: &Device,
) -> (Tensor<2>, Tensor<3>) {
    let b = batch.size;
    let (canonical_mean, canonical_var) = net.forward(launcher.motors.clone());
    let after = row_mask(&batch.after_impact, [b, 3], device);
    let var =
        canonical_var.mask_where(after.clone(), p.init_spin_after_impact.clone().reshape([1, 3]).repeat_dim(0, b));
    let r = launcher.rotation.clone();
    let mean = r.clone().matmul(canonical_mean.unsqueeze_dim(2)).reshape([b, 3]).mask_fill(after, 0.0);
    let cov = symmetrize(r.clone().matmul(diag_embed(var)).matmul(r.swap_dims(1, 2)));
    (mean, cov)
}
