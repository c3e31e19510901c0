//! MountainCar over random terrain (thesis 4.5.4): a car on a 1-D track of Gaussian bumps, pushed by a
//! tangential acceleration |u| ≤ 3. The terrain is the hidden parameter: a context model has to infer the
//! ground's shape from how the car moves.

pub mod dynamics;
pub mod terrain;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub use dynamics::{MountainCarDynamics, DT, MAX_ACCEL, X_LIMIT};
pub use terrain::{Bump, Terrain, WALLS};

use crate::envs::{Dynamics, Env, EnvSpec, Step};
use crate::util::domain::Domain;

/// The fastest start `--init-state` takes, in m/s either way (see [`MountainCar::state_error`]).
const MAX_SPEED: f64 = 10.0;

pub struct MountainCar {
    dynamics: MountainCarDynamics,
    state: [f64; 2],
}

impl Default for MountainCar {
    fn default() -> Self {
        Self::new()
    }
}

impl MountainCar {
    /// The walls-only valley until `sample_instance` draws a terrain.
    pub fn new() -> Self {
        Self::with_terrain(Terrain::walls_only())
    }

    pub fn with_terrain(terrain: Terrain) -> Self {
        MountainCar { dynamics: MountainCarDynamics::new(terrain), state: [0.0, 0.0] }
    }

    pub fn terrain(&self) -> &Terrain {
        &self.dynamics.terrain
    }

    pub fn mountaincar_dynamics(&self) -> MountainCarDynamics {
        self.dynamics.clone()
    }
}

impl Env for MountainCar {
    fn spec(&self) -> EnvSpec {
        let names = vec!["x".to_string(), "x_dot".to_string()];
        EnvSpec {
            name: "mountaincar".into(),
            state_names: names.clone(),
            obs_names: names,
            action_low: vec![-MAX_ACCEL],
            action_high: vec![MAX_ACCEL],
            dt: DT,
            angular: vec![false, false],
        }
    }

    /// x ∼ U(−0.8, 0.8), ẋ ∼ U(−2, 2).
    fn reset(&mut self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        self.state = [rng.random_range(-0.8..0.8), rng.random_range(-2.0..2.0)];
        self.observe()
    }

    fn step(&mut self, action: &[f64]) -> Step {
        let reward = self.dynamics.advance(&mut self.state, action[0]);
        Step { obs: self.observe(), reward, done: false }
    }

    fn state(&self) -> Vec<f64> {
        self.state.to_vec()
    }

    fn set_state(&mut self, state: &[f64]) {
        self.state = [state[0], state[1]];
    }

    /// The car lives between the walls; its acceleration is at most about 13 m/s² on a 2 m track, so from the
    /// reset's ±2 m/s it gets little past 7.5 m/s before a wall stops it.
    fn state_error(&self, state: &[f64]) -> Option<String> {
        let x = Domain::closed(-X_LIMIT, X_LIMIT).in_unit("m").check("x", state[0]);
        let x_dot = Domain::closed(-MAX_SPEED, MAX_SPEED).in_unit("m/s").check("x_dot", state[1]);
        x.and(x_dot).err().map(|e| e.to_string())
    }

    fn observe(&self) -> Vec<f64> {
        self.state.to_vec()
    }

    /// `{"bumps": [{"loc", "height", "width"}, …]}`, the two walls last.
    fn params(&self) -> serde_json::Value {
        serde_json::to_value(&self.dynamics.terrain).unwrap_or(serde_json::Value::Null)
    }

    fn sample_instance(&mut self, rng: &mut ChaCha8Rng) {
        self.dynamics = MountainCarDynamics::new(Terrain::sample(rng));
    }

    fn dynamics(&self) -> Option<Box<dyn Dynamics>> {
        Some(Box::new(self.mountaincar_dynamics()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn sampled(seed: u64) -> MountainCar {
        let mut env = MountainCar::new();
        env.sample_instance(&mut ChaCha8Rng::seed_from_u64(seed));
        env
    }

    /// ½ẋ² + U(x) with U' = −g·h'/(1 + h'²): what the frictionless, unforced model conserves (the block's
    /// horizontal acceleration is g·sin φ·cos φ). Integrated numerically from 0.
    fn energy(terrain: &Terrain, state: &[f64]) -> f64 {
        let n = 1000;
        let dx = state[0] / n as f64;
        let force = |x: f64| {
            let s = terrain.slope(x);
            10.0 * s / (1.0 + s * s)
        };
        let potential: f64 = (0..n).map(|i| 0.5 * (force(i as f64 * dx) + force((i + 1) as f64 * dx)) * dx).sum();
        0.5 * state[1] * state[1] + potential
    }

    #[test]
    fn unforced_car_does_not_gain_energy() {
        for seed in 0..10 {
            let mut env = sampled(seed);
            let terrain = env.terrain().clone();
            env.reset(&mut ChaCha8Rng::seed_from_u64(100 + seed));
            let start = energy(&terrain, &env.state());
            let mut last = start;
            for _ in 0..400 {
                env.step(&[0.0]);
                let e = energy(&terrain, &env.state());
                assert!(e <= start + 0.02 * (1.0 + start.abs()), "seed {seed}: energy {e} from {start}");
                last = e;
            }
            assert!(last <= start + 1e-3, "seed {seed}: friction should not add energy ({last} vs {start})");
        }
    }

    #[test]
    fn oscillation_in_the_valley_slowly_loses_energy_to_friction() {
        let mut env = MountainCar::new();
        let terrain = env.terrain().clone();
        env.set_state(&[0.6, 0.0]);
        let start = energy(&terrain, &env.state());
        let mut highest = f64::NEG_INFINITY;
        let mut turns = 0;
        let mut last_v = 0.0;
        for _ in 0..1000 {
            env.step(&[0.0]);
            let s = env.state();
            highest = highest.max(energy(&terrain, &s) - start);
            turns += usize::from(s[1] * last_v < 0.0);
            last_v = s[1];
            assert!(s[0].abs() < 0.6 + 1e-9, "never higher up the wall than released: {s:?}");
        }
        let end = energy(&terrain, &env.state());
        assert!(turns >= 4, "the car swings back and forth ({turns} turns)");
        // The integrator's error shows as ~0.4 % swings; friction then takes about a third over 50 s.
        assert!(highest < 0.01 * start, "energy rose by {highest} of {start}");
        assert!(end < 0.8 * start, "friction dissipates: {end} of {start}");
    }

    #[test]
    fn pushing_accelerates_and_rest_in_a_symmetric_valley_is_rest() {
        let mut env = MountainCar::new();
        env.set_state(&[0.0, 0.0]);
        for _ in 0..10 {
            env.step(&[0.0]);
        }
        assert_eq!(env.state(), vec![0.0, 0.0], "no slope, no speed, no friction");
        env.step(&[3.0]);
        let s = env.state();
        assert!(s[0] > 0.0 && s[1] > 0.1, "{s:?}");
    }

    #[test]
    fn the_track_ends_clamp_position_and_stop_the_car() {
        let mut env = sampled(3);
        env.set_state(&[0.98, 2.0]);
        env.step(&[3.0]);
        assert_eq!(env.state(), vec![1.0, 0.0]);
        env.set_state(&[-0.98, -2.0]);
        env.step(&[-3.0]);
        assert_eq!(env.state(), vec![-1.0, 0.0]);
        env.set_state(&[-0.98, -2.0]);
        env.step(&[-300.0]);
        assert_eq!(env.state(), vec![-1.0, 0.0], "actions beyond ±3 are clipped, not rejected");
    }

    #[test]
    fn reward_is_on_the_pre_step_state() {
        let mut env = sampled(4);
        let d = env.mountaincar_dynamics();
        env.set_state(&[0.3, 1.0]);
        let step = env.step(&[1.0]);
        assert_eq!(step.reward, d.reward(0.3));
        assert!(step.reward <= 0.0);
    }

    #[test]
    fn same_seeds_same_instance_and_trajectory() {
        let run = |seed| {
            let mut env = sampled(seed);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut out = vec![env.reset(&mut rng)];
            out.extend((0..50).map(|k| env.step(&[(k as f64 * 0.37).sin() * 3.0]).obs));
            (env.params(), out)
        };
        assert_eq!(run(8), run(8));
        assert_ne!(run(8).0, run(9).0);
    }

    #[test]
    fn env_and_planner_dynamics_agree() {
        let mut env = sampled(6);
        let d = env.dynamics().unwrap();
        env.set_state(&[-0.2, 0.7]);
        let mut s = vec![-0.2, 0.7];
        for k in 0..30 {
            let a = [if k < 15 { -3.0 } else { 3.0 }];
            let r = d.step(&mut s, &a);
            let step = env.step(&a);
            assert_eq!((step.obs.clone(), step.reward), (s.clone(), r));
        }
    }

    #[test]
    fn params_round_trip_as_json() {
        let env = sampled(7);
        let back: Terrain = serde_json::from_value(env.params()).unwrap();
        assert_eq!(&back, env.terrain());
    }
}
