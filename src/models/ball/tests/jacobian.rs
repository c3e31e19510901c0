//! The analytic Jacobian (appendix C.2) against central finite differences of the step itself.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::impact::time_of_impact;
use super::super::*;
use crate::filtering::Mat;

const H: f64 = 1e-5;

fn model() -> BallModel {
    BallModel::new(BallModelParams::thesis_learned()).unwrap()
}

fn random_state(rng: &mut ChaCha8Rng) -> BallState {
    let mut z = BallState::zeros();
    for i in 0..3 {
        z[P + i] = rng.random_range(-1.0..1.0);
        z[V + i] = rng.random_range(-6.0..6.0);
        z[W + i] = rng.random_range(-30.0..30.0);
    }
    z[AD] = rng.random_range(-1.0..1.0);
    z[AM] = rng.random_range(-1.0..1.0);
    z
}

/// Which smooth piece of g a state is on: the branch and the two clamps of the time of impact.
fn regime(model: &BallModel, z: &BallState, phase: Phase) -> (bool, bool, bool) {
    let toi = time_of_impact(z, &model.params().physics);
    (model.impacts(z, phase), toi.d_pz == 0.0, toi.d_vz == 0.0)
}

/// Central differences with one Richardson extrapolation (error O(h⁴): close to the plane the time of impact has
/// large higher derivatives, which plain O(h²) differences misjudge), or None when a perturbation would leave the
/// smooth piece z is on (g is not differentiable across the branch switch or a clamp).
fn finite_difference(model: &BallModel, z: &BallState, phase: Phase) -> Option<Mat<STATE_DIM, STATE_DIM>> {
    let here = regime(model, z, phase);
    let central = |i: usize, h: f64| {
        let (mut plus, mut minus) = (*z, *z);
        plus[i] += h;
        minus[i] -= h;
        let same = regime(model, &plus, phase) == here && regime(model, &minus, phase) == here;
        same.then(|| (model.step(&plus, phase).0 - model.step(&minus, phase).0) / (2.0 * h))
    };
    let mut jac = Mat::<STATE_DIM, STATE_DIM>::zeros();
    for i in 0..STATE_DIM {
        let h = H * z[i].abs().max(1.0);
        let (coarse, fine) = (central(i, h)?, central(i, h / 2.0)?);
        jac.set_column(i, &((fine * 4.0 - coarse) / 3.0));
    }
    Some(jac)
}

/// Largest entrywise error relative to the entry's size, with entries below 1 compared absolutely (a relative
/// error of a zero entry means nothing).
fn relative_error(analytic: &Mat<STATE_DIM, STATE_DIM>, numeric: &Mat<STATE_DIM, STATE_DIM>) -> f64 {
    analytic.iter().zip(numeric.iter()).map(|(a, n)| (a - n).abs() / n.abs().max(1.0)).fold(0.0, f64::max)
}

/// Checks `count` states drawn by `draw` that land in the wanted branch; returns the worst error.
fn check(count: usize, seed: u64, want_impact: bool, draw: impl Fn(&mut ChaCha8Rng) -> (BallState, Phase)) -> f64 {
    let model = model();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut checked, mut worst) = (0, 0.0f64);
    let mut tries = 0;
    while checked < count {
        tries += 1;
        assert!(tries < 20 * count, "sampler rarely hits the wanted branch");
        let (z, phase) = draw(&mut rng);
        if model.impacts(&z, phase) != want_impact {
            continue;
        }
        let Some(numeric) = finite_difference(&model, &z, phase) else { continue };
        let (next, analytic, _) = model.step_with_jacobian(&z, phase);
        assert_eq!(next, model.step(&z, phase).0);
        let err = relative_error(&analytic, &numeric);
        assert!(err < 1e-5, "error {err:e} at z = {z:?} ({phase:?})\nanalytic {analytic}\nnumeric {numeric}");
        worst = worst.max(err);
        checked += 1;
    }
    eprintln!("worst relative error over {count} states: {worst:.2e}");
    worst
}

fn table_top() -> f64 {
    let phys = BallPhysics::default();
    phys.table_z + phys.ball_radius
}

#[test]
fn free_flight_jacobian_matches_finite_differences() {
    check(1000, 1, false, |rng| {
        let mut z = random_state(rng);
        z[P + 2] = table_top() + rng.random_range(0.05..1.5);
        (z, Phase::BeforeImpact)
    });
}

#[test]
fn free_flight_jacobian_matches_near_the_plane() {
    // Ends of steps just above the plane, and balls already below it after their bounce.
    check(1000, 2, false, |rng| {
        let mut z = random_state(rng);
        let dt = BallPhysics::default().dt;
        let end_height = rng.random_range(1e-5..2e-2);
        z[P + 2] = table_top() + end_height - dt * z[V + 2];
        let phase = if rng.random_bool(0.3) { Phase::AfterImpact } else { Phase::BeforeImpact };
        if phase == Phase::AfterImpact {
            z[P + 2] -= rng.random_range(0.0..0.3);
        }
        (z, phase)
    });
}

#[test]
fn impact_jacobian_matches_finite_differences() {
    check(1000, 3, true, |rng| {
        let mut z = random_state(rng);
        let dt = BallPhysics::default().dt;
        z[V + 2] = -rng.random_range(0.5..7.0);
        // Lower edge above the plane by a fraction of what the Euler step covers, so the step crosses it.
        z[P + 2] = table_top() + rng.random_range(0.0..1.0) * -z[V + 2] * dt;
        (z, Phase::BeforeImpact)
    });
}

#[test]
fn impact_jacobian_matches_at_the_edges_of_the_step() {
    // Impacts right at the start or the end of the step, and balls starting below the plane (clamped height).
    check(1000, 4, true, |rng| {
        let mut z = random_state(rng);
        let dt = BallPhysics::default().dt;
        z[V + 2] = rng.random_range(-4.0..0.5);
        let offset = match rng.random_range(0..3) {
            0 => rng.random_range(1e-4..1e-3),
            1 => -z[V + 2] * dt * rng.random_range(0.97..1.0),
            _ => -rng.random_range(0.0..0.01),
        };
        z[P + 2] = table_top() + offset;
        (z, Phase::BeforeImpact)
    });
}
