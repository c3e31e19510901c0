//! Adam with PyTorch's update rule and every hyperparameter explicit, plus global gradient-norm clipping as
//! torch.nn.utils.clip_grad_norm_ does it. The moments live in plain buffers so a checkpoint holds them and
//! `--resume` continues bit for bit. (burn's own Adam defaults ε to 1e-5 and clips each tensor on its own.)

use num_traits::Float;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::util::domain::number;
use crate::util::wide::widest_fn;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdamConfig {
    pub learning_rate: f64,
    pub beta1: f64,
    pub beta2: f64,
    pub epsilon: f64,
    /// L2 penalty added to the gradient (torch.optim.Adam's `weight_decay`, not AdamW's decoupled decay).
    pub weight_decay: f64,
    /// Scale all gradients together so their global L2 norm is at most this; `None` = no clipping.
    pub clip_grad_norm: Option<f64>,
}

impl AdamConfig {
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(format!("optimizer: {m}")));
        // Every method here trains with rates of 1e-4 to 1e-2; past 1 an f32 update overshoots any weight, and
        // 1e300 is infinity in f32.
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0 && self.learning_rate <= 1.0) {
            return bad(format!("learning_rate must lie in (0, 1], got {}", number(self.learning_rate)));
        }
        for (name, beta) in [("beta1", self.beta1), ("beta2", self.beta2)] {
            if !(0.0..1.0).contains(&beta) {
                return bad(format!("{name} must lie in [0, 1), got {beta}"));
            }
        }
        // ε guards a division by √v̂; beyond 1 it would swamp every gradient's scale.
        if !(self.epsilon.is_finite() && self.epsilon > 0.0 && self.epsilon <= 1.0) {
            return bad(format!("epsilon must lie in (0, 1], got {}", number(self.epsilon)));
        }
        // An L2 penalty of 1 already pulls every weight to zero faster than any loss pushes it away.
        if !(self.weight_decay.is_finite() && (0.0..=1.0).contains(&self.weight_decay)) {
            return bad(format!("weight_decay must lie in [0, 1], got {}", number(self.weight_decay)));
        }
        if let Some(c) = self.clip_grad_norm {
            if !(c.is_finite() && c > 0.0 && c <= 1e12) {
                return bad(format!("clip_grad_norm must lie in (0, 1e12], got {}", number(c)));
            }
        }
        Ok(())
    }
}

/// Elements per parallel task of the update.
const UPDATE_BLOCK: usize = 1 << 14;

/// Optimizer state for a list of parameter buffers.
#[derive(Clone, Debug, PartialEq)]
pub struct Adam<T> {
    pub config: AdamConfig,
    /// Updates applied so far (torch's `step`).
    pub step: u64,
    pub exp_avg: Vec<Vec<T>>,
    pub exp_avg_sq: Vec<Vec<T>>,
}

impl<T: Float + Send + Sync> Adam<T> {
    pub fn new(config: AdamConfig, sizes: &[usize]) -> Self {
        Adam {
            config,
            step: 0,
            exp_avg: sizes.iter().map(|&n| vec![T::zero(); n]).collect(),
            exp_avg_sq: sizes.iter().map(|&n| vec![T::zero(); n]).collect(),
        }
    }

    fn cast(x: f64) -> T {
        T::from(x).unwrap_or_else(T::nan)
    }

    /// One update of `params` with `grads` (consumed: clipped and decayed in place). With clipping configured,
    /// returns the global gradient norm before clipping; without, the norm is not computed (a sequential sum over
    /// every gradient would cost a fused training step a tenth of its time) and `None` is returned.
    pub fn update(&mut self, params: &mut [&mut Vec<T>], grads: &mut [Vec<T>]) -> Result<Option<f64>> {
        if params.len() != self.exp_avg.len() || grads.len() != params.len() {
            return Err(Error::config(format!(
                "optimizer holds {} tensors, got {} parameters and {} gradients",
                self.exp_avg.len(),
                params.len(),
                grads.len()
            )));
        }
        let mut norm = None;
        if let Some(max_norm) = self.config.clip_grad_norm {
            let total = grads.iter().flatten().fold(T::zero(), |acc, g| acc + *g * *g).sqrt();
            let coef = Self::cast(max_norm) / (total + Self::cast(1e-6));
            if coef < T::one() {
                grads.iter_mut().flatten().for_each(|g| *g = *g * coef);
            }
            norm = Some(total.to_f64().unwrap_or(f64::NAN));
        }
        for (k, (p, g)) in params.iter().zip(grads.iter()).enumerate() {
            if p.len() != g.len() || p.len() != self.exp_avg[k].len() {
                return Err(Error::config(format!("optimizer tensor {k}: sizes of parameter and gradient differ")));
            }
        }
        let step = self.next_step();
        // Tensors update independently, element by element in one order: the bytes do not depend on threads.
        params
            .par_iter_mut()
            .zip(grads.par_iter())
            .zip(self.exp_avg.par_iter_mut().zip(self.exp_avg_sq.par_iter_mut()))
            .for_each(|((p, g), (m, v))| {
                // Blocks rather than whole tensors: a network's few large weights then spread over every thread.
                p.par_chunks_mut(UPDATE_BLOCK)
                    .zip(g.par_chunks(UPDATE_BLOCK))
                    .zip(m.par_chunks_mut(UPDATE_BLOCK).zip(v.par_chunks_mut(UPDATE_BLOCK)))
                    .for_each(|((p, g), (m, v))| step.apply(p, g, m, v));
            });
        Ok(norm)
    }

    /// Counts an update without clipping and returns its coefficients, for a training step that applies them
    /// to each block of parameters as soon as that block's gradient is ready (PETS). Refused when clipping is
    /// configured: the global norm needs every gradient first.
    pub fn begin_unclipped_update(&mut self) -> Result<AdamStep<T>> {
        if self.config.clip_grad_norm.is_some() {
            return Err(Error::config("optimizer: a block-wise update cannot clip the global gradient norm"));
        }
        Ok(self.next_step())
    }

    fn next_step(&mut self) -> AdamStep<T> {
        self.step += 1;
        let c = &self.config;
        let (beta1, beta2) = (Self::cast(c.beta1), Self::cast(c.beta2));
        let steps = self.step.min(i32::MAX as u64) as i32;
        let bias1 = T::one() - beta1.powi(steps);
        AdamStep {
            beta1,
            beta2,
            epsilon: Self::cast(c.epsilon),
            weight_decay: Self::cast(c.weight_decay),
            inverse_bias2_sqrt: T::one() / (T::one() - beta2.powi(steps)).sqrt(),
            step_size: Self::cast(c.learning_rate) / bias1,
        }
    }
}

/// One update's coefficients. Every element takes the same arithmetic wherever it is applied, so a step that
/// updates block by block gives the bytes of [`Adam::update`].
#[derive(Clone, Copy, Debug)]
pub struct AdamStep<T> {
    beta1: T,
    beta2: T,
    epsilon: T,
    weight_decay: T,
    /// 1 / √(1 − β₂ᵗ): a multiply per element where torch divides (a vector division costs more than the
    /// rest of the update); the two differ in the last bit at most.
    inverse_bias2_sqrt: T,
    step_size: T,
}

impl<T: Float> AdamStep<T> {
    /// Updates parameters `p` with gradients `g` and their moments `m`, `v` (all the same length).
    pub fn apply(&self, p: &mut [T], g: &[T], m: &mut [T], v: &mut [T]) {
        apply_widest(self, p, g, m, v);
    }

    #[inline(always)]
    fn apply_here(&self, p: &mut [T], g: &[T], m: &mut [T], v: &mut [T]) {
        debug_assert!(g.len() == p.len() && m.len() == p.len() && v.len() == p.len(), "Adam: block sizes differ");
        let AdamStep { beta1, beta2, epsilon, weight_decay, inverse_bias2_sqrt, step_size } = *self;
        // Zipped slices rather than indices: without bounds checks the loop vectorizes.
        let step = |p: &mut T, grad: T, m: &mut T, v: &mut T| {
            *m = beta1 * *m + (T::one() - beta1) * grad;
            *v = beta2 * *v + (T::one() - beta2) * grad * grad;
            let denom = v.sqrt() * inverse_bias2_sqrt + epsilon;
            *p = *p - step_size * *m / denom;
        };
        let each = p.iter_mut().zip(g.iter()).zip(m.iter_mut().zip(v.iter_mut()));
        if weight_decay > T::zero() {
            each.for_each(|((p, &g), (m, v))| step(p, g + weight_decay * *p, m, v));
        } else {
            each.for_each(|((p, &g), (m, v))| step(p, g, m, v));
        }
    }
}

widest_fn! {
    fn apply_widest[T: Float](step: &AdamStep<T>, p: &mut [T], g: &[T], m: &mut [T], v: &mut [T]) {
        step.apply_here(p, g, m, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> AdamConfig {
        AdamConfig {
            learning_rate: 0.1,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-8,
            weight_decay: 0.0,
            clip_grad_norm: None,
        }
    }

    /// 1e300 is a finite f64 but infinity as the f32 the networks update with.
    #[test]
    fn absurd_settings_are_refused_with_their_range() {
        let refused = |change: fn(&mut AdamConfig), expected: &str| {
            let mut c = config();
            change(&mut c);
            let err = c.validate().unwrap_err().to_string();
            assert!(err.contains(expected), "{err}");
        };
        refused(|c| c.learning_rate = 1e300, "learning_rate must lie in (0, 1], got 1e300");
        refused(|c| c.epsilon = 5.0, "epsilon must lie in (0, 1]");
        refused(|c| c.weight_decay = 1e19, "weight_decay must lie in [0, 1]");
        refused(|c| c.clip_grad_norm = Some(1e300), "clip_grad_norm must lie in (0, 1e12]");
        config().validate().unwrap();
    }

    #[test]
    fn first_step_moves_each_parameter_by_the_learning_rate() {
        // With bias correction, Adam's first step is lr · sign(g) (up to ε).
        let mut adam = Adam::<f64>::new(config(), &[2]);
        let mut p = vec![1.0, -1.0];
        let mut g = vec![vec![0.5, -3.0]];
        adam.update(&mut [&mut p], &mut g).unwrap();
        assert!((p[0] - 0.9).abs() < 1e-6 && (p[1] + 0.9).abs() < 1e-6, "{p:?}");
    }

    /// The update compiled for the CPU's widest vectors gives the bits of one element at a time.
    #[test]
    fn every_vector_width_gives_the_same_bits() {
        let mut adam = Adam::<f32>::new(AdamConfig { weight_decay: 1e-4, ..config() }, &[1001]);
        let params: Vec<f32> = (0..1001).map(|i| (i as f32 * 0.61).cos()).collect();
        let grads: Vec<f32> = (0..1001).map(|i| (i as f32 * 0.37).sin() * 1e-3).collect();
        adam.exp_avg_sq[0].iter_mut().enumerate().for_each(|(i, v)| *v = i as f32 * 1e-7);
        let step = adam.begin_unclipped_update().unwrap();
        let (mut p, mut m, mut v) = (params.clone(), adam.exp_avg[0].clone(), adam.exp_avg_sq[0].clone());
        step.apply(&mut p, &grads, &mut m, &mut v);
        let (mut p1, mut m1, mut v1) = (params, adam.exp_avg[0].clone(), adam.exp_avg_sq[0].clone());
        for i in 0..p1.len() {
            let one = i..i + 1;
            step.apply_here(&mut p1[one.clone()], &grads[one.clone()], &mut m1[one.clone()], &mut v1[one]);
        }
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!((bits(&p), bits(&m), bits(&v)), (bits(&p1), bits(&m1), bits(&v1)));
    }

    #[test]
    fn minimizes_a_quadratic() {
        let mut adam = Adam::<f32>::new(config(), &[3]);
        let mut p = vec![3.0f32, -2.0, 0.5];
        for _ in 0..500 {
            let mut g = vec![p.iter().map(|x| 2.0 * x).collect::<Vec<_>>()];
            adam.update(&mut [&mut p], &mut g).unwrap();
        }
        assert!(p.iter().all(|x| x.abs() < 1e-2), "{p:?}");
    }

    #[test]
    fn clipping_scales_the_global_norm() {
        let mut cfg = config();
        cfg.clip_grad_norm = Some(1.0);
        let mut adam = Adam::<f64>::new(cfg, &[1, 1]);
        let (mut a, mut b) = (vec![0.0], vec![0.0]);
        let mut g = vec![vec![3.0], vec![4.0]];
        let norm = adam.update(&mut [&mut a, &mut b], &mut g).unwrap();
        assert!((norm.expect("clipping computes the norm") - 5.0).abs() < 1e-12);
        assert!((g[0][0] - 0.6).abs() < 1e-6 && (g[1][0] - 0.8).abs() < 1e-6, "{g:?}");
    }

    #[test]
    fn bad_hyperparameters_are_rejected() {
        let mut cfg = config();
        cfg.beta2 = 1.0;
        assert!(cfg.validate().is_err());
        cfg = config();
        cfg.clip_grad_norm = Some(f64::NAN);
        assert!(cfg.validate().is_err());
    }
}
