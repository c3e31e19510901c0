//! `mbrl eval`: reproduce the thesis' experiments and write reports.

use std::path::PathBuf;

use anyhow::bail;
use clap::{Args, Subcommand};
use mbrl::envs::pendulum::PendulumVariant;
use mbrl::eval::dataset_report;
use mbrl::eval::quick::run_quick;
use mbrl::eval::swingup::{self, SwingupSettings};
use mbrl::run::dir::Provenance;

use crate::cem_args::CemArgs;
use crate::common::{command_line, run_job, GlobalArgs, ModelChoice};

/// Run an evaluation protocol and write a report directory (report.md, CSV, PNG).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl eval quick
  mbrl eval dataset --input datasets/pendulum-random.mcap
  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup")]
pub struct EvalArgs {
    #[command(subcommand)]
    protocol: Protocol,
}

#[derive(Subcommand, Debug)]
enum Protocol {
    /// Small reproduction of every implemented method (about a minute).
    #[command(after_help = "Example:\n  mbrl eval quick --out reports/quick")]
    Quick {
        /// Report directory.
        #[arg(long, default_value = "reports/quick")]
        out: PathBuf,
    },
    /// Summarise a dataset: rollouts, returns, state ranges, plots.
    #[command(
        after_help = "Example:\n  mbrl eval dataset --input datasets/pendulum-random.mcap --out reports/dataset"
    )]
    Dataset {
        /// Dataset file written by `mbrl collect` or `mbrl plan`.
        #[arg(long)]
        input: PathBuf,
        /// Report directory.
        #[arg(long, default_value = "reports/dataset")]
        out: PathBuf,
    },
    /// Pendulum swing-up with MPC: success rate, returns, angle plots.
    #[command(after_help = "Example:\n  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup")]
    PendulumSwingup(SwingupArgs),
}

#[derive(Args, Debug)]
struct SwingupArgs {
    /// Dynamics model the planner uses.
    #[arg(long, value_enum)]
    model: ModelChoice,
    /// Number of episodes (each with its own start state).
    #[arg(long, default_value_t = 10)]
    episodes: usize,
    /// Environment variant: pendulum[:light|heavy|mass=<m>|inverted|quadrant].
    #[arg(long, default_value = "pendulum")]
    env: String,
    /// Steps per episode.
    #[arg(long, default_value_t = 150)]
    steps: usize,
    #[command(flatten)]
    cem: CemArgs,
    /// Report directory.
    #[arg(long, default_value = "reports/pendulum-swingup")]
    out: PathBuf,
}

pub fn run(global: &GlobalArgs, args: EvalArgs) -> anyhow::Result<()> {
    let provenance = Provenance::new(command_line(), global.seed, global.thread_count());
    match args.protocol {
        Protocol::Quick { out } => {
            let summary = run_job(global, "eval quick", |monitor| run_quick(&provenance, &out, monitor))?;
            for line in summary.lines {
                println!("{line}");
            }
            println!("report: {}", out.join("report.md").display());
        }
        Protocol::Dataset { input, out } => {
            let s = run_job(global, "eval dataset", |_| dataset_report::report(&input, &provenance, &out))?;
            println!(
                "{}: {} rollouts, {} transitions of {}, mean return {:.2}; report: {}",
                input.display(),
                s.rollouts,
                s.transitions,
                s.env,
                s.mean_return,
                out.join("report.md").display()
            );
        }
        Protocol::PendulumSwingup(a) => {
            let ModelChoice::True = a.model;
            let variant = match mbrl::envs::parse_env(&a.env)? {
                mbrl::envs::EnvName::Pendulum(v) => v,
            };
            if a.episodes == 0 || a.steps < swingup::SUCCESS_WINDOW {
                bail!("--episodes must be at least 1 and --steps at least {}", swingup::SUCCESS_WINDOW);
            }
            let settings = swingup_settings(variant, a.steps, &a.cem);
            settings.cem.validate()?;
            let summary = run_job(global, "eval pendulum-swingup", |monitor| {
                swingup::evaluate(&settings, a.episodes, &provenance, &a.out, monitor)
            })?;
            println!(
                "{}/{} episodes succeeded; mean return {:.1}; report: {}",
                summary.successes,
                summary.episodes,
                summary.returns.iter().sum::<f64>() / summary.episodes as f64,
                a.out.join("report.md").display()
            );
        }
    }
    Ok(())
}

fn swingup_settings(variant: PendulumVariant, steps: usize, cem: &CemArgs) -> SwingupSettings {
    let mut settings = SwingupSettings::thesis(variant);
    settings.steps = steps;
    settings.cem = cem.config(&settings.cem.action_low, &settings.cem.action_high);
    settings
}
