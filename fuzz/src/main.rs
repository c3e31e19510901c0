#![doc = include_str!("../README.md")]

mod campaign;
mod extremes;
mod garbage;
mod mcap_doc;
mod mutant;
mod mutators;
mod report;
mod runner;
mod seeds;
mod targets;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};

use campaign::{fuzz_every_reader, settings};
use seeds::{generate, seeds, seeds_pass_the_python_mcap_reader, WORK};
use targets::{targets, Target};

/// `ulimit -v` in KiB: 4 GiB of address space. An unbounded allocation fails instead of swapping the machine.
pub(crate) const MEMORY_LIMIT_KIB: u64 = 4 << 20;
/// A run still going after this long counts as a hang.
pub(crate) const TIME_LIMIT: Duration = Duration::from_secs(20);
/// Mutants per target in the CI slice.
pub(crate) const DEFAULT_MUTANTS: u64 = 100;

/// Process-level fuzzing of every file and string reader of the `mbrl` binary (see fuzz/README.md). Each flag
/// falls back to the environment variable named in its help, then to its default.
#[derive(Parser)]
#[command(name = "mbrl-fuzz", version)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) child: Option<Child>,
    /// Mutants per target [env: MBRL_FUZZ_MUTANTS] [default: 100]
    #[arg(long, value_name = "N")]
    pub(crate) mutants: Option<u64>,
    /// Another family of mutants [env: MBRL_FUZZ_SEED] [default: 0]
    #[arg(long, value_name = "N")]
    pub(crate) seed: Option<u64>,
    /// Comma-separated substrings of target names (see --list) [env: MBRL_FUZZ_TARGETS]
    #[arg(long, value_name = "A,B")]
    pub(crate) targets: Option<String>,
    /// Parallel runs [env: MBRL_FUZZ_JOBS] [default: one per core]
    #[arg(long, value_name = "N")]
    pub(crate) jobs: Option<usize>,
    /// The `mbrl` binary to fuzz [env: MBRL_FUZZ_BIN] [default: target/release/mbrl]
    #[arg(long, value_name = "PATH")]
    pub(crate) bin: Option<PathBuf>,
    /// Where the seeds (DIR/tmp/fuzz-seeds) and the saved failures (DIR/fuzz-failures) go
    #[arg(long, value_name = "DIR", default_value = "target")]
    pub(crate) dir: PathBuf,
    /// Print every run's outcome and first stderr line [env: MBRL_FUZZ_VERBOSE, set to anything]
    #[arg(long)]
    pub(crate) verbose: bool,
    /// Structure-aware extremes instead of random mutations: mutant i writes one extreme value (±1.8e308,
    /// 5e-324, 0, -0, -1, 1e19, 2^64-1, NaN, inf, an empty or million-element array, …) into one numeric field
    /// of the input or one numeric flag, and a clean exit whose outputs hold NaN or infinity fails
    /// [env: MBRL_FUZZ_EXTREMES, set to anything]
    #[arg(long)]
    pub(crate) extremes: bool,
    /// With --extremes: only the fields and flags whose name contains one of these comma-separated substrings
    /// (`--fields=metadata.dt,--steps`: with `=` when the first starts with `--`) [env: MBRL_FUZZ_FIELDS]
    #[arg(long, value_name = "A,B")]
    pub(crate) fields: Option<String>,
    /// Print the target names and exit
    #[arg(long)]
    pub(crate) list: bool,
}

#[derive(Subcommand)]
enum Child {
    /// The child process of the `boardset-read` target: reads a board set through the library (no `mbrl`
    /// subcommand reads board sets).
    #[command(hide = true)]
    ReadBoardSet { path: PathBuf },
}

/// Reads a board set through the library: what the `boardset-read` target runs.
fn read_board_set(path: &Path) -> ExitCode {
    match mbrl::data::boardset::read_board_set(path) {
        Ok(set) => {
            println!("{} boards of {}", set.boards.len(), set.game);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(Child::ReadBoardSet { path }) = &cli.child {
        return read_board_set(path);
    }
    let all = targets();
    if cli.list {
        for target in &all {
            println!("{}", target.name);
        }
        return ExitCode::SUCCESS;
    }
    // 2: the campaign could not run; 1: it ran and found something.
    let setup_error = |message: String| {
        eprintln!("mbrl-fuzz: error: {message}");
        ExitCode::from(2)
    };
    let settings = match settings(&cli) {
        Ok(settings) => settings,
        Err(message) => return setup_error(message),
    };
    if !settings.binary.is_file() {
        let hint = if cli.bin.is_none() && std::env::var_os("MBRL_FUZZ_BIN").is_none() {
            ": build it with `cargo build --release` in the repository root, or pass --bin PATH"
        } else {
            ""
        };
        return setup_error(format!("{} not found{hint}", settings.binary.display()));
    }
    let targets: Vec<&Target> =
        all.iter().filter(|t| settings.only.is_empty() || settings.only.iter().any(|o| t.name.contains(o))).collect();
    if targets.is_empty() {
        return setup_error(format!("--targets {}: matches no target (see --list)", settings.only.join(",")));
    }
    // Absolute: the children run inside the seed directory.
    let dir = match std::path::absolute(&cli.dir) {
        Ok(dir) => dir,
        Err(e) => return setup_error(format!("{}: {e}", cli.dir.display())),
    };
    WORK.set(dir).expect("set once");
    let fields = cli.fields.clone().or_else(|| std::env::var("MBRL_FUZZ_FIELDS").ok()).unwrap_or_default();
    let fields = fields.split(',').map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect();
    extremes::FIELDS.set(fields).expect("set once");
    eprintln!("fuzz: testing {}", settings.binary.display());
    if let Err(message) = generate(&settings.binary) {
        return setup_error(message);
    }
    let outcome = seeds_pass_the_python_mcap_reader(seeds()).and_then(|()| fuzz_every_reader(&settings, &targets));
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("mbrl-fuzz: {report}");
            ExitCode::FAILURE
        }
    }
}
