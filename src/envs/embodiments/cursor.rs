//! Cursor (thesis D.1.1): a point on the board moved by bounded steps, pushing where it stands.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::manipulator::{BoardPoint, Manipulator, ScriptedController};
use crate::util::domain::number;

/// Largest move per step along each axis. The authors' action space is a float32 box of ±0.2 and moves are
/// clipped to its bounds, so the bound is 0.2 rounded to float32 (0.20000000298023224): three clipped moves
/// from the wall end just past the third field edge, not on it.
pub const MAX_STEP: f64 = 0.2f32 as f64;
/// A push happens when the third action component exceeds this. The authors' code writes it as
/// −1 + 0.8·2, which in floating point is 0.6000000000000001, so an action of exactly that value does
/// not push.
pub const PUSH_THRESHOLD: f64 = -1.0 + 0.8 * 2.0;
pub const SKILL_STEP_LIMIT: usize = 10;

#[derive(Clone, Debug, Default)]
pub struct Cursor {
    position: BoardPoint,
}

impl Cursor {
    pub fn new() -> Self {
        Cursor { position: [0.5, 0.5] }
    }
}

impl Manipulator for Cursor {
    fn name(&self) -> &'static str {
        "cursor"
    }

    fn action_low(&self) -> Vec<f64> {
        vec![-MAX_STEP, -MAX_STEP, -1.0]
    }

    fn action_high(&self) -> Vec<f64> {
        vec![MAX_STEP, MAX_STEP, 1.0]
    }

    fn obs_names(&self) -> Vec<&'static str> {
        vec!["cursor_x", "cursor_y"]
    }

    fn observe(&self) -> Vec<f64> {
        self.position.to_vec()
    }

    fn state_names(&self) -> Vec<&'static str> {
        self.obs_names()
    }

    fn state(&self) -> Vec<f64> {
        self.position.to_vec()
    }

    fn state_problem(&self, state: &[f64]) -> Option<String> {
        let names = self.state_names();
        state
            .iter()
            .zip(names)
            .find(|(v, _)| !(0.0..=1.0).contains(*v))
            .map(|(v, name)| format!("{name} = {} is off the board; expected a value in [0, 1]", number(*v)))
    }

    fn set_state(&mut self, state: &[f64]) {
        self.position = [state[0].clamp(0.0, 1.0), state[1].clamp(0.0, 1.0)];
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        self.position = [rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)];
    }

    /// The move is applied (and clipped to the board) before the push is checked, as in the original.
    fn step(&mut self, action: &[f64]) -> Option<BoardPoint> {
        for (position, delta) in self.position.iter_mut().zip(&action[..2]) {
            *position = (*position + delta.clamp(-MAX_STEP, MAX_STEP)).clamp(0.0, 1.0);
        }
        (action[2] > PUSH_THRESHOLD).then_some(self.position)
    }

    fn effector(&self) -> BoardPoint {
        self.position
    }

    fn skill_step_limit(&self) -> usize {
        SKILL_STEP_LIMIT
    }

    fn dt(&self) -> f64 {
        1.0
    }
}

/// Moves straight towards the target at full speed and pushes on arrival.
#[derive(Clone, Debug, Default)]
pub struct CursorController;

impl ScriptedController for CursorController {
    fn act(&mut self, manipulator: &dyn Manipulator, target: BoardPoint) -> Vec<f64> {
        let here = manipulator.effector();
        let delta = [target[0] - here[0], target[1] - here[1]];
        let arrives = delta.iter().all(|d| d.abs() <= MAX_STEP);
        vec![delta[0].clamp(-MAX_STEP, MAX_STEP), delta[1].clamp(-MAX_STEP, MAX_STEP), if arrives { 1.0 } else { -1.0 }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moves_are_clipped_and_push_after_moving() {
        let mut c = Cursor::new();
        c.set_state(&[0.9, 0.1]);
        assert_eq!(c.step(&[0.5, -0.5, 0.0]), None);
        assert_eq!(c.effector(), [1.0, 0.0], "clipped to ±0.2 and to the board");
        assert_eq!(c.step(&[-0.1, 0.1, 0.61]), Some([0.9, 0.1]));
        assert_eq!(c.step(&[0.0, 0.0, 0.6]), None, "threshold is strict");
    }

    #[test]
    fn controller_reaches_any_target_within_the_skill_limit() {
        let mut c = Cursor::new();
        let mut ctrl = CursorController;
        for (start, target) in [([0.0, 0.0], [0.9, 0.9]), ([0.5, 0.5], [0.5, 0.5]), ([1.0, 0.0], [0.1, 0.7])] {
            c.set_state(&start);
            let pushed = (0..SKILL_STEP_LIMIT).find_map(|_| {
                let a = ctrl.act(&c, target);
                c.step(&a)
            });
            let p = pushed.expect("pushes within the limit");
            assert!((p[0] - target[0]).abs() < 1e-12 && (p[1] - target[1]).abs() < 1e-12);
        }
    }
}
