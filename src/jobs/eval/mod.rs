//! `mbrl eval`: reproduce the thesis' experiments and write reports; `eval render` redraws one from its summary.

mod boards;
mod models;
mod pendulum;

use std::fmt;
use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};

use super::{output_dir, Invocation, Job};
use crate::eval::seads::SeadsEvalSummary;
use crate::eval::summary::{read_config, ProtocolConfig, Summary};
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::{refuse, Result};

/// Run an evaluation protocol and write a report directory (report.md, CSV, PNG, summary.json, config.json).
#[derive(Args, Debug)]
#[command(after_help = "\
Every report directory holds summary.json (the report's figures) and config.json (the protocol's settings and seed). `mbrl eval render DIR` redraws report.md, the CSVs and the PNGs from DIR/summary.json alone; `mbrl eval <protocol> --config DIR/config.json` reruns the protocol with the recorded settings and seed. With --config only --out, KEY=VALUE arguments and the global flags may be given: any other flag of the protocol is rejected, and --seed, when given, must equal the recorded seed.

KEY=VALUE arguments set any key of the `settings` table of the protocol's config.json (nested keys joined by '.', e.g. `settings.boards_per_depth=50` for embodied), after --config or the flags, so they win over both; an unknown key lists the valid ones.

Examples (in order: each uses what the ones before it wrote):
  mbrl eval quick
  mbrl collect --env pendulum --rollouts 200 --steps 30 --out datasets/pendulum-random.mcap
  mbrl eval dataset --input datasets/pendulum-random.mcap
  mbrl eval boards
  mbrl eval ball --model thesis --model initial
  mbrl eval embodied --game lightsout --embodiment cursor --max-depth 5 --boards 200 --out reports/embodied
  mbrl eval embodied --config reports/embodied/config.json settings.boards_per_depth=50 --out reports/embodied-50
  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup
  mbrl eval render reports/swingup
  mbrl eval pendulum-swingup --config reports/swingup/config.json --out reports/swingup-again")]
pub struct EvalOptions {
    #[command(subcommand)]
    protocol: Protocol,
}

#[derive(Subcommand, Debug)]
enum Protocol {
    /// Small reproduction of every implemented method, each line with its thesis target and verdict (about 10.5
    /// minutes on 2 cores).
    #[command(
        long_about = "Small reproduction of every implemented method: ten slices, from the pendulum swing-up with the \
                      true model to TRADYN navigation. Each printed line, and each row of report.md, states the thesis \
                      figure or table it reproduces and a verdict (reproduced / not at this scale / smoke test only) \
                      reached from the run's own numbers; summary.json records the same per slice. A full run takes \
                      about 10.5 minutes on two idle cores (`--threads 2`); each slice prints a header on stderr.",
        after_help = "Example:\n  mbrl eval quick --out reports/quick"
    )]
    Quick(QuickOptions),
    /// Summarise a dataset: rollouts, returns, state ranges, plots.
    #[command(after_help = "Examples:\n  \
                            mbrl collect --env pendulum:heavy --rollouts 50 --steps 30 --out datasets/pendulum-heavy-random.mcap\n  \
                            mbrl eval dataset --input datasets/pendulum-heavy-random.mcap --out reports/heavy-data")]
    Dataset(pendulum::DatasetOptions),
    /// Depth and train/test split tables of LightsOut 5x5 and TileSwap (thesis Tables 7.1, 7.2).
    #[command(after_help = "Example:\n  mbrl eval boards --out reports/boards")]
    Boards(boards::BoardsOptions),
    /// A manipulator's scripted controller plays optimal plans of boards of depth 1..D.
    #[command(after_help = "Examples:\n  \
                            mbrl eval embodied --game lightsout --embodiment cursor --max-depth 5 --boards 200 --out reports/embodied\n  \
                            mbrl eval embodied --config reports/embodied/config.json settings.boards_per_depth=50 --out reports/embodied-50\n  \
                            mbrl eval embodied --game tileswap --embodiment reacher --max-depth 5 --boards 100")]
    Embodied(boards::EmbodiedOptions),
    /// Ball prediction error vs horizon on simulated shots, default and unseen launcher poses (thesis 6.5).
    #[command(after_help = "Examples:\n  mbrl eval ball --model thesis --model initial --out reports/ball\n  \
                            mbrl eval ball --config reports/ball/config.json settings.test_shots_unseen=10 --out reports/ball-unseen-10")]
    Ball(models::BallOptions),
    /// Explore the Context (thesis 4.5): calibration strategies compared by prediction error after calibration.
    #[command(
        after_help = "Examples:\n  mbrl eval context --model models/context-toy-inner --env toy:inner --transitions 1\n  \
                            mbrl eval context --model models/context-pendulum-quadrant --env pendulum:quadrant --contexts 50 --transitions 30 --horizon 20 --swingup"
    )]
    Context(models::ContextOptions),
    /// TRADYN (thesis 5.5): ±terrain lookup × ±calibration on navigation tasks on test maps: energy, final
    /// distance, failures (Table 5.2), Wilcoxon on energies (Fig. 5.7), prediction error (Fig. 5.5), paths (Fig. 5.6).
    #[command(
        after_help = "Examples:\n  mbrl eval tradyn --model-terrain models/tradyn-terrain --model-no-terrain models/tradyn-no-terrain --maps datasets/terrain --tasks 20\n  \
                            mbrl eval tradyn --model-terrain models/tradyn-terrain --model-no-terrain models/tradyn-no-terrain --maps datasets/terrain --tasks 150 --candidates 1000 --iters 20"
    )]
    Tradyn(models::TradynOptions),
    /// SEADS (thesis 7.4): skill coverage, boards solved per depth with and without replanning, planning time.
    #[command(
        after_help = "Example:\n  mbrl eval seads --model models/seads-tileswap-cursor --boards 20 --out reports/seads-tileswap"
    )]
    Seads(boards::SeadsOptions),
    /// DLGPD (thesis 3.5.3): swing-up success and return vs evidence rollouts on the standard, inverted, light
    /// and heavy pendulum, with matching and mismatching evidence (Figs. 3.4/3.5 analogues).
    #[command(
        after_help = "Examples:\n  mbrl eval dlgpd --model models/dlgpd-small --evidence-rollouts 5,10 --runs 2\n  \
                            mbrl eval dlgpd --model models/dlgpd-medium --env pendulum:inverted --evidence-rollouts 10,20,50 --runs 3 --candidates 1000 --elites 100"
    )]
    Dlgpd(pendulum::DlgpdOptions),
    /// Pendulum swing-up with MPC: success rate, returns, angle plots.
    #[command(
        after_help = "Examples:\n  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup\n  \
                            mbrl eval pendulum-swingup --config reports/swingup/config.json episodes=3 --out reports/swingup-3"
    )]
    PendulumSwingup(pendulum::SwingupOptions),
    /// Redraw a report (report.md, CSVs, PNGs) from its summary.json, without rerunning anything.
    #[command(after_help = "Example:\n  mbrl eval render reports/swingup")]
    Render {
        /// A report directory written by `mbrl eval` (it holds summary.json).
        dir: PathBuf,
    },
}

#[derive(Args, Debug)]
struct QuickOptions {
    /// Report directory (default: reports/quick; when that exists, the first free reports/quick-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun with the seed a quick report recorded (its config.json).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

/// A protocol to run in a view, or a report already redrawn: `eval render` only reads and writes the report's
/// own files, too quick for a live view.
pub enum Eval {
    Run(Job<'static, EvalSummary>),
    Rendered(Box<EvalSummary>),
}

/// What an evaluation prints: its result lines and where its report is.
pub struct EvalSummary {
    /// The runs a SEADS comparison compared, each printed before the comparison.
    compared: Vec<SeadsEvalSummary>,
    summary: Summary,
    out: PathBuf,
}

impl fmt::Display for EvalSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        for run in &self.compared {
            writeln!(f, "{run}")?;
        }
        let report = self.out.join("report.md");
        match &self.summary {
            // One result line, which ends with the report's path.
            Summary::PendulumSwingup(_) | Summary::Dataset(_) => {
                write!(f, "{}; report: {}", self.summary, report.display())
            }
            summary => {
                let lines = summary.to_string();
                if !lines.is_empty() {
                    writeln!(f, "{lines}")?;
                }
                write!(f, "report: {}", report.display())
            }
        }
    }
}

/// Checks the protocol's flags (and loads its models), so that a bad flag or checkpoint fails before any view.
pub fn prepare(options: EvalOptions, invocation: &Invocation) -> Result<Eval> {
    let job = match options.protocol {
        Protocol::Quick(options) => {
            let provenance = match &options.config {
                Some(path) => recorded::<crate::eval::quick::QuickConfig>(invocation, path)?.1,
                None => invocation.provenance(),
            };
            report_job(
                "eval quick",
                output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/quick"), invocation)?,
                move |monitor, out| Ok(Summary::Quick(crate::eval::quick::run_quick(&provenance, out, monitor)?)),
            )
        }
        Protocol::Dataset(options) => pendulum::dataset(options, invocation)?,
        Protocol::Boards(options) => boards::boards(options, invocation)?,
        Protocol::Embodied(options) => boards::embodied(options, invocation)?,
        Protocol::Ball(options) => models::ball(options, invocation)?,
        Protocol::Context(options) => models::context(options, invocation)?,
        Protocol::Tradyn(options) => models::tradyn(options, invocation)?,
        Protocol::Seads(options) => boards::seads(options, invocation)?,
        Protocol::Dlgpd(options) => pendulum::dlgpd(options, invocation)?,
        Protocol::PendulumSwingup(options) => pendulum::swingup(options, invocation)?,
        Protocol::Render { dir } => {
            let summary = Summary::load(&dir)?;
            summary.render(&dir)?;
            return Ok(Eval::Rendered(Box::new(EvalSummary { compared: Vec::new(), summary, out: dir })));
        }
    };
    Ok(Eval::Run(job))
}

/// A job that writes one report into `out` and prints its summary.
fn report_job(
    title: &str,
    out: PathBuf,
    work: impl FnOnce(&dyn Monitor, &Path) -> Result<Summary> + Send + 'static,
) -> Job<'static, EvalSummary> {
    Job::new(title, move |monitor| {
        let summary = work(monitor, &out)?;
        Ok(EvalSummary { compared: Vec::new(), summary, out })
    })
}

/// The settings a report's config.json recorded, and the provenance of a rerun with this command line: the
/// recorded seed, unless --seed names another.
fn recorded<T: ProtocolConfig>(invocation: &Invocation, path: &Path) -> Result<(T, Provenance)> {
    let (config, recorded) = read_config::<T>(path)?;
    if invocation.seed != 0 && invocation.seed != recorded.seed {
        refuse!(
            "--seed {} differs from the seed {} that --config {} recorded; drop --seed to rerun with it",
            invocation.seed,
            recorded.seed,
            path.display()
        );
    }
    let rerun = Invocation { seed: recorded.seed, ..invocation.clone() };
    Ok((config, rerun.provenance()))
}
