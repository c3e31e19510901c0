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
