//! 2-d convolutions stored as PyTorch stores them (Conv2d weight [out, in, k, k]; ConvTranspose2d weight
//! [in, out, k, k]; bias [out]), without padding, with torch's default initialization.

use burn::config::Config;
use burn::module::{Module, Param};
use burn::tensor::module::{conv2d, conv_transpose2d};
use burn::tensor::ops::{ConvOptions, ConvTransposeOptions};
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::init::torch_uniform;
use super::tensor::tensor;

#[derive(Config, Debug)]
pub struct Conv2dConfig {
    pub channels_in: usize,
    pub channels_out: usize,
    pub kernel: usize,
    pub stride: usize,
}

#[derive(Module, Debug)]
pub struct Conv2d {
    pub weight: Param<Tensor<4>>,
    pub bias: Param<Tensor<1>>,
    stride: usize,
}

#[derive(Module, Debug)]
pub struct ConvTranspose2d {
    pub weight: Param<Tensor<4>>,
    pub bias: Param<Tensor<1>>,
    stride: usize,
}

impl Conv2dConfig {
    /// torch.nn.Conv2d's default initialization: U(±1/√fan_in), fan_in = in · k².
    pub fn init<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> Conv2d {
        let (i, o, k) = (self.channels_in, self.channels_out, self.kernel);
        let fan_in = i * k * k;
        Conv2d {
            weight: Param::from_tensor(tensor(torch_uniform(rng, o * i * k * k, fan_in), [o, i, k, k], device)),
            bias: Param::from_tensor(tensor(torch_uniform(rng, o, fan_in), [o], device)),
            stride: self.stride,
        }
    }

    /// torch.nn.ConvTranspose2d's default initialization: torch takes fan_in from the weight's second
    /// dimension, which for a transposed convolution is the output channels: fan_in = out · k².
    pub fn init_transposed<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> ConvTranspose2d {
        let (i, o, k) = (self.channels_in, self.channels_out, self.kernel);
        let fan_in = o * k * k;
        ConvTranspose2d {
            weight: Param::from_tensor(tensor(torch_uniform(rng, i * o * k * k, fan_in), [i, o, k, k], device)),
            bias: Param::from_tensor(tensor(torch_uniform(rng, o, fan_in), [o], device)),
            stride: self.stride,
        }
    }
}

impl Conv2d {
    /// [batch, in, h, w] → [batch, out, (h − k)/s + 1, (w − k)/s + 1].
    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        let s = self.stride;
        conv2d(x, self.weight.val(), Some(self.bias.val()), ConvOptions::new([s, s], [0, 0], [1, 1], 1))
    }
}

impl ConvTranspose2d {
    /// [batch, in, h, w] → [batch, out, (h − 1)·s + k, (w − 1)·s + k].
    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        let s = self.stride;
        let options = ConvTransposeOptions::new([s, s], [0, 0], [0, 0], [1, 1], 1);
        conv_transpose2d(x, self.weight.val(), Some(self.bias.val()), options)
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::nn::tensor::{training_device, values};

    #[test]
    fn convolutions_compute_what_torch_computes() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let conv = Conv2dConfig::new(2, 3, 2, 2).init(&device, &mut rng);
        let x: Vec<f32> = (0..2 * 4 * 4).map(|i| (i as f32 * 0.37).sin()).collect();
        let input = tensor(x.clone(), [1, 2, 4, 4], &device);
        let y = conv.forward(input.clone());
        assert_eq!(y.dims(), [1, 3, 2, 2]);
        let (w, b, y) = (values(&conv.weight.val()), values(&conv.bias.val()), values(&y));
        // y[o, r, c] = b[o] + Σ_i Σ_kr Σ_kc w[o, i, kr, kc] x[i, 2r + kr, 2c + kc]
        for o in 0..3 {
            for (r, c) in [(0, 0), (1, 1), (0, 1)] {
                let mut expected = b[o];
                for i in 0..2 {
                    for kr in 0..2 {
                        for kc in 0..2 {
                            expected += w[((o * 2 + i) * 2 + kr) * 2 + kc] * x[(i * 4 + 2 * r + kr) * 4 + 2 * c + kc];
                        }
                    }
                }
                let got = y[(o * 2 + r) * 2 + c];
                assert!((got - expected).abs() < 1e-5, "out {o},{r},{c}: {got} vs {expected}");
            }
        }
        // The transposed convolution scatters each input pixel through the kernel: with one input pixel, its
        // output is that pixel times the kernel plus the bias.
        let deconv = Conv2dConfig::new(1, 2, 3, 2).init_transposed(&device, &mut rng);
        let y = deconv.forward(tensor(vec![2.0], [1, 1, 1, 1], &device));
        assert_eq!(y.dims(), [1, 2, 3, 3]);
        let (w, b, y) = (values(&deconv.weight.val()), values(&deconv.bias.val()), values(&y));
        for (i, got) in y.iter().enumerate() {
            let o = i / 9;
            assert!((got - (2.0 * w[i] + b[o])).abs() < 1e-5);
        }
        assert_eq!(deconv.forward(tensor(vec![0.0; 25], [1, 1, 5, 5], &device)).dims(), [1, 2, 11, 11]);
    }
}
