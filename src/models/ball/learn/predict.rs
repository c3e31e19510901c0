//! The batched EKF prediction: μ ← g(μ), Σ ← F Σ Fᵀ + Q with per-sample branches for the one table impact.

use burn::tensor::{Device, Tensor};

use super::device::{row_mask, values};
use super::flight::{flight, free_jacobian, free_step, Consts, StepLen};
use super::impact::{impact_step, ImpactPlan};
use super::linalg::symmetrize;
use crate::models::ball::{BallPhysics, Phase};

/// Per-forward-pass inputs of the prediction that do not change between steps.
pub struct PredictInputs<'a> {
    pub consts: &'a Consts,
    /// C' = blockdiag(I₃, C, 1, 1) \[11, 11\].
    pub c_full: Tensor<2>,
    /// diag(Q) as \[1, 11, 11\].
    pub q: Tensor<3>,
    pub physics: &'a BallPhysics,
    pub device: &'a Device,
}

/// One prediction step; `phases` advances for the samples that bounce.
pub fn predict(mean: Tensor<2>, cov: Tensor<3>, phases: &mut [Phase], inp: &PredictInputs) -> (Tensor<2>, Tensor<3>) {
    let (k, physics) = (inp.consts, inp.physics);
    let dt = StepLen::Fixed(physics.dt);
    let f = flight(&mean, k, physics);
    let mut next = free_step(&mean, &f, &dt);
    let mut jac = free_jacobian(&f, &dt, k);
    // Reading the means back costs a sync; after every sample has bounced no decision is left to take.
    if phases.contains(&Phase::BeforeImpact) {
        let plan = ImpactPlan::new(&values(&mean), phases, physics);
        if plan.any() {
            let (next_imp, jac_imp) = impact_step(&mean, &f, &inp.c_full, &plan, k, physics, inp.device);
            next = next.mask_where(row_mask(&plan.impacting, [k.batch, 11], inp.device), next_imp);
            jac = jac.mask_where(row_mask(&plan.impacting, [k.batch, 11, 11], inp.device), jac_imp);
            for (phase, hit) in phases.iter_mut().zip(&plan.impacting) {
                if *hit {
                    *phase = Phase::AfterImpact;
                }
            }
        }
    }
    let cov = symmetrize(jac.clone().matmul(cov).matmul(jac.swap_dims(1, 2)) + inp.q.clone());
    (next, cov)
}
