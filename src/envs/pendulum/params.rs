//! Physical constants of gym's Pendulum-v0 and the variants used in the thesis.

use serde::{Deserialize, Serialize};

/// Actuator of one quadrant in the quadrant-gain family (thesis 4.5.3): the clipped action is multiplied
/// by `gain * sign`, so some quadrants are weaker, stronger or reversed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct QuadrantActuator {
    pub gain: f64,
    pub sign: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PendulumParams {
    pub gravity: f64,
    pub mass: f64,
    pub length: f64,
    pub dt: f64,
    pub max_speed: f64,
    pub max_torque: f64,
    /// Multiplies the action before clipping; −1 inverts the actuator.
    pub action_factor: f64,
    /// Per-quadrant actuators, indexed by [`quadrant_of`]; `None` for the plain pendulum.
    pub quadrants: Option<[QuadrantActuator; 4]>,
    /// Simulator steps per environment step; rewards of the repeats are summed.
    pub action_repeat: usize,
}

impl Default for PendulumParams {
    fn default() -> Self {
        PendulumParams {
            gravity: 10.0,
            mass: 1.0,
            length: 1.0,
            dt: 0.05,
            max_speed: 8.0,
            max_torque: 2.0,
            action_factor: 1.0,
            quadrants: None,
            action_repeat: 1,
        }
    }
}

/// Wraps an angle into [−π, π) the way gym does (Python's floored modulo).
pub fn angle_normalize(theta: f64) -> f64 {
    (theta + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
}

/// Quadrant index of an angle: 0 = [π/2, π], 1 = [0, π/2), 2 = [−π/2, 0), 3 = [−π, −π/2).
pub fn quadrant_of(theta: f64) -> usize {
    use std::f64::consts::FRAC_PI_2;
    let a = angle_normalize(theta);
    if a >= FRAC_PI_2 {
        0
    } else if a >= 0.0 {
        1
    } else if a >= -FRAC_PI_2 {
        2
    } else {
        3
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn angle_normalize_matches_python_modulo() {
        assert!((angle_normalize(3.0 * PI / 2.0) - (-PI / 2.0)).abs() < 1e-15);
        assert!((angle_normalize(-3.0 * PI / 2.0) - (PI / 2.0)).abs() < 1e-15);
        assert_eq!(angle_normalize(PI), -PI);
        assert_eq!(angle_normalize(0.25), 0.25);
    }

    #[test]
    fn quadrants_follow_the_thesis_convention() {
        assert_eq!(quadrant_of(3.0), 0);
        assert_eq!(quadrant_of(PI / 2.0), 0);
        assert_eq!(quadrant_of(0.0), 1);
        assert_eq!(quadrant_of(-0.1), 2);
        assert_eq!(quadrant_of(-3.0), 3);
        assert_eq!(quadrant_of(PI), 3, "π wraps to −π");
    }
}
