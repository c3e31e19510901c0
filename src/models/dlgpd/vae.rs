//! DLGPD's convolutional VAE (thesis Tables A.1/A.2; METHODS.md): two stacked 64 × 64 RGB frames (older first,
//! 6 channels) → a 3-d Gaussian latent, and back to the logits of both frames. Convolutions without
//! padding; the std head is softplus(x + 0.55) + 0.01 as in the authors' code.

use burn::module::Module;
use burn::tensor::activation::{relu, softplus};
use burn::tensor::{Device, Tensor};
use rand::Rng;

use crate::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d};
use crate::nn::{Linear, LinearConfig};

pub const FRAME_CHANNELS: usize = 6;
pub const FRAME_SIDE: usize = 64;
/// Width of the encoder's last convolution output, flattened (256 channels × 2 × 2).
const FLAT: usize = 1024;
const STD_SHIFT: f64 = 0.55;
const STD_FLOOR: f64 = 0.01;

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
        let std = softplus(self.std.forward(h.clone()).add_scalar(STD_SHIFT), 1.0).add_scalar(STD_FLOOR);
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
