//! The scripted controller that plays board games with the arm: inverse kinematics and a saturated
//! computed-torque PD law, pushing once its own model of the arm predicts the finger on the aim point.

use std::f64::consts::{PI, TAU};

use super::{
    arm_to_board, board_to_arm, min_reach, pressed_reach, pressed_wrist_angle, Reacher, ACTION_REPEAT, ARM_LENGTH,
    BOARD_HALF_EXTENT, FINGER_OFFSET, GEAR, WRIST_LIMIT,
};
use crate::envs::embodiments::manipulator::{BoardPoint, Manipulator, ScriptedController};

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
/// lie beyond the wrist's range. For those the controller presses the wrist into its stop, where the
/// soft limit holds it 4.75° past (the finger then circles at [`pressed_reach`]), and heads for the
/// reachable point nearest to the target in the max-norm; it pushes once the finger is no farther
/// (max-norm) from the target than that point plus [`ReacherController::SHORTFALL_SLACK`]: for the centre field of a
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
        // Pressed at full torque the wrist rests past the stop, so the finger circles closer in.
        let (aim, press) = if r_t >= r_min {
            (t, None)
        } else {
            let f = self.model.finger();
            (Self::max_norm_projection(t, pressed_reach(), f[1].atan2(f[0])), Some(1.0))
        };
        let max_norm = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs());
        let shortfall = max_norm(arm_to_board(aim), target);
        // Both elbow branches; the joint-space move that takes the longest decides.
        let mut best: Option<(f64, [f64; 2], f64)> = None;
        for elbow in [1.0, -1.0] {
            let joints = match press {
                Some(_) => {
                    let wrist = elbow * pressed_wrist_angle();
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
        // Pressed into the stop, the soft limit lets the wrist sink up to 5° past 160°, which moves the
        // finger off the aim circle towards the target: there only the distance to the target counts.
        let close = match plan.press {
            None => (finger[0] - aim[0]).hypot(finger[1] - aim[1]) <= self.tolerance,
            Some(_) => {
                (finger[0] - target[0]).abs().max((finger[1] - target[1]).abs())
                    <= plan.shortfall + Self::SHORTFALL_SLACK
            }
        };
        let velocity = next.finger_velocity();
        let slow = velocity[0].hypot(velocity[1]) / (2.0 * BOARD_HALF_EXTENT) <= self.max_push_speed;
        let push = close && slow;
        vec![u[0], u[1], if push { 1.0 } else { -1.0 }]
    }

    fn reset(&mut self) {
        self.plan = None;
    }
}
