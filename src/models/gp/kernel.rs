//! The squared-exponential kernel with one lengthscale per input dimension (ARD) and an outputscale,
//! k(x, x′) = σ_f² exp(−½ Σ_d (x_d − x′_d)² / ℓ_d²): GPyTorch's `ScaleKernel(RBFKernel(ard_num_dims))`.

use faer::Mat;

#[derive(Clone, Debug, PartialEq)]
pub struct SeArd {
    pub lengthscales: Vec<f64>,
    /// σ_f², the prior variance of the function.
    pub outputscale: f64,
}

impl SeArd {
    pub fn dims(&self) -> usize {
        self.lengthscales.len()
    }

    /// K(a, b) for row-major inputs `a` (rows × dims) and `b`. Differences are taken coordinate by
    /// coordinate rather than through ‖a‖² + ‖b‖² − 2a·b, which cancels badly for nearby points: the latent
    /// inputs here have few dimensions, so the direct form costs little more.
    pub fn matrix(&self, a: &[f64], b: &[f64]) -> Mat<f64> {
        let d = self.dims();
        let inv_sq: Vec<f64> = self.lengthscales.iter().map(|l| 1.0 / (l * l)).collect();
        let (na, nb) = (a.len() / d, b.len() / d);
        Mat::from_fn(na, nb, |i, j| {
            let (xi, xj) = (&a[i * d..(i + 1) * d], &b[j * d..(j + 1) * d]);
            let r2: f64 = xi.iter().zip(xj).zip(&inv_sq).map(|((p, q), w)| (p - q) * (p - q) * w).sum();
            self.outputscale * (-0.5 * r2).exp()
        })
    }
}
