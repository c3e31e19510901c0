//! The robot-specific parameters of Table 5.1, drawn uniformly per instance.

use rand::Rng;
use serde::{Deserialize, Serialize};

pub const MASS: (f64, f64) = (1.0, 4.0);
pub const K_THROTTLE: (f64, f64) = (500.0, 1000.0);
pub const K_STEER: (f64, f64) = (std::f64::consts::PI / 8.0, std::f64::consts::PI / 4.0);

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotParams {
    /// kg
    pub mass: f64,
    /// Force per unit throttle (N).
    pub k_throttle: f64,
    /// Heading change per unit steer and step (rad).
    pub k_steer: f64,
}

impl RobotParams {
    /// The middle of every range: the robot before an instance is drawn (and the authors' fixed robot).
    pub fn nominal() -> Self {
        let mid = |(lo, hi): (f64, f64)| (lo + hi) / 2.0;
        RobotParams { mass: mid(MASS), k_throttle: mid(K_THROTTLE), k_steer: mid(K_STEER) }
    }

    pub fn sample<R: Rng + ?Sized>(rng: &mut R) -> Self {
        RobotParams {
            mass: rng.random_range(MASS.0..MASS.1),
            k_throttle: rng.random_range(K_THROTTLE.0..K_THROTTLE.1),
            k_steer: rng.random_range(K_STEER.0..K_STEER.1),
        }
    }
}
