use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::config::{ContextConfig, EnvFamily, Preset};
use super::data::{ContextData, Episode, InstancePair};
use super::fast::{gaussian_entropy, FastContextModel};
use super::net::{param_name, ContextNet};
use super::train::ContextTrainer;
use crate::nn::tensor::{inference_device, mask, tensor, values};
use crate::nn::ParamSet;
use crate::train::TrainingMethod;

fn tiny_config() -> ContextConfig {
    let mut c = ContextConfig::preset(Preset::Small, EnvFamily::Control);
    c.embedding = 16;
    c.hidden_units = 16;
    c.transition_features = 8;
    c.latent_dim = 2;
    c.batch_size = 8;
    c.chunk_states = 6;
    c.context_max = 4;
    c
}

/// A trained-looking network: weights of unit scale rather than the small initial ones.
fn random_net(config: &ContextConfig, s: usize, a: usize, seed: u64) -> (ContextNet, ParamSet) {
    let device = inference_device();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let net = ContextNet::init(config, s, a, 0, &device, &mut rng);
    let mut params = ParamSet::<f32>::from_module(&net, param_name);
    params.tensors.iter_mut().flat_map(|t| t.values.iter_mut()).for_each(|v| *v = rng.random_range(-0.5..0.5));
    (params.load_into(net, &device).unwrap(), params)
}

fn close(a: &[f32], b: &[f32], tol: f32) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() <= tol * (1.0 + y.abs()), "{x} vs {y}");
    }
}

#[test]
fn fast_path_matches_the_burn_network() {
    let config = tiny_config();
    let (s, a, rows, horizon) = (3, 1, 5, 4);
    let (net, params) = random_net(&config, s, a, 1);
    let fast = FastContextModel::from_params(&params).unwrap();
    let device = inference_device();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut sample = |n: usize| -> Vec<f32> { (0..n).map(|_| rng.random_range(-1.5..1.5)).collect() };

    // Beliefs of a set.
    let set = sample(3 * (2 * s + a));
    let pooled_burn = net.pool(tensor(set.clone(), [1, 3, 2 * s + a], &device), mask(vec![true; 3], [1, 3], &device));
    let belief_burn = net.belief(pooled_burn.clone());
    let pooled = fast.pool(&set);
    close(&pooled, &values(&pooled_burn), 1e-4);
    let belief = fast.belief(&pooled, 1);
    close(&belief.mean, &values(&belief_burn.mean), 1e-4);
    close(&belief.std, &values(&belief_burn.std), 1e-4);

    // Mean rollouts: the GRU driven from the embedded start state with one β per row.
    let init = sample(s);
    let actions = sample(rows * horizon * a);
    let betas = sample(rows * config.latent_dim);
    let mut out = vec![0.0; rows * horizon * s];
    fast.rollout_means(&init, &actions, &betas, rows, horizon, None, &mut out, &mut Default::default());
    let ctx = net.embed_context(tensor(betas.clone(), [rows, config.latent_dim], &device));
    let mut h = net.embed_state(tensor(init.repeat(rows), [rows, s], &device));
    for t in 0..horizon {
        let act: Vec<f32> =
            (0..rows).flat_map(|r| actions[(r * horizon + t) * a..(r * horizon + t + 1) * a].to_vec()).collect();
        let x = burn::tensor::Tensor::cat(vec![ctx.clone(), net.embed_action(tensor(act, [rows, a], &device))], 1);
        h = net.gru.forward(x, h);
        let (mean, _) = net.decode(h.clone());
        let expected = values(&mean);
        let got: Vec<f32> =
            (0..rows).flat_map(|r| out[(r * horizon + t) * s..(r * horizon + t + 1) * s].to_vec()).collect();
        close(&got, &expected, 1e-3);
    }
}

#[test]
fn context_std_never_grows_when_a_transition_is_added() {
    // Property over random networks and random sets: eq. 4.26 holds by construction, whatever the weights.
    let config = tiny_config();
    let (s, a) = (3, 1);
    let d = 2 * s + a;
    for seed in 0..20 {
        let (_, params) = random_net(&config, s, a, 100 + seed);
        let fast = FastContextModel::from_params(&params).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut set: Vec<f32> = Vec::new();
        let mut previous = fast.belief(&fast.pool(&set), 1).std;
        for _ in 0..12 {
            set.extend((0..d).map(|_| rng.random_range(-3.0f32..3.0)));
            let std = fast.belief(&fast.pool(&set), 1).std;
            for (now, before) in std.iter().zip(&previous) {
                // Monotone in exact arithmetic; the GEMM may round a sum of unchanged terms by an ulp.
                assert!(*now <= before * (1.0 + 1e-6), "std grew from {before} to {now} (seed {seed})");
            }
            previous = std;
        }
    }
}

#[test]
fn entropy_after_an_imagined_rollout_matches_pooling_it_by_hand() {
    let config = tiny_config();
    let (s, a, horizon) = (3, 1, 3);
    let (_, params) = random_net(&config, s, a, 9);
    let fast = FastContextModel::from_params(&params).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    let base: Vec<f32> = (0..2 * (2 * s + a)).map(|_| rng.random_range(-1.0..1.0)).collect();
    let init: Vec<f32> = (0..s).map(|_| rng.random_range(-1.0..1.0)).collect();
    let actions: Vec<f32> = (0..horizon * a).map(|_| rng.random_range(-2.0..2.0)).collect();
    let states: Vec<f32> = (0..horizon * s).map(|_| rng.random_range(-1.0..1.0)).collect();
    let mut out = [0.0];
    fast.entropy_after(&fast.pool(&base), &init, &actions, &states, 1, horizon, &mut out, &mut Default::default());
    let mut all = base.clone();
    let start = fast.reconstruct(&init);
    for t in 0..horizon {
        all.extend_from_slice(if t == 0 { &start } else { &states[(t - 1) * s..t * s] });
        all.extend_from_slice(&actions[t * a..(t + 1) * a]);
        all.extend_from_slice(&states[t * s..(t + 1) * s]);
    }
    let expected = gaussian_entropy(&fast.belief(&fast.pool(&all), 1).std);
    assert!((out[0] - expected).abs() < 1e-5, "{} vs {expected}", out[0]);
}

/// Toy-like data: s' = A s + [α, 0] u for |u| < 1 (no noise), α per instance.
fn toy_like(instances: usize, len: usize, seed: u64) -> ContextData {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let episode = |alpha: f32, rng: &mut ChaCha8Rng| {
        let mut x = [rng.random_range(-1.0f32..1.0), rng.random_range(-1.0f32..1.0)];
        let (mut states, mut actions) = (x.to_vec(), Vec::new());
        for _ in 0..len {
            let u: f32 = rng.random_range(-2.0..2.0);
            let squash = (1.0 - u.abs()).max(0.0);
            x = [0.8 * x[0] + 0.2 * x[1] + alpha * squash, -0.2 * x[0] + 0.8 * x[1]];
            states.extend_from_slice(&x);
            actions.push(u);
        }
        Episode { states, actions, len }
    };
    let pairs = (0..instances)
        .map(|_| {
            let alpha = rng.random_range(-1.0..1.0);
            InstancePair { target: episode(alpha, &mut rng), source: episode(alpha, &mut rng) }
        })
        .collect();
    ContextData { state_dim: 2, action_dim: 1, local_dim: 0, pairs }
}

#[test]
fn training_lowers_the_loss_and_resumes_identically() {
    let mut config = tiny_config();
    config.constant_variance = true;
    config.latent_dim = 1;
    let data = toy_like(40, 12, 3);
    let (train, valid) = data.split(0.2, 1);
    let mut trainer = ContextTrainer::new(config.clone(), 7, train.clone(), valid.clone()).unwrap();
    let first = trainer.validate().unwrap().unwrap();
    for step in 1..=300 {
        let loss = trainer.step(step).unwrap();
        assert!(loss.is_finite());
    }
    let later = trainer.validate().unwrap().unwrap();
    assert!(later < first - 1.0, "validation loss {first} → {later}");
    // Adding the chunk to the context can only sharpen the belief (monotone std head), so the logged mean std
    // of q(β | C ∪ D) is never above that of q(β | C).
    let scalar = |name: &str| trainer.step_scalars().iter().find(|(n, _)| *n == name).map(|(_, v)| *v).unwrap();
    let (posterior, context) = (scalar("context/posterior_std"), scalar("context/context_std"));
    assert!(0.01 < posterior && posterior <= context * (1.0 + 1e-6), "{posterior} vs {context}");

    // Stop at step 30 and restore into a fresh trainer: the next steps give the same losses.
    let mut a = ContextTrainer::new(config.clone(), 7, train.clone(), valid.clone()).unwrap();
    for step in 1..=30 {
        a.step(step).unwrap();
    }
    let saved = a.state();
    let mut b = ContextTrainer::new(config, 7, train, valid).unwrap();
    b.restore(&saved).unwrap();
    for step in 31..=35 {
        assert_eq!(a.step(step).unwrap(), b.step(step).unwrap());
    }
}

/// Sizes in config.json are checked against each other before a network is sized from them (a flipped
/// `angular` flag once reached the fast path's GEMM with the wrong width; a huge action_dim aborted).
#[test]
fn model_spec_sizes_must_agree_and_be_plausible() {
    let spec = super::ModelSpec {
        state_names: vec!["theta".into(), "omega".into()],
        angular: vec![true, false],
        action_dim: 1,
        feature_dim: 3,
        observations: false,
        local_dim: 0,
    };
    assert!(spec.validate().is_ok());
    let flipped = super::ModelSpec { angular: vec![true, true], ..spec.clone() };
    assert!(flipped.validate().unwrap_err().to_string().contains("do not fit"));
    let huge = super::ModelSpec { action_dim: usize::MAX, ..spec };
    assert!(huge.validate().unwrap_err().to_string().contains("1..=256"));
}

#[test]
fn quadrant_pendulum_calibration_starts_hanging_down_nearly_at_rest() {
    use super::calibration::default_start;
    use crate::envs::registry::parse_env;
    use crate::util::seeding::rng_for;
    use std::f64::consts::PI;
    let quadrant = parse_env("pendulum:quadrant").unwrap();
    let starts: Vec<Vec<f64>> =
        (0..50).map(|seed| default_start(&quadrant, &mut rng_for(seed, &[4])).expect("a thesis start")).collect();
    for s in &starts {
        assert!((s[0] - PI).abs() <= 0.05 && s[1].abs() <= 0.05, "{s:?} is not hanging down at rest");
    }
    assert_ne!(starts[0], starts[1], "the start is drawn from the seed");
    assert_eq!(Some(starts[3].clone()), default_start(&quadrant, &mut rng_for(3, &[4])));
    assert_eq!(default_start(&parse_env("pendulum").unwrap(), &mut rng_for(0, &[4])), None);
}

/// Loss and gradients of the hand-written backward pass against burn's autodiff on the same batch: the toy's
/// shape (constant variance, D_β 1), the pendulum's (variance decoder) and TRADYN's (terrain features as input).
#[test]
fn hand_written_gradients_match_burn_autodiff() {
    use super::grad::loss_and_gradients;
    use crate::nn::tensor::{scalar, training_device};

    for (case, (s, a, local, constant_variance, latent)) in
        [(2, 1, 0, true, 1), (3, 1, 0, false, 2), (8, 2, 3, false, 3)].into_iter().enumerate()
    {
        let mut config = tiny_config();
        config.constant_variance = constant_variance;
        config.latent_dim = latent;
        // A low floor lets some KL terms pass their gradient and clamps others.
        config.kl_floor = 0.02;
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(10 + case as u64);
        let net = ContextNet::init(&config, s, a, local, &device, &mut rng);
        let mut params = ParamSet::<f32>::from_module(&net, param_name);
        params.tensors.iter_mut().flat_map(|t| t.values.iter_mut()).for_each(|v| *v = rng.random_range(-0.5..0.5));
        let net = params.load_into(net, &device).unwrap();
        let episode = |rng: &mut ChaCha8Rng| Episode {
            states: (0..21 * s).map(|_| rng.random_range(-1.0..1.0)).collect(),
            actions: (0..20 * a).map(|_| rng.random_range(-1.0..1.0)).collect(),
            len: 20,
        };
        let pairs = (0..6).map(|_| InstancePair { target: episode(&mut rng), source: episode(&mut rng) }).collect();
        let data = ContextData { state_dim: s, action_dim: a, local_dim: local, pairs };
        let batch =
            data.sample_batch(&mut rng, config.batch_size, config.chunk_states, config.context_max, 0.5, latent);
        assert!(batch.present.iter().any(|p| !p), "the batch should hold a partly empty context set");

        let parts = net.loss(&batch, &config, &device);
        let reference = ParamSet::<f32>::gradients(&net, &parts.loss.backward());
        let (loss, grads) = loss_and_gradients(&params, &batch, &config, true).unwrap();
        let grads = grads.unwrap();
        let rel = |x: f64, y: f64| (x - y).abs() / (1.0 + y.abs());
        assert!(
            rel(loss.loss, scalar(&parts.loss)) < 1e-4,
            "case {case}: loss {} vs {}",
            loss.loss,
            scalar(&parts.loss)
        );
        assert!(rel(loss.kl, scalar(&parts.kl)) < 1e-4, "case {case}: kl");
        assert!(rel(loss.multi_step, scalar(&parts.multi_step)) < 1e-4, "case {case}: multi-step");
        assert!(rel(loss.posterior_std, scalar(&parts.posterior_std)) < 1e-5, "case {case}: posterior std");
        for ((tensor, ours), theirs) in params.tensors.iter().zip(&grads).zip(&reference) {
            let scale = theirs.iter().fold(0.0f32, |m, x| m.max(x.abs())).max(1e-3);
            let worst = ours.iter().zip(theirs).fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(worst <= 2e-4 * scale, "case {case}: '{}' differs by {worst} at scale {scale}", tensor.name);
        }
        assert!(grads.iter().flatten().any(|g| *g != 0.0));
    }
}

/// Every element-wise pass and GEMM of the hand-written step splits work without changing any sum's order: at a
/// size where the passes do split (decoder rows × units well over the one-thread threshold), one, two and three
/// threads give the same bytes.
#[test]
fn loss_and_gradients_do_not_depend_on_the_thread_count() {
    use super::grad::loss_and_gradients;

    let mut config = tiny_config();
    (config.embedding, config.hidden_units, config.batch_size, config.chunk_states) = (48, 48, 48, 20);
    let (s, a) = (3, 1);
    let (_, params) = random_net(&config, s, a, 21);
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let episode = |rng: &mut ChaCha8Rng| Episode {
        states: (0..41 * s).map(|_| rng.random_range(-1.0..1.0)).collect(),
        actions: (0..40 * a).map(|_| rng.random_range(-1.0..1.0)).collect(),
        len: 40,
    };
    let pairs = (0..6).map(|_| InstancePair { target: episode(&mut rng), source: episode(&mut rng) }).collect();
    let data = ContextData { state_dim: s, action_dim: a, local_dim: 0, pairs };
    let batch = data.sample_batch(&mut rng, config.batch_size, config.chunk_states, config.context_max, 0.5, 2);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let (loss, grads) = pool.install(|| loss_and_gradients(&params, &batch, &config, true)).unwrap();
        (loss.loss.to_bits(), grads.unwrap())
    };
    let one = run(1);
    assert!(one.1.iter().flatten().any(|g| *g != 0.0));
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}
