//! Reacher (thesis 7.4.1, D.1.2): dm_control's planar two-link arm without its target, over a 0.3 × 0.3
//! board; a third action component pushes at the finger.
//!
//! The physics is our own rigid-body simulation of the MJCF model `dm_control/suite/reacher.xml`, which
//! the authors' environment (`seads_envs/hybrid/reacher/xmls/reacher.xml`) copies unchanged apart from
//! removing the target and adding the board. Facts taken from those files:
//!
//! - `<option timestep="0.02">` with contacts disabled and no integrator given (MuJoCo's default Euler);
//! - joints: hinges about z, `damping="0.01"`, no armature; the wrist `limited="true" range="-160 160"`
//!   (degrees, the MJCF default unit); the shoulder unlimited;
//! - motors: `gear=".05" ctrlrange="-1 1" ctrllimited="true"` on both joints;
//! - body `arm` at the origin with capsule geom `fromto="0 0 0 0.12 0 0" size=".01"`; body `hand` at
//!   `pos=".12 0 0"` with capsule `fromto="0 0 0 0.1 0 0" size=".01"`; body `finger` at `pos=".12 0 0"` in
//!   the hand frame with a sphere geom of radius 0.01. Gravity acts along −z, normal to the plane of
//!   motion, so it does no work.
//!
//! From the authors' SEADS environment (`seads_envs/hybrid/reacher/common.py`): action repeat 2, joints
//! reset to U(0, 2π) with zero velocity, push threshold `-1 + 0.8·2 = 0.6` on the third action component,
//! finger position normalized as (xy + 0.15)/0.3, and a push counts only with the normalized finger
//! position inside [0, 1]², checked after the physics steps of that action.
//!
//! Masses and inertias follow from MuJoCo's defaults (`inertiafromgeom`, geom density 1000 kg/m³), see
//! [`ArmInertia::dm_control`]. The dynamics are the standard planar two-link equations
//! M(q) q̈ + C(q, q̇) q̇ + B q̇ = gear·u, stepped like MuJoCo's Euler integrator: the velocity first, with the
//! joint damping taken implicitly ((M + h·B) q̈ = gear·u − C q̇ − B q̇, as `mj_Euler` does whenever a dof has
//! damping), then the position with the new velocity.
//!
//! Simplification: MuJoCo enforces the wrist range with a soft constraint (a stiff spring-damper with
//! time constant 2·timestep that lets the wrist sink about 2° past 160° under full torque). Here the limit
//! is a hard stop: a wrist arriving at ±160° is clamped there, and a plastic impulse at the wrist (an
//! internal torque between the links) removes the velocity that drives into the stop, both on arrival
//! and, before the position update, while it rests against the stop.

use std::f64::consts::{PI, TAU};

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::manipulator::{BoardPoint, Manipulator, ScriptedController};

/// Physics timestep of `reacher.xml` (seconds).
pub const TIMESTEP: f64 = 0.02;
/// Physics steps per control step (thesis D.1.2).
pub const ACTION_REPEAT: usize = 2;
/// Motor gear: joint torque = GEAR · ctrl, ctrl ∈ [−1, 1].
pub const GEAR: f64 = 0.05;
/// Joint damping of both hinges (N·m·s/rad).
pub const DAMPING: f64 = 0.01;
/// Shoulder to wrist (position of body `hand` in body `arm`; also the length of the `arm` capsule).
pub const ARM_LENGTH: f64 = 0.12;
/// Length of the `hand` capsule's segment (it ends short of the finger).
pub const HAND_LENGTH: f64 = 0.1;
/// Wrist to finger centre (position of body `finger` in body `hand`).
pub const FINGER_OFFSET: f64 = 0.12;
/// Radius of both capsules.
pub const CAPSULE_RADIUS: f64 = 0.01;
/// Radius of the finger sphere.
pub const FINGER_RADIUS: f64 = 0.01;
/// MuJoCo's default geom density (kg/m³).
pub const DENSITY: f64 = 1000.0;
/// Wrist range ±160°.
pub const WRIST_LIMIT: f64 = 160.0 * PI / 180.0;
/// A push happens when the third action component exceeds this (authors' code: −1 + 0.8·2).
pub const PUSH_THRESHOLD: f64 = 0.6;
/// The board covers [−0.15, 0.15]² in the arm's plane (thesis D.1.2).
pub const BOARD_HALF_EXTENT: f64 = 0.15;
/// Skill step limit for Reacher (thesis 7.4.1).
pub const SKILL_STEP_LIMIT: usize = 50;

/// Farthest the finger gets from the shoulder.
pub const MAX_REACH: f64 = ARM_LENGTH + FINGER_OFFSET;
/// Closest the finger gets to the shoulder (wrist at ±160°): 0.0417, i.e. 0.139 board units around the
/// board centre can never be touched.
pub fn min_reach() -> f64 {
    (ARM_LENGTH * ARM_LENGTH + FINGER_OFFSET * FINGER_OFFSET + 2.0 * ARM_LENGTH * FINGER_OFFSET * WRIST_LIMIT.cos())
        .sqrt()
}

/// Mass and rotational inertia (about the centre, normal to the axis) of a capsule whose segment has
/// length `length`, as MuJoCo computes them for a uniform density: a cylinder of that length plus two
/// hemispheres displaced to its ends.
pub fn capsule_mass_inertia(length: f64, radius: f64, density: f64) -> (f64, f64) {
    let cylinder = density * PI * radius * radius * length;
    let sphere = density * 4.0 / 3.0 * PI * radius.powi(3);
    let inertia = cylinder * (3.0 * radius * radius + length * length) / 12.0
        + 2.0 * sphere * radius * radius / 5.0
        + sphere * length * (3.0 * radius + 2.0 * length) / 8.0;
    (cylinder + sphere, inertia)
}

/// Mass and rotational inertia (about its centre) of a uniform sphere.
pub fn sphere_mass_inertia(radius: f64, density: f64) -> (f64, f64) {
    let mass = density * 4.0 / 3.0 * PI * radius.powi(3);
    (mass, 2.0 * mass * radius * radius / 5.0)
}

/// The inertial parameters the planar two-link equations need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmInertia {
    /// Moment of inertia of the upper arm about the shoulder axis.
    pub shoulder_link: f64,
    /// Moment of inertia of the distal body (hand + finger) about the wrist axis.
    pub wrist_link: f64,
    /// Mass of the distal body.
    pub distal_mass: f64,
    /// First moment of the distal body about the wrist (mass × distance of its centre of mass); the
    /// centre lies on the hand's axis because both geoms do.
    pub distal_moment: f64,
}

impl ArmInertia {
    /// Derived from `reacher.xml` with MuJoCo's defaults (density 1000 kg/m³, inertia from geoms):
    ///
    /// - `arm` capsule, segment 0.12, radius 0.01: m = 1000·(π·0.01²·0.12 + 4/3·π·0.01³) = 0.041888 kg,
    ///   I_c = 6.3314e-5 kg·m² about its centre (cylinder m_c(3r² + L²)/12 plus hemispheres
    ///   2m_s r²/5 + m_s L(3r + 2L)/8, as in MuJoCo's compiler), centre 0.06 from the shoulder:
    ///   J₁ = I_c + m·0.06² = 2.1411e-4;
    /// - `hand` capsule, segment 0.1: m = 0.035605 kg, I_c = 3.9176e-5, centre 0.05 from the wrist;
    /// - `finger` sphere, r = 0.01: m = 0.0041888 kg, I_c = 1.6755e-7, centre 0.12 from the wrist;
    /// - distal body (hand + finger, welded): m₂ = 0.039794 kg, m₂c₂ = 2.2829e-3 kg·m,
    ///   J₂ = 3.9176e-5 + 0.035605·0.05² + 1.6755e-7 + 0.0041888·0.12² = 1.8867e-4 kg·m².
    pub fn dm_control() -> Self {
        let (arm_mass, arm_inertia) = capsule_mass_inertia(ARM_LENGTH, CAPSULE_RADIUS, DENSITY);
        let (hand_mass, hand_inertia) = capsule_mass_inertia(HAND_LENGTH, CAPSULE_RADIUS, DENSITY);
        let (finger_mass, finger_inertia) = sphere_mass_inertia(FINGER_RADIUS, DENSITY);
        let arm_centre = ARM_LENGTH / 2.0;
        let hand_centre = HAND_LENGTH / 2.0;
        ArmInertia {
            shoulder_link: arm_inertia + arm_mass * arm_centre * arm_centre,
            wrist_link: hand_inertia
                + hand_mass * hand_centre * hand_centre
                + finger_inertia
                + finger_mass * FINGER_OFFSET * FINGER_OFFSET,
            distal_mass: hand_mass + finger_mass,
            distal_moment: hand_mass * hand_centre + finger_mass * FINGER_OFFSET,
        }
    }
}

/// Arm-plane position (metres, shoulder at the origin) of the finger for joint angles `q`.
pub fn finger_position(q: [f64; 2]) -> [f64; 2] {
    let a = q[0] + q[1];
    [ARM_LENGTH * q[0].cos() + FINGER_OFFSET * a.cos(), ARM_LENGTH * q[0].sin() + FINGER_OFFSET * a.sin()]
}

/// Arm plane → board coordinates. Arm +x is board x (columns); arm +y is board *up*, so rows (board y)
/// count downwards. (The authors' code uses (y + 0.15)/0.3 for rows, the mirror image; the arm is
/// mirror-symmetric and its reset distribution too, so this only relabels the board.)
pub fn arm_to_board(p: [f64; 2]) -> BoardPoint {
    let extent = 2.0 * BOARD_HALF_EXTENT;
    [(p[0] + BOARD_HALF_EXTENT) / extent, (BOARD_HALF_EXTENT - p[1]) / extent]
}

/// Inverse of [`arm_to_board`].
pub fn board_to_arm(b: BoardPoint) -> [f64; 2] {
    let extent = 2.0 * BOARD_HALF_EXTENT;
    [b[0] * extent - BOARD_HALF_EXTENT, BOARD_HALF_EXTENT - b[1] * extent]
}

fn solve2(m: [[f64; 2]; 2], f: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [(m[1][1] * f[0] - m[0][1] * f[1]) / det, (m[0][0] * f[1] - m[1][0] * f[0]) / det]
}

/// The planar two-link arm.
#[derive(Clone, Debug)]
pub struct Reacher {
    /// Joint angles [shoulder, wrist] (radians; the shoulder is not wrapped, like MuJoCo's qpos).
    q: [f64; 2],
    /// Joint velocities.
    v: [f64; 2],
    inertia: ArmInertia,
    /// Joint damping of both hinges; a field so that tests can switch it off.
    pub damping: f64,
}

impl Default for Reacher {
    fn default() -> Self {
        Self::new()
    }
}

impl Reacher {
    pub fn new() -> Self {
        Reacher { q: [0.0, 0.0], v: [0.0, 0.0], inertia: ArmInertia::dm_control(), damping: DAMPING }
    }

    pub fn inertia(&self) -> ArmInertia {
        self.inertia
    }

    pub fn joint_angles(&self) -> [f64; 2] {
        self.q
    }

    pub fn joint_velocities(&self) -> [f64; 2] {
        self.v
    }

    /// Finger position in the arm plane (metres).
    pub fn finger(&self) -> [f64; 2] {
        finger_position(self.q)
    }

    /// Finger velocity in the arm plane (m/s).
    pub fn finger_velocity(&self) -> [f64; 2] {
        let [q1, q2] = self.q;
        let a = q1 + q2;
        let (wa, wb) = (self.v[0], self.v[0] + self.v[1]);
        [
            -ARM_LENGTH * q1.sin() * wa - FINGER_OFFSET * a.sin() * wb,
            ARM_LENGTH * q1.cos() * wa + FINGER_OFFSET * a.cos() * wb,
        ]
    }

    /// Joint-space inertia matrix M(q) (depends on the wrist angle only).
    pub fn mass_matrix(&self, wrist: f64) -> [[f64; 2]; 2] {
        let i = &self.inertia;
        let coupling = ARM_LENGTH * i.distal_moment * wrist.cos();
        let m11 = i.shoulder_link + i.wrist_link + i.distal_mass * ARM_LENGTH * ARM_LENGTH + 2.0 * coupling;
        let m12 = i.wrist_link + coupling;
        [[m11, m12], [m12, i.wrist_link]]
    }

    /// Coriolis and centrifugal forces C(q, q̇) q̇.
    pub fn bias_forces(&self) -> [f64; 2] {
        let h = ARM_LENGTH * self.inertia.distal_moment * self.q[1].sin();
        let [v1, v2] = self.v;
        [-h * v2 * (2.0 * v1 + v2), h * v1 * v1]
    }

    /// Kinetic energy ½ q̇ᵀ M q̇.
    pub fn kinetic_energy(&self) -> f64 {
        let m = self.mass_matrix(self.q[1]);
        let [v1, v2] = self.v;
        0.5 * (m[0][0] * v1 * v1 + 2.0 * m[0][1] * v1 * v2 + m[1][1] * v2 * v2)
    }

    /// One physics step of `TIMESTEP` with motor controls `ctrl` (clipped to [−1, 1]).
    pub fn physics_step(&mut self, ctrl: [f64; 2]) {
        self.integrate(ctrl, TIMESTEP);
    }

    /// One semi-implicit Euler step of length `h`.
    fn integrate(&mut self, ctrl: [f64; 2], h: f64) {
        let m = self.mass_matrix(self.q[1]);
        let bias = self.bias_forces();
        let mut force = [0.0; 2];
        for j in 0..2 {
            let u = if ctrl[j].is_finite() { ctrl[j].clamp(-1.0, 1.0) } else { 0.0 };
            force[j] = GEAR * u - bias[j] - self.damping * self.v[j];
        }
        // Damping implicit in the velocity update, as MuJoCo's Euler integrator does.
        let lhs = [[m[0][0] + h * self.damping, m[0][1]], [m[1][0], m[1][1] + h * self.damping]];
        let acc = solve2(lhs, force);
        self.v = [self.v[0] + h * acc[0], self.v[1] + h * acc[1]];
        // Resting on (or beyond) a stop: no velocity into it, before the position moves.
        let side = self.q[1].signum();
        if self.q[1].abs() >= WRIST_LIMIT && self.v[1] * side > 0.0 {
            self.stop_wrist(lhs);
        }
        self.q = [self.q[0] + h * self.v[0], self.q[1] + h * self.v[1]];
        // Arriving at a stop within this step: clamp and stop the wrist there.
        if self.q[1].abs() > WRIST_LIMIT {
            self.q[1] = self.q[1].signum() * WRIST_LIMIT;
            if self.v[1] * self.q[1] > 0.0 {
                self.stop_wrist(lhs);
            }
        }
    }

    /// Plastic impulse at the wrist: the wrist velocity becomes zero. It acts through the same matrix
    /// as the velocity update (M + h·B, like MuJoCo's constraint force, which enters the Euler update
    /// alongside the other forces), so a torque pressing the wrist into its stop does not leak into the
    /// shoulder, and without damping the shoulder's angular momentum is unchanged.
    fn stop_wrist(&mut self, metric: [[f64; 2]; 2]) {
        // Column e₂ of the inverse metric.
        let column = solve2(metric, [0.0, 1.0]);
        let impulse = -self.v[1] / column[1];
        self.v[0] += column[0] * impulse;
        self.v[1] = 0.0;
    }
}

impl Manipulator for Reacher {
    fn name(&self) -> &'static str {
        "reacher"
    }

    fn action_low(&self) -> Vec<f64> {
        vec![-1.0; 3]
    }

    fn action_high(&self) -> Vec<f64> {
        vec![1.0; 3]
    }

    /// dm_control's reacher observes the joint positions and velocities (and the vector to its target);
    /// here the angles are given as cos/sin (the shoulder is unbounded), followed by the velocities and
    /// the finger's board position, which takes the target's place.
    fn obs_names(&self) -> Vec<&'static str> {
        vec![
            "shoulder_cos",
            "shoulder_sin",
            "wrist_cos",
            "wrist_sin",
            "shoulder_velocity",
            "wrist_velocity",
            "finger_x",
            "finger_y",
        ]
    }

    fn observe(&self) -> Vec<f64> {
        let (s1, c1) = self.q[0].sin_cos();
        let (s2, c2) = self.q[1].sin_cos();
        let f = self.effector();
        vec![c1, s1, c2, s2, self.v[0], self.v[1], f[0], f[1]]
    }

    /// [shoulder angle, wrist angle, shoulder velocity, wrist velocity].
    fn state(&self) -> Vec<f64> {
        vec![self.q[0], self.q[1], self.v[0], self.v[1]]
    }

    fn set_state(&mut self, state: &[f64]) {
        self.q = [state[0], state[1]];
        self.v = [state[2], state[3]];
    }

    /// Both angles U(0, 2π), zero velocity (authors' code). MuJoCo keeps the raw wrist sample and its
    /// soft limit then drives a wrist beyond +160° (56 % of the draws, the raw value lies in (160°, 360°))
    /// back to +160° within the first few physics steps; we clamp right away, which ends in the same
    /// place without the transient.
    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        let shoulder = rng.random_range(0.0..TAU);
        let wrist: f64 = rng.random_range(0.0..TAU);
        self.q = [shoulder, wrist.min(WRIST_LIMIT)];
        self.v = [0.0, 0.0];
    }

    fn step(&mut self, action: &[f64]) -> Option<BoardPoint> {
        for _ in 0..ACTION_REPEAT {
            self.physics_step([action[0], action[1]]);
        }
        let finger = self.effector();
        let on_board = finger.iter().all(|c| (0.0..=1.0).contains(c));
        (action[2] > PUSH_THRESHOLD && on_board).then_some(finger)
    }

    /// The finger in board coordinates.
    fn effector(&self) -> BoardPoint {
        arm_to_board(self.finger())
    }

    fn skill_step_limit(&self) -> usize {
        SKILL_STEP_LIMIT
    }

    fn dt(&self) -> f64 {
        TIMESTEP * ACTION_REPEAT as f64
    }
}

/// Where the controller is heading for the current target.
#[derive(Clone, Debug)]
struct Plan {
    target: BoardPoint,
    /// Where the finger should push (arm plane): the target, or for a target too close to the shoulder
    /// the reachable point nearest to it in the max-norm.
    aim: [f64; 2],
    /// Joint goal (the shoulder angle taken as the equivalent nearest to where it started).
    goal: [f64; 2],
    /// Max-norm distance (board units) between aim and target (used only for unreachable targets).
    shortfall: f64,
    /// For an unreachable target: the side (±1) of the wrist stop to press against.
    press: Option<f64>,
}

/// Drives the finger to a board point with inverse kinematics and a saturated computed-torque PD law,
/// and pushes once a one-step prediction with the arm's own dynamics puts the finger within `tolerance`
/// of the aim point and nearly at rest.
///
/// Points closer than [`min_reach`] to the shoulder (a disc of radius 0.139 around the board centre)
/// cannot be touched. For those the controller presses the wrist against its stop and pushes at the
/// reachable point nearest to the target in the max-norm, with the push point no farther (max-norm)
/// from the target than that point plus [`ReacherController::SHORTFALL_SLACK`]: for the centre field of a
/// 5×5 LightsOut board this is a point on the diagonal 0.098 from its centre, just inside the field.
#[derive(Clone, Debug)]
pub struct ReacherController {
    /// Push radius around the aim point (board units). LightsOut 5×5 fields are 0.2 wide and TileSwap
    /// pivots accept L1 ≤ 1/6, so 0.03 leaves wide margins for both.
    pub tolerance: f64,
    /// Largest finger speed (board units per second) at which it pushes.
    pub max_push_speed: f64,
    /// Proportional gain (1/s²) of the computed-torque law. With `kd` about critically damped:
    /// ω ≈ 14 rad/s, ζ ≈ 1.06, ω·T ≈ 0.57 at the 0.04 s control period. Tuned over 90 000 random
    /// moves: larger gains shave the mean by a step but lengthen the slowest moves.
    pub kp: f64,
    /// Derivative gain (1/s).
    pub kd: f64,
    model: Reacher,
    plan: Option<Plan>,
}

impl Default for ReacherController {
    fn default() -> Self {
        Self::new()
    }
}

impl ReacherController {
    /// Extra max-norm distance (board units) allowed beyond the unavoidable shortfall for unreachable
    /// targets.
    pub const SHORTFALL_SLACK: f64 = 0.001;
    /// How far past the stop the wrist goal lies when pressing, so the PD law pushes into it.
    const PRESS_OVERSHOOT: f64 = 0.3;

    pub fn new() -> Self {
        ReacherController {
            tolerance: 0.03,
            max_push_speed: 0.5,
            kp: 200.0,
            kd: 30.0,
            model: Reacher::new(),
            plan: None,
        }
    }

    /// Joint angles putting the finger at arm-plane point `p` with the wrist sign `elbow` (±1), or None
    /// when `p` is out of reach.
    fn inverse_kinematics(p: [f64; 2], elbow: f64) -> Option<[f64; 2]> {
        let r2 = p[0] * p[0] + p[1] * p[1];
        let c = (r2 - ARM_LENGTH * ARM_LENGTH - FINGER_OFFSET * FINGER_OFFSET) / (2.0 * ARM_LENGTH * FINGER_OFFSET);
        if !(-1.0..=1.0).contains(&c) {
            return None;
        }
        let wrist = elbow * c.acos();
        if wrist.abs() > WRIST_LIMIT + 1e-12 {
            return None;
        }
        let wrist = wrist.clamp(-WRIST_LIMIT, WRIST_LIMIT);
        let shoulder = p[1].atan2(p[0]) - (FINGER_OFFSET * wrist.sin()).atan2(ARM_LENGTH + FINGER_OFFSET * wrist.cos());
        Some([shoulder, wrist])
    }

    /// The point at distance `radius` from the shoulder nearest to `t` in the max-norm; ties (as for
    /// the exact centre, where the four diagonals tie) go to the direction closest to `heading`.
    fn max_norm_projection(t: [f64; 2], radius: f64, heading: f64) -> [f64; 2] {
        const SAMPLES: usize = 7200;
        let mut best = (f64::INFINITY, f64::INFINITY, [0.0, 0.0]);
        for k in 0..SAMPLES {
            let phi = TAU * k as f64 / SAMPLES as f64;
            let p = [radius * phi.cos(), radius * phi.sin()];
            let dist = (p[0] - t[0]).abs().max((p[1] - t[1]).abs());
            let turn = wrap_angle(phi - heading).abs();
            if dist < best.0 - 1e-12 || (dist < best.0 + 1e-12 && turn < best.1) {
                best = (dist.min(best.0), turn, p);
            }
        }
        best.2
    }

    fn make_plan(&self, target: BoardPoint) -> Plan {
        let t = board_to_arm(target);
        let [q1, q2] = self.model.q;
        let r_min = min_reach();
        let r_t = t[0].hypot(t[1]);
        let (aim, press) = if r_t >= r_min {
            (t, None)
        } else {
            let f = self.model.finger();
            (Self::max_norm_projection(t, r_min, f[1].atan2(f[0])), Some(1.0))
        };
        let max_norm = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs());
        let shortfall = max_norm(arm_to_board(aim), target);
        // Both elbow branches; the joint-space move that takes the longest decides.
        let mut best: Option<(f64, [f64; 2], f64)> = None;
        for elbow in [1.0, -1.0] {
            let joints = match press {
                Some(_) => {
                    let wrist = elbow * WRIST_LIMIT;
                    let shoulder = aim[1].atan2(aim[0])
                        - (FINGER_OFFSET * wrist.sin()).atan2(ARM_LENGTH + FINGER_OFFSET * wrist.cos());
                    Some([shoulder, wrist])
                }
                None => Self::inverse_kinematics(aim, elbow),
            };
            let Some([s, w]) = joints else { continue };
            let shoulder = q1 + wrap_angle(s - q1);
            let cost = (shoulder - q1).abs().max((w - q2).abs());
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, [shoulder, w], elbow));
            }
        }
        // Every aim point lies within reach, so one branch exists; fall back to the current pose anyway.
        let (_, goal, elbow) = best.unwrap_or((0.0, [q1, q2], 1.0));
        Plan { target, aim, goal, shortfall, press: press.map(|_| elbow) }
    }

    /// Saturated computed-torque PD controls towards the plan's joint goal.
    fn controls(&self, plan: &Plan) -> [f64; 2] {
        let arm = &self.model;
        let mut goal = plan.goal;
        if let Some(side) = plan.press {
            if arm.q[1] * side >= WRIST_LIMIT {
                // Wrist held against its stop: the arm turns as one rigid body about the shoulder (the
                // wrist torque and the stop's reaction are internal), so PD on the shoulder alone.
                let m = arm.mass_matrix(arm.q[1]);
                let acc = self.kp * (goal[0] - arm.q[0]) - self.kd * arm.v[0];
                let torque = m[0][0] * acc + arm.damping * arm.v[0];
                return [(torque / GEAR).clamp(-1.0, 1.0), side];
            }
            goal[1] = side * (WRIST_LIMIT + Self::PRESS_OVERSHOOT);
        }
        let acc = [0, 1].map(|j| self.kp * (goal[j] - arm.q[j]) - self.kd * arm.v[j]);
        let m = arm.mass_matrix(arm.q[1]);
        let bias = arm.bias_forces();
        // τ = τ₀ + s·M·acc: shrink the acceleration (keeping its direction, so the joints stay
        // coordinated) until both torques fit the motors.
        let base = [0, 1].map(|j| bias[j] + arm.damping * arm.v[j]);
        let inertial = [0, 1].map(|j| m[j][0] * acc[0] + m[j][1] * acc[1]);
        let mut scale: f64 = 1.0;
        for j in 0..2 {
            if base[j].abs() < GEAR && inertial[j] != 0.0 {
                let bound = if inertial[j] > 0.0 { GEAR - base[j] } else { -GEAR - base[j] };
                scale = scale.min(bound / inertial[j]);
            }
        }
        let scale = scale.max(0.0);
        [0, 1].map(|j| ((base[j] + scale * inertial[j]) / GEAR).clamp(-1.0, 1.0))
    }
}

fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

impl ScriptedController for ReacherController {
    fn act(&mut self, manipulator: &dyn Manipulator, target: BoardPoint) -> Vec<f64> {
        self.model.set_state(&manipulator.state());
        if self.plan.as_ref().is_none_or(|p| p.target != target) {
            self.plan = Some(self.make_plan(target));
        }
        let plan = self.plan.as_ref().expect("plan was just made");
        let u = self.controls(plan);
        // Where this action leaves the finger.
        let mut next = self.model.clone();
        for _ in 0..ACTION_REPEAT {
            next.physics_step(u);
        }
        let finger = next.effector();
        let aim = arm_to_board(plan.aim);
        let close = (finger[0] - aim[0]).hypot(finger[1] - aim[1]) <= self.tolerance;
        let within_shortfall = plan.press.is_none()
            || (finger[0] - target[0]).abs().max((finger[1] - target[1]).abs())
                <= plan.shortfall + Self::SHORTFALL_SLACK;
        let velocity = next.finger_velocity();
        let slow = velocity[0].hypot(velocity[1]) / (2.0 * BOARD_HALF_EXTENT) <= self.max_push_speed;
        let push = close && within_shortfall && slow;
        vec![u[0], u[1], if push { 1.0 } else { -1.0 }]
    }

    fn reset(&mut self) {
        self.plan = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
        (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
    }

    #[test]
    fn derived_masses_and_reach() {
        let i = ArmInertia::dm_control();
        assert!((i.shoulder_link - 2.1411e-4).abs() < 1e-8, "{i:?}");
        assert!((i.wrist_link - 1.8867e-4).abs() < 1e-8, "{i:?}");
        assert!((i.distal_mass - 0.039794).abs() < 1e-6, "{i:?}");
        assert!((i.distal_moment - 2.2829e-3).abs() < 1e-7, "{i:?}");
        assert!((min_reach() - 0.24 * (80.0f64).to_radians().cos()).abs() < 1e-12);
        // Every board corner is within reach.
        assert!(BOARD_HALF_EXTENT * 2f64.sqrt() < MAX_REACH);
    }

    #[test]
    fn forward_kinematics_and_board_frame() {
        let cases = [
            ([0.0, 0.0], [0.24, 0.0]),
            ([PI / 2.0, 0.0], [0.0, 0.24]),
            ([0.0, PI / 2.0], [0.12, 0.12]),
            ([PI / 2.0, -PI / 2.0], [0.12, 0.12]),
            ([PI, 0.0], [-0.24, 0.0]),
        ];
        for (q, p) in cases {
            assert!(close(finger_position(q), p, 1e-12), "{q:?}");
        }
        assert!(close(arm_to_board([0.0, 0.0]), [0.5, 0.5], 1e-12));
        assert!(close(arm_to_board([0.15, 0.15]), [1.0, 0.0], 1e-12), "arm +y is board up");
        assert!(close(arm_to_board([-0.15, -0.15]), [0.0, 1.0], 1e-12));
        let b = [0.3, 0.8];
        assert!(close(arm_to_board(board_to_arm(b)), b, 1e-12));
        let mut arm = Reacher::new();
        arm.set_state(&[0.0, PI / 2.0, 0.0, 0.0]);
        assert!(close(arm.effector(), [0.9, 0.1], 1e-12));
        assert_eq!(arm.observe().len(), arm.obs_names().len());
        // Finger velocity matches a finite difference.
        arm.set_state(&[0.3, 0.7, 1.3, -0.4]);
        let v = arm.finger_velocity();
        let eps = 1e-7;
        let p0 = finger_position([0.3, 0.7]);
        let p1 = finger_position([0.3 + 1.3 * eps, 0.7 - 0.4 * eps]);
        assert!(close(v, [(p1[0] - p0[0]) / eps, (p1[1] - p0[1]) / eps], 1e-6));
    }

    /// Largest relative kinetic-energy error over `duration` seconds of free, undamped motion.
    fn energy_error(h: f64, duration: f64) -> f64 {
        let mut arm = Reacher::new();
        arm.damping = 0.0;
        arm.set_state(&[0.4, 0.5, 2.0, 1.0]);
        let e0 = arm.kinetic_energy();
        let mut worst: f64 = 0.0;
        for _ in 0..(duration / h).round() as usize {
            arm.integrate([0.0, 0.0], h);
            assert!(arm.joint_angles()[1].abs() < WRIST_LIMIT, "test motion must not touch the stop");
            worst = worst.max((arm.kinetic_energy() - e0).abs() / e0);
        }
        worst
    }

    #[test]
    fn kinetic_energy_is_conserved_without_torque_and_damping() {
        // 100 control steps (4 s). Semi-implicit Euler with a configuration-dependent mass matrix (MuJoCo's
        // Euler, too) slowly gains energy in undamped motion, about 2.5 %/s here, negligible next to the
        // real damping (time constants 0.02 to 0.15 s). The error shrinks in proportion to the step (first
        // order), which it would not if the equations of motion were wrong.
        let duration = 100.0 * TIMESTEP * ACTION_REPEAT as f64;
        let coarse = energy_error(TIMESTEP, duration);
        let fine = energy_error(TIMESTEP / 8.0, duration);
        assert!(coarse < 0.15, "relative energy error {coarse}");
        assert!(fine < 0.02 && fine < coarse / 5.0, "error {fine} at h/8 vs {coarse}");
        // A rigid spin of the stretched arm keeps its energy exactly.
        let mut arm = Reacher::new();
        arm.damping = 0.0;
        arm.set_state(&[0.0, 0.0, 3.0, 0.0]);
        let e0 = arm.kinetic_energy();
        for _ in 0..100 {
            arm.step(&[0.0, 0.0, -1.0]);
        }
        assert!((arm.kinetic_energy() - e0).abs() < 1e-12 * e0);
        // With damping the energy only decreases.
        let mut arm = Reacher::new();
        arm.set_state(&[0.4, 0.5, 2.0, 1.0]);
        let mut e = arm.kinetic_energy();
        for _ in 0..50 {
            arm.step(&[0.0, 0.0, -1.0]);
            let next = arm.kinetic_energy();
            assert!(next <= e);
            e = next;
        }
        assert!(e < 0.01 * e0);
    }

    #[test]
    fn full_torque_reaches_the_damping_limited_speed() {
        // Terminal joint speed gear/damping = 5 rad/s.
        let mut arm = Reacher::new();
        for _ in 0..100 {
            arm.step(&[1.0, 0.0, -1.0]);
        }
        let v = arm.joint_velocities();
        assert!((v[0] - GEAR / DAMPING).abs() < 0.01, "{v:?}");
    }

    #[test]
    fn wrist_limit_holds() {
        let mut arm = Reacher::new();
        arm.set_state(&[0.0, 2.5, 0.0, 4.0]);
        for _ in 0..60 {
            arm.step(&[0.0, 1.0, -1.0]);
            assert!(arm.joint_angles()[1] <= WRIST_LIMIT);
        }
        assert_eq!(arm.joint_angles()[1], WRIST_LIMIT);
        assert_eq!(arm.joint_velocities()[1], 0.0);
        for _ in 0..60 {
            arm.step(&[0.3, -1.0, -1.0]);
            assert!(arm.joint_angles()[1] >= -WRIST_LIMIT);
        }
        assert_eq!(arm.joint_angles()[1], -WRIST_LIMIT);
        // Reset clamps the raw U(0, 2π) wrist draw into its range.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut at_stop = 0;
        for _ in 0..1000 {
            arm.reset(&mut rng);
            let q = arm.joint_angles();
            assert!((0.0..=WRIST_LIMIT).contains(&q[1]) && (0.0..TAU).contains(&q[0]));
            at_stop += (q[1] == WRIST_LIMIT) as usize;
        }
        assert!((500..620).contains(&at_stop), "{at_stop}");
    }

    #[test]
    fn same_seed_same_trajectory() {
        let run = |seed: u64| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut arm = Reacher::new();
            arm.reset(&mut rng);
            let mut states = vec![];
            for _ in 0..40 {
                let a = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
                arm.step(&a);
                states.push(arm.state());
            }
            states
        };
        assert_eq!(run(3), run(3));
        assert_ne!(run(3), run(4));
        // set_state restores the trajectory exactly.
        let mut a = Reacher::new();
        a.set_state(&[1.0, -0.5, 2.0, 3.0]);
        let saved = a.state();
        a.step(&[0.2, -0.7, 0.0]);
        let after = a.state();
        let mut b = Reacher::new();
        b.set_state(&saved);
        b.step(&[0.2, -0.7, 0.0]);
        assert_eq!(b.state(), after);
    }

    #[test]
    fn pushes_count_only_on_the_board_and_above_the_threshold() {
        let mut arm = Reacher::new();
        // Stretched along +x: finger at x = 0.24 > 0.15, off the board.
        arm.set_state(&[0.0, 0.0, 0.0, 0.0]);
        assert_eq!(arm.step(&[0.0, 0.0, 1.0]), None);
        assert!(arm.effector()[0] > 1.0);
        // Folded to (0.12, 0.12): on the board.
        arm.set_state(&[0.0, PI / 2.0, 0.0, 0.0]);
        assert_eq!(arm.step(&[0.0, 0.0, PUSH_THRESHOLD]), None, "threshold is strict");
        let p = arm.step(&[0.0, 0.0, 0.61]).expect("on the board");
        assert!(close(p, [0.9, 0.1], 1e-12));
    }

    /// Runs the controller from `start` to `target`; returns the push point and steps, if it pushed.
    fn episode(ctrl: &mut ReacherController, start: &[f64], target: BoardPoint) -> Option<(BoardPoint, usize)> {
        let mut arm = Reacher::new();
        arm.set_state(start);
        ctrl.reset();
        (1..=SKILL_STEP_LIMIT).find_map(|step| {
            let a = ctrl.act(&arm, target);
            arm.step(&a).map(|p| (p, step))
        })
    }

    /// 2000 random targets in [0.05, 0.95]²; the arm is reset before every fourth move and otherwise
    /// starts where the previous push left it (the game does not reset it after a move).
    #[test]
    fn controller_pushes_random_targets_within_the_skill_limit() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut ctrl = ReacherController::new();
        let mut arm = Reacher::new();
        let (trials, mut ok, mut steps, mut unreachable) = (2000, 0, 0, 0);
        for trial in 0..trials {
            if trial % 4 == 0 {
                arm.reset(&mut rng);
            }
            let target = [rng.random_range(0.05..0.95), rng.random_range(0.05..0.95)];
            let t = board_to_arm(target);
            let reachable = t[0].hypot(t[1]) >= min_reach();
            unreachable += !reachable as usize;
            ctrl.reset();
            let pushed = (1..=SKILL_STEP_LIMIT).find_map(|step| {
                let a = ctrl.act(&arm, target);
                arm.step(&a).map(|p| (p, step))
            });
            let Some((p, n)) = pushed else { continue };
            let good = if reachable {
                (p[0] - target[0]).hypot(p[1] - target[1]) <= ctrl.tolerance
            } else {
                // The nearest reachable point lies at most r_min/√2 from the target in the max-norm.
                let bound = min_reach() / 2f64.sqrt() / (2.0 * BOARD_HALF_EXTENT);
                (p[0] - target[0]).abs().max((p[1] - target[1]).abs()) <= bound + ReacherController::SHORTFALL_SLACK
            };
            if good {
                ok += 1;
                steps += n;
            }
        }
        let rate = ok as f64 / trials as f64;
        eprintln!(
            "reacher controller: {ok}/{trials} pushed ({unreachable} targets out of reach), mean {:.1} steps",
            steps as f64 / ok as f64
        );
        assert!(rate >= 0.995, "success rate {rate}");
    }

    #[test]
    fn controller_performs_every_lightsout_and_tileswap_move() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut ctrl = ReacherController::new();
        let mut arm = Reacher::new();
        let field = |v: f64| ((v * 5.0).floor() as usize).min(4);
        let mut failures = vec![];
        // LightsOut 5×5: field centres, including the centre field, whose middle is out of reach.
        for r in 0..5 {
            for c in 0..5 {
                let target = [(c as f64 + 0.5) / 5.0, (r as f64 + 0.5) / 5.0];
                for _ in 0..20 {
                    arm.reset(&mut rng);
                    match episode(&mut ctrl, &arm.state(), target) {
                        Some((p, _)) if field(p[0]) == c && field(p[1]) == r => {}
                        other => failures.push((target, other)),
                    }
                }
            }
        }
        // TileSwap 3×3: pivots at the midpoints of interior edges, L1 ≤ 1/6.
        let mut pivots = vec![];
        for i in 0..3 {
            for j in 1..3 {
                pivots.push([(i as f64 + 0.5) / 3.0, j as f64 / 3.0]);
                pivots.push([j as f64 / 3.0, (i as f64 + 0.5) / 3.0]);
            }
        }
        for &target in &pivots {
            for _ in 0..20 {
                arm.reset(&mut rng);
                match episode(&mut ctrl, &arm.state(), target) {
                    Some((p, _)) if (p[0] - target[0]).abs() + (p[1] - target[1]).abs() <= 1.0 / 6.0 => {}
                    other => failures.push((target, other)),
                }
            }
        }
        assert!(failures.is_empty(), "{} failures: {:?}", failures.len(), &failures[..failures.len().min(5)]);
    }

    /// The real games through [`EmbodiedBoard`](crate::envs::embodiments::embodied::EmbodiedBoard): every
    /// move, one after another without resetting the arm, performs exactly that move.
    #[test]
    fn executes_every_move_of_the_real_games() {
        use crate::envs::boards::{BoardGame, LightsOut, TileSwap};
        use crate::envs::embodiments::embodied::EmbodiedBoard;
        use crate::envs::Env;

        fn check<G: BoardGame>(game: G) {
            let mut env = EmbodiedBoard::new(game.clone(), Box::new(Reacher::new()), game.goal());
            let mut ctrl = ReacherController::new();
            let mut rng = ChaCha8Rng::seed_from_u64(21);
            for round in 0..4 {
                env.reset(&mut rng);
                for mv in 0..game.num_moves() {
                    let before = env.board();
                    let out = env.execute(&mut ctrl, mv);
                    assert_eq!(out.performed, Some(mv), "{} move {mv}, round {round}", game.name());
                    assert_eq!(env.board(), game.apply(before, mv));
                }
            }
        }
        check(LightsOut::new(5).unwrap());
        check(TileSwap::new());
    }
}
