//! SAC at SEADS' Cursor-LightsOut sizes: network input 2 (cursor) + 25 (board) + 1 (remaining time) + 25
//! (one-hot skill) = 53, action 3, hidden [256, 256]. One update at batch 128 (SEADS runs 16 per epoch) and one
//! `act` for the 32 episodes collected in lockstep.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mbrl::rl::sac::Sac;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod inputs;
use inputs::{sac_batch as batch, sac_config as config, SAC_OBS as OBS};

fn update(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut sac = Sac::new(config(), &mut rng).unwrap();
    let batch = batch(&mut rng, 128);
    let mut group = c.benchmark_group("sac_cursor_lightsout");
    group.sample_size(30);
    group.throughput(Throughput::Elements(1));
    group.bench_function("update_batch128", |b| b.iter(|| sac.update(&batch, &mut rng).unwrap()));
    group.finish();
}

fn act(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let sac = Sac::new(config(), &mut rng).unwrap();
    let obs: Vec<f32> = (0..32 * OBS).map(|_| rng.random_range(0.0..1.0)).collect();
    let mut group = c.benchmark_group("sac_cursor_lightsout");
    group.bench_function("act_32_rows_stochastic", |b| b.iter(|| sac.act(&obs, 32, false, &mut rng)));
    group.bench_function("act_32_rows_deterministic", |b| b.iter(|| sac.act(&obs, 32, true, &mut rng)));
    group.finish();
}

criterion_group!(benches, update, act);
criterion_main!(benches);
