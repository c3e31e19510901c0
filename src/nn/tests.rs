//! The building blocks against hand-computed references.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::nn::gaussian::LogVarBoundsConfig;
use crate::nn::tensor::{inference_device, mask, tensor, training_device, values};

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

#[test]
fn gru_cell_follows_torch_equations() {
    let device = inference_device();
    let (i, h) = (3, 4);
    let cell = GruCellConfig::new(i, h).init(&device, &mut ChaCha8Rng::seed_from_u64(1));
    let p = ParamSet::<f32>::from_module(&cell, |s| s.to_string());
    let w_ih = &p.get("weight_ih").unwrap().values;
    let w_hh = &p.get("weight_hh").unwrap().values;
    let b_ih = &p.get("bias_ih").unwrap().values;
    let b_hh = &p.get("bias_hh").unwrap().values;
    let x = [0.3f32, -1.2, 0.7];
    let h0 = [0.1f32, -0.4, 0.25, 0.9];
    let out = values(&cell.forward(tensor(x.to_vec(), [1, i], &device), tensor(h0.to_vec(), [1, h], &device)));
    let gate = |row: usize| {
        let gi: f64 = (0..i).map(|k| w_ih[row * i + k] as f64 * x[k] as f64).sum::<f64>() + b_ih[row] as f64;
        let gh: f64 = (0..h).map(|k| w_hh[row * h + k] as f64 * h0[k] as f64).sum::<f64>() + b_hh[row] as f64;
        (gi, gh)
    };
    for j in 0..h {
        let (ri, rh) = gate(j);
        let (zi, zh) = gate(h + j);
        let (ni, nh) = gate(2 * h + j);
        let r = sigmoid(ri + rh);
        let z = sigmoid(zi + zh);
        let n = (ni + r * nh).tanh();
        let expected = (1.0 - z) * n + z * h0[j] as f64;
        assert!((out[j] as f64 - expected).abs() < 1e-5, "unit {j}: {} vs {expected}", out[j]);
    }
}

#[test]
fn set_max_pool_starts_from_zero_and_ignores_padding() {
    let device = inference_device();
    // Set 0: members (1, −2) and (3, −1); set 1: one member (−5, 4) and padding (9, 9); set 2: empty.
    let features = tensor(vec![1.0, -2.0, 3.0, -1.0, -5.0, 4.0, 9.0, 9.0, 7.0, 7.0, 7.0, 7.0], [3, 2, 2], &device);
    let present = mask(vec![true, true, true, false, false, false], [3, 2], &device);
    assert_eq!(values(&max_pool_sets(features, present)), vec![3.0, 0.0, 0.0, 4.0, 0.0, 0.0]);
}

#[test]
fn non_negative_linear_starts_from_the_absolute_values_of_the_usual_draw() {
    // Every weight starts active, as the authors' positive-weights layer (abs of torch's draw); the bias keeps
    // its sign.
    let device = inference_device();
    let config = LinearConfig::new(6, 5);
    let plain = config.init(&device, &mut ChaCha8Rng::seed_from_u64(4));
    let non_negative = config.init_non_negative(&device, &mut ChaCha8Rng::seed_from_u64(4));
    let plain = ParamSet::<f32>::from_module(&plain, |s| s.into());
    let non_negative = ParamSet::<f32>::from_module(&non_negative, |s| s.into());
    let values = |p: &ParamSet, name: &str| p.get(name).unwrap().values.clone();
    let drawn = values(&plain, "weight");
    assert!(drawn.iter().any(|w| *w < 0.0), "the draw has negative weights to drop");
    assert_eq!(values(&non_negative, "weight"), drawn.iter().map(|w| w.abs()).collect::<Vec<_>>());
    assert_eq!(values(&non_negative, "bias"), values(&plain, "bias"));
}

#[test]
fn non_negative_linear_ignores_negative_weights() {
    let device = inference_device();
    let layer = LinearConfig::new(2, 1).init_non_negative(&device, &mut ChaCha8Rng::seed_from_u64(2));
    let mut p = ParamSet::<f32>::from_module(&layer, |s| s.to_string());
    p.tensors[0].values = vec![-3.0, 2.0];
    p.tensors[1].values = vec![0.5];
    let layer = p.load_into(layer, &device).unwrap();
    let y = values(&layer.forward(tensor(vec![10.0, 1.0], [1, 2], &device)));
    assert_eq!(y, vec![2.5]);
}

#[test]
fn log_variance_bounds_hold_at_extremes() {
    let device = inference_device();
    let bounds = LogVarBoundsConfig::new(1).init(&device);
    let y = values(&bounds.apply(tensor(vec![-100.0, 0.0, 100.0], [1, 3], &device).reshape([3, 1])));
    assert!(y[0] >= -10.0 - 1e-4 && y[0] < -9.0, "{y:?}");
    assert!(y[2] <= 0.5 + 1e-4 && y[2] > 0.0, "{y:?}");
    assert!(y[1] > y[0] && y[1] < y[2]);
}

#[test]
fn param_set_round_trips_and_gradients_cover_every_parameter() {
    let device = training_device();
    let mlp = EnsembleMlpConfig::new(2, 3, 2, 1, 4, Activation::Silu).init(&device, &mut ChaCha8Rng::seed_from_u64(3));
    let p = ParamSet::<f32>::from_module(&mlp, |s| s.to_string());
    let names: Vec<&str> = p.tensors.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["hidden_layers.0.weight", "hidden_layers.0.bias", "output.weight", "output.bias"]);
    let mut changed = p.clone();
    changed.tensors[2].values[0] += 1.0;
    let mlp = changed.load_into(mlp, &device).unwrap();
    assert_eq!(ParamSet::<f32>::from_module(&mlp, |s| s.to_string()), changed);
    let loss = mlp.forward(tensor(vec![0.5; 2 * 5 * 3], [2, 5, 3], &device)).powi_scalar(2).sum();
    let grads = ParamSet::<f32>::gradients(&mlp, &loss.backward());
    assert_eq!(grads.len(), 4);
    assert!(grads.iter().all(|g| g.iter().any(|v| *v != 0.0)));
}

#[test]
fn gaussian_nll_matches_formula() {
    let device = inference_device();
    let mean = tensor(vec![1.0, 2.0], [1, 1, 2], &device);
    let logvar = tensor(vec![0.0, 2.0f32.ln()], [1, 1, 2], &device);
    let target = tensor(vec![0.0, 0.0], [1, 1, 2], &device);
    let nll = crate::nn::tensor::scalar(&gaussian_nll(mean, logvar, target));
    let expected = 0.5 * ((1.0 + 0.0) + (4.0 / 2.0 + 2.0f64.ln())) / 2.0;
    assert!((nll - expected).abs() < 1e-6, "{nll} vs {expected}");
}
