//! `mbrl calibrate`: act in an unseen instance to infer its hidden parameters with a trained context model, and
//! save the calibration transitions (the context set) for `plan --context`.

use std::path::PathBuf;

use anyhow::bail;
use clap::{Args, ValueEnum};
use mbrl::data::write_dataset;
use mbrl::envs::parse_env;
use mbrl::models::context::calibration::{
    calibration_dataset, layout, run_calibration, CalibrationRequest, CalibrationSettings, Strategy,
};
use mbrl::models::context::{self, fast::gaussian_entropy};

use crate::common::{check_output_file, command_line, file_stem, parse_floats, run_job, GlobalArgs};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum StrategyChoice {
    /// Uniformly random actions (the baseline).
    Random,
    /// One action sequence maximizing the expected information gain, planned at the start (eq. 4.36).
    OpenLoop,
    /// Replan the EIG-optimal sequence after every transition, horizon min(H_max, N − n) (eq. 4.37).
    Mpc,
}

/// Calibrate a context model in an instance of its env by expected information gain.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl calibrate --model models/context-toy-inner --env toy:inner --instance-seed 7 --strategy open-loop --transitions 1 --out calib.mcap
  mbrl calibrate --model models/context-pendulum-quadrant --env pendulum:quadrant --instance-seed 3 --strategy mpc --transitions 30 --horizon 20
  mbrl plan --env pendulum:quadrant --model models/context-pendulum-quadrant --context calib.mcap --instance-seed 3

The instance (hidden parameters) is the one --instance-seed names in every command. Starts: toy and
MountainCar at x = 0 (thesis), pendulum from its reset draw (--seed), or --init-state. The thesis uses
CEM 1000 candidates / 100 elites / 10 iterations and 20 β samples; pendulum N = 30, H_max = 20;
MountainCar N = 50, H_max = 30. The command prints the entropy of q(β | transitions) before and after.")]
pub struct CalibrateArgs {
    /// A context-model checkpoint (`mbrl train --method context`).
    #[arg(long)]
    model: PathBuf,
    /// Environment the model was trained on, e.g. toy:inner, pendulum:quadrant, mountaincar.
    #[arg(long)]
    env: String,
    /// Which instance (hidden parameters) to calibrate in.
    #[arg(long)]
    instance_seed: u64,
    #[arg(long, value_enum)]
    strategy: StrategyChoice,
    /// Calibration transitions N.
    #[arg(long, default_value_t = 30)]
    transitions: usize,
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
    /// Start state, comma-separated in the env's state order (pendulum: θ,θ̇). Default: the thesis' start
    /// (toy x = 0; MountainCar x = ẋ = 0; pendulum:quadrant hanging down, |θ − π|, |θ̇| ≤ 0.05, drawn from
    /// --seed), elsewhere a reset drawn from --seed.
    #[arg(long)]
    init_state: Option<String>,
    /// Where to write the calibration transitions (default: datasets/calib-<env>-<strategy>-i<S>.mcap).
    #[arg(long)]
    out: Option<PathBuf>,
}

impl StrategyChoice {
    pub fn strategy(self) -> Strategy {
        match self {
            StrategyChoice::Random => Strategy::Random,
            StrategyChoice::OpenLoop => Strategy::OpenLoop,
            StrategyChoice::Mpc => Strategy::Mpc,
        }
    }
}

pub fn run(global: &GlobalArgs, args: CalibrateArgs) -> anyhow::Result<()> {
    let env = parse_env(&args.env)?;
    let strategy = args.strategy.strategy();
    let settings = CalibrationSettings {
        strategy,
        transitions: args.transitions,
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
    let model = context::load(&args.model, &env)?;
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
        "calibrate {} ({}, {} transitions, instance {})",
        env.canonical(),
        strategy.name(),
        args.transitions,
        args.instance_seed
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
        "calibrated {} instance {} ({}) with {} {} transitions: entropy of q(β | context) {:.3} → {:.3} nats",
        env.canonical(),
        args.instance_seed,
        instance,
        calibration.rollout.len(),
        strategy.name(),
        prior,
        last
    );
    say!("context set written to {}", out.display());
    Ok(())
}
