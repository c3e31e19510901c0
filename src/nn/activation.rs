//! Activation functions by name, applied to burn tensors (training) and to plain slices (fast inference).

use burn::tensor::{activation, Tensor};
use serde::{Deserialize, Serialize};

use crate::util::wide::widest_fn;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Activation {
    Relu,
    /// x·σ(x), "swish" in PETS.
    Silu,
    Tanh,
    Sigmoid,
    Identity,
}

impl Activation {
    pub fn apply<const D: usize>(self, x: Tensor<D>) -> Tensor<D> {
        match self {
            Activation::Relu => activation::relu(x),
            Activation::Silu => activation::silu(x),
            Activation::Tanh => activation::tanh(x),
            Activation::Sigmoid => activation::sigmoid(x),
            Activation::Identity => x,
        }
    }

    /// The planning path's activation. libm's `expf` is a call per element and took two thirds of a PETS MPC
    /// step; [`fast_exp`] is branch-free arithmetic the compiler vectorizes, at the widest width the CPU has
    /// (checked at run time, so the binary still runs everywhere: `util::wide`).
    pub fn apply_in_place(self, xs: &mut [f32]) {
        activate_widest(self, xs);
    }

    #[inline(always)]
    fn apply_portable(self, xs: &mut [f32]) {
        // Blocks of 16 give the compiler independent vectors to interleave: the polynomial in fast_exp is a
        // chain of dependent operations, which one vector at a time would leave latency-bound.
        let (blocks, rest) = xs.as_chunks_mut::<16>();
        for block in blocks {
            self.apply_block(block);
        }
        self.apply_block(rest);
    }

    #[inline(always)]
    fn apply_block(self, xs: &mut [f32]) {
        match self {
            Activation::Relu => xs.iter_mut().for_each(|x| *x = x.max(0.0)),
            Activation::Silu => xs.iter_mut().for_each(|x| *x *= 1.0 / (1.0 + fast_exp(-*x))),
            Activation::Tanh => xs.iter_mut().for_each(|x| *x = fast_tanh(*x)),
            Activation::Sigmoid => xs.iter_mut().for_each(|x| *x = fast_sigmoid(*x)),
            Activation::Identity => {}
        }
    }

    /// In place like [`Activation::apply_in_place`], and writes dh/dz at each element into `derivative`, so a
    /// hand-written backward pass multiplies by it without recomputing any exponential.
    pub fn apply_with_derivative(self, xs: &mut [f32], derivative: &mut [f32]) {
        assert_eq!(xs.len(), derivative.len(), "one derivative per element");
        activate_with_derivative_widest(self, xs, derivative);
    }

    #[inline(always)]
    fn apply_with_derivative_portable(self, xs: &mut [f32], derivative: &mut [f32]) {
        let (blocks, rest) = xs.as_chunks_mut::<16>();
        let (slope_blocks, slope_rest) = derivative.as_chunks_mut::<16>();
        for (block, slope) in blocks.iter_mut().zip(slope_blocks) {
            self.derivative_block(block, slope);
        }
        self.derivative_block(rest, slope_rest);
    }

    #[inline(always)]
    fn derivative_block(self, xs: &mut [f32], slope: &mut [f32]) {
        let each = xs.iter_mut().zip(slope.iter_mut());
        match self {
            Activation::Relu => each.for_each(|(x, d)| {
                *d = if *x > 0.0 { 1.0 } else { 0.0 };
                *x = x.max(0.0);
            }),
            // One division per element, shared by the value and the slope: a vector division costs more than
            // the whole exponential here.
            Activation::Silu => each.for_each(|(x, d)| {
                let s = 1.0 / (1.0 + fast_exp(-*x));
                *d = s * (1.0 + *x * (1.0 - s));
                *x *= s;
            }),
            Activation::Tanh => each.for_each(|(x, d)| {
                *x = fast_tanh(*x);
                *d = 1.0 - *x * *x;
            }),
            Activation::Sigmoid => each.for_each(|(x, d)| {
                *x = fast_sigmoid(*x);
                *d = *x * (1.0 - *x);
            }),
            Activation::Identity => slope.fill(1.0),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Activation::Relu => "relu",
            Activation::Silu => "silu",
            Activation::Tanh => "tanh",
            Activation::Sigmoid => "sigmoid",
            Activation::Identity => "identity",
        }
    }
}

/// e^x for f32 to about 2e-7 relative (and 0 / 1.7e38 beyond the clamp): x = k·ln 2 + r with |r| ≤ ln 2 / 2,
/// e^r by its degree-6 Taylor polynomial, 2^k built in the exponent bits.
#[inline(always)]
pub fn fast_exp(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    // Adding 1.5·2²³ rounds to the nearest integer k and leaves k in the low mantissa bits, so no
    // float-to-int conversion (which Rust saturates lane by lane, defeating vectorization) is needed.
    const SHIFTER: f32 = 12_582_912.0;
    const SHIFTER_BITS: i32 = 0x4B40_0000;
    // max/min rather than clamp: they compile to plain vector min/max without clamp's NaN propagation.
    #[allow(clippy::manual_clamp)]
    let x = x.max(-87.0).min(88.0);
    let shifted = x * LOG2E + SHIFTER;
    let k = shifted - SHIFTER;
    let r = x - k * LN2_HI - k * LN2_LO;
    // Estrin's scheme: three short chains instead of one of length six.
    let r2 = r * r;
    let p =
        (1.0 + r) + r2 * (0.5 + r * (1.0 / 6.0)) + r2 * r2 * ((1.0 / 24.0 + r * (1.0 / 120.0)) + r2 * (1.0 / 720.0));
    let exponent = (shifted.to_bits() as i32).wrapping_sub(SHIFTER_BITS).wrapping_add(127);
    p * f32::from_bits((exponent as u32) << 23)
}

/// σ(x) from [`fast_exp`] (relative error below 1e-6).
#[inline(always)]
pub fn fast_sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + fast_exp(-x))
}

/// tanh(x) from [`fast_exp`] (error below 1e-6); exactly ±1 far out.
#[inline(always)]
pub fn fast_tanh(x: f32) -> f32 {
    1.0 - 2.0 / (fast_exp(2.0 * x) + 1.0)
}

/// ln(1 + e^x) without libm calls: max(x, 0) + ln(1 + e^−|x|), the logarithm of 1 + y ∈ [1, 2] as
/// 2·atanh(y / (2 + y)) by its odd series to s⁹ (|s| ≤ 1/3, error below 1e-7).
#[inline(always)]
pub fn fast_softplus(x: f32) -> f32 {
    let y = fast_exp(-x.abs());
    let s = y / (2.0 + y);
    let s2 = s * s;
    let series = s * (2.0 + s2 * (2.0 / 3.0 + s2 * (2.0 / 5.0 + s2 * (2.0 / 7.0 + s2 * (2.0 / 9.0)))));
    x.max(0.0) + series
}

widest_fn! {
    fn activate_widest(activation: Activation, xs: &mut [f32]) {
        activation.apply_portable(xs)
    }
}

widest_fn! {
    fn activate_with_derivative_widest(activation: Activation, xs: &mut [f32], derivative: &mut [f32]) {
        activation.apply_with_derivative_portable(xs, derivative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The copies compiled for the CPU's widest vectors give the bits of the baseline loop (`util::wide`).
    #[test]
    fn every_vector_width_gives_the_same_bits() {
        let xs: Vec<f32> = (0..1003).map(|i| (i as f32 * 0.37).sin() * 12.0).collect();
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for activation in [Activation::Relu, Activation::Silu, Activation::Tanh, Activation::Sigmoid] {
            let (mut wide, mut wide_slope) = (xs.clone(), vec![0.0; xs.len()]);
            activation.apply_with_derivative(&mut wide, &mut wide_slope);
            let (mut base, mut base_slope) = (xs.clone(), vec![0.0; xs.len()]);
            for (x, d) in base.iter_mut().zip(base_slope.iter_mut()) {
                activation.derivative_block(std::slice::from_mut(x), std::slice::from_mut(d));
            }
            assert_eq!((bits(&wide), bits(&wide_slope)), (bits(&base), bits(&base_slope)), "{activation:?}");
            let mut applied = xs.clone();
            activation.apply_in_place(&mut applied);
            assert_eq!(bits(&applied), bits(&base), "{activation:?}");
        }
    }

    #[test]
    fn fast_exp_is_accurate_over_the_range_networks_use() {
        let mut worst = 0.0f64;
        let mut x = -80.0f32;
        while x < 80.0 {
            let exact = (x as f64).exp();
            worst = worst.max(((fast_exp(x) as f64) - exact).abs() / exact);
            x += 0.0137;
        }
        assert!(worst < 5e-7, "worst relative error {worst}");
        assert_eq!(fast_exp(-1000.0), fast_exp(-87.0));
        assert!(fast_exp(1000.0).is_finite());
    }

    #[test]
    fn fast_sigmoid_and_tanh_are_accurate_and_saturate_cleanly() {
        assert_eq!((fast_tanh(50.0), fast_tanh(-50.0)), (1.0, -1.0));
        assert_eq!(fast_sigmoid(100.0), 1.0);
        assert!((0.0..1e-37).contains(&fast_sigmoid(-100.0)));
        assert_eq!(fast_softplus(100.0), 100.0);
        assert!((0.0..1e-30).contains(&fast_softplus(-100.0)));
        for x in [-3.0f32, -0.5, 0.0, 0.7, 2.5] {
            assert!((fast_tanh(x) - x.tanh()).abs() < 1e-6);
            assert!((fast_sigmoid(x) - 1.0 / (1.0 + (-x).exp())).abs() < 1e-6);
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        for activation in
            [Activation::Relu, Activation::Silu, Activation::Tanh, Activation::Sigmoid, Activation::Identity]
        {
            let xs: Vec<f32> = (0..37).map(|i| -4.1 + 0.23 * i as f32).collect();
            let (mut h, mut slope) = (xs.clone(), vec![0.0; xs.len()]);
            activation.apply_with_derivative(&mut h, &mut slope);
            let mut plain = xs.clone();
            activation.apply_in_place(&mut plain);
            assert_eq!(h, plain, "{activation:?}: the same outputs as apply_in_place");
            for (k, &x) in xs.iter().enumerate() {
                let f = |x: f64| {
                    let mut v = [x as f32];
                    activation.apply_in_place(&mut v);
                    v[0] as f64
                };
                let numeric = (f(x as f64 + 1e-2) - f(x as f64 - 1e-2)) / 2e-2;
                assert!((slope[k] as f64 - numeric).abs() < 2e-3, "{activation:?} at {x}: {} vs {numeric}", slope[k]);
            }
        }
    }

    #[test]
    fn fast_softplus_matches_the_definition() {
        let mut x = -30.0f32;
        while x < 30.0 {
            let exact = (x as f64).exp().ln_1p();
            let err = ((fast_softplus(x) as f64) - exact).abs();
            assert!(err <= 2e-6 * exact.max(1e-3), "x {x}: {} vs {exact}", fast_softplus(x));
            x += 0.0173;
        }
    }
}
