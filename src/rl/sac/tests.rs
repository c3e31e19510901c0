//! SAC against direct formulas, the burn forward pass, a one-step task it must learn, and its saved state.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::agent::log_prob;
use super::inference::{squash, TwinQFast};
use super::networks::{QNetwork, CRITIC_TARGET};
use super::*;
use crate::nn::tensor::{tensor, training_device, values};
use crate::train::tensors::TensorData;

fn config(obs_dim: usize, low: Vec<f64>, high: Vec<f64>) -> SacConfig {
    SacConfig { hidden: vec![32, 32], ..SacConfig::new(obs_dim, low, high) }
}

fn cursor_like() -> SacConfig {
    config(6, vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0])
}

fn random_obs(rng: &mut ChaCha8Rng, n: usize, scale: f32) -> Vec<f32> {
    (0..n).map(|_| rng.random_range(-scale..scale)).collect()
}

fn random_batch(rng: &mut ChaCha8Rng, c: &SacConfig, rows: usize) -> TransitionBatch {
    let actions = (0..rows * c.action_dim)
        .map(|i| {
            let k = i % c.action_dim;
            rng.random_range(c.action_low[k]..c.action_high[k]) as f32
        })
        .collect();
    TransitionBatch {
        rows,
        obs: random_obs(rng, rows * c.obs_dim, 1.0),
        actions,
        rewards: random_obs(rng, rows, 1.0),
        next_obs: random_obs(rng, rows * c.obs_dim, 1.0),
        done: (0..rows).map(|i| (i % 3 == 0) as u8 as f32).collect(),
    }
}

fn assert_in_bounds(actions: &[f32], c: &SacConfig) {
    for (i, a) in actions.iter().enumerate() {
        let k = i % c.action_dim;
        assert!(*a >= c.action_low[k] as f32 && *a <= c.action_high[k] as f32, "action {i} = {a} outside dim {k}");
    }
}

#[test]
fn deterministic_actions_match_the_burn_forward_and_stay_in_bounds() {
    let c = cursor_like();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let sac = Sac::new(c.clone(), &mut rng).unwrap();
    let rows = 40;
    // Large inputs drive some outputs into tanh's saturation, where the bounds matter.
    let obs = random_obs(&mut rng, rows * c.obs_dim, 30.0);
    let fast = sac.act(&obs, rows, true, &mut rng);
    assert_in_bounds(&fast, &c);
    let (mean, _) = sac.policy_module().unwrap().forward(tensor(obs, [rows, c.obs_dim], &training_device()));
    let (scale, bias) = (c.action_scale(), c.action_bias());
    for (i, (m, f)) in values(&mean).iter().zip(&fast).enumerate() {
        let expected = m.tanh() * scale[i % 3] + bias[i % 3];
        assert!(
            (f - expected).abs() <= 1e-5 * (1.0 + expected.abs()),
            "row {} dim {}: {f} vs {expected}",
            i / 3,
            i % 3
        );
    }
    assert!(fast.iter().any(|a| a.abs() > 0.15), "no output near saturation; the test lost its point");
}

#[test]
fn target_critic_fast_path_matches_the_burn_critic() {
    // The target starts as a copy of the critic, so the fast path's min Q must equal burn's min(Q1, Q2).
    let c = cursor_like();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let sac = Sac::new(c.clone(), &mut rng).unwrap();
    let target = TwinQFast::from_params(sac.target_params(), CRITIC_TARGET, c.hidden.len()).unwrap();
    let (rows, width) = (17, c.obs_dim + c.action_dim);
    let input = random_obs(&mut rng, rows * width, 2.0);
    let fast = target.min_q(&input, rows);
    let critic = QNetwork::init(&c, &training_device(), &mut ChaCha8Rng::seed_from_u64(0));
    let critic = sac.critic_params().load_into(critic, &training_device()).unwrap();
    let (q1, q2) = critic.forward(tensor(input, [rows, width], &training_device()));
    for (f, q) in fast.iter().zip(values(&q1.min_pair(q2))) {
        assert!((f - q).abs() <= 1e-5 * (1.0 + q.abs()), "{f} vs {q}");
    }
}

#[test]
fn stochastic_actions_stay_in_bounds_vary_and_follow_the_seed() {
    let c = cursor_like();
    let sac = Sac::new(c.clone(), &mut ChaCha8Rng::seed_from_u64(2)).unwrap();
    let rows = 64;
    let obs: Vec<f32> = [0.3, -0.1, 0.5, 0.0, 1.0, -0.7].repeat(rows);
    let a = sac.act(&obs, rows, false, &mut ChaCha8Rng::seed_from_u64(5));
    assert_in_bounds(&a, &c);
    let first_dim: Vec<f32> = a.iter().step_by(3).copied().collect();
    let spread =
        first_dim.iter().cloned().fold(f32::MIN, f32::max) - first_dim.iter().cloned().fold(f32::MAX, f32::min);
    assert!(spread > 0.05, "samples of one observation barely vary: spread {spread}");
    assert_eq!(a, sac.act(&obs, rows, false, &mut ChaCha8Rng::seed_from_u64(5)));
    assert_ne!(a, sac.act(&obs, rows, false, &mut ChaCha8Rng::seed_from_u64(6)));
    assert!(sac.try_act(&obs[1..], rows, false, &mut ChaCha8Rng::seed_from_u64(5)).is_err());
}

#[test]
fn tanh_gaussian_log_prob_matches_the_direct_formula() {
    let (mean, log_std, eps) = (
        vec![0.3f32, -1.5, 2.0, 0.0, -0.2, 0.9],
        vec![-1.0f32, 0.5, -3.0, 0.0, 1.5, -0.4],
        vec![0.7f32, -1.2, 0.1, 2.3, -0.4, 0.0],
    );
    // The Cursor's bounds: the scale's Jacobian enters the density.
    let scale = [0.2f32, 0.2, 1.0];
    let expected: Vec<f64> = (0..2)
        .map(|r| {
            (0..3)
                .map(|k| {
                    let i = r * 3 + k;
                    let (m, s, e) = (mean[i] as f64, log_std[i] as f64, eps[i] as f64);
                    let u = m + s.exp() * e;
                    let normal = -0.5 * ((u - m) / s.exp()).powi(2) - s - 0.5 * (2.0 * std::f64::consts::PI).ln();
                    normal - (scale[k] as f64 * (1.0 - u.tanh().powi(2)) + 1e-6).ln()
                })
                .sum()
        })
        .collect();
    let device = training_device();
    let squashed: Vec<f32> = (0..6).map(|i| (mean[i] + log_std[i].exp() * eps[i]).tanh()).collect();
    let burn = values(&log_prob(
        tensor(eps.clone(), [2, 3], &device),
        tensor(log_std.clone(), [2, 3], &device),
        tensor(squashed.clone(), [2, 3], &device),
        tensor(scale.to_vec(), [1, 3], &device),
    ));
    let (fast_actions, fast) = squash(&mean, &log_std, &eps, &scale);
    for r in 0..2 {
        assert!((burn[r] as f64 - expected[r]).abs() < 1e-3, "burn row {r}: {} vs {}", burn[r], expected[r]);
        assert!((fast[r] as f64 - expected[r]).abs() < 1e-3, "fast row {r}: {} vs {}", fast[r], expected[r]);
    }
    assert_eq!(fast_actions, squashed);
}

#[test]
fn learns_to_match_the_observation_on_a_one_step_task() {
    // obs x ∈ [−1, 1], reward −(a − x)², episode over: the best action is a = x (env bounds ±1.5 test rescaling).
    let mut c = config(1, vec![-1.5], vec![1.5]);
    c.alpha = 0.01;
    c.learning_rate = 3e-3;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut sac = Sac::new(c.clone(), &mut rng).unwrap();
    let probe: Vec<f32> = (0..41).map(|i| -1.0 + i as f32 / 20.0).collect();
    let error = |sac: &Sac| -> f32 {
        let a = sac.act(&probe, probe.len(), true, &mut ChaCha8Rng::seed_from_u64(0));
        a.iter().zip(&probe).map(|(a, x)| (a - x).abs()).sum::<f32>() / probe.len() as f32
    };
    let before = error(&sac);
    for _ in 0..300 {
        let rows = 128;
        let obs = random_obs(&mut rng, rows, 1.0);
        let actions: Vec<f32> = (0..rows).map(|_| rng.random_range(-1.5f32..1.5)).collect();
        let rewards = obs.iter().zip(&actions).map(|(x, a)| -(a - x) * (a - x)).collect();
        let batch = TransitionBatch { rows, next_obs: obs.clone(), obs, actions, rewards, done: vec![1.0; rows] };
        let losses = sac.update(&batch, &mut rng).unwrap();
        assert!(losses.actor.is_finite() && losses.critic.is_finite());
    }
    let after = error(&sac);
    assert!(before > 0.3, "the untrained policy already solves the task: {before}");
    assert!(after < 0.1, "mean abs error after training {after} (before {before})");
}

#[test]
fn restored_agent_continues_bit_identically() {
    let c = cursor_like();
    let mut data_rng = ChaCha8Rng::seed_from_u64(3);
    let batches: Vec<TransitionBatch> = (0..5).map(|_| random_batch(&mut data_rng, &c, 32)).collect();
    let mut a = Sac::new(c.clone(), &mut ChaCha8Rng::seed_from_u64(11)).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for b in &batches[..3] {
        a.update(b, &mut rng).unwrap();
    }
    let mut b = Sac::new(c.clone(), &mut ChaCha8Rng::seed_from_u64(99)).unwrap();
    assert_ne!(a.weights(), b.weights());
    b.restore(&a.state()).unwrap();
    assert_eq!(a.state(), b.state());
    let (mut rng_a, mut rng_b) = (ChaCha8Rng::seed_from_u64(13), ChaCha8Rng::seed_from_u64(13));
    for batch in &batches[3..] {
        assert_eq!(a.update(batch, &mut rng_a).unwrap(), b.update(batch, &mut rng_b).unwrap());
    }
    assert_eq!(a.state(), b.state());
    assert_eq!(a.updates(), 5);
}

#[test]
fn the_same_seed_gives_the_same_agent_and_names_follow_pytorch() {
    let c = cursor_like();
    let a = Sac::new(c.clone(), &mut ChaCha8Rng::seed_from_u64(4)).unwrap();
    let b = Sac::new(c, &mut ChaCha8Rng::seed_from_u64(4)).unwrap();
    assert_eq!(a.state(), b.state());
    let names: Vec<String> = a.weights().iter().map(|t| t.name.clone()).collect();
    let expected = [
        "policy.net.0.weight",
        "policy.net.0.bias",
        "policy.net.2.weight",
        "policy.net.2.bias",
        "policy.mean_linear.weight",
        "policy.mean_linear.bias",
        "policy.log_std_linear.weight",
        "policy.log_std_linear.bias",
        "critic.q1.0.weight",
        "critic.q1.0.bias",
        "critic.q1.2.weight",
        "critic.q1.2.bias",
        "critic.q1.4.weight",
        "critic.q1.4.bias",
        "critic.q2.0.weight",
    ];
    assert_eq!(names[..expected.len()], expected);
    assert_eq!(a.weights()[8].shape, vec![32, 6 + 3]);
    // Xavier-uniform weights, zero biases.
    let w = &a.weights()[0];
    let bound = (6.0f32 / (6 + 32) as f32).sqrt();
    let TensorData::F32(v) = &w.data else { panic!("f32 weights") };
    assert!(v.iter().all(|x| x.abs() <= bound) && v.iter().any(|x| x.abs() > 0.8 * bound));
    assert!(matches!(&a.weights()[1].data, TensorData::F32(b) if b.iter().all(|x| *x == 0.0)));
}

#[test]
fn from_weights_rebuilds_the_same_policy() {
    let c = cursor_like();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut a = Sac::new(c.clone(), &mut rng).unwrap();
    let batch = random_batch(&mut rng, &c, 16);
    a.update(&batch, &mut rng).unwrap();
    let b = Sac::from_weights(c.clone(), &a.weights()).unwrap();
    let obs = random_obs(&mut rng, 8 * c.obs_dim, 1.0);
    let mut r = ChaCha8Rng::seed_from_u64(0);
    assert_eq!(a.act(&obs, 8, true, &mut r), b.act(&obs, 8, true, &mut r));
    assert_eq!(b.critic_params().tensors[0].values, a.critic_params().tensors[0].values);
    assert_eq!(b.target_params().tensors[0].values, a.critic_params().tensors[0].values);
}

#[test]
fn wrong_layouts_are_errors_and_leave_the_agent_unchanged() {
    let c = cursor_like();
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mut sac = Sac::new(c.clone(), &mut rng).unwrap();
    let before = sac.state();

    let mut missing = before.clone();
    missing.remove(4);
    let err = sac.restore(&missing).unwrap_err().to_string();
    assert!(err.contains("tensors"), "{err}");

    let mut short = before.clone();
    if let TensorData::F32(v) = &mut short[0].data {
        v.pop();
    }
    let err = sac.restore(&short).unwrap_err().to_string();
    assert!(err.contains(&short[0].name), "{err}");

    let mut renamed = before.clone();
    renamed.last_mut().unwrap().name = "steps".into();
    assert!(sac.restore(&renamed).unwrap_err().to_string().contains("updates"));

    let mut nan = before.clone();
    nan[2].data = TensorData::F32(vec![f32::NAN; nan[2].shape.iter().product()]);
    assert!(sac.restore(&nan).is_err());
    assert_eq!(sac.state(), before);

    let bigger = SacConfig { hidden: vec![32, 48], ..c.clone() };
    assert!(Sac::from_weights(bigger, &sac.weights()).is_err());
    assert!(Sac::from_weights(c.clone(), &sac.state()).is_err());
    let mut f64_weights = sac.weights();
    f64_weights[0] =
        crate::train::StoredTensor::f64(f64_weights[0].name.clone(), f64_weights[0].shape.clone(), vec![0.0; 32 * 6]);
    assert!(Sac::from_weights(c, &f64_weights).unwrap_err().to_string().contains("f32"));
}

#[test]
fn bad_batches_and_configs_are_errors() {
    let c = cursor_like();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let mut sac = Sac::new(c.clone(), &mut rng).unwrap();
    let good = random_batch(&mut rng, &c, 8);
    let mut short = good.clone();
    short.next_obs.pop();
    let err = sac.update(&short, &mut rng).unwrap_err();
    assert!(matches!(err.kind(), crate::ErrorKind::BadShape { name, .. } if name.contains("next_obs")), "{err}");
    let mut nan = good.clone();
    nan.rewards[5] = f32::NAN;
    assert!(sac.update(&nan, &mut rng).unwrap_err().to_string().contains("row 5"));
    assert!(sac.update(&TransitionBatch::default(), &mut rng).is_err());
    assert_eq!(sac.updates(), 0);
    assert!(sac.update(&good, &mut rng).is_ok());

    let cases: Vec<(SacConfig, &str)> = vec![
        (SacConfig { obs_dim: 0, ..c.clone() }, "obs_dim"),
        (SacConfig { action_dim: 2, ..c.clone() }, "action_low"),
        (SacConfig { action_low: vec![-0.2, 0.3, -1.0], ..c.clone() }, "low"),
        (SacConfig { action_high: vec![0.2, f64::INFINITY, 1.0], ..c.clone() }, "finite"),
        (SacConfig { hidden: vec![], ..c.clone() }, "hidden"),
        (SacConfig { hidden: vec![32, 0], ..c.clone() }, "hidden"),
        (SacConfig { gamma: f64::NAN, ..c.clone() }, "gamma"),
        (SacConfig { tau: 0.0, ..c.clone() }, "tau"),
        (SacConfig { learning_rate: 10.0, ..c.clone() }, "learning_rate"),
        (SacConfig { alpha: -0.1, ..c.clone() }, "alpha"),
        (SacConfig { batch_size: 0, ..c.clone() }, "batch_size"),
    ];
    for (bad, field) in cases {
        let err = bad.validate().unwrap_err().to_string();
        assert!(err.contains(field) && !err.contains('\n'), "{field}: {err}");
        assert!(Sac::new(bad, &mut rng).is_err());
    }
}

/// Both losses and every gradient of the hand-written update against burn's autodiff through the modules of
/// `networks.rs`, on weights large enough that some log σ leave the clamp and both critics win some rows' min.
#[test]
fn hand_written_losses_and_gradients_match_burn_autodiff() {
    use super::grad::{actor_loss_and_gradients, critic_loss_and_gradients};
    use super::networks::CRITIC;
    use crate::nn::tensor::scalar;
    use crate::nn::ParamSet;
    use burn::module::Module;
    use burn::tensor::Tensor;

    let mut c = config(7, vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0]);
    c.hidden = vec![9, 8];
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let mut sac = Sac::new(c.clone(), &mut rng).unwrap();
    for t in sac.policy_params.tensors.iter_mut().chain(sac.critic_params.tensors.iter_mut()) {
        t.values.iter_mut().for_each(|v| *v = rng.random_range(-0.9..0.9));
    }
    let (rows, od, ad) = (13, c.obs_dim, c.action_dim);
    let batch = random_batch(&mut rng, &c, rows);
    let obs = random_obs(&mut rng, rows * od, 3.0);
    let targets = random_obs(&mut rng, rows, 2.0);
    let eps = random_obs(&mut rng, rows * ad, 1.5);
    let (scale, bias) = (c.action_scale(), c.action_bias());
    let device = training_device();
    let close = |name: &str, ours: &[Vec<f32>], theirs: &[Vec<f32>], params: &ParamSet| {
        for ((t, ours), theirs) in params.tensors.iter().zip(ours).zip(theirs) {
            let scale = theirs.iter().fold(0.0f32, |m, x| m.max(x.abs())).max(1e-3);
            let worst = ours.iter().zip(theirs).fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(worst <= 2e-4 * scale, "{name}: '{}' differs by {worst} at scale {scale}", t.name);
            assert!(ours.iter().any(|g| *g != 0.0), "{name}: '{}' got no gradient", t.name);
        }
    };

    let input = super::inference::concat_rows(&obs, od, &batch.actions, ad, rows);
    let critic = sac.critic_module().unwrap();
    let (q1, q2) = critic.forward(tensor(input.clone(), [rows, od + ad], &device));
    let target = tensor(targets.clone(), [rows, 1], &device);
    let loss = (q1 - target.clone()).square().mean() + (q2 - target).square().mean();
    let reference = ParamSet::<f32>::gradients(&critic, &loss.backward());
    let (ours, _, grads) =
        critic_loss_and_gradients(&sac.critic_params, CRITIC, &c.hidden, &input, &targets, rows).unwrap();
    assert!((ours - scalar(&loss)).abs() < 1e-4 * (1.0 + ours.abs()), "critic loss {ours} vs {}", scalar(&loss));
    close("critic", &grads, &reference, &sac.critic_params);

    let policy = sac.policy_module().unwrap();
    let frozen = sac.critic_module().unwrap().no_grad();
    let obs_t = tensor(obs.clone(), [rows, od], &device);
    let (mean, log_std) = policy.forward(obs_t.clone());
    let raw = values(&mean).len();
    assert_eq!(raw, rows * ad);
    let eps_t = tensor(eps.clone(), [rows, ad], &device);
    let squashed = (mean + log_std.clone().exp() * eps_t.clone()).tanh();
    let scale_t = tensor(scale.clone(), [1, ad], &device);
    let lp = log_prob(eps_t, log_std.clone(), squashed.clone(), scale_t.clone());
    let actions = squashed * scale_t + tensor(bias.clone(), [1, ad], &device);
    let (q1, q2) = frozen.forward(Tensor::cat(vec![obs_t, actions], 1));
    let chose_q2 = values(&q2).iter().zip(values(&q1)).filter(|(b, a)| *b < a).count();
    assert!(chose_q2 > 0 && chose_q2 < rows, "both critics should win some rows' min ({chose_q2} of {rows})");
    let clamped = values(&log_std).iter().filter(|&&s| s == super::networks::LOG_STD_MAX).count();
    assert!(clamped > 0, "some log σ should hit the clamp");
    let alpha = 0.3f32;
    let loss = (lp * alpha - q1.min_pair(q2)).mean();
    let reference = ParamSet::<f32>::gradients(&policy, &loss.backward());
    let actor = actor_loss_and_gradients(
        &sac.policy_params,
        &sac.critic_params,
        CRITIC,
        &c.hidden,
        &obs,
        &eps,
        &scale,
        &bias,
        alpha,
        rows,
    )
    .unwrap();
    let theirs = scalar(&loss);
    assert!((actor.loss - theirs).abs() < 1e-4 * (1.0 + theirs.abs()), "actor loss {} vs {theirs}", actor.loss);
    close("actor", &actor.gradients, &reference, &sac.policy_params);
}

/// The twin critics run side by side and GEMMs split by rows or columns only: one thread or two, same bytes.
#[test]
fn losses_and_gradients_do_not_depend_on_the_thread_count() {
    use super::grad::{actor_loss_and_gradients, critic_loss_and_gradients};
    use super::networks::CRITIC;

    let mut c = config(9, vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0]);
    c.hidden = vec![256, 256];
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let sac = Sac::new(c.clone(), &mut rng).unwrap();
    let (rows, od, ad) = (128, c.obs_dim, c.action_dim);
    let batch = random_batch(&mut rng, &c, rows);
    let input = super::inference::concat_rows(&batch.obs, od, &batch.actions, ad, rows);
    let targets = random_obs(&mut rng, rows, 2.0);
    let eps = random_obs(&mut rng, rows * ad, 1.5);
    let (scale, bias) = (c.action_scale(), c.action_bias());
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let (loss, q, critic) =
                critic_loss_and_gradients(&sac.critic_params, CRITIC, &c.hidden, &input, &targets, rows).unwrap();
            let actor = actor_loss_and_gradients(
                &sac.policy_params,
                &sac.critic_params,
                CRITIC,
                &c.hidden,
                &batch.obs,
                &eps,
                &scale,
                &bias,
                0.2,
                rows,
            )
            .unwrap();
            (loss.to_bits(), q.to_bits(), critic, actor.loss.to_bits(), actor.gradients)
        })
    };
    assert_eq!(run(1), run(2));
}

/// The critic targets are computed in row blocks cut by the batch size: whole updates give the same bytes at
/// one to four threads, for batches of one block (3 rows) and of several (300 rows: four blocks of 75).
#[test]
fn updates_do_not_depend_on_the_thread_count() {
    let mut c = config(9, vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0]);
    c.hidden = vec![32, 32];
    for rows in [3, 300] {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut rng = ChaCha8Rng::seed_from_u64(8);
                let mut sac = Sac::new(c.clone(), &mut rng).unwrap();
                let batch = random_batch(&mut rng, &c, rows);
                let losses: Vec<u64> = (0..2)
                    .flat_map(|_| {
                        let l = sac.update(&batch, &mut rng).unwrap();
                        [l.actor.to_bits(), l.critic.to_bits(), l.mean_q.to_bits()]
                    })
                    .collect();
                let bits = |p: &crate::nn::ParamSet| {
                    p.tensors.iter().flat_map(|t| t.values.iter().map(|v| v.to_bits())).collect()
                };
                let params: Vec<Vec<u32>> =
                    vec![bits(sac.policy_params()), bits(sac.critic_params()), bits(sac.target_params())];
                (losses, params)
            })
        };
        let one = run(1);
        for threads in [2, 3, 4] {
            assert_eq!(one, run(threads), "{rows} rows, {threads} threads");
        }
    }
}

/// The blocked critic targets equal the whole batch's through the acting path, whose sampling draws the same
/// noise from the same stream.
#[test]
fn blocked_critic_targets_equal_the_unblocked_computation() {
    use super::inference::{concat_rows, PolicyFast, TwinQFast};
    use super::networks::CRITIC_TARGET;
    let mut c = config(9, vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0]);
    c.hidden = vec![32, 32];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let sac = Sac::new(c.clone(), &mut rng).unwrap();
    let rows = 300;
    let batch = random_batch(&mut rng, &c, rows);
    let (od, ad) = (c.obs_dim, c.action_dim);
    let (scale, bias) = (c.action_scale(), c.action_bias());
    let policy = PolicyFast::from_params(sac.policy_params(), c.hidden.len()).unwrap();
    let targets = TwinQFast::from_params(sac.target_params(), CRITIC_TARGET, c.hidden.len()).unwrap();
    let mut stream = rng.clone();
    let (squashed, log_prob) = policy.sample(&batch.next_obs, rows, &scale, &mut stream);
    let actions: Vec<f32> = squashed
        .iter()
        .enumerate()
        .map(|(i, y)| {
            let k = i % ad;
            (y * scale[k] + bias[k]).clamp(c.action_low[k] as f32, c.action_high[k] as f32)
        })
        .collect();
    let next_q = targets.min_q(&concat_rows(&batch.next_obs, od, &actions, ad, rows), rows);
    let (gamma, alpha) = (c.gamma as f32, c.alpha as f32);
    let whole: Vec<u32> = (0..rows)
        .map(|i| (batch.rewards[i] + (1.0 - batch.done[i]) * gamma * (next_q[i] - alpha * log_prob[i])).to_bits())
        .collect();
    let eps: Vec<f32> = (0..rows * ad).map(|_| rng.sample(rand_distr::StandardNormal)).collect();
    let blocked: Vec<u32> = sac.critic_targets(&batch, &eps).iter().map(|y| y.to_bits()).collect();
    assert_eq!(blocked, whole);
}
