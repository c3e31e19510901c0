//! `mbrl eval`: reproduce the thesis' experiments and write reports; `eval render` redraws one from its summary.

mod boards;
mod models;
mod pendulum;

use std::path::{Path, PathBuf};

use anyhow::bail;
use clap::{Args, Subcommand};
use mbrl::eval::summary::{read_config, ProtocolConfig, Summary};
use mbrl::run::dir::Provenance;

use crate::common::{command_line, GlobalArgs};

/// Run an evaluation protocol and write a report directory (report.md, CSV, PNG, summary.json, config.json).
#[derive(Args, Debug)]
#[command(after_help = "\
Every report directory holds summary.json (the report's figures) and config.json (the protocol's settings and
seed). `mbrl eval render DIR` redraws report.md, the CSVs and the PNGs from DIR/summary.json alone;
`mbrl eval <protocol> --config DIR/config.json` reruns the protocol with the recorded settings and seed. With
--config only --out (and the global flags) may be given: any other flag of the protocol is rejected, and --seed,
when given, must equal the recorded seed.

Examples:
  mbrl eval quick
  mbrl eval dataset --input datasets/pendulum-random.mcap
  mbrl eval boards
  mbrl eval ball --model thesis --model initial
  mbrl eval embodied --game lightsout --embodiment cursor --max-depth 5 --boards 200
  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup
  mbrl eval render reports/swingup
  mbrl eval pendulum-swingup --config reports/swingup/config.json --out reports/swingup-again")]
pub struct EvalArgs {
    #[command(subcommand)]
    protocol: Protocol,
}

#[derive(Subcommand, Debug)]
enum Protocol {
    /// Small reproduction of every implemented method (about a minute).
    #[command(after_help = "Example:\n  mbrl eval quick --out reports/quick")]
    Quick(QuickArgs),
    /// Summarise a dataset: rollouts, returns, state ranges, plots.
    #[command(after_help = "Examples:\n  mbrl eval dataset --input datasets/pendulum-random.mcap\n  \
                            mbrl eval dataset --input datasets/pendulum-heavy-random.mcap --out reports/heavy-data")]
    Dataset(pendulum::DatasetArgs),
    /// Depth and train/test split tables of LightsOut 5x5 and TileSwap (thesis Tables 7.1, 7.2).
    #[command(after_help = "Example:\n  mbrl eval boards --out reports/boards")]
    Boards(boards::BoardsArgs),
    /// A manipulator's scripted controller plays optimal plans of boards of depth 1..D.
    #[command(
        after_help = "Examples:\n  mbrl eval embodied --game lightsout --embodiment cursor --max-depth 5 --boards 200\n  \
                            mbrl eval embodied --game tileswap --embodiment reacher --max-depth 5 --boards 100"
    )]
    Embodied(boards::EmbodiedArgs),
    /// Ball prediction error vs horizon on simulated shots, default and unseen launcher poses (thesis 6.5).
    #[command(after_help = "Examples:\n  mbrl eval ball --model thesis --model initial\n  \
                            mbrl eval ball --model models/ball-ekf --train-shots 108 --test-shots 163 --unseen-shots 30")]
    Ball(models::BallArgs),
    /// Explore the Context (thesis 4.5): calibration strategies compared by prediction error after calibration.
    #[command(
        after_help = "Examples:\n  mbrl eval context --model models/context-toy-inner --env toy:inner --transitions 1\n  \
                            mbrl eval context --model models/context-pendulum-quadrant --env pendulum:quadrant --contexts 50 --transitions 30 --horizon 20 --swingup"
    )]
    Context(models::ContextArgs),
    /// TRADYN (thesis 5.5): ±terrain lookup × ±calibration on navigation tasks on test maps: energy, final
    /// distance, failures (Table 5.2), Wilcoxon on energies (Fig. 5.7), prediction error (Fig. 5.5), paths (Fig. 5.6).
    #[command(
        after_help = "Examples:\n  mbrl eval tradyn --model-terrain models/tradyn-terrain --model-no-terrain models/tradyn-no-terrain --maps datasets/terrain --tasks 20\n  \
                            mbrl eval tradyn --model-terrain models/tradyn-terrain --model-no-terrain models/tradyn-no-terrain --maps datasets/terrain --tasks 150 --candidates 1000 --iters 20"
    )]
    Tradyn(models::TradynArgs),
    /// SEADS (thesis 7.4): skill coverage, boards solved per depth with and without replanning, planning time.
    #[command(
        after_help = "Example:\n  mbrl eval seads --model models/seads-tileswap-cursor --boards 20 --out reports/seads-tileswap"
    )]
    Seads(boards::SeadsArgs),
    /// DLGPD (thesis 3.5.3): swing-up success and return vs evidence rollouts on the standard, inverted, light
    /// and heavy pendulum, with matching and mismatching evidence (Figs. 3.4/3.5 analogues).
    #[command(
        after_help = "Examples:\n  mbrl eval dlgpd --model models/dlgpd-small --evidence-rollouts 5,10 --runs 2\n  \
                            mbrl eval dlgpd --model models/dlgpd-medium --env pendulum:inverted --evidence-rollouts 10,20,50 --runs 3 --candidates 1000 --elites 100"
    )]
    Dlgpd(pendulum::DlgpdArgs),
    /// Pendulum swing-up with MPC: success rate, returns, angle plots.
    #[command(
        after_help = "Example:\n  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup\n  \
                            mbrl eval pendulum-swingup --model models/pets-pendulum --episodes 10"
    )]
    PendulumSwingup(pendulum::SwingupArgs),
    /// Redraw a report (report.md, CSVs, PNGs) from its summary.json, without rerunning anything.
    #[command(after_help = "Example:\n  mbrl eval render reports/swingup")]
    Render {
        /// A report directory written by `mbrl eval` (it holds summary.json).
        dir: PathBuf,
    },
}

#[derive(Args, Debug)]
struct QuickArgs {
    /// Report directory.
    #[arg(long, default_value = "reports/quick")]
    out: PathBuf,
    /// Rerun with the seed a quick report recorded (its config.json).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

pub fn run(global: &GlobalArgs, args: EvalArgs) -> anyhow::Result<()> {
    let provenance = Provenance::new(command_line(), global.seed, global.thread_count());
    match args.protocol {
        Protocol::Quick(a) => {
            let provenance = match &a.config {
                Some(path) => recorded::<mbrl::eval::quick::QuickConfig>(global, path)?.1,
                None => provenance,
            };
            let summary = crate::common::run_job(global, "eval quick", |monitor| {
                mbrl::eval::quick::run_quick(&provenance, &a.out, monitor)
            })?;
            print(&summary, &a.out);
        }
        Protocol::Dataset(a) => pendulum::dataset(global, provenance, a)?,
        Protocol::Boards(a) => boards::boards(global, provenance, a)?,
        Protocol::Embodied(a) => boards::embodied(global, provenance, a)?,
        Protocol::Ball(a) => models::ball(global, provenance, a)?,
        Protocol::Context(a) => models::context(global, provenance, a)?,
        Protocol::Tradyn(a) => models::tradyn(global, provenance, a)?,
        Protocol::Seads(a) => boards::seads(global, provenance, a)?,
        Protocol::Dlgpd(a) => pendulum::dlgpd(global, provenance, a)?,
        Protocol::PendulumSwingup(a) => pendulum::swingup(global, provenance, a)?,
        Protocol::Render { dir } => {
            let summary = Summary::load(&dir)?;
            summary.render(&dir)?;
            match &summary {
                Summary::PendulumSwingup(s) => print_inline(s, &dir),
                Summary::Dataset(s) => print_inline(s, &dir),
                other => print(other, &dir),
            }
        }
    }
    Ok(())
}

/// The settings a report's config.json recorded, and the provenance of a rerun with this command line: the
/// recorded seed, unless --seed names another.
fn recorded<T: ProtocolConfig>(global: &GlobalArgs, path: &Path) -> anyhow::Result<(T, Provenance)> {
    let (config, recorded) = read_config::<T>(path)?;
    if global.seed != 0 && global.seed != recorded.seed {
        bail!(
            "--seed {} differs from the seed {} that --config {} recorded; drop --seed to rerun with it",
            global.seed,
            recorded.seed,
            path.display()
        );
    }
    Ok((config, Provenance::new(command_line(), recorded.seed, global.thread_count())))
}

/// Prints a protocol's result lines and where its report is.
fn print(summary: &impl std::fmt::Display, out: &Path) {
    let lines = summary.to_string();
    if !lines.is_empty() {
        say!("{lines}");
    }
    say!("report: {}", out.join("report.md").display());
}

/// As [`print`], for the protocols whose one result line ends with the report's path.
fn print_inline(summary: &impl std::fmt::Display, out: &Path) {
    say!("{summary}; report: {}", out.join("report.md").display());
}
