//! One CEM MPC step with the ground-truth pendulum at the thesis' settings (1000 candidates × horizon 20 ×
//! 10 iterations). Target: ≥ 100 MPC steps/s on 2 cores.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mbrl::control::ReturnObjective;
use mbrl::envs::pendulum::{PendulumDynamics, PendulumParams};
use mbrl::planning::{Cem, CemConfig, NoiseKind};

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn mpc_step(c: &mut Criterion) {
    let dynamics = PendulumDynamics { params: PendulumParams::default() };
    let init = [std::f64::consts::PI, 0.0];
    let mut group = c.benchmark_group("cem_mpc_step_pendulum_1000x20x10");
    group.throughput(Throughput::Elements(1));
    for (name, noise) in [("white", NoiseKind::White), ("colored_0.5", NoiseKind::Colored { beta: 0.5 })] {
        let config = CemConfig { noise, ..CemConfig::for_box(&[-2.0], &[2.0]) };
        let mut cem = Cem::new(config, 0).unwrap();
        group.bench_function(name, |b| {
            b.iter(|| cem.plan(&ReturnObjective::new(&dynamics, &init, 0), |_| {}));
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = mpc_step
}
criterion_main!(benches);
