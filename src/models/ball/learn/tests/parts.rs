//! Pieces of the learner on their own.

use nalgebra::Matrix3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::device::{tensor, values};
use super::super::linalg::inverse_3x3;
use super::super::spin_net::HIDDEN;
use super::super::*;
use super::data::recordings;
use crate::data::ball_io::{Recording, RecordingInfo};
use crate::envs::ball::launcher::{canonical_spin, wheel_rpm};
use crate::envs::ball::{LaunchParams, Orientation};
use crate::models::ball::BallModelParams;

#[test]
fn softplus_round_trips_and_floors() {
    for v in [1e-4, 1e-2, 1.0, 3.28, 1.00001e-6] {
        assert!((softplus(inverse_softplus(v)) - v).abs() < 1e-12 * v.max(1e-6), "{v}");
    }
    // Table C.2's variances at the floor itself come back a hair above it.
    let at_floor = softplus(inverse_softplus(1e-6));
    assert!(at_floor > 1e-6 && at_floor - 1e-6 < 1e-11);
}

#[test]
fn parameters_round_trip_through_the_module() {
    let device = training_device();
    for params in [BallModelParams::initial(), BallModelParams::thesis_learned()] {
        let back = BallParamsModule::from_params(&params, None, &device).to_params(&params.physics);
        assert_eq!(back.c, params.c);
        assert_eq!((back.a_d0, back.a_m0), (params.a_d0, params.a_m0));
        let pairs = back.q_diag.iter().zip(&params.q_diag).chain(back.r_diag.iter().zip(&params.r_diag));
        for (a, b) in pairs.chain(back.init_spin_var_after_impact.iter().zip(&params.init_spin_var_after_impact)) {
            assert!((a - b).abs() < 1e-11 * b.max(1.0), "{a} vs {b}");
        }
        back.validate().unwrap();
    }
}

#[test]
fn inverse_3x3_matches_nalgebra() {
    let device = training_device();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mats: Vec<Matrix3<f64>> = (0..5)
        .map(|_| {
            let a = Matrix3::from_fn(|_, _| rng.random_range(-1.0..1.0));
            (a * a.transpose() + Matrix3::identity() * 0.1) * 1e-4
        })
        .collect();
    let flat: Vec<f64> = mats.iter().flat_map(|m| m.transpose().iter().copied().collect::<Vec<_>>()).collect();
    let (inv, det) = inverse_3x3(tensor(flat, [5, 3, 3], &device));
    let (inv, det) = (values(&inv), values(&det));
    for (k, m) in mats.iter().enumerate() {
        let expected = m.try_inverse().unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let got = inv[9 * k + 3 * i + j];
                assert!((got - expected[(i, j)]).abs() < 1e-9 * expected.amax(), "{k} ({i},{j})");
            }
        }
        assert!((det[k] - m.determinant()).abs() < 1e-12 * m.determinant().abs());
    }
}

#[test]
fn launch_rotation_turns_the_canonical_shot_into_the_launcher_s() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for orientation in Orientation::ALL {
        let motors = [rng.random_range(0.1..0.2), rng.random_range(0.1..0.2), rng.random_range(0.1..0.2)];
        let shot =
            LaunchParams::from_actuation(orientation, motors, rng.random_range(0.4..0.6), rng.random_range(0.7..1.0));
        let r = launch_rotation(&shot.side_info());
        let spin = canonical_spin(wheel_rpm(motors));
        let velocity = shot.velocity();
        for i in 0..3 {
            let rotated_spin: f64 = (0..3).map(|j| r[i][j] * spin[j]).sum();
            assert!((rotated_spin - shot.spin[i]).abs() < 1e-9, "{orientation}: spin {i}");
            assert!((r[i][0] * shot.speed - velocity[i]).abs() < 1e-9, "{orientation}: direction {i}");
        }
    }
}

#[test]
fn spin_network_weights_round_trip_and_agree_with_the_tensor_net() {
    let device = training_device();
    let net = SpinNet::init(&mut ChaCha8Rng::seed_from_u64(4), &device);
    let weights = net.weights();
    assert_eq!(SpinNet::from_weights(&weights, &device).unwrap().weights(), weights);
    let s_m = [0.12, 0.17, 0.15];
    let (mean, var) = net.forward(tensor(s_m.to_vec(), [1, 3], &device));
    let (m, v) = weights.canonical(s_m);
    for i in 0..3 {
        assert!((values(&mean)[i] - m[i]).abs() < 1e-12 && (values(&var)[i] - v[i]).abs() < 1e-12);
    }
    let bad = SpinNetWeights { w1: vec![0.0; 5], ..weights };
    assert!(SpinNet::from_weights(&bad, &device).is_err());
}

/// Weights are checked one by one, and together by how far the outputs can reach over actuations in [0, 1]³:
/// all ones reach 256 · 3 = 768, all twenties 307 200, past what any launcher's spin needs.
#[test]
fn spin_network_weights_are_refused_where_their_outputs_could_run_away() {
    let weights = |w1: f64, w2: f64| SpinNetWeights { w1: vec![w1; 3 * HIDDEN], w2: vec![w2; 6 * HIDDEN] };
    weights(1.0, 1.0).check().unwrap();
    let err = weights(20.0, 20.0).check().unwrap_err().to_string();
    assert!(err.contains("output 0 can reach 307200") && err.contains("±1e5"), "{err}");
    let mut absurd = weights(0.1, 0.1);
    absurd.w2[1256] = 1e19;
    let err = absurd.check().unwrap_err().to_string();
    assert!(err.contains("w2[1256] = 1e19: expected a finite number in [-1e6, 1e6]"), "{err}");
}

fn recording(frames: Vec<u64>, measured: impl Fn(u64) -> bool, impact_frame: Option<u64>) -> Recording {
    let positions = frames.iter().map(|&f| measured(f).then_some([0.0, 1.0 - 0.02 * f as f64, 0.3])).collect();
    Recording { id: 1, frames, positions, truth: None, info: RecordingInfo { impact_frame, ..Default::default() } }
}

#[test]
fn chunks_start_on_two_measured_frames_and_skip_the_bounce_pair() {
    let physics = BallModelParams::initial().physics;
    // Frames 10..=69 with frame 30 absent from the list and frame 33 lost; bounce first seen at frame 40.
    let frames: Vec<u64> = (10..70).filter(|&f| f != 30).collect();
    let rec = recording(frames, |f| f != 33, Some(40));
    let chunks = cut_chunks(&[rec], 20, &physics).unwrap();
    let starts: Vec<u64> = chunks.iter().map(|c| c.start_frame).collect();
    // Windows of 20 frames start at 10..=50; starts whose pair includes 30 or 33, or straddles 39/40, drop out.
    let expected: Vec<u64> = (10..=50).filter(|s| ![29, 30, 32, 33, 39].contains(s)).collect();
    assert_eq!(starts, expected);
    for c in &chunks {
        assert_eq!(c.slots.len(), 18);
        assert_eq!(c.after_impact, c.start_frame >= 40, "start {}", c.start_frame);
        let lost = (c.start_frame + 2..c.start_frame + 20).filter(|f| [30, 33].contains(f)).count();
        assert_eq!(c.measured(), 18 - lost);
    }
    assert!(cut_chunks(&[], 2, &physics).is_err());
}

#[test]
fn detected_impact_frames_match_the_simulator_s() {
    let physics = BallModelParams::initial().physics;
    let recs = recordings(20, 6);
    let mut exact = 0;
    for rec in &recs {
        let dense: Vec<Option<[f64; 3]>> = rec.positions.clone();
        let found = detect_impact_frame(&dense, &physics).map(|k| rec.frames[0] + k as u64);
        let truth = rec.info.impact_frame.unwrap();
        // A bounce hidden by dropouts is missed; otherwise the frame is at most one off.
        if let Some(f) = found {
            assert!(f.abs_diff(truth) <= 1, "detected {f}, simulator {truth}");
            exact += usize::from(f == truth);
        }
    }
    assert!(exact >= 15, "{exact} of 20 exact");
}

/// One step of the batched model, free and impact branches with their Jacobians, against
/// `BallModel::step_with_jacobian` on states that exercise every clamp of the time of impact.
#[test]
fn batched_step_and_jacobian_match_the_reference_model() {
    use super::super::filter::impact_map;
    use super::super::flight::{flight, free_jacobian, free_step, Consts, StepLen};
    use super::super::impact::{impact_step, ImpactPlan};
    use crate::models::ball::{BallModel, BallState, Phase};

    let params = BallModelParams::thesis_learned();
    let model = BallModel::new(params.clone()).unwrap();
    let phys = &params.physics;
    let on_table = phys.table_z + phys.ball_radius;
    let states: [[f64; 11]; 5] = [
        // Free flight with spin.
        [0.1, 2.0, 0.3, 0.4, -4.5, 1.0, -2.0, 0.7, 0.4, 0.22, 0.05],
        // Falling through the plane within the step.
        [0.1, 1.0, on_table + 0.01, 0.3, -3.0, -3.4, -2.4, -0.6, -0.7, 0.2, 0.01],
        // Starting just below the plane, still falling: h is clamped.
        [0.1, 1.0, on_table - 0.002, 0.3, -3.0, -3.4, 1.0, 2.0, -0.5, 0.2, 0.01],
        // Below the plane and rising slowly: the time of impact exceeds the step and is capped.
        [0.1, 1.0, on_table - 0.001, 0.0, -1.0, 0.01, 0.5, -0.5, 0.2, 0.2, 0.01],
        // After its bounce a ball falling through the plane stays in free flight.
        [0.1, 0.2, on_table + 0.01, 0.3, -3.0, -3.0, 0.0, 0.0, 0.0, 0.2, 0.01],
    ];
    let phases =
        [Phase::BeforeImpact, Phase::BeforeImpact, Phase::BeforeImpact, Phase::BeforeImpact, Phase::AfterImpact];
    let device = training_device();
    let module = BallParamsModule::from_params(&params, None, &device);
    let k = Consts::new(5, phys, &device);
    let x = tensor(states.iter().flatten().copied().collect(), [5, 11], &device);
    let f = flight(&x, &k, phys);
    let dt = StepLen::Fixed(phys.dt);
    let (free_next, free_jac) = (values(&free_step(&x, &f, &dt)), values(&free_jacobian(&f, &dt, &k)));
    let plan = ImpactPlan::new(&values(&x), &phases, phys);
    assert_eq!(plan.impacting, [false, true, true, true, false]);
    assert_eq!(plan.clamped_height, [false, false, true, true, false]);
    assert_eq!(plan.capped, [false, false, false, true, false]);
    let c_full = impact_map(module.c.val(), &device);
    let (imp_next, imp_jac) = impact_step(&x, &f, &c_full, &plan, &k, phys, &device);
    let (imp_next, imp_jac) = (values(&imp_next), values(&imp_jac));

    for (i, s) in states.iter().enumerate() {
        let (next, jac, phase) = model.step_with_jacobian(&BallState::from(*s), phases[i]);
        assert_eq!(phase == Phase::AfterImpact && phases[i] == Phase::BeforeImpact, plan.impacting[i]);
        let (ours_next, ours_jac) = if plan.impacting[i] { (&imp_next, &imp_jac) } else { (&free_next, &free_jac) };
        for r in 0..11 {
            assert!((ours_next[11 * i + r] - next[r]).abs() < 1e-12, "state {i}, entry {r}");
            for c in 0..11 {
                let (a, b) = (ours_jac[121 * i + 11 * r + c], jac[(r, c)]);
                assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "state {i}, J[{r}][{c}]: {a} vs {b}");
            }
        }
    }
}
