//! Initial weights drawn from our seeded RNG in the distributions the reference PyTorch code uses.

use rand::Rng;
use rand_distr::StandardNormal;

/// torch.nn.Linear's and GRUCell's default: U(−1/√fan_in, 1/√fan_in).
pub fn torch_uniform<R: Rng + ?Sized>(rng: &mut R, n: usize, fan_in: usize) -> Vec<f32> {
    let bound = 1.0 / (fan_in.max(1) as f64).sqrt();
    (0..n).map(|_| rng.random_range(-bound..bound) as f32).collect()
}

/// mbrl-lib's ensemble-layer initialization: normal with std 1/(2√fan_in), redrawn outside two standard
/// deviations.
pub fn truncated_normal<R: Rng + ?Sized>(rng: &mut R, n: usize, fan_in: usize) -> Vec<f32> {
    let std = 1.0 / (2.0 * (fan_in.max(1) as f64).sqrt());
    (0..n)
        .map(|_| loop {
            let z: f64 = rng.sample(StandardNormal);
            if z.abs() <= 2.0 {
                break (z * std) as f32;
            }
        })
        .collect()
}

/// torch.nn.init.xavier_uniform_ with gain 1 for a [fan_out, fan_in] weight: U(−a, a), a = √(6/(fan_in + fan_out)).
pub fn xavier_uniform<R: Rng + ?Sized>(rng: &mut R, fan_in: usize, fan_out: usize) -> Vec<f32> {
    let bound = (6.0 / (fan_in + fan_out).max(1) as f64).sqrt();
    (0..fan_in * fan_out).map(|_| rng.random_range(-bound..bound) as f32).collect()
}
