//! `mbrl collect`: roll out a behaviour policy in a simulator and save the dataset as MCAP.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use mbrl::data::collect::{collect_random, CollectSettings};
use mbrl::data::write_dataset;
use mbrl::envs::parse_env;

use crate::common::{command_line, file_stem, run_job, GlobalArgs};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Policy {
    /// Uniformly random actions within the action bounds.
    Random,
}

/// Collect rollouts from a simulator into an MCAP dataset.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl collect --env pendulum --rollouts 500 --steps 30 --out datasets/pendulum.mcap
  mbrl collect --env pendulum:quadrant --rollouts 100 --steps 50 --seed 3

Start states: θ ~ U[-π, π], θ̇ ~ U[-8, 8]; actions ~ U[-2, 2]. Parametrized variants
(pendulum:quadrant) draw a new instance per rollout; its parameters go into the metadata.")]
pub struct CollectArgs {
    /// Environment: pendulum[:light|heavy|mass=<m>|inverted|quadrant].
    #[arg(long)]
    env: String,
    /// Number of rollouts.
    #[arg(long, default_value_t = 100)]
    rollouts: usize,
    /// Steps per rollout.
    #[arg(long, default_value_t = 30)]
    steps: usize,
    /// Behaviour policy.
    #[arg(long, value_enum, default_value_t = Policy::Random)]
    policy: Policy,
    /// Output file (default: datasets/<env>-random.mcap).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(global: &GlobalArgs, args: CollectArgs) -> anyhow::Result<()> {
    let env = parse_env(&args.env)?;
    let out =
        args.out.unwrap_or_else(|| PathBuf::from(format!("datasets/{}-random.mcap", file_stem(&env.canonical()))));
    let settings = CollectSettings {
        env,
        rollouts: args.rollouts,
        steps: args.steps,
        seed: global.seed,
        command_line: command_line(),
    };
    let dataset = run_job(global, "collect", |monitor| {
        let data = match args.policy {
            Policy::Random => collect_random(&settings, monitor)?,
        };
        write_dataset(&out, &data)?;
        Ok(data)
    })?;
    println!(
        "wrote {} transitions in {} rollouts of {} to {}",
        dataset.steps.len(),
        args.rollouts,
        dataset.meta.env,
        out.display()
    );
    Ok(())
}
