//! Speed of TRADYN's simulator: one 10 ms unicycle step (adaptive RK45 with the friction turn resolved) in
//! the two regimes that matter: driving (constant acceleration, a few RK steps) and reversing through v = 0
//! (the banded crossing, the expensive case).

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::envs::terrain::generate_map;
use mbrl::envs::unicycle::{RobotParams, UnicycleDynamics};
use mbrl::envs::Dynamics;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn bench(c: &mut Criterion) {
    let dynamics = UnicycleDynamics {
        robot: RobotParams { mass: 2.5, k_throttle: 750.0, k_steer: 0.6 },
        map: Arc::new(generate_map(0, 0)),
    };
    c.bench_function("unicycle_step_driving", |b| {
        b.iter(|| {
            let mut state = [0.5, 0.5, 3.0, 0.4];
            dynamics.step(black_box(&mut state), black_box(&[0.3, 0.2]))
        })
    });
    c.bench_function("unicycle_step_reversing", |b| {
        b.iter(|| {
            let mut state = [0.5, 0.5, 1.0, 0.4];
            dynamics.step(black_box(&mut state), black_box(&[-1.0, 0.0]))
        })
    });
    // A 100-step rollout of colored-noise-like smooth actions: the mix a dataset sees.
    let actions: Vec<[f64; 2]> = (0..100).map(|t| [(t as f64 * 0.13).sin(), (t as f64 * 0.07).cos() * 0.5]).collect();
    c.bench_function("unicycle_rollout_100_steps", |b| {
        b.iter(|| {
            let mut state = [0.3, 0.6, 0.0, 1.0];
            actions.iter().map(|a| dynamics.step(&mut state, a)).sum::<f64>()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
