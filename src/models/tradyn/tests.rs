use std::sync::Arc;

use burn::tensor::Tensor;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::navigation::{navigate, NavigationObjective, NavigationSettings, NavigationTask};
use crate::control::BatchDynamics;
use crate::control::Objective;
use crate::envs::terrain::generate_map;
use crate::envs::unicycle::{RobotParams, Unicycle, UnicycleDynamics, UnicycleTerrain};
use crate::envs::Env;
use crate::models::context_net::config::{ContextConfig, EnvFamily, Preset};
use crate::models::context_net::fast::{FastContextModel, LocalFeatures};
use crate::models::context_net::net::{param_name, ContextNet};
use crate::nn::tensor::{inference_device, tensor, values};
use crate::nn::ParamSet;
use crate::run::NullMonitor;

/// A smooth stand-in for a map, so the test sees the lookup follow the predicted position.
struct Waves;

impl LocalFeatures for Waves {
    fn at(&self, predicted: &[f32], out: &mut [f32]) {
        let (x, y) = (predicted[0], predicted[1]);
        out.copy_from_slice(&[x.sin(), y.cos(), x * y]);
    }
}

#[test]
fn fast_path_reads_the_terrain_at_every_predicted_position_like_the_burn_network() {
    let mut config = ContextConfig::preset(Preset::Small, EnvFamily::Control);
    (config.embedding, config.hidden_units, config.transition_features, config.latent_dim) = (16, 16, 8, 2);
    let (s, a, local, rows, horizon) = (8, 2, 3, 4, 5);
    let device = inference_device();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let net = ContextNet::init(&config, s, a, local, &device, &mut rng);
    let mut params = ParamSet::<f32>::from_module(&net, param_name);
    params.tensors.iter_mut().flat_map(|t| t.values.iter_mut()).for_each(|v| *v = rng.random_range(-0.5..0.5));
    let net = params.load_into(net, &device).unwrap();
    let fast = FastContextModel::from_params(&params).unwrap();
    assert_eq!((fast.state_dim, fast.predicted_dim, fast.local_dim), (8, 5, 3));

    let mut sample = |n: usize| -> Vec<f32> { (0..n).map(|_| rng.random_range(-1.0..1.0)).collect() };
    let init = sample(s);
    let actions = sample(rows * horizon * a);
    let betas = sample(rows * config.latent_dim);
    let mut out = vec![0.0; rows * horizon * s];
    fast.rollout_means(&init, &actions, &betas, rows, horizon, Some(&Waves), &mut out, &mut Default::default());

    let ctx = net.embed_context(tensor(betas, [rows, config.latent_dim], &device));
    let mut h = net.embed_state(tensor(init[..5].repeat(rows), [rows, 5], &device));
    let mut tau = vec![0.0f32; rows * local];
    for r in 0..rows {
        Waves.at(&init[..5], &mut tau[r * local..(r + 1) * local]);
    }
    for t in 0..horizon {
        let act: Vec<f32> =
            (0..rows).flat_map(|r| actions[(r * horizon + t) * a..(r * horizon + t + 1) * a].to_vec()).collect();
        let terrain = net.embed_terrain(tensor(tau.clone(), [rows, local], &device)).unwrap();
        let x = Tensor::cat(vec![ctx.clone(), net.embed_action(tensor(act, [rows, a], &device)), terrain], 1);
        h = net.gru.forward(x, h);
        let mean = values(&net.decode(h.clone()).0);
        for r in 0..rows {
            let got = &out[(r * horizon + t) * s..(r * horizon + t + 1) * s];
            let predicted = &mean[r * 5..(r + 1) * 5];
            for (g, e) in got[..5].iter().zip(predicted) {
                assert!((g - e).abs() <= 1e-3 * (1.0 + e.abs()), "step {t} row {r}: {g} vs {e}");
            }
            Waves.at(predicted, &mut tau[r * local..(r + 1) * local]);
            for (g, e) in got[5..].iter().zip(&tau[r * local..(r + 1) * local]) {
                assert!((g - e).abs() <= 1e-3, "terrain at step {t}: {g} vs {e}");
            }
        }
    }
}

fn robot_on_one_map() -> (Unicycle, UnicycleDynamics) {
    let map = generate_map(3, 0);
    let env = Unicycle::new(Arc::new(UnicycleTerrain::new(vec![map])));
    let dynamics = UnicycleDynamics { robot: RobotParams::nominal(), ..env.unicycle_dynamics().clone() };
    (env, dynamics)
}

#[test]
fn the_distance_term_is_normalized_over_the_candidates() {
    let (_, dynamics) = robot_on_one_map();
    let init = [0.5, 0.5, 0.0, 0.0];
    let objective = NavigationObjective { dynamics: &dynamics, init: &init, goal: [0.8, 0.5] };
    // Three zero-throttle candidates (no energy, the robot stays) and full throttle straight on, 4 steps.
    let horizon = 4;
    let mut candidates = vec![0.0; 4 * horizon * 2];
    for t in 0..horizon {
        candidates[3 * horizon * 2 + t * 2] = 1.0;
    }
    let mut costs = [0.0; 4];
    objective.costs(&candidates, horizon, &mut costs);
    // Distances: three equal, one smaller; their z-scores are ±√3 and 1/√3 around a mean of 0.
    let z_far = 1.0 / 3f64.sqrt();
    for c in &costs[..3] {
        assert!((c - z_far).abs() < 1e-9, "{costs:?}");
    }
    let energy = 0.5 * horizon as f64;
    assert!((costs[3] - (energy - 3f64.sqrt())).abs() < 1e-9, "{costs:?}");
    // All candidates alike: no distance preference at all, only energy.
    let mut same = [0.0; 2];
    objective.costs(&candidates[..2 * horizon * 2], horizon, &mut same);
    assert_eq!(same, [0.0, 0.0]);
}

#[test]
fn the_oracle_planner_drives_the_simulated_robot_to_a_nearby_goal() {
    let (mut env, dynamics) = robot_on_one_map();
    env.set_state(&[0.5, 0.5, 0.0, 0.0]);
    let mut settings = NavigationSettings::thesis();
    // Small, because the simulator is slow near rest (every step brackets the friction kink) and CEM tries many
    // reversals there.
    (settings.steps, settings.horizon) = (20, 10);
    (settings.cem.candidates, settings.cem.elites, settings.cem.iterations) = (60, 8, 4);
    let task = NavigationTask { start: [0.3, 0.4, 1.0], goal: [0.38, 0.5] };
    let mut steps = 0;
    let episode = navigate(&mut env, &dynamics, &task, &settings, 5, &NullMonitor, |s| {
        assert_eq!(s.planned.len(), settings.horizon.min(settings.steps - s.t) * dynamics.state_dim());
        steps += 1;
    })
    .unwrap();
    assert_eq!((steps, episode.rollout.len()), (20, 20));
    assert!(episode.success, "final distance {}", episode.final_distance);
    let energy: f64 = episode.rollout.actions.iter().map(|a| a[0].clamp(-1.0, 1.0).powi(2)).sum();
    assert!((episode.energy - energy).abs() < 1e-12 && energy > 0.0);
    // The same seed plans the same actions.
    let again = navigate(&mut env, &dynamics, &task, &settings, 5, &NullMonitor, |_| {}).unwrap();
    assert_eq!(again.rollout, episode.rollout);
}

#[test]
fn tasks_off_the_map_are_refused() {
    let bad_start = NavigationTask { start: [1.2, 0.5, 0.0], goal: [0.5, 0.5] };
    assert!(bad_start.validate().unwrap_err().to_string().contains("[0, 1]²"));
    let bad_goal = NavigationTask { start: [0.2, 0.5, 0.0], goal: [0.5, f64::NAN] };
    assert!(bad_goal.validate().unwrap_err().to_string().contains("goal"));
}
