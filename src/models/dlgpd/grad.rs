//! The image VAE's training step written out over flat f32 buffers: its first convolution as GEMMs straight
//! over the frames regrouped into blocks (`nn::blocked_conv`), the others as im2col GEMMs
//! (`nn::conv_backprop`), its heads as dense layers, the Bernoulli reconstruction and entropy terms in closed
//! form, and the GP terms' latent gradients added where the burn path injects them. Both observations go
//! through the encoder as one batch of 2B images. `model.rs` keeps the burn graph as the reference: a test holds
//! the loss and every gradient here to burn's.

use rayon::prelude::*;

use super::latent_gp::gp_terms;
use super::model::{Batch, Gradients, StepLoss};
use super::vae::{FRAME_CHANNELS, FRAME_SIDE, STD_FLOOR, STD_SHIFT};
use crate::error::{Error, Result};
use crate::models::gp::GpHypers;
use crate::nn::activation::{fast_sigmoid, fast_softplus};
use crate::nn::backprop::{add_into, zero_gradients, Dense};
use crate::nn::blocked_conv::{BlockedConv, BlockedInput};
use crate::nn::conv_backprop::{to_channels_first, to_channels_last, Direction, Grids, InputGradient, StridedConv};
use crate::nn::ParamSet;
use crate::util::wide::widest_fn;

/// Channels of the encoder's four convolutions (Table A.1) and of the decoder's transposed ones (Table A.2).
const ENCODER_CHANNELS: [usize; 4] = [32, 64, 128, 256];
const DECODER: [(usize, usize); 4] = [(128, 5), (64, 5), (32, 6), (FRAME_CHANNELS, 6)];
const KERNEL: usize = 4;
const STRIDE: usize = 2;
/// The decoder's dense layer feeds a 1 × 1 grid of this many channels.
const FLAT: usize = 1024;

/// The convolutional VAE's layers over a parameter set named as `VaeNet::params` names them.
pub struct ConvVaeGrad<'a> {
    /// The first convolution reads the frames themselves, regrouped into blocks.
    first: BlockedConv,
    /// The other three.
    encoder: Vec<StridedConv>,
    /// Channels and side of the encoder's last grid, flattened channels-first into the heads' input.
    encoder_out: (usize, usize),
    mean: Dense<'a>,
    std: Dense<'a>,
    fc: Dense<'a>,
    decoder: Vec<StridedConv>,
}

/// What the encoder's forward pass keeps for its backward pass.
struct EncoderTape {
    /// Every ReLU'd convolution output, channels-last.
    grids: Vec<Vec<f32>>,
    /// The last grid flattened channels-first, as the heads read it.
    flat: Vec<f32>,
    /// The std head before its softplus.
    raw_std: Vec<f32>,
}

struct DecoderTape {
    /// The ReLU'd dense output and the ReLU'd outputs of all but the last transposed convolution.
    grids: Vec<Vec<f32>>,
}

impl<'a> ConvVaeGrad<'a> {
    pub fn new(params: &'a ParamSet, latent: usize) -> Result<Self> {
        let channels = (FRAME_CHANNELS, ENCODER_CHANNELS[0]);
        let first = BlockedConv::new(params, "encoder.conv1", FRAME_SIDE, channels, KERNEL, STRIDE)?;
        let mut encoder = Vec::new();
        let (mut side, mut channels) = (first.out_side(), ENCODER_CHANNELS[0]);
        for (i, &out) in ENCODER_CHANNELS.iter().enumerate().skip(1) {
            let grids = Grids::conv(side, channels, out, KERNEL, STRIDE);
            encoder.push(StridedConv::new(params, &format!("encoder.conv{}", i + 1), grids, Direction::Down)?);
            (side, channels) = (grids.small_side, out);
        }
        let (encoder_side, flat) = (side, side * side * channels);
        let mut decoder = Vec::new();
        let (mut side, mut channels) = (1, FLAT);
        for (i, &(out, kernel)) in DECODER.iter().enumerate() {
            let grids = Grids::conv_transpose(side, channels, out, kernel, STRIDE);
            decoder.push(StridedConv::new(params, &format!("decoder.deconv{}", i + 1), grids, Direction::Up)?);
            (side, channels) = (grids.big_side, out);
        }
        if side != FRAME_SIDE {
            return Err(Error::config(format!("the decoder ends at {side} × {side}, not the frames' {FRAME_SIDE}")));
        }
        Ok(ConvVaeGrad {
            encoder_out: (ENCODER_CHANNELS[3], encoder_side),
            mean: Dense::new(params, "encoder.mean", flat, latent, false)?,
            std: Dense::new(params, "encoder.std", flat, latent, false)?,
            fc: Dense::new(params, "decoder.fc", latent, FLAT, false)?,
            first,
            encoder,
            decoder,
        })
    }

    /// The frames, as the first convolution reads them → encoder (mean, std) and the tape.
    fn encode(&self, frames: &BlockedInput<'_>, images: usize) -> (Vec<f32>, Vec<f32>, EncoderTape) {
        let mut grids = vec![self.first.forward(frames, true)];
        for layer in &self.encoder {
            let y = layer.forward(grids.last().expect("the first convolution's output at least"), images, true);
            grids.push(y);
        }
        let (channels, side) = self.encoder_out;
        let flat = to_channels_first(grids.last().expect("four grids"), channels, side);
        let mean = self.mean.forward(&flat, images);
        let raw_std = self.std.forward(&flat, images);
        let std = raw_std.iter().map(|&r| fast_softplus(r + STD_SHIFT as f32) + STD_FLOOR as f32).collect();
        (mean, std, EncoderTape { grids, flat, raw_std })
    }

    fn encode_backward(
        &self,
        frames: &BlockedInput<'_>,
        tape: &EncoderTape,
        d_mean: &[f32],
        mut d_std: Vec<f32>,
        images: usize,
        grads: &mut [Vec<f32>],
    ) {
        for (d, r) in d_std.iter_mut().zip(&tape.raw_std) {
            *d *= fast_sigmoid(r + STD_SHIFT as f32);
        }
        let mut d_flat = self.mean.backward(&tape.flat, d_mean, images, grads, true);
        let d_from_std = self.std.backward(&tape.flat, &d_std, images, grads, true);
        add_into(&mut d_flat, &d_from_std);
        let (channels, side) = self.encoder_out;
        let mut d = to_channels_last(&d_flat, channels, side);
        // Every layer's input is the ReLU output of the layer below, so each hands down the gradient below that
        // ReLU, masked while in cache; only the top layer masks its own output's gradient.
        let top = self.encoder.len() - 1;
        for (i, layer) in self.encoder.iter().enumerate().rev() {
            let relu_output = (i == top).then(|| tape.grids[i + 1].as_slice());
            d = layer.backward(&tape.grids[i], &mut d, relu_output, images, grads, InputGradient::BelowRelu);
        }
        self.first.backward(frames, &d, None, grads);
    }

    /// Latents [rows, L] → pixel logits, channels-last [rows, 64, 64, 6], and the tape.
    fn decode(&self, latents: &[f32], rows: usize) -> (Vec<f32>, DecoderTape) {
        let mut grids = vec![self.fc.forward_relu(latents, rows)];
        let last = self.decoder.len() - 1;
        for (i, layer) in self.decoder.iter().enumerate() {
            let y = layer.forward(grids.last().expect("the dense output at least"), rows, i != last);
            if i == last {
                return (y, DecoderTape { grids });
            }
            grids.push(y);
        }
        unreachable!("the decoder has layers")
    }

    /// Logit gradients → latent gradients.
    fn decode_backward(
        &self,
        latents: &[f32],
        tape: &DecoderTape,
        d_logits: Vec<f32>,
        rows: usize,
        grads: &mut [Vec<f32>],
    ) -> Vec<f32> {
        // The last layer has no ReLU, and every layer's input is a ReLU's output (the dense layer's for the
        // first): each hands down the gradient below that ReLU, masked while in cache.
        let mut d = d_logits;
        for (i, layer) in self.decoder.iter().enumerate().rev() {
            d = layer.backward(&tape.grids[i], &mut d, None, rows, grads, InputGradient::BelowRelu);
        }
        self.fc.backward(latents, &d, rows, grads, true)
    }
}

/// Σ over pixels of the binary cross-entropy with logits against `targets`, and the logits overwritten with
/// the loss's gradient scaled by `scale`. Each frame is summed by one thread, in `LANES` f32 partial sums (so
/// the loop vectorizes without reordering any sum) added up in f64.
fn bce_into_gradient(logits: &mut [f32], targets: &[f32], scale: f32) -> f64 {
    let frame = FRAME_CHANNELS * FRAME_SIDE * FRAME_SIDE;
    let sums: Vec<f64> = logits
        .par_chunks_mut(frame)
        .zip(targets.par_chunks(frame))
        .map(|(logits, targets)| frame_bce_into_gradient(logits, targets, scale))
        .collect();
    sums.iter().sum()
}

widest_fn! {
    /// One frame's part of [`bce_into_gradient`].
    fn frame_bce_into_gradient(logits: &mut [f32], targets: &[f32], scale: f32) -> f64 {
        const LANES: usize = 16;
        let mut lanes = [0.0f32; LANES];
        for (logits, targets) in logits.chunks_mut(LANES).zip(targets.chunks(LANES)) {
            for ((lane, l), &t) in lanes.iter_mut().zip(logits.iter_mut()).zip(targets) {
                *lane += fast_softplus(*l) - *l * t;
                *l = (fast_sigmoid(*l) - t) * scale;
            }
        }
        lanes.iter().map(|&s| s as f64).sum::<f64>()
    }
}

/// The image VAE's loss (and, when wanted, gradients in the order of `params`) on a batch, as
/// [`super::model::loss_and_gradients`] defines it.
pub fn images_loss_and_gradients(
    params: &ParamSet,
    transition: &[GpHypers],
    reward: &GpHypers,
    batch: &Batch,
    noise: (&[f32], &[f32]),
    gradients: Gradients,
) -> Result<StepLoss> {
    let latent = transition.len();
    let net = ConvVaeGrad::new(params, latent)?;
    let rows = batch.rows;
    let width = FRAME_CHANNELS * FRAME_SIDE * FRAME_SIDE;
    if batch.obs.len() != rows * width || batch.next_obs.len() != rows * width {
        return Err(Error::data(format!("DLGPD batch: {rows} rows of frames need {width} values each")));
    }
    let frames = net.first.input(&[&batch.obs, &batch.next_obs])?;
    let (mean, std, tape) = net.encode(&frames, 2 * rows);
    let eps = noise.0.iter().chain(noise.1);
    let samples: Vec<f32> = mean.iter().zip(&std).zip(eps).map(|((m, s), e)| m + s * e).collect();
    let (sample, next_sample) = samples.split_at(rows * latent);
    let next_std = &std[rows * latent..];

    let targets = &to_channels_last(&batch.next_obs, FRAME_CHANNELS, FRAME_SIDE);
    let inv_rows = 1.0 / rows.max(1) as f64;
    // The decoder's passes and the GPs (f64 Cholesky factorizations, a tenth of a batch-1024 step) need only the
    // samples, so they run side by side.
    let decoder_passes = || {
        let (mut d_logits, decoder_tape) = net.decode(next_sample, rows);
        let reconstruction = bce_into_gradient(&mut d_logits, targets, inv_rows as f32) * inv_rows;
        let backward = match gradients {
            Gradients::NotWanted => None,
            Gradients::Wanted => {
                let mut grads = zero_gradients(params);
                let d_next = net.decode_backward(next_sample, &decoder_tape, d_logits, rows, &mut grads);
                Some((grads, d_next))
            }
        };
        (reconstruction, backward)
    };
    let as_f64 = |v: &[f32]| v.iter().map(|&x| x as f64).collect::<Vec<f64>>();
    let gp_pass =
        || gp_terms(transition, reward, &as_f64(sample), &batch.actions, &as_f64(next_sample), &batch.rewards);
    let ((reconstruction, backward), gp) = rayon::join(decoder_passes, gp_pass);
    let gp = gp?;
    let entropy = -0.5 * inv_rows * next_std.iter().map(|&s| (s as f64).ln()).sum::<f64>();
    let total = reconstruction + entropy + gp.value;
    if !total.is_finite() {
        return Err(Error::diverged(format!(
            "DLGPD loss is {total} (reconstruction {reconstruction}, entropy {entropy}, GP {})",
            gp.value
        )));
    }
    let vae_gradients = match backward {
        None => Vec::new(),
        Some((mut grads, d_next)) => {
            // d sample = the GP's gradient; then d mean = d sample and d std = d sample ⊙ ε, per half.
            let mut d_mean: Vec<f32> = gp.d_latents.iter().map(|&g| g as f32).collect();
            d_mean.extend(gp.d_next_latents.iter().zip(&d_next).map(|(&g, d)| g as f32 + d));
            let d_std = d_mean
                .iter()
                .zip(noise.0.iter().chain(noise.1))
                .zip(&std)
                .enumerate()
                .map(|(i, ((d, e), s))| d * e - if i >= rows * latent { 0.5 * inv_rows as f32 / s } else { 0.0 })
                .collect();
            net.encode_backward(&frames, &tape, &d_mean, d_std, 2 * rows, &mut grads);
            grads
        }
    };
    Ok(StepLoss { total, reconstruction, entropy, gp, vae_gradients })
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::models::dlgpd::data::ObservationKind;
    use crate::models::dlgpd::model::{burn_loss_and_gradients, init_hypers, sample_noise};
    use crate::models::dlgpd::vae::VaeNet;
    use crate::nn::tensor::training_device;

    /// The loss, its parts and every gradient against burn's graph on random frames, with GPs initialized
    /// from the batch as training does, so that every term carries weight.
    #[test]
    fn hand_written_gradients_match_burn_autodiff() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let kind = ObservationKind::Images { side: FRAME_SIDE };
        let vae = VaeNet::init(kind, 3, 0, &device, &mut rng).unwrap();
        let rows = 5;
        let width = kind.input_len();
        let frame = |rng: &mut ChaCha8Rng| -> Vec<f32> {
            (0..rows * width).map(|_| if rng.random_bool(0.2) { rng.random_range(0.0..1.0) } else { 0.0 }).collect()
        };
        let batch = Batch {
            rows,
            obs: frame(&mut rng),
            next_obs: frame(&mut rng),
            actions: (0..rows).map(|_| rng.random_range(-2.0..2.0)).collect(),
            rewards: (0..rows).map(|_| rng.random_range(-3.0..0.0)).collect(),
        };
        let noise = sample_noise(rows, 3, &mut rng);
        let latents: Vec<f64> = (0..rows * 3).map(|_| rng.random_range(-1.0..1.0)).collect();
        let next: Vec<f64> = latents.iter().map(|l| l + rng.random_range(-0.1..0.1)).collect();
        let (transition, reward) = init_hypers(&latents, &next, &batch.rewards, 1).unwrap();
        let noise = (&noise.0[..], &noise.1[..]);
        let theirs =
            burn_loss_and_gradients(&vae, &transition, &reward, &batch, noise, Gradients::Wanted, &device).unwrap();
        let params = vae.params();
        let ours = images_loss_and_gradients(&params, &transition, &reward, &batch, noise, Gradients::Wanted).unwrap();
        for (what, a, b) in [
            ("total", ours.total, theirs.total),
            ("reconstruction", ours.reconstruction, theirs.reconstruction),
            ("entropy", ours.entropy, theirs.entropy),
            ("gp", ours.gp.value, theirs.gp.value),
        ] {
            assert!((a - b).abs() <= 1e-4 * (1.0 + b.abs()), "{what}: {a} vs {b}");
        }
        for ((tensor, ours), theirs) in params.tensors.iter().zip(&ours.vae_gradients).zip(&theirs.vae_gradients) {
            assert_eq!(ours.len(), theirs.len(), "'{}'", tensor.name);
            let scale = theirs.iter().fold(0.0f32, |m, x| m.max(x.abs())).max(1e-3);
            let worst = ours.iter().zip(theirs).fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(worst <= 1e-3 * scale, "'{}' differs by {worst} at scale {scale}", tensor.name);
            assert!(ours.iter().any(|g| *g != 0.0), "'{}' got no gradient", tensor.name);
        }
    }

    /// Each image is gathered and regrouped by one thread, chunks and tasks depend on the batch alone and
    /// partial sums are added in order, so the bytes do not depend on the threads.
    #[test]
    fn loss_and_gradients_do_not_depend_on_the_thread_count() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let kind = ObservationKind::Images { side: FRAME_SIDE };
        let params = VaeNet::init(kind, 3, 0, &device, &mut rng).unwrap().params();
        let rows = 4;
        let width = kind.input_len();
        let mut frame = || -> Vec<f32> { (0..rows * width).map(|_| rng.random_range(0.0..1.0)).collect() };
        let batch = Batch {
            rows,
            obs: frame(),
            next_obs: frame(),
            actions: vec![0.5, -1.0, 0.0, 2.0],
            rewards: vec![-1.0, -0.5, -2.0, -0.1],
        };
        let noise = sample_noise(rows, 3, &mut ChaCha8Rng::seed_from_u64(1));
        let latents: Vec<f64> = (0..rows * 3).map(|i| (i as f64 * 0.37).sin()).collect();
        let next: Vec<f64> = latents.iter().map(|l| l * 0.9).collect();
        let (transition, reward) = init_hypers(&latents, &next, &batch.rewards, 1).unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let step = images_loss_and_gradients(
                    &params,
                    &transition,
                    &reward,
                    &batch,
                    (&noise.0, &noise.1),
                    Gradients::Wanted,
                )
                .unwrap();
                (step.total.to_bits(), step.vae_gradients)
            })
        };
        assert_eq!(run(1), run(2));
    }
}
