//! The filter's starting belief p(z_τ(2) | m_τ(1), m_τ(2)) from the first two available measurements (6.4.3).

use nalgebra::{Matrix3, Vector3};

use super::params::BallModelParams;
use super::state::{BallBelief, BallState, Phase, AD, AM, P, STATE_DIM, V, W};
use super::BallModelError;
use crate::filtering::Mat;

/// Where the belief over the initial spin comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SpinPrior {
    /// No launcher information (the thesis' ablation): ω ~ N(0, diag(\[σ_ω\]⊕)) in the world frame, before or after
    /// the impact.
    Uninformed,
    /// Launcher information: the spin network's "canonical" moments for a launch along +x (C.1.3) and the rotation
    /// R_rot(φ_f + φ_l, θ_l) from that frame to the world, giving ω = R ω→x, Σ_ω = R Σ→x Rᵀ (6.4.3). After the impact
    /// the spin no longer relates to the launcher: ω = 0, Σ_ω = R diag(\[σ_ω,ai\]⊕) Rᵀ. The thesis writes the latter
    /// unrotated; the authors' release rotates it, and Table C.2's σ_ω,ai was learned that way.
    Launcher { rotation: [[f64; 3]; 3], canonical_mean: [f64; 3], canonical_cov: [[f64; 3]; 3] },
}

/// Initial belief at the time of `m2`: p = m2, v = (m2 − m1)/(ΔT · frame_gap) with frame_gap = τ(2) − τ(1) the
/// number of camera frames between the two measurements (dropouts make it > 1), spin from `spin`, a_d and a_m from
/// their learned means; covariance blockdiag(Σ_p, Σ_v, Σ_ω, σ_ad, σ_am). `after_impact` says m2 was taken after the
/// bounce; the belief then starts in [`Phase::AfterImpact`] so the model adds no second bounce.
pub fn initial_belief(
    params: &BallModelParams,
    m1: [f64; 3],
    m2: [f64; 3],
    frame_gap: u32,
    after_impact: bool,
    spin: &SpinPrior,
) -> Result<BallBelief, BallModelError> {
    if frame_gap == 0 {
        return Err(BallModelError::ZeroFrameGap);
    }
    if m1.iter().chain(&m2).any(|x| !x.is_finite()) {
        return Err(BallModelError::NonFiniteInitialValue { what: "measurement" });
    }
    let (spin_mean, spin_cov) = spin_moments(params, after_impact, spin)?;
    let elapsed = params.physics.dt * f64::from(frame_gap);

    let mut mean = BallState::zeros();
    let mut cov = Mat::<STATE_DIM, STATE_DIM>::zeros();
    for i in 0..3 {
        mean[P + i] = m2[i];
        mean[V + i] = (m2[i] - m1[i]) / elapsed;
        mean[W + i] = spin_mean[i];
        cov[(P + i, P + i)] = params.init_pos_var[i];
        cov[(V + i, V + i)] = params.init_vel_var[i];
    }
    mean[AD] = params.a_d0;
    mean[AM] = params.a_m0;
    cov.fixed_view_mut::<3, 3>(W, W).copy_from(&spin_cov);
    cov[(AD, AD)] = params.a_d_var;
    cov[(AM, AM)] = params.a_m_var;
    let mode = if after_impact { Phase::AfterImpact } else { Phase::BeforeImpact };
    Ok(BallBelief { mean, cov, mode })
}

fn spin_moments(
    params: &BallModelParams,
    after_impact: bool,
    spin: &SpinPrior,
) -> Result<(Vector3<f64>, Matrix3<f64>), BallModelError> {
    let SpinPrior::Launcher { rotation, canonical_mean, canonical_cov } = spin else {
        return Ok((Vector3::zeros(), Matrix3::from_diagonal(&params.init_spin_var.into())));
    };
    let mut entries = rotation.iter().flatten().chain(canonical_mean).chain(canonical_cov.iter().flatten());
    if entries.any(|x| !x.is_finite()) {
        return Err(BallModelError::NonFiniteInitialValue { what: "launcher spin prior" });
    }
    let r = Matrix3::from_fn(|i, j| rotation[i][j]);
    let (mean, cov) = if after_impact {
        (Vector3::zeros(), Matrix3::from_diagonal(&params.init_spin_var_after_impact.into()))
    } else {
        (r * Vector3::from(*canonical_mean), Matrix3::from_fn(|i, j| canonical_cov[i][j]))
    };
    let rotated = r * cov * r.transpose();
    // Symmetrized so that rounding in R Σ Rᵀ (or a slightly asymmetric input) cannot leave the belief asymmetric.
    Ok((mean, (rotated + rotated.transpose()) * 0.5))
}
