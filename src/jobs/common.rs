//! What every job shares: the invocation it runs under, the work it hands to a view, and the checks every
//! subcommand applies to its flags.

use std::path::Path;

use crate::envs::pendulum::PendulumVariant;
use crate::envs::{parse_env, EnvName};
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::{refuse, Result};

/// The command a job runs under: the seed of every random choice, the worker threads (same seed and thread
/// count, same bytes) and the command line as typed, which datasets and run records keep.
#[derive(Clone, Debug)]
pub struct Invocation {
    pub seed: u64,
    pub threads: usize,
    pub command_line: String,
}

impl Invocation {
    pub fn provenance(&self) -> Provenance {
        Provenance::new(self.command_line.clone(), self.seed, self.threads)
    }
}

/// Work whose settings have been checked, waiting for a view to run it. Everything a job can refuse without
/// doing work is refused before one is made, so a bad flag never opens the live view.
pub struct Job<'a, S> {
    pub title: String,
    work: Work<'a, S>,
}

type Work<'a, S> = Box<dyn FnOnce(&dyn Monitor) -> Result<S> + Send + 'a>;

impl<'a, S> Job<'a, S> {
    pub fn new(title: impl Into<String>, work: impl FnOnce(&dyn Monitor) -> Result<S> + Send + 'a) -> Self {
        Job { title: title.into(), work: Box::new(work) }
    }

    pub fn run(self, monitor: &dyn Monitor) -> Result<S> {
        (self.work)(monitor)
    }
}

/// A warning on stderr: something the user should know that does not stop the command (a model still in
/// training, taken with `--allow-incomplete`). Results go to stdout through the binary; this is the one
/// other line the library writes.
pub fn warn(message: &str) {
    eprintln!("warning: {message}");
}

/// Memory one recorded planning step takes, for the budget estimate of `plan` and `eval pendulum-swingup`.
pub const STEP_RECORD_BYTES: usize = 512;

/// Accepts only finite numbers, so NaN or inf never reach a simulator or planner (a clap value parser).
pub fn finite_f64(text: &str) -> std::result::Result<f64, String> {
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

/// The pendulum variant an env name denotes; other envs have no continuous MPC task yet.
pub fn pendulum_variant(name: &str) -> Result<PendulumVariant> {
    match parse_env(name)? {
        EnvName::Pendulum(v) => Ok(v),
        EnvName::Ball => {
            refuse!(
                "'ball' has no control task; use `mbrl filter` / `mbrl predict`; CEM planning supports pendulum envs"
            )
        }
        env @ (EnvName::Toy(_) | EnvName::MountainCar | EnvName::Unicycle(_) | EnvName::Terrain) => {
            refuse!("'{}' has no MPC task here yet; CEM planning supports pendulum envs", env.canonical())
        }
        env @ EnvName::Embodied(..) => refuse!(
            "'{}' is a board game played by a manipulator: plan its moves with `mbrl solve-board --embodiment`; CEM \
             planning supports pendulum envs",
            env.canonical()
        ),
        EnvName::Board(g) => refuse!(
            "'{}' is a board game: solve it with `mbrl solve-board --game {}`; CEM planning supports pendulum envs",
            g.name(),
            g.name()
        ),
    }
}

/// A comma-separated list of finite numbers (`--init-state 0.5,-1`), or an error naming the flag.
pub fn parse_floats(flag: &str, text: &str) -> Result<Vec<f64>> {
    text.split(',')
        .enumerate()
        .map(|(i, part)| match part.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => refuse!("{flag} '{text}': value {} ('{}') is not a finite number", i + 1, part.trim()),
        })
        .collect()
}

/// Extensions of the files mbrl reads or writes: an output named with one of them promises that format.
const KNOWN_EXTENSIONS: [&str; 10] = ["mcap", "csv", "npz", "json", "jsonl", "png", "md", "txt", "toml", "safetensors"];

/// Checks an output file before any work starts: not a directory, and not named for another format
/// (`plan --out p.csv` would otherwise get MCAP bytes). Names without a known extension are taken as given.
pub fn check_output_file(flag: &str, path: &Path, extension: &str) -> Result<()> {
    let named = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if let Some(named) = named.filter(|n| KNOWN_EXTENSIONS.contains(&n.as_str()) && n != extension) {
        let hint = if extension == "mcap" { "; `mbrl export` turns MCAP into CSV or .npz" } else { "" };
        refuse!(
            "{flag} {}: this writes {} and the name says .{named}; name it .{extension}{hint}",
            path.display(),
            extension.to_ascii_uppercase()
        );
    }
    crate::util::atomic::Target::of(path)?;
    Ok(())
}
