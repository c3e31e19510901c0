//! Swing-up with a trained DLGPD model (thesis 3.4, as the authors' planning code runs it): the GPs are
//! conditioned on encoded evidence rollouts of the system at hand (hyperparameters and standardization as
//! trained, no retraining), and CEM plans on mean latent rollouts from the encoder's mean of the last two
//! observations. A candidate's return sums, per step, the reward GP's mean averaged over 5 samples of the
//! latent from N(mean, predictive variance) (t = 0: the encoder's variance).

use std::sync::atomic::{AtomicU64, Ordering};

use rand::Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

use super::data::{angle_observation, frame_planes, ObservationKind, Windows, OBSERVATION_NOISE_STD};
use super::dynamics::LatentDynamics;
use super::evidence::condition_on_rows;
use super::job::TrainedDlgpd;
use super::vae::encode_rows;
use crate::control::Objective;
use crate::control::{run_episode, Agent, Transition};
use crate::data::{Dataset, Rollout};
use crate::envs::pendulum::render::PendulumRenderer;
use crate::envs::pendulum::swingup::is_success;
use crate::envs::pendulum::{Pendulum, PendulumVariant, StartDistribution};
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::nn::tensor::inference_device;
use crate::planning::mpc::planning_failed;
use crate::planning::{Cem, CemConfig};
use crate::run::Monitor;
use crate::util::seeding::{derive_seed, rng_for};

/// Latent samples per step for the expected reward (the authors' 5).
pub const REWARD_SAMPLES: usize = 5;
/// The authors' CEM stops once the first action's std is below this.
pub const STOP_STD: f64 = 0.01;
/// Candidates that share a random stream and a batched GP prediction; fixed, so results do not depend on
/// the thread count.
const CANDIDATES_PER_CHUNK: usize = 100;
const EPISODE_STREAM: u64 = 1;
const OBSERVATION_STREAM: u64 = 2;
const PLANNER_STREAM: u64 = 3;
const OBJECTIVE_STREAM: u64 = 4;

/// The trained model's GPs conditioned on the evidence in `data` (encoder means of every transition's two
/// observations; the observation noise is drawn from `seed` as at training).
pub fn condition_on(trained: &TrainedDlgpd, data: &Dataset, seed: u64) -> Result<LatentDynamics> {
    let windows = Windows::from_dataset(data, trained.run.details.observation, seed)?;
    if windows.action_dim != trained.run.details.action_dim {
        return Err(Error::data(format!(
            "evidence actions have {} dimensions; the model was trained with {}",
            windows.action_dim, trained.run.details.action_dim
        )));
    }
    let rows: Vec<usize> = (0..windows.len()).collect();
    condition_on_rows(&trained.vae, (&trained.transition, &trained.reward), trained.scale.clone(), &windows, &rows)
}

/// Noisy observations of the pendulum as the model saw them in training: a rendered frame or the angle, with
/// N(0, 0.01²) noise (pixels clipped to [0, 1]). The authors add the planning-time pixel noise at 500 × 500
/// before resizing; here it is added at the model's resolution, as for the training data.
pub struct Observer {
    kind: ObservationKind,
    renderer: Option<PendulumRenderer>,
    rng: rand_chacha::ChaCha8Rng,
}

impl Observer {
    pub fn new(kind: ObservationKind, seed: u64) -> Observer {
        let renderer = matches!(kind, ObservationKind::Images { .. }).then(PendulumRenderer::new);
        Observer { kind, renderer, rng: rng_for(seed, &[OBSERVATION_STREAM]) }
    }

    pub fn observe(&mut self, theta: f64) -> Vec<f32> {
        let clean: Vec<f32> = match (&self.kind, self.renderer.as_mut()) {
            (ObservationKind::Images { side }, Some(renderer)) => {
                frame_planes(&renderer.frame(theta), side * side).collect()
            }
            _ => angle_observation(theta).to_vec(),
        };
        let clip = matches!(self.kind, ObservationKind::Images { .. });
        clean
            .into_iter()
            .map(|v| {
                let noisy = v + self.rng.sample::<f32, _>(StandardNormal) * OBSERVATION_NOISE_STD;
                if clip {
                    noisy.clamp(0.0, 1.0)
                } else {
                    noisy
                }
            })
            .collect()
    }
}

/// −(expected return) of candidate action sequences from a latent belief, on the conditioned GPs.
pub struct LatentObjective<'a> {
    pub dynamics: &'a LatentDynamics,
    pub mean: Vec<f64>,
    pub variance: Vec<f64>,
    pub seed: u64,
    calls: AtomicU64,
}

impl<'a> LatentObjective<'a> {
    pub fn new(dynamics: &'a LatentDynamics, mean: Vec<f64>, variance: Vec<f64>, seed: u64) -> Self {
        LatentObjective { dynamics, mean, variance, seed, calls: AtomicU64::new(0) }
    }

    /// Expected return of each candidate in `chunk` (each `horizon × action_dim`).
    fn returns(&self, chunk: &[f64], horizon: usize, seed: u64) -> Result<Vec<f64>> {
        let dims = self.mean.len();
        let action_dim = self.dynamics.action_dim();
        let rows = chunk.len() / (horizon * action_dim);
        let mut rng = rng_for(seed, &[]);
        let mut mean: Vec<f64> = self.mean.repeat(rows);
        let mut variance: Vec<f64> = self.variance.repeat(rows);
        let mut returns = vec![0.0; rows];
        let mut actions = vec![0.0; rows * action_dim];
        let mut sample = vec![0.0; rows * dims];
        for t in 0..horizon {
            for r in 0..rows {
                let start = r * horizon * action_dim + t * action_dim;
                actions[r * action_dim..(r + 1) * action_dim].copy_from_slice(&chunk[start..start + action_dim]);
            }
            for _ in 0..REWARD_SAMPLES {
                for ((s, m), v) in sample.iter_mut().zip(&mean).zip(&variance) {
                    *s = m + v.max(0.0).sqrt() * rng.sample::<f64, _>(StandardNormal);
                }
                let rewards = self.dynamics.reward_mean(&sample, &actions)?;
                for (total, r) in returns.iter_mut().zip(rewards) {
                    *total += r / REWARD_SAMPLES as f64;
                }
            }
            if t + 1 < horizon {
                (mean, variance) = self.dynamics.step(&mean, &actions)?;
            }
        }
        Ok(returns)
    }
}

impl Objective for LatentObjective<'_> {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
        let call = self.calls.fetch_add(1, Ordering::Relaxed);
        let per = horizon * self.dynamics.action_dim();
        candidates
            .par_chunks(per * CANDIDATES_PER_CHUNK)
            .zip(costs.par_chunks_mut(CANDIDATES_PER_CHUNK))
            .enumerate()
            .for_each(|(chunk_index, (chunk, out))| {
                let seed = derive_seed(self.seed, &[call, chunk_index as u64]);
                match self.returns(chunk, horizon, seed) {
                    Ok(returns) => out.iter_mut().zip(returns).for_each(|(c, r)| *c = -r),
                    // A prediction that fails (non-finite latents) must not win the elite selection.
                    Err(_) => out.iter_mut().for_each(|c| *c = f64::INFINITY),
                }
            });
    }
}

#[derive(Clone, Debug)]
pub struct ControlSettings {
    pub variant: PendulumVariant,
    pub steps: usize,
    pub cem: CemConfig,
}

impl ControlSettings {
    /// The authors' planner: horizon 20, 1000 candidates, 100 elites, at most 30 iterations stopping once the
    /// first action's std is ≤ 0.01, re-initialized at every step; 150 steps.
    pub fn authors(variant: PendulumVariant) -> ControlSettings {
        let cem = CemConfig {
            iterations: 30,
            warm_start: false,
            stop_std: Some(STOP_STD),
            ..CemConfig::for_box(&[-2.0], &[2.0])
        };
        ControlSettings { variant, steps: 150, cem }
    }
}

pub struct ControlEpisode {
    /// The planned steps (after the warm-up step that gives the second frame).
    pub rollout: Rollout,
    pub total_return: f64,
    pub success: bool,
    /// CEM iterations per step (the early stop makes them vary).
    pub iterations: Vec<usize>,
}

/// CEM on the conditioned GPs from the encoded last two noisy observations; the observer renders the next one
/// after every step, as the camera would.
pub struct ImageAgent<'a> {
    trained: &'a TrainedDlgpd,
    dynamics: &'a LatentDynamics,
    cem: Cem,
    observer: Observer,
    previous: Vec<f32>,
    current: Vec<f32>,
    seed: u64,
    monitor: &'a dyn Monitor,
    /// CEM iterations per step (the early stop makes them vary).
    iterations: Vec<usize>,
}

impl Agent for ImageAgent<'_> {
    fn act(&mut self, t: usize, _state: &[f64], _observation: &[f64]) -> Result<Vec<f64>> {
        let monitor = self.monitor;
        let input: Vec<f32> = self.previous.iter().chain(&self.current).copied().collect();
        let width = self.trained.run.details.observation.input_len();
        let (mean, std) = encode_rows(&self.trained.vae, &input, width, &inference_device());
        let mean: Vec<f64> = mean.into_iter().map(f64::from).collect();
        let variance: Vec<f64> = std.into_iter().map(|s| f64::from(s) * f64::from(s)).collect();
        let objective =
            LatentObjective::new(self.dynamics, mean, variance, derive_seed(self.seed, &[OBJECTIVE_STREAM, t as u64]));
        let mut used = 0;
        let plan = self.cem.plan(&objective, |it| {
            used += 1;
            monitor.scalar("cem/best_cost", it.iteration as u64, it.best_cost);
            monitor.scalar("cem/elite_mean_cost", it.iteration as u64, it.elite_mean_cost);
        });
        let plan = plan.map_err(|e| planning_failed(t, e))?;
        self.iterations.push(used);
        Ok(plan[..1].to_vec())
    }

    fn observe(&mut self, step: &Transition) -> Result<()> {
        let next = self.observer.observe(step.next_state[0]);
        self.previous = std::mem::replace(&mut self.current, next);
        Ok(())
    }
}

/// One swing-up from the hanging position in `settings.variant`, planned on `dynamics`. Before planning,
/// one step with a small random action (0.1 · U[−2, 2], as the authors') gives the second observation.
pub fn swing_up(
    trained: &TrainedDlgpd,
    dynamics: &LatentDynamics,
    settings: &ControlSettings,
    seed: u64,
    monitor: &dyn Monitor,
) -> Result<ControlEpisode> {
    settings.cem.validate()?;
    let mut env = Pendulum::new(settings.variant.clone()).with_start(StartDistribution::Hanging);
    let mut rng = rng_for(seed, &[EPISODE_STREAM]);
    env.reset(&mut rng);
    let mut observer = Observer::new(trained.run.details.observation, seed);
    let previous = observer.observe(env.state()[0]);
    let warm_up = 0.1 * rng.random_range(-2.0..2.0);
    env.step(&[warm_up]);
    let current = observer.observe(env.state()[0]);
    let mut agent = ImageAgent {
        trained,
        dynamics,
        cem: Cem::new(settings.cem.clone(), derive_seed(seed, &[PLANNER_STREAM]))?,
        observer,
        previous,
        current,
        seed,
        monitor,
        iterations: Vec::with_capacity(settings.steps),
    };
    let phase = "MPC steps";
    let rollout = run_episode(&mut env, &mut agent, settings.steps, monitor, |step, env, _| {
        let t = step.t as u64;
        monitor.scalar("pendulum/angle", t, crate::envs::pendulum::angle_normalize(env.state()[0]));
        monitor.scalar("pendulum/action", t, step.action[0]);
        monitor.scalar("pendulum/reward", t, step.reward);
        monitor.progress(phase, t + 1, settings.steps as u64);
        Ok(())
    })?;
    let total_return = rollout.total_reward();
    let success = is_success(&rollout.rewards);
    Ok(ControlEpisode { rollout, total_return, success, iterations: agent.iterations })
}
