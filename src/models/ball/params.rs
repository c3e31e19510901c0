//! Parameters Ψ of the ball EKF (6.4.3) and the fixed physical constants of the setup.
//!
//! Variances are stored as variances, i.e. after the thesis' softplus \[σ\]⊕ = log(1 + eˢ) + 1e-6: that is how
//! Tables C.1 and C.2 state them, and a trainer that optimizes the unconstrained σ converts at its own boundary.
//!
//! The values are the model's own transcription of the thesis, not the simulator's: the simulator adopts the
//! learned model as its ground truth, but may be retuned without moving the model's published defaults. A test
//! (`models/ball/tests/model.rs`) holds the two transcriptions equal where the simulator is meant to agree.

use serde::{Deserialize, Serialize};

use super::BallModelError;
use crate::util::domain::Domain;

/// Entries of the impact matrix C (eq. 6.26): the thesis' trained ones lie within ±1.5; ten would multiply a
/// velocity or spin tenfold at every bounce.
const IMPACT_COEFFICIENT: Domain = Domain::closed(-10.0, 10.0);
/// Every variance of the model (positions in m², velocities in (m/s)², spins and coefficients in their units²):
/// positive, from far below any camera's noise to far above any flight's spread.
const VARIANCE: Domain = Domain::closed(1e-20, 1e6);
/// a_d and a_m, whose squares (plus ε) are the drag and Magnus coefficients: the thesis' are 0.22 and 1.2e-5;
/// at 10 drag would stop a 20 m/s ball within a frame.
const COEFFICIENT_ROOT: Domain = Domain::closed(-10.0, 10.0);

/// Constants of the recording setup, not learned.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallPhysics {
    /// Step ΔT = 1/180 s: the cameras run at 180 Hz (6.4.2).
    pub dt: f64,
    /// |g| in m/s², acting along −z (6.4.1).
    pub gravity: f64,
    /// ε in k_d = a_d² + ε, k_m = a_m² + ε (6.4.2).
    pub coeff_offset: f64,
    /// Height z_table of the table surface (centre (0.1325, 1.7425, −0.461) in the authors' release).
    pub table_z: f64,
    pub ball_radius: f64,
}

impl Default for BallPhysics {
    fn default() -> Self {
        // The 180 Hz camera rate (thesis lines 4591-4592); g (line 4555); ε (lines 4575-4577); z_table and the
        // radius from `IDEAL_TABLE` and `RADIUS_OF_BALL` in the authors' ball_model/data/__init__.py.
        BallPhysics { dt: 1.0 / 180.0, gravity: 9.802, coeff_offset: 0.05, table_z: -0.461, ball_radius: 0.02 }
    }
}

/// The learned parameters Ψ = (C, σ_q, σ_r, σ_p, σ_v, σ_ω, σ_ω,ai, a_d, a_m, σ_ad, σ_am); the spin network ψ_f
/// lives elsewhere and hands its result in as a [`super::SpinPrior`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallModelParams {
    /// Impact map, row-major: (v⁺, ω⁺) = C (v⁻, ω⁻) (eq. 6.19).
    pub c: [[f64; 6]; 6],
    /// Transition noise variances diag(Q) = \[σ_q\]⊕ for (p, v, ω, a_d, a_m) (eq. 6.23).
    pub q_diag: [f64; 11],
    /// Measurement noise variances diag(R) = \[σ_r\]⊕.
    pub r_diag: [f64; 3],
    /// Initial position variances Σ_p = diag(\[σ_p\]⊕).
    pub init_pos_var: [f64; 3],
    /// Initial velocity variances Σ_v = diag(\[σ_v\]⊕).
    pub init_vel_var: [f64; 3],
    /// Initial spin variances \[σ_ω\]⊕ when no launcher information is used.
    pub init_spin_var: [f64; 3],
    /// Initial spin variances \[σ_ω,ai\]⊕ when the filter starts after the impact and launcher information is used.
    pub init_spin_var_after_impact: [f64; 3],
    /// Initial mean of a_d.
    pub a_d0: f64,
    /// Initial mean of a_m.
    pub a_m0: f64,
    /// Initial variance \[σ_ad\]⊕ of a_d.
    pub a_d_var: f64,
    /// Initial variance \[σ_am\]⊕ of a_m.
    pub a_m_var: f64,
    #[serde(default)]
    pub physics: BallPhysics,
}

impl BallModelParams {
    /// The drag and Magnus coefficients k_d = a_d² + ε and k_m = a_m² + ε (6.4.2) at the initial means of a_d
    /// and a_m: the learned values in the units of the thesis' tables.
    pub fn initial_coefficients(&self) -> (f64, f64) {
        let eps = self.physics.coeff_offset;
        (self.a_d0 * self.a_d0 + eps, self.a_m0 * self.a_m0 + eps)
    }

    /// Starting point of training, Table C.1 (thesis lines 6680-6706) and C.1.1 (lines 6653-6662). The table gives
    /// σ as inv[·]⊕(x), i.e. the variance itself is x.
    pub fn initial() -> Self {
        let mut c = [[0.0; 6]; 6];
        for (i, row) in c.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        // Only v_z flips at the bounce; spin unchanged.
        c[2][2] = -1.0;
        BallModelParams {
            c,
            q_diag: [1e-4, 1e-4, 1e-4, 1e-2, 1e-2, 1e-2, 1e-3, 1e-3, 1e-3, 1e-2, 1e-2],
            r_diag: [1e-3; 3],
            init_pos_var: [1e-4; 3],
            init_vel_var: [1e-2; 3],
            init_spin_var: [1.0; 3],
            init_spin_var_after_impact: [1.0; 3],
            a_d0: 0.1f64.sqrt(),
            a_m0: 0.1f64.sqrt(),
            a_d_var: 1e-2,
            a_m_var: 1e-2,
            physics: BallPhysics::default(),
        }
    }

    /// The trained model reported in the thesis: C from eq. 6.26 (lines 5003-5019), the rest from Table C.2
    /// (lines 6708-6733). That model used launcher information, so Table C.2 has no σ_ω; its Table C.1 value is kept.
    pub fn thesis_learned() -> Self {
        BallModelParams {
            // Block order and the kept "−0.00" signs as in the simulator's `IMPACT_MATRIX`, which explains them.
            c: [
                [0.54, -0.01, -0.0, -0.01, 0.12, 0.01],
                [0.01, 0.55, 0.0, -0.11, -0.01, -0.01],
                [-0.01, -0.0, -0.92, 0.01, 0.0, 0.0],
                [0.19, -1.40, 0.01, -0.20, 0.09, -0.03],
                [1.44, 0.14, -0.03, -0.01, -0.12, -0.01],
                [0.01, -0.05, 0.15, 0.05, -0.05, 1.37],
            ],
            q_diag: [1.00e-6, 1.00e-6, 1.00e-6, 1.16e-6, 1.19e-6, 1.10e-6, 1.73e-3, 1.31e-3, 1.00e-6, 1.16e-6, 1.30e-3],
            r_diag: [1.02e-6, 1.03e-6, 1.00e-6],
            init_pos_var: [1.38e-6, 1.63e-6, 1.00e-6],
            init_vel_var: [0.12, 0.14, 0.09],
            init_spin_var: [1.0; 3],
            init_spin_var_after_impact: [0.19, 3.28, 0.12],
            a_d0: 0.2168,
            a_m0: 1.22e-5,
            a_d_var: 5.70e-6,
            a_m_var: 3.10e-3,
            physics: BallPhysics::default(),
        }
    }

    /// Rejects what would break the filter later far from its cause, or make it predict nonsense: each value
    /// within a range no table-tennis set-up (nor the thesis' trained model) comes near the ends of.
    pub fn validate(&self) -> Result<(), BallModelError> {
        let check = |field: &'static str, path: String, domain: Domain, x: f64| {
            domain
                .check(&path, x)
                .map(|_| ())
                .map_err(|e| BallModelError::InvalidParameter { field, message: e.to_string() })
        };
        for (i, row) in self.c.iter().enumerate() {
            for (j, &x) in row.iter().enumerate() {
                check("c", format!("c[{i}][{j}]"), IMPACT_COEFFICIENT, x)?;
            }
        }
        let variances: [(&'static str, &[f64]); 8] = [
            ("q_diag", &self.q_diag),
            ("r_diag", &self.r_diag),
            ("init_pos_var", &self.init_pos_var),
            ("init_vel_var", &self.init_vel_var),
            ("init_spin_var", &self.init_spin_var),
            ("init_spin_var_after_impact", &self.init_spin_var_after_impact),
            ("a_d_var", std::slice::from_ref(&self.a_d_var)),
            ("a_m_var", std::slice::from_ref(&self.a_m_var)),
        ];
        for (field, values) in variances {
            for (i, &x) in values.iter().enumerate() {
                let path = if values.len() == 1 { field.to_string() } else { format!("{field}[{i}]") };
                check(field, path, VARIANCE, x)?;
            }
        }
        for (field, x) in [("a_d0", self.a_d0), ("a_m0", self.a_m0)] {
            check(field, field.to_string(), COEFFICIENT_ROOT, x)?;
        }
        let p = &self.physics;
        // Beyond these the flight arithmetic overflows or the time-of-impact search never ends.
        let physics = [
            ("physics.dt", p.dt, Domain::closed(1e-5, 0.1).in_unit("s")),
            ("physics.gravity", p.gravity, Domain::closed(1e-3, 100.0).in_unit("m/s²")),
            ("physics.ball_radius", p.ball_radius, Domain::closed(1e-4, 1.0).in_unit("m")),
            ("physics.coeff_offset", p.coeff_offset, Domain::closed(0.0, 1.0)),
            ("physics.table_z", p.table_z, Domain::closed(-10.0, 10.0).in_unit("m")),
        ];
        for (field, x, domain) in physics {
            check(field, field.to_string(), domain, x)?;
        }
        Ok(())
    }
}
