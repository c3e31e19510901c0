//! `eval ball`, `eval context` and `eval tradyn`: protocols of trained filters and context models.

use std::path::PathBuf;

use clap::Args;

use super::{recorded, report_job, EvalSummary};
use crate::envs::EnvName;
use crate::eval::ball::{self, BallConfig, BallEvalSettings};
use crate::eval::context::{ContextEvalConfig, ContextEvalSettings};
use crate::eval::summary::Summary;
use crate::eval::swingup::SwingupSettings;
use crate::eval::tradyn::{TradynEvalConfig, TradynEvalModels};
use crate::jobs::choices::StrategyChoice;
use crate::jobs::model_options::{accepting, report_unfinished};
use crate::jobs::overrides::Overrides;
use crate::jobs::{output_dir, Invocation, Job};
use crate::models::ball::checkpoint::{load_ball_model, report_name};
use crate::models::context::calibration::{CalibrationSettings, Strategy};
use crate::{refuse, Result};

#[derive(Args, Debug)]
pub struct BallOptions {
    /// EKF models to compare (repeatable): thesis, initial, or checkpoint directories.
    #[arg(long, default_values_t = ["thesis".to_string(), "initial".to_string()])]
    model: Vec<String>,
    /// Default-pose shots the black-box baseline is fitted on.
    #[arg(long, default_value_t = 108)]
    train_shots: usize,
    /// Rotated copies per training shot.
    #[arg(long, default_value_t = 19)]
    augment_rotations: usize,
    /// Default-pose test shots.
    #[arg(long, default_value_t = 163)]
    test_shots: usize,
    /// Test shots per unseen pose (5 poses).
    #[arg(long, default_value_t = 30)]
    unseen_shots: usize,
    /// Report directory (default: reports/ball; when that exists, the first free reports/ball-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun the settings and seed a ball report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "train_shots", "augment_rotations", "test_shots", "unseen_shots"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

pub fn ball(options: BallOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => (
            BallConfig {
                models: options.model.clone(),
                settings: BallEvalSettings {
                    train_shots: options.train_shots,
                    augment_rotations: options.augment_rotations,
                    test_shots_default: options.test_shots,
                    test_shots_unseen: options.unseen_shots,
                    ..BallEvalSettings::default()
                },
            },
            invocation.provenance(),
        ),
    };
    let config = options.set.apply(config)?;
    let models = config.models.iter().map(|m| Ok((report_name(m), load_ball_model(m)?))).collect::<Result<Vec<_>>>()?;
    config.validate()?;
    Ok(report_job(
        "eval ball",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/ball"), invocation)?,
        move |monitor, out| Ok(Summary::Ball(ball::evaluate(&config, models, &provenance, out, monitor)?)),
    ))
}

#[derive(Args, Debug)]
pub struct ContextOptions {
    /// A context-model checkpoint (`mbrl train context`).
    #[arg(long, required_unless_present = "config")]
    model: Option<PathBuf>,
    /// The env the model was trained on.
    #[arg(long, required_unless_present = "config", value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Unseen contexts (instances) to calibrate in (thesis: 50).
    #[arg(long, default_value_t = 20)]
    contexts: usize,
    /// Random validation rollouts per context (thesis: 20).
    #[arg(long, default_value_t = 20)]
    validation_rollouts: usize,
    /// Steps per validation rollout (thesis: 50).
    #[arg(long, default_value_t = 50)]
    validation_steps: usize,
    /// Calibration transitions N (toy 1–3, pendulum 30, MountainCar 50).
    #[arg(long, default_value_t = 30)]
    transitions: usize,
    /// H_max of MPC calibration (pendulum 20, MountainCar 30).
    #[arg(long, default_value_t = 20)]
    horizon: usize,
    /// Strategies to compare (repeatable; default: all three).
    #[arg(long, value_enum)]
    strategy: Vec<StrategyChoice>,
    /// CEM candidates per iteration (thesis 1000).
    #[arg(long, default_value_t = 1000)]
    candidates: usize,
    /// CEM elites (thesis 100).
    #[arg(long, default_value_t = 100)]
    elites: usize,
    /// CEM iterations (thesis 10).
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// β samples of the information gain (thesis 20).
    #[arg(long, default_value_t = 20)]
    beta_samples: usize,
    /// Pendulum: after each calibration, swing up with MPC on the calibrated model (thesis 4.5.3), and once on
    /// the true equations as the reference.
    #[arg(long)]
    swingup: bool,
    /// Agent steps of each swing-up (thesis 50; the quadrant pendulum repeats each action twice).
    #[arg(long, default_value_t = 50, requires = "swingup")]
    swingup_steps: usize,
    /// CEM candidates of the swing-up planner (thesis 1000; elites are a tenth, 10 iterations, horizon 20).
    #[arg(long, default_value_t = 1000, requires = "swingup")]
    swingup_candidates: usize,
    /// Take a run still in training (its best-validation weights so far); the report says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Report directory (default: reports/context; when that exists, the first free reports/context-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun the settings and seed a context report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "env", "contexts", "validation_rollouts", "validation_steps", "transitions", "horizon", "strategy", "candidates", "elites", "iters", "beta_samples", "swingup", "swingup_steps", "swingup_candidates", "allow_incomplete"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

impl ContextOptions {
    fn config(&self, env: &EnvName) -> Result<ContextEvalConfig> {
        let strategies: Vec<Strategy> = if self.strategy.is_empty() {
            Strategy::ALL.to_vec()
        } else {
            self.strategy.iter().map(|&s| s.into()).collect()
        };
        let swingup = match (self.swingup, env) {
            (false, _) => None,
            (true, EnvName::Pendulum(variant)) => {
                let mut swingup = SwingupSettings::thesis(variant.clone());
                swingup.steps = self.swingup_steps;
                swingup.cem.candidates = self.swingup_candidates;
                swingup.cem.elites = (self.swingup_candidates / 10).max(2);
                Some(swingup)
            }
            (true, other) => {
                refuse!("--swingup needs a pendulum env (pendulum:quadrant in the thesis), not '{}'", other.canonical())
            }
        };
        Ok(ContextEvalConfig {
            model: self.model.clone().unwrap_or_default(),
            env: env.canonical(),
            allow_incomplete: self.allow_incomplete,
            settings: ContextEvalSettings {
                contexts: self.contexts,
                validation_rollouts: self.validation_rollouts,
                validation_steps: self.validation_steps,
                strategies,
                calibration: CalibrationSettings {
                    strategy: Strategy::Random,
                    transitions: self.transitions,
                    horizon_max: self.horizon,
                    candidates: self.candidates,
                    elites: self.elites,
                    iterations: self.iters,
                    beta_samples: self.beta_samples,
                },
                swingup,
            },
        })
    }
}

pub fn context(options: ContextOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => (
            options.config(&crate::envs::parse_env(options.env.as_deref().unwrap_or_default())?)?,
            invocation.provenance(),
        ),
    };
    let config = options.set.apply(config)?;
    let env = crate::envs::parse_env(&config.env)?;
    if !config.model.is_dir() {
        refuse!("--model {}: no such checkpoint directory", config.model.display());
    }
    config.validate(&env)?;
    let model = crate::models::context::load(&config.model, &env, accepting(config.allow_incomplete))?;
    report_unfinished(&config.model, &model.progress);
    Ok(report_job(
        "eval context",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/context"), invocation)?,
        move |monitor, out| {
            Ok(Summary::Context(crate::eval::context::evaluate(&model, &env, &config, &provenance, out, monitor)?))
        },
    ))
}

#[derive(Args, Debug)]
pub struct TradynOptions {
    /// The TRADYN model with terrain lookup (`mbrl train tradyn`): the +T variants.
    #[arg(long, required_unless_present = "config")]
    model_terrain: Option<PathBuf>,
    /// The ablation trained with `--no-terrain`: the −T variants.
    #[arg(long, required_unless_present = "config")]
    model_no_terrain: Option<PathBuf>,
    /// The map set (`mbrl collect --env terrain`); tasks are drawn on its test maps.
    #[arg(long, required_unless_present = "config")]
    maps: Option<PathBuf>,
    /// Navigation tasks (thesis: 150 per model seed).
    #[arg(long, default_value_t = 20)]
    tasks: usize,
    /// Random colored calibration transitions from each start (thesis 10).
    #[arg(long, default_value_t = 10)]
    transitions: usize,
    /// Executed steps per task (thesis 50).
    #[arg(long, default_value_t = 50)]
    steps: usize,
    /// Longest planning horizon (thesis 30; it shrinks to the steps left).
    #[arg(long, default_value_t = 30)]
    horizon: usize,
    /// CEM candidates per iteration (thesis 1000; the default trades it for time on a CPU).
    #[arg(long, default_value_t = 300)]
    candidates: usize,
    /// CEM elites (thesis 50).
    #[arg(long, default_value_t = 30)]
    elites: usize,
    /// CEM iterations (thesis 20).
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// Length of the random rollout per task whose open-loop prediction is scored (thesis 50).
    #[arg(long, default_value_t = 50)]
    prediction_steps: usize,
    /// Report directory (default: reports/tradyn; when that exists, the first free reports/tradyn-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Take runs still in training (their best-validation weights so far); the report says how far each got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Rerun the settings and seed a tradyn report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model_terrain", "model_no_terrain", "maps", "tasks", "transitions", "steps", "horizon", "candidates", "elites", "iters", "prediction_steps", "allow_incomplete"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

pub fn tradyn(options: TradynOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    use crate::models::tradyn::TradynModel;
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => (
            TradynEvalConfig {
                model_terrain: options.model_terrain.clone().unwrap_or_default(),
                model_no_terrain: options.model_no_terrain.clone().unwrap_or_default(),
                maps: options.maps.clone().unwrap_or_default(),
                allow_incomplete: options.allow_incomplete,
                tasks: options.tasks,
                transitions: options.transitions,
                steps: options.steps,
                horizon: options.horizon,
                candidates: options.candidates,
                elites: options.elites,
                iters: options.iters,
                prediction_steps: options.prediction_steps,
            },
            invocation.provenance(),
        ),
    };
    let config = options.set.apply(config)?;
    config.settings()?;
    for (flag, dir) in [("--model-terrain", &config.model_terrain), ("--model-no-terrain", &config.model_no_terrain)] {
        if !dir.is_dir() {
            refuse!("{flag} {}: no such checkpoint directory", dir.display());
        }
    }
    let accept = accepting(config.allow_incomplete);
    let models = TradynEvalModels {
        terrain: TradynModel::load(&config.model_terrain, accept)?,
        no_terrain: TradynModel::load(&config.model_no_terrain, accept)?,
    };
    for model in [&models.terrain, &models.no_terrain] {
        report_unfinished(&model.loaded.dir, &model.loaded.progress);
    }
    models.check()?;
    let maps =
        crate::data::terrain_set::read_terrain_set(&config.maps, Some(crate::envs::terrain::TerrainSplit::Test))?;
    Ok(report_job(
        "eval tradyn",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/tradyn"), invocation)?,
        move |monitor, out| {
            Ok(Summary::Tradyn(crate::eval::tradyn::evaluate(&models, maps, &config, &provenance, out, monitor)?))
        },
    ))
}
