//! One optimizer step of the ball EKF's likelihood training at the thesis' batch (64 chunks of 50 frames):
//! forward filter, backward pass through burn's autodiff, Adam update. Measured as 10 steps per sample.

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::models::ball::learn::{train, TrainSettings};
use mbrl::run::NullMonitor;

mod inputs;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn bench(c: &mut Criterion) {
    let recordings = inputs::ball_recordings();
    let mut group = c.benchmark_group("ball_ekf_train_10_steps_batch64x50");
    group.sample_size(10);
    for launcher_prior in [false, true] {
        let train_settings = TrainSettings { steps: 10, launcher_prior, ..TrainSettings::default() };
        let name = if launcher_prior { "launcher_prior" } else { "broad_prior" };
        group.bench_function(name, |b| b.iter(|| train(&recordings, &train_settings, &NullMonitor).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
