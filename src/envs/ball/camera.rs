//! The vision tracking system: 180 Hz position measurements of the ball's centre with Gaussian noise and
//! missing frames (thesis lines 4589-4592 for the rate, 4633-4638 for noise and "occasionally" missing
//! measurements).
//!
//! Noise: the learned measurement variance `[σ_r]⊕` of Table C.2 (thesis line 6729) is (1.02, 1.03, 1.00)·10⁻⁶ m²,
//! i.e. a standard deviation of ≈ 1.0 mm per axis. That value sits at the softplus floor of 10⁻⁶, so the real
//! noise may be somewhat larger (the learned initial velocity variance ≈ 0.1 m²/s² of the same table fits
//! finite differences of ≈ 1.4 mm noise); the default keeps the table's value, which makes data from this
//! simulator yield the same learned R.
//!
//! Dropouts: the thesis quantifies neither their rate nor their pattern. Occlusions and failed detections
//! come both singly and in runs, so each frame is lost independently with `dropout_prob` (5 %), and with
//! `burst_prob` (0.5 %) a run of `burst_len.0 ..= burst_len.1` (2-6) consecutive frames starts. The first
//! frame of a recording is always observed: a recording begins when the tracker first sees the ball. Missing
//! frames stay in the trajectory as `None`, so frame indices keep the gaps visible as in the recordings'
//! `frame_indices`.
//!
//! The tracker covers a region around the table (`bounds_min ..= bounds_max`): a recording holds the frames
//! from the ball's first entry into it until it leaves it, or until `max_duration` after the launch. The
//! default region is the table rectangle grown by 0.5 m in x and 0.25 m in y, from 0.3 m below to 2.5 m above
//! the table plane. With it, launcher shots end where the recordings in the authors' plots end
//! (ball_model/data/notebooks/graphics/visualization_lp7.png, lp91-95.png): near the table's far end line,
//! about 1.1-1.25 s after launch (the longest recording has 235 frames ≈ 1.3 s, thesis line 4840). The 2 s
//! cap only matters for unusual shots.

use rand::Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use super::impact::{TABLE_CENTER, TABLE_LENGTH, TABLE_WIDTH};
use super::vec3::Vec3;

/// Camera trigger rate in Hz (thesis lines 4591-4592).
pub const FRAME_RATE: f64 = 180.0;

/// Learned measurement variances of Table C.2 in m² (thesis line 6729).
pub const LEARNED_MEASUREMENT_VARIANCE: Vec3 = [1.02e-6, 1.03e-6, 1.00e-6];

/// Margins of the tracked region around the table (m): sideways (x), along the table (y), below the plane.
const BOUNDS_MARGIN_X: f64 = 0.5;
const BOUNDS_MARGIN_Y: f64 = 0.25;
const BOUNDS_BELOW: f64 = 0.3;
const BOUNDS_ABOVE: f64 = 2.5;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraModel {
    pub rate_hz: f64,
    /// Per-axis standard deviation of the position noise (m).
    pub noise_std: Vec3,
    /// Probability that a frame is lost on its own.
    pub dropout_prob: f64,
    /// Probability per frame that a run of lost frames starts.
    pub burst_prob: f64,
    /// Shortest and longest run length (frames).
    pub burst_len: (u32, u32),
    /// Longest recording (s).
    pub max_duration: f64,
    pub bounds_min: Vec3,
    pub bounds_max: Vec3,
}

impl Default for CameraModel {
    fn default() -> Self {
        let c = TABLE_CENTER;
        let (half_x, half_y) = (0.5 * TABLE_WIDTH + BOUNDS_MARGIN_X, 0.5 * TABLE_LENGTH + BOUNDS_MARGIN_Y);
        CameraModel {
            rate_hz: FRAME_RATE,
            noise_std: LEARNED_MEASUREMENT_VARIANCE.map(f64::sqrt),
            dropout_prob: 0.05,
            burst_prob: 0.005,
            burst_len: (2, 6),
            max_duration: 2.0,
            bounds_min: [c[0] - half_x, c[1] - half_y, c[2] - BOUNDS_BELOW],
            bounds_max: [c[0] + half_x, c[1] + half_y, c[2] + BOUNDS_ABOVE],
        }
    }
}

impl CameraModel {
    /// A noiseless camera that never drops a frame (for tests and ground-truth plots).
    pub fn perfect() -> Self {
        CameraModel { noise_std: [0.0; 3], dropout_prob: 0.0, burst_prob: 0.0, ..CameraModel::default() }
    }

    pub fn frame_period(&self) -> f64 {
        1.0 / self.rate_hz
    }

    /// Index of the last frame a recording may have.
    pub fn max_frame(&self) -> u64 {
        (self.max_duration * self.rate_hz + 1e-9).floor() as u64
    }

    pub fn in_bounds(&self, p: &[f64]) -> bool {
        (0..3).all(|i| p[i] >= self.bounds_min[i] && p[i] <= self.bounds_max[i])
    }

    /// Starts the dropout process of one recording.
    pub fn tracker(&self) -> Tracker<'_> {
        Tracker { camera: self, burst_left: 0, frames_seen: 0 }
    }
}

/// The per-recording state of the dropout process (a run of lost frames spans several calls).
pub struct Tracker<'a> {
    camera: &'a CameraModel,
    burst_left: u32,
    frames_seen: u64,
}

impl Tracker<'_> {
    /// Whether the next frame is observed.
    pub fn next_observed<R: Rng + ?Sized>(&mut self, rng: &mut R) -> bool {
        let first = self.frames_seen == 0;
        self.frames_seen += 1;
        if first {
            return true;
        }
        if self.burst_left > 0 {
            self.burst_left -= 1;
            return false;
        }
        let cam = self.camera;
        if cam.burst_prob > 0.0 && rng.random_bool(cam.burst_prob.min(1.0)) {
            let (lo, hi) = cam.burst_len;
            self.burst_left = rng.random_range(lo.max(1)..=hi.max(lo.max(1))) - 1;
            return false;
        }
        !(cam.dropout_prob > 0.0 && rng.random_bool(cam.dropout_prob.min(1.0)))
    }

    /// The next frame's measurement of the true centre `p`, or `None` if the frame is lost.
    pub fn measure<R: Rng + ?Sized>(&mut self, p: &Vec3, rng: &mut R) -> Option<Vec3> {
        if !self.next_observed(rng) {
            return None;
        }
        let std = self.camera.noise_std;
        Some(std::array::from_fn(|i| p[i] + std[i] * rng.sample::<f64, _>(StandardNormal)))
    }
}
