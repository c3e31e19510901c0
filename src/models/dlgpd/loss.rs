//! The VAE's parts of DLGPD's loss in burn, and the seam through which the GP terms (computed in f64
//! outside the graph, with their own gradients) join it.

use burn::tensor::activation::relu;
use burn::tensor::Tensor;

use crate::nn::tensor::tensor;

/// A scalar whose value is `value` and whose gradient with respect to `x` is `grad` (row-major like `x`):
/// Σ x ⊙ G plus the constant that restores the value. How a loss term computed outside burn, such as the GP
/// marginal likelihood, sends its gradient into the encoder.
pub fn injected<const D: usize>(x: Tensor<D>, grad: &[f64], value: f64) -> Tensor<1> {
    let dims = x.dims();
    let device = x.device();
    let g = tensor(grad.iter().map(|&v| v as f32).collect(), dims, &device);
    let x_values = crate::nn::tensor::values(&x);
    let linear_part: f64 = x_values.iter().zip(grad).map(|(a, b)| *a as f64 * b).sum();
    (x * g).sum().add_scalar(value - linear_part)
}

/// Σ over pixels of binary cross-entropy with logits against targets in [0, 1], divided by the batch size
/// (the authors' normalization: summed over the 2 × 3 × 64 × 64 pixels, averaged over the batch). Written in
/// the overflow-free form max(l, 0) − l·t + ln(1 + e^−|l|).
pub fn reconstruction_bce(logits: Tensor<4>, targets: Tensor<4>) -> Tensor<1> {
    let batch = logits.dims()[0].max(1) as f64;
    let stable = relu(logits.clone()) - logits.clone() * targets + logits.abs().neg().exp().log1p();
    stable.sum().div_scalar(batch)
}

/// −½ Σ log σ over the next observations' encoder stds, divided by the batch size (the authors' entropy term;
/// a Gaussian's entropy would weigh Σ log σ by 1).
pub fn entropy_term(next_std: Tensor<2>) -> Tensor<1> {
    let batch = next_std.dims()[0].max(1) as f64;
    next_std.log().sum().mul_scalar(-0.5 / batch)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::tensor::{scalar, training_device, values};

    #[test]
    fn injected_terms_carry_their_value_and_gradient() {
        let device = training_device();
        let x = tensor(vec![0.5, -1.0, 2.0, 0.25], [2, 2], &device).require_grad();
        let grad = [0.1, -0.2, 0.3, 4.0];
        let term = injected(x.clone() * 2.0, &grad, 7.5);
        assert!((scalar(&term) - 7.5).abs() < 1e-5);
        let grads = term.backward();
        let got = values(&x.grad(&grads).unwrap());
        for (g, want) in got.iter().zip(grad) {
            assert!((*g as f64 - 2.0 * want).abs() < 1e-6, "{g} vs {}", 2.0 * want);
        }
    }

    #[test]
    fn bce_and_entropy_match_their_formulas() {
        let device = training_device();
        let logits = [-30.0f32, -1.0, 0.0, 2.0, 40.0, 0.5, -0.5, 3.0];
        let targets = [0.0f32, 0.2, 0.5, 1.0, 1.0, 0.9, 0.0, 0.3];
        let loss = reconstruction_bce(
            tensor(logits.to_vec(), [2, 1, 2, 2], &device),
            tensor(targets.to_vec(), [2, 1, 2, 2], &device),
        );
        let direct: f64 = logits
            .iter()
            .zip(targets)
            .map(|(&l, t)| {
                let p = 1.0 / (1.0 + (-(l as f64)).exp());
                -(t as f64 * p.max(1e-300).ln() + (1.0 - t as f64) * (1.0 - p).max(1e-300).ln())
            })
            .sum::<f64>()
            / 2.0;
        // Saturated logits lose the direct form's precision; the stable form stays exact.
        assert!((scalar(&loss) - direct).abs() < 1e-4 * direct.abs(), "{} vs {direct}", scalar(&loss));
        let std = tensor(vec![0.5, 1.0, 2.0, 0.1], [2, 2], &device);
        let expected = -0.5 * [0.5f64, 1.0, 2.0, 0.1].iter().map(|s| s.ln()).sum::<f64>() / 2.0;
        assert!((scalar(&entropy_term(std)) - expected).abs() < 1e-5);
    }
}
