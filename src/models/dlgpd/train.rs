//! DLGPD on the shared training loop: each step draws a batch of transitions, which is also the GPs'
//! training set, and takes one step of each of the authors' three Adams (VAE, transition GPs, reward GP;
//! Adam is elementwise, so one Adam over the GP vectors is the same). The GPs start from the first batch's
//! latents. A checkpoint's weights carry the latent standardization that planning freezes: the statistics of
//! the encoder's samples on (at most) 1024 training transitions, as the authors' planning code takes them.

use std::cell::{Cell, Ref, RefCell};

use burn::tensor::Device;
use rand::seq::index::sample;
use rand::Rng;
use rand_distr::StandardNormal;

use super::config::DlgpdConfig;
use super::data::{ObservationKind, Windows};
use super::evidence::{condition_on_rows, encoded_means};
use super::latent_gp::LatentScale;
use super::model::{
    init_hypers, loss_and_gradients, raw_gradient, raw_vector, sample_noise, set_raw_vector, Batch, Gradients,
    StepLoss, Weights,
};
use super::prediction::reward_errors;
use super::vae::{encode_rows, VaeNet};
use crate::error::{Error, Result};
use crate::models::gp::{GpHypers, HyperInit};
use crate::nn::params::NamedTensor;
use crate::nn::tensor::{inference_device, training_device};
use crate::nn::{Adam, AdamConfig, ParamSet};
use crate::train::tensors::TensorData;
use crate::train::{state, StoredTensor, TrainingMethod};
use crate::util::seeding::rng_for;

const INIT_STREAM: u64 = 1;
const BATCH_STREAM: u64 = 2;
const VALID_STREAM: u64 = 3;
const SCALE_STREAM: u64 = 4;
/// Training transitions the frozen standardization is measured on (the authors' one batch of 1024).
pub const SCALE_ROWS: usize = 1024;

pub const SCALE_MEAN: &str = "latent_scale.mean";
pub const SCALE_STD: &str = "latent_scale.std";
pub const REWARD_GP: &str = "reward_gp";
const GP_STATE_PREFIX: &str = "gp";
/// The GP optimizer's saved state is kept apart from the VAE's (both have an `adam.step`).
const GP_OPTIMIZER_PREFIX: &str = "gp_optimizer.";

pub fn transition_gp_name(d: usize) -> String {
    format!("transition_gp.{d}")
}

/// The GPs' hyperparameters with their optimizer.
struct Gps {
    transition: Vec<GpHypers>,
    reward: GpHypers,
    adam: Adam<f64>,
}

impl Gps {
    fn names(&self) -> Vec<String> {
        (0..self.transition.len()).map(transition_gp_name).chain([REWARD_GP.to_string()]).collect()
    }

    fn all(&self) -> impl Iterator<Item = &GpHypers> {
        self.transition.iter().chain(std::iter::once(&self.reward))
    }

    /// The raw vectors as a parameter set, for the optimizer's saved state.
    fn raw_params(&self) -> ParamSet<f64> {
        let tensors = self
            .names()
            .into_iter()
            .zip(self.all())
            .map(|(name, h)| {
                let values = raw_vector(h);
                NamedTensor { name: format!("{GP_STATE_PREFIX}.{name}"), shape: vec![values.len()], values }
            })
            .collect();
        ParamSet { tensors }
    }

    fn stored(&self, prefix: &str) -> Vec<StoredTensor> {
        self.names().iter().zip(self.all()).flat_map(|(name, h)| h.stored(&format!("{prefix}{name}"))).collect()
    }
}

fn gp_adam(config: &DlgpdConfig, sizes: &[usize]) -> Adam<f64> {
    Adam::new(adam_config(config.learning_rate), sizes)
}

fn adam_config(learning_rate: f64) -> AdamConfig {
    AdamConfig { learning_rate, beta1: 0.9, beta2: 0.999, epsilon: 1e-8, weight_decay: 0.0, clip_grad_norm: None }
}

/// The GPs stored under `prefix` (`transition_gp.0` …, `reward_gp`), over latent ⊕ action inputs.
pub fn gps_from_stored(
    tensors: &[StoredTensor],
    prefix: &str,
    latent_dim: usize,
    action_dim: usize,
) -> Result<(Vec<GpHypers>, GpHypers)> {
    let inputs = latent_dim + action_dim;
    let prior = HyperInit::dlgpd(inputs, 1.0).outputscale_prior;
    let transition = (0..latent_dim)
        .map(|d| GpHypers::from_stored(&format!("{prefix}{}", transition_gp_name(d)), tensors, inputs, prior))
        .collect::<Result<Vec<_>>>()?;
    let reward = GpHypers::from_stored(&format!("{prefix}{REWARD_GP}"), tensors, inputs, prior)?;
    Ok((transition, reward))
}

/// Rollouts on each side of the validation's reward-prediction check (evidence from training rollouts,
/// scored on held-out ones): 20, the evidence size of the thesis' planning runs.
const CHECK_ROLLOUTS: usize = 20;

/// The rows of the first `count` rollouts among `rows` (rows of a rollout are consecutive, in time order).
fn leading_rollouts(windows: &Windows, rows: &[usize], count: usize) -> Vec<usize> {
    let mut seen = 0;
    let mut last = None;
    rows.iter()
        .copied()
        .take_while(|&r| {
            let id = windows.rollout[r];
            if last != Some(id) {
                seen += 1;
                last = Some(id);
            }
            seen <= count
        })
        .collect()
}

pub struct DlgpdTrainer {
    config: DlgpdConfig,
    seed: u64,
    device: Device,
    /// The burn module encodes (validation, the frozen scale, the planner's check) and trains the angle VAE;
    /// `params` are the weights. The image VAE trains on `params` alone, so after each update the module is
    /// only marked stale and reloaded when next used: copying its 17 MB out and back in at every step cost
    /// about 15 ms of serial work per 0.5 s step on two threads at batch 256.
    vae: RefCell<Option<VaeNet>>,
    vae_is_stale: Cell<bool>,
    params: ParamSet<f32>,
    vae_adam: Adam<f32>,
    gps: Option<Gps>,
    windows: Windows,
    train_rows: Vec<usize>,
    valid_rows: Vec<usize>,
    last: Option<StepLoss>,
    /// The frozen standardization of the current weights: an improving validation needs it twice (the
    /// prediction check and the saved weights), and at image size it costs a thousand encodings.
    frozen_scale_of_weights: RefCell<Option<LatentScale>>,
}

impl DlgpdTrainer {
    pub fn new(
        config: DlgpdConfig,
        seed: u64,
        windows: Windows,
        train_rows: Vec<usize>,
        valid_rows: Vec<usize>,
    ) -> Result<Self> {
        config.validate()?;
        if train_rows.len() < 2 {
            return Err(Error::data(format!(
                "{} training transitions; DLGPD's GPs need a batch of at least 2",
                train_rows.len()
            )));
        }
        // The image VAE trains on its hand-written path; its burn module only encodes (validation, the frozen
        // scale). On the autodiff device every such pass through the weights would stay in burn's graph, which
        // only a backward pass clears, and none comes: a gigabyte at every validation.
        let device = match windows.kind {
            ObservationKind::Images { .. } => inference_device(),
            ObservationKind::Angles => training_device(),
        };
        let mut rng = rng_for(seed, &[INIT_STREAM]);
        let vae = VaeNet::init(windows.kind, config.latent_dim, config.hidden_units, &device, &mut rng)?;
        let params = vae.params();
        let sizes: Vec<usize> = params.tensors.iter().map(|t| t.values.len()).collect();
        let vae_adam = Adam::new(adam_config(config.learning_rate), &sizes);
        Ok(DlgpdTrainer {
            config,
            seed,
            device,
            vae: RefCell::new(Some(vae)),
            vae_is_stale: Cell::new(false),
            params,
            vae_adam,
            gps: None,
            windows,
            train_rows,
            valid_rows,
            last: None,
            frozen_scale_of_weights: RefCell::new(None),
        })
    }

    pub fn parameter_count(&self) -> usize {
        self.params.count()
    }

    /// The burn module with the current weights.
    fn vae(&self) -> Result<Ref<'_, VaeNet>> {
        const PRESENT: &str = "the VAE is only taken out while loading new weights";
        if self.vae_is_stale.get() {
            let mut slot = self.vae.borrow_mut();
            let vae = slot.take().expect(PRESENT);
            *slot = Some(vae.with_params(&self.params, &self.device)?);
            self.vae_is_stale.set(false);
        }
        Ok(Ref::map(self.vae.borrow(), |vae| vae.as_ref().expect(PRESENT)))
    }

    /// The loss of `batch` (and its gradients when wanted) at the current weights.
    fn loss(&self, gps: &Gps, batch: &Batch, noise: (&[f32], &[f32]), gradients: Gradients) -> Result<StepLoss> {
        let module;
        let weights = match self.windows.kind {
            ObservationKind::Images { .. } => Weights::Images(&self.params),
            ObservationKind::Angles => {
                module = self.vae()?;
                Weights::Angles(&module)
            }
        };
        loss_and_gradients(weights, &gps.transition, &gps.reward, batch, noise, gradients, &self.device)
    }

    fn batch(&self, rows: &[usize]) -> Batch {
        let (obs, next_obs) = self.windows.observations(rows);
        let (actions, rewards) = self.windows.actions_and_rewards(rows);
        Batch { rows: rows.len(), obs, next_obs, actions, rewards }
    }

    /// Reparameterized samples of the encoder at `obs` with standard-normal `noise`.
    fn samples(&self, obs: &[f32], noise: &[f32]) -> Result<Vec<f64>> {
        let (mean, std) = encode_rows(&*self.vae()?, obs, self.windows.kind.input_len(), &self.device);
        Ok(mean.iter().zip(&std).zip(noise).map(|((m, s), e)| (m + s * e) as f64).collect())
    }

    /// The GPs' starting point from the first batch, as the authors' first `set_train_data` does.
    fn init_gps(&self, batch: &Batch, noise: (&[f32], &[f32])) -> Result<Gps> {
        let latents = self.samples(&batch.obs, noise.0)?;
        let next = self.samples(&batch.next_obs, noise.1)?;
        let (transition, reward) = init_hypers(&latents, &next, &batch.rewards, self.windows.action_dim)?;
        let sizes: Vec<usize> = transition.iter().chain([&reward]).map(|h| raw_vector(h).len()).collect();
        Ok(Gps { transition, reward, adam: gp_adam(&self.config, &sizes) })
    }

    /// The standardization planning freezes: mean and std (+0.01) of encoder samples on training transitions.
    pub fn frozen_scale(&self) -> Result<LatentScale> {
        if let Some(scale) = self.frozen_scale_of_weights.borrow().as_ref() {
            return Ok(scale.clone());
        }
        let scale = self.compute_frozen_scale()?;
        *self.frozen_scale_of_weights.borrow_mut() = Some(scale.clone());
        Ok(scale)
    }

    fn compute_frozen_scale(&self) -> Result<LatentScale> {
        let mut rng = rng_for(self.seed, &[SCALE_STREAM]);
        let count = self.train_rows.len().min(SCALE_ROWS);
        let rows: Vec<usize> =
            sample(&mut rng, self.train_rows.len(), count).into_iter().map(|i| self.train_rows[i]).collect();
        let (obs, _) = self.windows.observations(&rows);
        let noise: Vec<f32> =
            (0..count * self.config.latent_dim).map(|_| rng.sample::<f32, _>(StandardNormal)).collect();
        LatentScale::of(&self.samples(&obs, &noise)?, self.config.latent_dim)
    }
}

impl TrainingMethod for DlgpdTrainer {
    fn step(&mut self, step: u64) -> Result<f64> {
        let mut rng = rng_for(self.seed, &[BATCH_STREAM, step]);
        let n = self.train_rows.len();
        let rows: Vec<usize> =
            sample(&mut rng, n, self.config.batch_size.min(n)).into_iter().map(|i| self.train_rows[i]).collect();
        let batch = self.batch(&rows);
        let noise = sample_noise(batch.rows, self.config.latent_dim, &mut rng);
        if self.gps.is_none() {
            self.gps = Some(self.init_gps(&batch, (&noise.0, &noise.1))?);
        }
        let gps = self.gps.as_ref().expect("initialized above");
        let mut loss = self.loss(gps, &batch, (&noise.0, &noise.1), Gradients::Wanted)?;
        let mut vae_grads = std::mem::take(&mut loss.vae_gradients);
        *self.frozen_scale_of_weights.get_mut() = None;
        self.vae_adam.update(&mut self.params.values_mut(), &mut vae_grads)?;
        self.vae_is_stale.set(true);
        let gps = self.gps.as_mut().expect("initialized above");
        let mut raw: Vec<Vec<f64>> = gps.all().map(raw_vector).collect();
        let mut grads: Vec<Vec<f64>> = loss.gp.d_hypers.iter().map(raw_gradient).collect();
        gps.adam.update(&mut raw.iter_mut().collect::<Vec<_>>(), &mut grads)?;
        let latent = gps.transition.len();
        for (k, v) in raw.iter().enumerate() {
            let h = if k < latent { &mut gps.transition[k] } else { &mut gps.reward };
            set_raw_vector(h, v);
        }
        let total = loss.total;
        self.last = Some(loss);
        Ok(total)
    }

    fn validate(&mut self) -> Result<Option<f64>> {
        let count = self.valid_rows.len().min(self.config.batch_size);
        let Some(gps) = self.gps.as_ref().filter(|_| count >= 2) else {
            return Ok(None);
        };
        let batch = self.batch(&self.valid_rows[..count]);
        let noise = sample_noise(count, self.config.latent_dim, &mut rng_for(self.seed, &[VALID_STREAM]));
        let loss = self.loss(gps, &batch, (&noise.0, &noise.1), Gradients::NotWanted)?;
        Ok(Some(loss.total))
    }

    /// The planner's view of the model: the GPs as trained, conditioned on the first training rollouts
    /// (encoder means, frozen standardization, as `plan` conditions them), predict the rewards of the first
    /// held-out rollouts open loop. A falling loss with a flat prediction error means a latent that the GPs
    /// cannot roll forward.
    fn validation_scalars(&mut self) -> Result<Vec<(&'static str, f64)>> {
        let evidence_rows = leading_rollouts(&self.windows, &self.train_rows, CHECK_ROLLOUTS);
        let scored_rows = leading_rollouts(&self.windows, &self.valid_rows, CHECK_ROLLOUTS);
        let Some(gps) = self.gps.as_ref().filter(|_| !evidence_rows.is_empty() && !scored_rows.is_empty()) else {
            return Ok(Vec::new());
        };
        let scale = self.frozen_scale()?;
        let vae = self.vae()?;
        let dynamics = condition_on_rows(&vae, (&gps.transition, &gps.reward), scale, &self.windows, &evidence_rows)?;
        let latents = encoded_means(&vae, &self.windows, &scored_rows)?;
        let errors = reward_errors(&dynamics, &self.windows, &scored_rows, &latents)?;
        let at = |h: usize| errors.open_loop_rmse.get(h).copied().unwrap_or(f64::NAN);
        Ok(vec![
            ("valid/reward_rmse_encoded", errors.encoded_rmse),
            ("valid/reward_rmse_h5", at(5)),
            ("valid/reward_rmse_h10", at(10)),
            ("valid/reward_rmse_constant", errors.constant_rmse),
        ])
    }

    fn weights(&self) -> Vec<StoredTensor> {
        let mut out = state::weights(&self.params);
        if let Some(gps) = &self.gps {
            out.extend(gps.stored(""));
        }
        // Only a degenerate encoder (every sample alike) has no scale; loading such a checkpoint then names it.
        if let Ok(scale) = self.frozen_scale() {
            let d = scale.mean.len();
            out.push(StoredTensor::f64(SCALE_MEAN, vec![d], scale.mean));
            out.push(StoredTensor::f64(SCALE_STD, vec![d], scale.std));
        }
        out
    }

    fn state(&self) -> Vec<StoredTensor> {
        let mut out = state::save(&self.params, &self.vae_adam);
        if let Some(gps) = &self.gps {
            out.extend(gps.stored("live."));
            out.extend(state::save(&gps.raw_params(), &gps.adam).into_iter().map(|mut t| {
                t.name = format!("{GP_OPTIMIZER_PREFIX}{}", t.name);
                t
            }));
        }
        out
    }

    fn restore(&mut self, saved: &[StoredTensor]) -> Result<()> {
        state::restore(saved, &mut self.params, &mut self.vae_adam)?;
        *self.frozen_scale_of_weights.get_mut() = None;
        self.vae_is_stale.set(true);
        let has_gps = saved.iter().any(|t| t.name.starts_with(&format!("live.{REWARD_GP}.")));
        self.gps = if has_gps {
            let (transition, reward) =
                gps_from_stored(saved, "live.", self.config.latent_dim, self.windows.action_dim)?;
            let sizes: Vec<usize> = transition.iter().chain([&reward]).map(|h| raw_vector(h).len()).collect();
            let mut gps = Gps { transition, reward, adam: gp_adam(&self.config, &sizes) };
            let mut raw = gps.raw_params();
            let optimizer: Vec<StoredTensor> = saved
                .iter()
                .filter_map(|t| {
                    let name = t.name.strip_prefix(GP_OPTIMIZER_PREFIX)?;
                    Some(StoredTensor { name: name.to_string(), ..t.clone() })
                })
                .collect();
            state::restore(&optimizer, &mut raw, &mut gps.adam)?;
            Some(gps)
        } else {
            None
        };
        Ok(())
    }

    fn step_scalars(&self) -> Vec<(&'static str, f64)> {
        let Some(l) = &self.last else {
            return Vec::new();
        };
        let mut scalars = vec![
            ("dlgpd/reconstruction", l.reconstruction),
            ("dlgpd/entropy", l.entropy),
            ("dlgpd/transition_gp_nll", l.gp.transition),
            ("dlgpd/reward_gp_nll", l.gp.reward),
            ("dlgpd/snr_penalty", l.gp.snr),
        ];
        if let Some(gps) = &self.gps {
            scalars.push(("dlgpd/action_lengthscale", shortest_action_lengthscale(&gps.transition)));
        }
        scalars
    }
}

/// The shortest lengthscale any transition GP has on an action input (inputs are [standardized latent, raw
/// action]; actions span [−2, 2]). Far above that span, no latent dimension's predicted next value depends on
/// the action, and a planner on the model has nothing to choose between.
fn shortest_action_lengthscale(transition: &[GpHypers]) -> f64 {
    transition
        .iter()
        .flat_map(|gp| {
            let lengthscales = gp.kernel().lengthscales;
            let latent = transition.len();
            lengthscales.into_iter().skip(latent)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether `stored` holds a tensor of f64 values named `name` with `len` entries.
pub fn f64_tensor<'a>(stored: &'a [StoredTensor], name: &str, len: usize) -> Option<&'a Vec<f64>> {
    match stored.iter().find(|t| t.name == name).map(|t| &t.data) {
        Some(TensorData::F64(v)) if v.len() == len && v.iter().all(|x| x.is_finite()) => Some(v),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::collect::{collect_random, CollectSettings};
    use crate::envs::parse_env;
    use crate::models::dlgpd::config::Preset;
    use crate::models::dlgpd::data::ObservationKind;
    use crate::run::NullMonitor;

    fn trainer(config: &DlgpdConfig) -> DlgpdTrainer {
        let settings = CollectSettings {
            env: parse_env("pendulum").unwrap(),
            rollouts: 12,
            steps: 10,
            seed: 3,
            command_line: "test".into(),
        };
        let data = collect_random(&settings, &NullMonitor).unwrap();
        let windows = Windows::from_dataset(&data, ObservationKind::Angles, 3).unwrap();
        let valid = windows.rows_where(|r| r < 2);
        let train = windows.rows_where(|r| r >= 2);
        DlgpdTrainer::new(config.clone(), 9, windows, train, valid).unwrap()
    }

    fn config() -> DlgpdConfig {
        DlgpdConfig { batch_size: 32, ..DlgpdConfig::preset(Preset::Small) }
    }

    #[test]
    fn steps_lower_the_validation_loss_and_a_restored_state_continues_identically() {
        let config = config();
        let mut a = trainer(&config);
        assert_eq!(a.validate().unwrap(), None, "no GPs before the first step");
        a.step(1).unwrap();
        let first = a.validate().unwrap().unwrap();
        for step in 2..=150 {
            assert!(a.step(step).unwrap().is_finite());
        }
        let later = a.validate().unwrap().unwrap();
        assert!(later < first, "validation loss {first} → {later}");
        let names: Vec<String> = a.weights().into_iter().map(|t| t.name).collect();
        for wanted in ["encoder.hidden1.weight", SCALE_MEAN, "transition_gp.2.covar_module.raw_outputscale"] {
            assert!(names.iter().any(|n| n == wanted), "{wanted} missing from {names:?}");
        }
        crate::train::tensors::to_bytes(&a.state()).unwrap();

        let mut b = trainer(&config);
        b.restore(&a.state()).unwrap();
        for step in 151..=155 {
            assert_eq!(a.step(step).unwrap(), b.step(step).unwrap(), "step {step}");
        }
        assert_eq!(a.weights(), b.weights());
    }

    #[test]
    fn validation_scores_the_planners_view_once_there_are_gps() {
        let mut t = trainer(&config());
        assert!(t.validation_scalars().unwrap().is_empty(), "no GPs before the first step");
        for step in 1..=150 {
            t.step(step).unwrap();
        }
        let scalars = t.validation_scalars().unwrap();
        let names: Vec<&str> = scalars.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "valid/reward_rmse_encoded",
                "valid/reward_rmse_h5",
                "valid/reward_rmse_h10",
                "valid/reward_rmse_constant"
            ]
        );
        // Two held-out rollouts of 10 steps have 9 windows each: open-loop errors up to h = 8 only, so no
        // 10-step figure (the training loop leaves non-finite figures out of the log).
        assert!(scalars[3].1 > 0.0 && scalars[..2].iter().all(|(_, v)| v.is_finite() && *v >= 0.0), "{scalars:?}");
        assert!(scalars[2].1.is_nan(), "{scalars:?}");
        let t2 = trainer(&config());
        assert_eq!(leading_rollouts(&t2.windows, &t2.valid_rows, 1).len(), 9);
        assert_eq!(leading_rollouts(&t2.windows, &t2.valid_rows, 20), t2.valid_rows);
    }

    #[test]
    fn the_stored_gps_load_back_with_their_bounds() {
        let mut t = trainer(&config());
        t.step(1).unwrap();
        let (transition, reward) = gps_from_stored(&t.weights(), "", 3, 1).unwrap();
        let gps = t.gps.as_ref().unwrap();
        assert_eq!(transition, gps.transition);
        assert_eq!(reward, gps.reward);
    }
}
