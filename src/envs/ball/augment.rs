//! Rotation augmentation (thesis lines 4812-4816; ball_model/data/generate_augmented.py): a recorded
//! trajectory is turned about the vertical axis through its lowest measured point, which pretends the launcher
//! stood elsewhere. Turning about the lowest point (the bounce) keeps the bounce where it was, so the rotated
//! ball still hits the table; gravity is unchanged by a rotation about z, so the rotated trajectory is as
//! physical as the original apart from the table edges. The thesis draws the angle from [0, 2π] and adds 19
//! rotated copies per training trajectory.

use super::vec3::{add, rotate_z, sub, Vec3};
use super::BallTrajectory;

/// The pivot the thesis rotates about: the measurement with the smallest z (as `rotate_single` takes
/// `argmin` over the measured positions). Falls back to the true states if every frame was lost.
pub fn augmentation_pivot(trajectory: &BallTrajectory) -> Vec3 {
    let lowest = |points: &mut dyn Iterator<Item = Vec3>| points.min_by(|a, b| a[2].total_cmp(&b[2]));
    lowest(&mut trajectory.positions.iter().flatten().copied())
        .or_else(|| lowest(&mut trajectory.true_states.iter().map(|s| [s[0], s[1], s[2]])))
        .unwrap_or([0.0; 3])
}

/// A copy of `trajectory` turned counter-clockwise by `angle` (rad) about the vertical axis through `pivot`:
/// measured and true positions, true velocities and spins, and the launch parameters (exit point, frame yaw,
/// azimuth, spin). Frame indices, times, dropouts and impact frames are unchanged.
pub fn rotate_about_z(trajectory: &BallTrajectory, angle: f64, pivot: Vec3) -> BallTrajectory {
    let turn_point = |p: &Vec3| {
        let q = add(&pivot, &rotate_z(&sub(p, &pivot), angle));
        // Heights are untouched by a turn about z; keeping them bit-exact keeps the lowest point the lowest.
        [q[0], q[1], p[2]]
    };
    let true_states = trajectory
        .true_states
        .iter()
        .map(|s| {
            let p = turn_point(&[s[0], s[1], s[2]]);
            let v = rotate_z(&[s[3], s[4], s[5]], angle);
            let w = rotate_z(&[s[6], s[7], s[8]], angle);
            [p[0], p[1], p[2], v[0], v[1], v[2], w[0], w[1], w[2]]
        })
        .collect();
    BallTrajectory {
        positions: trajectory.positions.iter().map(|m| m.as_ref().map(turn_point)).collect(),
        true_states,
        launch: trajectory.launch.rotated_about_z(angle, &pivot),
        ..trajectory.clone()
    }
}
