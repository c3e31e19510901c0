use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;

/// Constant-velocity model (position, velocity), position observed: linear, so the EKF must be the Kalman filter.
struct ConstantVelocity {
    dt: f64,
    q: f64,
    r: f64,
}

impl EkfModel<2, 1> for ConstantVelocity {
    type Mode = ();

    fn predict(&self, x: &Vector<2>, _: &mut ()) -> (Vector<2>, Mat<2, 2>) {
        let f = Mat::<2, 2>::new(1.0, self.dt, 0.0, 1.0);
        (f * x, f)
    }

    fn measure(&self, x: &Vector<2>) -> (Vector<1>, Mat<1, 2>) {
        (Vector::<1>::new(x[0]), Mat::<1, 2>::new(1.0, 0.0))
    }

    fn process_noise(&self, _: &Vector<2>) -> Mat<2, 2> {
        let dt = self.dt;
        self.q * Mat::<2, 2>::new(dt.powi(3) / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt)
    }

    fn measurement_noise(&self) -> Mat<1, 1> {
        Mat::<1, 1>::new(self.r)
    }
}

/// A 3-d random walk seen through a fixed, non-trivial linear map with correlated noise.
struct Mixed {
    h: Mat<3, 3>,
    r: Mat<3, 3>,
}

impl EkfModel<3, 3> for Mixed {
    type Mode = ();

    fn predict(&self, x: &Vector<3>, _: &mut ()) -> (Vector<3>, Mat<3, 3>) {
        (*x, Mat::<3, 3>::identity())
    }

    fn measure(&self, x: &Vector<3>) -> (Vector<3>, Mat<3, 3>) {
        (self.h * x, self.h)
    }

    fn process_noise(&self, _: &Vector<3>) -> Mat<3, 3> {
        Mat::<3, 3>::identity() * 0.01
    }

    fn measurement_noise(&self) -> Mat<3, 3> {
        self.r
    }
}

fn mixed() -> Mixed {
    let h = Mat::<3, 3>::new(1.0, 0.2, 0.0, -0.3, 0.9, 0.1, 0.0, 0.5, 1.2);
    let r = Mat::<3, 3>::new(0.04, 0.01, 0.0, 0.01, 0.09, -0.02, 0.0, -0.02, 0.05);
    Mixed { h, r }
}

/// Scalar-arithmetic Kalman filter for the constant-velocity model, textbook form (eq. 6.6-6.7), written without
/// the code under test so that agreement means something.
fn closed_form_cv(
    model: &ConstantVelocity,
    x0: [f64; 2],
    p0: [[f64; 2]; 2],
    ms: &[Option<f64>],
) -> Vec<([f64; 2], [[f64; 2]; 2], f64)> {
    let dt = model.dt;
    let (q11, q12, q22) = (model.q * dt.powi(3) / 3.0, model.q * dt * dt / 2.0, model.q * dt);
    let (mut x, mut p) = (x0, p0);
    let mut ll = 0.0;
    let mut out = Vec::new();
    for m in ms {
        x = [x[0] + dt * x[1], x[1]];
        p = [
            [p[0][0] + dt * (p[1][0] + p[0][1]) + dt * dt * p[1][1] + q11, p[0][1] + dt * p[1][1] + q12],
            [p[1][0] + dt * p[1][1] + q12, p[1][1] + q22],
        ];
        if let Some(m) = m {
            let v = m - x[0];
            let s = p[0][0] + model.r;
            let k = [p[0][0] / s, p[1][0] / s];
            x = [x[0] + k[0] * v, x[1] + k[1] * v];
            p = [
                [p[0][0] - k[0] * s * k[0], p[0][1] - k[0] * s * k[1]],
                [p[1][0] - k[1] * s * k[0], p[1][1] - k[1] * s * k[1]],
            ];
            ll += -0.5 * (v * v / s + s.ln() + (2.0 * PI).ln());
        }
        out.push((x, p, ll));
    }
    out
}

#[test]
fn linear_model_matches_closed_form_kalman_filter() {
    let model = ConstantVelocity { dt: 0.1, q: 0.5, r: 0.04 };
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let ms: Vec<Option<f64>> = (0..200)
        .map(|k| if k % 7 == 3 { None } else { Some(0.3 * k as f64 * 0.1 + rng.random_range(-0.2..0.2)) })
        .collect();
    let x0 = [0.1, -0.2];
    let p0 = [[1.0, 0.1], [0.1, 2.0]];
    let expected = closed_form_cv(&model, x0, p0, &ms);

    let slots: Vec<Option<[f64; 1]>> = ms.iter().map(|m| m.map(|v| [v])).collect();
    let out = filter(&model, &Vector::<2>::from(x0), &Mat::<2, 2>::new(1.0, 0.1, 0.1, 2.0), &slots).unwrap();

    for (k, (x, p, _)) in expected.iter().enumerate() {
        assert!((out.states[k] - Vector::<2>::from(*x)).amax() < 1e-10, "state {k}");
        let p = Mat::<2, 2>::new(p[0][0], p[0][1], p[1][0], p[1][1]);
        assert!((out.covariances[k] - p).amax() < 1e-10, "covariance {k}");
    }
    let ll = expected.last().unwrap().2;
    assert!((out.log_likelihood - ll).abs() < 1e-9 * ll.abs().max(1.0), "{} vs {ll}", out.log_likelihood);
}

#[test]
fn log_likelihood_is_the_gaussian_density_of_the_innovation() {
    let model = mixed();
    let prior = Belief::new(
        Vector::<3>::new(0.5, -1.0, 2.0),
        Mat::<3, 3>::new(0.3, 0.05, 0.0, 0.05, 0.2, 0.04, 0.0, 0.04, 0.5),
    );
    let m = Vector::<3>::new(0.2, -0.4, 3.1);
    let (_, ll) = update(&model, &prior, &m).unwrap();

    let s = model.h * prior.cov * model.h.transpose() + model.r;
    let v = m - model.h * prior.mean;
    let quad = (v.transpose() * s.try_inverse().unwrap() * v)[(0, 0)];
    let direct = (-0.5 * quad).exp() / ((2.0 * PI).powi(3) * s.determinant()).sqrt();
    assert!((ll - direct.ln()).abs() < 1e-12, "{ll} vs {}", direct.ln());
}

#[test]
fn missing_measurements_only_predict() {
    let model = mixed();
    let x0 = Vector::<3>::new(0.0, 1.0, -1.0);
    let p0 = Mat::<3, 3>::identity() * 0.2;
    let slots = [Some([0.1, 0.9, -0.8]), None, None, Some([0.2, 1.1, -0.7]), None];
    let out = filter(&model, &x0, &p0, &slots).unwrap();

    let (b1, ll1) = update(&model, &predict(&model, &Belief::new(x0, p0)), &Vector::<3>::new(0.1, 0.9, -0.8)).unwrap();
    let b2 = predict(&model, &b1);
    let b3 = predict(&model, &b2);
    let (b4, ll4) = update(&model, &predict(&model, &b3), &Vector::<3>::new(0.2, 1.1, -0.7)).unwrap();
    let b5 = predict(&model, &b4);
    for (k, b) in [b1, b2, b3, b4, b5].iter().enumerate() {
        assert_eq!(out.states[k], b.mean, "state {k}");
        assert_eq!(out.covariances[k], b.cov, "cov {k}");
    }
    assert_eq!(out.log_likelihood, ll1 + ll4);
}

#[test]
fn all_missing_is_a_forecast() {
    let model = ConstantVelocity { dt: 0.05, q: 0.1, r: 0.01 };
    let start = Belief::new(Vector::<2>::new(1.0, 2.0), Mat::<2, 2>::identity());
    let out = filter_belief(&model, &start, &[None; 12]).unwrap();
    let fc = forecast(&model, &start, 12);
    let means = forecast_means(&model, &start.mean, (), 12);
    assert_eq!(out.log_likelihood, 0.0);
    for k in 0..12 {
        assert_eq!(out.states[k], fc[k].mean);
        assert_eq!(out.covariances[k], fc[k].cov);
        assert_eq!(means[k], fc[k].mean);
    }
    assert_eq!(out.last_belief().unwrap(), fc[11]);
}

#[test]
fn indefinite_innovation_covariance_is_a_typed_error() {
    let mut model = mixed();
    model.r = -Mat::<3, 3>::identity();
    let err = filter(&model, &Vector::<3>::zeros(), &(Mat::<3, 3>::identity() * 0.01), &[None, Some([0.0; 3])]);
    assert_eq!(
        err.unwrap_err(),
        FilterError::AtMeasurement { index: 1, source: Box::new(FilterError::InnovationNotPositiveDefinite) }
    );
}

#[test]
fn non_finite_measurement_is_a_typed_error() {
    let model = mixed();
    let err = filter(&model, &Vector::<3>::zeros(), &Mat::<3, 3>::identity(), &[Some([0.0, f64::NAN, 0.0])]);
    assert_eq!(err.unwrap_err(), FilterError::NonFiniteMeasurement.at(0));
}
