//! Flags every subcommand shares, and how a job is shown: live TUI, progress lines, or nothing.

use std::io::IsTerminal;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::Context;
use clap::Args;
use mbrl::jobs::{Invocation, Job};
use mbrl::run::{ChannelMonitor, ConsoleMonitor, Event, Monitor, NullMonitor};

use mbrl::tui::{run_live, LiveOptions, LiveOutcome, DEFAULT_GRACE};

#[derive(Args, Clone, Debug)]
pub struct GlobalArgs {
    /// Seed for every random choice; the same seed and thread count give the same output bytes.
    #[arg(long, global = true, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0 = one per core).
    #[arg(long, global = true, default_value_t = 0)]
    pub threads: usize,
    /// Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It
    /// opens once the work has run a second and closes by itself when the work ends.
    #[arg(long, global = true, overrides_with = "no_tui")]
    pub tui: bool,
    /// Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold).
    #[arg(long, global = true)]
    pub hold: bool,
    /// Print plain progress lines on stderr instead of the live view.
    #[arg(long, global = true, overrides_with = "tui")]
    pub no_tui: bool,
    /// Replace an output named with --out (or another output flag) that exists; without it such a command is
    /// refused. Default output names never replace anything: a free numbered name is used.
    #[arg(long, global = true)]
    pub force: bool,
    /// Print only results and errors.
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// Record this command's outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR's
    /// lock while it runs; when DIR records this same command as done, do nothing. What makes a job list's
    /// lines safe to rerun (`mbrl sweep plan` adds it to every line).
    #[arg(long, global = true, value_name = "DIR")]
    pub job_dir: Option<std::path::PathBuf>,
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

/// `MBRL_TUI` in the environment: the live view's default for every command, outside the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TuiSetting {
    /// On a terminal, as without the variable.
    Auto,
    /// Progress lines on stderr; `--tui` on a command line still asks for the view.
    Never,
    /// As `--hold` on every command.
    Hold,
}

fn tui_setting() -> anyhow::Result<TuiSetting> {
    match std::env::var("MBRL_TUI") {
        Err(std::env::VarError::NotPresent) => Ok(TuiSetting::Auto),
        Ok(value) => match value.as_str() {
            "" | "auto" => Ok(TuiSetting::Auto),
            "never" => Ok(TuiSetting::Never),
            "hold" => Ok(TuiSetting::Hold),
            other => anyhow::bail!("MBRL_TUI='{other}': expected never, auto or hold"),
        },
        Err(std::env::VarError::NotUnicode(_)) => anyhow::bail!("MBRL_TUI is not UTF-8: expected never, auto or hold"),
    }
}

impl GlobalArgs {
    pub fn use_tui(&self) -> bool {
        if self.quiet || self.no_tui {
            return false;
        }
        self.tui || (tui_setting().ok() != Some(TuiSetting::Never) && std::io::stdout().is_terminal())
    }

    /// How the live view opens and closes: after a grace second, closing by itself unless held.
    pub fn live_options(&self) -> LiveOptions {
        LiveOptions { hold: self.hold || tui_setting().ok() == Some(TuiSetting::Hold), grace: DEFAULT_GRACE }
    }

    pub fn thread_count(&self) -> usize {
        rayon::current_num_threads()
    }

    /// What a library job needs to know of this command.
    pub fn invocation(&self) -> Invocation {
        Invocation { seed: self.seed, threads: self.thread_count(), command_line: command_line(), force: self.force }
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
    tui_setting()?;
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
        // Training runs its whole loop on a worker (`util::warm_pool`): the main thread's stack size, not
        // rayon's default 2 MiB.
        .stack_size(8 << 20)
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

/// Runs a prepared job in the view the flags ask for and prints its summary.
pub fn show<S: std::fmt::Display + Send>(global: &GlobalArgs, job: Job<'_, S>) -> anyhow::Result<()> {
    let title = job.title.clone();
    let summary = run_job(global, &title, |monitor| job.run(monitor))?;
    say!("{summary}");
    Ok(())
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
        let outcome = run_live(receiver, cancel.clone(), title, global.live_options()).context("terminal view failed");
        let result = worker.join().map_err(|_| anyhow::anyhow!("the job panicked"))?;
        match outcome? {
            LiveOutcome::QuitByUser | LiveOutcome::Finished => Ok(result?),
        }
    })
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
