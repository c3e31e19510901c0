//! burn's autodiff gradients of the batched loss against central differences of the nalgebra loss.

use burn::tensor::DType;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::super::device::values;
use super::super::*;
use super::data::recordings;
use crate::models::ball::BallModelParams;

/// Chunks from two shots: four with the bounce inside the window, two after it, two before it.
fn chunks() -> Vec<Chunk> {
    let recs = recordings(2, 8);
    let all = cut_chunks(&recs, 50, &BallModelParams::initial().physics).unwrap();
    let impact = |c: &Chunk| recs[c.recording as usize].info.impact_frame.unwrap();
    let bouncing = all.iter().filter(|c| !c.after_impact && impact(c) < c.start_frame + 45).step_by(9).take(4);
    let after = all.iter().filter(|c| c.after_impact).step_by(11).take(2);
    let before = all.iter().filter(|c| impact(c) >= c.start_frame + 50).step_by(13).take(2);
    let picked: Vec<Chunk> = bouncing.chain(after).chain(before).cloned().collect();
    assert_eq!(picked.len(), 8);
    picked
}

/// One scalar parameter: how to read its autodiff gradient and how to move it in the nalgebra parameters (raw
/// values for variances, as the optimizer sees them).
struct Probe {
    name: &'static str,
    grad: fn(&BallParamsModule, &burn::tensor::Gradients) -> f64,
    shift: fn(&mut BallModelParams, f64),
}

fn shift_raw(v: &mut f64, h: f64) {
    *v = softplus(inverse_softplus(*v) + h);
}

fn grad_at<const D: usize>(
    p: &burn::module::Param<burn::tensor::Tensor<D>>,
    g: &burn::tensor::Gradients,
    i: usize,
) -> f64 {
    values(&p.val().grad(g).expect("parameter takes part in the loss"))[i]
}

fn probes() -> Vec<Probe> {
    vec![
        Probe { name: "C[2][2]", grad: |m, g| grad_at(&m.c, g, 14), shift: |p, h| p.c[2][2] += h },
        Probe { name: "C[0][0]", grad: |m, g| grad_at(&m.c, g, 0), shift: |p, h| p.c[0][0] += h },
        Probe { name: "C[1][1]", grad: |m, g| grad_at(&m.c, g, 7), shift: |p, h| p.c[1][1] += h },
        Probe { name: "C[4][0]", grad: |m, g| grad_at(&m.c, g, 24), shift: |p, h| p.c[4][0] += h },
        Probe { name: "raw Q[4]", grad: |m, g| grad_at(&m.q, g, 4), shift: |p, h| shift_raw(&mut p.q_diag[4], h) },
        Probe { name: "raw Q[0]", grad: |m, g| grad_at(&m.q, g, 0), shift: |p, h| shift_raw(&mut p.q_diag[0], h) },
        Probe { name: "raw R[2]", grad: |m, g| grad_at(&m.r, g, 2), shift: |p, h| shift_raw(&mut p.r_diag[2], h) },
        Probe { name: "a_d0", grad: |m, g| grad_at(&m.a_d0, g, 0), shift: |p, h| p.a_d0 += h },
        Probe { name: "a_m0", grad: |m, g| grad_at(&m.a_m0, g, 0), shift: |p, h| p.a_m0 += h },
        Probe {
            name: "raw σ_v[1]",
            grad: |m, g| grad_at(&m.init_vel, g, 1),
            shift: |p, h| shift_raw(&mut p.init_vel_var[1], h),
        },
    ]
}

fn assert_close(name: &str, autodiff: f64, numeric: f64) {
    let err = (autodiff - numeric).abs();
    eprintln!("{name}: autodiff {autodiff:.9e}, central difference {numeric:.9e}");
    assert!(err <= 1e-4 * numeric.abs() + 1e-8, "{name}: autodiff {autodiff:e} vs central difference {numeric:e}");
}

#[test]
fn broad_prior_gradients_match_central_differences() {
    let chunks = chunks();
    let device = training_device();
    let start = BallModelParams::initial();
    let module = BallParamsModule::from_params(&start, None, &device);
    let exact = module.to_params(&start.physics);
    let refs: Vec<&Chunk> = chunks.iter().collect();
    let batch = Batch::new(&refs, false, &device).unwrap();
    let loss = chunk_loss(&module, &batch, &start.physics, &device).unwrap();
    let grads = loss.backward();
    // f64 end to end, whatever the flex device's default float is in this process.
    assert_eq!(loss.dtype(), DType::F64);
    assert_eq!(module.c.val().grad(&grads).unwrap().dtype(), DType::F64);
    let h = 1e-6;
    for probe in probes() {
        let loss_at = |step: f64| {
            let mut p = exact.clone();
            (probe.shift)(&mut p, step);
            reference_loss(&p, None, &chunks).unwrap()
        };
        let numeric = (loss_at(h) - loss_at(-h)) / (2.0 * h);
        assert_close(probe.name, (probe.grad)(&module, &grads), numeric);
    }
}

#[test]
fn spin_network_gradients_match_central_differences() {
    let chunks = chunks();
    let device = training_device();
    let start = BallModelParams::thesis_learned();
    let net = SpinNet::init(&mut ChaCha8Rng::seed_from_u64(2), &device);
    let module = BallParamsModule::from_params(&start, Some(net), &device);
    let exact = module.to_params(&start.physics);
    let weights = module.spin_net.as_ref().unwrap().weights();
    let refs: Vec<&Chunk> = chunks.iter().collect();
    let batch = Batch::new(&refs, true, &device).unwrap();
    let grads = chunk_loss(&module, &batch, &start.physics, &device).unwrap().backward();
    let net = module.spin_net.as_ref().unwrap();
    let h = 1e-6;
    // Hidden units with positive input weights are active for every s_m ∈ [0, 1]³. W₂ rows 0-2 give the mean,
    // 3-5 the variance; W₁ feeds both. Both are stored transposed in the module.
    let active: Vec<usize> =
        (0..spin_net::HIDDEN).filter(|&j| (0..3).all(|k| weights.w1[3 * j + k] > 0.0)).take(2).collect();
    let (a, b) = (active[0], active[1]);
    for (name, in_w1, row, col) in [("W2[1][a]", false, 1, a), ("W2[4][b]", false, 4, b), ("W1[a][2]", true, a, 2)] {
        let autodiff = if in_w1 {
            grad_at(&net.w1_t, &grads, spin_net::HIDDEN * col + row)
        } else {
            grad_at(&net.w2_t, &grads, 6 * col + row)
        };
        let loss_at = |step: f64| {
            let mut w = weights.clone();
            if in_w1 {
                w.w1[3 * row + col] += step;
            } else {
                w.w2[spin_net::HIDDEN * row + col] += step;
            }
            reference_loss(&exact, Some(&w), &chunks).unwrap()
        };
        assert_close(name, autodiff, (loss_at(h) - loss_at(-h)) / (2.0 * h));
    }
    let ad = grad_at(&module.a_d0, &grads, 0);
    let mut p = exact.clone();
    p.a_d0 += h;
    let up = reference_loss(&p, Some(&weights), &chunks).unwrap();
    p.a_d0 -= 2.0 * h;
    let down = reference_loss(&p, Some(&weights), &chunks).unwrap();
    assert_close("a_d0 (launcher prior)", ad, (up - down) / (2.0 * h));
}
