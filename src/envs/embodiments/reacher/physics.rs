//! The arm's rigid-body model: masses and inertias from the MJCF geoms, forward kinematics, and the planar
//! two-link dynamics stepped like MuJoCo's Euler integrator, with the wrist's soft limit.

use std::f64::consts::PI;

use super::limit::{is_past_stop, resting_violation, wrist_limit_torque, WristLimitInput};
use super::{
    ARM_LENGTH, CAPSULE_RADIUS, DAMPING, DENSITY, FINGER_OFFSET, FINGER_RADIUS, GEAR, HAND_LENGTH, TIMESTEP,
    WRIST_LIMIT,
};

/// Closest the finger gets to the shoulder (wrist at ±160°): 0.0417, i.e. 0.139 board units around the
/// board centre can never be touched.
pub fn min_reach() -> f64 {
    (ARM_LENGTH * ARM_LENGTH + FINGER_OFFSET * FINGER_OFFSET + 2.0 * ARM_LENGTH * FINGER_OFFSET * WRIST_LIMIT.cos())
        .sqrt()
}

/// Where full torque into a stop holds the wrist (magnitude): 4.75° past 160°, by the soft limit.
pub fn pressed_wrist_angle() -> f64 {
    WRIST_LIMIT + resting_violation(GEAR, Reacher::new().inverse_inertia_at_rest, TIMESTEP)
}

/// Distance of the finger from the shoulder with the wrist pressed into a stop: 0.0319, closer than
/// [`min_reach`] because the soft limit gives way.
pub fn pressed_reach() -> f64 {
    let wrist = pressed_wrist_angle();
    (ARM_LENGTH * ARM_LENGTH + FINGER_OFFSET * FINGER_OFFSET + 2.0 * ARM_LENGTH * FINGER_OFFSET * wrist.cos()).sqrt()
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

fn solve2(m: [[f64; 2]; 2], f: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [(m[1][1] * f[0] - m[0][1] * f[1]) / det, (m[0][0] * f[1] - m[1][0] * f[0]) / det]
}

/// The planar two-link arm.
#[derive(Clone, Debug)]
pub struct Reacher {
    /// Joint angles [shoulder, wrist] (radians; the shoulder is not wrapped, like MuJoCo's qpos).
    pub(super) q: [f64; 2],
    /// Joint velocities.
    pub(super) v: [f64; 2],
    inertia: ArmInertia,
    /// Joint damping of both hinges; a field so that tests can switch it off.
    pub damping: f64,
    /// (M⁻¹)₂₂ with both joints at zero, which scales the limit's softness (MuJoCo's `dof_invweight0`).
    inverse_inertia_at_rest: f64,
}

impl Default for Reacher {
    fn default() -> Self {
        Self::new()
    }
}

impl Reacher {
    pub fn new() -> Self {
        let mut arm = Reacher {
            q: [0.0, 0.0],
            v: [0.0, 0.0],
            inertia: ArmInertia::dm_control(),
            damping: DAMPING,
            inverse_inertia_at_rest: 0.0,
        };
        arm.inverse_inertia_at_rest = solve2(arm.mass_matrix(0.0), [0.0, 1.0])[1];
        arm
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

    /// One semi-implicit Euler step of length `h`, as `mj_Euler` takes it: the wrist limit's force is
    /// solved with the plain inertia, then all forces go through (M + h·B) so that the damping acts
    /// implicitly, then the position moves with the new velocity.
    pub(super) fn integrate(&mut self, ctrl: [f64; 2], h: f64) {
        let m = self.mass_matrix(self.q[1]);
        let bias = self.bias_forces();
        let mut force = [0.0; 2];
        for j in 0..2 {
            let u = if ctrl[j].is_finite() { ctrl[j].clamp(-1.0, 1.0) } else { 0.0 };
            force[j] = GEAR * u - bias[j] - self.damping * self.v[j];
        }
        // Inside the range (most steps) MuJoCo has no limit row, and the two solves it needs are skipped.
        if is_past_stop(self.q[1]) {
            force[1] += wrist_limit_torque(&WristLimitInput {
                wrist_angle: self.q[1],
                wrist_velocity: self.v[1],
                free_acceleration: solve2(m, force)[1],
                inverse_inertia: solve2(m, [0.0, 1.0])[1],
                inverse_inertia_at_rest: self.inverse_inertia_at_rest,
                timestep: h,
            });
        }
        let lhs = [[m[0][0] + h * self.damping, m[0][1]], [m[1][0], m[1][1] + h * self.damping]];
        let acc = solve2(lhs, force);
        self.v = [self.v[0] + h * acc[0], self.v[1] + h * acc[1]];
        self.q = [self.q[0] + h * self.v[0], self.q[1] + h * self.v[1]];
    }
}
