//! `eval dataset`, `eval pendulum-swingup` and `eval dlgpd`.

use std::path::PathBuf;

use clap::Args;

use super::{recorded, report_job, EvalSummary};
use crate::eval::dlgpd::DlgpdEvalConfig;
use crate::eval::summary::Summary;
use crate::eval::swingup::{self, ModelSpec, SwingupConfig, SwingupSettings};
use crate::jobs::cem_options::CemOptions;
use crate::jobs::model_options::{accepting, report_unfinished, ModelOptions, PropagationChoice};
use crate::jobs::overrides::Overrides;
use crate::jobs::{output_dir, pendulum_variant, Invocation, Job, STEP_RECORD_BYTES};
use crate::{refuse, Result};

#[derive(Args, Debug)]
pub struct DatasetOptions {
    /// Dataset file written by `mbrl collect` or `mbrl plan`.
    #[arg(long, required_unless_present = "config", conflicts_with = "config")]
    input: Option<PathBuf>,
    /// Report directory (default: reports/dataset; when that exists, the first free reports/dataset-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Redo the report of the dataset a dataset report recorded (its config.json).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

pub fn dataset(options: DatasetOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (input, provenance) = match (&options.config, options.input) {
        (Some(path), _) => {
            let (config, provenance) = recorded::<crate::eval::dataset_report::DatasetConfig>(invocation, path)?;
            (config.input, provenance)
        }
        (None, input) => (input.unwrap_or_default(), invocation.provenance()),
    };
    Ok(report_job(
        "eval dataset",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/dataset"), invocation)?,
        move |_, out| Ok(Summary::Dataset(crate::eval::dataset_report::report(&input, &provenance, out)?)),
    ))
}

#[derive(Args, Debug)]
pub struct SwingupOptions {
    #[command(flatten)]
    model: Option<ModelOptions>,
    /// Number of episodes (each with its own start state).
    #[arg(long, default_value_t = 10)]
    episodes: usize,
    #[arg(long, default_value = "pendulum", value_parser = crate::jobs::names::pendulum_envs(), hide_possible_values = true, help = concat!("Environment variant: ", crate::pendulum_envs!()))]
    env: String,
    /// Steps per episode.
    #[arg(long, default_value_t = 150)]
    steps: usize,
    #[command(flatten)]
    cem: CemOptions,
    /// Report directory (default: reports/pendulum-swingup; when that exists, the first free reports/pendulum-swingup-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun the settings and seed a swing-up report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "particles", "propagation", "context", "allow_incomplete", "episodes", "env", "steps", "horizon", "candidates", "elites", "iters", "noise", "beta", "no_warm_start"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

impl SwingupOptions {
    fn config(&self) -> Result<SwingupConfig> {
        let Some(m) = &self.model else {
            refuse!("the following required argument was not provided: --model <MODEL> (or --config FILE)");
        };
        let mut settings = SwingupSettings::thesis(pendulum_variant(&self.env)?);
        settings.steps = self.steps;
        settings.cem = self.cem.config(&settings.cem.action_low, &settings.cem.action_high);
        let propagation = match m.propagation {
            PropagationChoice::Ts1 => "ts1",
            PropagationChoice::Tsinf => "tsinf",
            PropagationChoice::Expectation => "expectation",
        };
        Ok(SwingupConfig {
            model: ModelSpec {
                model: m.model.clone(),
                particles: m.particles,
                propagation: propagation.into(),
                context: m.context.clone(),
                allow_incomplete: m.allow_incomplete,
            },
            env: self.env.clone(),
            episodes: self.episodes,
            settings,
        })
    }
}

/// The command's model flags from a recorded model.
fn model_options(spec: &ModelSpec) -> Result<ModelOptions> {
    let propagation = match spec.propagation.as_str() {
        "ts1" => PropagationChoice::Ts1,
        "tsinf" => PropagationChoice::Tsinf,
        "expectation" => PropagationChoice::Expectation,
        other => refuse!("model.propagation '{other}': expected ts1, tsinf or expectation"),
    };
    Ok(ModelOptions {
        model: spec.model.clone(),
        particles: spec.particles,
        propagation,
        context: spec.context.clone(),
        allow_incomplete: spec.allow_incomplete,
    })
}

pub fn swingup(options: SwingupOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => (options.config()?, invocation.provenance()),
    };
    let config = options.set.apply(config)?;
    let model = model_options(&config.model)?.load(&crate::envs::parse_env(&config.env)?)?;
    config.validate()?;
    crate::util::budget::check(
        &format!("--episodes {} × --steps {}", config.episodes, config.settings.steps),
        crate::util::budget::times(&[config.episodes, config.settings.steps], STEP_RECORD_BYTES),
        "evaluate fewer or shorter episodes",
    )?;
    Ok(report_job(
        "eval pendulum-swingup",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/pendulum-swingup"), invocation)?,
        move |monitor, out| {
            Ok(Summary::PendulumSwingup(swingup::evaluate(&config, model.as_deref(), &provenance, out, monitor)?))
        },
    ))
}

#[derive(Args, Debug)]
pub struct DlgpdOptions {
    /// A DLGPD checkpoint (`mbrl train dlgpd`).
    #[arg(long, required_unless_present = "config")]
    model: Option<PathBuf>,
    /// Settings to swing up (repeatable; default: the thesis' pendulum, pendulum:inverted, pendulum:light,
    /// pendulum:heavy).
    #[arg(long, value_parser = crate::jobs::names::pendulum_envs(), hide_possible_values = true)]
    env: Vec<String>,
    /// Evidence sizes in rollouts of 30 frames (thesis: 10, 20, 30, 50, 70, 100, 200).
    #[arg(long, value_delimiter = ',', default_value = "5,10,20")]
    evidence_rollouts: Vec<usize>,
    /// Runs per point, each with its own evidence pool and start state (thesis: 27).
    #[arg(long, default_value_t = 2)]
    runs: usize,
    /// Steps per swing-up.
    #[arg(long, default_value_t = 150)]
    steps: usize,
    /// CEM candidates per iteration (the authors': 1000, about 1.5 s a step on 2 cores at 10 evidence rollouts).
    #[arg(long, default_value_t = 300)]
    candidates: usize,
    /// CEM elites (the authors': 100).
    #[arg(long, default_value_t = 30)]
    elites: usize,
    /// At most this many CEM iterations per step (the authors': 30, stopping at first-action std ≤ 0.01).
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// Skip the swing-ups: only check the conditioned models' reward predictions on held-out rollouts
    /// (seconds instead of an hour; tells a model that cannot see the pendulum from a planner that fails).
    #[arg(long, conflicts_with_all = ["runs", "steps", "candidates", "elites", "iters"])]
    prediction_only: bool,
    /// Take a run still in training (its best-validation weights so far); the report says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Report directory (default: reports/dlgpd; when that exists, the first free reports/dlgpd-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun the settings and seed a dlgpd report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "env", "evidence_rollouts", "runs", "steps", "candidates", "elites", "iters", "prediction_only", "allow_incomplete"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

pub fn dlgpd(options: DlgpdOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => {
            // The command's own error for a bad --env names the pendulum variants it knows.
            for env in &options.env {
                pendulum_variant(env)?;
            }
            let config = DlgpdEvalConfig {
                model: options.model.clone().unwrap_or_default(),
                envs: options.env.clone(),
                evidence_rollouts: options.evidence_rollouts.clone(),
                runs: options.runs,
                steps: options.steps,
                candidates: options.candidates,
                elites: options.elites,
                iters: options.iters,
                prediction_only: options.prediction_only,
                allow_incomplete: options.allow_incomplete,
            };
            (config, invocation.provenance())
        }
    };
    let config = options.set.apply(config)?;
    config.settings()?;
    let trained = crate::models::dlgpd::job::load(&config.model, accepting(config.allow_incomplete))?;
    report_unfinished(&config.model, &trained.progress);
    Ok(report_job(
        "eval dlgpd",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/dlgpd"), invocation)?,
        move |monitor, out| {
            Ok(Summary::Dlgpd(crate::eval::dlgpd::evaluate(&trained, &config, &provenance, out, monitor)?))
        },
    ))
}
