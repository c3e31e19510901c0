//! The pendulum's transition and reward as pure functions, shared by the environment and by planners.

use super::params::{angle_normalize, quadrant_of, PendulumParams};
use crate::envs::Dynamics;

/// One simulator step of gym Pendulum-v0. The order matters: the reward is computed on the pre-step
/// state, θ advances with the *unclipped* new velocity, and only then is θ̇ clipped (gymnasium v1 clips
/// first, which gives different trajectories).
pub fn substep(p: &PendulumParams, state: &mut [f64; 2], action: f64) -> f64 {
    let [theta, theta_dot] = *state;
    let torque = applied_torque(p, theta, action);
    let cost = angle_normalize(theta).powi(2) + 0.1 * theta_dot.powi(2) + 0.001 * torque.powi(2);
    let accel = -3.0 * p.gravity / (2.0 * p.length) * (theta + std::f64::consts::PI).sin()
        + 3.0 / (p.mass * p.length.powi(2)) * torque;
    let new_theta_dot = theta_dot + accel * p.dt;
    state[0] = theta + new_theta_dot * p.dt;
    state[1] = new_theta_dot.clamp(-p.max_speed, p.max_speed);
    -cost
}

/// The torque that reaches the joint. The quadrant family clips first and then scales, so its effective
/// range is ±(gain·max_torque); the other variants scale first and then clip.
fn applied_torque(p: &PendulumParams, theta: f64, action: f64) -> f64 {
    match &p.quadrants {
        Some(q) => {
            let actuator = q[quadrant_of(theta)];
            action.clamp(-p.max_torque, p.max_torque) * actuator.gain * actuator.sign
        }
        None => (action * p.action_factor).clamp(-p.max_torque, p.max_torque),
    }
}

/// One environment step: `action_repeat` simulator steps with summed rewards.
pub fn env_step(p: &PendulumParams, state: &mut [f64; 2], action: f64) -> f64 {
    (0..p.action_repeat).map(|_| substep(p, state, action)).sum()
}

/// Ground-truth pendulum dynamics for planners.
#[derive(Clone, Debug)]
pub struct PendulumDynamics {
    pub params: PendulumParams,
}

impl Dynamics for PendulumDynamics {
    fn state_dim(&self) -> usize {
        2
    }

    fn action_dim(&self) -> usize {
        1
    }

    fn step(&self, state: &mut [f64], action: &[f64]) -> f64 {
        let mut s = [state[0], state[1]];
        let r = env_step(&self.params, &mut s, action[0]);
        state[0] = s[0];
        state[1] = s[1];
        r
    }
}

/// gym's pendulum reward from the pre-step state and the action, for learned models that predict the state
/// alone. Exact where one action is one simulator step and no hidden actuator scales the torque's magnitude
/// (every variant but `quadrant`): mass changes leave the cost alone, and an inverted action has the same square.
#[derive(Clone, Debug)]
pub struct PendulumReward {
    pub max_torque: f64,
}

impl PendulumReward {
    pub fn for_params(p: &PendulumParams) -> Option<Self> {
        let magnitude_kept = (p.action_factor.abs() - 1.0).abs() < 1e-12;
        (p.quadrants.is_none() && p.action_repeat == 1 && magnitude_kept)
            .then_some(PendulumReward { max_torque: p.max_torque })
    }
}

impl PendulumReward {
    pub fn reward_of(&self, state: &[f64], action: &[f64]) -> f64 {
        let torque = action[0].clamp(-self.max_torque, self.max_torque);
        -(angle_normalize(state[0]).powi(2) + 0.1 * state[1].powi(2) + 0.001 * torque.powi(2))
    }
}

/// gym's cost of the pre-step state and the commanded action, counted once per simulator step of an action
/// repeat: the swing-up objective a planner uses where the true reward depends on hidden parameters (the
/// quadrant family scales the torque, and its repeat's second state is never observed). A surrogate, named so
/// in reports; the environment's own reward is what episodes are scored by.
#[derive(Clone, Debug)]
pub struct NominalPendulumReward {
    pub max_torque: f64,
    pub action_repeat: usize,
}

impl NominalPendulumReward {
    pub fn reward_of(&self, state: &[f64], action: &[f64]) -> f64 {
        let torque = action[0].clamp(-self.max_torque, self.max_torque);
        let cost = angle_normalize(state[0]).powi(2) + 0.1 * state[1].powi(2) + 0.001 * torque.powi(2);
        -cost * self.action_repeat as f64
    }
}

#[cfg(test)]
mod reward_tests {
    use super::*;
    use crate::envs::pendulum::PendulumVariant;

    #[test]
    fn known_reward_equals_the_simulator_reward() {
        for name in ["", "light", "heavy", "inverted"] {
            let p = PendulumVariant::parse(name).unwrap().fixed_params();
            let reward = PendulumReward::for_params(&p).expect("variant has a closed-form reward");
            for (theta, speed, action) in [(3.0, 0.5, 1.5), (-0.2, -7.0, -3.0), (7.5, 2.0, 0.3)] {
                let mut s = [theta, speed];
                let r = env_step(&p, &mut s, action);
                assert!((reward.reward_of(&[theta, speed], &[action]) - r).abs() < 1e-12, "{name}");
            }
        }
        assert!(PendulumReward::for_params(&PendulumVariant::parse("quadrant").unwrap().fixed_params()).is_none());
    }
}
