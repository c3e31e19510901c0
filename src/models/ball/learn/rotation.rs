//! R_rot(φ_f + φ_l, θ_l) (6.4.3): the rotation from the canonical launch frame (launch along +x) to the world,
//! from a recording's launcher side information.

/// `launcher_phi_to_angle` of the authors' ball_model/data/rotations.py: total azimuth in the default frame (deg)
/// = slope · s_φ + intercept.
const PHI_SLOPE_DEG: f64 = -56.08558569861544;
const PHI_INTERCEPT_DEG: f64 = -60.094624032259446;

/// `launcher_theta_to_angle` of rotations.py: polar angle of the launch direction from +z (deg), linear below
/// the switch point and constant above it.
const THETA_SWITCH: f64 = 0.8740863280312021;
const THETA_SLOPE_DEG: f64 = -32.82521212632685;
const THETA_INTERCEPT_DEG: f64 = 81.98843931100635;
const THETA_HIGH_DEG: f64 = 53.29637017666002;

/// `side_info` in the layout of `data::ball_io::SIDE_INFO_COLUMNS`: (sin, cos of the frame's rotation relative to
/// the default frame, s_φ, s_θ, s_tl, s_tr, s_b). The default frame has φ_f = −90° (thesis 6.4.3); the head
/// angles come from the same piecewise-linear regressions of s_φ, s_θ the thesis trains with (the model's own copy
/// of the simulator's launcher map; a test holds them equal). R = R_z(φ_f + φ_l) · R_y(θ_l − 90°) tilts +x up by
/// the elevation 90° − θ_l, then turns it to the azimuth, as the launcher does.
pub fn launch_rotation(side_info: &[f64; 7]) -> [[f64; 3]; 3] {
    let frame_yaw = side_info[0].atan2(side_info[1]) - std::f64::consts::FRAC_PI_2;
    let azimuth = frame_yaw + head_azimuth(side_info[2]);
    let tilt = head_polar_angle(side_info[3]) - std::f64::consts::FRAC_PI_2;
    let (sz, cz) = azimuth.sin_cos();
    let (sy, cy) = tilt.sin_cos();
    let rz = [[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]];
    let ry = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]];
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| rz[i][k] * ry[k][j]).sum()))
}

/// The side information as it is known when a shot is predicted (thesis 6.4.3): the launcher's settings,
/// but the frame's yaw inferred from the direction between the first two measured positions, since a
/// launcher moved to an unseen pose does not report where it stands. `None` without side information or
/// two distinct measurements.
pub fn observed_side_info(recording: &crate::data::ball_io::Recording) -> Option<[f64; 7]> {
    let mut side_info = recording.info.side_info?;
    let mut measured = recording.positions.iter().flatten();
    let (first, second) = (measured.next()?, measured.next()?);
    let (dx, dy) = (second[0] - first[0], second[1] - first[1]);
    if dx.hypot(dy) == 0.0 {
        return None;
    }
    // The launch direction's azimuth is the frame's yaw plus the head's own azimuth; the default frame's
    // yaw (−90°) is stored as angle 0.
    let frame_yaw = dy.atan2(dx) - head_azimuth(side_info[2]);
    let (sin, cos) = (frame_yaw + std::f64::consts::FRAC_PI_2).sin_cos();
    side_info[0] = sin;
    side_info[1] = cos;
    Some(side_info)
}

/// The motor actuations s_m = (s_tl, s_tr, s_b), the spin network's input.
pub fn motor_actuations(side_info: &[f64; 7]) -> [f64; 3] {
    [side_info[4], side_info[5], side_info[6]]
}

/// Head azimuth φ_l (rad) relative to the launcher frame; the default frame's −90° is taken off.
fn head_azimuth(s_phi: f64) -> f64 {
    (PHI_SLOPE_DEG * s_phi + PHI_INTERCEPT_DEG + 90.0).to_radians()
}

/// Polar angle θ_l (rad) of the launch direction, measured from +z.
fn head_polar_angle(s_theta: f64) -> f64 {
    let deg = if s_theta < THETA_SWITCH { THETA_SLOPE_DEG * s_theta + THETA_INTERCEPT_DEG } else { THETA_HIGH_DEG };
    deg.to_radians()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::ball::launcher;

    /// On simulated shots of every pose the yaw read off the first two measurements lands within a few
    /// degrees of the launcher's true one (measurement noise ≈ 1 mm over a ≈ 2 cm step).
    #[test]
    fn the_frame_yaw_is_recovered_from_the_first_two_measurements() {
        use crate::envs::ball::Orientation;
        let mut worst: f64 = 0.0;
        let mut errors = Vec::new();
        for (k, orientation) in
            [Orientation::Default, Orientation::Unseen(2), Orientation::Unseen(5)].into_iter().enumerate()
        {
            let settings = crate::data::collect_ball::BallCollectSettings {
                trajectories: 8,
                orientation,
                augment_rotations: 0,
                seed: 11 + k as u64,
                command_line: String::new(),
            };
            let shots =
                crate::data::collect_ball::collect_ball(&settings, &crate::run::NullMonitor).unwrap().recordings;
            for shot in &shots {
                let truth = shot.info.side_info.unwrap();
                let seen = observed_side_info(shot).unwrap();
                let error = (seen[0].atan2(seen[1]) - truth[0].atan2(truth[1]) + std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                worst = worst.max(error.abs());
                errors.push(error);
                assert_eq!(&seen[2..], &truth[2..]);
            }
        }
        // Unbiased: the errors are the measurement noise, not a wrong angle convention (which would be off by
        // tens of degrees on every shot).
        let bias = errors.iter().sum::<f64>() / errors.len() as f64;
        assert!(bias.to_degrees().abs() < 3.0, "mean yaw error {:.1}°", bias.to_degrees());
        assert!(worst.to_degrees() < 20.0, "worst yaw error {:.1}°", worst.to_degrees());
    }

    /// Model and simulator describe the same launcher, so the copies must agree, on both sides of the θ switch.
    #[test]
    fn head_angles_match_the_simulators_launcher() {
        for i in 0..=100 {
            let s = i as f64 / 100.0;
            assert_eq!(head_azimuth(s), launcher::head_azimuth(s), "s_phi = {s}");
            assert_eq!(head_polar_angle(s), launcher::head_polar_angle(s), "s_theta = {s}");
        }
    }
}
