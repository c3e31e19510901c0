//! Writes the ball EKF's training case for the PyTorch reference (benches/pytorch/ball_reference.py): the
//! bench's simulated recordings (benches/inputs/mod.rs `ball_recordings`, included below) cut into chunks as
//! the trainer cuts them, the batches of the first `STEPS` optimizer steps of `train` under
//! `TrainSettings::default()`, the raw parameters and physics, the loss and its gradients with respect to the
//! raw parameters on the first batch, and the losses `train` itself reports over those steps.
//!
//!   cargo run --release --example ball_loss_case -- [FILE]   (default target/ball_loss_case.json)
//!
//! benches/vs_pytorch.py runs it before PyTorch's side of the `ball_b64x50` row, which trains on these batches.

use std::path::PathBuf;

use burn::module::Param;
use burn::tensor::{Gradients, Tensor};
use mbrl::models::ball::learn::{
    chunk_loss, cut_chunks, train, training_device, BallParamsModule, Batch, Chunk, TrainSettings,
};
use mbrl::run::NullMonitor;
use mbrl::util::seeding::rng_for;
use rand::seq::SliceRandom;
use serde_json::{json, Value};

// The benches' own inputs, so the case is exactly the data `ball_b64x50` trains on.
#[path = "../benches/inputs/mod.rs"]
mod inputs;

/// The bench's `ball()` times `train` for 11 steps less `train` for 1.
const STEPS: u64 = 11;

/// The trainer's shuffle stream (`SHUFFLE_STREAM` in src/models/ball/learn/trainer.rs).
const SHUFFLE_STREAM: u64 = 0;

/// The chunks of step `step` (from 1) as `BallEkfTrainer::batch` draws them: consecutive slices of a seeded
/// permutation per epoch. The loss of the first batch is held to `train`'s own below, which catches a drift.
fn batch_indices(chunks: usize, settings: &TrainSettings, step: u64) -> Vec<usize> {
    let size = settings.batch_size;
    let per_epoch = chunks.div_ceil(size) as u64;
    let (epoch, index) = ((step - 1) / per_epoch, ((step - 1) % per_epoch) as usize);
    let mut order: Vec<usize> = (0..chunks).collect();
    order.shuffle(&mut rng_for(settings.seed, &[SHUFFLE_STREAM, epoch]));
    order[index * size..((index + 1) * size).min(chunks)].to_vec()
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f64> {
    t.to_data().try_into_vec::<f64>().expect("f64 tensor data")
}

/// The batch as the reference reads it: m1, m2 [B, 3], per chunk its slots ([x, y, z] or null), and the phase.
fn batch_json(chunks: &[&Chunk]) -> Value {
    json!({
        "m1": chunks.iter().map(|c| c.m1).collect::<Vec<_>>(),
        "m2": chunks.iter().map(|c| c.m2).collect::<Vec<_>>(),
        "slots": chunks.iter().map(|c| &c.slots).collect::<Vec<_>>(),
        "after_impact": chunks.iter().map(|c| c.after_impact).collect::<Vec<_>>(),
    })
}

/// The raw (unconstrained) parameters and, for each, its gradient in `grads` (zeros where it takes no part in the
/// loss, as the after-impact spin variance under the broad prior).
fn raw_and_gradients(module: &BallParamsModule, grads: &Gradients) -> (Value, Value) {
    let named: [(&str, &Param<Tensor<1>>); 10] = [
        ("q", &module.q),
        ("r", &module.r),
        ("init_pos", &module.init_pos),
        ("init_vel", &module.init_vel),
        ("init_spin", &module.init_spin),
        ("init_spin_after_impact", &module.init_spin_after_impact),
        ("a_d0", &module.a_d0),
        ("a_m0", &module.a_m0),
        ("a_d_var", &module.a_d_var),
        ("a_m_var", &module.a_m_var),
    ];
    let grad_of = |t: Tensor<1>| {
        let n = t.dims()[0];
        t.grad(grads).map_or(vec![0.0; n], values)
    };
    let (mut raw, mut grad) = (serde_json::Map::new(), serde_json::Map::new());
    raw.insert("c".into(), json!(values(module.c.val().reshape([36]))));
    grad.insert("c".into(), json!(module.c.val().grad(grads).map_or(vec![0.0; 36], |g| values(g.reshape([36])))));
    for (name, p) in named {
        raw.insert(name.into(), json!(values(p.val())));
        grad.insert(name.into(), json!(grad_of(p.val())));
    }
    (Value::Object(raw), Value::Object(grad))
}

fn main() {
    let out = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "target/ball_loss_case.json".into()));
    let settings = TrainSettings { steps: STEPS, ..TrainSettings::default() };
    assert!(!settings.launcher_prior, "the reference has no launcher spin network");
    let physics = &settings.initial.physics;
    let recordings = inputs::ball_recordings();
    let chunks = cut_chunks(&recordings, settings.chunk_len, physics).expect("chunks");
    let batches: Vec<Vec<&Chunk>> = (1..=STEPS)
        .map(|step| batch_indices(chunks.len(), &settings, step).into_iter().map(|i| &chunks[i]).collect())
        .collect();

    let device = training_device();
    let module = BallParamsModule::from_params(&settings.initial, None, &device);
    let batch = Batch::new(&batches[0], false, &device).expect("batch");
    let loss_tensor = chunk_loss(&module, &batch, physics, &device).expect("loss");
    let loss: f64 = loss_tensor.clone().into_scalar();
    let (raw, gradients) = raw_and_gradients(&module, &loss_tensor.backward());

    let trained = train(&recordings, &settings, &NullMonitor).expect("training");
    let relative = (trained.losses[0] - loss).abs() / loss.abs();
    assert!(relative < 1e-12, "step 1's batch is not the trainer's: loss {loss} vs train's {}", trained.losses[0]);

    let case = json!({
        "physics": {
            "dt": physics.dt,
            "gravity": physics.gravity,
            "coeff_offset": physics.coeff_offset,
            "table_z": physics.table_z,
            "ball_radius": physics.ball_radius,
        },
        "optimizer": {
            "lr": settings.learning_rate,
            "beta1": settings.beta1,
            "beta2": settings.beta2,
            "eps": settings.epsilon,
        },
        "chunks": chunks.len(),
        "raw_params": raw,
        "batches": batches.iter().map(|b| batch_json(b)).collect::<Vec<_>>(),
        "loss": loss,
        "gradients": gradients,
        "train_losses": trained.losses,
    });
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).expect("the output directory");
    }
    std::fs::write(&out, serde_json::to_vec(&case).expect("JSON")).expect("the case file");
    eprintln!(
        "{}: {} chunks, {} batches of {}, loss {loss:.12e}",
        out.display(),
        chunks.len(),
        batches.len(),
        settings.batch_size
    );
}
