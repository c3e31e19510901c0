//! Explore the Context: one training step (batch 64 and 512 × 50-state chunks, the thesis network), one
//! 1000-candidate × 20-step mean rollout on the fast path (the unit PyTorch's 7.3 batches/s refers to), one
//! CEM iteration of EIG calibration (1000 candidates × 20 β samples × horizon 20) and one MPC step on a calibrated
//! checkpoint (1000 × 20 × 10 iterations). PyTorch figures: benches/pytorch/context_reference.py.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mbrl::control::Objective;
use mbrl::control::ReturnObjective;
use mbrl::data::collect::{collect_instance_pairs, InstancePairSettings};
use mbrl::data::write_dataset;
use mbrl::envs::parse_env;
use mbrl::models::context::config::{ContextConfig, EnvFamily, Preset};
use mbrl::models::context::dynamics::ContextDynamics;
use mbrl::models::context::eig::EigObjective;
use mbrl::models::context::fast::{FastContextModel, RolloutScratch};
use mbrl::models::context::net::{param_name, ContextNet};
use mbrl::models::context::ContextTrainer;
use mbrl::models::context::{load, Context};
use mbrl::nn::tensor::inference_device;
use mbrl::nn::ParamSet;
use mbrl::planning::{Cem, CemConfig};
use mbrl::run::dir::Provenance;
use mbrl::run::NullMonitor;
use mbrl::train::job::start;
use mbrl::train::TrainingMethod;
use mbrl::train::{Accept, Request};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod inputs;
use inputs::{context_data as data, CONTEXT_ACTION as ACTION, CONTEXT_STATE as STATE};

fn paper_config(batch: usize) -> ContextConfig {
    let mut c = ContextConfig::preset(Preset::Paper, EnvFamily::Control);
    c.batch_size = batch;
    c
}

fn train_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("context_train_step_50_states");
    group.sample_size(10);
    for batch in [64, 512] {
        let mut trainer = ContextTrainer::new(paper_config(batch), 0, data(200, 100), data(0, 100)).unwrap();
        let mut step = 0;
        group.bench_function(format!("batch_{batch}"), |b| {
            b.iter(|| {
                step += 1;
                trainer.step(step).unwrap()
            })
        });
    }
    group.finish();
}

fn model() -> FastContextModel {
    let config = paper_config(64);
    let net = ContextNet::init(&config, STATE, ACTION, 0, &inference_device(), &mut ChaCha8Rng::seed_from_u64(2));
    FastContextModel::from_params(&ParamSet::<f32>::from_module(&net, param_name)).unwrap()
}

fn planning(c: &mut Criterion) {
    let fast = model();
    let (candidates, horizon) = (1000, 20);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let actions64: Vec<f64> = (0..candidates * horizon).map(|_| rng.random_range(-2.0..2.0)).collect();
    let actions: Vec<f32> = actions64.iter().map(|x| *x as f32).collect();
    let init = vec![-1.0, 0.0, 0.0];
    let betas: Vec<f32> = (0..candidates * fast.latent_dim).map(|_| rng.random_range(-1.0..1.0)).collect();

    let mut group = c.benchmark_group("context_planning");
    group.sample_size(10);
    group.throughput(Throughput::Elements((candidates * horizon) as u64));
    group.bench_function("rollout_1000x20_mean_one_thread", |b| {
        let mut out = vec![0.0; candidates * horizon * STATE];
        let mut scratch = RolloutScratch::default();
        b.iter(|| fast.rollout_means(&init, &actions, &betas, candidates, horizon, None, &mut out, &mut scratch))
    });
    group.throughput(Throughput::Elements((candidates * horizon * 20) as u64));
    group.bench_function("eig_cem_iteration_1000x20_beta20", |b| {
        let objective = EigObjective::new(&fast, init.clone(), vec![0.0; fast.transition_features], 20, 4);
        let mut costs = vec![0.0; candidates];
        b.iter(|| objective.costs(&actions64, horizon, &mut costs))
    });
    group.finish();
}

/// A real (one-step-trained) paper-size checkpoint on pendulum:quadrant data, loaded as the CLI loads it and
/// conditioned on a few transitions: the MPC step a `plan --context` run repeats every env step.
fn mpc_step(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let env = parse_env("pendulum:quadrant").unwrap();
    let data = dir.path().join("pairs.mcap");
    let collect =
        InstancePairSettings { env: env.clone(), instances: 20, steps: 60, seed: 1, command_line: String::new() };
    write_dataset(&data, &collect_instance_pairs(&collect, &NullMonitor).unwrap()).unwrap();
    let mut config = paper_config(64);
    config.steps = 1;
    let provenance = Provenance::new(String::new(), 0, 1);
    let request = Request::<Context> { env: None, data: vec![data], seed: 0, config, variant: (), provenance };
    let out = dir.path().join("model");
    start(&out, &request, &NullMonitor).unwrap();
    let model = load(&out, &env, Accept::Finished).unwrap();
    let context: Vec<f32> = (0..10 * model.fast.transition_dim()).map(|i| ((i % 7) as f32 - 3.0) * 0.3).collect();
    let dynamics = ContextDynamics::new(model, &context, &env).unwrap();
    let init = [std::f64::consts::PI, 0.0];
    let mut group = c.benchmark_group("context_mpc_step_1000x20x10");
    group.sample_size(10);
    let mut cem = Cem::new(CemConfig::for_box(&[-2.0], &[2.0]), 0).unwrap();
    group.bench_function("paper_net", |b| b.iter(|| cem.plan(&ReturnObjective::new(&dynamics, &init, 0), |_| {})));
    group.finish();
}

criterion_group!(benches, train_step, planning, mpc_step);
criterion_main!(benches);
