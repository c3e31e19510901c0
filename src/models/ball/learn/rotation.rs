//! R_rot(φ_f + φ_l, θ_l) (6.4.3): the rotation from the canonical launch frame (launch along +x) to the world,
//! from a recording's launcher side information.

use crate::envs::ball::launcher::{head_azimuth, head_polar_angle};

/// `side_info` in the layout of `data::ball_io::SIDE_INFO_COLUMNS`: (sin, cos of the frame's rotation relative to
/// the default frame, s_φ, s_θ, s_tl, s_tr, s_b). The default frame has φ_f = −90° (thesis 6.4.3); the head
/// angles come from the same piecewise-linear regressions of s_φ, s_θ the thesis trains with (they are the
/// simulator's launcher map). R = R_z(φ_f + φ_l) · R_y(θ_l − 90°) tilts +x up by the elevation 90° − θ_l, then
/// turns it to the azimuth, as the launcher does.
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
