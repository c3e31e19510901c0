//! The ball EKF's training as a [`TrainingMethod`] of the shared loop: checkpoints, `--resume`, progress and
//! divergence handling come from `train::fit`; this file only says how one Adam step on eq. 6.24 goes.

use burn::tensor::Device;
use rand::seq::SliceRandom;
use rayon::prelude::*;

use super::batch::Batch;
use super::chunks::{cut_chunks, Chunk};
use super::device::training_device;
use super::filter::chunk_loss;
use super::params::BallParamsModule;
use super::spin_net::{SpinNet, SpinNetWeights};
use super::train::TrainSettings;
use crate::data::ball_io::Recording;
use crate::error::{Error, Result};
use crate::models::ball::{BallModelParams, BallPhysics};
use crate::nn::params::ParamSet;
use crate::nn::Adam;
use crate::train::{state, StoredTensor, TrainingMethod};
use crate::util::seeding::rng_for;

/// Random streams under the seed: one per epoch's shuffle, one for the spin network's initial weights.
const SHUFFLE_STREAM: u64 = 0;
const SPIN_NET_STREAM: u64 = 1;

pub struct BallEkfTrainer {
    settings: TrainSettings,
    device: Device,
    module: Option<BallParamsModule>,
    params: ParamSet<f64>,
    adam: Adam<f64>,
    chunks: Vec<Chunk>,
}

impl BallEkfTrainer {
    pub fn new(recordings: &[Recording], settings: &TrainSettings) -> Result<Self> {
        settings.validate()?;
        let chunks = cut_chunks(recordings, settings.chunk_len, &settings.initial.physics)?;
        if chunks.is_empty() {
            return Err(Error::data(format!(
                "no training chunks in {} recordings: a chunk needs {} consecutive frames whose first two are measured",
                recordings.len(),
                settings.chunk_len
            )));
        }
        let device = training_device();
        let spin_net =
            settings.launcher_prior.then(|| SpinNet::init(&mut rng_for(settings.seed, &[SPIN_NET_STREAM]), &device));
        let module = BallParamsModule::from_params(&settings.initial, spin_net, &device);
        let params = ParamSet::<f64>::from_module(&module, |p| p.to_string());
        let sizes: Vec<usize> = params.tensors.iter().map(|t| t.values.len()).collect();
        let adam = Adam::new(settings.optimizer(), &sizes);
        Ok(BallEkfTrainer { settings: settings.clone(), device, module: Some(module), params, adam, chunks })
    }

    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    fn module(&self) -> &BallParamsModule {
        self.module.as_ref().expect("the module is only taken out while loading new values")
    }

    /// The current parameters for the nalgebra filter, and the launcher network when it is learned.
    pub fn current(&self) -> (BallModelParams, Option<SpinNetWeights>) {
        let module = self.module();
        (module.to_params(&self.settings.initial.physics), module.spin_net.as_ref().map(SpinNet::weights))
    }

    /// The chunks of step `step` (from 1): epochs are consecutive slices of a seeded permutation, reshuffled
    /// each epoch, the last batch of an epoch possibly smaller. A function of the step alone, so a resumed run
    /// draws the same batches.
    fn batch(&self, step: u64) -> Vec<usize> {
        let n = self.chunks.len();
        let size = self.settings.batch_size;
        let per_epoch = n.div_ceil(size) as u64;
        let (epoch, index) = ((step - 1) / per_epoch, ((step - 1) % per_epoch) as usize);
        let mut order: Vec<usize> = (0..n).collect();
        order.shuffle(&mut rng_for(self.settings.seed, &[SHUFFLE_STREAM, epoch]));
        order[index * size..((index + 1) * size).min(n)].to_vec()
    }

    fn load(&mut self) -> Result<()> {
        let module = self.module.take().expect("module present");
        self.module = Some(self.params.load_into(module, &self.device)?);
        Ok(())
    }
}

/// One run of a batch's chunks: its share of the loss, and its gradients where that share is finite.
struct PartLoss {
    value: f64,
    grads: Option<Vec<Vec<f64>>>,
}

fn part_loss(
    module: &BallParamsModule,
    chunks: &[&Chunk],
    batch_size: usize,
    launcher: bool,
    physics: &BallPhysics,
    device: &Device,
) -> Result<PartLoss> {
    let batch = Batch::part_of(chunks, batch_size, launcher, device)?;
    let loss = chunk_loss(module, &batch, physics, device)?;
    let value: f64 = loss.clone().into_scalar();
    let grads = value.is_finite().then(|| ParamSet::<f64>::gradients(module, &loss.backward()));
    Ok(PartLoss { value, grads })
}

impl TrainingMethod for BallEkfTrainer {
    fn step(&mut self, step: u64) -> Result<f64> {
        let picked: Vec<&Chunk> = self.batch(step).into_iter().map(|i| &self.chunks[i]).collect();
        let launcher = self.settings.launcher_prior;
        let (physics, device) = (&self.settings.initial.physics, &self.device);
        // burn's graph for a batch is a few thousand small tensor operations, about a third of whose time does
        // not shrink with the batch; on more threads the batch is cut into one run of chunks per thread, each
        // its own graph over its own copy of the parameters, and the runs' losses and gradients are added in
        // run order. The sums' order depends on the thread count, so the bytes do too, as for every training.
        let runs = rayon::current_num_threads().clamp(1, picked.len().max(1));
        let parts: Vec<Result<PartLoss>> = if runs == 1 {
            vec![part_loss(self.module(), &picked, picked.len(), launcher, physics, device)]
        } else {
            let (module, params) = (self.module(), &self.params);
            (0..runs)
                .into_par_iter()
                .map(|run| {
                    let chunks = &picked[picked.len() * run / runs..picked.len() * (run + 1) / runs];
                    let own = params.load_into(module.clone(), device)?;
                    part_loss(&own, chunks, picked.len(), launcher, physics, device)
                })
                .collect()
        };
        let mut value = 0.0;
        let mut total: Option<Vec<Vec<f64>>> = None;
        for part in parts {
            let part = part?;
            value += part.value;
            let Some(grads) = part.grads else { continue };
            match &mut total {
                None => total = Some(grads),
                Some(total) => {
                    for (sum, add) in total.iter_mut().zip(&grads) {
                        sum.iter_mut().zip(add).for_each(|(s, a)| *s += a);
                    }
                }
            }
        }
        let Some(mut grads) = total.filter(|_| value.is_finite()) else {
            return Ok(value);
        };
        self.adam.update(&mut self.params.values_mut(), &mut grads)?;
        self.load()?;
        Ok(value)
    }

    fn validate(&mut self) -> Result<Option<f64>> {
        Ok(None)
    }

    fn weights(&self) -> Vec<StoredTensor> {
        state::weights(&self.params)
    }

    fn state(&self) -> Vec<StoredTensor> {
        state::save(&self.params, &self.adam)
    }

    fn restore(&mut self, saved: &[StoredTensor]) -> Result<()> {
        state::restore(saved, &mut self.params, &mut self.adam)?;
        self.load()
    }

    fn artifacts(&self) -> Result<Vec<(String, Vec<u8>)>> {
        let (params, spin_net) = self.current();
        let json = |value: serde_json::Value| {
            let mut bytes = serde_json::to_vec_pretty(&value).map_err(|e| Error::config(e.to_string()))?;
            bytes.push(b'\n');
            Ok::<_, Error>(bytes)
        };
        let mut files = vec![(
            crate::models::ball::checkpoint::PARAMS_FILE.to_string(),
            json(serde_json::to_value(&params).map_err(|e| Error::config(e.to_string()))?)?,
        )];
        if let Some(net) = spin_net {
            files.push((
                crate::models::ball::checkpoint::SPIN_NET_FILE.to_string(),
                json(serde_json::to_value(&net).map_err(|e| Error::config(e.to_string()))?)?,
            ));
        }
        Ok(files)
    }
}
