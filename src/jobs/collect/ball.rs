//! Simulated table-tennis shots seen by the camera (thesis 6.5.1), with rotated copies for training.

use std::path::PathBuf;

use super::{CollectOptions, CollectSummary};
use crate::data::ball_io::write_ball_dataset;
use crate::data::collect_ball::{collect_ball, BallCollectSettings};
use crate::envs::ball::Orientation;
use crate::jobs::{output_file, Invocation, Job};
use crate::Result;

pub(super) fn prepare(
    trajectories: usize,
    options: CollectOptions,
    invocation: &Invocation,
) -> Result<Job<'static, CollectSummary>> {
    let orientation = Orientation::parse(&options.orientation)?;
    let default = || PathBuf::from(format!("datasets/ball-{}.mcap", orientation.name()));
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    let settings = BallCollectSettings {
        trajectories,
        orientation,
        augment_rotations: options.augment_rotations,
        seed: invocation.seed,
        command_line: invocation.command_line.clone(),
    };
    Ok(Job::new("collect ball shots", move |monitor| {
        let data = collect_ball(&settings, monitor)?;
        write_ball_dataset(&out, &data)?;
        Ok(CollectSummary::Ball {
            trajectories: data.recordings.len(),
            shots: trajectories,
            orientation: orientation.name(),
            frames: data.recordings.iter().map(|r| r.frames.len()).sum(),
            out,
        })
    }))
}
