//! Table-tennis ball simulator: the ground truth behind synthetic data that resembles the thesis' real
//! recordings (chapter 6, thesis lines 4256-5143; /work/shared/METHODS.md §4).
//!
//! A launcher (`launcher`, `orientation`) shoots the ball; it flies under gravity, drag and the Magnus effect
//! (`flight`), bounces off the table by the learned linear impact map (`impact`, joined in `integrate`), and a
//! 180 Hz tracker measures its centre with noise and lost frames (`camera`). `augment` rotates recordings the
//! way the thesis augments its training data. All physical constants are the thesis' learned values (eq. 6.26,
//! Table C.2), so a learned EKF is judged against the model it was designed to be.

pub mod augment;
pub mod camera;
pub mod flight;
pub mod impact;
pub mod integrate;
pub mod launcher;
pub mod orientation;
mod vec3;

#[cfg(test)]
mod tests;

use rand::Rng;
use serde::{Deserialize, Serialize};

pub use augment::{augmentation_pivot, rotate_about_z};
pub use camera::CameraModel;
pub use flight::{BallState, FlightParams};
pub use impact::{ImpactModel, Table};
pub use integrate::BallPhysics;
pub use launcher::LaunchParams;
pub use orientation::Orientation;

/// One recording: what the tracker saw and what really happened, frame by frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BallTrajectory {
    /// Camera frame numbers counted from the launch (frame 0 = the ball leaves the launcher), consecutive. The
    /// recording starts with the first frame that finds the ball inside the tracked region, so the first index
    /// is 0 unless the launcher stands outside it.
    pub frame_indices: Vec<u64>,
    /// Seconds since launch of each frame (frame index / rate).
    pub times: Vec<f64>,
    /// Measured centre per frame; `None` where the frame was lost.
    pub positions: Vec<Option<[f64; 3]>>,
    /// True (p, v, ω) per frame, also for lost frames.
    pub true_states: Vec<[f64; 9]>,
    pub launch: LaunchParams,
    /// First frame at or after the first table contact (the recordings' `first_up_idx` counts the first
    /// measurement after the impact instead; here it is the true event, independent of dropouts).
    pub impact_frame: Option<u64>,
    /// Times (s since launch) of every table contact within the recording. The EKF assumes one; launcher
    /// shots give one, but a shot along the table can bounce twice, and the simulator keeps what happens.
    pub impact_times: Vec<f64>,
}

impl BallTrajectory {
    pub fn len(&self) -> usize {
        self.frame_indices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frame_indices.is_empty()
    }

    /// Seconds from the first to the last frame.
    pub fn duration(&self) -> f64 {
        match (self.times.first(), self.times.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// Share of frames without a measurement.
    pub fn dropout_fraction(&self) -> f64 {
        let lost = self.positions.iter().filter(|p| p.is_none()).count();
        lost as f64 / self.positions.len().max(1) as f64
    }
}

/// Simulates one shot with the thesis' ground-truth physics (`BallPhysics::default()`).
pub fn simulate<R: Rng + ?Sized>(launch: &LaunchParams, camera: &CameraModel, rng: &mut R) -> BallTrajectory {
    simulate_with(&BallPhysics::default(), launch, camera, rng)
}

/// Simulates one shot: frames at k / rate after the launch, recorded from the ball's first entry into the
/// camera's region until it leaves it, stops bouncing, or `camera.max_duration` has passed. A shot that never
/// enters the region gives an empty trajectory.
pub fn simulate_with<R: Rng + ?Sized>(
    physics: &BallPhysics,
    launch: &LaunchParams,
    camera: &CameraModel,
    rng: &mut R,
) -> BallTrajectory {
    let period = camera.frame_period();
    let mut state = launch.initial_state();
    let mut tracker = camera.tracker();
    let mut impact_times = Vec::new();
    let mut trajectory = BallTrajectory {
        frame_indices: Vec::new(),
        times: Vec::new(),
        positions: Vec::new(),
        true_states: Vec::new(),
        launch: launch.clone(),
        impact_frame: None,
        impact_times: Vec::new(),
    };
    for frame in 0..=camera.max_frame() {
        if frame > 0 {
            let outcome = physics.advance(&mut state, period, (frame - 1) as f64 * period, &mut impact_times);
            if outcome == integrate::Outcome::Resting {
                break;
            }
        }
        if !camera.in_bounds(&state) {
            if trajectory.is_empty() {
                continue;
            }
            break;
        }
        trajectory.frame_indices.push(frame);
        trajectory.times.push(frame as f64 * period);
        trajectory.positions.push(tracker.measure(&[state[0], state[1], state[2]], rng));
        trajectory.true_states.push(state);
    }
    let (first, last) = match (trajectory.times.first(), trajectory.times.last()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => return trajectory,
    };
    // Contacts after the last frame were never seen; one just before the first frame still shaped it.
    impact_times.retain(|&t| t > first - period && t <= last);
    // A contact inside (k−1, k] frame periods is first visible in frame k.
    trajectory.impact_frame = impact_times.first().map(|t| (t / period - 1e-9).ceil().max(0.0) as u64);
    trajectory.impact_times = impact_times;
    trajectory
}
