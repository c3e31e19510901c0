//! A board game played through a manipulator: observation = manipulator ⊕ symbolic board ⊕ remaining
//! skill time. A skill (one intended game move) ends when the board changes or at the step limit
//! (thesis 7.3.1).

use rand_chacha::ChaCha8Rng;

use super::manipulator::{BoardPoint, Manipulator, ScriptedController};
use crate::envs::boards::BoardGame;
use crate::envs::{Dynamics, Env, EnvSpec, Step};

pub struct EmbodiedBoard<G: BoardGame> {
    game: G,
    board: G::State,
    manipulator: Box<dyn Manipulator>,
    /// Steps since the skill started: a board change ends the skill but does not reset the count, so the
    /// step that changed the board reports the time that was left (the authors' time-limit wrapper); the
    /// next skill starts at full time through [`start_skill`](Self::start_skill) or a reset.
    skill_step: usize,
}

/// What happened during one attempted move.
#[derive(Clone, Debug, PartialEq)]
pub struct MoveOutcome {
    /// The move the board actually made, if any.
    pub performed: Option<usize>,
    pub steps: usize,
}

impl<G: BoardGame> EmbodiedBoard<G> {
    pub fn new(game: G, manipulator: Box<dyn Manipulator>, board: G::State) -> Self {
        EmbodiedBoard { game, board, manipulator, skill_step: 0 }
    }

    pub fn game(&self) -> &G {
        &self.game
    }

    pub fn board(&self) -> G::State {
        self.board
    }

    pub fn set_board(&mut self, board: G::State) {
        self.board = board;
        self.skill_step = 0;
    }

    pub fn manipulator(&self) -> &dyn Manipulator {
        self.manipulator.as_ref()
    }

    /// Puts the manipulator in `state` (see [`Manipulator::state`]), leaving board and skill time.
    pub fn set_manipulator_state(&mut self, state: &[f64]) {
        self.manipulator.set_state(state);
    }

    /// A new skill attempt: full skill time again, the manipulator where it is.
    pub fn start_skill(&mut self) {
        self.skill_step = 0;
    }

    fn remaining_time(&self) -> f64 {
        let limit = self.manipulator.skill_step_limit() as f64;
        (limit - self.skill_step as f64).max(0.0) / limit
    }

    /// One control step; returns the game move a push performed, if any.
    pub fn act(&mut self, action: &[f64]) -> Option<usize> {
        let performed = self.manipulator.step(action).and_then(|p| self.game.move_at(p));
        if let Some(mv) = performed {
            self.board = self.game.apply(self.board, mv);
        }
        self.skill_step += 1;
        performed
    }

    /// Runs `controller` towards `mv` until the board changes or the skill step limit is reached.
    pub fn execute(&mut self, controller: &mut dyn ScriptedController, mv: usize) -> MoveOutcome {
        self.execute_observed(controller, mv, |_, _| {})
    }

    /// As [`execute`](Self::execute), reporting the effector position after every control step.
    pub fn execute_observed(
        &mut self,
        controller: &mut dyn ScriptedController,
        mv: usize,
        mut on_step: impl FnMut(usize, BoardPoint),
    ) -> MoveOutcome {
        controller.reset();
        self.skill_step = 0;
        let target = self.game.move_target(mv);
        let limit = self.manipulator.skill_step_limit();
        for steps in 1..=limit {
            let action = controller.act(self.manipulator.as_ref(), target);
            let performed = self.act(&action);
            on_step(steps, self.manipulator.effector());
            if performed.is_some() {
                return MoveOutcome { performed, steps };
            }
        }
        self.skill_step = 0;
        MoveOutcome { performed: None, steps: limit }
    }
}

impl<G: BoardGame> Env for EmbodiedBoard<G> {
    fn spec(&self) -> EnvSpec {
        let name = self.manipulator.name();
        let board: Vec<String> = (0..self.game.symbolic(self.board).len()).map(|i| format!("board_{i}")).collect();
        let with_board_and_time = |mut names: Vec<String>| {
            names.extend(board.iter().cloned());
            names.push("remaining_time".into());
            names
        };
        EnvSpec {
            name: format!("{}:{name}", self.game.name()),
            state_names: with_board_and_time(self.manipulator.state_names().iter().map(|s| s.to_string()).collect()),
            obs_names: with_board_and_time(self.manipulator.obs_names().iter().map(|s| s.to_string()).collect()),
            action_low: self.manipulator.action_low(),
            action_high: self.manipulator.action_high(),
            dt: self.manipulator.dt(),
            angular: vec![false; self.manipulator.state().len() + board.len() + 1],
        }
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        self.manipulator.reset(rng);
        self.skill_step = 0;
        self.observe()
    }

    /// Reward-free (SEADS learns without reward): the reward is 1 when the board becomes solved.
    fn step(&mut self, action: &[f64]) -> Step {
        let moved = self.act(action).is_some();
        let solved = self.board == self.game.goal();
        let skill_over = moved || self.skill_step >= self.manipulator.skill_step_limit();
        Step { obs: self.observe(), reward: if moved && solved { 1.0 } else { 0.0 }, done: skill_over }
    }

    /// Physical manipulator state ⊕ board bits ⊕ remaining skill time.
    fn state(&self) -> Vec<f64> {
        let mut state = self.manipulator.state();
        state.extend(self.game.symbolic(self.board));
        state.push(self.remaining_time());
        state
    }

    fn set_state(&mut self, state: &[f64]) {
        let m = self.manipulator.state().len();
        let bits = self.game.symbolic(self.board).len();
        self.manipulator.set_state(&state[..m]);
        if let Some(board) = state.get(m..m + bits).and_then(|b| self.game.decode_symbolic(b)) {
            self.board = board;
        }
        if let Some(&remaining) = state.get(m + bits) {
            let limit = self.manipulator.skill_step_limit() as f64;
            self.skill_step = ((1.0 - remaining) * limit).round().max(0.0) as usize;
        }
    }

    fn observe(&self) -> Vec<f64> {
        let mut obs = self.manipulator.observe();
        obs.extend(self.game.symbolic(self.board));
        obs.push(self.remaining_time());
        obs
    }

    fn params(&self) -> serde_json::Value {
        serde_json::json!({ "game": self.game.name(), "embodiment": self.manipulator.name() })
    }

    /// Embodied boards are planned on the symbolic board, not with continuous dynamics.
    fn dynamics(&self) -> Option<Box<dyn Dynamics>> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::boards::LightsOut;
    use crate::envs::embodiments::cursor::{Cursor, CursorController};
    use rand::SeedableRng;

    #[test]
    fn cursor_executes_a_plan_to_the_goal() {
        let game = LightsOut::new(5).unwrap();
        let plan = [3, 17, 12];
        let board = game.pressed(&plan);
        let mut env = EmbodiedBoard::new(game.clone(), Box::new(Cursor::new()), board);
        env.reset(&mut ChaCha8Rng::seed_from_u64(1));
        let obs = env.observe();
        assert_eq!(obs.len(), 2 + 25 + 1);
        assert_eq!(obs[27], 1.0, "full skill time left");
        for mv in plan {
            let out = env.execute(&mut CursorController, mv);
            assert_eq!(out.performed, Some(mv));
        }
        assert_eq!(env.board(), game.goal());
    }
}
