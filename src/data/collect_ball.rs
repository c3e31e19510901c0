//! Synthetic ball recordings from the simulator, with optional rotation augmentation (thesis 6.5.1).

use rand::Rng;

use super::ball_io::{BallDataset, Recording, RecordingInfo};
use crate::envs::ball::{
    augmentation_pivot, rotate_about_z, simulate, BallTrajectory, CameraModel, LaunchParams, Orientation,
};
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::util::seeding::rng_for;

/// Shots tried per kept trajectory before giving up (a shot is kept when it bounces exactly once).
const MAX_TRIES_PER_SHOT: usize = 50;

pub struct BallCollectSettings {
    pub trajectories: usize,
    pub orientation: Orientation,
    /// Rotated copies added per trajectory (19 in the thesis' augmented training set).
    pub augment_rotations: usize,
    pub seed: u64,
    pub command_line: String,
}

fn to_recording(id: u32, t: &BallTrajectory, rotated_from: Option<(u32, f64)>) -> Recording {
    Recording {
        id,
        frames: t.frame_indices.clone(),
        positions: t.positions.clone(),
        truth: Some(t.true_states.clone()),
        info: RecordingInfo {
            side_info: Some(t.launch.side_info()),
            orientation: Some(t.launch.orientation.name()),
            launch: serde_json::to_value(&t.launch).ok(),
            impact_frame: t.impact_frame,
            rotated_from,
        },
    }
}

/// Shots from the launcher in the given orientation. Like the real recordings (whose impact detector
/// assumes one bounce), only shots with exactly one table impact are kept.
/// A shot in memory, generously: a few hundred frames of measurement, true state and bookkeeping.
const SHOT_BYTES: usize = 400 * 256;

pub fn collect_ball(settings: &BallCollectSettings, monitor: &dyn Monitor) -> Result<BallDataset> {
    if settings.trajectories == 0 {
        return Err(Error::config("--trajectories must be at least 1"));
    }
    let shots = settings.augment_rotations.saturating_add(1);
    crate::util::budget::check(
        &format!("--trajectories {} × (1 + --augment-rotations {})", settings.trajectories, settings.augment_rotations),
        crate::util::budget::times(&[settings.trajectories, shots], SHOT_BYTES),
        "collect fewer shots per file",
    )?;
    let camera = CameraModel::default();
    let mut originals = Vec::with_capacity(settings.trajectories);
    for k in 0..settings.trajectories {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        let shot = (0..MAX_TRIES_PER_SHOT)
            .map(|attempt| {
                let mut rng = rng_for(settings.seed, &[k as u64, attempt as u64]);
                let launch = LaunchParams::sample(settings.orientation, &mut rng);
                simulate(&launch, &camera, &mut rng)
            })
            .find(|t| t.impact_times.len() == 1 && t.positions.iter().filter(|p| p.is_some()).count() >= 2)
            .ok_or_else(|| Error::config("the launcher produced no single-bounce shot; check its settings"))?;
        originals.push(shot);
        monitor.progress("simulate shots", k as u64 + 1, settings.trajectories as u64);
    }
    let mut recordings: Vec<Recording> =
        originals.iter().enumerate().map(|(k, t)| to_recording(k as u32, t, None)).collect();
    let mut next_id = originals.len() as u32;
    for (k, t) in originals.iter().enumerate() {
        let mut rng = rng_for(settings.seed, &[k as u64, u64::MAX]);
        let pivot = augmentation_pivot(t);
        for _ in 0..settings.augment_rotations {
            let angle = rng.random_range(0.0..std::f64::consts::TAU);
            recordings.push(to_recording(next_id, &rotate_about_z(t, angle, pivot), Some((k as u32, angle))));
            next_id += 1;
        }
    }
    Ok(BallDataset {
        source: "simulator".into(),
        seed: settings.seed,
        command_line: settings.command_line.clone(),
        mbrl_version: crate::VERSION.into(),
        recordings,
    })
}
