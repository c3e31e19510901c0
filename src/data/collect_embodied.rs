//! Skill episodes of a board game played through a manipulator (SEADS, thesis 7.3.1): replays of given
//! actions and random-policy collection.
//!
//! An episode is one skill attempt: it ends when the board changes or at the skill step limit (10 Cursor,
//! 50 Reacher), the same boundary the SEADS agent learns on. Each episode is its own rollout, numbered in
//! order, so a reader splits episodes by rollout id; the metadata holds per rollout the game, the
//! embodiment and the board the episode started from.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::collect::{check_size, timesteps, REPLAY_STREAM};
use super::{Dataset, DatasetLayout, Rollout, Timestep};
use crate::envs::boards::{BoardGame, GameSpec, LightsOut, TileSwap};
use crate::envs::embodiments::embodied::EmbodiedBoard;
use crate::envs::embodiments::{BoardLayout, Embodiment};
use crate::envs::{Env, EnvName, EnvSpec};
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::util::seeding::rng_for;

pub struct EmbodiedReplaySettings {
    pub game: GameSpec,
    pub embodiment: Embodiment,
    /// One action per control step; values beyond the bounds are clipped as in any step.
    pub actions: Vec<Vec<f64>>,
    /// The manipulator's start state (Cursor: x, y; Reacher: joint angles, joint velocities); `None`
    /// resets it from `seed`.
    pub init_state: Option<Vec<f64>>,
    /// The start board in the game's canonical comma-separated form; `None` starts from the solved board,
    /// so every push shows as exactly its move's pattern.
    pub board: Option<String>,
    pub seed: u64,
    pub command_line: String,
}

pub struct EmbodiedCollectSettings {
    pub game: GameSpec,
    pub embodiment: Embodiment,
    pub episodes: usize,
    pub seed: u64,
    pub command_line: String,
}

/// Steps the manipulator through the given actions, one skill episode after another: after a board
/// change or a timeout the next episode starts with full skill time from where the manipulator is.
pub fn replay_embodied(settings: &EmbodiedReplaySettings) -> Result<Dataset> {
    match settings.game {
        GameSpec::LightsOut(n) => replay_game(LightsOut::new(n)?, settings),
        GameSpec::TileSwap => replay_game(TileSwap::new(), settings),
    }
}

/// `episodes` skill episodes of uniformly random actions, each from a scrambled board (uniform over the
/// boards the moves reach: every field pressed with probability 1/2 for LightsOut, a uniform permutation
/// for TileSwap) and a manipulator reset as in the original (Cursor uniform on the board, Reacher joints
/// U(0, 2π) at rest). Episode k draws everything from its own stream under `seed`.
pub fn collect_embodied(settings: &EmbodiedCollectSettings, monitor: &dyn Monitor) -> Result<Dataset> {
    match settings.game {
        GameSpec::LightsOut(n) => collect_game(LightsOut::new(n)?, settings, monitor),
        GameSpec::TileSwap => collect_game(TileSwap::new(), settings, monitor),
    }
}

/// Parses `--init-state` for an embodied env: the manipulator's state only, inside its workspace.
pub fn parse_manipulator_state(text: &str, game: GameSpec, embodiment: Embodiment) -> Result<Vec<f64>> {
    let env = EnvName::Embodied(game, embodiment).canonical();
    let names = embodiment.build(&BoardLayout::of_spec(game)?)?.0.state_names().join(",");
    let state = text
        .split(',')
        .map(|field| {
            let field = field.trim();
            field.parse::<f64>().map_err(|_| {
                Error::config(format!("--init-state: '{field}' is not a number; expected {names} for {env}"))
            })
        })
        .collect::<Result<Vec<f64>>>()?;
    check_manipulator_state(&state, game, embodiment)?;
    Ok(state)
}

fn check_manipulator_state(state: &[f64], game: GameSpec, embodiment: Embodiment) -> Result<()> {
    let env = EnvName::Embodied(game, embodiment).canonical();
    let manipulator = embodiment.build(&BoardLayout::of_spec(game)?)?.0;
    let names = manipulator.state_names();
    let expected = || format!("expected {} finite numbers ({}) for {env}", names.len(), names.join(","));
    if state.len() != names.len() {
        return Err(Error::config(format!("--init-state has {} value(s); {}", state.len(), expected())));
    }
    if let Some(bad) = state.iter().find(|x| !x.is_finite()) {
        return Err(Error::config(format!("--init-state: {bad} is not finite; {}", expected())));
    }
    match manipulator.state_problem(state) {
        Some(problem) => Err(Error::config(format!("--init-state: {problem} for {env}"))),
        None => Ok(()),
    }
}

fn replay_game<G: BoardGame>(game: G, settings: &EmbodiedReplaySettings) -> Result<Dataset> {
    let name = EnvName::Embodied(settings.game, settings.embodiment).canonical();
    let board = match &settings.board {
        Some(text) => game.parse(text).map_err(|e| Error::config(format!("--board '{text}': {e}")))?,
        None => game.goal(),
    };
    let manipulator = settings.embodiment.build(&BoardLayout::of(&game))?.0;
    let mut env = EmbodiedBoard::new(game, manipulator, board);
    let spec = spec_named(&env, &name);
    if let Some((t, a)) = settings.actions.iter().enumerate().find(|(_, a)| a.len() != spec.action_dim()) {
        return Err(Error::data(format!("action {t} has {} value(s); {name} takes {}", a.len(), spec.action_dim())));
    }
    if settings.actions.is_empty() {
        return Err(Error::data("no actions to replay"));
    }
    env.reset(&mut rng_for(settings.seed, &[REPLAY_STREAM]));
    if let Some(state) = &settings.init_state {
        check_manipulator_state(state, settings.game, settings.embodiment)?;
        env.set_manipulator_state(state);
    }
    let mut episodes = Episodes::new(&spec);
    let mut current = episodes.begin(&env);
    for action in &settings.actions {
        let step = env.step(action);
        current.push(action.clone(), step.reward, env.state(), step.obs);
        if step.done {
            episodes.finish(&env, current);
            env.start_skill();
            current = episodes.begin(&env);
        }
    }
    if !current.is_empty() {
        episodes.finish(&env, current);
    }
    Ok(episodes.into_dataset(&spec, settings.seed, &settings.command_line))
}

fn collect_game<G: BoardGame>(game: G, settings: &EmbodiedCollectSettings, monitor: &dyn Monitor) -> Result<Dataset> {
    if settings.episodes == 0 {
        return Err(Error::config("--episodes must be at least 1"));
    }
    let name = EnvName::Embodied(settings.game, settings.embodiment).canonical();
    let goal = game.goal();
    let mut env = EmbodiedBoard::new(game.clone(), settings.embodiment.build(&BoardLayout::of(&game))?.0, goal);
    let spec = spec_named(&env, &name);
    let limit = env.manipulator().skill_step_limit();
    check_size(&spec, settings.episodes, limit, "--episodes × the skill step limit")?;
    let mut episodes = Episodes::new(&spec);
    for k in 0..settings.episodes {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        let mut rng = rng_for(settings.seed, &[k as u64]);
        env.set_board(game.scramble(&mut rng));
        env.reset(&mut rng);
        let mut rollout = episodes.begin(&env);
        loop {
            let action = random_action(&spec, &mut rng);
            let step = env.step(&action);
            rollout.push(action, step.reward, env.state(), step.obs);
            if step.done {
                break;
            }
        }
        episodes.finish(&env, rollout);
        monitor.progress("collect skill episodes", k as u64 + 1, settings.episodes as u64);
    }
    Ok(episodes.into_dataset(&spec, settings.seed, &settings.command_line))
}

fn random_action(spec: &EnvSpec, rng: &mut ChaCha8Rng) -> Vec<f64> {
    spec.action_low.iter().zip(&spec.action_high).map(|(&lo, &hi)| rng.random_range(lo..=hi)).collect()
}

/// The env's spec under its command-line name, so the dataset names an env `parse_env` reads back.
fn spec_named<G: BoardGame>(env: &EmbodiedBoard<G>, name: &str) -> EnvSpec {
    EnvSpec { name: name.to_string(), ..env.spec() }
}

/// Episodes as they are recorded: rollouts numbered in order, with the board each started from.
struct Episodes {
    spec: EnvSpec,
    steps: Vec<Timestep>,
    instances: Vec<serde_json::Value>,
    start_board: String,
}

impl Episodes {
    fn new(spec: &EnvSpec) -> Self {
        Episodes { spec: spec.clone(), steps: Vec::new(), instances: Vec::new(), start_board: String::new() }
    }

    fn begin<G: BoardGame>(&mut self, env: &EmbodiedBoard<G>) -> Rollout {
        self.start_board = env.game().canonical_string(env.board());
        Rollout::start(env.state(), env.observe())
    }

    fn finish<G: BoardGame>(&mut self, env: &EmbodiedBoard<G>, rollout: Rollout) {
        let id = self.instances.len() as u32;
        self.steps.extend(timesteps(&self.spec, &rollout, id));
        self.instances.push(serde_json::json!({
            "game": env.game().name(),
            "embodiment": env.manipulator().name(),
            "start_board": self.start_board,
        }));
    }

    fn into_dataset(self, spec: &EnvSpec, seed: u64, command_line: &str) -> Dataset {
        Dataset {
            meta: crate::data::DatasetMeta::for_env(spec, seed, command_line, self.instances, DatasetLayout::Rollouts),
            steps: self.steps,
            frames: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::NullMonitor;

    fn replay_settings(actions: Vec<Vec<f64>>, init_state: Option<Vec<f64>>) -> EmbodiedReplaySettings {
        EmbodiedReplaySettings {
            game: GameSpec::LightsOut(5),
            embodiment: Embodiment::Cursor,
            actions,
            init_state,
            board: None,
            seed: 1,
            command_line: "test".into(),
        }
    }

    #[test]
    fn a_scripted_push_toggles_its_field_and_ends_the_episode() {
        // From (0.5, 0.5) to (0.7, 0.3) = field (row 1, col 3) and push there; then two idle steps.
        let actions = vec![vec![0.2, -0.2, 1.0], vec![0.0, 0.0, -1.0], vec![0.0, 0.0, -1.0]];
        let data = replay_embodied(&replay_settings(actions, Some(vec![0.5, 0.5]))).unwrap();
        assert_eq!(data.meta.env, "lightsout:cursor");
        let push = &data.steps[0];
        assert_eq!(push.state[..2], [0.5, 0.5]);
        let lit: Vec<usize> = (0..25).filter(|&i| push.next_state[2 + i] == 1.0).collect();
        assert_eq!(lit, vec![3, 7, 8, 9, 13], "field 8 and its neighbours");
        assert_eq!(push.next_state[27], 0.9, "the changing step records the time left, as the reference does");
        assert_eq!(data.steps[1].state[27], 1.0, "the next skill starts with full time");
        assert_eq!((data.steps[1].rollout, data.steps[1].t), (1, 0), "the next episode starts");
        assert_eq!(data.steps[2].next_state[27], 0.8, "two of ten skill steps used");
        assert_eq!(data.meta.instances.len(), 2);
        assert_eq!(data.meta.instances[1]["start_board"], "0,0,0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0");
    }

    #[test]
    fn timeouts_split_episodes_at_the_skill_limit() {
        let data = replay_embodied(&replay_settings(vec![vec![0.0, 0.0, -1.0]; 25], None)).unwrap();
        let ids: Vec<u32> = data.steps.iter().map(|s| s.rollout).collect();
        assert_eq!(ids.iter().filter(|&&i| i == 0).count(), 10);
        assert_eq!(ids.iter().filter(|&&i| i == 2).count(), 5);
        assert_eq!(data.steps[9].next_state[27], 0.0);
        assert_eq!(Rollout::group(&data.steps).unwrap().len(), 3);
    }

    #[test]
    fn bad_start_states_and_boards_are_explained() {
        let reacher = |text| parse_manipulator_state(text, GameSpec::TileSwap, Embodiment::Reacher);
        assert_eq!(reacher("1, 0.5, 0, -2").unwrap(), vec![1.0, 0.5, 0.0, -2.0]);
        let err = reacher("1,2").unwrap_err().to_string();
        assert!(err.contains("2 value(s)") && err.contains("shoulder_angle,wrist_angle"), "{err}");
        assert!(reacher("0,3,0,0").is_ok(), "past the stop is a state the soft limit returns from");
        let err = reacher("0,7,0,0").unwrap_err().to_string();
        assert!(err.contains("wrist_angle = 7") && err.contains("tileswap:reacher"), "{err}");
        let cursor = |text| parse_manipulator_state(text, GameSpec::LightsOut(5), Embodiment::Cursor);
        let err = cursor("0.5,1.2").unwrap_err().to_string();
        assert!(err.contains("cursor_y = 1.2 is off the board"), "{err}");
        assert!(cursor("0.5,NaN").unwrap_err().to_string().contains("not finite"));
        let settings =
            EmbodiedReplaySettings { board: Some("0,1".into()), ..replay_settings(vec![vec![0.0; 3]], None) };
        let err = replay_embodied(&settings).unwrap_err().to_string();
        assert!(err.starts_with("--board '0,1'") && err.contains("25"), "{err}");
        let err = replay_embodied(&replay_settings(vec![vec![0.0; 2]], None)).unwrap_err().to_string();
        assert!(err.contains("action 0 has 2 value(s)"), "{err}");
    }

    #[test]
    fn random_episodes_end_on_a_board_change_or_the_limit() {
        for (game, embodiment, limit) in
            [(GameSpec::TileSwap, Embodiment::Cursor, 10), (GameSpec::LightsOut(5), Embodiment::Reacher, 50)]
        {
            let settings = EmbodiedCollectSettings { game, embodiment, episodes: 6, seed: 3, command_line: "t".into() };
            let data = collect_embodied(&settings, &NullMonitor).unwrap();
            let episodes = Rollout::group(&data.steps).unwrap();
            assert_eq!(episodes.len(), 6);
            assert_eq!(data.meta.instances.len(), 6);
            let bits = data.meta.state_names.iter().filter(|n| n.starts_with("board_")).count();
            let m = data.meta.state_names.len() - bits - 1;
            for (_, r) in &episodes {
                let changed = r.states.last().unwrap()[m..m + bits] != r.states[0][m..m + bits];
                assert!(changed || r.len() == limit, "{} steps without a board change", r.len());
                assert!(r.states[..r.len()].windows(2).all(|w| w[0][m..m + bits] == w[1][m..m + bits]));
            }
            assert_eq!(data, collect_embodied(&settings, &NullMonitor).unwrap(), "seeded");
        }
    }
}
