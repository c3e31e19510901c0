//! PETS: one training step (ensemble of 5, batch 256 per member) and one MPC step on the ensemble at the
//! thesis' CEM settings (1000 candidates × horizon 20 × 10 iterations) with 20 TS-∞ particles, on the fast
//! f32 inference path and through burn's forward pass. The same network's forward in PyTorch is measured by
//! benches/pytorch/pets_reference.py; README lists both.

use burn::tensor::Device;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mbrl::control::ReturnObjective;
use mbrl::control::{BatchDynamics, RewardFn};
use mbrl::envs::pendulum::dynamics::PendulumReward;
use mbrl::models::pets::data::Transitions;
use mbrl::models::pets::net::{torch_name, PetsNet};
use mbrl::models::pets::{PetsConfig, PetsDynamics, PetsTrainer, Preset, Propagation};
use mbrl::nn::features::features;
use mbrl::nn::tensor::{inference_device, tensor, values};
use mbrl::nn::{Normalizer, ParamSet};
use mbrl::planning::{Cem, CemConfig};
use mbrl::train::TrainingMethod;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod inputs;
use inputs::{pets_transitions as transitions, PENDULUM_ANGULAR as ANGULAR};

fn config(preset: Preset) -> PetsConfig {
    PetsConfig::preset(preset)
}

fn train_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("pets_train_step_ensemble5_batch256");
    group.sample_size(20);
    for (name, preset) in [("small_3x64", Preset::Small), ("medium_4x200", Preset::Medium)] {
        let mut trainer = PetsTrainer::new(config(preset), 0, transitions(5000), Transitions::default()).unwrap();
        let mut step = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                step += 1;
                trainer.step(step).unwrap()
            })
        });
    }
    group.finish();
}

fn trained_like(preset: Preset) -> (PetsConfig, PetsNet, ParamSet, Normalizer) {
    let config = config(preset);
    let device = inference_device();
    let net = PetsNet::init(&config, 4, 2, &device, &mut ChaCha8Rng::seed_from_u64(2));
    let params = ParamSet::<f32>::from_module(&net, torch_name);
    let normalizer = Normalizer { mean: vec![0.0, 0.0, 0.0, 0.0], std: vec![0.7, 0.7, 4.0, 1.2] };
    (config, net, params, normalizer)
}

/// The same rollout through burn's forward pass (TS-∞, particle p on member p mod E), for comparison.
struct BurnPets {
    net: PetsNet,
    normalizer: Normalizer,
    members: usize,
    particles: usize,
    reward: PendulumReward,
    device: Device,
}

impl BatchDynamics for BurnPets {
    fn state_dim(&self) -> usize {
        2
    }

    fn action_dim(&self) -> usize {
        1
    }

    fn rollout(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        seed: u64,
        returns: &mut [f64],
        _states: Option<&mut [f64]>,
    ) {
        let (e, p, n) = (self.members, self.particles, returns.len());
        let rows = n * p;
        let per_member = rows / e;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Row order [member][candidate][particle of that member] so a reshape gives [E, rows/E, ·].
        let row_candidate: Vec<usize> = (0..rows).map(|r| (r % per_member) / (p / e)).collect();
        let mut state: Vec<f64> = init.iter().copied().cycle().take(rows * 2).collect();
        let mut total = vec![0.0; rows];
        for t in 0..horizon {
            let mut input = Vec::with_capacity(rows * 4);
            for r in 0..rows {
                features(
                    &state[2 * r..2 * r + 2],
                    &actions[row_candidate[r] * horizon + t..][..1],
                    &ANGULAR,
                    &mut input,
                );
            }
            self.normalizer.apply(&mut input);
            let (mean, logvar) = self.net.forward(tensor(input, [e, per_member, 4], &self.device));
            let (mean, logvar) = (values(&mean), values(&logvar));
            for r in 0..rows {
                let s = [state[2 * r], state[2 * r + 1]];
                let mut next = [0.0; 2];
                for j in 0..2 {
                    let z: f64 = rng.sample(StandardNormal);
                    next[j] = s[j] + mean[2 * r + j] as f64 + (0.5 * logvar[2 * r + j] as f64).exp() * z;
                }
                let a = actions[row_candidate[r] * horizon + t];
                total[r] += self.reward.reward(&s, &[a], &next);
                state[2 * r..2 * r + 2].copy_from_slice(&next);
            }
        }
        returns.iter_mut().for_each(|x| *x = 0.0);
        for r in 0..rows {
            returns[row_candidate[r]] += total[r] / p as f64;
        }
    }

    fn describe(&self) -> String {
        "burn forward".into()
    }
}

fn mpc_step(c: &mut Criterion) {
    let init = [std::f64::consts::PI, 0.0];
    let mut group = c.benchmark_group("pets_mpc_step_1000x20x10_20particles");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    for (name, preset) in [("small_3x64", Preset::Small), ("medium_4x200", Preset::Medium)] {
        let (config, net, params, normalizer) = trained_like(preset);
        let reward = PendulumReward { max_torque: 2.0 };
        let fast = PetsDynamics::new(
            &config,
            &params,
            normalizer.clone(),
            ANGULAR.to_vec(),
            1,
            Some(Box::new(reward.clone())),
            Propagation::TsInf,
            20,
        )
        .unwrap();
        let burn =
            BurnPets { net, normalizer, members: config.ensemble, particles: 20, reward, device: inference_device() };
        let models: [(&str, &dyn BatchDynamics); 2] = [("fast", &fast), ("burn", &burn)];
        for (path, model) in models {
            let mut cem = Cem::new(CemConfig::for_box(&[-2.0], &[2.0]), 0).unwrap();
            group.bench_function(format!("{name}/{path}"), |b| {
                b.iter(|| cem.plan(&ReturnObjective::new(model, &init, 0), |_| {}));
            });
        }
    }
    group.finish();
}

criterion_group!(benches, train_step, mpc_step);
criterion_main!(benches);
