//! Table contact: the table's geometry and the linear impact map (v⁺, ω⁺) = C (v⁻, ω⁻) (thesis eq. 6.19,
//! line 4559), with the learned C of eq. 6.26 as the ground truth.

use serde::{Deserialize, Serialize};

use super::flight::BallState;
use super::vec3::Vec3;

/// Learned impact matrix C of eq. 6.26 (thesis lines 4994-5022), rows/columns ordered (v_x, v_y, v_z, ω_x,
/// ω_y, ω_z). The extracted thesis text prints the four 3×3 blocks one after another: lines 5005-5007,
/// 5009-5011, 5013-5015 and 5017-5019. Which block is which follows from the discussion in lines 5033-5047:
/// C_vv holds the −0.92 sign flip of v_z; C_vω has (1,2) = 0.12 (ω_y↑ → v_x↑) and (2,1) = −0.11
/// (ω_x↑ → v_y↓); C_ωv has (1,2) = −1.40 (v_y↓ → ω_x↑), (2,1) = 1.44 and the bottom-right 0.15; C_ωω has the
/// bottom-right 1.37. Entries printed as "−0.00" are the thesis' two-decimal rounding and are kept as −0.0.
pub const IMPACT_MATRIX: [[f64; 6]; 6] = [
    [0.54, -0.01, -0.0, -0.01, 0.12, 0.01],
    [0.01, 0.55, 0.0, -0.11, -0.01, -0.01],
    [-0.01, -0.0, -0.92, 0.01, 0.0, 0.0],
    [0.19, -1.40, 0.01, -0.20, 0.09, -0.03],
    [1.44, 0.14, -0.03, -0.01, -0.12, -0.01],
    [0.01, -0.05, 0.15, 0.05, -0.05, 1.37],
];

/// Table centre (x, y, z) in metres: `IDEAL_TABLE` in the authors' ball_model/data/__init__.py, also
/// /work/shared/METHODS.md ("Ball" facts). Its z is the table plane z_table = −0.461.
pub const TABLE_CENTER: Vec3 = [0.1325, 1.7425, -0.461];

/// Table length along y: the standard ITTF 2.74 m. The authors' ball_model/utils/plotting.py
/// (`setup_board_axis`) draws the table as IDEAL_TABLE ± 1.37 m in y, so the long axis is y.
pub const TABLE_LENGTH: f64 = 2.74;

/// Table width along x: the standard ITTF 1.525 m (plotting.py: IDEAL_TABLE ± 0.7625 m in x).
pub const TABLE_WIDTH: f64 = 1.525;

/// Ball radius in metres: `RADIUS_OF_BALL` in ball_model/data/__init__.py; METHODS.md.
pub const BALL_RADIUS: f64 = 0.02;

/// The playing surface: a horizontal rectangle. The net is not modelled (neither the thesis' model nor the
/// launcher trajectories, which clear it, need it).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table {
    pub center: Vec3,
    /// Extent along y (m).
    pub length: f64,
    /// Extent along x (m).
    pub width: f64,
}

impl Default for Table {
    fn default() -> Self {
        Table { center: TABLE_CENTER, length: TABLE_LENGTH, width: TABLE_WIDTH }
    }
}

impl Table {
    pub fn z(&self) -> f64 {
        self.center[2]
    }

    /// Whether a ball centred above `p` rests on the surface. Contacts on the rim or edges are not modelled:
    /// a ball whose centre is outside the rectangle falls past the table.
    pub fn contains_xy(&self, p: &[f64]) -> bool {
        (p[0] - self.center[0]).abs() <= 0.5 * self.width && (p[1] - self.center[1]).abs() <= 0.5 * self.length
    }
}

/// Where and how the ball bounces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImpactModel {
    pub c: [[f64; 6]; 6],
    pub table: Table,
    pub ball_radius: f64,
}

impl Default for ImpactModel {
    fn default() -> Self {
        ImpactModel { c: IMPACT_MATRIX, table: Table::default(), ball_radius: BALL_RADIUS }
    }
}

impl ImpactModel {
    /// Signed distance of the ball's lowest point above the table plane (negative = penetrating).
    pub fn gap(&self, s: &BallState) -> f64 {
        s[2] - self.ball_radius - self.table.z()
    }

    /// The state right after contact: (v, ω) mapped by C, the position put exactly on the surface so that
    /// round-off in the located contact time can never leave the ball inside the table.
    pub fn apply(&self, s: &BallState) -> BallState {
        let mut out = *s;
        for (row, c_row) in self.c.iter().enumerate() {
            out[3 + row] = (0..6).map(|col| c_row[col] * s[3 + col]).sum();
        }
        out[2] = self.table.z() + self.ball_radius;
        out
    }
}
