//! The `mbrl` command line: parses flags and hands each subcommand to the library.

/// `println!` for results, through `common::say` (a closed stdout is not a crash).
macro_rules! say {
    () => {
        $crate::common::say(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::common::say(format_args!($($arg)*))
    };
}

mod common;
mod completions;
mod train;
mod watch;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use common::GlobalArgs;

// mimalloc, tuned by `mbrl::util::alloc` (which says why); declared here, not in the library, so that programs
// linking the library choose their own.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const ABOUT: &str = "Model-based reinforcement learning: simulators, learned models, planners and filters.";

const AFTER_HELP: &str = "\
Examples:
  mbrl eval quick                      # small reproduction of every method, report in reports/quick/
  mbrl plan --env pendulum --model true --steps 150
  mbrl collect --env pendulum:heavy --rollouts 10 --steps 30 --out datasets/heavy.mcap
  mbrl solve-board --game lightsout --random-depth 9 --model true
  mbrl collect --env ball --trajectories 20 --out datasets/ball.mcap
  mbrl predict --model thesis --input datasets/ball.mcap --horizon 1s
  mbrl watch reports/quick/pendulum-swingup
  mbrl export --input datasets/heavy.mcap --out heavy.npz
  mbrl list envs                       # also: methods, presets, embodiments
  mbrl sweep plan sweep.toml --out sweeps/s  # seeds × settings as Slurm job arrays or local job lists";

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
    Collect(mbrl::jobs::collect::CollectOptions),
    Plan(mbrl::jobs::plan::PlanOptions),
    Train(mbrl::jobs::train::TrainOptions),
    Calibrate(mbrl::jobs::calibrate::CalibrateOptions),
    Filter(mbrl::jobs::filter::FilterOptions),
    Predict(mbrl::jobs::predict::PredictOptions),
    SolveBoard(mbrl::jobs::solve_board::SolveBoardOptions),
    Eval(mbrl::jobs::eval::EvalOptions),
    Watch(watch::WatchArgs),
    Export(mbrl::jobs::export::ExportOptions),
    List(mbrl::jobs::list::ListOptions),
    Sweep(mbrl::jobs::sweep::SweepOptions),
    Completions(completions::CompletionsArgs),
}

fn main() {
    if let Err(e) = mbrl::util::interrupt::install() {
        eprintln!("error: could not install the Ctrl-C handler: {e}");
        std::process::exit(1);
    }
    let args = train::alias::rewrite(std::env::args_os().collect(), &Cli::command());
    let cli = accept_negative_numbers(Cli::command())
        .try_get_matches_from(&args)
        .and_then(|matches| Cli::from_arg_matches(&matches))
        .unwrap_or_else(|err| exit_on_usage_error(err));
    let job = cli.global.job_dir.as_deref().and_then(start_job);
    let outcome = common::init_threads(&cli.global).and_then(|()| match cli.command {
        Command::Collect(args) => match mbrl::jobs::collect::prepare(args, &cli.global.invocation())? {
            mbrl::jobs::collect::Collection::Now(job) => {
                say!("{}", job.run(&mbrl::run::NullMonitor)?);
                Ok(())
            }
            mbrl::jobs::collect::Collection::Viewed(job) => common::show(&cli.global, job),
        },
        Command::Plan(args) => common::show(&cli.global, mbrl::jobs::plan::prepare(args, &cli.global.invocation())?),
        Command::Train(args) => match mbrl::jobs::train::prepare(args, &cli.global.invocation())? {
            Some(job) => common::show(&cli.global, job),
            None => exit_on_usage_error(
                Cli::command().error(clap::error::ErrorKind::MissingSubcommand, mbrl::jobs::train::MISSING_METHOD),
            ),
        },
        Command::Calibrate(args) => {
            common::show(&cli.global, mbrl::jobs::calibrate::prepare(args, &cli.global.invocation())?)
        }
        Command::Filter(args) => {
            common::show(&cli.global, mbrl::jobs::filter::prepare(args, &cli.global.invocation())?)
        }
        Command::Predict(args) => {
            common::show(&cli.global, mbrl::jobs::predict::prepare(args, &cli.global.invocation())?)
        }
        Command::SolveBoard(args) => {
            // A plan played that misses the goal is shown, then fails the command.
            let job = mbrl::jobs::solve_board::prepare(args, &cli.global.invocation())?;
            let summary = common::run_job(&cli.global, &job.title.clone(), |monitor| job.run(monitor))?;
            say!("{summary}");
            Ok(summary.verdict()?)
        }
        Command::Eval(args) => match mbrl::jobs::eval::prepare(args, &cli.global.invocation())? {
            mbrl::jobs::eval::Eval::Run(job) => common::show(&cli.global, job),
            mbrl::jobs::eval::Eval::Rendered(summary) => {
                say!("{summary}");
                Ok(())
            }
        },
        Command::Watch(args) => watch::run(&cli.global, args),
        Command::Export(args) => {
            mbrl::jobs::export::run(args, &cli.global.invocation()).map(|summary| say!("{summary}")).map_err(Into::into)
        }
        Command::List(args) => mbrl::jobs::list::run(args).map(|table| say!("{table}")).map_err(Into::into),
        Command::Sweep(args) => {
            let outcome = mbrl::jobs::sweep::run(args, &validate_job_line)?;
            say!("{outcome}");
            match outcome.exit_status() {
                0 => Ok(()),
                status => std::process::exit(status),
            }
        }
        Command::Completions(args) => completions::run(args),
    });
    let failure = outcome.as_ref().err().map(|err| {
        let cancelled = err.downcast_ref::<mbrl::Error>().is_some_and(|e| e.is_cancelled());
        (format!("error: {}", one_line(&format!("{err:#}"))), cancelled)
    });
    if let Some(job) = job {
        if let Err(e) = job.finish(failure.clone().map_or(Ok(()), Err)) {
            eprintln!("warning: the job record was not written: {}", one_line(&e.to_string()));
        }
    }
    if let Some((line, cancelled)) = failure {
        eprintln!("{line}");
        std::process::exit(if cancelled { 130 } else { 1 });
    }
}

/// `--job-dir`: the command's arguments (after the binary) are the job's identity; a job recorded done with
/// the same arguments ends here, successfully, with nothing done.
fn start_job(dir: &std::path::Path) -> Option<mbrl::run::job_record::JobGuard> {
    let args: Vec<String> = std::env::args_os().skip(1).map(|a| a.to_string_lossy().into_owned()).collect();
    let command = shlex::try_join(args.iter().map(String::as_str)).unwrap_or_else(|_| args.join(" "));
    match mbrl::run::job_record::begin(dir, &command) {
        Ok(mbrl::run::job_record::Begin::Run(guard)) => Some(guard),
        Ok(mbrl::run::job_record::Begin::AlreadyDone) => {
            say!(
                "done already: {} records this command as finished",
                dir.join(mbrl::run::job_record::RECORD_FILE).display()
            );
            std::process::exit(0);
        }
        Err(e) => {
            eprintln!("error: --job-dir {}", one_line(&e.to_string()));
            std::process::exit(1);
        }
    }
}

/// A planned sweep line parses as this command line would parse it, so a typo in a spec fails at planning.
fn validate_job_line(args: &[String]) -> Result<(), String> {
    let mut argv = vec![std::ffi::OsString::from("mbrl")];
    argv.extend(args.iter().map(std::ffi::OsString::from));
    let argv = train::alias::rewrite(argv, &Cli::command());
    match accept_negative_numbers(Cli::command()).try_get_matches_from(&argv) {
        Ok(matches) => Cli::from_arg_matches(&matches).map(drop).map_err(|e| first_line(&e.to_string())),
        Err(e) => Err(first_line(&e.to_string())),
    }
}

fn first_line(message: &str) -> String {
    let line = message.lines().find(|l| !l.trim().is_empty()).unwrap_or("").trim();
    one_line(line.strip_prefix("error: ").unwrap_or(line))
}

/// Negative values reach each flag's own check (`--lr -1` → "--lr must be positive") instead of clap's
/// "unexpected argument '-1'"; flags that take no value still start with a dash.
fn accept_negative_numbers(command: clap::Command) -> clap::Command {
    command
        .mut_args(|arg| if arg.get_action().takes_values() { arg.allow_negative_numbers(true) } else { arg })
        .mut_subcommands(accept_negative_numbers)
}

/// Help and version print as clap renders them; a usage error becomes one line: clap's message and where to
/// read more, so scripts that grep stderr see one line per failure like every other error.
fn exit_on_usage_error(err: clap::Error) -> ! {
    use clap::error::ErrorKind;
    if matches!(
        err.kind(),
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        err.exit();
    }
    // clap's message can continue on the next lines (the missing arguments, a tip); the usage block after it
    // is what the help hint points to.
    let rendered = err.to_string();
    let message = rendered
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ");
    let message = message.strip_prefix("error: ").unwrap_or(&message);
    // Rust's integer parser says "invalid digit found in string"; for the unsigned counts and seeds this
    // means the value, as the user typed it, is negative or not a whole number.
    let negative = message.starts_with("invalid value '-");
    let message = message.replace(
        "invalid digit found in string",
        if negative { "must be a whole number ≥ 0" } else { "not a whole number" },
    );
    let help = help_command(&train::alias::rewrite(std::env::args_os().collect(), &Cli::command()));
    eprintln!("error: {} (see '{}')", one_line(&message), one_line(&help));
    std::process::exit(2);
}

/// The help that documents the flags of the command line typed: `mbrl train dlgpd --help` for a flag that
/// `train dlgpd` does not take, not the list of methods.
fn help_command(args: &[std::ffi::OsString]) -> String {
    let mut command = Cli::command();
    let mut path = vec!["mbrl".to_string()];
    for arg in args.iter().skip(1).take(2) {
        let Some(sub) = arg.to_str().and_then(|a| command.find_subcommand(a)).cloned() else {
            break;
        };
        path.push(sub.get_name().to_string());
        command = sub;
    }
    format!("{} --help", path.join(" "))
}

/// Control characters from inputs (a file name with a newline, bytes of a corrupt header) are escaped, so
/// an error is always exactly one line and cannot drive the terminal.
fn one_line(message: &str) -> String {
    message.chars().map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() }).collect()
}
