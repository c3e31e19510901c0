//! Gaussian noise with power spectral density ∝ 1/f^β along time (Pinneri et al. 2020, "iCEM"):
//! β = 0 is white noise, larger β gives smoother, more correlated action sequences.

use std::sync::Arc;

use rand::Rng;
use rand_distr::StandardNormal;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

/// Draws unit-variance colored-noise sequences of a fixed length. Built once per planner (the FFT plan
/// and spectral weights are reused).
pub struct ColoredNoise {
    len: usize,
    /// Amplitude per frequency bin 0..=len/2.
    amplitudes: Vec<f64>,
    /// Standard deviation of the unnormalized output, used to bring it to unit variance.
    std: f64,
    inverse: Arc<dyn Fft<f64>>,
}

impl ColoredNoise {
    pub fn new(beta: f64, len: usize) -> Self {
        assert!(len > 0, "colored noise needs a positive length");
        let bins = len / 2 + 1;
        // The zero frequency would get infinite power; like the reference method, clamp it to the lowest
        // nonzero frequency 1/len.
        let amplitudes: Vec<f64> = (0..bins)
            .map(|k| {
                let f = (k as f64 / len as f64).max(1.0 / len as f64);
                f.powf(-beta / 2.0)
            })
            .collect();
        let std = theoretical_std(&amplitudes, len);
        let inverse = FftPlanner::new().plan_fft_inverse(len);
        ColoredNoise { len, amplitudes, std, inverse }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Fills `out` (length `len`) with one sequence. `scratch` must have length `len`.
    pub fn sample_into<R: Rng + ?Sized>(&self, rng: &mut R, scratch: &mut [Complex<f64>], out: &mut [f64]) {
        let n = self.len;
        let bins = self.amplitudes.len();
        for (k, (bin, amplitude)) in scratch[..bins].iter_mut().zip(&self.amplitudes).enumerate() {
            let re: f64 = rng.sample(StandardNormal);
            let im: f64 = rng.sample(StandardNormal);
            // Bins whose conjugate is themselves (DC, and Nyquist for even lengths) must be real.
            let self_conjugate = k == 0 || (n.is_multiple_of(2) && k == n / 2);
            *bin = if self_conjugate { Complex::new(re * std::f64::consts::SQRT_2, 0.0) } else { Complex::new(re, im) }
                * *amplitude;
        }
        // Hermitian symmetry makes the inverse transform real.
        for k in bins..n {
            scratch[k] = scratch[n - k].conj();
        }
        self.inverse.process(scratch);
        for (o, c) in out.iter_mut().zip(scratch.iter()) {
            *o = c.re / self.std;
        }
    }
}

/// Standard deviation of each output sample when every bin's real and imaginary parts are N(0, 1)
/// (real-only bins are scaled by √2 to keep the same power), before normalization.
fn theoretical_std(amplitudes: &[f64], n: usize) -> f64 {
    // Each output sample is Σ_k over the full spectrum of X_k e^{2πikt/n}; its variance is
    // Σ_k Var(X_k) = Σ over all n bins of 2·a_k² (re and im each contribute a_k²).
    let full: f64 = (0..n)
        .map(|k| {
            let bin = if k < amplitudes.len() { k } else { n - k };
            2.0 * amplitudes[bin].powi(2)
        })
        .sum();
    full.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn sample_many(beta: f64, len: usize, count: usize) -> Vec<Vec<f64>> {
        let noise = ColoredNoise::new(beta, len);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut scratch = vec![Complex::new(0.0, 0.0); len];
        (0..count)
            .map(|_| {
                let mut out = vec![0.0; len];
                noise.sample_into(&mut rng, &mut scratch, &mut out);
                out
            })
            .collect()
    }

    fn lag1_correlation(samples: &[Vec<f64>]) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for s in samples {
            for w in s.windows(2) {
                num += w[0] * w[1];
            }
            den += s.iter().map(|x| x * x).sum::<f64>();
        }
        num / den
    }

    #[test]
    fn samples_have_unit_variance() {
        for beta in [0.0, 0.5, 2.0] {
            let samples = sample_many(beta, 30, 4000);
            let n = samples.len() * 30;
            let var = samples.iter().flatten().map(|x| x * x).sum::<f64>() / n as f64;
            assert!((var - 1.0).abs() < 0.06, "beta {beta}: variance {var}");
        }
    }

    #[test]
    fn larger_beta_is_smoother() {
        let white = lag1_correlation(&sample_many(0.0, 32, 2000));
        let pink = lag1_correlation(&sample_many(1.0, 32, 2000));
        let red = lag1_correlation(&sample_many(2.0, 32, 2000));
        assert!(white.abs() < 0.05, "white noise is uncorrelated: {white}");
        assert!(pink > white + 0.1 && red > pink + 0.1, "{white} {pink} {red}");
    }
}
