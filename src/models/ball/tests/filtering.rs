//! The ball model inside the generic EKF: convergence on its own trajectories and covariance health.

use nalgebra::Cholesky;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::super::*;
use crate::filtering::{filter_belief, forecast, forecast_means};

/// A launched ball (towards −y, slightly up, with spin) that bounces once within `steps`. Spin and coefficients
/// lie within about one standard deviation of the uninformed initial belief, as a trajectory the model was fitted
/// to would.
fn truth(model: &BallModel, steps: usize) -> Vec<BallState> {
    let z0 = [0.1, 2.8, 0.1, 0.4, -4.5, 1.0, -0.9, 0.7, 0.4, model.params().a_d0 + 0.002, 0.05];
    let mut z = BallState::from(z0);
    let mut phase = Phase::BeforeImpact;
    let mut out = vec![z];
    for _ in 1..steps {
        (z, phase) = model.step(&z, phase);
        out.push(z);
    }
    assert_eq!(phase, Phase::AfterImpact, "the test trajectory should contain the bounce");
    out
}

#[test]
fn noiseless_trajectory_is_tracked() {
    let model = BallModel::new(BallModelParams::thesis_learned()).unwrap();
    let states = truth(&model, 160);
    let pos = |k: usize| [states[k][P], states[k][P + 1], states[k][P + 2]];
    // Dropouts, including right after initialization and around the bounce.
    let slots: Vec<Option<[f64; 3]>> =
        (2..states.len()).map(|k| if k % 9 == 4 || (95..98).contains(&k) { None } else { Some(pos(k)) }).collect();
    let start = initial_belief(model.params(), pos(0), pos(1), 1, false, &SpinPrior::Uninformed).unwrap();
    let out = filter_belief(&model, &start, &slots).unwrap();

    let position_error = |k: usize| (out.states[k - 2].fixed_rows::<3>(P) - states[k].fixed_rows::<3>(P)).norm();
    let velocity_error = |k: usize| (out.states[k - 2].fixed_rows::<3>(V) - states[k].fixed_rows::<3>(V)).norm();
    assert!(velocity_error(3) > 0.01, "the finite-difference start should be visibly off");
    for k in states.len() - 20..states.len() {
        assert!(position_error(k) < 2e-4, "step {k}: position error {}", position_error(k));
        assert!(velocity_error(k) < 0.03, "step {k}: velocity error {}", velocity_error(k));
    }
    assert_eq!(*out.modes.last().unwrap(), Phase::AfterImpact);
    assert!(out.log_likelihood.is_finite());

    // A forecast from the last belief follows the truth's own continuation.
    let last = out.last_belief().unwrap();
    let means = forecast_means(&model, &last.mean, last.mode, 10);
    let full = forecast(&model, &last, 10);
    for k in 0..10 {
        assert_eq!(means[k], full[k].mean);
    }
}

#[test]
fn covariance_stays_symmetric_positive_definite_for_500_steps() {
    for params in [BallModelParams::thesis_learned(), BallModelParams::initial()] {
        let model = BallModel::new(params).unwrap();
        let states = truth(&model, 502);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let noise: Vec<Normal<f64>> =
            model.params().r_diag.iter().map(|r| Normal::new(0.0, r.sqrt()).unwrap()).collect();
        let measure = |k: usize, rng: &mut ChaCha8Rng| -> [f64; 3] {
            std::array::from_fn(|i| states[k][P + i] + noise[i].sample(rng))
        };
        let (m1, m2) = (measure(0, &mut rng), measure(1, &mut rng));
        let slots: Vec<Option<[f64; 3]>> =
            (2..states.len()).map(|k| if k % 5 == 0 { None } else { Some(measure(k, &mut rng)) }).collect();
        let start = initial_belief(model.params(), m1, m2, 1, false, &SpinPrior::Uninformed).unwrap();
        let out = filter_belief(&model, &start, &slots).unwrap();
        assert_eq!(out.covariances.len(), 500);
        for (k, p) in out.covariances.iter().enumerate() {
            assert_eq!(*p, p.transpose(), "step {k}: covariance not symmetric");
            assert!(Cholesky::new(*p).is_some(), "step {k}: covariance not positive definite");
            assert!(p.symmetric_eigenvalues().min() > 0.0, "step {k}");
        }
    }
}
