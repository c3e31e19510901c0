//! A recording through the ball EKF: filtering from the first two measurements, and predicting ahead with
//! the landing point on the table and the crossing of a vertical plane (what a robot's return stroke needs).

use serde::Serialize;

use super::{initial_belief, BallBelief, BallModel, Phase, SpinPrior, P};
use crate::data::ball_io::{Recording, FRAME_RATE};
use crate::error::{Error, Result};
use crate::filtering::{filter_belief, forecast};

/// Filtered belief per frame, from the second measurement on.
#[derive(Clone, Debug)]
pub struct Track {
    pub frames: Vec<u64>,
    pub beliefs: Vec<BallBelief>,
    /// log p(m_3:N | m_1, m_2) of the filtered part (eq. 6.24).
    pub log_likelihood: f64,
}

fn model_error(what: impl std::fmt::Display) -> Error {
    Error::data(format!("ball model: {what}"))
}

/// Filters `recording` up to and including frame `until` (all frames when `None`), starting with the given
/// spin prior (broad, or from the launcher settings).
pub fn filter_recording(
    model: &BallModel,
    recording: &Recording,
    until: Option<u64>,
    prior: &SpinPrior,
) -> Result<Track> {
    let measured: Vec<(usize, [f64; 3])> =
        recording.positions.iter().enumerate().filter_map(|(i, p)| p.map(|p| (i, p))).take(2).collect();
    let [(i1, m1), (i2, m2)] = measured[..] else {
        return Err(Error::data(format!(
            "trajectory {}: needs two measured positions to start the filter",
            recording.id
        )));
    };
    let gap = u32::try_from(recording.frames[i2] - recording.frames[i1])
        .map_err(|_| Error::data(format!("trajectory {}: first measurements too far apart", recording.id)))?;
    let start = initial_belief(model.params(), m1, m2, gap, false, prior).map_err(model_error)?;
    let last = until.unwrap_or(u64::MAX);
    // One slot per camera frame after the second measurement; frames missing from the recording are
    // dropouts too.
    let mut frames = vec![recording.frames[i2]];
    let mut slots = Vec::new();
    let mut next = recording.frames[i2] + 1;
    for (frame, position) in recording.frames.iter().zip(&recording.positions).skip(i2 + 1) {
        if *frame > last {
            break;
        }
        while next < *frame {
            slots.push(None);
            frames.push(next);
            next += 1;
        }
        slots.push(*position);
        frames.push(*frame);
        next = frame + 1;
    }
    let out = filter_belief(model, &start, &slots)
        .map_err(|e| Error::diverged(format!("trajectory {}: filter failed: {e}", recording.id)))?;
    let mut beliefs = vec![start];
    beliefs.extend(out.states.iter().zip(&out.covariances).zip(&out.modes).map(|((m, c), p)| BallBelief {
        mean: *m,
        cov: *c,
        mode: *p,
    }));
    Ok(Track { frames, beliefs, log_likelihood: out.log_likelihood })
}

/// A predicted point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PredictedPoint {
    pub frame: u64,
    pub t: f64,
    pub position: [f64; 3],
    /// Standard deviation of each position component.
    pub std: [f64; 3],
    pub after_impact: bool,
}

pub fn predict_ahead(model: &BallModel, from: &BallBelief, from_frame: u64, steps: usize) -> Vec<PredictedPoint> {
    forecast(model, from, steps)
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let frame = from_frame + k as u64 + 1;
            PredictedPoint {
                frame,
                t: frame as f64 / FRAME_RATE,
                position: [b.mean[P], b.mean[P + 1], b.mean[P + 2]],
                std: [b.cov[(0, 0)].sqrt(), b.cov[(1, 1)].sqrt(), b.cov[(2, 2)].sqrt()],
                after_impact: b.mode == Phase::AfterImpact,
            }
        })
        .collect()
}

/// Where the prediction first switches to the after-impact phase: the table landing point.
pub fn landing(points: &[PredictedPoint], before: &BallBelief) -> Option<PredictedPoint> {
    if before.mode == Phase::AfterImpact {
        return None;
    }
    points.iter().find(|p| p.after_impact).copied()
}

/// First crossing of the plane y = `plane_y`, linearly interpolated between predicted points.
pub fn plane_crossing(
    points: &[PredictedPoint],
    start: [f64; 3],
    start_t: f64,
    plane_y: f64,
) -> Option<(f64, [f64; 3])> {
    let mut prev = (start_t, start);
    for p in points {
        let (t0, a) = prev;
        let b = p.position;
        if (a[1] - plane_y) * (b[1] - plane_y) <= 0.0 && a[1] != b[1] {
            let s = (plane_y - a[1]) / (b[1] - a[1]);
            let lerp = |i: usize| a[i] + s * (b[i] - a[i]);
            return Some((t0 + s * (p.t - t0), [lerp(0), plane_y, lerp(2)]));
        }
        prev = (p.t, b);
    }
    None
}

/// Measurements a filter sees at least before predicting (thesis 6.5.2).
pub const MIN_FILTERED_MEASUREMENTS: usize = 10;
/// Prediction–measurement pairs at the end of a trajectory whose largest distance is the error (6.5.2).
pub const ERROR_PAIRS: usize = 5;

/// The frame to filter until when predicting `horizon_frames` before the end: one horizon before the
/// last frame, but never fewer than ten measurements.
pub fn protocol_cut(recording: &Recording, horizon_frames: u64) -> Option<u64> {
    let last = *recording.frames.last()?;
    let tenth = recording
        .frames
        .iter()
        .zip(&recording.positions)
        .filter(|(_, p)| p.is_some())
        .nth(MIN_FILTERED_MEASUREMENTS - 1)?
        .0;
    Some(last.saturating_sub(horizon_frames).max(*tenth))
}

/// Largest distance over the last five predicted points that have a measurement at the same frame.
pub fn prediction_error(points: &[PredictedPoint], recording: &Recording) -> Option<f64> {
    let measured: std::collections::HashMap<u64, [f64; 3]> =
        recording.frames.iter().zip(&recording.positions).filter_map(|(f, p)| p.map(|p| (*f, p))).collect();
    let pairs: Vec<f64> = points
        .iter()
        .filter_map(|p| {
            measured.get(&p.frame).map(|m| (0..3).map(|i| (p.position[i] - m[i]).powi(2)).sum::<f64>().sqrt())
        })
        .collect();
    if pairs.is_empty() {
        return None;
    }
    Some(pairs[pairs.len().saturating_sub(ERROR_PAIRS)..].iter().copied().fold(0.0, f64::max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ball_io::RecordingInfo;
    use crate::envs::ball::{simulate, CameraModel, LaunchParams, Orientation};
    use crate::models::ball::BallModelParams;
    use rand::SeedableRng;

    fn recording(seed: u64) -> Recording {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let launch = LaunchParams::sample(Orientation::Default, &mut rng);
        let t = simulate(&launch, &CameraModel::default(), &mut rng);
        Recording {
            id: 0,
            frames: t.frame_indices.clone(),
            positions: t.positions.clone(),
            truth: Some(t.true_states.clone()),
            info: RecordingInfo::default(),
        }
    }

    #[test]
    fn filtering_tracks_the_simulated_ball() {
        let model = BallModel::new(BallModelParams::thesis_learned()).unwrap();
        let rec = recording(3);
        let track = filter_recording(&model, &rec, None, &SpinPrior::Uninformed).unwrap();
        assert_eq!(*track.frames.last().unwrap(), *rec.frames.last().unwrap());
        let truth = rec.truth.as_ref().unwrap();
        let last = track.beliefs.last().unwrap();
        let true_last = truth.last().unwrap();
        let err = (0..3).map(|i| (last.mean[i] - true_last[i]).powi(2)).sum::<f64>().sqrt();
        assert!(err < 0.01, "final position error {err}");
    }

    #[test]
    fn prediction_lands_on_the_table_and_crosses_planes() {
        let model = BallModel::new(BallModelParams::thesis_learned()).unwrap();
        let rec = recording(4);
        let track = filter_recording(&model, &rec, Some(rec.frames[0] + 20), &SpinPrior::Uninformed).unwrap();
        let belief = track.beliefs.last().unwrap();
        let points = predict_ahead(&model, belief, *track.frames.last().unwrap(), 180);
        let land = landing(&points, belief).expect("the shot lands on the table");
        assert!((land.position[2] - (-0.461 + 0.02)).abs() < 0.05, "{:?}", land.position);
        let start = [belief.mean[0], belief.mean[1], belief.mean[2]];
        let (_, crossing) = plane_crossing(&points, start, 0.0, 1.0).expect("crosses y = 1");
        assert_eq!(crossing[1], 1.0);
    }
}
