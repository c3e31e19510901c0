//! The joint forward step g(z) of eq. 6.22 with its Jacobian (appendix C.2), as an [`EkfModel`].

use nalgebra::{Matrix6, SMatrix};

use super::flight::{acceleration_jacobian, free_dt_derivative, free_jacobian, free_step};
use super::impact::{apply_impact, crosses_table, time_of_impact};
use super::params::BallModelParams;
use super::state::{BallBelief, BallState, Phase, MEAS_DIM, P, STATE_DIM, V};
use super::BallModelError;
use crate::filtering::{EkfModel, Mat, Vector};

type StateMat = Mat<STATE_DIM, STATE_DIM>;

/// The ball EKF model with its parameters unpacked into the matrices the filter multiplies with.
#[derive(Clone, Debug)]
pub struct BallModel {
    params: BallModelParams,
    c: Matrix6<f64>,
    q: StateMat,
    r: Mat<MEAS_DIM, MEAS_DIM>,
}

impl BallModel {
    pub fn new(params: BallModelParams) -> Result<Self, BallModelError> {
        params.validate()?;
        let c = Matrix6::from_fn(|i, j| params.c[i][j]);
        let q = StateMat::from_diagonal(&Vector::<STATE_DIM>::from(params.q_diag));
        let r = Mat::<MEAS_DIM, MEAS_DIM>::from_diagonal(&Vector::<MEAS_DIM>::from(params.r_diag));
        Ok(BallModel { params, c, q, r })
    }

    pub fn params(&self) -> &BallModelParams {
        &self.params
    }

    /// Whether the step from z hits the table: it would cross the plane and the trajectory has not bounced yet.
    pub fn impacts(&self, z: &BallState, phase: Phase) -> bool {
        phase == Phase::BeforeImpact && crosses_table(z, &self.params.physics)
    }

    /// g(z): the next state and phase.
    pub fn step(&self, z: &BallState, phase: Phase) -> (BallState, Phase) {
        let phys = &self.params.physics;
        if !self.impacts(z, phase) {
            return (free_step(z, phys.dt, phys), phase);
        }
        let t = time_of_impact(z, phys).dt;
        let after = apply_impact(&free_step(z, t, phys), &self.c);
        (free_step(&after, phys.dt - t, phys), Phase::AfterImpact)
    }

    /// g(z) with J = ∂g/∂z. In the impact branch the time of impact depends on z, so (C.2)
    /// J = J_z(z⁺, Δrem) C' (J_z(z, Δimp) + J_Δt(z) ∂Δimp/∂z) − J_Δt(z⁺, Δrem) ∂Δimp/∂z, using ∂Δrem/∂z = −∂Δimp/∂z.
    pub fn step_with_jacobian(&self, z: &BallState, phase: Phase) -> (BallState, StateMat, Phase) {
        let phys = &self.params.physics;
        if !self.impacts(z, phase) {
            return (free_step(z, phys.dt, phys), free_jacobian(z, phys.dt, phys), phase);
        }
        let toi = time_of_impact(z, phys);
        let d_toi = toi.gradient();
        let remaining = phys.dt - toi.dt;

        // J2.2 = ∂z⁻/∂z, then J2 = C' J2.2 (rows of v and ω mixed by C).
        let mut j_before = free_jacobian(z, toi.dt, phys) + free_dt_derivative(z, phys) * d_toi;
        let mixed = self.c * j_before.fixed_rows::<6>(V);
        j_before.fixed_rows_mut::<6>(V).copy_from(&mixed);

        let z_plus = apply_impact(&free_step(z, toi.dt, phys), &self.c);
        let jac = free_jacobian(&z_plus, remaining, phys) * j_before - free_dt_derivative(&z_plus, phys) * d_toi;
        (free_step(&z_plus, remaining, phys), jac, Phase::AfterImpact)
    }

    /// F P Fᵀ for a free-flight step without forming F. F differs from the identity only in its first six rows
    /// (∂p/∂v = dt·I and the velocity rows I + dt·∂a/∂v, dt·∂a/∂(ω, a_d, a_m)), so with U = F[0..6, :] P the result
    /// is P outside the first six rows and columns, U's last five columns (and their transpose) beside them, and
    /// U F[0..6, :]ᵀ in the corner: about a sixth of the dense pair of 11³ products. `p` must be symmetric.
    fn propagate_free_flight(&self, z: &BallState, p: &StateMat) -> StateMat {
        let dt = self.params.physics.dt;
        let b = acceleration_jacobian(z, &self.params.physics) * dt;
        let mut u = SMatrix::<f64, 6, STATE_DIM>::zeros();
        for j in 0..STATE_DIM {
            for i in 0..3 {
                u[(P + i, j)] = p[(P + i, j)] + dt * p[(V + i, j)];
                u[(V + i, j)] = p[(V + i, j)];
            }
            for k in 0..8 {
                let pk = p[(V + k, j)];
                for i in 0..3 {
                    u[(V + i, j)] += b[(i, k)] * pk;
                }
            }
        }
        let mut out = *p;
        for j in 6..STATE_DIM {
            for i in 0..6 {
                out[(i, j)] = u[(i, j)];
                out[(j, i)] = u[(i, j)];
            }
        }
        let mut corner = SMatrix::<f64, 6, 6>::zeros();
        for i in 0..6 {
            for j in 0..3 {
                corner[(i, P + j)] = u[(i, P + j)] + dt * u[(i, V + j)];
                let mut s = u[(i, V + j)];
                for k in 0..8 {
                    s += u[(i, V + k)] * b[(j, k)];
                }
                corner[(i, V + j)] = s;
            }
        }
        out.fixed_view_mut::<6, 6>(0, 0).copy_from(&((corner + corner.transpose()) * 0.5));
        out
    }
}

impl EkfModel<STATE_DIM, MEAS_DIM> for BallModel {
    type Mode = Phase;

    fn predict(&self, x: &BallState, mode: &mut Phase) -> (BallState, StateMat) {
        let (next, jac, phase) = self.step_with_jacobian(x, *mode);
        *mode = phase;
        (next, jac)
    }

    fn measure(&self, x: &BallState) -> (Vector<MEAS_DIM>, Mat<MEAS_DIM, STATE_DIM>) {
        (x.fixed_rows::<3>(P).into_owned(), Mat::<MEAS_DIM, STATE_DIM>::identity())
    }

    fn process_noise(&self, _: &BallState) -> StateMat {
        self.q
    }

    fn measurement_noise(&self) -> Mat<MEAS_DIM, MEAS_DIM> {
        self.r
    }

    fn predict_mean(&self, x: &BallState, mode: &mut Phase) -> BallState {
        let (next, phase) = self.step(x, *mode);
        *mode = phase;
        next
    }

    fn predict_belief(&self, belief: &BallBelief) -> BallBelief {
        if self.impacts(&belief.mean, belief.mode) {
            // Once per trajectory: the dense product with the full impact Jacobian is cheap enough.
            let (mean, f, mode) = self.step_with_jacobian(&belief.mean, belief.mode);
            let cov = f * belief.cov * f.transpose() + self.q;
            return BallBelief { mean, cov: (cov + cov.transpose()) * 0.5, mode };
        }
        let (mean, mode) = self.step(&belief.mean, belief.mode);
        // Q is diagonal, so adding it keeps the exact symmetry of the structured product.
        let cov = self.propagate_free_flight(&belief.mean, &belief.cov) + self.q;
        BallBelief { mean, cov, mode }
    }
}
