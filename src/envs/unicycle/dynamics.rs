//! One 10 ms step of the unicycle of thesis eq. 5.14: the heading turns first, the friction coefficient is read
//! at the current position, then position and speed are integrated with Dormand-Prince RK45 (rtol 1e-3,
//! atol 1e-6: scipy `solve_ivp`'s defaults, which the authors used), then clipped.

use std::sync::Arc;

use super::params::RobotParams;
use crate::envs::terrain::TerrainMap;
use crate::envs::Dynamics;
use crate::util::rk45;

pub const DT: f64 = 0.01;
pub const GRAVITY: f64 = 9.81;
pub const MAX_SPEED: f64 = 5.0;
pub const RTOL: f64 = 1e-3;
pub const ATOL: f64 = 1e-6;
/// Sharpness of the smooth sign in the Coulomb friction, tanh(1000 v).
const FRICTION_SHARPNESS: f64 = 1000.0;
/// Below this speed and acceleration the robot is at rest: the authors zero the acceleration there, which
/// keeps a stopped robot from creeping under the smoothed friction.
const REST: f64 = 1e-3;

/// Position and speed over one step, with heading, friction and force fixed.
#[derive(Clone, Copy)]
pub struct Motion {
    pub cos_phi: f64,
    pub sin_phi: f64,
    pub mu: f64,
    pub mass: f64,
    pub force: f64,
}

impl Motion {
    /// d/dt [x, y, v].
    pub fn derivative(&self, v: f64) -> [f64; 3] {
        let friction = -(FRICTION_SHARPNESS * v).tanh() * self.mu * self.mass * GRAVITY;
        let mut a = (self.force + friction) / self.mass;
        if v.abs() < REST && a.abs() < REST {
            a = 0.0;
        }
        [v * self.cos_phi, v * self.sin_phi, a]
    }
}

/// Above this speed tanh(1000 v) is ±1 to within 4e-9: the acceleration is constant, and below it the
/// friction turns over within a few microseconds.
const SATURATED_SPEED: f64 = 0.01;
/// Below `SATURATED_SPEED` steps stay within bands of this width, narrow enough for the error estimate to see
/// tanh(1000 v) turn (speed errors 2e-5 against a fine reference; 0.002 halves that at twice the cost).
const KINK_BAND: f64 = 0.004;

/// [x, y, v] after `duration` by adaptive RK45. Steps are kept from jumping over the friction's turn at v = 0:
/// they are cut where |v| falls to 0.01 and then cross the turn in 0.004 m/s bands (see
/// [`rk45::solve_with_regions`]). The plain controller with the thesis' tolerances, like scipy's that the
/// authors ran, is off by up to 0.3 m/s on steps where the robot reverses. If the solver gives up (stiffness near v = 0 beyond its step
/// budget), the fixed-step reference finishes the step instead, so a step always has an answer.
pub fn integrate(motion: Motion, xyv: [f64; 3], duration: f64) -> [f64; 3] {
    let region = |y: &[f64; 3]| {
        let v = y[2];
        if v.abs() > SATURATED_SPEED {
            if v > 0.0 {
                i32::MAX
            } else {
                i32::MIN
            }
        } else {
            (v / KINK_BAND).floor() as i32
        }
    };
    rk45::solve_with_regions(|y: &[f64; 3]| motion.derivative(y[2]), xyv, duration, RTOL, ATOL, region)
        .unwrap_or_else(|_| integrate_fixed(motion, xyv, duration, 100_000))
}

/// Classical RK4 with `steps` equal steps: the fine reference the adaptive solver is tested against.
pub fn integrate_fixed(motion: Motion, xyv: [f64; 3], duration: f64, steps: usize) -> [f64; 3] {
    let h = duration / steps as f64;
    let mut y = xyv;
    let add = |y: [f64; 3], k: [f64; 3], s: f64| [y[0] + s * k[0], y[1] + s * k[1], y[2] + s * k[2]];
    for _ in 0..steps {
        let k1 = motion.derivative(y[2]);
        let k2 = motion.derivative(add(y, k1, h / 2.0)[2]);
        let k3 = motion.derivative(add(y, k2, h / 2.0)[2]);
        let k4 = motion.derivative(add(y, k3, h)[2]);
        for i in 0..3 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    y
}

/// The unicycle of one instance (robot and map) as pure dynamics. State [x, y, v, φ]; action [throttle,
/// steer] clipped to [−1, 1]; reward −½·throttle², the energy term of eq. 5.13 (the goal term belongs to a
/// task, not to the robot).
#[derive(Clone, Debug)]
pub struct UnicycleDynamics {
    pub robot: RobotParams,
    pub map: Arc<TerrainMap>,
}

impl UnicycleDynamics {
    pub fn advance(&self, state: &mut [f64], action: &[f64]) -> f64 {
        let throttle = clip_action(action[0]);
        let steer = clip_action(action[1]);
        let phi = (state[3] + steer * self.robot.k_steer).rem_euclid(std::f64::consts::TAU);
        let motion = Motion {
            cos_phi: phi.cos(),
            sin_phi: phi.sin(),
            mu: self.map.friction_at(state[0], state[1]),
            mass: self.robot.mass,
            force: throttle * self.robot.k_throttle,
        };
        let [x, y, v] = integrate(motion, [state[0], state[1], state[2]], DT);
        state[0] = x.clamp(0.0, 1.0);
        state[1] = y.clamp(0.0, 1.0);
        state[2] = v.clamp(-MAX_SPEED, MAX_SPEED);
        state[3] = phi;
        -0.5 * throttle * throttle
    }
}

/// NaN becomes 0 (no input) rather than poisoning the state.
pub fn clip_action(a: f64) -> f64 {
    if a.is_nan() {
        0.0
    } else {
        a.clamp(-1.0, 1.0)
    }
}

impl Dynamics for UnicycleDynamics {
    fn state_dim(&self) -> usize {
        4
    }

    fn action_dim(&self) -> usize {
        2
    }

    fn step(&self, state: &mut [f64], action: &[f64]) -> f64 {
        self.advance(state, action)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::terrain::{generate_map, MAP_SIZE};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn flat_map(color: [u8; 3]) -> Arc<TerrainMap> {
        let rgb = color.iter().copied().cycle().take(MAP_SIZE * MAP_SIZE * 3).collect();
        Arc::new(TerrainMap::from_rgb(rgb, "flat").unwrap())
    }

    fn robot() -> RobotParams {
        RobotParams { mass: 2.0, k_throttle: 700.0, k_steer: 0.5 }
    }

    #[test]
    fn with_zero_throttle_the_robot_stops_and_stays_stopped() {
        for color in [[230, 230, 230], [120, 40, 200], [0, 0, 0]] {
            let dynamics = UnicycleDynamics { robot: robot(), map: flat_map(color) };
            let mut state = [0.5, 0.5, 4.0, 0.3];
            let mut speeds = Vec::new();
            for _ in 0..800 {
                dynamics.advance(&mut state, &[0.0, 0.2]);
                speeds.push(state[2]);
            }
            // Friction decelerates at μ·g ≥ 0.98 m/s², so 4 m/s is gone within ~4 s; then the robot stays put
            // (the smoothed friction leaves a residue of micrometres per second, never a creep).
            let rest = &speeds[450..];
            assert!(rest.iter().all(|v| v.abs() < 1e-5), "{color:?}: {:?}", &rest[..3]);
            let moving = speeds.iter().take_while(|v| v.abs() > 1e-3).count();
            assert!(speeds[..moving].windows(2).all(|w| w[1].abs() <= w[0].abs()), "speed only decays");
        }
    }

    #[test]
    fn rk45_agrees_with_a_fine_fixed_step_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut worst = 0.0f64;
        for _ in 0..300 {
            let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let mass = rng.random_range(1.0..4.0);
            let motion = Motion {
                cos_phi: phi.cos(),
                sin_phi: phi.sin(),
                mu: crate::envs::terrain::friction_of_color(rng.random()),
                mass,
                force: rng.random_range(-1.0..1.0) * rng.random_range(500.0..1000.0),
            };
            // Include starts near rest, where the smoothed friction is stiff.
            let v = if rng.random_bool(0.3) { rng.random_range(-0.01..0.01) } else { rng.random_range(-5.0..5.0) };
            let start = [0.5, 0.5, v];
            let adaptive = integrate(motion, start, DT);
            let reference = integrate_fixed(motion, start, DT, 20_000);
            for i in 0..3 {
                worst = worst.max((adaptive[i] - reference[i]).abs());
            }
        }
        // Measured 1e-5 (speed) and 1e-7 (position); without the banding across v = 0, 0.34 m/s.
        assert!(worst < 1e-4, "largest deviation {worst}");
    }

    #[test]
    fn positions_stay_in_the_unit_square_and_speed_within_limits() {
        let dynamics = UnicycleDynamics {
            robot: RobotParams { mass: 1.0, k_throttle: 1000.0, k_steer: 0.7 },
            map: Arc::new(generate_map(0, 0)),
        };
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut state = [0.02, 0.98, 0.0, 1.0];
        for _ in 0..2000 {
            let action = [rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5)];
            let reward = dynamics.advance(&mut state, &action);
            assert!((0.0..=1.0).contains(&state[0]) && (0.0..=1.0).contains(&state[1]), "{state:?}");
            assert!(state[2].abs() <= MAX_SPEED && (0.0..std::f64::consts::TAU).contains(&state[3]));
            assert!((-0.5..=0.0).contains(&reward));
        }
    }

    #[test]
    fn steering_turns_the_heading_by_the_gain_before_moving() {
        let dynamics = UnicycleDynamics { robot: robot(), map: flat_map([255, 255, 255]) };
        let mut state = [0.5, 0.5, 2.0, 0.0];
        dynamics.advance(&mut state, &[0.0, 1.0]);
        assert!((state[3] - 0.5).abs() < 1e-15);
        // Moving along the new heading: dy/dx = tan(0.5).
        assert!(((state[1] - 0.5) / (state[0] - 0.5) - 0.5f64.tan()).abs() < 1e-9);
    }
}
