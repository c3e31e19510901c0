//! `mbrl predict`: filter the start of ball recordings, predict the rest, report landing and
//! interception points.

use std::fmt;
use std::path::PathBuf;

use clap::Args;

use super::{finite_f64, output_file, Invocation, Job};
use crate::data::ball_io::{read_recordings, FRAME_RATE};
use crate::models::ball::checkpoint::load_ball_model;
use crate::models::ball::track::{
    filter_recording, landing, plane_crossing, predict_ahead, prediction_error, protocol_cut, PredictedPoint,
};
use crate::util::table::write_csv;
use crate::{refuse, Error, Result};

/// Predict table-tennis ball trajectories: filter until a horizon before the end, then predict ahead.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl predict --model thesis --input datasets/ball-default.mcap --horizon 1s --out predicted.csv
  mbrl predict --model thesis --input recording.csv --from-frame 40 --horizon 0.5s --plane-y 0.2

By default each trajectory is filtered until one horizon before its last frame (at least ten measurements, thesis 6.5.2) and predicted from there; the error is the largest distance over the last five prediction-measurement pairs. --plane-y reports where the ball crosses that vertical plane.")]
pub struct PredictOptions {
    /// Ball model: thesis, initial, or a checkpoint directory.
    #[arg(long)]
    model: String,
    /// Recordings: a .mcap ball dataset or a .csv recording.
    #[arg(long)]
    input: PathBuf,
    /// How far to predict: seconds with an `s` suffix (1s, 0.5s) or camera frames with `f` (90f).
    #[arg(long, default_value = "1s")]
    horizon: String,
    /// Filter until this camera frame instead of one horizon before the end.
    #[arg(long)]
    from_frame: Option<u64>,
    /// Report the crossing of the plane y = this value [m].
    #[arg(long, value_parser = finite_f64)]
    plane_y: Option<f64>,
    /// CSV of predicted points (default: predicted.csv; when that exists, the first free predicted-2.csv, …).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// One trajectory's prediction: where it started, its error, its landing and its plane crossing.
pub struct TrajectoryPrediction {
    pub id: u32,
    pub from_frame: u64,
    pub error: Option<f64>,
    pub landing: Option<PredictedPoint>,
    pub crossing: Option<(f64, [f64; 3])>,
}

/// Per trajectory one line, then where the predicted points were written.
pub struct PredictSummary {
    pub trajectories: Vec<TrajectoryPrediction>,
    horizon: String,
    plane_y: Option<f64>,
    pub out: PathBuf,
}

impl fmt::Display for PredictSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        for p in &self.trajectories {
            let error =
                p.error.map(|e| format!("{:.1} cm", 100.0 * e)).unwrap_or_else(|| "n/a (no later measurements)".into());
            write!(f, "trajectory {}: predicted from frame {}, error {error}", p.id, p.from_frame)?;
            if let Some(l) = &p.landing {
                write!(f, "; lands at ({:.3}, {:.3}) m, t = {:.3} s", l.position[0], l.position[1], l.t)?;
            }
            match (p.crossing, self.plane_y) {
                (Some((t, c)), _) => {
                    write!(f, "; crosses y = {:.3} at x = {:.3}, z = {:.3} m, t = {t:.3} s", c[1], c[0], c[2])?
                }
                (None, Some(y)) => write!(f, "; does not cross y = {y:.3} within the {} horizon", self.horizon)?,
                (None, None) => {}
            }
            writeln!(f)?;
        }
        write!(f, "wrote predictions to {}", self.out.display())
    }
}

fn horizon_frames(text: &str) -> Result<u64> {
    let parsed = if let Some(s) = text.strip_suffix('s') {
        s.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0).map(|v| (v * FRAME_RATE).round() as u64)
    } else if let Some(f) = text.strip_suffix('f') {
        f.parse::<u64>().ok().filter(|v| *v > 0)
    } else {
        None
    };
    match parsed {
        Some(frames) if frames > 0 => Ok(frames),
        _ => refuse!("--horizon '{text}': expected a positive duration like 1s, 0.5s or 90f (camera frames at 180 Hz)"),
    }
}

pub fn prepare(options: PredictOptions, invocation: &Invocation) -> Result<Job<'static, PredictSummary>> {
    let out = output_file("--out", options.out.as_deref(), || PathBuf::from("predicted.csv"), "csv", invocation)?;
    let model = load_ball_model(&options.model)?;
    let steps = horizon_frames(&options.horizon)?;
    let recordings = read_recordings(&options.input)?;
    // Every predicted point (mean and covariance) is kept until the CSV is written.
    crate::util::budget::check(
        &format!("--horizon {} for {} trajectories", options.horizon, recordings.len()),
        crate::util::budget::times(&[steps as usize, recordings.len()], 1024),
        "predict a shorter horizon",
    )?;
    Ok(Job::new("predict", move |monitor| {
        let mut rows = Vec::new();
        let mut trajectories = Vec::new();
        for (k, rec) in recordings.iter().enumerate() {
            let cut = options
                .from_frame
                .or_else(|| protocol_cut(rec, steps))
                .ok_or_else(|| Error::data(format!("trajectory {}: fewer than ten measurements to filter", rec.id)))?;
            let track = filter_recording(&model.model, rec, Some(cut), &model.prior(rec))?;
            let (from_frame, belief) =
                (*track.frames.last().unwrap_or(&cut), *track.beliefs.last().expect("start belief"));
            let points = predict_ahead(&model.model, &belief, from_frame, steps as usize);
            let start = [belief.mean[0], belief.mean[1], belief.mean[2]];
            let crossing =
                options.plane_y.and_then(|y| plane_crossing(&points, start, from_frame as f64 / FRAME_RATE, y));
            trajectories.push(TrajectoryPrediction {
                id: rec.id,
                from_frame,
                error: prediction_error(&points, rec),
                landing: landing(&points, &belief),
                crossing,
            });
            for p in &points {
                rows.push(vec![
                    rec.id.to_string(),
                    p.frame.to_string(),
                    format!("{:.6}", p.t),
                    format!("{:.6}", p.position[0]),
                    format!("{:.6}", p.position[1]),
                    format!("{:.6}", p.position[2]),
                    format!("{:.6}", p.std[0]),
                    format!("{:.6}", p.std[1]),
                    format!("{:.6}", p.std[2]),
                    p.after_impact.to_string(),
                ]);
            }
            monitor.progress("predict recordings", k as u64 + 1, recordings.len() as u64);
        }
        let header = ["trajectory", "frame", "t", "x", "y", "z", "std_x", "std_y", "std_z", "after_impact"];
        write_csv(&out, &header, &rows)?;
        Ok(PredictSummary { trajectories, horizon: options.horizon, plane_y: options.plane_y, out })
    }))
}
