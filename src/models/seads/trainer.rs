//! One SEADS epoch as a [`TrainingMethod`] step (the authors' Algorithm 2 loop): once the memory holds enough
//! episodes, relabel a sample plus the recent episodes and take forward-model steps on their final transitions,
//! relabel a fresh sample with the updated model and take SAC steps on every transition with the intrinsic reward
//! on the final one; then collect new episodes with the current skill policy.

use burn::tensor::Device;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::boards::BoardPool;
use super::collect::{policy_input, Collector, Starts};
use super::config::SeadsConfig;
use super::forward_model::{model_inputs, torch_name, FlipModel, FlipNet, FlipScratch};
use super::memory::{Episode, EpisodeMemory, ObsLayout};
use super::relabel::relabel_by_assignment;
use super::reward::{clipped_posterior, episode_reward};
use crate::envs::boards::{BoardGame, Split};
use crate::envs::embodiments::Embodiment;
use crate::error::{Error, Result};
use crate::nn::tensor::{scalar, tensor, training_device};
use crate::nn::{Adam, AdamConfig, ParamSet};
use crate::rl::sac::{Sac, TransitionBatch};
use crate::train::tensors::{StoredTensor, TensorData};
use crate::train::Budget;
use crate::train::{state, TrainingMethod};
use crate::util::seeding::{derive_seed, rng_for};

const INIT_STREAM: u64 = 1;
const EPOCH_STREAM: u64 = 2;
pub const MODEL_PREFIX: &str = "forward_model.";

/// What the forward model says about one episode.
struct Judged {
    changed: bool,
    /// log q(z_T | z_0, k) for every k.
    log_likelihoods: Vec<f64>,
}

/// Figures of the last epoch, for the live view and the report.
#[derive(Clone, Debug, Default)]
pub struct EpochStats {
    pub env_steps: u64,
    pub model_loss: f64,
    pub mean_final_reward: Option<f64>,
    pub critic_loss: Option<f64>,
    pub actor_loss: Option<f64>,
    /// Distinct game moves the skills execute: for each skill, the move its recent episodes performed most often.
    pub distinct_moves: usize,
    /// One of the epoch's new episodes as text: its skill, the move it made, the board before and after.
    pub board: String,
}

pub struct SeadsTrainer<G: BoardGame> {
    config: SeadsConfig,
    seed: u64,
    game: G,
    pool: BoardPool<G>,
    collector: Collector<G>,
    sac: Sac,
    device: Device,
    model_net: Option<FlipNet>,
    model_params: ParamSet,
    model_adam: Adam<f32>,
    model: FlipModel,
    memory: EpisodeMemory,
    env_steps: u64,
    pub last: EpochStats,
}

impl<G: BoardGame> SeadsTrainer<G> {
    pub fn new(config: SeadsConfig, game: G, embodiment: Embodiment, seed: u64) -> Result<Self> {
        config.validate()?;
        let pool = BoardPool::new(&game, config.max_board_depth, Split::Train)?;
        let collector = Collector::new(&game, embodiment, config.episodes_per_epoch, config.skills)?;
        let layout = collector.layout;
        let mut rng = rng_for(seed, &[INIT_STREAM]);
        let (low, high) = collector.action_bounds();
        let sac_config = config.sac_config(layout.obs_dim + config.skills, low, high);
        let sac = Sac::new(sac_config, &mut rng)?;
        let device = training_device();
        let net = FlipNet::init(layout.bits, config.skills, config.model_hidden, &device, &mut rng);
        let model_params = ParamSet::<f32>::from_module(&net, torch_name);
        let sizes: Vec<usize> = model_params.tensors.iter().map(|t| t.values.len()).collect();
        let model_adam = Adam::new(model_adam_config(&config), &sizes);
        let model = FlipModel::from_params(&model_params, layout.bits, config.skills)?;
        Ok(SeadsTrainer {
            memory: EpisodeMemory::new(config.episode_memory),
            config,
            seed,
            game,
            pool,
            collector,
            sac,
            device,
            model_net: Some(net),
            model_params,
            model_adam,
            model,
            env_steps: 0,
            last: EpochStats::default(),
        })
    }

    pub fn layout(&self) -> ObsLayout {
        self.collector.layout
    }

    pub fn step_limit(&self) -> usize {
        self.collector.step_limit()
    }

    pub fn env_steps(&self) -> u64 {
        self.env_steps
    }

    pub fn sac(&self) -> &Sac {
        &self.sac
    }

    pub fn model(&self) -> &FlipModel {
        &self.model
    }

    pub fn game(&self) -> &G {
        &self.game
    }

    fn judge(&self, episodes: &[&Episode]) -> Vec<Judged> {
        let layout = self.collector.layout;
        let starts: Vec<f32> = episodes.iter().flat_map(|e| layout.first_board(e).iter().copied()).collect();
        let ends: Vec<f32> = episodes.iter().flat_map(|e| layout.last_board(e).iter().copied()).collect();
        let lls = self.model.log_likelihoods(&starts, &ends, &mut FlipScratch::default());
        episodes
            .iter()
            .zip(lls.chunks(self.config.skills))
            .map(|(e, ll)| Judged { changed: layout.changed(e), log_likelihoods: ll.to_vec() })
            .collect()
    }

    /// The labels after relabelling a random share `ratio` of the episodes (only those that changed the board,
    /// when `only_changed`) by one assignment.
    fn relabel(
        &self,
        episodes: &[&Episode],
        judged: &[Judged],
        ratio: f64,
        only_changed: bool,
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<usize>> {
        let mut labels: Vec<usize> = episodes.iter().map(|e| e.label).collect();
        if !self.config.relabel || ratio == 0.0 {
            return Ok(labels);
        }
        let chosen: Vec<usize> = (0..episodes.len())
            .filter(|&i| rng.random::<f64>() < ratio && (!only_changed || judged[i].changed))
            .collect();
        let posteriors: Vec<Vec<f64>> = chosen.iter().map(|&i| clipped_posterior(&judged[i].log_likelihoods)).collect();
        let chosen_labels: Vec<usize> = chosen.iter().map(|&i| labels[i]).collect();
        for (&i, new) in chosen.iter().zip(relabel_by_assignment(&posteriors, &chosen_labels)?) {
            labels[i] = new;
        }
        Ok(labels)
    }

    fn model_step(&mut self, episodes: &[&Episode], labels: &[usize], rng: &mut ChaCha8Rng) -> Result<f64> {
        let layout = self.collector.layout;
        let (bits, k, b) = (layout.bits, self.config.skills, self.config.model_batch);
        let mut loss_sum = 0.0;
        for _ in 0..self.config.model_updates {
            let picks: Vec<usize> = (0..b).map(|_| rng.random_range(0..episodes.len())).collect();
            let boards: Vec<&[f32]> = picks.iter().map(|&i| layout.first_board(episodes[i])).collect();
            let skills: Vec<usize> = picks.iter().map(|&i| labels[i]).collect();
            let flipped: Vec<f32> = picks
                .iter()
                .flat_map(|&i| {
                    let (a, z) = (layout.first_board(episodes[i]), layout.last_board(episodes[i]));
                    a.iter().zip(z).map(|(x, y)| if x != y { 1.0 } else { 0.0 }).collect::<Vec<f32>>()
                })
                .collect();
            let net = self.model_net.as_ref().expect("the forward model is only taken out while loading weights");
            let loss = net.loss(
                tensor(model_inputs(&boards, &skills, k), [b, bits + k], &self.device),
                tensor(flipped, [b, bits], &self.device),
            );
            let value = scalar(&loss);
            if !value.is_finite() {
                return Ok(value);
            }
            loss_sum += value;
            let mut grads = ParamSet::<f32>::gradients(net, &loss.backward());
            self.model_adam.update(&mut self.model_params.values_mut(), &mut grads)?;
            self.reload_model()?;
        }
        Ok(loss_sum / self.config.model_updates as f64)
    }

    fn reload_model(&mut self) -> Result<()> {
        let net = self.model_net.take().expect("forward model present");
        self.model_net = Some(self.model_params.load_into(net, &self.device)?);
        self.model = FlipModel::from_params(&self.model_params, self.collector.layout.bits, self.config.skills)?;
        Ok(())
    }

    /// SAC steps on every transition of the episodes; the reward sits on the final transition only.
    fn sac_steps(
        &mut self,
        episodes: &[&Episode],
        judged: &[Judged],
        labels: &[usize],
        rng: &mut ChaCha8Rng,
    ) -> Result<(f64, f64, f64)> {
        let layout = self.collector.layout;
        let k = self.config.skills;
        // (episode, step) of every transition, and the final rewards.
        let finals: Vec<f64> = judged
            .iter()
            .zip(labels)
            .map(|(j, &label)| episode_reward(j.changed, &j.log_likelihoods, label, self.config.reward))
            .collect();
        let index: Vec<(usize, usize)> =
            episodes.iter().enumerate().flat_map(|(e, ep)| (0..layout.steps(ep)).map(move |t| (e, t))).collect();
        let (mut critic, mut actor) = (0.0, 0.0);
        for _ in 0..self.config.sac_updates {
            let rows = self.config.sac_batch;
            let mut batch = TransitionBatch { rows, ..TransitionBatch::default() };
            for _ in 0..rows {
                let (e, t) = index[rng.random_range(0..index.len())];
                let episode = episodes[e];
                let last = t + 1 == layout.steps(episode);
                policy_input(layout.obs(episode, t), labels[e], k, &mut batch.obs);
                policy_input(layout.obs(episode, t + 1), labels[e], k, &mut batch.next_obs);
                batch.actions.extend_from_slice(&episode.actions[t * layout.action_dim..(t + 1) * layout.action_dim]);
                batch.rewards.push(if last { finals[e] as f32 } else { 0.0 });
                batch.done.push(if last { 1.0 } else { 0.0 });
            }
            let losses = self.sac.update(&batch, rng)?;
            critic += losses.critic;
            actor += losses.actor;
        }
        let n = self.config.sac_updates as f64;
        Ok((critic / n, actor / n, finals.iter().sum::<f64>() / finals.len().max(1) as f64))
    }

    /// The forward model's loss on episodes it has not trained on, with their original labels.
    fn held_out_model_loss(&self, episodes: &[Episode]) -> f64 {
        let refs: Vec<&Episode> = episodes.iter().collect();
        let judged = self.judge(&refs);
        let bits = self.collector.layout.bits as f64;
        let total: f64 = judged.iter().zip(episodes).map(|(j, e)| -j.log_likelihoods[e.label]).sum();
        total / (bits * episodes.len().max(1) as f64)
    }

    fn distinct_moves(&self) -> usize {
        let k = self.config.skills;
        let moves = self.game.num_moves();
        let mut counts = vec![vec![0u32; moves]; k];
        for e in self.memory.recent(self.config.sampled_episodes) {
            if let Some(m) = e.performed {
                counts[e.label][m] += 1;
            }
        }
        let mut modes: Vec<usize> = counts
            .iter()
            .filter_map(|c| {
                c.iter()
                    .enumerate()
                    .max_by_key(|&(m, &n)| (n, std::cmp::Reverse(m)))
                    .filter(|(_, &n)| n > 0)
                    .map(|(m, _)| m)
            })
            .collect();
        modes.sort_unstable();
        modes.dedup();
        modes.len()
    }

    /// Episodes with the current policy from boards of `starts`.
    pub fn collect(
        &mut self,
        labels: &[usize],
        starts: Starts<'_, G>,
        deterministic: bool,
        rng: &mut ChaCha8Rng,
    ) -> Vec<Episode> {
        let sac = &self.sac;
        self.collector.collect(labels, starts, rng, |inputs, rows, rng| sac.act(inputs, rows, deterministic, rng))
    }

    fn describe(&self, episode: &Episode) -> String {
        let layout = self.collector.layout;
        let render = |bits: &[f32]| {
            let bits: Vec<f64> = bits.iter().map(|&b| b as f64).collect();
            self.game.decode_symbolic(&bits).map(|b| self.game.render(b)).unwrap_or_default()
        };
        format!(
            "skill {} → {} in {} steps\nbefore:\n{}\nafter:\n{}",
            episode.label,
            episode.performed.map(|m| self.game.move_name(m)).unwrap_or_else(|| "no move".into()),
            layout.steps(episode),
            render(layout.first_board(episode)),
            render(layout.last_board(episode))
        )
    }
}

fn model_adam_config(config: &SeadsConfig) -> AdamConfig {
    // torch.optim.Adam's defaults with the authors' rate.
    AdamConfig {
        learning_rate: config.model_learning_rate,
        beta1: 0.9,
        beta2: 0.999,
        epsilon: 1e-8,
        weight_decay: 0.0,
        clip_grad_norm: None,
    }
}

impl<G: BoardGame> TrainingMethod for SeadsTrainer<G> {
    fn step(&mut self, epoch: u64) -> Result<f64> {
        let mut rng = rng_for(self.seed, &[EPOCH_STREAM, epoch]);
        let sampled = self.config.sampled_episodes;
        let mut stats = EpochStats::default();
        if self.memory.len() >= sampled {
            let mut episodes = self.memory.sample(sampled, &mut rng);
            episodes.extend(self.memory.recent(sampled));
            let episodes: Vec<Episode> = episodes.into_iter().cloned().collect();
            let refs: Vec<&Episode> = episodes.iter().collect();
            let judged = self.judge(&refs);
            let labels = self.relabel(&refs, &judged, self.config.relabel_model, false, &mut rng)?;
            let model_loss = self.model_step(&refs, &labels, &mut rng)?;
            if !model_loss.is_finite() {
                return Ok(model_loss);
            }

            let mut episodes = self.memory.sample(sampled, &mut rng);
            episodes.extend(self.memory.recent(sampled));
            let episodes: Vec<Episode> = episodes.into_iter().cloned().collect();
            let refs: Vec<&Episode> = episodes.iter().collect();
            let judged = self.judge(&refs);
            let labels = self.relabel(&refs, &judged, self.config.relabel_sac, true, &mut rng)?;
            let (critic, actor, reward) = self.sac_steps(&refs, &judged, &labels, &mut rng)?;
            stats.critic_loss = Some(critic);
            stats.actor_loss = Some(actor);
            stats.mean_final_reward = Some(reward);
        }
        let labels: Vec<usize> =
            (0..self.config.episodes_per_epoch).map(|_| rng.random_range(0..self.config.skills)).collect();
        let mut collect_rng = ChaCha8Rng::seed_from_u64(derive_seed(self.seed, &[EPOCH_STREAM, epoch, 1]));
        let sac = &self.sac;
        let new = self.collector.collect(&labels, Starts::Pool(&self.pool), &mut collect_rng, |inputs, rows, rng| {
            sac.act(inputs, rows, false, rng)
        });
        let loss = self.held_out_model_loss(&new);
        stats.board = new.first().map(|e| self.describe(e)).unwrap_or_default();
        let layout = self.collector.layout;
        self.env_steps += new.iter().map(|e| layout.steps(e) as u64).sum::<u64>();
        for episode in new {
            self.memory.add(episode);
        }
        stats.env_steps = self.env_steps;
        stats.model_loss = loss;
        stats.distinct_moves = self.distinct_moves();
        self.last = stats;
        Ok(loss)
    }

    fn validate(&mut self) -> Result<Option<f64>> {
        Ok(None)
    }

    fn weights(&self) -> Vec<StoredTensor> {
        let mut out = self.sac.weights();
        out.extend(state::weights(&self.model_params).into_iter().map(|mut t| {
            t.name = format!("{MODEL_PREFIX}{}", t.name);
            t
        }));
        out
    }

    fn state(&self) -> Vec<StoredTensor> {
        let mut out: Vec<StoredTensor> = self
            .sac
            .state()
            .into_iter()
            .map(|mut t| {
                t.name = format!("sac.{}", t.name);
                t
            })
            .collect();
        out.extend(state::save(&self.model_params, &self.model_adam).into_iter().map(|mut t| {
            t.name = format!("{MODEL_PREFIX}{}", t.name);
            t
        }));
        out.extend(self.memory.to_stored("memory"));
        out.push(StoredTensor::f64("env_steps", vec![1], vec![self.env_steps as f64]));
        out
    }

    fn restore(&mut self, saved: &[StoredTensor]) -> Result<()> {
        let strip = |prefix: &str| -> Vec<StoredTensor> {
            saved
                .iter()
                .filter_map(|t| t.name.strip_prefix(prefix).map(|n| StoredTensor { name: n.to_string(), ..t.clone() }))
                .collect()
        };
        self.sac.restore(&strip("sac."))?;
        state::restore(&strip(MODEL_PREFIX), &mut self.model_params, &mut self.model_adam)?;
        self.reload_model()?;
        self.memory = EpisodeMemory::from_stored(
            saved,
            "memory",
            self.config.episode_memory,
            self.collector.layout,
            self.config.skills,
        )?;
        self.env_steps = match saved.iter().find(|t| t.name == "env_steps").map(|t| &t.data) {
            Some(TensorData::F64(v)) if v.len() == 1 && v[0] >= 0.0 && v[0].fract() == 0.0 => v[0] as u64,
            _ => return Err(Error::config("training state lacks a valid 'env_steps'")),
        };
        Ok(())
    }

    fn budget(&self) -> Option<Budget> {
        Some(Budget { unit: "env steps", used: self.env_steps, total: self.config.env_steps })
    }

    fn step_texts(&self) -> Vec<(&'static str, String)> {
        vec![("board", self.last.board.clone())]
    }

    fn step_scalars(&self) -> Vec<(&'static str, f64)> {
        let s = &self.last;
        let mut out = vec![("seads/env_steps", s.env_steps as f64), ("seads/distinct_moves", s.distinct_moves as f64)];
        if let Some(r) = s.mean_final_reward {
            out.push(("seads/intrinsic_reward", r));
        }
        if let (Some(c), Some(a)) = (s.critic_loss, s.actor_loss) {
            out.push(("sac/critic_loss", c));
            out.push(("sac/actor_loss", a));
        }
        out
    }
}
