//! One training step of every learned method, at one thread and at two, timed as PyTorch's side is
//! (benches/pytorch/training_steps.py), plus the machine's f32 GEMM ceiling through faer in the same run.
//! benches/vs_pytorch.py runs both and prints the ratio table; run alone, this prints one JSON object per line:
//!
//!   cargo bench --bench training_steps -- [--quick] [--only NAME[,NAME…]] [--threads N]
//!
//! `REPEATS=N` in the environment times N steps of each workload instead of its own count: a profile of many
//! steps then shows the steady state rather than the first step's page faults.
//!
//! Each workload's figure is the median of its timed steps after warm-up steps; the ceiling is the best of
//! several 1024³ products. The step counts and sizes are those the issue names (PETS small and medium, the
//! context model's paper net at batch 64 and 512, SAC at batch 128, DLGPD at 256 and 1024, the ball EKF at
//! 64 chunks × 50 frames).

use std::time::Instant;

use faer::{Accum, Mat};
use mbrl::models::ball::learn::{train as train_ball, TrainSettings};
use mbrl::models::context::config::{ContextConfig, EnvFamily, Preset as ContextPreset};
use mbrl::models::context::ContextTrainer;
use mbrl::models::dlgpd::data::ObservationKind;
use mbrl::models::dlgpd::model::{loss_and_gradients, sample_noise, Batch, Gradients, Weights};
use mbrl::models::dlgpd::vae::VaeNet;
use mbrl::models::gp::{GpHypers, HyperInit};
use mbrl::models::pets::data::Transitions;
use mbrl::models::pets::{PetsConfig, PetsTrainer, Preset as PetsPreset};
use mbrl::nn::backprop::matmul;
use mbrl::nn::tensor::training_device;
use mbrl::rl::sac::Sac;
use mbrl::run::NullMonitor;
use mbrl::train::TrainingMethod;
use mbrl::util::warm_pool::{run_warm, Warm};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod inputs;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Something that takes one training step per call; a step that times itself returns its own figure.
type Step = Box<dyn FnMut() -> Option<f64>>;

struct Workload {
    name: &'static str,
    /// Builds the trainer (not timed) and returns its step.
    build: fn() -> Step,
    warmup: usize,
    /// Timed steps: the median of these is the figure.
    repeats: usize,
}

fn pets(preset: PetsPreset) -> Step {
    let mut trainer =
        PetsTrainer::new(PetsConfig::preset(preset), 0, inputs::pets_transitions(5000), Transitions::default())
            .unwrap();
    let mut step = 0;
    Box::new(move || {
        step += 1;
        trainer.step(step).unwrap();
        None
    })
}

fn context(batch: usize) -> Step {
    let mut config = ContextConfig::preset(ContextPreset::Paper, EnvFamily::Control);
    config.batch_size = batch;
    let mut trainer =
        ContextTrainer::new(config, 0, inputs::context_data(200, 100), inputs::context_data(0, 100)).unwrap();
    let mut step = 0;
    Box::new(move || {
        step += 1;
        trainer.step(step).unwrap();
        None
    })
}

/// SEADS' Cursor-LightsOut sizes: observation 53, action 3, hidden [256, 256].
fn sac() -> Step {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut sac = Sac::new(inputs::sac_config(), &mut rng).unwrap();
    let batch = inputs::sac_batch(&mut rng, 128);
    Box::new(move || {
        sac.update(&batch, &mut rng).unwrap();
        None
    })
}

/// The whole step's loss and gradients (two encodings of the frame pairs, one decoding, four exact GPs),
/// without the optimizer update, as PyTorch's side times it.
fn dlgpd(rows: usize) -> Step {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let device = training_device();
    // The weights as `train` holds them between steps: outside the module, read in place.
    let params = VaeNet::init(ObservationKind::Images { side: 64 }, 3, 0, &device, &mut rng).unwrap().params();
    let transition: Vec<GpHypers> = (0..3).map(|_| GpHypers::new(&HyperInit::dlgpd(4, 1.0)).unwrap()).collect();
    let reward = GpHypers::new(&HyperInit::dlgpd(4, 4.0)).unwrap();
    let pixels = rows * 6 * 64 * 64;
    let frames: Vec<f32> = (0..pixels).map(|i| ((i % 251) as f32) / 251.0).collect();
    let actions: Vec<f64> = (0..rows).map(|_| rng.random_range(-2.0..2.0)).collect();
    let rewards: Vec<f64> = (0..rows).map(|_| -rng.random_range(0.0..10.0)).collect();
    let batch = Batch { rows, obs: frames.clone(), next_obs: frames, actions, rewards };
    let noise = sample_noise(rows, 3, &mut rng);
    Box::new(move || {
        let weights = Weights::Images(&params);
        loss_and_gradients(weights, &transition, &reward, &batch, (&noise.0, &noise.1), Gradients::Wanted, &device)
            .unwrap();
        None
    })
}

/// One optimizer step at the thesis' batch: `train` for 11 steps minus `train` for 1, so the set-up (chunk
/// cutting, the first filter pass) is not counted.
fn ball() -> Step {
    let recordings = inputs::ball_recordings();
    Box::new(move || {
        let run = |steps| {
            let start = Instant::now();
            train_ball(&recordings, &TrainSettings { steps, ..TrainSettings::default() }, &NullMonitor).unwrap();
            start.elapsed()
        };
        let (one, eleven) = (run(1), run(11));
        Some(eleven.saturating_sub(one).as_secs_f64() / 10.0)
    })
}

const WORKLOADS: &[Workload] = &[
    Workload { name: "pets_small", build: || pets(PetsPreset::Small), warmup: 20, repeats: 200 },
    Workload { name: "pets_medium", build: || pets(PetsPreset::Medium), warmup: 10, repeats: 60 },
    Workload { name: "context_b64", build: || context(64), warmup: 2, repeats: 10 },
    Workload { name: "context_b512", build: || context(512), warmup: 1, repeats: 3 },
    Workload { name: "sac_b128", build: sac, warmup: 10, repeats: 100 },
    Workload { name: "dlgpd_b256", build: || dlgpd(256), warmup: 1, repeats: 3 },
    Workload { name: "dlgpd_b1024", build: || dlgpd(1024), warmup: 1, repeats: 3 },
    Workload { name: "ball_b64x50", build: ball, warmup: 0, repeats: 3 },
];

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    if n % 2 == 1 {
        xs[n / 2]
    } else {
        0.5 * (xs[n / 2 - 1] + xs[n / 2])
    }
}

fn time_workload(workload: &Workload, quick: bool, warm: &Warm) -> (f64, usize) {
    let mut step = (workload.build)();
    let (warmup, repeats) = if quick {
        (workload.warmup.min(2), (workload.repeats / 5).max(2))
    } else {
        (workload.warmup, workload.repeats)
    };
    let repeats = match std::env::var("REPEATS") {
        Ok(value) => value.parse().ok().filter(|&n: &usize| n > 0).unwrap_or_else(|| {
            eprintln!("REPEATS={value}: expected a whole number of timed steps, at least 1");
            std::process::exit(2)
        }),
        Err(_) => repeats,
    };
    for _ in 0..warmup {
        warm.rearm();
        step();
    }
    let samples = (0..repeats)
        .map(|_| {
            warm.rearm();
            let start = Instant::now();
            let own = step();
            own.unwrap_or(start.elapsed().as_secs_f64())
        })
        .collect();
    (median(samples), repeats)
}

/// The best rate of a 1024 × 1024 × 1024 f32 product (2.15 GFLOP each) on the pool's threads, through faer's
/// kernel split by rows as the fused training paths call it (`nn::backprop::matmul`).
fn gemm_ceiling(quick: bool) -> f64 {
    let n = 1024;
    let a = Mat::<f32>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 17) as f32 / 17.0 - 0.5);
    let b = Mat::<f32>::from_fn(n, n, |i, j| ((i * 5 + j * 11) % 13) as f32 / 13.0 - 0.5);
    let mut c = Mat::<f32>::zeros(n, n);
    let flops = 2.0 * (n * n * n) as f64;
    (0..if quick { 10 } else { 40 })
        .map(|_| {
            let start = Instant::now();
            matmul(c.as_mut(), Accum::Replace, a.as_ref(), b.as_ref());
            flops / start.elapsed().as_secs_f64() / 1e9
        })
        .fold(0.0, f64::max)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let only: Option<Vec<String>> = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .map(|list| list.split(',').map(str::to_string).collect());
    if let Some(names) = &only {
        if let Some(unknown) = names.iter().find(|n| WORKLOADS.iter().all(|w| w.name != n.as_str())) {
            let known: Vec<&str> = WORKLOADS.iter().map(|w| w.name).collect();
            eprintln!("error: unknown workload '{unknown}'; known: {}", known.join(", "));
            std::process::exit(2);
        }
    }
    let thread_counts: Vec<usize> = match args.iter().position(|a| a == "--threads") {
        Some(i) => match args.get(i + 1).and_then(|n| n.parse().ok()).filter(|&n| n > 0) {
            Some(n) => vec![n],
            None => {
                eprintln!("error: --threads expects a positive thread count");
                std::process::exit(2);
            }
        },
        None => vec![1, 2],
    };
    for threads in thread_counts {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a rayon pool");
        let ceiling = pool.install(|| gemm_ceiling(quick));
        println!(r#"{{"workload":"gemm_ceiling","threads":{threads},"gflops":{ceiling:.2}}}"#);
        for workload in WORKLOADS {
            if only.as_ref().is_some_and(|names| !names.iter().any(|n| n == workload.name)) {
                continue;
            }
            // As `train` runs its steps: on a pool thread, the other workers kept awake (`util::warm_pool`).
            let (seconds, samples) = pool.install(|| run_warm(|warm| time_workload(workload, quick, warm)));
            println!(
                r#"{{"workload":"{}","threads":{threads},"seconds":{seconds:.6e},"samples":{samples}}}"#,
                workload.name
            );
        }
    }
}
