//! The `mbrl` command line: parses flags and hands each subcommand to the library.

mod calibrate;
mod cem_args;
mod collect;
mod common;
mod completions;
mod eval;
mod filter;
mod model_args;
mod plan;
mod predict;
mod solve_board;
mod train;
mod watch;

use clap::{Parser, Subcommand};

use common::GlobalArgs;

const ABOUT: &str = "Model-based reinforcement learning: simulators, learned models, planners and filters.";

const AFTER_HELP: &str = "\
Examples:
  mbrl eval quick                      # small reproduction of every method, report in reports/quick/
  mbrl plan --env pendulum --model true --steps 150
  mbrl collect --env pendulum:heavy --rollouts 10 --steps 30 --out datasets/heavy.mcap
  mbrl solve-board --game lightsout --random-depth 9 --model true
  mbrl collect --env ball --trajectories 20 --out datasets/ball.mcap
  mbrl predict --model thesis --input datasets/ball.mcap --horizon 1s
  mbrl watch reports/quick/pendulum-swingup";

#[derive(Parser)]
#[command(name = "mbrl", version, about = ABOUT, after_help = AFTER_HELP, propagate_version = true)]
pub struct Cli {
    #[command(flatten)]
    global: GlobalArgs,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    Collect(collect::CollectArgs),
    Plan(plan::PlanArgs),
    Train(train::TrainArgs),
    Calibrate(calibrate::CalibrateArgs),
    Filter(filter::FilterArgs),
    Predict(predict::PredictArgs),
    SolveBoard(solve_board::SolveBoardArgs),
    Eval(eval::EvalArgs),
    Watch(watch::WatchArgs),
    Completions(completions::CompletionsArgs),
}

fn main() {
    let cli = Cli::parse();
    let outcome = common::init_threads(&cli.global).and_then(|()| match cli.command {
        Command::Collect(args) => collect::run(&cli.global, args),
        Command::Plan(args) => plan::run(&cli.global, args),
        Command::Train(args) => train::run(&cli.global, args),
        Command::Calibrate(args) => calibrate::run(&cli.global, args),
        Command::Filter(args) => filter::run(&cli.global, args),
        Command::Predict(args) => predict::run(&cli.global, args),
        Command::SolveBoard(args) => solve_board::run(&cli.global, args),
        Command::Eval(args) => eval::run(&cli.global, args),
        Command::Watch(args) => watch::run(&cli.global, args),
        Command::Completions(args) => completions::run(args),
    });
    if let Err(err) = outcome {
        let cancelled = err.downcast_ref::<mbrl::Error>().is_some_and(|e| matches!(e, mbrl::Error::Cancelled));
        eprintln!("error: {err:#}");
        std::process::exit(if cancelled { 130 } else { 1 });
    }
}
