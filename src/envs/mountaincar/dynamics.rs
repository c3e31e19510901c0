//! One MountainCar step as a pure function: a block sliding with friction on the local incline, the incline
//! averaged between here and the predicted next point (Heun-like, thesis 4.5.4).

use super::terrain::Terrain;
use crate::envs::Dynamics;

pub const DT: f64 = 0.05;
const GRAVITY: f64 = -10.0;
const FRICTION: f64 = 0.001;
pub const MAX_ACCEL: f64 = 3.0;
/// The track ends here; the car stops dead at either end.
pub const X_LIMIT: f64 = 1.0;

/// numpy's sign: 0 at 0, so a car at rest feels no friction (`f64::signum(0.0)` is 1).
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The terrain with its reward reference, computed once per instance.
#[derive(Clone, Debug)]
pub struct MountainCarDynamics {
    pub terrain: Terrain,
    max_height: f64,
}

impl MountainCarDynamics {
    pub fn new(terrain: Terrain) -> Self {
        let max_height = terrain.grid_max_height();
        MountainCarDynamics { terrain, max_height }
    }

    /// −(h(x) − max h)²: how far below the top the car is. Depends on the state alone.
    pub fn reward(&self, x: f64) -> f64 {
        -(self.terrain.height(x) - self.max_height).powi(2)
    }

    /// Advances `[x, ẋ]` by one step; returns the reward of the pre-step state (the authors' convention).
    pub fn advance(&self, state: &mut [f64; 2], action: f64) -> f64 {
        let u = action.clamp(-MAX_ACCEL, MAX_ACCEL);
        let [x, v] = *state;
        let reward = self.reward(x);
        let mut slope = self.terrain.slope(x);
        let (mut accel, mut x_new) = (0.0, x);
        // The second pass redoes the step on the slope averaged with the first pass's landing point.
        for _ in 0..2 {
            let angle = slope.atan();
            let tangential = GRAVITY * angle.sin() + u;
            let friction = (GRAVITY * angle.cos() * FRICTION).abs().min(tangential.abs());
            accel = (tangential - sign(v) * friction) * angle.cos();
            x_new = x + DT * v + 0.5 * accel * DT * DT;
            slope = 0.5 * slope + 0.5 * self.terrain.slope(x_new);
        }
        let mut v_new = v + accel * DT;
        if x_new >= X_LIMIT {
            (x_new, v_new) = (X_LIMIT, 0.0);
        }
        if x_new <= -X_LIMIT {
            (x_new, v_new) = (-X_LIMIT, 0.0);
        }
        *state = [x_new, v_new];
        reward
    }
}

impl Dynamics for MountainCarDynamics {
    fn state_dim(&self) -> usize {
        2
    }

    fn action_dim(&self) -> usize {
        1
    }

    fn step(&self, state: &mut [f64], action: &[f64]) -> f64 {
        let mut s = [state[0], state[1]];
        let r = self.advance(&mut s, action[0]);
        state.copy_from_slice(&s);
        r
    }
}
