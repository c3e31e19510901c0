//! One DLGPD training step's loss and gradients: encode both observations, sample the latents, decode the
//! next observation, add the GP terms (f64, outside the graph) through gradient injection, and backpropagate
//! into the VAE; the GP hyperparameters get their gradients from the GP terms directly.

use burn::tensor::{Device, Tensor};
use rand::Rng;
use rand_distr::StandardNormal;

use super::grad::images_loss_and_gradients;
use super::latent_gp::{gp_terms, GpTerms, LatentScale};
use super::loss::{entropy_term, injected};
use super::vae::VaeNet;
use crate::error::{Error, Result};
use crate::models::gp::{GpHypers, HyperInit, ObjectiveGradients};
use crate::nn::tensor::{scalar, tensor, values};
use crate::nn::ParamSet;

/// A batch of transitions: observations and next observations as rows of the VAE's input (for images
/// [rows, 6, side, side] flattened), actions [rows, A], rewards [rows].
pub struct Batch {
    pub rows: usize,
    pub obs: Vec<f32>,
    pub next_obs: Vec<f32>,
    pub actions: Vec<f64>,
    pub rewards: Vec<f64>,
}

#[derive(Debug)]
pub struct StepLoss {
    pub total: f64,
    pub reconstruction: f64,
    pub entropy: f64,
    pub gp: GpTerms,
    /// In the order of `VaeNet::params`; empty when gradients were not asked for.
    pub vae_gradients: Vec<Vec<f32>>,
}

/// The GPs' starting hyperparameters from the first batch's encoded latents (the authors initialize on the
/// first `set_train_data`): each transition GP from the variance of its standardized next latent, the reward
/// GP from the variance of the rewards.
pub fn init_hypers(
    latents: &[f64],
    next_latents: &[f64],
    rewards: &[f64],
    action_dim: usize,
) -> Result<(Vec<GpHypers>, GpHypers)> {
    let dims = latents.len() / rewards.len().max(1);
    let scale = LatentScale::of(latents, dims)?;
    let variance = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1).max(1) as f64
    };
    let transition = (0..dims)
        .map(|d| {
            let scaled: Vec<f64> =
                (0..rewards.len()).map(|b| (next_latents[b * dims + d] - scale.mean[d]) / scale.std[d]).collect();
            GpHypers::new(&HyperInit::dlgpd(dims + action_dim, variance(&scaled)))
        })
        .collect::<Result<Vec<_>>>()?;
    let reward = GpHypers::new(&HyperInit::dlgpd(dims + action_dim, variance(rewards)))
        .map_err(|e| Error::data(format!("{e} (the first batch's rewards must vary to start the reward GP)")))?;
    Ok((transition, reward))
}

/// Standard-normal noise for the reparameterized samples of a batch: current, then next latents.
pub fn sample_noise<R: Rng + ?Sized>(rows: usize, latent: usize, rng: &mut R) -> (Vec<f32>, Vec<f32>) {
    let mut draw = || (0..rows * latent).map(|_| rng.sample::<f32, _>(StandardNormal)).collect::<Vec<f32>>();
    let current = draw();
    (current, draw())
}

/// Whether a loss evaluation also backpropagates (training) or not (validation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gradients {
    Wanted,
    NotWanted,
}

/// The VAE a loss is taken with, as each path reads it.
#[derive(Clone, Copy)]
pub enum Weights<'a> {
    /// The image VAE's parameters, which its hand-written path (`grad.rs`) reads in place: a trainer keeps
    /// them outside the burn module, which need not be reloaded after every update.
    Images(&'a ParamSet<f32>),
    /// The angle VAE's burn module, which trains through burn's autodiff.
    Angles(&'a VaeNet),
}

/// Loss (and, when wanted, gradients) of one batch. `noise` = the standard-normal draws of the current and
/// next latents.
pub fn loss_and_gradients(
    weights: Weights<'_>,
    transition: &[GpHypers],
    reward: &GpHypers,
    batch: &Batch,
    noise: (&[f32], &[f32]),
    gradients: Gradients,
    device: &Device,
) -> Result<StepLoss> {
    match weights {
        Weights::Images(params) => images_loss_and_gradients(params, transition, reward, batch, noise, gradients),
        Weights::Angles(vae) => burn_loss_and_gradients(vae, transition, reward, batch, noise, gradients, device),
    }
}

/// [`loss_and_gradients`] through burn's autodiff, for either VAE: the angle VAE's path and the image VAE's
/// reference.
pub fn burn_loss_and_gradients(
    vae: &VaeNet,
    transition: &[GpHypers],
    reward: &GpHypers,
    batch: &Batch,
    noise: (&[f32], &[f32]),
    gradients: Gradients,
    device: &Device,
) -> Result<StepLoss> {
    let latent = transition.len();
    let width = batch.obs.len() / batch.rows.max(1);
    let obs: Tensor<2> = tensor(batch.obs.clone(), [batch.rows, width], device);
    let next: Tensor<2> = tensor(batch.next_obs.clone(), [batch.rows, width], device);
    let (mean, std) = vae.encode(obs);
    let (next_mean, next_std) = vae.encode(next.clone());
    let eps = tensor(noise.0.to_vec(), [batch.rows, latent], device);
    let next_eps = tensor(noise.1.to_vec(), [batch.rows, latent], device);
    let sample = mean + std * eps;
    let next_sample = next_mean + next_std.clone() * next_eps;
    let reconstruction = vae.reconstruction(next_sample.clone(), next);
    let entropy = entropy_term(next_std);
    let as_f64 = |t: &Tensor<2>| values(t).into_iter().map(f64::from).collect::<Vec<f64>>();
    let (s, s_next) = (as_f64(&sample), as_f64(&next_sample));
    let gp = gp_terms(transition, reward, &s, &batch.actions, &s_next, &batch.rewards)?;
    let gp_loss = injected(sample, &gp.d_latents, 0.0) + injected(next_sample, &gp.d_next_latents, gp.value);
    let (reconstruction_value, entropy_value) = (scalar(&reconstruction), scalar(&entropy));
    let loss = reconstruction + entropy + gp_loss;
    let total = scalar(&loss);
    if !total.is_finite() {
        return Err(Error::diverged(format!(
            "DLGPD loss is {total} (reconstruction {reconstruction_value}, entropy {entropy_value}, GP {})",
            gp.value
        )));
    }
    let vae_gradients = match gradients {
        Gradients::Wanted => vae.gradients(&loss.backward()),
        Gradients::NotWanted => Vec::new(),
    };
    Ok(StepLoss { total, reconstruction: reconstruction_value, entropy: entropy_value, gp, vae_gradients })
}

/// A GP's raw hyperparameters as one flat vector for the optimizer (lengthscales, outputscale, noise), and
/// the matching gradient.
pub fn raw_vector(h: &GpHypers) -> Vec<f64> {
    let mut v = h.raw_lengthscales.clone();
    v.extend([h.raw_outputscale, h.raw_noise]);
    v
}

pub fn raw_gradient(g: &ObjectiveGradients) -> Vec<f64> {
    let mut v = g.raw_lengthscales.clone();
    v.extend([g.raw_outputscale, g.raw_noise]);
    v
}

pub fn set_raw_vector(h: &mut GpHypers, v: &[f64]) {
    let d = h.raw_lengthscales.len();
    h.raw_lengthscales.copy_from_slice(&v[..d]);
    h.raw_outputscale = v[d];
    h.raw_noise = v[d + 1];
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::models::dlgpd::data::tests::rendered_pendulum;
    use crate::models::dlgpd::data::{ObservationKind, Windows};
    use crate::nn::tensor::training_device;
    use crate::nn::{Adam, AdamConfig};

    #[test]
    fn a_few_adam_steps_lower_the_loss_on_one_batch() {
        let data = rendered_pendulum(4, 5, 2);
        let kind = ObservationKind::Images { side: 64 };
        let frames = Windows::from_dataset(&data, kind, 0).unwrap();
        let rows: Vec<usize> = (0..frames.len()).collect();
        let (obs, next_obs) = frames.observations(&rows);
        let (actions, rewards) = frames.actions_and_rewards(&rows);
        let batch = Batch { rows: rows.len(), obs, next_obs, actions, rewards };
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let vae = VaeNet::init(kind, 3, 0, &device, &mut rng).unwrap();
        let mut params = vae.params();
        let sizes: Vec<usize> = params.tensors.iter().map(|t| t.values.len()).collect();
        let adam_config = |lr| AdamConfig {
            learning_rate: lr,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-8,
            weight_decay: 0.0,
            clip_grad_norm: None,
        };
        let mut vae_adam = Adam::<f32>::new(adam_config(1e-3), &sizes);
        // Fixed noise, so the loss changes only through the parameters.
        let noise = sample_noise(batch.rows, 3, &mut rng);
        let first = {
            let width = kind.input_len();
            let (mean, _) = vae.encode(tensor(batch.obs.clone(), [batch.rows, width], &device));
            let (next_mean, _) = vae.encode(tensor(batch.next_obs.clone(), [batch.rows, width], &device));
            let f = |t: Tensor<2>| values(&t).into_iter().map(f64::from).collect::<Vec<f64>>();
            init_hypers(&f(mean), &f(next_mean), &batch.rewards, 1).unwrap()
        };
        let (mut transition, mut reward) = first;
        let mut gp_adams: Vec<Adam<f64>> =
            (0..4).map(|_| Adam::<f64>::new(adam_config(1e-2), &[raw_vector(&reward).len()])).collect();
        let mut losses = Vec::new();
        for _ in 0..8 {
            let step = loss_and_gradients(
                Weights::Images(&params),
                &transition,
                &reward,
                &batch,
                (&noise.0, &noise.1),
                Gradients::Wanted,
                &device,
            )
            .unwrap();
            losses.push(step.total);
            let mut grads = step.vae_gradients;
            vae_adam.update(&mut params.values_mut(), &mut grads).unwrap();
            for (k, g) in step.gp.d_hypers.iter().enumerate() {
                let h = if k < 3 { &mut transition[k] } else { &mut reward };
                let mut v = raw_vector(h);
                gp_adams[k].update(&mut [&mut v], &mut [raw_gradient(g)]).unwrap();
                set_raw_vector(h, &v);
            }
        }
        assert!(losses.iter().all(|l| l.is_finite()), "{losses:?}");
        assert!(losses[7] < losses[0], "loss should fall on a fixed batch: {losses:?}");
    }
}
