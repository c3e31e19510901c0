//! Golden values: the loss terms, gradients and context beliefs of a small fixed network and batch, computed once
//! with the authors' own code (EmbodiedVision/explorethecontext at commit 8d4c552b, `compute_loss` of
//! `train_model.py`, `MLPContextEncoder`, `GruTransitionModel`, in float64) by `tests/fixtures/context_golden.py`,
//! whose docstring lists the settings. Weights and inputs come from an integer hash both sides compute, so the
//! script needs no weight file. They hold the model to the authors' through rewrites of the network, its fused
//! training path and its fast inference path: each must agree within 1e-5 relative.

use burn::tensor::Tensor;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::config::{ContextConfig, EnvFamily, Preset};
use super::data::Batch;
use super::eig::EigObjective;
use super::fast::FastContextModel;
use super::grad::loss_and_gradients;
use super::net::{param_name, ContextNet};
use crate::nn::tensor::{mask, scalar, tensor, training_device, values};
use crate::nn::ParamSet;

const TOLERANCE: f64 = 1e-5;
/// The gradient of the mean head's output bias sums posterior and prior terms about a hundred times its size
/// that cancel (the KL gradients with respect to the two means are opposite), so float32 rounding moves it
/// further: by 7e-6 in the authors' own code run in float32 (`context_golden.py --float32`), by 1-2e-5 here.
const CANCELLING: (&str, f64) = ("context_mean.second.bias", 3e-5);
const B: usize = 8;
const N: usize = 6;
const T: usize = N - 1;
const CONTEXT_MAX: usize = 5;
const CONTEXT_SIZES: [usize; B] = [0, 1, 2, 3, 4, 5, 2, 5];
/// Context sets made of their own chunk's first transitions (their KL terms sit at the floor).
const FROM_CHUNK: [bool; B] = [false, false, false, false, true, true, false, false];
const SET_SIZE: usize = 5;

/// A value in [0, 1) from an integer hash of (seed, k); `context_golden.py` computes the same.
fn hash01(seed: u64, k: u64) -> f64 {
    let m = 0xFFFF_FFFFu64;
    let mut h = (k * 0x9E37_79B1 + seed * 0x85EB_CA77 + 1) & m;
    h ^= h >> 15;
    h = (h * 0x2C1B_3C6D) & m;
    h ^= h >> 12;
    h = (h * 0x297A_2D39) & m;
    h ^= h >> 15;
    h as f64 / 4294967296.0
}

fn pattern(seed: u64, n: usize, amp: f64) -> Vec<f32> {
    (0..n as u64).map(|k| ((hash01(seed, k) * 2.0 - 1.0) * amp) as f32).collect()
}

fn name_seed(name: &str) -> u64 {
    name.bytes().enumerate().map(|(i, c)| (i as u64 + 1) * c as u64).sum::<u64>() % 100_003
}

/// Pendulum-like (state 3, D_β 2, variance decoder) or toy-like (state 2, D_β 1, constant variance).
struct Case {
    s: usize,
    a: usize,
    latent: usize,
    constant_variance: bool,
}

const PENDULUM: Case = Case { s: 3, a: 1, latent: 2, constant_variance: false };
const TOY: Case = Case { s: 2, a: 1, latent: 1, constant_variance: true };

fn config(case: &Case) -> ContextConfig {
    let mut c = ContextConfig::preset(Preset::Small, EnvFamily::Control);
    c.embedding = 16;
    c.hidden_units = 200;
    c.transition_features = 16;
    c.latent_dim = case.latent;
    c.constant_variance = case.constant_variance;
    c.batch_size = B;
    c.chunk_states = N;
    c.context_max = CONTEXT_MAX;
    c.kl_weight = 5.0;
    c.kl_floor = 0.1;
    c
}

/// The network with every tensor set from the hash: weights ±2/√fan_in, vectors ±0.2.
fn golden_net(case: &Case) -> (ContextNet, ParamSet) {
    let device = training_device();
    let net = ContextNet::init(&config(case), case.s, case.a, 0, &device, &mut ChaCha8Rng::seed_from_u64(0));
    let mut params = ParamSet::<f32>::from_module(&net, param_name);
    for t in &mut params.tensors {
        let amp = if t.shape.len() == 2 { 2.0 / (t.shape[1] as f64).sqrt() } else { 0.2 };
        t.values = pattern(name_seed(&t.name), t.values.len(), amp);
    }
    (params.load_into(net, &device).unwrap(), params)
}

fn golden_batch(case: &Case) -> Batch {
    let (s, a, lat) = (case.s, case.a, case.latent);
    let tdim = 2 * s + a;
    let states = pattern(1, B * N * s, 1.0);
    let actions = pattern(2, B * T * a, 2.0);
    let transition = |i: usize, k: usize| -> Vec<f32> {
        let mut row = states[(i * N + k) * s..(i * N + k + 1) * s].to_vec();
        row.extend_from_slice(&actions[(i * T + k) * a..(i * T + k + 1) * a]);
        row.extend_from_slice(&states[(i * N + k + 1) * s..(i * N + k + 2) * s]);
        row
    };
    let chunk_transitions = (0..B).flat_map(|i| (0..T).flat_map(move |k| transition(i, k))).collect();
    let mut context = pattern(3, B * CONTEXT_MAX * tdim, 1.0);
    let mut present = vec![false; B * CONTEXT_MAX];
    for i in 0..B {
        for m in 0..CONTEXT_MAX {
            let row = &mut context[(i * CONTEXT_MAX + m) * tdim..(i * CONTEXT_MAX + m + 1) * tdim];
            present[i * CONTEXT_MAX + m] = m < CONTEXT_SIZES[i];
            if m >= CONTEXT_SIZES[i] {
                row.fill(0.0);
            } else if FROM_CHUNK[i] {
                row.copy_from_slice(&transition(i, m));
            }
        }
    }
    Batch {
        size: B,
        chunk: N,
        local_dim: 0,
        states,
        actions,
        chunk_transitions,
        context_max: CONTEXT_MAX,
        context,
        present,
        noise_sequence: pattern(4, B * lat, 1.7),
        noise_single: pattern(5, B * T * lat, 1.7),
    }
}

fn relative(ours: f64, theirs: f64) -> f64 {
    (ours - theirs).abs() / theirs.abs().max(1e-12)
}

/// Every term and gradient of both loss paths (burn's autodiff and the fused one that trains) against the
/// golden values; reports all deviations past the tolerance at once.
fn check_loss(case: &Case, terms: &[(&str, f64)], gradients: &[(&str, f64, usize, f64)]) {
    let (net, params) = golden_net(case);
    let batch = golden_batch(case);
    let config = config(case);
    let device = training_device();
    let parts = net.loss(&batch, &config, &device);
    let burn_grads = ParamSet::<f32>::gradients(&net, &parts.loss.backward());
    let (fused, fused_grads) = loss_and_gradients(&params, &batch, &config, true).unwrap();
    let fused_grads = fused_grads.unwrap();
    let burn_terms = [
        ("loss", scalar(&parts.loss)),
        ("reconstruction", scalar(&parts.reconstruction)),
        ("single_step", scalar(&parts.single_step)),
        ("multi_step", scalar(&parts.multi_step)),
        ("kl", scalar(&parts.kl)),
        ("context_std", scalar(&parts.context_std)),
    ];
    let fused_terms = [
        ("loss", fused.loss),
        ("reconstruction", fused.reconstruction),
        ("single_step", fused.single_step),
        ("multi_step", fused.multi_step),
        ("kl", fused.kl),
        ("context_std", fused.context_std),
    ];
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    let mut check = |what: String, ours: f64, theirs: f64, tolerance: f64| {
        let r = relative(ours, theirs);
        worst = worst.max(r);
        if r > tolerance || !ours.is_finite() {
            failures.push(format!("{what}: {ours} vs {theirs} (relative {r:.1e})"));
        }
    };
    for (path, ours) in [("burn", &burn_terms), ("fused", &fused_terms)] {
        for (name, theirs) in terms {
            let value = ours.iter().find(|(n, _)| n == name).map(|(_, v)| *v).unwrap();
            check(format!("{path} {name}"), value, *theirs, TOLERANCE);
        }
    }
    assert_eq!(gradients.len(), params.tensors.len(), "a golden gradient per tensor");
    for (path, grads) in [("burn", &burn_grads), ("fused", &fused_grads)] {
        for (name, norm, index, entry) in gradients {
            let k = params.tensors.iter().position(|t| t.name == *name).unwrap_or_else(|| panic!("no tensor {name}"));
            let g = &grads[k];
            let tolerance = if *name == CANCELLING.0 { CANCELLING.1 } else { TOLERANCE };
            let ours_norm = g.iter().map(|x| (*x as f64).powi(2)).sum::<f64>().sqrt();
            check(format!("{path} ∇{name} norm"), ours_norm, *norm, tolerance);
            check(format!("{path} ∇{name}[{index}]"), g[*index] as f64, *entry, tolerance);
        }
    }
    eprintln!("largest relative deviation from the authors' values: {worst:.2e}");
    assert!(failures.is_empty(), "{} deviations past {TOLERANCE:e}:\n{}", failures.len(), failures.join("\n"));
}

// --- Golden values printed by tests/fixtures/context_golden.py (float64, the authors' code) ---

// explorethecontext 8d4c552b1be5282e33418a6387c4486719b5e897, torch.float64
const PENDULUM_TERMS: &[(&str, f64)] = &[
    ("loss", 152.80087352116826),
    ("reconstruction", -3.7506275841549437),
    ("single_step", -3.564429719476054),
    ("multi_step", -14.688033044514533),
    ("kl", 130.79778317302274),
    ("context_std", 0.22556238786535315),
];

/// (tensor, Euclidean norm of its gradient, index of the gradient's largest |entry|, that entry).
const PENDULUM_GRADIENTS: &[(&str, f64, usize, f64)] = &[
    ("action_encoder.first.bias", 1.1245038721578209, 31, -0.2484940140485234),
    ("action_encoder.first.weight", 1.0982731476352496, 78, -0.19452521608561263),
    ("action_encoder.second.bias", 1.627276239058412, 6, 1.3392082357974195),
    ("action_encoder.second.weight", 16.831605172630024, 1381, 1.8939504080157408),
    ("context_embedding.first.bias", 1.8483328189005572, 147, -0.4205346409645673),
    ("context_embedding.first.weight", 3.0792697222122176, 294, -0.5816070716652822),
    ("context_embedding.second.bias", 2.164231028606391, 5, 1.9146253301872787),
    ("context_embedding.second.weight", 29.934223667964883, 1156, 5.517213063035149),
    ("context_mean.first.bias", 71.84449750146887, 175, 24.135465229488084),
    ("context_mean.first.weight", 437.1617306926327, 2810, 66.83357616654452),
    ("context_mean.second.bias", 1.3808985860577205, 1, -1.376206484981907),
    ("context_mean.second.weight", 1140.5776358882138, 40, 257.97584141552477),
    ("context_std.first.bias", 42.77528025860468, 167, 7.697512581468855),
    ("context_std.first.weight", 107.35204818219508, 266, 12.502404816618741),
    ("context_std.second.bias", 46.84192028091843, 0, 43.04618335250426),
    ("context_std.second.weight", 722.5234146257592, 159, 132.2948927984827),
    ("gru.bias_hh", 2.451098436013836, 44, -1.8356090187631242),
    ("gru.bias_ih", 3.6023702082192046, 44, -2.2246998257308834),
    ("gru.weight_hh", 3.830662495982785, 719, 1.5237022807535987),
    ("gru.weight_ih", 15.916124223454972, 1220, -5.38735011447365),
    ("mean_decoder.first.bias", 5.049089957958161, 118, 1.125842202114571),
    ("mean_decoder.first.weight", 8.301557682474675, 1903, -0.916062549821961),
    ("mean_decoder.second.bias", 6.928645015250485, 0, 6.368174575528712),
    ("mean_decoder.second.weight", 35.61381283262896, 134, 9.051591525704733),
    ("state_encoder.first.bias", 1.0150148832925319, 170, 0.2242952455845899),
    ("state_encoder.first.weight", 0.9405434040899567, 72, -0.1646351432068181),
    ("state_encoder.second.bias", 1.3505724097670946, 7, -0.8852495840371866),
    ("state_encoder.second.weight", 8.577162497624437, 1419, -0.647675610359282),
    ("transition_encoder.first.bias", 189.52039850088866, 182, 39.23026424617375),
    ("transition_encoder.first.weight", 322.3283248040567, 1088, 46.86972802950089),
    ("transition_encoder.second.bias", 210.62361075281288, 9, 79.53471348419043),
    ("transition_encoder.second.weight", 1866.226972363463, 1492, 208.4233235543034),
    ("variance_decoder.first.bias", 1.1857989865004384, 195, 0.2535738023182111),
    ("variance_decoder.first.weight", 1.8965082132113207, 3135, -0.20673845282767433),
    ("variance_decoder.second.bias", 1.7305475810693223, 0, -1.209725493754054),
    ("variance_decoder.second.weight", 8.218873183915656, 77, -1.3471433232046186),
];

const TOY_TERMS: &[(&str, f64)] = &[
    ("loss", 61.83226571794286),
    ("reconstruction", -2.00090251753433),
    ("single_step", -2.0906940291513365),
    ("multi_step", -8.600709148682599),
    ("kl", 49.1399600225746),
    ("context_std", 0.23436195742231677),
];

/// (tensor, Euclidean norm of its gradient, index of the gradient's largest |entry|, that entry).
const TOY_GRADIENTS: &[(&str, f64, usize, f64)] = &[
    ("action_encoder.first.bias", 0.38870788394892414, 188, 0.08520852727399866),
    ("action_encoder.first.weight", 0.4195524095319367, 188, -0.08255677042679674),
    ("action_encoder.second.bias", 0.5319059751881597, 8, -0.2964282572329957),
    ("action_encoder.second.weight", 6.471029619525067, 1781, -0.6011082769330993),
    ("constant_variance", 1.1834304745554207, 1, 1.010299718691345),
    ("context_embedding.first.bias", 0.5963482165184731, 39, 0.15869443598721553),
    ("context_embedding.first.weight", 0.8230412340473583, 39, 0.21448389347062308),
    ("context_embedding.second.bias", 0.74842438952138, 5, 0.4981615424145514),
    ("context_embedding.second.weight", 10.920753505100645, 618, 1.3803194375361225),
    ("context_mean.first.bias", 28.678519141354023, 94, 9.634747722665395),
    ("context_mean.first.weight", 195.59387675407342, 1514, 26.108553304473553),
    ("context_mean.second.bias", 0.4146911687778072, 0, 0.4146911687778072),
    ("context_mean.second.weight", 541.2103285325902, 95, 148.27730406250612),
    ("context_std.first.bias", 17.527154007588685, 81, 3.166356636809968),
    ("context_std.first.weight", 35.38742904417032, 1578, 3.9353661512974663),
    ("context_std.second.bias", 22.416596750006384, 0, 22.416596750006384),
    ("context_std.second.weight", 306.6769759879794, 123, 62.438113936346845),
    ("gru.bias_hh", 0.7289336866238663, 33, -0.49482293052299203),
    ("gru.bias_ih", 1.084723357224994, 33, -0.6861070710777618),
    ("gru.weight_hh", 1.1799058753231113, 543, 0.4006723412928139),
    ("gru.weight_ih", 3.1042705956802097, 1070, -1.095396047952153),
    ("mean_decoder.first.bias", 1.8615164673064448, 118, 0.48945404570451917),
    ("mean_decoder.first.weight", 3.119524203826388, 1894, -0.3330061930175081),
    ("mean_decoder.second.bias", 2.4122297839236646, 0, 1.7726798166821145),
    ("mean_decoder.second.weight", 11.91565172966859, 198, 2.326240307279914),
    ("state_encoder.first.bias", 0.505800663222742, 143, 0.11526192393078855),
    ("state_encoder.first.weight", 0.4016859012896909, 117, -0.05832007264534146),
    ("state_encoder.second.bias", 0.6485291524977922, 6, -0.3671938897092605),
    ("state_encoder.second.weight", 4.522827833350458, 2573, 0.450052597878152),
    ("transition_encoder.first.bias", 76.69969968950664, 186, -16.09303738528841),
    ("transition_encoder.first.weight", 120.51377188565166, 192, -18.037537321250944),
    ("transition_encoder.second.bias", 86.74437493038053, 2, 35.06225550417079),
    ("transition_encoder.second.weight", 757.4806601207908, 3083, 88.1656714678404),
];

/// q(β | five fixed transitions) and q(β | ∅) of the pendulum-like network: mean, std, mean, std.
const BELIEF: [[f64; 2]; 4] = [
    [0.8319661272123663, -0.3300263731394482],
    [0.055034506649327034, 0.05254566704382089],
    [-0.04914585495700535, 0.038628151353242185],
    [0.8859827042824084, 0.960145324541757],
];

/// The mean over three β samples of Σ_d H[q(β_d | 3 observed ∪ 4 imagined transitions)] for one action sequence
/// (the authors' `CemTransitionModel` with sampled contexts and `CemReturnModel`, criterion "neg-entropy"), and
/// the same with the imagined rollout starting at the true state instead of the model's reconstruction of it.
const EIG_ENTROPY: f64 = -2.651165167264628;
const EIG_ENTROPY_FROM_TRUE_START: f64 = -3.0754867170630145;

#[test]
fn loss_and_gradients_match_the_authors_code_on_a_pendulum_like_model() {
    check_loss(&PENDULUM, PENDULUM_TERMS, PENDULUM_GRADIENTS);
}

#[test]
fn loss_and_gradients_match_the_authors_code_on_a_toy_like_model() {
    check_loss(&TOY, TOY_TERMS, TOY_GRADIENTS);
}

#[test]
fn context_belief_matches_the_authors_encoder() {
    let (net, params) = golden_net(&PENDULUM);
    let fast = FastContextModel::from_params(&params).unwrap();
    let device = training_device();
    let tdim = 2 * PENDULUM.s + PENDULUM.a;
    let set = pattern(6, SET_SIZE * tdim, 1.0);
    let [mean, std, empty_mean, empty_std] = BELIEF;
    let close = |what: &str, ours: &[f32], theirs: &[f64]| {
        assert_eq!(ours.len(), theirs.len());
        for (x, y) in ours.iter().zip(theirs) {
            let r = relative(*x as f64, *y);
            assert!(r <= TOLERANCE, "{what}: {x} vs {y} (relative {r:.1e})");
        }
    };
    for (what, rows, m, s) in [("set", &set[..], mean, std), ("empty set", &[][..], empty_mean, empty_std)] {
        let belief = fast.belief(&fast.pool(rows), 1);
        close(&format!("fast {what} mean"), &belief.mean, &m);
        close(&format!("fast {what} std"), &belief.std, &s);
        let k = rows.len() / tdim;
        let pooled = if k == 0 {
            Tensor::zeros([1, fast.transition_features], &device)
        } else {
            net.pool(tensor(rows.to_vec(), [1, k, tdim], &device), mask(vec![true; k], [1, k], &device))
        };
        let belief = net.belief(pooled);
        close(&format!("burn {what} mean"), &values(&belief.mean), &m);
        close(&format!("burn {what} std"), &values(&belief.std), &s);
    }
}

#[test]
fn eig_objective_matches_the_authors_calibration() {
    let (_, params) = golden_net(&PENDULUM);
    let fast = FastContextModel::from_params(&params).unwrap();
    let (s, a, lat) = (PENDULUM.s, PENDULUM.a, PENDULUM.latent);
    let (observed, horizon, samples) = (3, 4, 3);
    let base = fast.pool(&pattern(7, observed * (2 * s + a), 1.0));
    let init = pattern(8, s, 1.0);
    let actions: Vec<f64> = pattern(9, horizon * a, 2.0).iter().map(|x| *x as f64).collect();
    let betas = pattern(10, samples * lat, 1.7);
    let objective = EigObjective::from_samples(&fast, init, base, betas);
    let mut entropy = [0.0];
    objective.posterior_entropies(&actions, horizon, &mut entropy);
    let r = relative(entropy[0], EIG_ENTROPY);
    assert!(r <= TOLERANCE, "{} vs {EIG_ENTROPY} (relative {r:.1e})", entropy[0]);
    // The start matters at these weights: the test would catch a rollout chopped from the true state.
    assert!(relative(EIG_ENTROPY_FROM_TRUE_START, EIG_ENTROPY) > 100.0 * TOLERANCE);
}
