//! `mbrl calibrate`: act in an unseen instance to infer its hidden parameters with a trained context model, and
//! save the calibration transitions (the context set) for `plan --context`.

use std::fmt;
use std::path::{Path, PathBuf};

use clap::Args;

use super::choices::StrategyChoice;
use super::model_options::{accepting, report_unfinished};
use super::{file_stem, output_file, parse_floats, Invocation, Job};
use crate::data::write_dataset;
use crate::envs::terrain::TerrainMap;
use crate::envs::unicycle::UnicycleTerrain;
use crate::envs::{parse_env, EnvName};
use crate::models::context::calibration::{
    calibration_dataset, layout, run_calibration, CalibrationRequest, CalibrationSettings,
};
use crate::models::context::{self, fast::gaussian_entropy, LoadedModel};
use crate::models::tradyn::{self, TradynModel};
use crate::train::{Accept, OpenedCheckpoint};
use crate::{refuse, Result};

/// Calibrate a context model in an instance of its env by expected information gain.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl calibrate --model models/context-toy-inner --env toy:inner --instance-seed 7 --strategy open-loop --transitions 1 --out calib.mcap
  mbrl collect --env pendulum:quadrant --instances 2000 --steps 100 --out datasets/quadrant-pairs.mcap
  mbrl train context --data datasets/quadrant-pairs.mcap --preset small --out models/context-pendulum-quadrant
  mbrl calibrate --model models/context-pendulum-quadrant --env pendulum:quadrant --instance-seed 3 --strategy mpc --transitions 30 --horizon 20 --out calib-quadrant.mcap
  mbrl plan --env pendulum:quadrant --model models/context-pendulum-quadrant --context calib-quadrant.mcap --instance-seed 3
  mbrl calibrate --model models/tradyn-terrain --env unicycle --map datasets/terrain/map050.png --instance-seed 4 --strategy random --init-state 0.2,0.3,0,1.57 --out calib-uni.mcap

The instance (hidden parameters) is the one --instance-seed names in every command. Starts: toy and MountainCar at x = 0 (thesis), pendulum from its reset draw (--seed), or --init-state. The thesis uses CEM 1000 candidates / 100 elites / 10 iterations and 20 β samples; pendulum N = 30, H_max = 20; MountainCar N = 50, H_max = 30. The command prints the entropy of q(β | transitions) before and after. A TRADYN model calibrates with random colored actions (as its data were collected), 10 transitions by default, on the --map the robot drives on; the instance is the robot (mass, throttle and steering gains).")]
pub struct CalibrateOptions {
    /// A context-model checkpoint (`mbrl train context`, or `mbrl train tradyn` for the unicycle).
    #[arg(long)]
    model: PathBuf,
    /// Environment the model was trained on, e.g. toy:inner, pendulum:quadrant, mountaincar, unicycle.
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: String,
    /// For --env unicycle: the terrain map (PNG) the robot calibrates on.
    #[arg(long)]
    map: Option<PathBuf>,
    /// Which instance (hidden parameters) to calibrate in.
    #[arg(long)]
    instance_seed: u64,
    #[arg(long, value_enum)]
    strategy: StrategyChoice,
    /// Calibration transitions N (default 30; TRADYN 10).
    #[arg(long)]
    transitions: Option<usize>,
    /// H_max: the longest planning horizon of MPC calibration.
    #[arg(long, default_value_t = 20)]
    horizon: usize,
    /// CEM candidates per iteration.
    #[arg(long, default_value_t = 1000)]
    candidates: usize,
    /// CEM elites.
    #[arg(long, default_value_t = 100)]
    elites: usize,
    /// CEM iterations.
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// β samples of the Monte Carlo information gain.
    #[arg(long, default_value_t = 20)]
    beta_samples: usize,
    /// Start state, comma-separated in the env's state order (pendulum: θ,θ̇; unicycle: x,y,v,φ). Default: the thesis' start
    /// (toy x = 0; MountainCar x = ẋ = 0; pendulum:quadrant hanging down, |θ − π|, |θ̇| ≤ 0.05, drawn from
    /// --seed), elsewhere a reset drawn from --seed.
    #[arg(long)]
    init_state: Option<String>,
    /// Where to write the calibration transitions (default: datasets/calib-<env>-<strategy>-i<S>.mcap; when
    /// that exists, the first free name ending -2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Take a run still in training (its best-validation weights so far); the output says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
}

/// The entropy of q(β | context) before and after calibrating, and where the context set went.
pub struct CalibrateSummary {
    env: String,
    instance_seed: u64,
    instance: serde_json::Value,
    transitions: usize,
    strategy: &'static str,
    prior_entropy: f64,
    entropy: f64,
    unfinished_note: String,
    out: PathBuf,
}

impl fmt::Display for CalibrateSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        writeln!(
            f,
            "calibrated {} instance {} ({}) with {} {} transitions: entropy of q(β | context) {:.3} → {:.3} nats{}",
            self.env,
            self.instance_seed,
            self.instance,
            self.transitions,
            self.strategy,
            self.prior_entropy,
            self.entropy,
            self.unfinished_note
        )?;
        write!(f, "context set written to {}", self.out.display())
    }
}

pub fn prepare(options: CalibrateOptions, invocation: &Invocation) -> Result<Job<'static, CalibrateSummary>> {
    let mut env = parse_env(&options.env)?;
    let unicycle = matches!(env, EnvName::Unicycle(_));
    match (&options.map, unicycle) {
        (Some(map), true) => env = env.with_terrain(UnicycleTerrain::new(vec![TerrainMap::read_png(map)?]))?,
        (None, true) => refuse!("--env unicycle: give --map PNG, the terrain the robot calibrates on"),
        (Some(_), false) => refuse!("--map is the unicycle's terrain; '{}' has none", env.canonical()),
        (None, false) => {}
    }
    let strategy = options.strategy.into();
    let transitions = options.transitions.unwrap_or(if unicycle { 10 } else { 30 });
    let settings = CalibrationSettings {
        strategy,
        transitions,
        horizon_max: options.horizon,
        candidates: options.candidates,
        elites: options.elites,
        iterations: options.iters,
        beta_samples: options.beta_samples,
    };
    settings.validate()?;
    let init_state = options.init_state.as_deref().map(|s| parse_floats("--init-state", s)).transpose()?;
    if !options.model.is_dir() {
        refuse!("--model {}: no such checkpoint directory", options.model.display());
    }
    let model = load_model(&options.model, &env, accepting(options.allow_incomplete))?;
    report_unfinished(&options.model, &model.progress);
    let default = || {
        let (env, strategy, instance) = (file_stem(&env.canonical()), strategy.name(), options.instance_seed);
        PathBuf::from(format!("datasets/calib-{env}-{strategy}-i{instance}.mcap"))
    };
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    let seed = invocation.seed;
    let request =
        CalibrationRequest { env: env.clone(), instance_seed: options.instance_seed, init_state, settings, seed };
    let spec = env.build()?.spec();
    let unfinished_note = model.progress.unfinished_note();
    let title = format!(
        "calibrate {} ({}, {} transitions, instance {}{})",
        env.canonical(),
        strategy.name(),
        transitions,
        options.instance_seed,
        unfinished_note
    );
    let command_line = invocation.command_line.clone();
    Ok(Job::new("calibrate", move |monitor| {
        monitor.emit(&layout(&title, &spec.state_names));
        let (calibration, instance) = run_calibration(&model, &request, monitor)?;
        let dataset = calibration_dataset(&env, &calibration, instance.clone(), seed, &command_line)?;
        write_dataset(&out, &dataset)?;
        let prior_entropy = gaussian_entropy(&model.fast.belief(&vec![0.0; model.fast.transition_features], 1).std);
        Ok(CalibrateSummary {
            env: env.canonical(),
            instance_seed: request.instance_seed,
            instance,
            transitions: calibration.rollout.len(),
            strategy: strategy.name(),
            prior_entropy,
            entropy: calibration.entropies.last().copied().unwrap_or(prior_entropy),
            unfinished_note,
            out,
        })
    }))
}

/// A context model of `env`, or a TRADYN model when `env` is the unicycle.
fn load_model(dir: &Path, env: &EnvName, accept: Accept) -> Result<LoadedModel> {
    let method = OpenedCheckpoint::open(dir)?.manifest.method;
    let unicycle = matches!(env, EnvName::Unicycle(_));
    if unicycle && method != tradyn::METHOD {
        refuse!(
            "{}: is a '{method}' checkpoint; the unicycle calibrates a TRADYN model (`mbrl train tradyn`)",
            dir.display()
        );
    }
    if method == tradyn::METHOD && !unicycle {
        refuse!("{}: is a TRADYN model of the unicycle; calibrate it with --env unicycle --map PNG", dir.display());
    }
    Ok(if unicycle { TradynModel::load(dir, accept)?.loaded } else { context::load(dir, env, accept)? })
}
