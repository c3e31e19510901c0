//! `mbrl predict`: filter the start of ball recordings, predict the rest, report landing and
//! interception points.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use mbrl::data::ball_io::{read_recordings, FRAME_RATE};
use mbrl::models::ball::checkpoint::load_ball_model;
use mbrl::models::ball::track::{
    filter_recording, landing, plane_crossing, predict_ahead, prediction_error, protocol_cut,
};
use mbrl::util::table::write_csv;

use crate::common::{check_output_file, run_job, GlobalArgs};

/// Predict table-tennis ball trajectories: filter until a horizon before the end, then predict ahead.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl predict --model thesis --input datasets/ball-default.mcap --horizon 1s --out predicted.csv
  mbrl predict --model thesis --input recording.csv --from-frame 40 --horizon 0.5s --plane-y 0.2

By default each trajectory is filtered until one horizon before its last frame (at least ten
measurements, thesis 6.5.2) and predicted from there; the error is the largest distance over the last
five prediction-measurement pairs. --plane-y reports where the ball crosses that vertical plane.")]
pub struct PredictArgs {
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
    #[arg(long, value_parser = crate::common::finite_f64)]
    plane_y: Option<f64>,
    /// CSV of predicted points.
    #[arg(long, default_value = "predicted.csv")]
    out: PathBuf,
}

fn horizon_frames(text: &str) -> anyhow::Result<u64> {
    let parsed = if let Some(s) = text.strip_suffix('s') {
        s.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0).map(|v| (v * FRAME_RATE).round() as u64)
    } else if let Some(f) = text.strip_suffix('f') {
        f.parse::<u64>().ok().filter(|v| *v > 0)
    } else {
        None
    };
    match parsed {
        Some(frames) if frames > 0 => Ok(frames),
        _ => bail!("--horizon '{text}': expected a positive duration like 1s, 0.5s or 90f (camera frames at 180 Hz)"),
    }
}

pub fn run(global: &GlobalArgs, args: PredictArgs) -> anyhow::Result<()> {
    check_output_file("--out", &args.out, "csv")?;
    let model = load_ball_model(&args.model)?;
    let steps = horizon_frames(&args.horizon)?;
    let recordings = read_recordings(&args.input)?;
    // Every predicted point (mean and covariance) is kept until the CSV is written.
    mbrl::util::budget::check(
        &format!("--horizon {} for {} trajectories", args.horizon, recordings.len()),
        mbrl::util::budget::times(&[steps as usize, recordings.len()], 1024),
        "predict a shorter horizon",
    )?;
    let summaries = run_job(global, "predict", |monitor| {
        let mut rows = Vec::new();
        let mut summaries = Vec::new();
        for (k, rec) in recordings.iter().enumerate() {
            let cut = args.from_frame.or_else(|| protocol_cut(rec, steps)).ok_or_else(|| {
                mbrl::Error::data(format!("trajectory {}: fewer than ten measurements to filter", rec.id))
            })?;
            let track = filter_recording(&model.model, rec, Some(cut), &model.prior(rec))?;
            let (from_frame, belief) =
                (*track.frames.last().unwrap_or(&cut), *track.beliefs.last().expect("start belief"));
            let points = predict_ahead(&model.model, &belief, from_frame, steps as usize);
            let start = [belief.mean[0], belief.mean[1], belief.mean[2]];
            let crossing = args.plane_y.and_then(|y| plane_crossing(&points, start, from_frame as f64 / FRAME_RATE, y));
            summaries.push((rec.id, from_frame, prediction_error(&points, rec), landing(&points, &belief), crossing));
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
        write_csv(&args.out, &header, &rows)?;
        Ok(summaries)
    })?;
    for (id, from, error, land, crossing) in summaries {
        let error =
            error.map(|e| format!("{:.1} cm", 100.0 * e)).unwrap_or_else(|| "n/a (no later measurements)".into());
        let mut line = format!("trajectory {id}: predicted from frame {from}, error {error}");
        if let Some(l) = land {
            line += &format!("; lands at ({:.3}, {:.3}) m, t = {:.3} s", l.position[0], l.position[1], l.t);
        }
        match (crossing, args.plane_y) {
            (Some((t, p)), _) => {
                line += &format!("; crosses y = {:.3} at x = {:.3}, z = {:.3} m, t = {t:.3} s", p[1], p[0], p[2])
            }
            (None, Some(y)) => line += &format!("; does not cross y = {y:.3} within the {} horizon", args.horizon),
            (None, None) => {}
        }
        say!("{line}");
    }
    say!("wrote predictions to {}", args.out.display());
    Ok(())
}
