//! The manipulator half of an embodied board game: something that moves over the board and can push.

use rand_chacha::ChaCha8Rng;

/// A point on the board in normalized board coordinates: (0, 0) is the top-left corner, (1, 1) the
/// bottom-right; x grows to the right (columns), y downwards (rows).
pub type BoardPoint = [f64; 2];

pub trait Manipulator: Send {
    /// Short name used on the command line (`cursor`, `reacher`).
    fn name(&self) -> &'static str;
    fn action_low(&self) -> Vec<f64>;
    fn action_high(&self) -> Vec<f64>;
    /// Names of the manipulator part of the observation.
    fn obs_names(&self) -> Vec<&'static str>;
    fn observe(&self) -> Vec<f64>;
    /// Names of the full physical state, in [`state`](Self::state) order.
    fn state_names(&self) -> Vec<&'static str>;
    /// Full physical state (for saving and restoring).
    fn state(&self) -> Vec<f64>;
    /// Why `state` is not a state this manipulator can be put in (a value outside its workspace), if it
    /// is not; the length and finiteness are checked by the caller.
    fn state_problem(&self, state: &[f64]) -> Option<String>;
    fn set_state(&mut self, state: &[f64]);
    fn reset(&mut self, rng: &mut ChaCha8Rng);
    /// Applies one control action. Returns the board point of a push when this action pushed while the
    /// effector was over the board; the game decides what a push there does.
    fn step(&mut self, action: &[f64]) -> Option<BoardPoint>;
    /// Where the effector is, in board coordinates (may lie outside [0, 1]² for an arm).
    fn effector(&self) -> BoardPoint;
    /// Steps a skill may take before it is cut off (thesis 7.3.1: 10 for Cursor, 50 for Reacher).
    fn skill_step_limit(&self) -> usize;
    /// Simulated seconds per `step`.
    fn dt(&self) -> f64;
}

/// A hand-written low-level controller: drives the effector to a board point and pushes there.
/// It executes planned moves for `solve-board --model true` and is the reference for learned skills.
pub trait ScriptedController {
    /// The next action towards pushing at `target`.
    fn act(&mut self, manipulator: &dyn Manipulator, target: BoardPoint) -> Vec<f64>;
    /// Forget internal state (new move).
    fn reset(&mut self) {}
}
