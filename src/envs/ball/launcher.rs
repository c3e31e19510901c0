//! The three-wheel ball launcher (thesis section 6.5.1, lines 4775-4815; design of Dittrich et al. 2022):
//! actuations s_m = (s_tl, s_tr, s_b) ∈ [0, 1]³ set the top-left, top-right and bottom wheel speeds, s_φ and
//! s_θ aim the head, and the frame stands at a pose with yaw φ_f (see `orientation`).
//!
//! Chain of maps, each from the thesis or the authors' code:
//! 1. actuation → wheel RPM: the measured motor curve `v2_offset` of ball_model/data/motors.py (Figure 6.3,
//!    right), interpolated piecewise linearly.
//! 2. wheel RPM → canonical spin (launch along +x): eq. 6.25 (thesis lines 4955-4975), every wheel adding a
//!    spin along its own axis scaled by α, β, γ. The factors are those the authors fitted to their learned
//!    spin network (ball_model/evaluation/notebooks/spin_evaluation.ipynb, printed output), so the spin is
//!    in the learned model's units that go with k_m = 0.05 (see `flight::K_M`).
//! 3. wheel speeds → launch speed: with three wheels gripping the ball without slip, the centre leaves at the
//!    mean rim speed; the spin comes from the wheels' differences (item 2). Wheel radius times grip
//!    efficiency is one effective radius, calibrated (see `EFFECTIVE_RIM_RADIUS`).
//! 4. s_φ, s_θ → head angles: the regressions of ball_model/data/rotations.py (Figure 6.3, left panels).
//!    φ_l is the azimuth relative to the frame; θ_l is the polar angle of the launch direction from +z.
//! 5. world direction and spin: R = R_z(φ_f + φ_l) · R_y(θ_l − 90°) applied to +x and to the canonical spin,
//!    as `build_launcher_rot_mat` and `build_aug_rot_mat` in rotations.py / ekf_cell.py compose them.
//!
//! A real launcher does not repeat a shot exactly, and the EKF only ever sees the actuations, so every sampled
//! shot scatters around the nominal map (the `*_JITTER` constants; the thesis does not quantify the scatter of
//! Figure 6.3, so these are assumptions of a fraction of a degree and a few percent).

use rand::Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use super::flight::BallState;
use super::orientation::Orientation;
use super::vec3::{add, rotate_y, rotate_z, scale, sub, wrap_angle, Vec3};

/// Actuation grid of the `v2_offset` motor curve (ball_model/data/motors.py).
const ACTUATION_GRID: [f64; 20] = [
    0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65, 0.70, 0.75, 0.80, 0.85, 0.90, 0.95,
    1.00,
];

/// Wheel RPM on that grid for the top-left, top-right and bottom motor (`rpm_tl`, `rpm_tr`, `rpm_bc`).
const RPM_CURVES: [[f64; 20]; 3] = [
    [
        297.0, 896.0, 1316.0, 1726.0, 2180.0, 2445.0, 2735.0, 3005.0, 3178.0, 3337.0, 3508.0, 3654.0, 3826.0, 3856.0,
        3917.0, 4123.0, 4337.0, 4575.0, 4614.0, 4615.0,
    ],
    [
        0.0, 476.0, 955.0, 1385.0, 1864.0, 2207.0, 2457.0, 2716.0, 2975.0, 3150.0, 3332.0, 3518.0, 3642.0, 3739.0,
        3851.0, 3960.0, 4060.0, 4198.0, 4433.0, 4596.0,
    ],
    [
        0.0, 517.0, 1077.0, 1594.0, 2055.0, 2515.0, 2851.0, 3091.0, 3387.0, 3572.0, 3757.0, 3930.0, 4060.0, 4278.0,
        4535.0, 4816.0, 4959.0, 4960.0, 4961.0, 4962.0,
    ],
];

/// α, β, γ of eq. 6.25 (learned spin units per RPM) for the top-left, top-right and bottom wheel: the values
/// printed by the authors' spin_evaluation.ipynb ("tensor([0.0071]) … tensor([0.0066]) … tensor([0.0079])").
pub const SPIN_FACTORS: [f64; 3] = [0.0071, 0.0066, 0.0079];

/// Spin axis each wheel adds, for a launch along +x. Eq. 6.25 gives them for a launch along −y:
/// tl (1/2, 0, −√3/2), tr (1/2, 0, √3/2), b (−1, 0, 0); rotating by +90° about z gives these. The bottom wheel
/// thus adds backspin (ω along −y for flight along +x lifts the ball), the top wheels topspin plus side spin.
const SPIN_AXES: [Vec3; 3] =
    [[0.0, 0.5, -0.866_025_403_784_438_6], [0.0, 0.5, 0.866_025_403_784_438_6], [0.0, -1.0, 0.0]];

/// `launcher_phi_to_angle` of ball_model/data/rotations.py: total azimuth in the default frame (deg) =
/// slope · s_φ + intercept. The default frame's −90° is subtracted to get φ_l.
const PHI_SLOPE_DEG: f64 = -56.08558569861544;
const PHI_INTERCEPT_DEG: f64 = -60.094624032259446;

/// `launcher_theta_to_angle` of rotations.py: polar angle of the launch direction from +z (deg), linear below
/// the switch point and constant above it (the head reaches its stop).
const THETA_SWITCH: f64 = 0.8740863280312021;
const THETA_SLOPE_DEG: f64 = -32.82521212632685;
const THETA_INTERCEPT_DEG: f64 = 81.98843931100635;
const THETA_HIGH_DEG: f64 = 53.29637017666002;

/// Head actuation ranges of the recordings (thesis line 4811).
pub const S_PHI_RANGE: (f64, f64) = (0.4, 0.6);
pub const S_THETA_RANGE: (f64, f64) = (0.7, 1.0);

/// Wheel radius × grip efficiency (m). Neither the thesis nor the authors' code gives the wheel size, so this
/// is calibrated: default shots at mid settings (mean wheel speed ≈ 120 rad/s) leave at ≈ 4.8 m/s and then
/// match the authors' plot of the default recordings (visualization_lp7.png): apex ≈ 0.4 m above the start
/// after ≈ 0.28 s, bounce after ≈ 0.68 s, second apex just above the start height after ≈ 1 s, and the near
/// end of the table after ≈ 1.15 s. Over the sampled actuation ranges about 80 % of shots bounce exactly once
/// inside the tracked region; the slowest ones bounce a second time near the table's end, the fastest overshoot
/// it (the linear wheel model spreads launch speeds by ±20 %; the recordings, whose impact detector asserts one
/// bounce, evidently did not contain such shots).
pub const EFFECTIVE_RIM_RADIUS: f64 = 0.040;

/// Shot-to-shot scatter (assumed, see module docs): standard deviations of the launch azimuth and elevation
/// (deg), and relative standard deviations of the launch speed and of the spin magnitude.
pub const AZIMUTH_JITTER_DEG: f64 = 0.5;
pub const ELEVATION_JITTER_DEG: f64 = 0.5;
pub const SPEED_JITTER: f64 = 0.01;
pub const SPIN_JITTER: f64 = 0.05;

/// Wheel RPM of (tl, tr, b) for actuations s_m. Actuations are clamped to the measured curve's [0.05, 1].
pub fn wheel_rpm(s_m: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| interpolate(&ACTUATION_GRID, &RPM_CURVES[i], s_m[i]))
}

fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let x = x.clamp(xs[0], xs[xs.len() - 1]);
    let i = xs.partition_point(|&g| g <= x).clamp(1, xs.len() - 1);
    let w = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
    ys[i - 1] + w * (ys[i] - ys[i - 1])
}

/// Head azimuth φ_l (rad) relative to the launcher frame.
pub fn head_azimuth(s_phi: f64) -> f64 {
    (PHI_SLOPE_DEG * s_phi + PHI_INTERCEPT_DEG + 90.0).to_radians()
}

/// Polar angle θ_l (rad) of the launch direction, measured from +z (elevation = 90° − θ_l).
pub fn head_polar_angle(s_theta: f64) -> f64 {
    let deg = if s_theta < THETA_SWITCH { THETA_SLOPE_DEG * s_theta + THETA_INTERCEPT_DEG } else { THETA_HIGH_DEG };
    deg.to_radians()
}

/// Spin (eq. 6.25) for a launch along +x from the wheels' RPM.
pub fn canonical_spin(rpm: [f64; 3]) -> Vec3 {
    (0..3).fold([0.0; 3], |acc, i| add(&acc, &scale(&SPIN_AXES[i], SPIN_FACTORS[i] * rpm[i])))
}

/// Launch speed (m/s): the mean rim speed of the three wheels.
pub fn launch_speed(wheel_speeds: [f64; 3]) -> f64 {
    EFFECTIVE_RIM_RADIUS * wheel_speeds.iter().sum::<f64>() / 3.0
}

/// Rotates a vector given in the canonical launch frame (launch along +x) into the world.
fn to_world(v: &Vec3, azimuth: f64, elevation: f64) -> Vec3 {
    // R_y(θ_l − 90°) with θ_l = 90° − elevation tilts +x up by the elevation.
    rotate_z(&rotate_y(v, -elevation), azimuth)
}

/// Everything about one shot: the settings the EKF may be told (orientation, actuations) and the kinematics
/// they produced.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LaunchParams {
    pub orientation: Orientation,
    /// (s_tl, s_tr, s_b).
    pub motor_actuation: [f64; 3],
    pub s_phi: f64,
    pub s_theta: f64,
    /// Launcher frame yaw φ_f (rad).
    pub frame_yaw: f64,
    /// Where the ball leaves the launcher (m).
    pub exit_position: Vec3,
    /// Angular speeds of the (tl, tr, b) wheels (rad/s).
    pub wheel_speeds: [f64; 3],
    /// Heading of the launch velocity, φ_f + φ_l plus scatter (rad); 0 = +x, counter-clockwise.
    pub azimuth: f64,
    /// Angle of the launch velocity above the horizontal (rad).
    pub elevation: f64,
    /// Launch speed (m/s).
    pub speed: f64,
    /// Initial spin in world coordinates (learned units, see `flight::K_M`).
    pub spin: Vec3,
}

impl LaunchParams {
    /// The nominal shot for given settings: no scatter.
    pub fn from_actuation(orientation: Orientation, motor_actuation: [f64; 3], s_phi: f64, s_theta: f64) -> Self {
        let pose = orientation.pose();
        let rpm = wheel_rpm(motor_actuation);
        let wheel_speeds = rpm.map(|r| r * std::f64::consts::TAU / 60.0);
        let azimuth = wrap_angle(pose.frame_yaw + head_azimuth(s_phi));
        let elevation = std::f64::consts::FRAC_PI_2 - head_polar_angle(s_theta);
        LaunchParams {
            orientation,
            motor_actuation,
            s_phi,
            s_theta,
            frame_yaw: pose.frame_yaw,
            exit_position: pose.exit_position,
            wheel_speeds,
            azimuth,
            elevation,
            speed: launch_speed(wheel_speeds),
            spin: to_world(&canonical_spin(rpm), azimuth, elevation),
        }
    }

    /// Draws settings uniformly from the thesis' ranges for this orientation (lines 4810-4812), then the
    /// shot's scatter around the nominal map.
    pub fn sample<R: Rng + ?Sized>(orientation: Orientation, rng: &mut R) -> Self {
        let ranges = orientation.motor_ranges();
        let motor_actuation = ranges.map(|(lo, hi)| rng.random_range(lo..=hi));
        let s_phi = rng.random_range(S_PHI_RANGE.0..=S_PHI_RANGE.1);
        let s_theta = rng.random_range(S_THETA_RANGE.0..=S_THETA_RANGE.1);
        let nominal = Self::from_actuation(orientation, motor_actuation, s_phi, s_theta);
        let mut normal = || -> f64 { rng.sample(StandardNormal) };
        let azimuth = wrap_angle(nominal.azimuth + AZIMUTH_JITTER_DEG.to_radians() * normal());
        let elevation = nominal.elevation + ELEVATION_JITTER_DEG.to_radians() * normal();
        let speed = nominal.speed * (1.0 + SPEED_JITTER * normal());
        let spin_gain = 1.0 + SPIN_JITTER * normal();
        let canonical = canonical_spin(wheel_rpm(motor_actuation));
        LaunchParams {
            azimuth,
            elevation,
            speed,
            spin: scale(&to_world(&canonical, azimuth, elevation), spin_gain),
            ..nominal
        }
    }

    pub fn velocity(&self) -> Vec3 {
        to_world(&[self.speed, 0.0, 0.0], self.azimuth, self.elevation)
    }

    /// (p, v, ω) at the moment the ball leaves the launcher.
    pub fn initial_state(&self) -> BallState {
        let v = self.velocity();
        let (p, w) = (self.exit_position, self.spin);
        [p[0], p[1], p[2], v[0], v[1], v[2], w[0], w[1], w[2]]
    }

    /// The recordings' side information, in the layout of the authors' HDF5 `side_info` (README):
    /// (sin, cos of the frame rotation relative to the default frame, s_φ, s_θ, s_tl, s_tr, s_b).
    pub fn side_info(&self) -> [f64; 7] {
        let rot = self.frame_yaw + std::f64::consts::FRAC_PI_2;
        let s = self.motor_actuation;
        [rot.sin(), rot.cos(), self.s_phi, self.s_theta, s[0], s[1], s[2]]
    }

    /// The same shot with the whole setup turned by `angle` about the vertical axis through `pivot`.
    pub fn rotated_about_z(&self, angle: f64, pivot: &Vec3) -> Self {
        LaunchParams {
            frame_yaw: wrap_angle(self.frame_yaw + angle),
            exit_position: add(pivot, &rotate_z(&sub(&self.exit_position, pivot), angle)),
            azimuth: wrap_angle(self.azimuth + angle),
            spin: rotate_z(&self.spin, angle),
            ..self.clone()
        }
    }
}
