//! Free flight between table contacts: gravity, quadratic drag and the Magnus effect,
//! v' = −k_d‖v‖v + k_m ω×v − g e_z, p' = v, ω' = 0 (thesis eq. 6.18, lines 4548-4556; discrete form eq. 6.21).
//!
//! The EKF of chapter 6 integrates this ODE with one explicit Euler step per camera frame (1/180 s). The
//! simulator is the "truth" that model is judged against, so it integrates the same ODE with classical RK4 at
//! a step ten times finer: its own error is then several orders of magnitude below the Euler model's.

use serde::{Deserialize, Serialize};

use super::vec3::{cross, norm, Vec3};

/// Gravitational acceleration in m/s², g = (0, 0, −9.802) (thesis line 4555; `gravity_z` in the authors'
/// ball_model/differentiable_simulator/simulator.py).
pub const GRAVITY: f64 = 9.802;

/// ε in k_d = a_d² + ε, k_m = a_m² + ε (thesis lines 4575-4577; `kd_km_offset = 0.05` in the authors'
/// ball_model/training/train_model_ekf.py).
pub const KD_KM_OFFSET: f64 = 0.05;

/// Learned initial mean of a_d, Table C.2 (thesis line 6732), model trained with launch information.
pub const LEARNED_A_D: f64 = 0.2168;

/// Learned initial mean of a_m, Table C.2 (thesis line 6733). It collapsed to ≈ 0, so k_m sits at ε.
pub const LEARNED_A_M: f64 = 1.22e-5;

/// Ground-truth drag coefficient k_d = a_d² + ε ≈ 0.0970 1/m.
pub const K_D: f64 = LEARNED_A_D * LEARNED_A_D + KD_KM_OFFSET;

/// Ground-truth Magnus coefficient k_m = a_m² + ε ≈ 0.0500. Only the product k_m·ω is identifiable (thesis
/// lines 4984-4990), so spins in this simulator are in the learned model's units, not physical rad/s.
pub const K_M: f64 = LEARNED_A_M * LEARNED_A_M + KD_KM_OFFSET;

/// Ball state (p, v, ω): position of the centre (m), velocity (m/s), spin (learned units, see `K_M`).
pub type BallState = [f64; 9];

/// Coefficients of the free-flight ODE. `Default` gives the thesis' learned values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightParams {
    pub k_d: f64,
    pub k_m: f64,
    pub gravity: f64,
}

impl Default for FlightParams {
    fn default() -> Self {
        FlightParams { k_d: K_D, k_m: K_M, gravity: GRAVITY }
    }
}

impl FlightParams {
    pub fn acceleration(&self, v: &Vec3, w: &Vec3) -> Vec3 {
        let speed = norm(v);
        let magnus = cross(w, v);
        [
            -self.k_d * speed * v[0] + self.k_m * magnus[0],
            -self.k_d * speed * v[1] + self.k_m * magnus[1],
            -self.k_d * speed * v[2] + self.k_m * magnus[2] - self.gravity,
        ]
    }

    pub fn derivative(&self, s: &BallState) -> BallState {
        let a = self.acceleration(&[s[3], s[4], s[5]], &[s[6], s[7], s[8]]);
        [s[3], s[4], s[5], a[0], a[1], a[2], 0.0, 0.0, 0.0]
    }

    /// One classical fourth-order Runge-Kutta step of length `h`.
    pub fn rk4_step(&self, s: &BallState, h: f64) -> BallState {
        let k1 = self.derivative(s);
        let k2 = self.derivative(&axpy(s, &k1, 0.5 * h));
        let k3 = self.derivative(&axpy(s, &k2, 0.5 * h));
        let k4 = self.derivative(&axpy(s, &k3, h));
        let mut out = *s;
        for i in 0..9 {
            out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        out
    }

    /// The EKF's own discretization (eq. 6.21): kept here so tests can show how much finer the truth is.
    pub fn euler_step(&self, s: &BallState, h: f64) -> BallState {
        axpy(s, &self.derivative(s), h)
    }

    /// Integrates `duration` seconds of free flight (no table) in `steps` equal RK4 steps.
    pub fn integrate(&self, s: &BallState, duration: f64, steps: usize) -> BallState {
        let h = duration / steps as f64;
        (0..steps).fold(*s, |state, _| self.rk4_step(&state, h))
    }
}

fn axpy(s: &BallState, d: &BallState, h: f64) -> BallState {
    let mut out = *s;
    for i in 0..9 {
        out[i] += h * d[i];
    }
    out
}
