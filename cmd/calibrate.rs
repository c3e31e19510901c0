//! `mbrl calibrate`: act in an unseen instance to infer its hidden parameters with a trained context model, and
//! save the calibration transitions (the context set) for `plan --context`.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use mbrl::data::write_dataset;
use mbrl::envs::terrain::TerrainMap;
use mbrl::envs::unicycle::UnicycleTerrain;
use mbrl::envs::{parse_env, EnvName};
use mbrl::models::context::calibration::{
    calibration_dataset, layout, run_calibration, CalibrationRequest, CalibrationSettings,
};
use mbrl::models::context::{self, fast::gaussian_entropy, LoadedModel};
use mbrl::models::tradyn::{self, TradynModel};
use mbrl::train::{Accept, OpenedCheckpoint};

use crate::common::{check_output_file, command_line, file_stem, parse_floats, run_job, GlobalArgs};
use mbrl::jobs::choices::StrategyChoice;
use mbrl::jobs::model_options::{accepting, report_unfinished};

/// Calibrate a context model in an instance of its env by expected information gain.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl calibrate --model models/context-toy-inner --env toy:inner --instance-seed 7 --strategy open-loop --transitions 1 --out calib.mcap
  mbrl calibrate --model models/context-pendulum-quadrant --env pendulum:quadrant --instance-seed 3 --strategy mpc --transitions 30 --horizon 20
  mbrl plan --env pendulum:quadrant --model models/context-pendulum-quadrant --context calib.mcap --instance-seed 3
  mbrl calibrate --model models/tradyn-terrain --env unicycle --map datasets/terrain/map050.png --instance-seed 4 --strategy random --init-state 0.2,0.3,0,1.57 --out calib-uni.mcap

The instance (hidden parameters) is the one --instance-seed names in every command. Starts: toy and
MountainCar at x = 0 (thesis), pendulum from its reset draw (--seed), or --init-state. The thesis uses
CEM 1000 candidates / 100 elites / 10 iterations and 20 β samples; pendulum N = 30, H_max = 20;
MountainCar N = 50, H_max = 30. The command prints the entropy of q(β | transitions) before and after.
A TRADYN model calibrates with random colored actions (as its data were collected), 10 transitions by
default, on the --map the robot drives on; the instance is the robot (mass, throttle and steering gains).")]
pub struct CalibrateArgs {
    /// A context-model checkpoint (`mbrl train context`, or `mbrl train tradyn` for the unicycle).
    #[arg(long)]
    model: PathBuf,
    /// Environment the model was trained on, e.g. toy:inner, pendulum:quadrant, mountaincar, unicycle.
    #[arg(long)]
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
    /// Where to write the calibration transitions (default: datasets/calib-<env>-<strategy>-i<S>.mcap).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Take a run still in training (its best-validation weights so far); the output says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
}

pub fn run(global: &GlobalArgs, args: CalibrateArgs) -> anyhow::Result<()> {
    let mut env = parse_env(&args.env)?;
    let unicycle = matches!(env, EnvName::Unicycle(_));
    match (&args.map, unicycle) {
        (Some(map), true) => env = env.with_terrain(UnicycleTerrain::new(vec![TerrainMap::read_png(map)?]))?,
        (None, true) => bail!("--env unicycle: give --map PNG, the terrain the robot calibrates on"),
        (Some(_), false) => bail!("--map is the unicycle's terrain; '{}' has none", env.canonical()),
        (None, false) => {}
    }
    let strategy = args.strategy.into();
    let transitions = args.transitions.unwrap_or(if unicycle { 10 } else { 30 });
    let settings = CalibrationSettings {
        strategy,
        transitions,
        horizon_max: args.horizon,
        candidates: args.candidates,
        elites: args.elites,
        iterations: args.iters,
        beta_samples: args.beta_samples,
    };
    settings.validate()?;
    let init_state = args.init_state.as_deref().map(|s| parse_floats("--init-state", s)).transpose()?;
    if !args.model.is_dir() {
        bail!("--model {}: no such checkpoint directory", args.model.display());
    }
    let model = load_model(&args.model, &env, accepting(args.allow_incomplete))?;
    report_unfinished(&args.model, &model.progress);
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from(format!(
            "datasets/calib-{}-{}-i{}.mcap",
            file_stem(&env.canonical()),
            strategy.name(),
            args.instance_seed
        ))
    });
    check_output_file("--out", &out, "mcap")?;
    let request = CalibrationRequest {
        env: env.clone(),
        instance_seed: args.instance_seed,
        init_state,
        settings,
        seed: global.seed,
    };
    let spec = env.build()?.spec();
    let title = format!(
        "calibrate {} ({}, {} transitions, instance {}{})",
        env.canonical(),
        strategy.name(),
        transitions,
        args.instance_seed,
        model.progress.unfinished_note()
    );
    let (calibration, instance) = run_job(global, "calibrate", |monitor| {
        monitor.emit(&layout(&title, &spec.state_names));
        let (calibration, instance) = run_calibration(&model, &request, monitor)?;
        let dataset = calibration_dataset(&env, &calibration, instance.clone(), global.seed, &command_line())?;
        write_dataset(&out, &dataset)?;
        Ok((calibration, instance))
    })?;
    let prior = gaussian_entropy(&model.fast.belief(&vec![0.0; model.fast.transition_features], 1).std);
    let last = calibration.entropies.last().copied().unwrap_or(prior);
    say!(
        "calibrated {} instance {} ({}) with {} {} transitions: entropy of q(β | context) {:.3} → {:.3} nats{}",
        env.canonical(),
        args.instance_seed,
        instance,
        calibration.rollout.len(),
        strategy.name(),
        prior,
        last,
        model.progress.unfinished_note()
    );
    say!("context set written to {}", out.display());
    Ok(())
}

/// A context model of `env`, or a TRADYN model when `env` is the unicycle.
fn load_model(dir: &std::path::Path, env: &EnvName, accept: Accept) -> anyhow::Result<LoadedModel> {
    let method = OpenedCheckpoint::open(dir)?.manifest.method;
    let unicycle = matches!(env, EnvName::Unicycle(_));
    if unicycle && method != tradyn::METHOD {
        bail!(
            "{}: is a '{method}' checkpoint; the unicycle calibrates a TRADYN model (`mbrl train tradyn`)",
            dir.display()
        );
    }
    if method == tradyn::METHOD && !unicycle {
        bail!("{}: is a TRADYN model of the unicycle; calibrate it with --env unicycle --map PNG", dir.display());
    }
    Ok(if unicycle { TradynModel::load(dir, accept)?.loaded } else { context::load(dir, env, accept)? })
}
