//! What every job shares: the invocation it runs under, the work it hands to a view, and the checks every
//! subcommand applies to its flags.

use std::path::{Path, PathBuf};

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
    /// `--force`: an explicitly named output that exists may be replaced.
    pub force: bool,
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

/// The one rule for where a command writes a file. A name the user gave (`given`) that exists is replaced only
/// with `--force`; a default name never replaces anything: when it is taken, the first free `name-2.ext`,
/// `name-3.ext`, … is used instead (the summary prints the name written). Either way a name that was free is
/// claimed, so a second command writing it meanwhile makes this one fail instead of silently replacing it.
pub fn output_file(
    flag: &str,
    given: Option<&Path>,
    default: impl FnOnce() -> PathBuf,
    extension: &str,
    invocation: &Invocation,
) -> Result<PathBuf> {
    let path = match given {
        Some(path) => {
            check_output_file(flag, path, extension)?;
            if path.is_file() && !invocation.force {
                refuse!("{flag} {} exists; add --force to replace it, or give another name", path.display());
            }
            path.to_path_buf()
        }
        None => {
            let path = free_name(&default())?;
            check_output_file(flag, &path, extension)?;
            path
        }
    };
    if !path.exists() {
        crate::util::atomic::claim_fresh(&path);
    }
    Ok(path)
}

/// As [`output_file`] for an output directory (a report, a map set): one that exists is replaced only with
/// `--force` when named, never when it is the default.
pub fn output_dir(
    flag: &str,
    given: Option<&Path>,
    default: impl FnOnce() -> PathBuf,
    invocation: &Invocation,
) -> Result<PathBuf> {
    match given {
        Some(path) => {
            if path.exists() && !path.is_dir() {
                refuse!("{flag} {}: exists and is not a directory", path.display());
            }
            if is_nonempty_dir(path) && !invocation.force {
                refuse!(
                    "{flag} {} exists and is not empty; add --force to replace what is in it, or give another name",
                    path.display()
                );
            }
            Ok(path.to_path_buf())
        }
        None => free_name(&default()),
    }
}

fn is_nonempty_dir(path: &Path) -> bool {
    std::fs::read_dir(path).is_ok_and(|mut entries| entries.next().is_some())
}

/// Most numbered names tried for a default output before giving up (a directory full of old results).
const MAX_NUMBERED_NAMES: u32 = 10_000;

/// `path` if nothing is there, else the first free `stem-N.ext` (N from 2).
fn free_name(path: &Path) -> Result<PathBuf> {
    // An empty directory is as good as nothing (a run stopped before it wrote anything, a `mkdir`).
    let taken = |p: &Path| std::fs::symlink_metadata(p).is_ok() && (!p.is_dir() || is_nonempty_dir(p));
    if !taken(path) {
        return Ok(path.to_path_buf());
    }
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let extension = path.extension().map(|e| format!(".{}", e.to_string_lossy())).unwrap_or_default();
    for n in 2..=MAX_NUMBERED_NAMES {
        let candidate = path.with_file_name(format!("{stem}-{n}{extension}"));
        if !taken(&candidate) {
            return Ok(candidate);
        }
    }
    refuse!("{}: {MAX_NUMBERED_NAMES} numbered outputs of this name exist; give --out", path.display())
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
