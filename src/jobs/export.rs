//! `mbrl export`: any mbrl data file as a CSV table or NumPy arrays.

use std::fmt;
use std::path::PathBuf;

use clap::Args;

use super::{output_file, Invocation};
use crate::data::export::{self, ExportFormat, Exported};
use crate::{refuse, Result};

/// Convert a dataset, board set, ball recording or filter-estimate file to CSV or NumPy `.npz`.
#[derive(Args, Debug)]
#[command(after_help = "\
The file's kind is read from its metadata. CSV holds one row per step (per board, per camera frame, per estimate); missing values (lost ball frames) are empty cells, booleans 0/1. The .npz archive holds the same columns as arrays plus what does not fit a table: rendered frames (N × H × W × 3, uint8), filter covariances (N × 11 × 11), per-recording launcher side information. Keys: datasets/README.md.

Examples:
  mbrl export --input datasets/pendulum.mcap --out pendulum.npz
  mbrl export --input datasets/pendulum.mcap --out pendulum.csv
  mbrl export --input datasets/ball.mcap --format npz --out ball.npz
  python3 -c \"import numpy as np; d = np.load('pendulum.npz'); print(d['state'].shape)\"")]
pub struct ExportOptions {
    /// An mbrl MCAP file: a dataset (`collect`), board set, ball recording or `filter --out *.mcap` output.
    #[arg(long)]
    input: PathBuf,
    /// Output file; its extension (.csv or .npz) chooses the format unless --format is given.
    #[arg(long)]
    out: PathBuf,
    /// csv or npz; must agree with --out's extension when that names a format.
    #[arg(long)]
    format: Option<String>,
}

pub struct ExportSummary {
    exported: Exported,
    format: ExportFormat,
    input: PathBuf,
    out: PathBuf,
}

impl fmt::Display for ExportSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "exported {} rows of {} {} to {} ({}): {}",
            self.exported.rows,
            self.exported.kind.describe(),
            self.input.display(),
            self.out.display(),
            self.format.extension(),
            self.exported.array_shapes(self.format).join(", ")
        )
    }
}

/// Export is quick and reads one file: it runs at once, with no view.
pub fn run(options: ExportOptions, invocation: &Invocation) -> Result<ExportSummary> {
    let format = choose_format(&options)?;
    // A directory, an existing file without --force or an unwritable place is refused before the input is read.
    output_file("--out", Some(&options.out), PathBuf::new, format.extension(), invocation)?;
    let exported = export::load(&options.input)?;
    export::write(&exported, format, &options.out)?;
    Ok(ExportSummary { exported, format, input: options.input, out: options.out })
}

fn choose_format(options: &ExportOptions) -> Result<ExportFormat> {
    let named = match &options.format {
        Some(text) => match ExportFormat::parse(text) {
            Some(f) => Some(f),
            None => refuse!("--format '{text}' is not known; supported: {}", ExportFormat::NAMES),
        },
        None => None,
    };
    let by_extension = ExportFormat::of_path(&options.out);
    match (named, by_extension) {
        (Some(f), Some(e)) if f != e => refuse!(
            "--format {} disagrees with --out {} (a .{} file); give --out a .{} name",
            f.extension(),
            options.out.display(),
            e.extension(),
            f.extension()
        ),
        (Some(f), _) | (None, Some(f)) => Ok(f),
        (None, None) => refuse!(
            "--out {}: cannot tell the format from the extension; name it .csv or .npz, or give --format ({})",
            options.out.display(),
            ExportFormat::NAMES
        ),
    }
}
