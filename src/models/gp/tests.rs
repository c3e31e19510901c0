use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::constraint::{inverse_softplus, softplus};
use super::*;

struct Problem {
    inputs: Vec<f64>,
    targets: Vec<f64>,
    prior_mean: Vec<f64>,
    kernel: SeArd,
    noise: f64,
}

/// A 3-d latent + 1-d action problem like DLGPD's transition GPs, with the mean = the first input.
fn problem(n: usize, seed: u64) -> Problem {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let d = 4;
    let inputs: Vec<f64> = (0..n * d).map(|_| rng.random_range(-2.0..2.0)).collect();
    let prior_mean: Vec<f64> = (0..n).map(|i| inputs[i * d]).collect();
    let targets: Vec<f64> =
        (0..n).map(|i| inputs[i * d] + 0.3 * (inputs[i * d + 1]).sin() + rng.random_range(-0.05..0.05)).collect();
    Problem {
        inputs,
        targets,
        prior_mean,
        kernel: SeArd { lengthscales: vec![0.7, 1.3, 2.0, 0.9], outputscale: 0.8 },
        noise: 0.05,
    }
}

fn condition(p: &Problem) -> ConditionedGp {
    ConditionedGp::condition(&p.inputs, &p.targets, &p.prior_mean, p.kernel.clone(), p.noise).unwrap()
}

fn dense_kernel(k: &SeArd, a: &[f64], b: &[f64]) -> DMatrix<f64> {
    let d = k.dims();
    DMatrix::from_fn(a.len() / d, b.len() / d, |i, j| {
        let r2: f64 = (0..d).map(|c| ((a[i * d + c] - b[j * d + c]) / k.lengthscales[c]).powi(2)).sum();
        k.outputscale * (-0.5 * r2).exp()
    })
}

#[test]
fn posterior_equals_a_dense_reference_solve() {
    let p = problem(60, 1);
    let gp = condition(&p);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let queries: Vec<f64> = (0..25 * 4).map(|_| rng.random_range(-2.5..2.5)).collect();
    let query_mean: Vec<f64> = (0..25).map(|i| queries[i * 4]).collect();
    let got = gp.predict(&queries, &query_mean, true).unwrap();

    let n = p.targets.len();
    let ky = dense_kernel(&p.kernel, &p.inputs, &p.inputs) + DMatrix::identity(n, n) * p.noise;
    let inverse = ky.clone().try_inverse().unwrap();
    let residual = DVector::from_iterator(n, p.targets.iter().zip(&p.prior_mean).map(|(y, m)| y - m));
    let cross = dense_kernel(&p.kernel, &queries, &p.inputs);
    let mean = &cross * (&inverse * &residual);
    let cov = &cross * &inverse * cross.transpose();
    for i in 0..25 {
        let (m, v) = (query_mean[i] + mean[i], p.kernel.outputscale - cov[(i, i)]);
        assert!((got.mean[i] - m).abs() < 1e-6, "mean {i}: {} vs {m}", got.mean[i]);
        assert!((got.variance[i] - v).abs() < 1e-6, "variance {i}: {} vs {v}", got.variance[i]);
    }
    let nll = 0.5
        * (residual.dot(&(&inverse * &residual))
            + ky.determinant().ln()
            + n as f64 * (2.0 * std::f64::consts::PI).ln());
    assert!((gp.neg_log_likelihood() - nll).abs() < 1e-6 * nll.abs().max(1.0), "{} vs {nll}", gp.neg_log_likelihood());
    assert_eq!(gp.jitter(), 0.0);
}

/// Central differences of the negative log likelihood along one coordinate of the problem.
fn numeric(p: &Problem, poke: impl Fn(&mut Problem, f64)) -> f64 {
    let h = 1e-6;
    let at = |delta: f64| {
        let mut q = Problem {
            inputs: p.inputs.clone(),
            targets: p.targets.clone(),
            prior_mean: p.prior_mean.clone(),
            kernel: p.kernel.clone(),
            noise: p.noise,
        };
        poke(&mut q, delta);
        condition(&q).neg_log_likelihood()
    };
    (at(h) - at(-h)) / (2.0 * h)
}

fn close(what: &str, analytic: f64, numeric: f64) {
    let tol = 1e-5 * analytic.abs().max(numeric.abs()).max(1.0);
    assert!((analytic - numeric).abs() < tol, "{what}: analytic {analytic} vs finite difference {numeric}");
}

#[test]
fn every_gradient_matches_finite_differences() {
    let p = problem(30, 2);
    let g = condition(&p).gradients();
    for i in 0..p.inputs.len() {
        close(&format!("input {i}"), g.inputs[i], numeric(&p, |q, h| q.inputs[i] += h));
    }
    for i in 0..p.targets.len() {
        close(&format!("target {i}"), g.targets[i], numeric(&p, |q, h| q.targets[i] += h));
        close(&format!("prior mean {i}"), g.prior_mean[i], numeric(&p, |q, h| q.prior_mean[i] += h));
    }
    for c in 0..4 {
        close(&format!("lengthscale {c}"), g.lengthscales[c], numeric(&p, |q, h| q.kernel.lengthscales[c] += h));
    }
    close("outputscale", g.outputscale, numeric(&p, |q, h| q.kernel.outputscale += h));
    close("noise", g.noise, numeric(&p, |q, h| q.noise += h));
}

#[test]
fn a_singular_kernel_matrix_is_recovered_by_jitter_and_bad_data_are_errors() {
    // The same input twice and no noise: K is singular; jitter makes it factorizable.
    let kernel = SeArd { lengthscales: vec![1.0], outputscale: 1.0 };
    let gp = ConditionedGp::condition(&[0.5, 0.5, 1.0], &[1.0, 1.0, 2.0], &[0.0; 3], kernel.clone(), 0.0).unwrap();
    assert!(gp.jitter() > 0.0 && gp.jitter() <= 1e-4, "jitter {}", gp.jitter());
    assert!(gp.neg_log_likelihood().is_finite());

    let err = |r: crate::error::Result<ConditionedGp>| r.expect_err("an error").to_string();
    let e = err(ConditionedGp::condition(&[0.5, f64::NAN], &[1.0, 1.0], &[0.0; 2], kernel.clone(), 0.1));
    assert!(e.contains("inputs") && e.contains("NaN"), "{e}");
    let e = err(ConditionedGp::condition(&[0.5, 1.0], &[1.0], &[0.0], kernel.clone(), 0.1));
    assert!(e.contains("expected 1 rows of 1"), "{e}");
    let e = err(ConditionedGp::condition(
        &[0.5],
        &[1.0],
        &[0.0],
        SeArd { lengthscales: vec![-1.0], outputscale: 1.0 },
        0.1,
    ));
    assert!(e.contains("hyperparameters"), "{e}");
    let e = err(ConditionedGp::condition(&[], &[], &[], kernel.clone(), 0.1));
    assert!(e.contains("no training points"), "{e}");
    let gp = ConditionedGp::condition(&[0.5], &[1.0], &[0.0], kernel, 0.1).unwrap();
    assert!(gp.predict(&[0.1, 0.2], &[0.0], false).is_err());
    assert!(gp.predict(&[f64::INFINITY], &[0.0], false).is_err());
}

#[test]
fn constraints_round_trip_and_the_gamma_prior_has_the_right_slope() {
    let c = GreaterThan { lower: 1e-2 };
    for raw in [-30.0, -3.0, 0.0, 2.5, 40.0] {
        let back = c.raw_for(c.value(raw)).unwrap();
        assert!((back - raw).abs() < 1e-6 * raw.abs().max(1.0), "{raw} → {back}");
        let h = 1e-6;
        let slope = (c.value(raw + h) - c.value(raw - h)) / (2.0 * h);
        assert!((slope - c.slope(raw)).abs() < 1e-6, "slope at {raw}");
    }
    assert!(c.raw_for(1e-2).is_none() && c.raw_for(f64::NAN).is_none());
    assert!((softplus(inverse_softplus(0.693)) - 0.693).abs() < 1e-12);
    let prior = GammaPrior { concentration: 1.0, rate: 5.0 };
    // Gamma(1, 5) is the exponential distribution with rate 5.
    assert!((prior.log_density(0.3) - (5f64.ln() - 1.5)).abs() < 1e-12);
    let h = 1e-6;
    let numeric = (prior.log_density(0.3 + h) - prior.log_density(0.3 - h)) / (2.0 * h);
    assert!((prior.d_log_density(0.3) - numeric).abs() < 1e-6);
}

#[test]
fn the_objective_differentiates_through_constraints_and_prior() {
    let p = problem(20, 3);
    let mut hypers = GpHypers::new(&HyperInit::dlgpd(4, 0.9)).unwrap();
    hypers.raw_lengthscales = vec![0.2, -0.4, 1.1, 0.0];
    // A signal-to-noise ratio of several hundred, where the penalty is of order 10 and its slope large.
    hypers.raw_outputscale = 3.0;
    hypers.raw_noise = -5.0;
    let value_at = |h: &GpHypers| h.objective(&p.inputs, &p.targets, &p.prior_mean).unwrap().0;
    let (_, g, _) = hypers.objective(&p.inputs, &p.targets, &p.prior_mean).unwrap();
    let step = 1e-6;
    let fd = |poke: &dyn Fn(&mut GpHypers, f64)| {
        let (mut a, mut b) = (hypers.clone(), hypers.clone());
        poke(&mut a, step);
        poke(&mut b, -step);
        (value_at(&a) - value_at(&b)) / (2.0 * step)
    };
    for c in 0..4 {
        close(&format!("raw lengthscale {c}"), g.raw_lengthscales[c], fd(&|h, d| h.raw_lengthscales[c] += d));
    }
    close("raw outputscale", g.raw_outputscale, fd(&|h, d| h.raw_outputscale += d));
    close("raw noise", g.raw_noise, fd(&|h, d| h.raw_noise += d));
    let (penalty, d_signal, d_noise) = hypers.snr_penalty();
    assert!(penalty > 1.0, "penalty {penalty}");
    let snr_fd = |poke: &dyn Fn(&mut GpHypers, f64)| {
        let (mut a, mut b) = (hypers.clone(), hypers.clone());
        poke(&mut a, step);
        poke(&mut b, -step);
        (a.snr_penalty().0 - b.snr_penalty().0) / (2.0 * step)
    };
    close("snr / raw outputscale", d_signal, snr_fd(&|h, d| h.raw_outputscale += d));
    close("snr / raw noise", d_noise, snr_fd(&|h, d| h.raw_noise += d));
    // The bounds hold whatever the raw values.
    hypers.raw_noise = -500.0;
    assert!(hypers.noise() >= 0.9e-3);
    assert!(GpHypers::new(&HyperInit::dlgpd(4, 0.0)).is_err(), "zero target variance leaves no valid start");
}

#[test]
fn hyperparameters_round_trip_through_a_checkpoint_under_gpytorch_names() {
    let mut hypers = GpHypers::new(&HyperInit::dlgpd(4, 0.7)).unwrap();
    hypers.raw_lengthscales = vec![0.1, -0.2, 0.3, 1.4];
    let stored = hypers.stored("transition.gp_0");
    assert!(stored.iter().any(|t| t.name == "transition.gp_0.covar_module.base_kernel.raw_lengthscale"));
    let bytes = crate::train::tensors::to_bytes(&stored).unwrap();
    let parsed = crate::train::tensors::parse(std::path::Path::new("m.safetensors"), &bytes).unwrap();
    let back = GpHypers::from_stored("transition.gp_0", &parsed, 4, hypers.outputscale_prior).unwrap();
    assert_eq!(back, hypers);
    let e = GpHypers::from_stored("transition.gp_0", &parsed, 3, None).unwrap_err().to_string();
    assert!(e.contains("raw_lengthscale") && e.contains("expected 3"), "{e}");
    assert!(GpHypers::from_stored("reward", &parsed, 4, None).unwrap_err().to_string().contains("lack"));
    let mut bad = stored.clone();
    bad[1] = crate::train::tensors::StoredTensor::f64(bad[1].name.clone(), vec![], vec![-1.0]);
    assert!(GpHypers::from_stored("transition.gp_0", &bad, 4, None).is_err());
}
