//! The arm as a board manipulator: the board frame in the arm's plane, observations, the reset distribution,
//! action repeat and the push rule of the authors' SEADS environment.

use std::f64::consts::TAU;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::{Reacher, ACTION_REPEAT, BOARD_HALF_EXTENT, DAMPING, GEAR, PUSH_THRESHOLD, SKILL_STEP_LIMIT, TIMESTEP};
use crate::envs::embodiments::manipulator::{BoardPoint, Manipulator};
use crate::util::domain::{number, Domain};

/// Arm plane → board coordinates, as the authors' `ReacherEnv._get_finger_pos` normalizes MuJoCo's world
/// x and y: both as (xy + 0.15)/0.3, so board columns grow with arm +x and board rows with arm +y.
///
/// An earlier version mirrored y (rows counted from arm +y downwards) on the argument that the arm is
/// mirror-symmetric. Its reset is not: the wrist starts in [0°, 160°] only (a U(0, 2π) draw clamped at the
/// stop), so a mirrored board pairs the fields with different start poses than the original and skill
/// statistics would not match.
pub fn arm_to_board(p: [f64; 2]) -> BoardPoint {
    let extent = 2.0 * BOARD_HALF_EXTENT;
    [(p[0] + BOARD_HALF_EXTENT) / extent, (p[1] + BOARD_HALF_EXTENT) / extent]
}

/// Inverse of [`arm_to_board`].
pub fn board_to_arm(b: BoardPoint) -> [f64; 2] {
    let extent = 2.0 * BOARD_HALF_EXTENT;
    [b[0] * extent - BOARD_HALF_EXTENT, b[1] * extent - BOARD_HALF_EXTENT]
}

impl Manipulator for Reacher {
    fn name(&self) -> &'static str {
        "reacher"
    }

    fn action_low(&self) -> Vec<f64> {
        vec![-1.0; 3]
    }

    fn action_high(&self) -> Vec<f64> {
        vec![1.0; 3]
    }

    /// dm_control's reacher observes the joint positions and velocities (and the vector to its target);
    /// here the angles are given as cos/sin (the shoulder is unbounded), followed by the velocities and
    /// the finger's board position, which takes the target's place.
    fn obs_names(&self) -> Vec<&'static str> {
        vec![
            "shoulder_cos",
            "shoulder_sin",
            "wrist_cos",
            "wrist_sin",
            "shoulder_velocity",
            "wrist_velocity",
            "finger_x",
            "finger_y",
        ]
    }

    fn observe(&self) -> Vec<f64> {
        let (s1, c1) = self.q[0].sin_cos();
        let (s2, c2) = self.q[1].sin_cos();
        let f = self.effector();
        vec![c1, s1, c2, s2, self.v[0], self.v[1], f[0], f[1]]
    }

    fn state_names(&self) -> Vec<&'static str> {
        vec!["shoulder_angle", "wrist_angle", "shoulder_velocity", "wrist_velocity"]
    }

    /// [shoulder angle, wrist angle, shoulder velocity, wrist velocity].
    fn state(&self) -> Vec<f64> {
        vec![self.q[0], self.q[1], self.v[0], self.v[1]]
    }

    /// The shoulder turns freely, but a start wound more than ~160 turns is none an episode reaches (and
    /// cos/sin of it keep few digits). The wrist may lie past its ±160° stops (the authors' reset leaves it there
    /// and the soft limit brings it back), but not more than a turn from zero, where the reset draws. The motors'
    /// top torque against the joints' damping holds a joint at GEAR / DAMPING = 5 rad/s; ten times that is
    /// no state the arm gets into.
    fn state_problem(&self, state: &[f64]) -> Option<String> {
        let speed = Domain::closed(-10.0 * GEAR / DAMPING, 10.0 * GEAR / DAMPING).in_unit("rad/s");
        let wrist = *state.get(1)?;
        if wrist.abs() > TAU {
            let wrist = number(wrist);
            return Some(format!("wrist_angle = {wrist} is more than a full turn; expected radians in [-2π, 2π]"));
        }
        let checks = [
            Domain::closed(-1e3, 1e3).in_unit("rad").check("shoulder_angle", *state.first()?),
            speed.check("shoulder_velocity", *state.get(2)?),
            speed.check("wrist_velocity", *state.get(3)?),
        ];
        checks.into_iter().find_map(|c| c.err()).map(|e| e.to_string())
    }

    fn set_state(&mut self, state: &[f64]) {
        self.q = [state[0], state[1]];
        self.v = [state[2], state[3]];
    }

    /// Both angles U(0, 2π), zero velocity (authors' code). The wrist keeps its draw even past the stop
    /// (56 % of draws lie in (160°, 360°)); the soft limit drives it back to 160° within about ten steps,
    /// as in the reference.
    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        let shoulder = rng.random_range(0.0..TAU);
        let wrist = rng.random_range(0.0..TAU);
        self.q = [shoulder, wrist];
        self.v = [0.0, 0.0];
    }

    fn step(&mut self, action: &[f64]) -> Option<BoardPoint> {
        for _ in 0..ACTION_REPEAT {
            self.physics_step([action[0], action[1]]);
        }
        let finger = self.effector();
        let on_board = finger.iter().all(|c| (0.0..=1.0).contains(c));
        (action[2] > PUSH_THRESHOLD && on_board).then_some(finger)
    }

    /// The finger in board coordinates.
    fn effector(&self) -> BoardPoint {
        arm_to_board(self.finger())
    }

    fn skill_step_limit(&self) -> usize {
        SKILL_STEP_LIMIT
    }

    fn dt(&self) -> f64 {
        TIMESTEP * ACTION_REPEAT as f64
    }
}
