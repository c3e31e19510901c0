//! DLGPD's training step, by parts, at the paper's batch of 1024 transitions: the GP terms (three transition
//! GPs and the reward GP conditioned on the batch, exact f64 Cholesky, with every gradient) and the VAE's
//! forward and backward pass (two encodings of 6 × 64 × 64 frames, one decoding). PyTorch reference for the
//! whole step on this kind of machine: 9.2 s at 2 threads (../shared/ARCHITECTURE.md).

use burn::tensor::Tensor;
use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::models::dlgpd::latent_gp::gp_terms;
use mbrl::models::dlgpd::loss::{entropy_term, reconstruction_bce};
use mbrl::models::dlgpd::vae::{ConvDecoder, ConvEncoder};
use mbrl::models::gp::{GpHypers, HyperInit};
use mbrl::nn::tensor::{tensor, training_device};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const BATCH: usize = 1024;

fn gp(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let latents: Vec<f64> = (0..BATCH * 3).map(|_| rng.random_range(-2.0..2.0)).collect();
    let actions: Vec<f64> = (0..BATCH).map(|_| rng.random_range(-2.0..2.0)).collect();
    let next: Vec<f64> = latents.iter().map(|s| s + rng.random_range(-0.1..0.1)).collect();
    let rewards: Vec<f64> = (0..BATCH).map(|b| -latents[b * 3].powi(2)).collect();
    let transition: Vec<GpHypers> = (0..3).map(|_| GpHypers::new(&HyperInit::dlgpd(4, 1.0)).unwrap()).collect();
    let reward = GpHypers::new(&HyperInit::dlgpd(4, 4.0)).unwrap();
    let mut group = c.benchmark_group("dlgpd_step_parts_batch_1024");
    group.sample_size(10);
    group.bench_function("gp_terms_4_gps_with_gradients", |b| {
        b.iter(|| gp_terms(&transition, &reward, &latents, &actions, &next, &rewards).unwrap())
    });
    let device = training_device();
    let encoder = ConvEncoder::init(3, &device, &mut rng);
    let decoder = ConvDecoder::init(3, &device, &mut rng);
    let pixels = BATCH * 6 * 64 * 64;
    let frames: Vec<f32> = (0..pixels).map(|i| ((i % 251) as f32) / 251.0).collect();
    group.bench_function("vae_forward_backward", |b| {
        b.iter(|| {
            let obs: Tensor<4> = tensor(frames.clone(), [BATCH, 6, 64, 64], &device);
            let next: Tensor<4> = tensor(frames.clone(), [BATCH, 6, 64, 64], &device);
            let (mean, _) = encoder.forward(obs);
            let (next_mean, next_std) = encoder.forward(next.clone());
            let logits = decoder.forward(next_mean.clone() + next_std.clone());
            let loss = reconstruction_bce(logits, next) + entropy_term(next_std) + mean.sum() * 0.0;
            loss.backward()
        })
    });
    group.finish();
}

criterion_group!(benches, gp);
criterion_main!(benches);
