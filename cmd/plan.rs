//! `mbrl plan`: model-predictive control with CEM in a simulator.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use mbrl::data::write_dataset;
use mbrl::eval::swingup::{self, SwingupSettings};

use crate::cem_args::CemArgs;
use crate::common::{command_line, file_stem, pendulum_variant, run_job, GlobalArgs};
use crate::model_args::ModelArgs;

/// Plan with CEM on a model and execute the plan in the simulator (MPC).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl plan --env pendulum --model true --horizon 20 --candidates 1000 --elites 100 --iters 10 --steps 150
  mbrl plan --env pendulum:heavy --model true --noise colored --beta 0.5 --out datasets/heavy-plan.mcap
  mbrl plan --env pendulum --model models/pets-pendulum --particles 20 --propagation tsinf
  mbrl plan --env pendulum:quadrant --model models/context-pendulum-quadrant --context calib.mcap --instance-seed 3

The pendulum starts hanging (θ ~ U[π-0.05, π+0.05], θ̇ ~ U[-0.05, 0.05]); success means each of the
last 25 rewards is above -1 (thesis 3.5.2).")]
pub struct PlanArgs {
    /// Environment: pendulum[:light|heavy|mass=<m>|inverted|quadrant].
    #[arg(long)]
    env: String,
    #[command(flatten)]
    model: ModelArgs,
    /// Steps to execute.
    #[arg(long, default_value_t = 150)]
    steps: usize,
    #[command(flatten)]
    cem: CemArgs,
    /// Plan in the instance (hidden parameters) this seed names, as `calibrate --instance-seed` does.
    #[arg(long)]
    instance_seed: Option<u64>,
    /// Where to save the executed rollout (default: datasets/plan-<env>.mcap).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(global: &GlobalArgs, args: PlanArgs) -> anyhow::Result<()> {
    let variant = pendulum_variant(&args.env)?;
    if args.steps == 0 {
        bail!("--steps must be at least 1");
    }
    let mut settings = SwingupSettings::thesis(variant);
    settings.steps = args.steps;
    settings.instance_seed = args.instance_seed;
    settings.cem = args.cem.config(&settings.cem.action_low, &settings.cem.action_high);
    settings.cem.validate()?;
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from(format!("datasets/plan-{}.mcap", file_stem(&settings.variant.env_name()))));
    let env = mbrl::envs::parse_env(&args.env)?;
    let model = args.model.load(&env)?;
    let model = model.as_deref();
    let seed = global.seed;
    let title = format!("plan: pendulum swing-up with {}", swingup::model_description(model));
    let episode = run_job(global, "plan: pendulum swing-up", |monitor| {
        monitor.emit(&swingup::layout(&title, model.is_some()));
        let episode = swingup::run_episode(&settings, model, seed, 0, monitor)?;
        write_dataset(
            &out,
            &swingup::episodes_dataset(&settings, seed, &command_line(), std::slice::from_ref(&episode)),
        )?;
        Ok(episode)
    })?;
    println!(
        "return {:.2}, success: {} (last 25 rewards > -1); rollout saved to {}",
        episode.total_return,
        if episode.success { "yes" } else { "no" },
        out.display()
    );
    Ok(())
}
