//! The batched impact step of eq. 6.22 with its Jacobian (C.2), the tensor counterpart of
//! `models::ball::model::step_with_jacobian`'s impact branch.
//!
//! Which samples bounce in a step, and which clamps of the time of impact are active, are discrete decisions:
//! they are taken on the host from the current means with the reference model's own tests, so both filters branch
//! identically, and enter the tensors as masks. Samples outside the branch are computed with harmless stand-in
//! values (so no NaN reaches a masked-out gradient) and discarded.

use burn::tensor::{Device, Tensor};

use super::device::{row_mask, tensor};
use super::flight::{flight, free_jacobian, free_step, Consts, Flight, StepLen};
use crate::models::ball::impact::crosses_table;
use crate::models::ball::{BallPhysics, BallState, Phase};

/// Height of the lower edge above the table assumed for a ball starting a step at or below the plane: the clamp
/// of `models::ball::impact::time_of_impact`, which keeps the gravity-only quadratic solvable.
const MIN_HEIGHT_ABOVE_TABLE: f64 = 1e-4;

/// Host-side decisions for one step.
pub struct ImpactPlan {
    pub impacting: Vec<bool>,
    /// h was clamped to −1e-4 (∂Δ_imp/∂p_z = 0).
    pub clamped_height: Vec<bool>,
    /// Δ_imp came out beyond the step and was cut to ΔT (zero gradient).
    pub capped: Vec<bool>,
}

impl ImpactPlan {
    /// Decides from the means `x` (row-major \[B, 11\]) which samples hit the table in this step.
    pub fn new(x: &[f64], phases: &[Phase], physics: &BallPhysics) -> Self {
        let n = phases.len();
        let mut plan = ImpactPlan { impacting: vec![false; n], clamped_height: vec![false; n], capped: vec![false; n] };
        for (i, phase) in phases.iter().enumerate() {
            let z = BallState::from_row_slice(&x[11 * i..11 * i + 11]);
            if *phase != Phase::BeforeImpact || !crosses_table(&z, physics) {
                continue;
            }
            plan.impacting[i] = true;
            let (pz, vz) = (z[2], z[5]);
            let g_z = -physics.gravity;
            let h_raw = -((pz - physics.ball_radius) - physics.table_z);
            plan.clamped_height[i] = h_raw > -MIN_HEIGHT_ABOVE_TABLE;
            let h = if plan.clamped_height[i] { -MIN_HEIGHT_ABOVE_TABLE } else { h_raw };
            plan.capped[i] = -(vz + (vz * vz + 2.0 * g_z * h).sqrt()) / g_z > physics.dt;
        }
        plan
    }

    pub fn any(&self) -> bool {
        self.impacting.contains(&true)
    }
}

/// g(x) and ∂g/∂x for the impact branch, for every sample; only the rows of impacting samples are meaningful.
/// `before` holds the flight quantities at x; `c_full` is C' = blockdiag(I₃, C, 1, 1) \[11, 11\].
pub fn impact_step(
    x: &Tensor<2>,
    before: &Flight,
    c_full: &Tensor<2>,
    plan: &ImpactPlan,
    k: &Consts,
    physics: &BallPhysics,
    device: &Device,
) -> (Tensor<2>, Tensor<3>) {
    let b = k.batch;
    let shape = [b, 1];
    let not_impacting: Vec<bool> = plan.impacting.iter().map(|i| !i).collect();
    let either = |a: &[bool], c: &[bool]| -> Vec<bool> { a.iter().zip(c).map(|(x, y)| *x || *y).collect() };
    let no_time = either(&plan.capped, &not_impacting);
    let no_height = either(&plan.clamped_height, &no_time);

    let pz = x.clone().slice([0..b, 2..3]);
    let vz = x.clone().slice([0..b, 5..6]);
    let h = (pz.sub_scalar(physics.ball_radius).sub_scalar(physics.table_z))
        .neg()
        .mask_fill(row_mask(&plan.clamped_height, shape, device), -MIN_HEIGHT_ABOVE_TABLE);
    let g_z = -physics.gravity;
    let radicand =
        (vz.clone().square() + h.mul_scalar(2.0 * g_z)).mask_fill(row_mask(&not_impacting, shape, device), 1.0);
    let root = radicand.sqrt();
    // Δ_imp = −(v_z + √(v_z² + 2 g_z h)) / g_z; ∂Δ/∂p_z = 1/√(·), ∂Δ/∂v_z = −(1 + v_z/√(·))/g_z (C.2).
    let t_imp = (vz.clone() + root.clone()).div_scalar(-g_z).mask_fill(row_mask(&no_time, shape, device), physics.dt);
    let d_pz = root.clone().recip().mask_fill(row_mask(&no_height, shape, device), 0.0);
    let d_vz = (vz / root).add_scalar(1.0).div_scalar(-g_z).mask_fill(row_mask(&no_time, shape, device), 0.0);
    let unit = |i: usize| {
        let mut e = vec![0.0; 11];
        e[i] = 1.0;
        tensor(e, [1, 11], device)
    };
    let d_toi = (d_pz * unit(2) + d_vz * unit(5)).unsqueeze_dim::<3>(1);

    let at = StepLen::PerSample(Box::new(t_imp.clone()));
    let x_minus = free_step(x, before, &at);
    // J2 = C' (J_z(z, Δimp) + J_Δt(z) ∂Δimp/∂z).
    let j_before = free_jacobian(before, &at, k) + before.rate.clone().unsqueeze_dim::<3>(2).matmul(d_toi.clone());
    let j_before = c_full.clone().unsqueeze::<3>().matmul(j_before);
    let x_plus = x_minus.matmul(c_full.clone().transpose());

    let after = flight(&x_plus, k, physics);
    let rest = StepLen::PerSample(Box::new(t_imp.neg().add_scalar(physics.dt)));
    let next = free_step(&x_plus, &after, &rest);
    // J = J_z(z⁺, Δrem) J2 − J_Δt(z⁺, Δrem) ∂Δimp/∂z, since ∂Δrem/∂z = −∂Δimp/∂z.
    let jac = free_jacobian(&after, &rest, k).matmul(j_before) - after.rate.unsqueeze_dim::<3>(2).matmul(d_toi);
    (next, jac)
}
