//! The unicycle robot of TRADYN (thesis 5.5.1) on a terrain map: throttle and steer in [−1, 1], friction from
//! the ground's colour, robot parameters (Table 5.1) and the map drawn per instance. The robot observes
//! [x, y, v/5, cos φ, sin φ] and the terrain feature τ under it.

pub mod dynamics;
pub mod params;

use std::sync::Arc;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub use dynamics::{clip_action, UnicycleDynamics, DT, MAX_SPEED};
pub use params::RobotParams;

use super::terrain::TerrainMap;
use super::{Dynamics, Env, EnvSpec, Exploration, Step};
use crate::util::domain::number;

/// The maps an instance may be drawn on: one map, or one split of a map set.
#[derive(Debug)]
pub struct UnicycleTerrain {
    pub maps: Vec<Arc<TerrainMap>>,
}

impl UnicycleTerrain {
    pub fn new(maps: Vec<TerrainMap>) -> Self {
        assert!(!maps.is_empty(), "a unicycle terrain needs at least one map");
        UnicycleTerrain { maps: maps.into_iter().map(Arc::new).collect() }
    }
}

impl PartialEq for UnicycleTerrain {
    fn eq(&self, other: &Self) -> bool {
        self.maps.len() == other.maps.len()
            && self.maps.iter().zip(&other.maps).all(|(a, b)| a.crc32 == b.crc32 && a.name == b.name)
    }
}

/// Names of the observation's features: the robot's, then the terrain's (`TERRAIN_FEATURES` of them).
pub const OBSERVATION_NAMES: [&str; 8] = ["x", "y", "v_over_5", "cos_phi", "sin_phi", "tau_r", "tau_g", "tau_b"];
pub const TERRAIN_FEATURES: usize = 3;

/// What the robot observes in state [x, y, v, φ] on `map`: [x, y, v/5, cos φ, sin φ, τ(x, y)].
pub fn observation(state: &[f64], map: &TerrainMap) -> Vec<f64> {
    let [x, y, v, phi] = [state[0], state[1], state[2], state[3]];
    let tau = map.feature_at(x, y);
    vec![x, y, v / MAX_SPEED, phi.cos(), phi.sin(), tau[0], tau[1], tau[2]]
}

/// Exploration noise of the authors' data: Gaussian colored noise, β = 0.5, std 0.5, drawn as one
/// 1000-sample sequence per action dimension and clipped.
pub const EXPLORATION: Exploration = Exploration::Colored { beta: 0.5, std: 0.5, min_len: 1000 };

pub struct Unicycle {
    terrain: Arc<UnicycleTerrain>,
    dynamics: UnicycleDynamics,
    state: [f64; 4],
}

impl Unicycle {
    /// The nominal robot on the terrain's first map until `sample_instance` draws one.
    pub fn new(terrain: Arc<UnicycleTerrain>) -> Self {
        let map = terrain.maps[0].clone();
        Unicycle {
            terrain,
            dynamics: UnicycleDynamics { robot: RobotParams::nominal(), map },
            state: [0.5, 0.5, 0.0, 0.0],
        }
    }

    pub fn unicycle_dynamics(&self) -> &UnicycleDynamics {
        &self.dynamics
    }
}

impl Env for Unicycle {
    fn spec(&self) -> EnvSpec {
        let names = |list: &[&str]| list.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        EnvSpec {
            name: "unicycle".into(),
            state_names: names(&["x", "y", "v", "phi"]),
            obs_names: names(&OBSERVATION_NAMES),
            action_low: vec![-1.0, -1.0],
            action_high: vec![1.0, 1.0],
            dt: DT,
            angular: vec![false, false, false, true],
        }
    }

    /// x, y ∼ U[0, 1], v ∼ U[−5, 5], φ ∼ U[0, 2π) (the authors' reset).
    fn reset(&mut self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        self.state = [
            rng.random_range(0.0..1.0),
            rng.random_range(0.0..1.0),
            rng.random_range(-MAX_SPEED..MAX_SPEED),
            rng.random_range(0.0..std::f64::consts::TAU),
        ];
        self.observe()
    }

    fn step(&mut self, action: &[f64]) -> Step {
        let reward = self.dynamics.advance(&mut self.state, action);
        Step { obs: self.observe(), reward, done: false }
    }

    fn state(&self) -> Vec<f64> {
        self.state.to_vec()
    }

    /// Positions outside [0, 1]² and speeds beyond ±5 are clipped, as every step would (`state_error` tells
    /// callers that take a start state from a user).
    fn set_state(&mut self, state: &[f64]) {
        self.state = [
            state[0].clamp(0.0, 1.0),
            state[1].clamp(0.0, 1.0),
            state[2].clamp(-MAX_SPEED, MAX_SPEED),
            state[3].rem_euclid(std::f64::consts::TAU),
        ];
    }

    fn observe(&self) -> Vec<f64> {
        observation(&self.state, &self.dynamics.map)
    }

    fn params(&self) -> serde_json::Value {
        let robot = &self.dynamics.robot;
        serde_json::json!({
            "mass": robot.mass,
            "k_throttle": robot.k_throttle,
            "k_steer": robot.k_steer,
            "map": self.dynamics.map.name,
            "map_crc32": self.dynamics.map.crc32,
        })
    }

    /// A robot from Table 5.1's ranges on a uniformly chosen map of the terrain.
    fn sample_instance(&mut self, rng: &mut ChaCha8Rng) {
        let robot = RobotParams::sample(rng);
        let index = if self.terrain.maps.len() > 1 { rng.random_range(0..self.terrain.maps.len()) } else { 0 };
        self.dynamics = UnicycleDynamics { robot, map: self.terrain.maps[index].clone() };
    }

    fn dynamics(&self) -> Option<Box<dyn Dynamics>> {
        Some(Box::new(self.dynamics.clone()))
    }

    fn state_error(&self, state: &[f64]) -> Option<String> {
        let [x, y, v] = [state[0], state[1], state[2]];
        if !((0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y)) {
            return Some(format!("the position ({}, {}) is outside the map [0, 1]²", number(x), number(y)));
        }
        if v.abs() > MAX_SPEED {
            return Some(format!("the speed {} is beyond ±{MAX_SPEED} m/s", number(v)));
        }
        None
    }

    fn exploration(&self) -> Exploration {
        EXPLORATION
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::terrain::generate_map;
    use rand::SeedableRng;

    fn env(maps: usize) -> Unicycle {
        let maps = (0..maps as u64).map(|i| generate_map(1, i)).collect();
        Unicycle::new(Arc::new(UnicycleTerrain::new(maps)))
    }

    #[test]
    fn observations_carry_the_scaled_speed_heading_and_terrain_feature() {
        let mut u = env(1);
        u.set_state(&[0.25, 0.75, 2.5, std::f64::consts::FRAC_PI_2]);
        let obs = u.observe();
        assert_eq!(&obs[..3], &[0.25, 0.75, 0.5]);
        assert!(obs[3].abs() < 1e-15 && (obs[4] - 1.0).abs() < 1e-15);
        let tau = u.unicycle_dynamics().map.feature_at(0.25, 0.75);
        assert_eq!(&obs[5..], &tau);
        assert_eq!(u.spec().obs_names.len(), obs.len());
    }

    #[test]
    fn instances_draw_robots_in_table_5_1_and_maps_from_the_terrain() {
        let mut u = env(3);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut maps = std::collections::HashSet::new();
        for _ in 0..40 {
            u.sample_instance(&mut rng);
            let p = u.params();
            let mass = p["mass"].as_f64().unwrap();
            let k_steer = p["k_steer"].as_f64().unwrap();
            assert!((1.0..4.0).contains(&mass) && (params::K_STEER.0..params::K_STEER.1).contains(&k_steer));
            maps.insert(p["map"].as_str().unwrap().to_string());
        }
        assert_eq!(maps.len(), 3);
    }
}
