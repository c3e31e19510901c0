//! The scripted controller: resolved-rate inverse kinematics of the grip site. It flies the hand, pointing
//! down with its fingers closed, to a point above the target and then lowers it onto the board until a
//! touch sensor registers the push.

use std::sync::Arc;

use mujoco_rs::prelude::*;

use super::ik::{site_jacobian, solve_dls, Data};
use super::{ARM_JOINTS, ARM_MAX_VELOCITY, FIELD_HALF, FINGER_MAX_VELOCITY, JOINTS};
use crate::envs::embodiments::manipulator::{BoardPoint, Manipulator, ScriptedController};

/// Drives the grip site with a proportional law in Cartesian space mapped to joint velocities through the
/// damped pseudo-inverse of its Jacobian, scaled down as a whole when a joint would exceed its velocity
/// limit (so the hand keeps its course).
pub struct JacoController {
    data: Data,
    tcp: usize,
    side: usize,
    /// Proportional gain (1/s) on the position and orientation error.
    pub gain: f64,
    /// Largest grip-site speed asked for (m/s).
    pub max_speed: f64,
    /// Height (m) of the grip site when it flies to the target.
    pub hover: f64,
    /// Horizontal distance (m) below which it starts to descend.
    pub descend_within: f64,
    target: Option<BoardPoint>,
    descending: bool,
}

impl JacoController {
    pub fn new(model: Arc<MjModel>, tcp: usize, side: usize) -> Self {
        JacoController {
            data: MjData::new(model),
            tcp,
            side,
            gain: 6.0,
            max_speed: 0.3,
            hover: 0.12,
            descend_within: 0.01,
            target: None,
            descending: false,
        }
    }

    fn world_of(&self, b: BoardPoint) -> [f64; 2] {
        let width = 2.0 * FIELD_HALF * self.side as f64;
        [b[0] * width - 0.5 * width, (1.0 - b[1]) * width - 0.5 * width]
    }
}

impl ScriptedController for JacoController {
    fn act(&mut self, manipulator: &dyn Manipulator, target: BoardPoint) -> Vec<f64> {
        let state = manipulator.state();
        self.data.qpos_mut().copy_from_slice(&state[..JOINTS]);
        self.data.qvel_mut().copy_from_slice(&state[JOINTS..]);
        self.data.kinematics();
        self.data.com_pos();
        if self.target != Some(target) {
            self.target = Some(target);
            self.descending = false;
        }
        let goal = self.world_of(target);
        let p = self.data.site_xpos()[self.tcp];
        let horizontal = (goal[0] - p[0]).hypot(goal[1] - p[1]);
        if horizontal < self.descend_within {
            self.descending = true;
        }
        // Below the board's surface while descending, so the speed stays up until the fingers touch.
        let height = if self.descending { -0.1 } else { self.hover };
        let mut velocity = [goal[0] - p[0], goal[1] - p[1], height - p[2]].map(|e| self.gain * e);
        let speed = velocity.iter().map(|v| v * v).sum::<f64>().sqrt();
        if speed > self.max_speed {
            velocity = velocity.map(|v| v * self.max_speed / speed);
        }
        // Turn the site's z axis (the hand's axis) towards straight down: ω = z × (−e_z).
        let m = self.data.site_xmat()[self.tcp];
        let axis = [m[2], m[5], m[8]];
        let turn = [-axis[1], axis[0], 0.0].map(|w| self.gain * w);
        let (jp, jr) = site_jacobian(&self.data, self.tcp);
        let e = [velocity[0], velocity[1], velocity[2], turn[0], turn[1], turn[2]];
        let mut rates = solve_dls(&jp, &jr, e, 1.0, 1e-4);
        let excess = rates.iter().zip(ARM_MAX_VELOCITY).map(|(r, max)| r.abs() / max).fold(1.0, f64::max);
        rates = rates.map(|r| r / excess);
        let mut action = rates.to_vec();
        action.resize(ARM_JOINTS, 0.0);
        // Closed fingers meet below the hand's axis: one contact point, near the grip site's projection.
        action.extend([FINGER_MAX_VELOCITY; 3]);
        action
    }

    fn reset(&mut self) {
        self.target = None;
        self.descending = false;
    }
}
