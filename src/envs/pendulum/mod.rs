//! gym Pendulum-v0 and the thesis' variants: mass change, inverted actions, per-quadrant actuators.

pub mod dynamics;
pub mod params;
pub mod render;
pub mod swingup;
pub mod variant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub use dynamics::{env_step, substep, PendulumDynamics};
pub use params::{angle_normalize, quadrant_of, PendulumParams, QuadrantActuator};
pub use variant::PendulumVariant;

use crate::envs::{Dynamics, Env, EnvSpec, Step};
use crate::util::domain::Domain;

/// The widest start angle `--init-state` takes, in radians either way.
const THETA_LIMIT: f64 = 1e3;

/// How an episode starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartDistribution {
    /// θ ∼ U[−π, π], θ̇ ∼ U[−8, 8]: data collection (thesis 3.5).
    Uniform,
    /// θ ∼ U[π − 0.05, π + 0.05], θ̇ ∼ U[−0.05, 0.05]: the swing-up task from the hanging position.
    Hanging,
}

pub struct Pendulum {
    variant: PendulumVariant,
    params: PendulumParams,
    state: [f64; 2],
    start: StartDistribution,
}

impl Pendulum {
    pub fn new(variant: PendulumVariant) -> Self {
        let params = variant.fixed_params();
        Pendulum { variant, params, state: [std::f64::consts::PI, 0.0], start: StartDistribution::Uniform }
    }

    pub fn with_start(mut self, start: StartDistribution) -> Self {
        self.start = start;
        self
    }

    pub fn pendulum_params(&self) -> &PendulumParams {
        &self.params
    }

    pub fn pendulum_dynamics(&self) -> PendulumDynamics {
        PendulumDynamics { params: self.params.clone() }
    }

    pub fn set_params(&mut self, params: PendulumParams) {
        self.params = params;
    }
}

impl Env for Pendulum {
    fn spec(&self) -> EnvSpec {
        EnvSpec {
            name: self.variant.env_name(),
            state_names: vec!["theta".into(), "theta_dot".into()],
            obs_names: vec!["cos_theta".into(), "sin_theta".into(), "theta_dot".into()],
            action_low: vec![-self.params.max_torque],
            action_high: vec![self.params.max_torque],
            dt: self.params.dt * self.params.action_repeat as f64,
            angular: vec![true, false],
        }
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        use std::f64::consts::PI;
        self.state = match self.start {
            StartDistribution::Uniform => {
                [rng.random_range(-PI..PI), rng.random_range(-self.params.max_speed..self.params.max_speed)]
            }
            StartDistribution::Hanging => [rng.random_range(PI - 0.05..PI + 0.05), rng.random_range(-0.05..0.05)],
        };
        self.observe()
    }

    fn step(&mut self, action: &[f64]) -> Step {
        let reward = env_step(&self.params, &mut self.state, action[0]);
        Step { obs: self.observe(), reward, done: false }
    }

    fn state(&self) -> Vec<f64> {
        self.state.to_vec()
    }

    fn set_state(&mut self, state: &[f64]) {
        self.state = [state[0], state[1]];
    }

    /// θ is not wrapped (gym keeps it as integrated), but a start wound more than ~160 turns is none a rollout
    /// reaches and cos/sin of it keep few digits; θ̇ is clipped to ±max_speed after every step, so a faster start
    /// is no state of this pendulum.
    fn state_error(&self, state: &[f64]) -> Option<String> {
        let speed = self.params.max_speed;
        let theta = Domain::closed(-THETA_LIMIT, THETA_LIMIT).in_unit("rad").check("theta", state[0]);
        let theta_dot = Domain::closed(-speed, speed).in_unit("rad/s").check("theta_dot", state[1]);
        theta.and(theta_dot).err().map(|e| e.to_string())
    }

    fn observe(&self) -> Vec<f64> {
        let [theta, theta_dot] = self.state;
        vec![theta.cos(), theta.sin(), theta_dot]
    }

    fn params(&self) -> serde_json::Value {
        serde_json::to_value(&self.params).unwrap_or(serde_json::Value::Null)
    }

    fn sample_instance(&mut self, rng: &mut ChaCha8Rng) {
        self.params = self.variant.sample_params(rng);
    }

    fn dynamics(&self) -> Option<Box<dyn Dynamics>> {
        Some(Box::new(self.pendulum_dynamics()))
    }
}
