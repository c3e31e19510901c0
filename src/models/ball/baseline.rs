//! A black-box reference for the ball EKF: direct multi-horizon ridge regression from the last few measured
//! positions to the displacement at every future frame.
//!
//! The thesis compares its gray-box EKF with two deep latent-variable models, RSSM and TVAE (6.5.2). Both need
//! tuned training schedules, a GPU-sized budget and a reimplementation whose fidelity would be hard to vouch
//! for; their numbers would say as much about our port as about black-box modelling. This baseline is instead
//! fitted in closed form, is deterministic, and has no physical prior at all: it learns drag, spin and the
//! bounce only as far as a linear map of a short position window can express them, averaged over the training
//! shots. It is therefore a transparent lower bar for "learning from data alone", not a reproduction of the
//! thesis' baseline numbers.
//!
//! The prediction from cut frame c is p̂_{c+h} = p_c + W_hᵀ x_c with one weight matrix per horizon h (no
//! rollout, so errors do not compound), where x_c holds the window's positions relative to p_c, optionally the
//! launcher side information, and a bias. Points carry std = 0 and `after_impact = false` (the model knows of
//! neither), so `track::prediction_error` scores them exactly like the EKF's.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::track::PredictedPoint;
use crate::data::ball_io::{Recording, FRAME_RATE};
use crate::error::{Error, Result};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BaselineSettings {
    /// Frames c−window+1..c whose positions form the features.
    pub window: usize,
    /// Longest horizon with its own weights (180 frames = the thesis' 1 s protocol).
    pub horizon_frames: usize,
    /// Ridge penalty per sample on the standardized features.
    pub ridge: f64,
    /// Append the launcher's seven side-information values to the features.
    pub use_launcher_info: bool,
}

impl Default for BaselineSettings {
    fn default() -> Self {
        // The penalty only has to make collinear windows (noise-free flight, constant side information)
        // solvable: with thousands of samples per horizon, 1e-4 predicted simulated shots no better and 1e-2
        // worse.
        BaselineSettings { window: 8, horizon_frames: 180, ridge: 1e-6, use_launcher_info: false }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RidgeBaseline {
    settings: BaselineSettings,
    /// Per-feature mean and scale of the training samples, so that one ridge value fits all units.
    mean: Vec<f64>,
    scale: Vec<f64>,
    /// `weights[h − 1][j]`: displacement at horizon h per standardized feature j; the last entry is the bias.
    weights: Vec<Vec<[f64; 3]>>,
    /// Training samples (cut frames) per horizon, `samples[h − 1]`.
    samples: Vec<usize>,
}

fn bad_settings(what: impl std::fmt::Display) -> Error {
    Error::config(format!("ridge baseline: {what}"))
}

fn unusable_data(what: impl std::fmt::Display) -> Error {
    Error::data(format!("ridge baseline: {what}"))
}

/// One slot per camera frame between a recording's first and last frame, since frames absent from the
/// recording are lost frames too.
struct Timeline {
    first: u64,
    slots: Vec<Option<[f64; 3]>>,
}

impl Timeline {
    fn new(recording: &Recording) -> Option<Self> {
        let first = *recording.frames.first()?;
        let last = *recording.frames.last()?;
        let mut slots = vec![None; usize::try_from(last.checked_sub(first)?).ok()? + 1];
        for (f, p) in recording.frames.iter().zip(&recording.positions) {
            slots[usize::try_from(f.checked_sub(first)?).ok()?] = *p;
        }
        Some(Timeline { first, slots })
    }

    fn index(&self, frame: u64) -> Option<usize> {
        let i = usize::try_from(frame.checked_sub(self.first)?).ok()?;
        (i < self.slots.len()).then_some(i)
    }

    fn measured(&self, j: usize) -> bool {
        self.slots[j].is_some()
    }

    /// The line through the measurements at slots a < b, evaluated at slot j (beyond b it extrapolates).
    fn line(&self, a: usize, b: usize, j: usize) -> [f64; 3] {
        let (pa, pb) = (self.slots[a].expect("measured"), self.slots[b].expect("measured"));
        let s = (j as f64 - a as f64) / (b as f64 - a as f64);
        [0, 1, 2].map(|k| pa[k] + s * (pb[k] - pa[k]))
    }

    /// Positions at slots i−k+1..=i from measurements at or before i only: a prediction from frame c must not
    /// peek at later measurements, and training uses the same rule so that it sees what prediction will see.
    /// Lost frames between measurements are interpolated; lost frames after the last measurement (the cut
    /// frame itself is often lost) continue the line through the last two. A window without any measurement
    /// of its own, or whose gaps have no measurement before them, cannot be filled.
    fn window(&self, i: usize, k: usize) -> Option<Vec<[f64; 3]>> {
        let lo = (i + 1).checked_sub(k)?;
        let last = (lo..=i).rev().find(|&j| self.measured(j))?;
        let before = |j: usize| (0..j).rev().find(|&m| self.measured(m));
        (lo..=i)
            .map(|j| match self.slots[j] {
                Some(p) => Some(p),
                None if j < last => {
                    let next = (j + 1..=last).find(|&m| self.measured(m)).expect("last is measured");
                    Some(self.line(before(j)?, next, j))
                }
                None => Some(self.line(before(last)?, last, j)),
            })
            .collect()
    }

    /// Every slot between the first and last measurement, lost ones interpolated from both sides (targets may
    /// use the whole recording).
    fn interpolated(&self) -> Vec<Option<[f64; 3]>> {
        let mut prev = None;
        (0..self.slots.len())
            .map(|j| {
                if self.measured(j) {
                    prev = Some(j);
                    return self.slots[j];
                }
                let next = (j + 1..self.slots.len()).find(|&m| self.measured(m));
                Some(self.line(prev?, next?, j))
            })
            .collect()
    }
}

/// Raw features at slot i and the anchor p_c they are relative to. The window's last position is the anchor
/// itself, always zero, so it is left out.
fn features(
    timeline: &Timeline,
    i: usize,
    recording: &Recording,
    settings: &BaselineSettings,
) -> Option<(Vec<f64>, [f64; 3])> {
    let window = timeline.window(i, settings.window)?;
    let anchor = *window.last()?;
    let mut x: Vec<f64> = window[..window.len() - 1].iter().flat_map(|p| [0, 1, 2].map(|k| p[k] - anchor[k])).collect();
    if settings.use_launcher_info {
        x.extend(recording.info.side_info?);
    }
    Some((x, anchor))
}

fn check_settings(s: &BaselineSettings) -> Result<()> {
    if s.window < 2 {
        return Err(bad_settings(format!("window {} frames; it needs at least 2 to see a velocity", s.window)));
    }
    if s.horizon_frames == 0 {
        return Err(bad_settings("horizon_frames must be at least 1"));
    }
    if !(s.ridge.is_finite() && s.ridge >= 0.0) {
        return Err(bad_settings(format!("ridge {} must be a finite non-negative number", s.ridge)));
    }
    Ok(())
}

struct Sample {
    x: Vec<f64>,
    /// Displacement p_{c+h} − p_c for h = 1..=targets.len().
    targets: Vec<[f64; 3]>,
}

fn training_samples(recordings: &[Recording], settings: &BaselineSettings) -> Result<Vec<Sample>> {
    let mut samples = Vec::new();
    for rec in recordings {
        if settings.use_launcher_info && rec.info.side_info.is_none() {
            return Err(unusable_data(format!(
                "trajectory {} has no launcher side information, which use_launcher_info needs",
                rec.id
            )));
        }
        let Some(timeline) = Timeline::new(rec) else { continue };
        let filled = timeline.interpolated();
        let Some(last) = filled.iter().rposition(Option::is_some) else { continue };
        for i in 0..timeline.slots.len() {
            let reach = last.saturating_sub(i).min(settings.horizon_frames);
            if reach == 0 {
                break;
            }
            let Some((x, anchor)) = features(&timeline, i, rec, settings) else { continue };
            let targets = (1..=reach)
                .map(|h| {
                    let p = filled[i + h].expect("between the cut's own measurement and the last one");
                    [0, 1, 2].map(|k| p[k] - anchor[k])
                })
                .collect();
            samples.push(Sample { x, targets });
        }
    }
    Ok(samples)
}

impl RidgeBaseline {
    /// Fits one ridge regression per horizon on every cut frame of every recording that has a full window;
    /// horizon h uses the cuts whose recording is measured at least h frames further on.
    pub fn fit(recordings: &[Recording], settings: BaselineSettings) -> Result<Self> {
        check_settings(&settings)?;
        let samples = training_samples(recordings, &settings)?;
        let dim = 3 * (settings.window - 1) + if settings.use_launcher_info { 7 } else { 0 };
        let n_all = samples.len();
        let mean: Vec<f64> = (0..dim).map(|j| samples.iter().map(|s| s.x[j]).sum::<f64>() / n_all as f64).collect();
        let scale: Vec<f64> = (0..dim)
            .map(|j| {
                let var = samples.iter().map(|s| (s.x[j] - mean[j]).powi(2)).sum::<f64>() / n_all as f64;
                // A constant feature (fixed launcher orientation) standardizes to zero and so gets no weight.
                if var.sqrt() > 1e-12 * (1.0 + mean[j].abs()) {
                    var.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        let design =
            |x: &[f64]| DVector::from_iterator(dim + 1, (0..dim).map(|j| (x[j] - mean[j]) / scale[j]).chain([1.0]));

        let horizon = settings.horizon_frames;
        // Both more samples than parameters and a margin, so that a few shots cannot pass as a model.
        let needed = 2 * (dim + 1);
        let mut by_reach: Vec<Vec<DVector<f64>>> = vec![Vec::new(); horizon + 1];
        let mut xty = vec![DMatrix::<f64>::zeros(dim + 1, 3); horizon];
        for s in &samples {
            let z = design(&s.x);
            for (xty_h, y) in xty.iter_mut().zip(&s.targets) {
                for (k, &y_k) in y.iter().enumerate() {
                    xty_h.column_mut(k).axpy(y_k, &z, 1.0);
                }
            }
            by_reach[s.targets.len()].push(z);
        }

        // The samples reaching horizon h are those reaching h + 1 plus those ending at h, so the Gram matrices
        // accumulate from the longest horizon down.
        let mut gram = DMatrix::<f64>::zeros(dim + 1, dim + 1);
        let mut count = 0;
        let mut weights = vec![Vec::new(); horizon];
        let mut counts = vec![0; horizon];
        for h in (1..=horizon).rev() {
            for z in &by_reach[h] {
                gram.ger(1.0, z, z, 1.0);
            }
            count += by_reach[h].len();
            if count < needed {
                return Err(unusable_data(format!(
                    "{count} training cuts reach {h} frames ahead, fewer than the {needed} its {} weights need; \
                     give more (or longer) recordings or a shorter horizon_frames",
                    dim + 1
                )));
            }
            let mut a = gram.clone();
            for j in 0..dim {
                a[(j, j)] += settings.ridge * count as f64;
            }
            let chol = a.cholesky().ok_or_else(|| {
                unusable_data(format!(
                    "the normal equations of horizon {h} are not positive definite (constant or collinear \
                     features, such as the side information of a single launcher orientation, need ridge > 0)"
                ))
            })?;
            let w = chol.solve(&xty[h - 1]);
            weights[h - 1] = (0..=dim).map(|j| [w[(j, 0)], w[(j, 1)], w[(j, 2)]]).collect();
            counts[h - 1] = count;
        }
        Ok(RidgeBaseline { settings, mean, scale, weights, samples: counts })
    }

    pub fn settings(&self) -> &BaselineSettings {
        &self.settings
    }

    /// Training cuts that had a target `h` frames ahead (`h` in 1..=horizon_frames).
    pub fn training_samples(&self, h: usize) -> Option<usize> {
        self.samples.get(h.checked_sub(1)?).copied()
    }

    /// Predicted positions at frames cut+1..=cut+steps from the measurements up to `cut_frame`; `None` when
    /// `steps` exceeds the trained horizon, the cut frame is not in the recording, its window cannot be filled,
    /// or the model wants launcher information the recording lacks.
    pub fn predict(&self, recording: &Recording, cut_frame: u64, steps: usize) -> Option<Vec<PredictedPoint>> {
        if steps > self.weights.len() {
            return None;
        }
        let timeline = Timeline::new(recording)?;
        let (x, anchor) = features(&timeline, timeline.index(cut_frame)?, recording, &self.settings)?;
        let z: Vec<f64> = x.iter().zip(self.mean.iter().zip(&self.scale)).map(|(v, (m, s))| (v - m) / s).collect();
        let points = self.weights[..steps]
            .iter()
            .enumerate()
            .map(|(h, w)| {
                let (bias, per_feature) = w.split_last().expect("bias");
                let position = [0, 1, 2]
                    .map(|k| anchor[k] + bias[k] + per_feature.iter().zip(&z).map(|(wj, zj)| wj[k] * zj).sum::<f64>());
                let frame = cut_frame + h as u64 + 1;
                PredictedPoint { frame, t: frame as f64 / FRAME_RATE, position, std: [0.0; 3], after_impact: false }
            })
            .collect();
        Some(points)
    }

    /// The thesis' protocol error (6.5.2) for one recording: cut `horizon_frames` before its end (at least ten
    /// measurements in), predict to the end, take the largest of the last five prediction-measurement distances.
    pub fn protocol_error(&self, recording: &Recording, horizon_frames: u64) -> Option<f64> {
        let cut = super::track::protocol_cut(recording, horizon_frames)?;
        let steps = usize::try_from(recording.frames.last()? - cut).ok()?;
        super::track::prediction_error(&self.predict(recording, cut, steps)?, recording)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ball_io::RecordingInfo;
    use crate::envs::ball::{simulate, CameraModel, LaunchParams, Orientation};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Noise-free gravity-only flights of 1.5 s with random start and velocity; every `lose_every`-th frame lost.
    fn parabolas(n: usize, seed: u64, lose_every: Option<usize>) -> Vec<Recording> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|id| {
                let p0: [f64; 3] = [0, 1, 2].map(|_| rng.random_range(-1.0..1.0));
                let v0 = [rng.random_range(-1.0..1.0), rng.random_range(-6.0..-3.0), rng.random_range(0.0..3.0)];
                let frames: Vec<u64> = (0..270).collect();
                let positions = frames
                    .iter()
                    .map(|&f| {
                        let t = f as f64 / FRAME_RATE;
                        let lost = lose_every.is_some_and(|m| f as usize % m == m - 1);
                        let p = [0, 1, 2].map(|k| p0[k] + v0[k] * t - if k == 2 { 0.5 * 9.81 * t * t } else { 0.0 });
                        (!lost).then_some(p)
                    })
                    .collect();
                Recording { id: id as u32, frames, positions, truth: None, info: RecordingInfo::default() }
            })
            .collect()
    }

    /// Default-orientation shots with one bounce, as `collect_ball` keeps them.
    fn shots(n: usize, seed: u64) -> Vec<Recording> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let camera = CameraModel::default();
        let mut out = Vec::new();
        while out.len() < n {
            let launch = LaunchParams::sample(Orientation::Default, &mut rng);
            let t = simulate(&launch, &camera, &mut rng);
            if t.impact_times.len() != 1 || t.positions.iter().flatten().count() < 20 {
                continue;
            }
            out.push(Recording {
                id: out.len() as u32,
                frames: t.frame_indices,
                positions: t.positions,
                truth: None,
                info: RecordingInfo { side_info: Some(t.launch.side_info()), ..Default::default() },
            });
        }
        out
    }

    fn median_protocol_error(model: &RidgeBaseline, test: &[Recording]) -> f64 {
        let mut errors: Vec<f64> = test.iter().filter_map(|r| model.protocol_error(r, 180)).collect();
        // A burst of lost frames right at the cut may leave a window without a measurement, but rarely.
        assert!(errors.len() * 10 >= test.len() * 9, "{} of {} shots predicted", errors.len(), test.len());
        errors.sort_by(f64::total_cmp);
        errors[errors.len() / 2]
    }

    #[test]
    fn ballistic_flight_is_predicted_almost_exactly() {
        let model = RidgeBaseline::fit(&parabolas(12, 1, None), BaselineSettings::default()).unwrap();
        let test = parabolas(5, 2, None);
        let worst = test.iter().map(|r| model.protocol_error(r, 180).unwrap()).fold(0.0, f64::max);
        assert!(worst < 1e-4, "1 s error on exact parabolas {worst}");
        // Straight lines through gaps miss a parabola by up to g·dt² ≈ 0.3 mm (an extrapolated cut frame), and the
        // weights read such offsets as velocity errors that grow over the second: millimetres remain.
        let model = RidgeBaseline::fit(&parabolas(12, 1, Some(7)), BaselineSettings::default()).unwrap();
        let test = parabolas(5, 2, Some(5));
        let worst = test.iter().map(|r| model.protocol_error(r, 180).unwrap()).fold(0.0, f64::max);
        assert!(worst < 1e-2, "1 s error on parabolas with lost frames {worst}");
    }

    #[test]
    fn predictions_start_after_the_cut_and_need_a_measured_window() {
        let model = RidgeBaseline::fit(&parabolas(12, 1, None), BaselineSettings::default()).unwrap();
        let mut rec = parabolas(1, 3, None).remove(0);
        let points = model.predict(&rec, 40, 180).unwrap();
        assert_eq!((points.len(), points[0].frame, points[179].frame), (180, 41, 220));
        assert!(points.iter().all(|p| p.std == [0.0; 3] && !p.after_impact));
        assert!(model.predict(&rec, 40, 181).is_none(), "beyond the trained horizon");
        assert!(model.predict(&rec, 6, 10).is_none(), "a window before the recording's start");
        assert!(model.predict(&rec, 500, 10).is_none(), "a cut after the recording");
        // Measurements after the cut must not matter, also when the cut frame itself is lost and has to be
        // extrapolated.
        for lose_cut in [false, true] {
            let mut later = rec.clone();
            later.positions[40] = later.positions[40].filter(|_| !lose_cut);
            let before = model.predict(&later, 40, 180).unwrap();
            for p in later.positions[41..].iter_mut().flatten() {
                p[2] += 1.0;
            }
            assert_eq!(model.predict(&later, 40, 180).unwrap(), before);
        }
        for p in &mut rec.positions[33..=40] {
            *p = None;
        }
        assert!(model.predict(&rec, 40, 10).is_none(), "a window without a measurement of its own");
    }

    #[test]
    fn simulated_shots_are_predicted_within_a_loose_bound() {
        let (train, test) = (shots(40, 10), shots(20, 11));
        for use_launcher_info in [false, true] {
            let settings = BaselineSettings { use_launcher_info, ..Default::default() };
            let model = RidgeBaseline::fit(&train, settings).unwrap();
            let median = median_protocol_error(&model, &test);
            eprintln!("ridge baseline, launcher info {use_launcher_info}: median 1 s protocol error {median:.3} m");
            assert!(median.is_finite() && median < 0.5, "{median}");
        }
    }

    #[test]
    fn launcher_information_changes_the_prediction() {
        let train = shots(40, 10);
        let test = &shots(1, 12)[0];
        let cut = test.frames[15];
        let plain = RidgeBaseline::fit(&train, BaselineSettings::default()).unwrap();
        let settings = BaselineSettings { use_launcher_info: true, ..Default::default() };
        let informed = RidgeBaseline::fit(&train, settings.clone()).unwrap();
        let end = |m: &RidgeBaseline, r: &Recording| m.predict(r, cut, 180).unwrap()[179].position;
        let gap = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
        assert!(gap(end(&plain, test), end(&informed, test)) > 1e-4);
        let mut other = test.clone();
        other.info.side_info.as_mut().unwrap()[4] += 0.03;
        assert!(gap(end(&informed, test), end(&informed, &other)) > 1e-4);
        other.info.side_info = None;
        assert!(informed.predict(&other, cut, 10).is_none());
        assert!(plain.predict(&other, cut, 10).is_some());
        let err = RidgeBaseline::fit(&[other], settings).unwrap_err().to_string();
        assert!(err.contains("side information"), "{err}");
    }

    #[test]
    fn a_saved_model_predicts_the_same() {
        let model = RidgeBaseline::fit(&parabolas(12, 1, Some(9)), BaselineSettings::default()).unwrap();
        let json = serde_json::to_string(&model).unwrap();
        let back: RidgeBaseline = serde_json::from_str(&json).unwrap();
        assert_eq!(back.settings(), model.settings());
        let rec = &parabolas(1, 4, None)[0];
        let (a, b) = (back.predict(rec, 50, 100).unwrap(), model.predict(rec, 50, 100).unwrap());
        // JSON may round the last bit of a float.
        let worst = a.iter().zip(&b).flat_map(|(p, q)| (0..3).map(|k| (p.position[k] - q.position[k]).abs()));
        assert!(worst.fold(0.0, f64::max) < 1e-12);
    }

    #[test]
    fn too_little_data_is_an_error() {
        for recordings in [Vec::new(), parabolas(1, 5, None)[..1].to_vec()] {
            let mut short = recordings.clone();
            for r in &mut short {
                r.frames.truncate(200);
                r.positions.truncate(200);
            }
            let err = RidgeBaseline::fit(&short, BaselineSettings::default()).unwrap_err().to_string();
            assert!(err.contains("training cuts reach 180 frames ahead"), "{err}");
        }
        let err = RidgeBaseline::fit(&parabolas(2, 5, None), BaselineSettings { window: 1, ..Default::default() })
            .unwrap_err()
            .to_string();
        assert!(err.contains("window 1"), "{err}");
    }
}
