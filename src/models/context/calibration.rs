//! Calibration (thesis 4.4.5): act in an unseen instance to collect the transitions that tell the model most
//! about its hidden parameters. Random actions are the baseline; open-loop calibration plans the whole sequence
//! once by maximizing the EIG; MPC calibration replans after every transition with the horizon
//! min(H_max, N − n).

use serde::{Deserialize, Serialize};

use super::eig::EigObjective;
use super::fast::{gaussian_entropy, max_into};
use super::LoadedModel;
use crate::control::{run_episode, Agent, Transition};
use crate::data::Rollout;
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::planning::mpc::planning_failed;
use crate::planning::{Cem, CemConfig, NoiseKind};
use crate::run::Monitor;
use crate::util::seeding::{derive_seed, rng_for};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    Random,
    OpenLoop,
    Mpc,
}

impl Strategy {
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Random => "random",
            Strategy::OpenLoop => "open-loop",
            Strategy::Mpc => "mpc",
        }
    }

    pub const ALL: [Strategy; 3] = [Strategy::Random, Strategy::OpenLoop, Strategy::Mpc];
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationSettings {
    pub strategy: Strategy,
    /// N: transitions to collect.
    pub transitions: usize,
    /// H_max of MPC calibration (pendulum 20, MountainCar 30).
    pub horizon_max: usize,
    pub candidates: usize,
    pub elites: usize,
    pub iterations: usize,
    /// β samples of the Monte Carlo EIG (20 in the thesis).
    pub beta_samples: usize,
}

impl CalibrationSettings {
    /// The thesis' settings: CEM 1000 / 100 / 10, 20 β samples.
    pub fn thesis(strategy: Strategy, transitions: usize, horizon_max: usize) -> Self {
        CalibrationSettings {
            strategy,
            transitions,
            horizon_max,
            candidates: 1000,
            elites: 100,
            iterations: 10,
            beta_samples: 20,
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::config(m));
        if !(1..=10_000).contains(&self.transitions) {
            return bad(format!("--transitions must be 1..=10000, got {}", self.transitions));
        }
        if !(1..=1000).contains(&self.horizon_max) {
            return bad(format!("--horizon must be 1..=1000, got {}", self.horizon_max));
        }
        if !(1..=1000).contains(&self.beta_samples) {
            return bad(format!("--beta-samples must be 1..=1000, got {}", self.beta_samples));
        }
        if !(2..=100_000).contains(&self.candidates) || !(2..=self.candidates).contains(&self.elites) {
            return bad(format!(
                "--candidates must be 2..=100000 and --elites 2..=candidates, got {} and {}",
                self.candidates, self.elites
            ));
        }
        if !(1..=1000).contains(&self.iterations) {
            return bad(format!("--iters must be 1..=1000, got {}", self.iterations));
        }
        Ok(())
    }
}

/// One executed calibration step.
pub struct CalibrationStep<'a> {
    pub t: usize,
    pub state: &'a [f64],
    pub action: &'a [f64],
    pub next_state: &'a [f64],
    /// H[q(β | transitions so far)] after this step.
    pub entropy: f64,
}

pub struct Calibration {
    pub rollout: Rollout,
    /// Entropy of the belief before any transition (index 0) and after each one.
    pub entropies: Vec<f64>,
}

/// Model-space rows [s, a, s'] of a rollout's transitions.
pub fn context_rows(model: &LoadedModel, rollout: &Rollout) -> Result<Vec<f32>> {
    let mut rows = Vec::new();
    for t in 0..rollout.len() {
        rows.extend(model.model_state(&rollout.states[t], rollout.observations.get(t))?);
        rows.extend(rollout.actions[t].iter().map(|a| *a as f32));
        rows.extend(model.model_state(&rollout.states[t + 1], rollout.observations.get(t + 1))?);
    }
    Ok(rows)
}

/// Calibration as an agent: random actions drawn up front, or CEM on the expected information gain (the whole
/// sequence once, or replanned each step); after each transition the context belief pools it.
pub struct CalibrationAgent<'a> {
    model: &'a LoadedModel,
    settings: &'a CalibrationSettings,
    seed: u64,
    monitor: &'a dyn Monitor,
    cem_config: Box<dyn Fn(usize) -> CemConfig + 'a>,
    action_dim: usize,
    random_actions: Vec<Vec<f64>>,
    plan: Vec<f64>,
    pooled: Vec<f32>,
    entropies: Vec<f64>,
}

impl<'a> CalibrationAgent<'a> {
    /// `env` is where the random actions are drawn for (its bounds and exploration noise).
    pub fn new(
        model: &'a LoadedModel,
        env: &dyn Env,
        settings: &'a CalibrationSettings,
        seed: u64,
        monitor: &'a dyn Monitor,
    ) -> Self {
        let spec = env.spec();
        let pooled = vec![0.0f32; model.fast.transition_features];
        let entropies = vec![gaussian_entropy(&model.fast.belief(&pooled, 1).std)];
        let random_actions = match settings.strategy {
            Strategy::Random => {
                crate::data::collect::exploration_actions(env, &mut rng_for(seed, &[0]), settings.transitions)
            }
            _ => Vec::new(),
        };
        let action_dim = spec.action_dim();
        let cem_config = Box::new(move |horizon: usize| CemConfig {
            horizon,
            candidates: settings.candidates,
            elites: settings.elites,
            iterations: settings.iterations,
            action_low: spec.action_low.clone(),
            action_high: spec.action_high.clone(),
            init_std: spec.action_low.iter().zip(&spec.action_high).map(|(l, h)| l.abs().max(h.abs())).collect(),
            noise: NoiseKind::White,
            warm_start: false,
            stop_std: None,
        });
        CalibrationAgent {
            model,
            settings,
            seed,
            monitor,
            cem_config,
            action_dim,
            random_actions,
            plan: Vec::new(),
            pooled,
            entropies,
        }
    }

    /// H[q(β | transitions so far)] before any transition (index 0) and after each one.
    pub fn entropies(&self) -> &[f64] {
        &self.entropies
    }
}

impl Agent for CalibrationAgent<'_> {
    fn act(&mut self, t: usize, state: &[f64], _observation: &[f64]) -> Result<Vec<f64>> {
        let (settings, monitor) = (self.settings, self.monitor);
        let n = settings.transitions;
        let a = self.action_dim;
        if settings.strategy == Strategy::Random {
            return Ok(self.random_actions.get(t).cloned().unwrap_or_default());
        }
        let mpc = settings.strategy == Strategy::Mpc;
        if mpc || t == 0 {
            let horizon = if mpc { settings.horizon_max.min(n - t) } else { n };
            let objective = EigObjective::new(
                &self.model.fast,
                self.model.features(state),
                self.pooled.clone(),
                settings.beta_samples,
                derive_seed(self.seed, &[1, t as u64]),
            );
            let mut cem = Cem::new((self.cem_config)(horizon), derive_seed(self.seed, &[2, t as u64]))?;
            let phase = format!("step {}/{n}: EIG planning", t + 1);
            self.plan = cem
                .plan(&objective, |it| {
                    monitor.scalar("cem/best_entropy", it.iteration as u64, it.best_cost);
                    monitor.progress(&phase, it.iteration as u64 + 1, settings.iterations as u64);
                })
                .map_err(|e| planning_failed(t, e))?;
            self.plan.truncate(horizon * a);
        }
        let offset = if mpc { 0 } else { t };
        Ok(self.plan[offset * a..(offset + 1) * a].to_vec())
    }

    fn observe(&mut self, step: &Transition) -> Result<()> {
        let mut row = self.model.model_state(&step.state, Some(&step.observation))?;
        row.extend(step.action.iter().map(|a| *a as f32));
        row.extend(self.model.model_state(&step.next_state, Some(&step.next_observation))?);
        max_into(&mut self.pooled, &self.model.fast.pool(&row));
        self.entropies.push(gaussian_entropy(&self.model.fast.belief(&self.pooled, 1).std));
        Ok(())
    }
}

/// Runs `settings.strategy` in `env` from its current state. `seed` keys random actions, β samples and CEM.
pub fn calibrate(
    model: &LoadedModel,
    env: &mut dyn Env,
    settings: &CalibrationSettings,
    seed: u64,
    monitor: &dyn Monitor,
    mut on_step: impl FnMut(&CalibrationStep),
) -> Result<Calibration> {
    settings.validate()?;
    if model.run.details.model.observations && settings.strategy != Strategy::Random {
        return Err(Error::config(format!(
            "a {} model calibrates with random actions (thesis 5.4.2); supported: --strategy random",
            model.run.method
        )));
    }
    let n = settings.transitions;
    let mut agent = CalibrationAgent::new(model, env, settings, seed, monitor);
    let rollout = run_episode(env, &mut agent, n, monitor, |step, _, agent| {
        let entropy = *agent.entropies().last().expect("the belief before any transition is recorded");
        on_step(&CalibrationStep {
            t: step.t,
            state: &step.state,
            action: &step.action,
            next_state: &step.next_state,
            entropy,
        });
        monitor.progress("calibration transitions", step.t as u64 + 1, n as u64);
        Ok(())
    })?;
    Ok(Calibration { rollout, entropies: agent.entropies })
}

/// The start of a calibration when the user gives none: the thesis' x = 0 (toy), x = ẋ = 0 (MountainCar) and,
/// for the quadrant pendulum, hanging down nearly at rest, θ ∼ U[π − 0.05, π + 0.05], θ̇ ∼ U[−0.05, 0.05] (4.5.3:
/// from there random actions reach the lower quadrants only, so the upper ones must be explored on purpose);
/// elsewhere the env's reset draw.
pub fn default_start<R: rand::Rng + ?Sized>(env: &crate::envs::EnvName, rng: &mut R) -> Option<Vec<f64>> {
    use std::f64::consts::PI;
    match env {
        crate::envs::EnvName::Toy(_) | crate::envs::EnvName::MountainCar => Some(vec![0.0, 0.0]),
        crate::envs::EnvName::Pendulum(_) if env.canonical() == "pendulum:quadrant" => {
            Some(vec![rng.random_range(PI - 0.05..PI + 0.05), rng.random_range(-0.05..0.05)])
        }
        _ => None,
    }
}

/// The live view of a calibration run.
pub fn layout(title: &str, state_names: &[String]) -> crate::run::Event {
    use crate::run::PanelSpec;
    crate::run::Event::Layout {
        title: title.to_string(),
        panels: vec![
            PanelSpec {
                title: "entropy of q(β | context) [nats]".into(),
                x_label: "transitions".into(),
                series: vec!["calibration/entropy".into()],
                restart_on_rewind: false,
                path: None,
            },
            PanelSpec {
                title: "executed trajectory".into(),
                x_label: "step".into(),
                series: state_names.iter().map(|n| format!("state/{n}")).collect(),
                restart_on_rewind: false,
                path: None,
            },
            PanelSpec {
                title: "EIG plan: best entropy (this step)".into(),
                x_label: "CEM iteration".into(),
                series: vec!["cem/best_entropy".into()],
                restart_on_rewind: true,
                path: None,
            },
        ],
    }
}

/// A calibration in an instance of `env`, as the `calibrate` command and `eval context` run it.
pub struct CalibrationRequest {
    pub env: crate::envs::EnvName,
    pub instance_seed: u64,
    /// The start state (env state space); `None`: [`default_start`] or the env's reset draw.
    pub init_state: Option<Vec<f64>>,
    pub settings: CalibrationSettings,
    pub seed: u64,
}

/// Builds the instance, puts it in its start state and calibrates; reports entropy and states to `monitor`.
pub fn run_calibration(
    model: &LoadedModel,
    request: &CalibrationRequest,
    monitor: &dyn Monitor,
) -> Result<(Calibration, serde_json::Value)> {
    let mut env = crate::envs::instance_env(&request.env, request.instance_seed)?;
    let spec = env.spec();
    // reset also seeds the env's own noise (toy), so it comes first even when the start is given.
    env.reset(&mut rng_for(request.seed, &[3]));
    let drawn_start = default_start(&request.env, &mut rng_for(request.seed, &[4]));
    if let Some(start) = request.init_state.clone().or(drawn_start) {
        crate::data::collect::check_start(env.as_ref(), &spec, &start)?;
        env.set_state(&start);
    }
    let names = spec.state_names.clone();
    let start = env.state();
    for (name, x) in names.iter().zip(&start) {
        monitor.scalar(&format!("state/{name}"), 0, *x);
    }
    let calibration = calibrate(model, env.as_mut(), &request.settings, request.seed, monitor, |step| {
        monitor.scalar("calibration/entropy", step.t as u64 + 1, step.entropy);
        for (name, x) in names.iter().zip(step.next_state) {
            monitor.scalar(&format!("state/{name}"), step.t as u64 + 1, *x);
        }
    })?;
    Ok((calibration, env.params()))
}

/// The calibration transitions as a one-rollout dataset (the context file `plan --context` reads).
pub fn calibration_dataset(
    env: &crate::envs::EnvName,
    calibration: &Calibration,
    instance: serde_json::Value,
    seed: u64,
    command_line: &str,
) -> Result<crate::data::Dataset> {
    let spec = env.build()?.spec();
    Ok(crate::data::Dataset::of_rollouts(
        &spec,
        vec![instance],
        std::slice::from_ref(&calibration.rollout),
        seed,
        command_line,
    ))
}

/// Model-space context rows from a context file (any rollout dataset of the model's env).
pub fn read_context(model: &LoadedModel, path: &std::path::Path) -> Result<Vec<f32>> {
    let dataset = crate::data::read_dataset(path)?;
    if dataset.meta.env != model.run.env() {
        return Err(Error::bad_file(
            path,
            format!("holds transitions of '{}'; the model is of '{}'", dataset.meta.env, model.run.env()),
        ));
    }
    let names_match =
        model.run.details.model.observations || dataset.meta.state_names == model.run.details.model.state_names;
    if !names_match || dataset.meta.action_dim != model.run.details.model.action_dim {
        return Err(Error::bad_file(
            path,
            format!(
                "has states ({}) and {} action dimensions; the model expects ({}) and {}",
                dataset.meta.state_names.join(", "),
                dataset.meta.action_dim,
                model.run.details.model.state_names.join(", "),
                model.run.details.model.action_dim
            ),
        ));
    }
    let rollouts = Rollout::group(&dataset.steps)
        .map_err(|i| Error::bad_file(path, format!("message {i} does not continue its rollout")))?;
    let mut rows = Vec::new();
    for (_, rollout) in &rollouts {
        rows.extend(context_rows(model, rollout).map_err(|e| e.at(path))?);
    }
    Ok(rows)
}
