//! Cost of one control step of the embodied arms: the Jaco on MuJoCo (50 physics steps of 2 ms with the
//! push check after each) beside the Reacher (2 steps of our own two-link integrator), both with their
//! scripted controllers' actions. Needs the `mujoco` feature: `cargo bench --features mujoco --bench jaco`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::envs::boards::LightsOut;
use mbrl::envs::embodiments::{BoardLayout, Embodiment};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn bench(c: &mut Criterion) {
    let board = BoardLayout::of(&LightsOut::new(5).unwrap());
    for embodiment in [Embodiment::Reacher, Embodiment::Jaco] {
        let (mut arm, mut ctrl) = embodiment.build(&board).unwrap();
        arm.reset(&mut ChaCha8Rng::seed_from_u64(0));
        // A mid-flight state, where the controller moves every joint: the common case of a rollout.
        for _ in 0..3 {
            let a = ctrl.act(arm.as_ref(), [0.9, 0.9]);
            arm.step(&a);
        }
        let start = arm.state();
        let action = ctrl.act(arm.as_ref(), [0.9, 0.9]);
        c.bench_function(&format!("{}_control_step", embodiment.name()), |b| {
            b.iter(|| {
                arm.set_state(&start);
                arm.step(black_box(&action))
            })
        });
        c.bench_function(&format!("{}_controller_act", embodiment.name()), |b| {
            b.iter(|| ctrl.act(arm.as_ref(), black_box([0.9, 0.9])))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
