//! Short training runs on simulated shots.

use std::time::Instant;

use super::super::*;
use super::data::recordings;
use crate::run::NullMonitor;

/// Seconds per optimizer step at the thesis' batch (64 chunks of 50 frames); run with `--ignored --nocapture`.
#[test]
#[ignore]
fn time_per_training_step() {
    let recs = recordings(40, 1);
    for launcher_prior in [false, true] {
        let settings = TrainSettings { steps: 3, launcher_prior, ..TrainSettings::default() };
        train(&recs, &settings, &NullMonitor).unwrap();
        let settings = TrainSettings { steps: 30, ..settings };
        let start = Instant::now();
        train(&recs, &settings, &NullMonitor).unwrap();
        let per_step = start.elapsed().as_secs_f64() / 30.0;
        eprintln!("launcher prior {launcher_prior}: {:.1} ms per step (batch 64 × 50 frames)", per_step * 1e3);
    }
}

#[test]
#[ignore]
fn scratch_training() {
    use burn::optim::{AdamConfig, GradientsParams};
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let physics = crate::models::ball::BallPhysics::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let camera = crate::envs::ball::CameraModel::default();
    let mut recs = Vec::new();
    let mut incoming = Vec::new();
    while recs.len() < 40 {
        let launch = crate::envs::ball::LaunchParams::sample(crate::envs::ball::Orientation::Default, &mut rng);
        let shot = crate::envs::ball::simulate(&launch, &camera, &mut rng);
        if shot.impact_times.len() != 1 || shot.len() < 80 {
            continue;
        }
        let k = (shot.impact_frame.unwrap() - shot.frame_indices[0]) as usize;
        incoming.push(shot.true_states[k - 1]);
        recs.push(crate::data::ball_io::Recording {
            id: recs.len() as u32,
            frames: shot.frame_indices.clone(),
            positions: shot.positions.clone(),
            truth: None,
            info: crate::data::ball_io::RecordingInfo {
                side_info: Some(launch.side_info()),
                impact_frame: shot.impact_frame,
                ..Default::default()
            },
        });
    }
    let vin: Vec<f64> =
        (0..6).map(|i| incoming.iter().map(|s| s[3 + i]).sum::<f64>() / incoming.len() as f64).collect();
    eprintln!("mean incoming v, w {vin:?}");
    let chunks = cut_chunks(&recs, 50, &physics).unwrap();
    let held: Vec<Chunk> = chunks.iter().step_by(23).cloned().collect();
    let mut init = crate::models::ball::BallModelParams::thesis_learned();
    init.c = crate::models::ball::BallModelParams::initial().c;
    init.a_d0 = 0.1f64.sqrt();
    init.a_m0 = 0.1f64.sqrt();
    for (launcher, bs) in [(false, 16usize), (true, 16), (false, 32)] {
        let device = training_device();
        let net = launcher.then(|| SpinNet::init(&mut rand_chacha::ChaCha8Rng::seed_from_u64(3), &device));
        let mut model = BallParamsModule::from_params(&init, net, &device);
        let mut opt = AdamConfig::new().with_epsilon(1e-8).init();
        let mut order: Vec<usize> = (0..chunks.len()).collect();
        order.shuffle(&mut rng);
        let start = Instant::now();
        for step in 0..=200usize {
            if step % 25 == 0 {
                let p = model.to_params(&physics);
                let w = model.spin_net.as_ref().map(|n| n.weights());
                let vz_out: f64 = (0..3).map(|j| p.c[2][j] * vin[j]).sum();
                let vz_out_w: f64 = (0..6).map(|j| p.c[2][j] * vin[j]).sum();
                eprintln!("launcher {launcher} bs {bs} step {step} ({:.1}s): held-out {:.3} C22 {:.3} rest(v) {:.3} rest(v,w) {:.3} a_d {:.4} a_m {:.4} r {:.2e}",
                    start.elapsed().as_secs_f64(), reference_loss(&p, w.as_ref(), &held).unwrap(), p.c[2][2], -vz_out / vin[2], -vz_out_w / vin[2], p.a_d0, p.a_m0, p.r_diag[0]);
            }
            let picked: Vec<&Chunk> =
                order[(step * bs) % (chunks.len() - bs)..][..bs].iter().map(|&i| &chunks[i]).collect();
            let batch = Batch::new(&picked, launcher, &device).unwrap();
            let loss = chunk_loss(&model, &batch, &physics, &device).unwrap();
            let g = GradientsParams::from_grads(loss.backward(), &model);
            model = opt.step(5e-3, model, g);
        }
    }
}
