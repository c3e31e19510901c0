//! DLGPD's VAE. The paper's is convolutional (thesis Tables A.1/A.2; METHODS.md): two stacked 64 × 64 RGB
//! frames (older first, 6 channels) → a 3-d Gaussian latent, and back to the logits of both frames, with a
//! Bernoulli likelihood. Convolutions without padding; the std head is softplus(x + 0.55) + 0.01 as in the
//! authors' code. The small preset's VAE is an MLP on two stacked pole directions (cos θ, sin θ) with a Gaussian
//! likelihood of fixed std, a documented deviation so that a model trains in minutes on a CPU.

use burn::module::Module;
use burn::tensor::activation::{relu, softplus};
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::data::ObservationKind;
use super::loss::reconstruction_bce;
use crate::error::{Error, Result};
use crate::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d};
use crate::nn::tensor::{tensor, values};
use crate::nn::{Linear, LinearConfig, ParamSet};

pub const FRAME_CHANNELS: usize = 6;
pub const FRAME_SIDE: usize = 64;
/// Width of the encoder's last convolution output, flattened (256 channels × 2 × 2).
const FLAT: usize = 1024;
pub const STD_SHIFT: f64 = 0.55;
pub const STD_FLOOR: f64 = 0.01;
/// The angle VAE's likelihood std: a few times the 0.01 observation noise, so that reconstruction weighs
/// about as much against the GP terms as the images' summed pixel likelihood does.
pub const ANGLE_LIKELIHOOD_STD: f64 = 0.05;

fn std_head(raw: Tensor<2>) -> Tensor<2> {
    softplus(raw.add_scalar(STD_SHIFT), 1.0).add_scalar(STD_FLOOR)
}

#[derive(Module, Debug)]
pub struct ConvEncoder {
    conv1: Conv2d,
    conv2: Conv2d,
    conv3: Conv2d,
    conv4: Conv2d,
    mean: Linear,
    std: Linear,
}

#[derive(Module, Debug)]
pub struct ConvDecoder {
    fc: Linear,
    deconv1: ConvTranspose2d,
    deconv2: ConvTranspose2d,
    deconv3: ConvTranspose2d,
    deconv4: ConvTranspose2d,
}

impl ConvEncoder {
    pub fn init<R: Rng + ?Sized>(latent: usize, device: &Device, rng: &mut R) -> Self {
        let conv = |i, o, rng: &mut R| Conv2dConfig::new(i, o, 4, 2).init(device, rng);
        ConvEncoder {
            conv1: conv(FRAME_CHANNELS, 32, rng),
            conv2: conv(32, 64, rng),
            conv3: conv(64, 128, rng),
            conv4: conv(128, 256, rng),
            mean: LinearConfig::new(FLAT, latent).init(device, rng),
            std: LinearConfig::new(FLAT, latent).init(device, rng),
        }
    }

    /// Frames [batch, 6, 64, 64] in [0, 1] → (mean, std), each [batch, latent].
    pub fn forward(&self, frames: Tensor<4>) -> (Tensor<2>, Tensor<2>) {
        let h = relu(self.conv1.forward(frames));
        let h = relu(self.conv2.forward(h));
        let h = relu(self.conv3.forward(h));
        let h = relu(self.conv4.forward(h));
        let h: Tensor<2> = h.flatten(1, 3);
        let std = std_head(self.std.forward(h.clone()));
        (self.mean.forward(h), std)
    }
}

impl ConvDecoder {
    pub fn init<R: Rng + ?Sized>(latent: usize, device: &Device, rng: &mut R) -> Self {
        let deconv = |i, o, k, rng: &mut R| Conv2dConfig::new(i, o, k, 2).init_transposed(device, rng);
        ConvDecoder {
            fc: LinearConfig::new(latent, FLAT).init(device, rng),
            deconv1: deconv(FLAT, 128, 5, rng),
            deconv2: deconv(128, 64, 5, rng),
            deconv3: deconv(64, 32, 6, rng),
            deconv4: deconv(32, FRAME_CHANNELS, 6, rng),
        }
    }

    /// Latents [batch, latent] → pixel logits [batch, 6, 64, 64] (older frame first).
    pub fn forward(&self, latent: Tensor<2>) -> Tensor<4> {
        let [batch, _] = latent.dims();
        let h = relu(self.fc.forward(latent)).reshape([batch, FLAT, 1, 1]);
        let h = relu(self.deconv1.forward(h));
        let h = relu(self.deconv2.forward(h));
        let h = relu(self.deconv3.forward(h));
        self.deconv4.forward(h)
    }
}

#[derive(Module, Debug)]
pub struct ConvVae {
    pub encoder: ConvEncoder,
    pub decoder: ConvDecoder,
}

#[derive(Module, Debug)]
pub struct MlpEncoder {
    hidden1: Linear,
    hidden2: Linear,
    mean: Linear,
    std: Linear,
}

#[derive(Module, Debug)]
pub struct MlpDecoder {
    hidden1: Linear,
    hidden2: Linear,
    out: Linear,
}

#[derive(Module, Debug)]
pub struct MlpVae {
    pub encoder: MlpEncoder,
    pub decoder: MlpDecoder,
}

impl MlpVae {
    pub fn init<R: Rng + ?Sized>(input: usize, hidden: usize, latent: usize, device: &Device, rng: &mut R) -> Self {
        let linear = |i, o, rng: &mut R| LinearConfig::new(i, o).init(device, rng);
        MlpVae {
            encoder: MlpEncoder {
                hidden1: linear(input, hidden, rng),
                hidden2: linear(hidden, hidden, rng),
                mean: linear(hidden, latent, rng),
                std: linear(hidden, latent, rng),
            },
            decoder: MlpDecoder {
                hidden1: linear(latent, hidden, rng),
                hidden2: linear(hidden, hidden, rng),
                out: linear(hidden, input, rng),
            },
        }
    }

    fn encode(&self, obs: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        let e = &self.encoder;
        let h = relu(e.hidden2.forward(relu(e.hidden1.forward(obs))));
        (e.mean.forward(h.clone()), std_head(e.std.forward(h)))
    }

    fn decode(&self, latent: Tensor<2>) -> Tensor<2> {
        let d = &self.decoder;
        d.out.forward(relu(d.hidden2.forward(relu(d.hidden1.forward(latent)))))
    }
}

/// The VAE of either observation kind, behind one interface: flat observation rows in, latents out.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)] // one per model, never in a collection
pub enum VaeNet {
    Images { side: usize, vae: ConvVae },
    Angles(MlpVae),
}

impl VaeNet {
    pub fn init<R: Rng + ?Sized>(
        kind: ObservationKind,
        latent: usize,
        hidden: usize,
        device: &Device,
        rng: &mut R,
    ) -> Result<VaeNet> {
        match kind {
            ObservationKind::Images { side: FRAME_SIDE } => Ok(VaeNet::Images {
                side: FRAME_SIDE,
                vae: ConvVae {
                    encoder: ConvEncoder::init(latent, device, rng),
                    decoder: ConvDecoder::init(latent, device, rng),
                },
            }),
            ObservationKind::Images { side } => Err(Error::data(format!(
                "frames are {side} × {side}; the convolutional VAE of Tables A.1/A.2 takes {FRAME_SIDE} × {FRAME_SIDE}"
            ))),
            ObservationKind::Angles => Ok(VaeNet::Angles(MlpVae::init(kind.input_len(), hidden, latent, device, rng))),
        }
    }

    fn as_images(obs: Tensor<2>, side: usize) -> Tensor<4> {
        let rows = obs.dims()[0];
        obs.reshape([rows, FRAME_CHANNELS, side, side])
    }

    /// Observation rows [rows, input_len] → encoder (mean, std), each [rows, latent].
    pub fn encode(&self, obs: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        match self {
            VaeNet::Images { side, vae } => vae.encoder.forward(Self::as_images(obs, *side)),
            VaeNet::Angles(vae) => vae.encode(obs),
        }
    }

    /// −log p(target | latent) summed over the observation and averaged over the batch: Bernoulli pixels
    /// (the paper) or the angle VAE's Gaussian.
    pub fn reconstruction(&self, latent: Tensor<2>, target: Tensor<2>) -> Tensor<1> {
        match self {
            VaeNet::Images { side, vae } => {
                reconstruction_bce(vae.decoder.forward(latent), Self::as_images(target, *side))
            }
            VaeNet::Angles(vae) => {
                let batch = latent.dims()[0].max(1) as f64;
                let scale = 1.0 / (2.0 * ANGLE_LIKELIHOOD_STD * ANGLE_LIKELIHOOD_STD * batch);
                (vae.decode(latent) - target).powi_scalar(2).sum().mul_scalar(scale)
            }
        }
    }

    /// The decoded observation rows: pixel intensities in [0, 1], or the angle VAE's means.
    pub fn decode(&self, latent: Tensor<2>) -> Vec<f32> {
        match self {
            VaeNet::Images { vae, .. } => {
                let logits = vae.decoder.forward(latent);
                values(&burn::tensor::activation::sigmoid(logits))
            }
            VaeNet::Angles(vae) => values(&vae.decode(latent)),
        }
    }

    /// Parameters named as the module's state_dict (`encoder.conv1.weight`).
    pub fn params(&self) -> ParamSet<f32> {
        let name = |n: &str| n.to_string();
        match self {
            VaeNet::Images { vae, .. } => ParamSet::from_module(vae, name),
            VaeNet::Angles(vae) => ParamSet::from_module(vae, name),
        }
    }

    pub fn gradients(&self, grads: &burn::tensor::Gradients) -> Vec<Vec<f32>> {
        match self {
            VaeNet::Images { vae, .. } => ParamSet::<f32>::gradients(vae, grads),
            VaeNet::Angles(vae) => ParamSet::<f32>::gradients(vae, grads),
        }
    }

    /// This network with `params` loaded (on `device`).
    pub fn with_params(self, params: &ParamSet<f32>, device: &Device) -> Result<VaeNet> {
        Ok(match self {
            VaeNet::Images { side, vae } => VaeNet::Images { side, vae: params.load_into(vae, device)? },
            VaeNet::Angles(vae) => VaeNet::Angles(params.load_into(vae, device)?),
        })
    }
}

/// Rows encoded at once outside training, bounding the memory of a conv forward pass.
const ENCODE_CHUNK: usize = 256;

/// Encoder means and stds of observation rows, in chunks.
pub fn encode_rows(vae: &VaeNet, obs: &[f32], width: usize, device: &Device) -> (Vec<f32>, Vec<f32>) {
    let (mut means, mut stds) = (Vec::new(), Vec::new());
    for chunk in obs.chunks(ENCODE_CHUNK * width) {
        let rows = chunk.len() / width;
        let (m, s) = vae.encode(tensor(chunk.to_vec(), [rows, width], device));
        means.extend(values(&m));
        stds.extend(values(&s));
    }
    (means, stds)
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::nn::tensor::{tensor, training_device, values};

    #[test]
    fn the_tables_shapes_hold_and_the_std_is_positive() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let encoder = ConvEncoder::init(3, &device, &mut rng);
        let decoder = ConvDecoder::init(3, &device, &mut rng);
        let n = 2 * FRAME_CHANNELS * FRAME_SIDE * FRAME_SIDE;
        let frames = tensor((0..n).map(|i| ((i % 97) as f32) / 97.0).collect(), [2, 6, 64, 64], &device);
        let (mean, std) = encoder.forward(frames);
        assert_eq!((mean.dims(), std.dims()), ([2, 3], [2, 3]));
        assert!(values(&std).iter().all(|&s| s > STD_FLOOR as f32));
        let logits = decoder.forward(mean);
        assert_eq!(logits.dims(), [2, 6, 64, 64]);
        assert!(values(&logits).iter().all(|x| x.is_finite()));
    }
}
