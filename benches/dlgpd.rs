//! DLGPD's training step at the paper's batch of 1024 transitions: the GP terms alone (three transition GPs
//! and the reward GP conditioned on the batch, exact f64 Cholesky, with every gradient), and the whole step's
//! loss and gradients (two encodings of 6 × 64 × 64 frames, one decoding, the GP terms injected, backward),
//! without the optimizer update; and one CEM iteration of the planner at two evidence sizes. PyTorch's figure for
//! the whole step, measured beside ours on the same machine: `make bench-vs-pytorch ONLY=dlgpd_b1024`.

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::models::dlgpd::data::ObservationKind;
use mbrl::models::dlgpd::latent_gp::gp_terms;
use mbrl::models::dlgpd::model::{loss_and_gradients, sample_noise, Batch, Gradients, Weights};
use mbrl::models::dlgpd::vae::VaeNet;
use mbrl::models::gp::{GpHypers, HyperInit};
use mbrl::nn::tensor::training_device;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

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
    // The weights as `train` holds them between steps: outside the module, read in place.
    let params = VaeNet::init(ObservationKind::Images { side: 64 }, 3, 0, &device, &mut rng).unwrap().params();
    let weights = Weights::Images(&params);
    let pixels = BATCH * 6 * 64 * 64;
    let frames: Vec<f32> = (0..pixels).map(|i| ((i % 251) as f32) / 251.0).collect();
    let batch = Batch { rows: BATCH, obs: frames.clone(), next_obs: frames, actions, rewards: rewards.clone() };
    let noise = sample_noise(BATCH, 3, &mut rng);
    group.bench_function("whole_step_gradients_without_optimizer", |b| {
        b.iter(|| {
            loss_and_gradients(weights, &transition, &reward, &batch, (&noise.0, &noise.1), Gradients::Wanted, &device)
                .unwrap()
        })
    });
    group.finish();
}

/// One CEM iteration of DLGPD's planner: 1000 candidates × horizon 20 rolled out as mean latents through the
/// three transition GPs (with predictive variances) and scored by the reward GP at 5 latent samples per step,
/// with 280 and 1400 evidence points (10 and 50 evidence rollouts of 28 transitions).
fn planning(c: &mut Criterion) {
    use mbrl::control::Objective;
    use mbrl::models::dlgpd::control::LatentObjective;
    use mbrl::models::dlgpd::dynamics::{Evidence, LatentDynamics};
    use mbrl::models::dlgpd::latent_gp::LatentScale;
    let mut group = c.benchmark_group("dlgpd_cem_iteration_1000x20");
    group.sample_size(10);
    for points in [280usize, 1400] {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let latents: Vec<f64> = (0..points * 3).map(|_| rng.random_range(-2.0..2.0)).collect();
        let actions: Vec<f64> = (0..points).map(|_| rng.random_range(-2.0..2.0)).collect();
        let next: Vec<f64> = latents.iter().enumerate().map(|(i, s)| s + 0.05 * actions[i / 3]).collect();
        let rewards: Vec<f64> = (0..points).map(|b| -latents[b * 3].powi(2)).collect();
        let transition: Vec<GpHypers> = (0..3).map(|_| GpHypers::new(&HyperInit::dlgpd(4, 1.0)).unwrap()).collect();
        let reward = GpHypers::new(&HyperInit::dlgpd(4, 4.0)).unwrap();
        let scale = LatentScale::of(&latents, 3).unwrap();
        let evidence = Evidence { latents: &latents, actions: &actions, next_latents: &next, rewards: &rewards };
        let dynamics = LatentDynamics::condition(&transition, &reward, scale, &evidence).unwrap();
        let objective = LatentObjective::new(&dynamics, vec![0.1, -0.2, 0.3], vec![0.01; 3], 7);
        let candidates: Vec<f64> = (0..1000 * 20).map(|_| rng.random_range(-2.0..2.0)).collect();
        let mut costs = vec![0.0; 1000];
        group.bench_function(format!("{points}_evidence_points"), |b| {
            b.iter(|| objective.costs(&candidates, 20, &mut costs))
        });
    }
    group.finish();
}

criterion_group!(benches, gp, planning);
criterion_main!(benches);
