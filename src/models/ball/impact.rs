//! The table impact inside one step (6.4.2, eq. 6.22): detection, time of impact, the linear map C' and the
//! derivative of the time of impact with respect to the state (appendix C.2, term J2.2.3).

use nalgebra::{Matrix6, SMatrix};

use super::params::BallPhysics;
use super::state::{BallState, P, V};

/// Height of the ball's lower edge above the table assumed when it starts a step at or below the plane. Without
/// it the gravity-only quadratic can have no real root; the authors' release clamps the same way.
const MIN_HEIGHT_ABOVE_TABLE: f64 = 1e-4;

const PZ: usize = P + 2;
const VZ: usize = V + 2;

/// Whether the full free-flight step would end with the ball's lower edge below the table (condition of eq. 6.22).
/// The Euler position update uses only the current velocity, so no acceleration is needed to decide.
pub(super) fn crosses_table(z: &BallState, phys: &BallPhysics) -> bool {
    z[PZ] + phys.dt * z[VZ] - phys.ball_radius < phys.table_z
}

/// Δ_imp ∈ [0, ΔT] and its gradient, which has entries only for p_z and v_z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ImpactTime {
    pub dt: f64,
    pub d_pz: f64,
    pub d_vz: f64,
}

impl ImpactTime {
    pub(super) fn gradient(&self) -> SMatrix<f64, 1, 11> {
        let mut g = SMatrix::<f64, 1, 11>::zeros();
        g[PZ] = self.d_pz;
        g[VZ] = self.d_vz;
        g
    }
}

/// Time until the lower edge reaches the table under gravity alone, p_z − r + v_z t − ½ g t² = z_table:
/// Δ_imp = −(v_z + √(v_z² + 2 g_z h)) / g_z with g_z = −g and h = −((p_z − r) − z_table) (6.4.2).
///
/// Gravity alone (no drag or Magnus) keeps the root real and, whenever the Euler step crosses the plane from
/// above, inside the step: the gravity parabola lies below the Euler line. Two clamps make it total: h ≤ −1e-4
/// (ball starting at or under the plane) and Δ_imp ≤ ΔT (possible only then). A clamped input has zero derivative,
/// so the gradient is that of the function actually evaluated.
pub(super) fn time_of_impact(z: &BallState, phys: &BallPhysics) -> ImpactTime {
    let g_z = -phys.gravity;
    let vz = z[VZ];
    let h_raw = -((z[PZ] - phys.ball_radius) - phys.table_z);
    let h_clamped = h_raw > -MIN_HEIGHT_ABOVE_TABLE;
    let h = if h_clamped { -MIN_HEIGHT_ABOVE_TABLE } else { h_raw };
    let root = (vz * vz + 2.0 * g_z * h).sqrt();
    let t = -(vz + root) / g_z;
    if t > phys.dt {
        return ImpactTime { dt: phys.dt, d_pz: 0.0, d_vz: 0.0 };
    }
    // ∂Δ/∂p_z = 1/√(·) and ∂Δ/∂v_z = −(1 + v_z/√(·))/g_z (C.2).
    let d_pz = if h_clamped { 0.0 } else { 1.0 / root };
    let d_vz = -(1.0 + vz / root) / g_z;
    ImpactTime { dt: t, d_pz, d_vz }
}

/// z⁺ = C' z⁻ with C' = blockdiag(I₃, C, 1, 1): C maps (v, ω) and leaves position and coefficients alone.
pub(super) fn apply_impact(z: &BallState, c: &Matrix6<f64>) -> BallState {
    let mut out = *z;
    let vw = c * z.fixed_rows::<6>(V);
    out.fixed_rows_mut::<6>(V).copy_from(&vw);
    out
}
