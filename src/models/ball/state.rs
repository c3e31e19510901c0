//! Layout of the ball state z = (p, v, ω, a_d, a_m) (eq. 6.20) and the discrete phase carried beside it.

use crate::filtering::{Belief, Vector};

pub const STATE_DIM: usize = 11;
pub const MEAS_DIM: usize = 3;

/// First index of the position p.
pub const P: usize = 0;
/// First index of the velocity v.
pub const V: usize = 3;
/// First index of the spin ω.
pub const W: usize = 6;
/// Index of a_d, with drag coefficient k_d = a_d² + ε.
pub const AD: usize = 9;
/// Index of a_m, with Magnus coefficient k_m = a_m² + ε.
pub const AM: usize = 10;

pub type BallState = Vector<STATE_DIM>;
pub type BallBelief = Belief<STATE_DIM, Phase>;

/// Whether the trajectory has had its table impact. The table is an infinite plane and a trajectory gets one
/// impact: a ball that has bounced and falls past the table's end must not bounce a second time on the plane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Phase {
    #[default]
    BeforeImpact,
    AfterImpact,
}
