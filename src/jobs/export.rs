//! `mbrl export`: any mbrl data file as a CSV table or NumPy arrays, and a run's metrics as a CSV table.

use std::fmt;
use std::path::{Path, PathBuf};

use clap::Args;

use super::{output_file, Invocation};
use crate::data::export::{self, ExportFormat, Exported};
use crate::data::metrics_export::{export_metrics, MetricsExported};
use crate::run::dir::METRICS_FILE;
use crate::run::watched::{metrics_path, run_dir};
use crate::{refuse, Result};

/// Convert a dataset, board set, ball recording or filter-estimate file to CSV or NumPy `.npz`, or a run's
/// metrics to CSV.
#[derive(Args, Debug)]
#[command(after_help = "\
The file's kind is read from its metadata. CSV holds one row per step (per board, per camera frame, per estimate); missing values (lost ball frames) are empty cells, booleans 0/1. The .npz archive holds the same columns as arrays plus what does not fit a table: rendered frames (N × H × W × 3, uint8), filter covariances (N × 11 × 11), per-recording launcher side information. Keys: datasets/README.md.

A run directory (train, eval, plan --out) or its metrics.jsonl exports every metric the run recorded (training
loss terms, validation, returns, planner costs) as one long CSV table: columns step,metric,value, one row per
point in the order recorded, NaN as an empty cell. Long because metrics come at different steps and some
restart their step every episode; pandas' pivot_table(index=\"step\", columns=\"metric\", values=\"value\")
makes the wide table. A run still writing is exported as far as it got.

Without --out the output goes beside the input: datasets/p.mcap gives datasets/p.csv (or .npz with --format
npz), a run directory gives RUN_DIR/metrics.csv; a name that is taken gets a number, never replaced.

Examples:
  mbrl export --input datasets/pendulum.mcap --out pendulum.npz
  mbrl export --input datasets/pendulum.mcap --out pendulum.csv
  mbrl export --input datasets/ball.mcap --format npz --out ball.npz
  mbrl export --input models/pets-pendulum                 # its metrics, to models/pets-pendulum/metrics.csv
  mbrl export --input models/pets-pendulum --out pets-loss.csv
  python3 -c \"import numpy as np; d = np.load('pendulum.npz'); print(d['state'].shape)\"")]
pub struct ExportOptions {
    /// An mbrl MCAP file (a dataset from `collect`, board set, ball recording or `filter --out *.mcap`
    /// output), or a run directory (or its metrics.jsonl) whose metrics to export.
    #[arg(long)]
    input: PathBuf,
    /// Output file; its extension (.csv or .npz) chooses the format unless --format is given. Default: beside
    /// the input (see below).
    #[arg(long)]
    out: Option<PathBuf>,
    /// csv or npz (metrics: csv only); must agree with --out's extension when that names a format.
    #[arg(long, value_parser = crate::jobs::names::export_formats(), hide_possible_values = true)]
    format: Option<String>,
}

/// What the input was turned into.
enum Done {
    Data(Exported, ExportFormat),
    Metrics(MetricsExported),
}

pub struct ExportSummary {
    done: Done,
    input: PathBuf,
    out: PathBuf,
}

impl fmt::Display for ExportSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let (input, out) = (self.input.display(), self.out.display());
        match &self.done {
            Done::Data(exported, format) => write!(
                f,
                "exported {} rows of {} {input} to {out} ({}): {}",
                exported.rows,
                exported.kind.describe(),
                format.extension(),
                exported.array_shapes(*format).join(", ")
            ),
            Done::Metrics(exported) => {
                let counts: Vec<String> = exported.points.iter().map(|(name, n)| format!("{name} {n}")).collect();
                write!(
                    f,
                    "exported {} points of {} metrics of run {input} to {out} (csv: step,metric,value): {}",
                    exported.rows(),
                    exported.points.len(),
                    counts.join(", ")
                )
            }
        }
    }
}

/// A run's metrics rather than a data file: a directory, or a metrics file named as such.
fn is_run(input: &Path) -> bool {
    input.is_dir() || input.extension().is_some_and(|e| e == "jsonl")
}

/// Export is quick and reads one file: it runs at once, with no view.
pub fn run(options: ExportOptions, invocation: &Invocation) -> Result<ExportSummary> {
    let format = choose_format(&options)?;
    let run = is_run(&options.input);
    if run && format != ExportFormat::Csv {
        refuse!(
            "--format {}: a run's metrics export as csv only (--input {} is a run)",
            format.extension(),
            options.input.display()
        );
    }
    let default = || default_out(&options.input, run, format);
    // A directory, an existing file without --force or an unwritable place is refused before the input is read.
    let out = output_file("--out", options.out.as_deref(), default, format.extension(), invocation)?;
    let done = if run {
        Done::Metrics(export_metrics(&metrics_path(&options.input), &out)?)
    } else {
        let exported = export::load(&options.input)?;
        export::write(&exported, format, &out)?;
        Done::Data(exported, format)
    };
    Ok(ExportSummary { done, input: options.input, out })
}

/// Beside the input: `RUN_DIR/metrics.csv` for a run, the data file's name with the format's extension.
fn default_out(input: &Path, run: bool, format: ExportFormat) -> PathBuf {
    if run {
        let metrics = Path::new(METRICS_FILE).with_extension(format.extension());
        run_dir(input).join(metrics)
    } else {
        input.with_extension(format.extension())
    }
}

fn choose_format(options: &ExportOptions) -> Result<ExportFormat> {
    let named = match &options.format {
        Some(text) => match ExportFormat::parse(text) {
            Some(f) => Some(f),
            None => refuse!(
                "--format '{text}' is not known{}; supported: {}",
                crate::util::suggest::did_you_mean(text, ExportFormat::NAMES.split(", ")),
                ExportFormat::NAMES
            ),
        },
        None => None,
    };
    let Some(out) = &options.out else {
        return Ok(named.unwrap_or(ExportFormat::Csv));
    };
    let by_extension = ExportFormat::of_path(out);
    match (named, by_extension) {
        (Some(f), Some(e)) if f != e => refuse!(
            "--format {} disagrees with --out {} (a .{} file); give --out a .{} name",
            f.extension(),
            out.display(),
            e.extension(),
            f.extension()
        ),
        (Some(f), _) | (None, Some(f)) => Ok(f),
        (None, None) => refuse!(
            "--out {}: cannot tell the format from the extension; name it .csv or .npz, or give --format ({})",
            out.display(),
            ExportFormat::NAMES
        ),
    }
}
