//! The synthetic training inputs the benchmarks share, so that `training_steps` times exactly what the
//! per-method benches time. Training speed does not depend on what the numbers mean. Each bench uses a part.
#![allow(dead_code)]

use mbrl::data::ball_io::Recording;
use mbrl::data::collect_ball::{collect_ball, BallCollectSettings};
use mbrl::envs::ball::Orientation;
use mbrl::models::context::data::{ContextData, Episode, InstancePair};
use mbrl::models::pets::data::Transitions;
use mbrl::nn::features::{feature_dim, features};
use mbrl::rl::sac::{SacConfig, TransitionBatch};
use mbrl::run::NullMonitor;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The pendulum's angle enters PETS through cos/sin; its velocity as it is.
pub const PENDULUM_ANGULAR: [bool; 2] = [true, false];

/// `n` random pendulum-like transitions for PETS: features of (θ, θ̇, torque) and the state change.
pub fn pets_transitions(n: usize) -> Transitions {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let angular = &PENDULUM_ANGULAR;
    let mut t = Transitions { input_dim: feature_dim(angular, 1), target_dim: 2, ..Default::default() };
    for _ in 0..n {
        let s = [rng.random_range(-std::f64::consts::PI..std::f64::consts::PI), rng.random_range(-8.0..8.0)];
        features(&s, &[rng.random_range(-2.0..2.0)], angular, &mut t.inputs);
        t.targets.extend([rng.random_range(-0.4f32..0.4), rng.random_range(-1.0f32..1.0)]);
    }
    t
}

/// The pendulum's state (cos θ, sin θ, θ̇) and action sizes, as the context model sees them.
pub const CONTEXT_STATE: usize = 3;
pub const CONTEXT_ACTION: usize = 1;

/// `instances` random pendulum-shaped rollout pairs of `len` steps for the context model.
pub fn context_data(instances: usize, len: usize) -> ContextData {
    let (state, action) = (CONTEXT_STATE, CONTEXT_ACTION);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut episode = || Episode {
        states: (0..(len + 1) * state).map(|_| rng.random_range(-1.0..1.0)).collect(),
        actions: (0..len * action).map(|_| rng.random_range(-2.0..2.0)).collect(),
        len,
    };
    let pairs = (0..instances).map(|_| InstancePair { target: episode(), source: episode() }).collect();
    ContextData { state_dim: state, action_dim: action, local_dim: 0, pairs }
}

/// SEADS' Cursor-LightsOut network input: cursor 2 + board 25 + remaining time 1 + one-hot skill 25.
pub const SAC_OBS: usize = 53;

/// SAC at SEADS' Cursor-LightsOut sizes: action 3 (dx, dy, push), hidden [256, 256].
pub fn sac_config() -> SacConfig {
    SacConfig::new(SAC_OBS, vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0])
}

/// A replay batch of `rows` random Cursor-LightsOut transitions.
pub fn sac_batch(rng: &mut ChaCha8Rng, rows: usize) -> TransitionBatch {
    let mut uniform = |n: usize, lo: f32, hi: f32| (0..n).map(|_| rng.random_range(lo..hi)).collect::<Vec<f32>>();
    TransitionBatch {
        rows,
        obs: uniform(rows * SAC_OBS, 0.0, 1.0),
        actions: uniform(rows * 3, -0.2, 0.2),
        rewards: uniform(rows, -2.0, 1.0),
        next_obs: uniform(rows * SAC_OBS, 0.0, 1.0),
        done: uniform(rows, 0.0, 1.0).into_iter().map(|x| (x < 0.1) as u8 as f32).collect(),
    }
}

/// 40 simulated table-tennis trajectories, enough for the EKF's batch of 64 chunks of 50 frames.
pub fn ball_recordings() -> Vec<Recording> {
    let settings = BallCollectSettings {
        trajectories: 40,
        orientation: Orientation::Default,
        augment_rotations: 0,
        seed: 1,
        command_line: String::new(),
    };
    collect_ball(&settings, &NullMonitor).expect("the simulated ball collects").recordings
}
