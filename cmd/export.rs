//! `mbrl export`: any mbrl data file as a CSV table or NumPy arrays.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use mbrl::data::export::{self, ExportFormat};
use mbrl::util::atomic::Target;

/// Convert a dataset, board set, ball recording or filter-estimate file to CSV or NumPy `.npz`.
#[derive(Args, Debug)]
#[command(after_help = "\
The file's kind is read from its metadata. CSV holds one row per step (per board, per camera frame, per
estimate); missing values (lost ball frames) are empty cells, booleans 0/1. The .npz archive holds the same
columns as arrays plus what does not fit a table: rendered frames (N × H × W × 3, uint8), filter
covariances (N × 11 × 11), per-recording launcher side information. Keys: datasets/README.md.

Examples:
  mbrl export --input datasets/pendulum.mcap --out pendulum.npz
  mbrl export --input datasets/pendulum.mcap --out pendulum.csv
  mbrl export --input datasets/ball.mcap --format npz --out ball.npz
  python3 -c \"import numpy as np; d = np.load('pendulum.npz'); print(d['state'].shape)\"")]
pub struct ExportArgs {
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

pub fn run(args: ExportArgs) -> anyhow::Result<()> {
    let format = choose_format(&args)?;
    // A directory or unwritable place is refused before the input is read.
    Target::of(&args.out)?;
    let exported = export::load(&args.input)?;
    export::write(&exported, format, &args.out)?;
    say!(
        "exported {} rows of {} {} to {} ({}): {}",
        exported.rows,
        exported.kind.describe(),
        args.input.display(),
        args.out.display(),
        format.extension(),
        exported.array_shapes(format).join(", ")
    );
    Ok(())
}

fn choose_format(args: &ExportArgs) -> anyhow::Result<ExportFormat> {
    let named = match &args.format {
        Some(text) => match ExportFormat::parse(text) {
            Some(f) => Some(f),
            None => bail!("--format '{text}' is not known; supported: {}", ExportFormat::NAMES),
        },
        None => None,
    };
    let by_extension = ExportFormat::of_path(&args.out);
    match (named, by_extension) {
        (Some(f), Some(e)) if f != e => bail!(
            "--format {} disagrees with --out {} (a .{} file); give --out a .{} name",
            f.extension(),
            args.out.display(),
            e.extension(),
            f.extension()
        ),
        (Some(f), _) | (None, Some(f)) => Ok(f),
        (None, None) => bail!(
            "--out {}: cannot tell the format from the extension; name it .csv or .npz, or give --format ({})",
            args.out.display(),
            ExportFormat::NAMES
        ),
    }
}
