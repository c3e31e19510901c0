//! Flags every subcommand shares, and how a job is shown: live TUI, progress lines, or nothing.

use std::io::IsTerminal;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::Context;
use clap::Args;
use mbrl::run::{ChannelMonitor, ConsoleMonitor, Event, Monitor, NullMonitor};
use mbrl::tui::{run_live, LiveOutcome};

#[derive(Args, Clone, Debug)]
pub struct GlobalArgs {
    /// Seed for every random choice; the same seed and thread count give the same output bytes.
    #[arg(long, global = true, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0 = one per core).
    #[arg(long, global = true, default_value_t = 0)]
    pub threads: usize,
    /// Show the live terminal view (default when stdout is a terminal).
    #[arg(long, global = true, overrides_with = "no_tui")]
    pub tui: bool,
    /// Print plain progress lines on stderr instead of the live view.
    #[arg(long, global = true, overrides_with = "tui")]
    pub no_tui: bool,
    /// Print only results and errors.
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// Refuse work whose flags ask for more memory than this (estimated before it starts).
    #[arg(long, global = true, value_name = "GIB", default_value_t = mbrl::util::budget::DEFAULT_LIMIT_GIB, value_parser = memory_gib)]
    pub max_memory_gib: f64,
}

fn memory_gib(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= 1e6 => Ok(v),
        _ => Err(format!("'{text}': expected a size in GiB between 0 and 1e6")),
    }
}

impl GlobalArgs {
    pub fn use_tui(&self) -> bool {
        if self.quiet || self.no_tui {
            return false;
        }
        self.tui || std::io::stdout().is_terminal()
    }

    pub fn thread_count(&self) -> usize {
        rayon::current_num_threads()
    }
}

/// The live view draws on stdout and reads keys from stdin or, when that is redirected, the controlling
/// terminal.
fn has_terminal() -> bool {
    std::io::stdout().is_terminal()
        && (std::io::stdin().is_terminal() || std::fs::OpenOptions::new().read(true).open("/dev/tty").is_ok())
}

/// More worker threads than this only cost memory (a stack each) on any machine mbrl runs on.
const MAX_THREADS: usize = 1024;

pub fn init_threads(global: &GlobalArgs) -> anyhow::Result<()> {
    if global.threads > MAX_THREADS {
        anyhow::bail!("--threads {}: at most {MAX_THREADS} worker threads (0 = one per core)", global.threads);
    }
    if global.tui && !global.quiet && !global.no_tui && !has_terminal() {
        anyhow::bail!(
            "--tui needs a terminal, and stdout is a pipe or file (or there is no controlling terminal); drop --tui, \
             or give --no-tui for progress lines on stderr"
        );
    }
    mbrl::util::budget::set_limit_gib(global.max_memory_gib);
    rayon::ThreadPoolBuilder::new()
        .num_threads(global.threads)
        .build_global()
        .context("could not start the worker threads")
}

/// The command line as typed, recorded in datasets and run configs.
pub fn command_line() -> String {
    // Record the program as `mbrl`, not the path it was started from, so outputs do not depend on
    // where the binary lives.
    std::env::args()
        .enumerate()
        .map(|(i, a)| if i == 0 { "mbrl".to_string() } else { a })
        .map(|a| {
            if a.is_empty() || a.contains(|c: char| c.is_whitespace() || "\"'$`\\".contains(c)) {
                format!("'{}'", a.replace('\'', r"'\''"))
            } else {
                a
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Runs `job` with the monitor the flags ask for. With the TUI, the job runs on a worker thread while the
/// view owns the terminal; quitting the view cancels the job.
pub fn run_job<T: Send>(
    global: &GlobalArgs,
    title: &str,
    job: impl FnOnce(&dyn Monitor) -> mbrl::Result<T> + Send,
) -> anyhow::Result<T> {
    if !global.use_tui() {
        let result = if global.quiet { job(&NullMonitor) } else { job(&ConsoleMonitor::new()) };
        return Ok(result?);
    }
    let (sender, receiver) = std::sync::mpsc::channel();
    let cancel = Arc::new(AtomicBool::new(false));
    let monitor = ChannelMonitor::new(sender, cancel.clone());
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            let result = job(&monitor);
            if let Err(e) = &result {
                monitor.emit(&Event::message(format!("error: {e}")));
            }
            monitor.emit(&Event::Finished { ok: result.is_ok() });
            result
        });
        let outcome = run_live(receiver, cancel.clone(), title).context("terminal view failed");
        let result = worker.join().map_err(|_| anyhow::anyhow!("the job panicked"))?;
        match outcome? {
            LiveOutcome::QuitByUser | LiveOutcome::Finished => Ok(result?),
        }
    })
}

/// Accepts only finite numbers, so NaN or inf never reach a simulator or planner.
pub fn finite_f64(text: &str) -> Result<f64, String> {
    let value: f64 = text.parse().map_err(|_| format!("'{text}' is not a number"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("'{text}' is not finite; expected a finite number"))
    }
}

/// A filesystem-friendly form of an env name (`pendulum:heavy` → `pendulum-heavy`).
pub fn file_stem(env: &str) -> String {
    env.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '-' }).collect()
}

/// The successor model a board search uses. The learned SEADS model joins this list when it lands.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelChoice {
    /// The game's own rules (ground truth).
    True,
}

/// The pendulum variant an env name denotes; other envs have no continuous MPC task yet.
pub fn pendulum_variant(name: &str) -> anyhow::Result<mbrl::envs::pendulum::PendulumVariant> {
    match mbrl::envs::parse_env(name)? {
        mbrl::envs::EnvName::Pendulum(v) => Ok(v),
        mbrl::envs::EnvName::Ball => {
            anyhow::bail!(
                "'ball' has no control task; use `mbrl filter` / `mbrl predict`; CEM planning supports pendulum envs"
            )
        }
        env @ (mbrl::envs::EnvName::Toy(_)
        | mbrl::envs::EnvName::MountainCar
        | mbrl::envs::EnvName::Unicycle(_)
        | mbrl::envs::EnvName::Terrain) => {
            anyhow::bail!("'{}' has no MPC task here yet; CEM planning supports pendulum envs", env.canonical())
        }
        env @ mbrl::envs::EnvName::Embodied(..) => anyhow::bail!(
            "'{}' is a board game played by a manipulator: plan its moves with `mbrl solve-board --embodiment`; CEM \
             planning supports pendulum envs",
            env.canonical()
        ),
        mbrl::envs::EnvName::Board(g) => anyhow::bail!(
            "'{}' is a board game: solve it with `mbrl solve-board --game {}`; CEM planning supports pendulum envs",
            g.name(),
            g.name()
        ),
    }
}

/// A comma-separated list of finite numbers (`--init-state 0.5,-1`), or an error naming the flag.
pub fn parse_floats(flag: &str, text: &str) -> anyhow::Result<Vec<f64>> {
    text.split(',')
        .enumerate()
        .map(|(i, part)| match part.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => anyhow::bail!("{flag} '{text}': value {} ('{}') is not a finite number", i + 1, part.trim()),
        })
        .collect()
}

/// Prints one line of results. A reader that closed stdout early (`mbrl … | head -1`) does not stop the
/// work, whose files are still written; any other failure to write ends the command with one error line.
pub fn say(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    write_stdout(out.write_fmt(args).and_then(|()| out.write_all(b"\n")));
}

/// The policy of `say` for any write to stdout.
pub fn write_stdout(result: std::io::Result<()>) {
    match result {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {}
        Err(e) => mbrl::util::interrupt::abandon_and_exit_with(1, &format!("cannot write to stdout: {e}")),
    }
}

/// Extensions of the files mbrl reads or writes: an output named with one of them promises that format.
const KNOWN_EXTENSIONS: [&str; 10] = ["mcap", "csv", "npz", "json", "jsonl", "png", "md", "txt", "toml", "safetensors"];

/// Checks an output file before any work starts: not a directory, and not named for another format
/// (`plan --out p.csv` would otherwise get MCAP bytes). Names without a known extension are taken as given.
pub fn check_output_file(flag: &str, path: &std::path::Path, extension: &str) -> anyhow::Result<()> {
    let named = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if let Some(named) = named.filter(|n| KNOWN_EXTENSIONS.contains(&n.as_str()) && n != extension) {
        let hint = if extension == "mcap" { "; `mbrl export` turns MCAP into CSV or .npz" } else { "" };
        anyhow::bail!(
            "{flag} {}: this writes {} and the name says .{named}; name it .{extension}{hint}",
            path.display(),
            extension.to_ascii_uppercase()
        );
    }
    mbrl::util::atomic::Target::of(path)?;
    Ok(())
}
