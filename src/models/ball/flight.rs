//! Free flight g_free(z, Δt) (eq. 6.21) and its derivatives with respect to the state (eq. C.1-C.5) and to the
//! step length (eq. C.6).

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::params::BallPhysics;
use super::state::{BallState, AD, AM, P, STATE_DIM, V, W};
use crate::filtering::Mat;

/// ∂a/∂(v, ω, a_d, a_m): the only non-trivial block of the free-flight Jacobian, shared by the dense Jacobian and
/// the structured covariance propagation.
pub(super) type AccelJacobian = SMatrix<f64, 3, 8>;

/// v̇ = −k_d ‖v‖ v + k_m ω × v + g (eq. 6.18).
pub(super) fn acceleration(z: &BallState, phys: &BallPhysics) -> Vector3<f64> {
    let v = z.fixed_rows::<3>(V);
    let w = z.fixed_rows::<3>(W);
    let (kd, km) = coefficients(z, phys);
    let mut a = -kd * v.norm() * v + km * w.cross(&v);
    a.z -= phys.gravity;
    a
}

fn coefficients(z: &BallState, phys: &BallPhysics) -> (f64, f64) {
    (z[AD] * z[AD] + phys.coeff_offset, z[AM] * z[AM] + phys.coeff_offset)
}

/// One Euler step of length `dt`; spin and coefficients are constant in flight.
pub(super) fn free_step(z: &BallState, dt: f64, phys: &BallPhysics) -> BallState {
    let a = acceleration(z, phys);
    let mut out = *z;
    for i in 0..3 {
        out[P + i] += dt * z[V + i];
        out[V + i] += dt * a[i];
    }
    out
}

/// ∂a/∂(v, ω, a_d, a_m) at z. The exact derivative uses k = a² + ε; C.2 writes a² in eq. C.2-C.3, which drops ε.
pub(super) fn acceleration_jacobian(z: &BallState, phys: &BallPhysics) -> AccelJacobian {
    let v = z.fixed_rows::<3>(V).into_owned();
    let w = z.fixed_rows::<3>(W).into_owned();
    let (kd, km) = coefficients(z, phys);
    let speed = v.norm();
    // ∂(‖v‖v)/∂v = ‖v‖ I + v vᵀ/‖v‖, which tends to 0 as v → 0 (‖v‖v is quadratic there).
    let d_norm_v = if speed > 0.0 { Matrix3::identity() * speed + v * v.transpose() / speed } else { Matrix3::zeros() };
    let mut j = AccelJacobian::zeros();
    // ω × v = [ω]ₓ v = −[v]ₓ ω.
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-kd * d_norm_v + km * w.cross_matrix()));
    j.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-km * v.cross_matrix()));
    j.fixed_view_mut::<3, 1>(0, 6).copy_from(&(-2.0 * z[AD] * speed * v));
    j.fixed_view_mut::<3, 1>(0, 7).copy_from(&(2.0 * z[AM] * w.cross(&v)));
    j
}

/// J_z(z, Δt) = ∂g_free(z, Δt)/∂z (eq. C.1).
pub(super) fn free_jacobian(z: &BallState, dt: f64, phys: &BallPhysics) -> Mat<STATE_DIM, STATE_DIM> {
    let mut j = Mat::<STATE_DIM, STATE_DIM>::identity();
    for i in 0..3 {
        j[(P + i, V + i)] = dt;
    }
    let mut rows = j.fixed_view_mut::<3, 8>(V, V);
    rows += acceleration_jacobian(z, phys) * dt;
    j
}

/// J_Δt(z) = ∂g_free(z, Δt)/∂Δt = (v, a, 0, 0, 0) (eq. C.6); independent of Δt for an Euler step.
pub(super) fn free_dt_derivative(z: &BallState, phys: &BallPhysics) -> BallState {
    let a = acceleration(z, phys);
    let mut d = BallState::zeros();
    for i in 0..3 {
        d[P + i] = z[V + i];
        d[V + i] = a[i];
    }
    d
}
