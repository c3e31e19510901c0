//! `mbrl filter`: run the ball EKF over recordings and write the filtered states with covariances.

use std::collections::HashMap;
use std::fmt;
use std::path::PathBuf;

use clap::Args;

use super::{output_file, Invocation, Job};
use crate::data::ball_estimates::{write_estimates_csv, write_estimates_mcap, BallEstimate};
use crate::data::ball_io::{read_recordings, FRAME_RATE};
use crate::models::ball::checkpoint::load_ball_model;
use crate::models::ball::track::filter_recording;
use crate::models::ball::Phase;
use crate::Result;

/// Filter table-tennis ball recordings with the gray-box EKF (thesis chapter 6).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl filter --model thesis --input datasets/ball-default.mcap --out filtered.csv --mcap filtered.mcap
  mbrl filter --model models/ball-ekf --input recording.csv

--model is `thesis` (learned values of eq. 6.26 / Table C.2), `initial` (Table C.1) or a directory written by training. CSV input: header frame (or t), x, y, z; empty x,y,z cells are lost frames.")]
pub struct FilterOptions {
    /// Ball model: thesis, initial, or a checkpoint directory.
    #[arg(long)]
    model: String,
    /// Recordings: a .mcap ball dataset or a .csv recording.
    #[arg(long)]
    input: PathBuf,
    /// CSV output: per frame the measurement, the state mean and its standard deviations (default:
    /// filtered.csv; when that exists, the first free filtered-2.csv, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write the means with full covariances as MCAP.
    #[arg(long)]
    mcap: Option<PathBuf>,
}

/// Per trajectory its id, log-likelihood and filtered frames; then what was written where.
pub struct FilterSummary {
    likelihoods: Vec<(u32, f64, usize)>,
    estimates: usize,
    out: PathBuf,
    mcap: Option<PathBuf>,
}

impl fmt::Display for FilterSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        for (id, ll, frames) in &self.likelihoods {
            writeln!(f, "trajectory {id}: {frames} frames filtered, log-likelihood {ll:.2}")?;
        }
        write!(f, "wrote {} estimates to {}", self.estimates, self.out.display())?;
        if let Some(path) = &self.mcap {
            write!(f, "\nwrote means and covariances to {}", path.display())?;
        }
        Ok(())
    }
}

pub fn prepare(options: FilterOptions, invocation: &Invocation) -> Result<Job<'static, FilterSummary>> {
    let model = load_ball_model(&options.model)?;
    let out = output_file("--out", options.out.as_deref(), || PathBuf::from("filtered.csv"), "csv", invocation)?;
    let mcap = match &options.mcap {
        Some(path) => Some(output_file("--mcap", Some(path), PathBuf::new, "mcap", invocation)?),
        None => None,
    };
    let recordings = read_recordings(&options.input)?;
    let command_line = invocation.command_line.clone();
    Ok(Job::new("filter", move |monitor| {
        let mut estimates = Vec::new();
        let mut likelihoods = Vec::new();
        for (k, rec) in recordings.iter().enumerate() {
            let track = filter_recording(&model.model, rec, None, &model.prior(rec))?;
            likelihoods.push((rec.id, track.log_likelihood, track.frames.len()));
            let measured: HashMap<u64, [f64; 3]> =
                rec.frames.iter().zip(&rec.positions).filter_map(|(f, p)| p.map(|p| (*f, p))).collect();
            for (frame, belief) in track.frames.iter().zip(&track.beliefs) {
                estimates.push(BallEstimate {
                    trajectory: rec.id,
                    frame: *frame,
                    t: *frame as f64 / FRAME_RATE,
                    measurement: measured.get(frame).copied(),
                    mean: std::array::from_fn(|i| belief.mean[i]),
                    covariance: belief.cov.transpose().iter().copied().collect(),
                    after_impact: belief.mode == Phase::AfterImpact,
                });
            }
            monitor.progress("filter recordings", k as u64 + 1, recordings.len() as u64);
        }
        write_estimates_csv(&out, &estimates)?;
        if let Some(path) = &mcap {
            write_estimates_mcap(path, &options.model, &command_line, &estimates)?;
        }
        Ok(FilterSummary { likelihoods, estimates: estimates.len(), out, mcap })
    }))
}
