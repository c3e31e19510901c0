//! Simulated recordings for the learning tests.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::data::ball_io::{Recording, RecordingInfo};
use crate::envs::ball::{simulate, CameraModel, LaunchParams, Orientation};

/// `n` recordings of default-orientation launcher shots with the default camera (noise, dropouts). Shots that
/// bounce twice are dropped: the model allows one impact per trajectory, as the recordings had.
pub fn recordings(n: usize, seed: u64) -> Vec<Recording> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let camera = CameraModel::default();
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let launch = LaunchParams::sample(Orientation::Default, &mut rng);
        let shot = simulate(&launch, &camera, &mut rng);
        if shot.impact_times.len() != 1 || shot.len() < 80 {
            continue;
        }
        out.push(Recording {
            id: out.len() as u32,
            frames: shot.frame_indices.clone(),
            positions: shot.positions.clone(),
            truth: None,
            info: RecordingInfo {
                side_info: Some(launch.side_info()),
                orientation: Some("default".into()),
                impact_frame: shot.impact_frame,
                ..RecordingInfo::default()
            },
        });
    }
    out
}
