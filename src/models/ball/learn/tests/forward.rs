//! The batched tensor filter against the nalgebra reference filter: same loss, chunk by chunk.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::super::device::values;
use super::super::*;
use super::data::recordings;
use crate::models::ball::{BallModel, BallModelParams};

/// Every 7th chunk of six shots: starts before the bounce with the bounce inside the window, after the bounce,
/// and near the end of the table, with and without dropouts.
pub fn mixed_chunks() -> Vec<Chunk> {
    let recs = recordings(6, 3);
    let all = cut_chunks(&recs, 50, &BallModelParams::initial().physics).unwrap();
    let chunks: Vec<Chunk> = all.into_iter().step_by(7).collect();
    let impact_of = |c: &Chunk| recs[c.recording as usize].info.impact_frame.unwrap();
    let bouncing = chunks.iter().filter(|c| !c.after_impact && impact_of(c) < c.start_frame + 50).count();
    let after = chunks.iter().filter(|c| c.after_impact).count();
    let free = chunks.iter().filter(|c| !c.after_impact && impact_of(c) >= c.start_frame + 50).count();
    let with_gaps = chunks.iter().filter(|c| c.measured() < c.slots.len()).count();
    assert!(bouncing >= 5 && after >= 5 && free >= 5 && with_gaps >= 5, "{bouncing} {after} {free} {with_gaps}");
    chunks
}

/// Largest |burn − nalgebra| per-chunk NLL, relative to max(1, |NLL|), and the two batch losses.
fn compare(params: &BallModelParams, spin_net: Option<SpinNet>, chunks: &[Chunk]) -> (f64, f64, f64) {
    let device = training_device();
    let launcher = spin_net.is_some();
    let module = BallParamsModule::from_params(params, spin_net, &device);
    // The module's own values (Table C.2's variances at the softplus floor move by 1e-12 on the way in).
    let exact = module.to_params(&params.physics);
    let weights = module.spin_net.as_ref().map(SpinNet::weights);
    let refs: Vec<&Chunk> = chunks.iter().collect();
    let batch = Batch::new(&refs, launcher, &device).unwrap();
    let ll = values(&log_likelihoods(&module, &batch, &params.physics, &device).unwrap());
    let model = BallModel::new(exact.clone()).unwrap();
    let steps = batch.steps;
    let mut worst: f64 = 0.0;
    for (i, chunk) in chunks.iter().enumerate() {
        let ours = -ll[i * steps..(i + 1) * steps].iter().sum::<f64>() / chunk.measured() as f64;
        let reference = chunk_nll(&model, weights.as_ref(), chunk).unwrap();
        worst = worst.max((ours - reference).abs() / reference.abs().max(1.0));
    }
    let loss: f64 = chunk_loss(&module, &batch, &params.physics, &device).unwrap().into_scalar();
    (worst, loss, reference_loss(&exact, weights.as_ref(), chunks).unwrap())
}

#[test]
fn broad_prior_loss_matches_the_nalgebra_filter() {
    let chunks = mixed_chunks();
    for params in [BallModelParams::initial(), BallModelParams::thesis_learned()] {
        let (worst, loss, reference) = compare(&params, None, &chunks);
        eprintln!("broad prior: worst relative chunk difference {worst:e}, loss {loss} vs {reference}");
        assert!(worst < 1e-9, "largest relative per-chunk difference {worst:e}");
        assert!((loss - reference).abs() < 1e-9 * reference.abs().max(1.0), "{loss} vs {reference}");
    }
}

#[test]
fn launcher_prior_loss_matches_the_nalgebra_filter() {
    let chunks = mixed_chunks();
    let device = training_device();
    let net = SpinNet::init(&mut ChaCha8Rng::seed_from_u64(5), &device);
    let (worst, loss, reference) = compare(&BallModelParams::thesis_learned(), Some(net), &chunks);
    eprintln!("launcher prior: worst relative chunk difference {worst:e}, loss {loss} vs {reference}");
    assert!(worst < 1e-9, "largest relative per-chunk difference {worst:e}");
    assert!((loss - reference).abs() < 1e-9 * reference.abs().max(1.0), "{loss} vs {reference}");
}
