//! Solving boards with what SEADS learned (thesis Alg. 3 and 4): breadth-first search over the forward model's
//! most likely successors, each planned skill executed by the skill policy in the embodiment, and a new plan
//! whenever the board turns out differently from the model's prediction (up to a replanning budget).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rand_chacha::ChaCha8Rng;

use super::collect::policy_input;
use super::forward_model::{FlipModel, FlipScratch};
use super::trainer::MODEL_PREFIX;
use super::{EmbodiedGame, Seads, SeadsRun};
use crate::control::{run_episode, Agent};
use crate::envs::boards::BoardGame;
use crate::envs::embodiments::embodied::EmbodiedBoard;
use crate::envs::embodiments::BoardLayout;
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::nn::ParamSet;
use crate::planning::bfs::{bidirectional, breadth_first, SearchLimits, SearchResult, SuccessorModel};
use crate::planning::board_view::{plan_text, show_boards, EffectorTrace};
use crate::rl::sac::Sac;
use crate::run::{Event, Monitor};
use crate::train::{open_run, Accept, TrainingProgress, MODEL_FILE};

/// A trained SEADS checkpoint: the skill policy and the forward model.
pub struct LoadedSeads {
    pub run: SeadsRun,
    pub env: EmbodiedGame,
    pub policy: Sac,
    pub model: FlipModel,
    pub dir: PathBuf,
    pub progress: TrainingProgress,
}

/// A SEADS run, finished or (with [`Accept::InProgress`]) still training: then the weights of its last
/// checkpoint, as SEADS has no validation to pick a best from.
pub fn load(dir: &Path, accept: Accept) -> Result<LoadedSeads> {
    let (opened, run) = open_run::<Seads>(dir, accept)?;
    let env = EmbodiedGame::parse(run.env())?;
    let weights = opened.tensors(MODEL_FILE)?;
    let (model_tensors, policy_tensors): (Vec<_>, Vec<_>) =
        weights.into_iter().partition(|t| t.name.starts_with(MODEL_PREFIX));
    let (manipulator, _) = env.embodiment.build(&env.board_layout()?)?;
    let sac_config =
        run.config.sac_config(run.details.policy_input, manipulator.action_low(), manipulator.action_high());
    let policy = Sac::from_weights(sac_config, &policy_tensors).map_err(|e| e.at(&dir.join(MODEL_FILE)))?;
    let mut params = ParamSet::<f32>::default();
    for t in model_tensors {
        let values = match t.data {
            crate::train::tensors::TensorData::F32(v) => v,
            _ => return Err(Error::bad_file(&dir.join(MODEL_FILE), format!("'{}' is not f32", t.name))),
        };
        params.tensors.push(crate::nn::NamedTensor {
            name: t.name.trim_start_matches(MODEL_PREFIX).to_string(),
            shape: t.shape,
            values,
        });
    }
    let model = FlipModel::from_params(&params, run.details.board_bits, run.config.skills)
        .map_err(|e| e.at(&dir.join(MODEL_FILE)))?;
    Ok(LoadedSeads { run, env, policy, model, dir: dir.to_path_buf(), progress: opened.progress() })
}

/// The learned forward model as a successor model: a skill leads to the most likely next board; a prediction
/// that is no board of the game counts as "nothing changes". Bidirectional search assumes skills undo
/// themselves; `check_inverse` verifies that on every state the search expands and records a violation.
pub struct LearnedSuccessors<'a, G: BoardGame> {
    pub game: &'a G,
    pub model: &'a FlipModel,
    pub check_inverse: bool,
    violated: AtomicBool,
}

impl<'a, G: BoardGame> LearnedSuccessors<'a, G> {
    pub fn new(game: &'a G, model: &'a FlipModel, check_inverse: bool) -> Self {
        LearnedSuccessors { game, model, check_inverse, violated: AtomicBool::new(false) }
    }

    pub fn inverse_violated(&self) -> bool {
        self.violated.load(Ordering::Relaxed)
    }

    /// Every skill's predicted successor of every state, `out[i·K + k]`. A search's batch of 1024 states is
    /// 25 600 MLP rows for LightsOut; the batch is split across the rayon pool (in order, so the result does not
    /// depend on the thread count).
    fn successors(&self, states: &[G::State]) -> Vec<G::State> {
        use rayon::prelude::*;
        let chunk = states.len().div_ceil(rayon::current_num_threads().max(1)).max(64);
        let parts: Vec<Vec<G::State>> = states.par_chunks(chunk).map(|part| self.successors_of(part)).collect();
        parts.concat()
    }

    /// `states[i]`'s predicted successor under `skills[i]`.
    fn successors_of_pairs(&self, states: &[G::State], skills: &[usize]) -> Vec<G::State> {
        use rayon::prelude::*;
        let chunk = states.len().div_ceil(rayon::current_num_threads().max(1)).max(256);
        let parts: Vec<Vec<G::State>> = states
            .par_chunks(chunk)
            .zip(skills.par_chunks(chunk))
            .map(|(part, part_skills)| {
                let bits: Vec<f32> =
                    part.iter().flat_map(|&s| self.game.symbolic(s).into_iter().map(|b| b as f32)).collect();
                let mut predicted = Vec::new();
                self.model.mode_successors_of_pairs(&bits, part_skills, &mut predicted, &mut FlipScratch::default());
                self.decode(&predicted, |row| part[row])
            })
            .collect();
        parts.concat()
    }

    fn successors_of(&self, states: &[G::State]) -> Vec<G::State> {
        let bits: Vec<f32> = states.iter().flat_map(|&s| self.game.symbolic(s).into_iter().map(|b| b as f32)).collect();
        let mut predicted = Vec::new();
        self.model.mode_successors(&bits, &mut predicted, &mut FlipScratch::default());
        let k = self.model.skills;
        self.decode(&predicted, |row| states[row / k])
    }

    /// Boards from predicted bit rows; a row that is no board of the game becomes `unchanged(row)`.
    fn decode(&self, predicted: &[f32], unchanged: impl Fn(usize) -> G::State) -> Vec<G::State> {
        let mut z = vec![0.0f64; self.model.bits];
        predicted
            .chunks(self.model.bits)
            .enumerate()
            .map(|(row, bits)| {
                z.iter_mut().zip(bits).for_each(|(a, &b)| *a = b as f64);
                self.game.decode_symbolic(&z).unwrap_or_else(|| unchanged(row))
            })
            .collect()
    }

    /// The model's prediction for one state and skill.
    pub fn predict(&self, state: G::State, skill: usize) -> G::State {
        self.successors(&[state])[skill]
    }
}

impl<G: BoardGame> SuccessorModel for LearnedSuccessors<'_, G> {
    type State = G::State;

    fn num_actions(&self) -> usize {
        self.model.skills
    }

    fn expand(&self, states: &[G::State], out: &mut Vec<G::State>) {
        let next = self.successors(states);
        if self.check_inverse {
            let k = self.model.skills;
            let skills: Vec<usize> = (0..next.len()).map(|i| i % k).collect();
            let back = self.successors_of_pairs(&next, &skills);
            if back.iter().enumerate().any(|(i, &b)| b != states[i / k]) {
                self.violated.store(true, Ordering::Relaxed);
            }
        }
        out.extend(next);
    }

    fn self_inverse(&self) -> bool {
        self.check_inverse
    }
}

/// One skill run by its policy until the board changed or its step limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExecutedSkill {
    pub skill: usize,
    /// The game move it performed, if the board changed by one.
    pub performed: Option<usize>,
    /// Manipulator steps it took (thesis Fig. 7.9's skill length).
    pub steps: usize,
}

/// How a board was solved (or not) with skills.
#[derive(Clone, Debug)]
pub struct SkillSolve<S> {
    /// Every plan made, the first and each replan.
    pub plans: Vec<Vec<usize>>,
    pub executed: Vec<ExecutedSkill>,
    pub final_board: S,
    pub solved: bool,
    pub control_steps: usize,
    pub planning_seconds: f64,
    /// Whether bidirectional search was used (the model was self-inverse on every state it met).
    pub bidirectional: bool,
}

/// Plans with the learned model (bidirectional where verified, else one-sided) from `board`.
pub fn plan_with_model<G: BoardGame>(
    game: &G,
    model: &FlipModel,
    board: G::State,
    bidirectional_allowed: bool,
    limits: &SearchLimits,
) -> Result<(SearchResult, bool)> {
    if bidirectional_allowed {
        let checked = LearnedSuccessors::new(game, model, true);
        let result = bidirectional(&checked, board, game.goal(), limits, |_| {})?;
        if !checked.inverse_violated() {
            return Ok((result, true));
        }
    }
    let one_sided = LearnedSuccessors::new(game, model, false);
    Ok((breadth_first(&one_sided, board, |s| *s == game.goal(), limits, |_| {})?, false))
}

/// One skill played by the deterministic skill policy until the embodiment says the skill is over.
struct SkillAgent<'a> {
    policy: &'a Sac,
    skill: usize,
    skills: usize,
    rng: &'a mut ChaCha8Rng,
    input: Vec<f32>,
}

impl Agent for SkillAgent<'_> {
    fn act(&mut self, _t: usize, _state: &[f64], observation: &[f64]) -> Result<Vec<f64>> {
        self.input.clear();
        let obs: Vec<f32> = observation.iter().map(|&x| x as f32).collect();
        policy_input(&obs, self.skill, self.skills, &mut self.input);
        let action = self.policy.try_act(&self.input, 1, true, &mut *self.rng)?;
        Ok(action.iter().map(|&a| a as f64).collect())
    }
}

/// Algorithm 4: plan, execute skill by skill with the deterministic policy, replan when the board differs from
/// the prediction, at most `max_replans` times.
#[allow(clippy::too_many_arguments)]
pub fn solve_with_skills<G: BoardGame>(
    game: &G,
    loaded: &LoadedSeads,
    board: G::State,
    bidirectional_allowed: bool,
    limits: &SearchLimits,
    max_replans: usize,
    rng: &mut ChaCha8Rng,
    monitor: &dyn Monitor,
) -> Result<SkillSolve<G::State>> {
    let (manipulator, _) = loaded.env.embodiment.build(&BoardLayout::of(game))?;
    let mut env = EmbodiedBoard::new(game.clone(), manipulator, board);
    env.reset(rng);
    let k = loaded.run.config.skills;
    let successors = LearnedSuccessors::new(game, &loaded.model, false);
    let mut out = SkillSolve {
        plans: Vec::new(),
        executed: Vec::new(),
        final_board: board,
        solved: board == game.goal(),
        control_steps: 0,
        planning_seconds: 0.0,
        bidirectional: false,
    };
    let mut trace = EffectorTrace::default();
    show_boards(monitor, game, board, None);
    while !out.solved && out.plans.len() <= max_replans {
        let started = Instant::now();
        let (result, bi) = plan_with_model(game, &loaded.model, env.board(), bidirectional_allowed, limits)?;
        out.planning_seconds += started.elapsed().as_secs_f64();
        out.bidirectional |= bi;
        let Some(plan) = result.plan else { break };
        let skills: Vec<String> = plan.iter().map(|k| format!("skill {k}")).collect();
        let number = out.plans.len() + 1;
        let show_plan = |played: usize, playing: bool| {
            let text = format!("plan {number} of skills:\n{}", plan_text(&skills, played, playing));
            monitor.emit(&Event::text("plan", text));
        };
        show_plan(0, false);
        out.plans.push(plan.clone());
        let phase = format!("plan {}: skills played", out.plans.len());
        for (i, &skill) in plan.iter().enumerate() {
            show_plan(i, true);
            let before = env.board();
            let expected = successors.predict(before, skill);
            env.set_board(before);
            let mut performed = None;
            let mut agent = SkillAgent { policy: &loaded.policy, skill, skills: k, rng: &mut *rng, input: Vec::new() };
            let executed = run_episode(&mut env, &mut agent, usize::MAX, monitor, |_, env, _| {
                trace.record(monitor, env.manipulator().effector());
                if env.board() != before {
                    performed = (0..game.num_moves()).find(|&m| game.apply(before, m) == env.board());
                }
                Ok(())
            })?;
            let steps = executed.len();
            out.control_steps += steps;
            out.executed.push(ExecutedSkill { skill, performed, steps });
            monitor.progress(&phase, i as u64 + 1, plan.len() as u64);
            show_plan(i + 1, false);
            let caption = format!("after {} skills", out.executed.len());
            show_boards(monitor, game, board, Some((&caption, env.board())));
            if env.board() != expected {
                break;
            }
        }
        out.solved = env.board() == game.goal();
    }
    out.final_board = env.board();
    Ok(out)
}
