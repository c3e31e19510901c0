//! `mbrl sweep`: seeds × settings as job lists for Slurm or a local `parallel`, their standing, their report.

use std::fmt;
use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};

use crate::error::{Error, Result};
use crate::refuse;
use crate::sweep::files::{self, JOBS_FILE};
use crate::sweep::plan::{Plan, Validate, PLAN_FILE};
use crate::sweep::report::{write_report, ReportSummary, COMPARE_FILE};
use crate::sweep::status::SweepStatus;
use crate::sweep::{expand, Spec};

/// Plan seeds × settings of any command as Slurm job arrays or local job lists; follow and report them.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl sweep plan sweeps/context-toy.toml --out sweeps/context-toy   # writes jobs.txt, slurm-*.sbatch, submit.sh
  sweeps/context-toy/run-local.sh 2            # run here, 2 jobs at a time (GNU parallel or xargs)
  sweeps/context-toy/submit.sh --wait          # or submit to Slurm as dependent job arrays
  mbrl sweep status sweeps/context-toy         # done / running / stopped at step k / failed / not started
  mbrl sweep report sweeps/context-toy         # per cell: mean, sd, 95 % t interval; curves; tests

A spec (TOML) names stages, each a command with a grid:
  [[stage]]
  name = \"train\"
  command = \"train context --data datasets/context/toy-inner.mcap --steps 2000\"
  [stage.grid]
  seed = [0, 1, 2]                 # --seed
  \"--preset\" = [\"small\", \"medium\"]   # a flag (true/false: present or absent)
  # lambda_kl = [0.5, 1.0]         # any other key: a trailing key=value override
  [[stage]]
  name = \"eval\"
  after = \"train\"                  # once per train run; {train} is that run's model
  command = \"eval context --model {train} --env toy:inner --contexts 10\"
  [slurm]
  cpus = 1
  memory = \"2G\"
  time = \"01:00:00\"

Every line is a complete mbrl command with --out in runs/<stage>/<job>/ and --job-dir there, so rerunning a \
line skips a finished job and resumes a stopped training: a requeued Slurm task or a second run-local.sh \
continues where the first stopped.")]
pub struct SweepOptions {
    #[command(subcommand)]
    action: SweepAction,
}

#[derive(Subcommand, Debug)]
enum SweepAction {
    /// Expand a spec into job lists and Slurm scripts in --out.
    Plan {
        /// The sweep spec (TOML).
        spec: PathBuf,
        /// The sweep's directory (created); rerunning the same spec there rewrites the same files.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Plan more than 10 000 jobs.
        #[arg(long)]
        allow_large: bool,
        /// The binary the job lines run (default: this one), e.g. its path on the cluster's shared disk.
        #[arg(long, value_name = "PATH")]
        mbrl: Option<PathBuf>,
    },
    /// Each job's standing: done, running, stopped at step k, failed (with its error), not started. Exits 1
    /// when a job failed, 3 when none failed but some are not done.
    Status {
        /// The sweep's directory.
        dir: PathBuf,
    },
    /// Per stage and cell (the grid values without the seed): n, mean, sd and a 95 % t interval of every
    /// scalar of the finished runs (eval summaries; trainings' final metrics), learning curves as mean ± t
    /// interval over seeds, and the spec's [[compare]] tests; report.md, cells.csv, compare.csv, PNGs.
    Report {
        /// The sweep's directory.
        dir: PathBuf,
        /// Where the report goes (default: DIR/report; replaced on every report).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

pub enum SweepOutcome {
    Planned(Planned),
    Status(SweepStatus),
    Reported(ReportSummary),
}

pub struct Planned {
    dir: PathBuf,
    stages: Vec<(String, usize)>,
    single_stage: bool,
}

impl fmt::Display for Planned {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let total: usize = self.stages.iter().map(|(_, n)| n).sum();
        let stages: Vec<String> = self.stages.iter().map(|(s, n)| format!("{s} {n}")).collect();
        writeln!(f, "planned {total} jobs ({}) in {}", stages.join(", "), self.dir.display())?;
        writeln!(
            f,
            "  here:  {}/run-local.sh 2     (2 jobs at a time; or parallel -j 2 < {}/{JOBS_FILE} for one stage)",
            self.dir.display(),
            self.dir.display()
        )?;
        if self.single_stage {
            write!(
                f,
                "  Slurm: sbatch {}/slurm.sbatch   (or {}/submit.sh --wait)",
                self.dir.display(),
                self.dir.display()
            )
        } else {
            write!(f, "  Slurm: {}/submit.sh --wait      (the stages as dependent job arrays)", self.dir.display())
        }
    }
}

impl fmt::Display for SweepOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SweepOutcome::Planned(p) => p.fmt(f),
            SweepOutcome::Status(s) => s.fmt(f),
            SweepOutcome::Reported(r) => r.fmt(f),
        }
    }
}

impl SweepOutcome {
    /// The exit status a script can test: 0 when every job is done (or nothing was asked but a plan), 1
    /// when one failed, 3 when some are unfinished.
    pub fn exit_status(&self) -> i32 {
        match self {
            SweepOutcome::Planned(_) | SweepOutcome::Reported(_) => 0,
            SweepOutcome::Status(s) if s.failed() > 0 => 1,
            SweepOutcome::Status(s) if s.done() < s.total() => 3,
            SweepOutcome::Status(_) => 0,
        }
    }
}

/// Runs a sweep action; `validate` parses each planned line as the command line would.
pub fn run(options: SweepOptions, validate: Validate) -> Result<SweepOutcome> {
    match options.action {
        SweepAction::Plan { spec, out, allow_large, mbrl } => plan(&spec, &out, allow_large, mbrl, validate),
        SweepAction::Status { dir } => Ok(SweepOutcome::Status(SweepStatus::of(&Plan::read(&dir)?))),
        SweepAction::Report { dir, out } => {
            let plan = Plan::read(&dir)?;
            let out = out.unwrap_or_else(|| dir.join("report"));
            let summary = write_report(&plan, &out)?;
            remove_stale(&out, &summary.files)?;
            Ok(SweepOutcome::Reported(summary))
        }
    }
}

fn plan(
    spec_path: &Path,
    out: &Path,
    allow_large: bool,
    mbrl: Option<PathBuf>,
    validate: Validate,
) -> Result<SweepOutcome> {
    let spec = Spec::read(spec_path)?;
    let dir = absolute(out).map_err(|e| Error::io(out, e))?;
    let text = dir.to_str().ok_or_else(|| Error::bad_file(out, "is not UTF-8; a job list names it on every line"))?;
    if text.chars().any(|c| c.is_whitespace() || c == '%' || c == '\'' || c == '"' || c.is_control()) {
        refuse!("--out {text}: a sweep directory whose path holds spaces, quotes or % cannot be named in #SBATCH lines; choose another");
    }
    let mbrl = match mbrl {
        Some(path) => path,
        None => std::env::current_exe()
            .map_err(|e| Error::config(format!("cannot find this binary's path ({e}); give --mbrl")))?,
    };
    let plan = expand(&spec, &dir, &mbrl, validate, allow_large).map_err(|e| e.at(spec_path))?;
    if dir.join(PLAN_FILE).is_file() {
        let existing = Plan::read(&dir)?;
        if existing.spec != plan.spec {
            refuse!(
                "--out {}: holds a different sweep (its {PLAN_FILE} has another spec); give another --out",
                dir.display()
            );
        }
        if existing.mbrl != plan.mbrl {
            refuse!(
                "--out {}: its jobs run {}, not {}; give --mbrl {} to keep them, or another --out",
                dir.display(),
                existing.mbrl.display(),
                plan.mbrl.display(),
                existing.mbrl.display()
            );
        }
    } else if std::fs::read_dir(&dir).is_ok_and(|mut entries| entries.next().is_some()) {
        refuse!("--out {}: holds files but no {PLAN_FILE}; give an empty or new directory", dir.display());
    }
    files::write_all(&plan)?;
    Ok(SweepOutcome::Planned(Planned {
        dir,
        stages: plan.stages.iter().map(|s| (s.name.clone(), s.jobs.len())).collect(),
        single_stage: plan.stages.len() == 1,
    }))
}

/// A report replaces the one before it: plots and tables the new report did not write (a metric gone, the
/// comparisons removed from the spec) go, so the directory never mixes two reports. Other files are left.
fn remove_stale(out: &Path, written: &[String]) -> Result<()> {
    let entries = std::fs::read_dir(out).map_err(|e| Error::io(out, e))?;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let ours = (name.starts_with("curves-") && name.ends_with(".png")) || name == COMPARE_FILE;
        if ours && !written.contains(&name) {
            std::fs::remove_file(entry.path()).map_err(|e| Error::io(&entry.path(), e))?;
        }
    }
    Ok(())
}

/// The directory as an absolute path (resolved when it exists), so that every line works from any directory;
/// nothing is created before the plan is known to be good.
fn absolute(path: &Path) -> std::io::Result<PathBuf> {
    match path.canonicalize() {
        Ok(resolved) => Ok(resolved),
        Err(_) => std::path::absolute(path),
    }
}
