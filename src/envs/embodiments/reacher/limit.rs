//! The wrist's joint limit as MuJoCo enforces it: a soft constraint with MuJoCo's default `solref`
//! (0.02, 1) and `solimp` (0.9, 0.95, 0.001, 0.5, 2), since `reacher.xml` sets neither.
//!
//! MuJoCo adds a limit row only while the joint is past its range (distance `pos` < margin 0), with
//! Jacobian −1 at the upper stop and +1 at the lower one. For that row it asks for the reference
//! acceleration `aref = −b·(J q̇) − k·d(pos)·pos` and regularizes with `R = (1 − d)/d · invweight0`, where
//! the impedance `d` follows solimp's sigmoid over the first `width` of violation and `invweight0` is the
//! inverse joint-space inertia of the wrist at qpos0. With one scalar constraint the (Newton) solver's
//! optimum has a closed form: the constraint force is `f = −(J a₀ − aref)/(J M⁻¹ Jᵀ + R)` when that is
//! positive and zero otherwise, `a₀` being the acceleration without the constraint. The force then enters
//! the Euler update beside the smooth forces.

use super::WRIST_LIMIT;

/// solref: time constant and damping ratio of the constraint's reference dynamics.
const TIME_CONSTANT: f64 = 0.02;
const DAMPING_RATIO: f64 = 1.0;
/// solimp: impedance at zero and at full violation width, the width, the sigmoid's midpoint and power.
const IMPEDANCE_MIN: f64 = 0.9;
const IMPEDANCE_MAX: f64 = 0.95;
const IMPEDANCE_WIDTH: f64 = 0.001;
const IMPEDANCE_MIDPOINT: f64 = 0.5;
const IMPEDANCE_POWER: f64 = 2.0;
/// MuJoCo clamps impedance into [mjMINIMP, mjMAXIMP] and R from below by mjMINVAL.
const MIN_IMPEDANCE: f64 = 1e-4;
const MAX_IMPEDANCE: f64 = 0.9999;
const MIN_VALUE: f64 = 1e-15;

/// solimp's impedance for a constraint violated by `violation` (≥ 0).
fn impedance(violation: f64) -> f64 {
    let x = violation / IMPEDANCE_WIDTH;
    if x >= 1.0 {
        return IMPEDANCE_MAX.clamp(MIN_IMPEDANCE, MAX_IMPEDANCE);
    }
    let y = if x <= IMPEDANCE_MIDPOINT {
        1.0 / IMPEDANCE_MIDPOINT.powf(IMPEDANCE_POWER - 1.0) * x.powf(IMPEDANCE_POWER)
    } else {
        1.0 - 1.0 / (1.0 - IMPEDANCE_MIDPOINT).powf(IMPEDANCE_POWER - 1.0) * (1.0 - x).powf(IMPEDANCE_POWER)
    };
    (IMPEDANCE_MIN + y * (IMPEDANCE_MAX - IMPEDANCE_MIN)).clamp(MIN_IMPEDANCE, MAX_IMPEDANCE)
}

/// How far past the stop a constant `torque` into it holds the wrist at rest: where the limit's force,
/// K·d·violation/R at rest, equals the torque (d = dmax, as the violation exceeds solimp's width).
pub(super) fn resting_violation(torque: f64, inverse_inertia_at_rest: f64, timestep: f64) -> f64 {
    let (stiffness, _) = reference_gains(timestep);
    let regularizer = (1.0 - IMPEDANCE_MAX) / IMPEDANCE_MAX * inverse_inertia_at_rest;
    torque * regularizer / (stiffness * IMPEDANCE_MAX)
}

/// solref's stiffness K and damping B, both with dmax, the time constant at least twice the timestep.
fn reference_gains(timestep: f64) -> (f64, f64) {
    let time_constant = TIME_CONSTANT.max(2.0 * timestep);
    let stiffness =
        1.0 / (IMPEDANCE_MAX * IMPEDANCE_MAX * time_constant * time_constant * DAMPING_RATIO * DAMPING_RATIO);
    (stiffness, 2.0 / (IMPEDANCE_MAX * time_constant))
}

/// Whether MuJoCo has a limit row for this wrist angle: only strictly past a stop.
pub(super) fn is_past_stop(wrist_angle: f64) -> bool {
    wrist_angle.abs() > WRIST_LIMIT
}

/// What the limit row needs from the arm at the start of a physics step.
pub(super) struct WristLimitInput {
    pub wrist_angle: f64,
    pub wrist_velocity: f64,
    /// Wrist acceleration without the limit (M⁻¹ times the smooth forces).
    pub free_acceleration: f64,
    /// J M⁻¹ Jᵀ = (M⁻¹)₂₂ at the current pose.
    pub inverse_inertia: f64,
    /// (M⁻¹)₂₂ at qpos0 (MuJoCo's `dof_invweight0`).
    pub inverse_inertia_at_rest: f64,
    /// Physics timestep; MuJoCo lengthens the time constant to at least twice it.
    pub timestep: f64,
}

/// The torque the limit puts on the wrist in this step (zero inside the range).
pub(super) fn wrist_limit_torque(input: &WristLimitInput) -> f64 {
    if !is_past_stop(input.wrist_angle) {
        return 0.0;
    }
    let (distance, jacobian) = if input.wrist_angle > 0.0 {
        (WRIST_LIMIT - input.wrist_angle, -1.0)
    } else {
        (input.wrist_angle + WRIST_LIMIT, 1.0)
    };
    let imp = impedance(-distance);
    let (stiffness, damping) = reference_gains(input.timestep);
    let reference = -damping * jacobian * input.wrist_velocity - stiffness * imp * distance;
    let regularizer = ((1.0 - imp) / imp * input.inverse_inertia_at_rest).max(MIN_VALUE);
    let residual = jacobian * input.free_acceleration - reference;
    if residual >= 0.0 {
        return 0.0;
    }
    let force = -residual / (input.inverse_inertia + regularizer);
    jacobian * force
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impedance_follows_the_solimp_sigmoid() {
        assert_eq!(impedance(0.0), 0.9);
        assert!((impedance(0.0005) - 0.925).abs() < 1e-15, "midpoint halfway");
        assert_eq!(impedance(0.001), 0.95);
        assert_eq!(impedance(0.3), 0.95);
        assert!(impedance(0.00025) < impedance(0.0005) && impedance(0.0005) < impedance(0.00075));
    }

    #[test]
    fn no_torque_inside_the_range_and_a_restoring_one_beyond() {
        let base = WristLimitInput {
            wrist_angle: WRIST_LIMIT,
            wrist_velocity: 1.0,
            free_acceleration: 10.0,
            inverse_inertia: 5000.0,
            inverse_inertia_at_rest: 6000.0,
            timestep: 0.02,
        };
        assert_eq!(wrist_limit_torque(&base), 0.0, "exactly at the stop is inside the range");
        let beyond = WristLimitInput { wrist_angle: WRIST_LIMIT + 0.01, ..base };
        assert!(wrist_limit_torque(&beyond) < 0.0);
        let below = WristLimitInput { wrist_angle: -WRIST_LIMIT - 0.01, wrist_velocity: -1.0, ..beyond };
        assert!(wrist_limit_torque(&below) > 0.0);
    }
}
