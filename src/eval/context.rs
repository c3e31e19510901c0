//! `mbrl eval context`: the protocol of thesis 4.5 at a chosen scale. Per context (an unseen instance):
//! random validation rollouts, then random / open-loop / MPC calibration from one shared start, each giving a
//! context set; the model conditioned on it (context mean) predicts the validation rollouts open loop. Reports
//! the prediction MSE against the horizon, paired Wilcoxon signed-rank tests between strategies, the
//! entropy after calibration, quadrants visited (pendulum) and, for the toy, the entropy after one transition
//! as a function of the action (Fig. 4.4a).

use std::fmt::Write as _;
use std::path::Path;

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::num;
use super::plot::{line_plot, rising_line_plot, Series};
use super::stats::{mean, wilcoxon_signed_rank, Alternative};
use super::summary::{publish, write_config};
use super::swingup::{self, SwingupSettings};
use crate::data::Rollout;
use crate::envs::{instance_env, EnvName};
use crate::error::{Error, Result};
use crate::models::context::calibration::{
    context_rows, run_calibration, CalibrationRequest, CalibrationSettings, Strategy,
};
use crate::models::context::dynamics::ContextDynamics;
use crate::models::context::fast::{gaussian_entropy, RolloutScratch};
use crate::models::context::LoadedModel;
use crate::run::dir::{Provenance, RunDir};
use crate::run::{Event, Monitor, PanelSpec, Tee};
use crate::util::atomic::write_text;
use crate::util::seeding::{derive_seed, rng_for};
use crate::util::table::write_csv;

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextEvalSettings {
    pub contexts: usize,
    /// Validation rollouts per context and their length (thesis: 20 × 50).
    pub validation_rollouts: usize,
    pub validation_steps: usize,
    pub strategies: Vec<Strategy>,
    /// N, H_max and the CEM/β-sample sizes of every EIG calibration.
    pub calibration: CalibrationSettings,
    /// Pendulum only: after each calibration, a swing-up planned on the model conditioned on it (thesis 4.5.3:
    /// CEM 1000/100/10, horizon 20, 50 agent steps), and one planned on the simulator's own equations in the
    /// same instance as the ground-truth reference.
    pub swingup: Option<SwingupSettings>,
}

pub const PROTOCOL: &str = "context";

/// The reference row's name in CSVs: the model given no calibration transitions.
const EMPTY_CONTEXT: &str = "empty-context";

/// `mbrl eval context`'s settings, as config.json records them.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextEvalConfig {
    /// The context-model checkpoint.
    pub model: std::path::PathBuf,
    /// The env the model was trained on.
    pub env: String,
    pub allow_incomplete: bool,
    pub settings: ContextEvalSettings,
}

impl ContextEvalConfig {
    /// The range checks of the command's flags, before the model is loaded.
    pub fn validate(&self, env: &EnvName) -> Result<()> {
        let s = &self.settings;
        s.calibration.validate()?;
        if let Some(sw) = &s.swingup {
            if !matches!(env, EnvName::Pendulum(_)) {
                return Err(Error::config(format!(
                    "--swingup needs a pendulum env (pendulum:quadrant in the thesis), not '{}'",
                    env.canonical()
                )));
            }
            if !(2..=100_000).contains(&sw.cem.candidates) || !(1..=10_000).contains(&sw.steps) {
                return Err(Error::config("--swingup-candidates must be 2..=100000 and --swingup-steps 1..=10000"));
            }
        }
        if !(2..=100_000).contains(&s.contexts)
            || !(1..=10_000).contains(&s.validation_rollouts)
            || !(1..=10_000).contains(&s.validation_steps)
        {
            return Err(Error::config(
                "--contexts must be 2..=100000, --validation-rollouts and --validation-steps 1..=10000",
            ));
        }
        Ok(())
    }
}

/// What one strategy achieved in one context.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Outcome {
    /// Per-step MSE over the validation rollouts (averaged over state dims and rollouts), by horizon.
    #[serde(with = "num::reals")]
    pub mse_by_horizon: Vec<f64>,
    #[serde(with = "num::real")]
    pub final_entropy: f64,
    pub quadrants: Option<usize>,
    #[serde(with = "num::opt")]
    pub swingup_return: Option<f64>,
    #[serde(with = "num::real")]
    pub action_response: f64,
}

/// The model given no calibration at all (the mean of q(β | ∅)) in one context: the reference row.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NoCalibration {
    #[serde(with = "num::reals")]
    pub mse_by_horizon: Vec<f64>,
    #[serde(with = "num::real")]
    pub action_response: f64,
}

/// A paired one-sided Wilcoxon signed-rank test between two strategies.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PairTest {
    pub better: Strategy,
    pub worse: Strategy,
    /// What "better" means (`MSE lower`, `swing-up return higher`).
    pub label: String,
    pub n: usize,
    #[serde(with = "num::real")]
    pub statistic: f64,
    #[serde(with = "num::real")]
    pub p_value: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ContextEvalSummary {
    pub provenance: Provenance,
    pub settings: ContextEvalSettings,
    pub env: String,
    /// The checkpoint and how far it was trained, as the report names it.
    pub model: String,
    /// Whether the model space holds angles as (cos, sin).
    pub angular: bool,
    /// Entropy of q(β | ∅).
    #[serde(with = "num::real")]
    pub prior_entropy: f64,
    /// Per context, per strategy (in `settings.strategies` order).
    pub outcomes: Vec<Vec<Outcome>>,
    pub no_calibration: Vec<NoCalibration>,
    /// With `swingup`: the return of the swing-up on the simulator's own equations, per context.
    #[serde(with = "num::reals")]
    pub ground_truth_returns: Vec<f64>,
    /// Mean over contexts of the mean validation MSE, per strategy.
    #[serde(with = "num::reals")]
    pub mean_mse: Vec<f64>,
    /// The same for the model given no calibration at all (the mean of q(β | ∅)): the reference that shows
    /// whether the model uses its context.
    #[serde(with = "num::real")]
    pub empty_context_mse: f64,
    /// Median over contexts of the action response (model / simulator, 1 = right, 0 = action ignored), per
    /// strategy, and for the model given no calibration.
    #[serde(with = "num::reals")]
    pub action_response: Vec<f64>,
    #[serde(with = "num::real")]
    pub empty_context_action_response: f64,
    /// First strategy named has lower MSE than the second.
    pub tests: Vec<PairTest>,
    /// Per strategy: p that it has lower MSE than no calibration.
    #[serde(with = "num::reals")]
    pub against_empty: Vec<f64>,
    /// With `swingup`: mean swing-up return per strategy, the ground truth's, and the return tests.
    pub swingup: Option<SwingupSummary>,
    /// Toy only: the entropy after one transition from s = 0 against the action (Fig. 4.4a), the prior entropy
    /// of that belief, and its means over informative and non-informative actions.
    pub toy: Option<ToyEntropy>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SwingupSummary {
    #[serde(with = "num::reals")]
    pub mean_return: Vec<f64>,
    #[serde(with = "num::real")]
    pub ground_truth_mean_return: f64,
    pub tests: Vec<PairTest>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ToyEntropy {
    /// (action, entropy) pairs.
    #[serde(with = "num::points")]
    pub curve: Vec<(f64, f64)>,
    #[serde(with = "num::real")]
    pub prior: f64,
    #[serde(with = "num::real")]
    pub informative: f64,
    #[serde(with = "num::real")]
    pub non_informative: f64,
}

impl ContextEvalSummary {
    /// The one-sided p of `better` over `worse` in the MSE tests.
    pub fn p_value(&self, better: Strategy, worse: Strategy) -> Option<f64> {
        self.tests.iter().find(|t| t.better == better && t.worse == worse).map(|t| t.p_value)
    }
}

impl std::fmt::Display for ContextEvalSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let strategies = &self.settings.strategies;
        for ((s, m), r) in strategies.iter().zip(&self.mean_mse).zip(&self.action_response) {
            writeln!(f, "{:<10} mean prediction MSE {m:.4e}, action response {r:.3}", s.name())?;
        }
        writeln!(
            f,
            "no calibration (empty context, reference) mean prediction MSE {:.4e}, action response {:.3}",
            self.empty_context_mse, self.empty_context_action_response
        )?;
        write!(
            f,
            "(action response: the model's one-step response to the action over the simulator's; 1 right, 0 ignored)"
        )?;
        for t in &self.tests {
            write!(f, "\nWilcoxon: {} lower than {}: p = {:.3e}", t.better.name(), t.worse.name(), t.p_value)?;
        }
        if let Some(sw) = &self.swingup {
            for (s, r) in strategies.iter().zip(&sw.mean_return) {
                write!(f, "\n{:<10} mean swing-up return {r:.1}", s.name())?;
            }
            write!(f, "\nground truth mean swing-up return {:.1}", sw.ground_truth_mean_return)?;
            for t in &sw.tests {
                write!(
                    f,
                    "\nWilcoxon: {} higher swing-up return than {}: p = {:.3e}",
                    t.better.name(),
                    t.worse.name(),
                    t.p_value
                )?;
            }
        }
        if let Some(toy) = &self.toy {
            write!(
                f,
                "\nentropy after one transition: informative actions {:.3}, non-informative {:.3} nats",
                toy.informative, toy.non_informative
            )?;
        }
        Ok(())
    }
}

fn layout(title: &str) -> Event {
    Event::Layout {
        title: title.into(),
        panels: vec![PanelSpec {
            title: "entropy of q(β | context) [nats]".into(),
            x_label: "transitions".into(),
            series: vec!["calibration/entropy".into()],
            restart_on_rewind: true,
            path: None,
        }],
    }
}

/// Open-loop mean predictions of `rollout` under β, per-step squared error averaged over model-space dims.
fn prediction_errors(model: &LoadedModel, beta: &[f32], rollout: &Rollout) -> Vec<f64> {
    let fast = &model.fast;
    let horizon = rollout.len();
    let s = fast.state_dim;
    let actions: Vec<f32> = rollout.actions.iter().flatten().map(|a| *a as f32).collect();
    let mut predicted = vec![0.0; horizon * s];
    fast.rollout_means(
        &model.features(&rollout.states[0]),
        &actions,
        beta,
        1,
        horizon,
        None,
        &mut predicted,
        &mut RolloutScratch::default(),
    );
    (0..horizon)
        .map(|t| {
            let truth = model.features(&rollout.states[t + 1]);
            truth.iter().zip(&predicted[t * s..(t + 1) * s]).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>()
                / s as f64
        })
        .collect()
}

fn random_rollout(env: &mut dyn crate::envs::Env, steps: usize, rng: &mut rand_chacha::ChaCha8Rng) -> Rollout {
    let spec = env.spec();
    let obs = env.reset(rng);
    let mut rollout = Rollout::start(env.state(), obs);
    for _ in 0..steps {
        let action: Vec<f64> =
            spec.action_low.iter().zip(&spec.action_high).map(|(&l, &h)| rng.random_range(l..=h)).collect();
        let step = env.step(&action);
        rollout.push(action, step.reward, env.state(), step.obs);
    }
    rollout
}

/// Entropy after a single transition from s = 0 under action a, the next state imagined by the model itself
/// with β from the prior (both ends of the transition the model's, as in EIG), averaged over `samples` draws
/// (thesis Fig. 4.4a).
pub fn entropy_after_one_action(model: &LoadedModel, actions: &[f64], samples: usize, seed: u64) -> Vec<f64> {
    let fast = &model.fast;
    let zero = vec![0.0f32; fast.transition_features];
    let prior = fast.belief(&zero, 1);
    let mut rng = rng_for(seed, &[]);
    let betas: Vec<f32> = (0..samples)
        .flat_map(|_| {
            prior
                .mean
                .iter()
                .zip(&prior.std)
                .map(|(m, s)| m + s * rng.sample::<f32, _>(rand_distr::StandardNormal))
                .collect::<Vec<_>>()
        })
        .collect();
    let init = model.features(&vec![0.0; model.run.details.model.angular.len()]);
    actions
        .iter()
        .map(|&a| {
            let acts = vec![a as f32; samples];
            let mut next = vec![0.0; samples * fast.state_dim];
            fast.rollout_means(&init, &acts, &betas, samples, 1, None, &mut next, &mut RolloutScratch::default());
            let mut entropies = vec![0.0; samples];
            fast.entropy_after(&zero, &init, &acts, &next, samples, 1, &mut entropies, &mut RolloutScratch::default());
            entropies.iter().sum::<f64>() / samples as f64
        })
        .collect()
}

/// Runs the protocol and writes report.md, CSVs and PNGs into `report_dir`.
pub fn evaluate(
    model: &LoadedModel,
    env: &EnvName,
    config: &ContextEvalConfig,
    provenance: &Provenance,
    report_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<ContextEvalSummary> {
    let settings = &config.settings;
    if settings.contexts < 2 || settings.validation_rollouts == 0 || settings.validation_steps == 0 {
        return Err(Error::config("eval context needs at least 2 contexts and 1 validation rollout of ≥ 1 step"));
    }
    if settings.strategies.is_empty() {
        return Err(Error::config("eval context needs at least one calibration strategy"));
    }
    settings.calibration.validate()?;
    if let Some(swingup) = &settings.swingup {
        if !matches!(env, EnvName::Pendulum(_)) {
            return Err(Error::config(format!(
                "the swing-up test needs a pendulum env (pendulum:quadrant in the thesis), not '{}'",
                env.canonical()
            )));
        }
        if swingup.steps == 0 {
            return Err(Error::config("the swing-up test needs at least 1 step"));
        }
    }
    let run = RunDir::create(report_dir)?;
    write_config(config, provenance, run.path())?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    monitor.emit(&layout(&format!("eval context: {} on {}", model.dir.display(), env.canonical())));
    let seed = provenance.seed;
    let is_quadrant = env.canonical() == "pendulum:quadrant";
    let mut outcomes: Vec<Vec<Outcome>> = Vec::with_capacity(settings.contexts);
    let mut no_calibration: Vec<NoCalibration> = Vec::with_capacity(settings.contexts);
    let empty_beta = model.fast.belief(&model.fast.pool(&[]), 1).mean;
    let mut ground_truth_returns = Vec::new();
    for k in 0..settings.contexts as u64 {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        monitor.progress("contexts", k, settings.contexts as u64);
        let instance_seed = derive_seed(seed, &[k, 0]);
        let mut env_k = instance_env(env, instance_seed)?;
        let mut rng = rng_for(seed, &[k, 1]);
        let validation: Vec<Rollout> = (0..settings.validation_rollouts)
            .map(|_| random_rollout(env_k.as_mut(), settings.validation_steps, &mut rng))
            .collect();
        let probe = action_probe(model, env_k.as_mut(), &validation);
        no_calibration.push(NoCalibration {
            mse_by_horizon: mse_by_horizon(model, &empty_beta, &validation, settings.validation_steps),
            action_response: action_response(model, &empty_beta, &probe),
        });
        // One start for every strategy: the thesis' fixed start, or one reset draw.
        let start = crate::models::context::calibration::default_start(env, &mut rng).unwrap_or_else(|| {
            env_k.reset(&mut rng);
            env_k.state()
        });
        let swingup_seed = derive_seed(seed, &[k, 3]);
        let swingup_settings = settings.swingup.as_ref().map(|sw| SwingupSettings {
            variant: match env {
                EnvName::Pendulum(v) => v.clone(),
                _ => unreachable!("checked above: the swing-up test runs on pendulum envs"),
            },
            instance_seed: Some(instance_seed),
            ..sw.clone()
        });
        if let Some(sw) = &swingup_settings {
            let truth = swingup::run_episode(sw, None, swingup_seed, 0, &crate::run::NullMonitor)?;
            ground_truth_returns.push(truth.total_return);
        }
        let mut per_strategy = Vec::new();
        for (j, strategy) in settings.strategies.iter().enumerate() {
            let request = CalibrationRequest {
                env: env.clone(),
                instance_seed,
                init_state: Some(start.clone()),
                settings: CalibrationSettings { strategy: *strategy, ..settings.calibration.clone() },
                seed: derive_seed(seed, &[k, 2, j as u64]),
            };
            let (calibration, _) = run_calibration(model, &request, &crate::run::NullMonitor)?;
            // The calibration runs quietly (its own layout would replace this job's); its entropy curve is
            // replayed into the panel declared above, which restarts at transition 0 for every strategy.
            for (n, entropy) in calibration.entropies.iter().enumerate() {
                monitor.scalar("calibration/entropy", n as u64, *entropy);
            }
            let rows = context_rows(model, &calibration.rollout)?;
            let beta = model.fast.belief(&model.fast.pool(&rows), 1).mean;
            let mse_by_horizon = mse_by_horizon(model, &beta, &validation, settings.validation_steps);
            let response = action_response(model, &beta, &probe);
            let quadrants = is_quadrant.then(|| {
                let mut seen = [false; 4];
                for s in &calibration.rollout.states {
                    seen[crate::envs::pendulum::quadrant_of(s[0])] = true;
                }
                seen.iter().filter(|x| **x).count()
            });
            let final_entropy = *calibration.entropies.last().expect("entropy before calibration is always there");
            monitor.scalar(&format!("context/{}/entropy", strategy.name()), k, final_entropy);
            // The same start and candidate seed for every strategy: the returns are paired by context.
            let swingup_return = match &swingup_settings {
                Some(sw) => {
                    let dynamics = ContextDynamics::new(model.clone(), &rows, env)?;
                    let episode = swingup::run_episode(sw, Some(&dynamics), swingup_seed, 0, &crate::run::NullMonitor)?;
                    monitor.scalar(&format!("context/{}/swingup_return", strategy.name()), k, episode.total_return);
                    Some(episode.total_return)
                }
                None => None,
            };
            per_strategy.push(Outcome {
                mse_by_horizon,
                final_entropy,
                quadrants,
                swingup_return,
                action_response: response,
            });
        }
        outcomes.push(per_strategy);
    }
    monitor.progress("contexts", settings.contexts as u64, settings.contexts as u64);
    let summary = summarize(model, env, settings, provenance, outcomes, no_calibration, ground_truth_returns)?;
    publish(PROTOCOL, &summary, run.path(), render)?;
    metrics.emit(&Event::Finished { ok: true });
    Ok(summary)
}

/// The simulator's one-step response to the action from every validation state, measured once per context and
/// shared by every β compared on it: Δ = next state (model space) under the highest action minus under the middle
/// of the action range.
struct ActionProbe {
    /// The highest and the middle action, as the model takes them.
    actions: Vec<f32>,
    /// Model-space start states, one row each.
    starts: Vec<Vec<f32>>,
    /// The simulator's Δ per start, state_dim each.
    true_deltas: Vec<f32>,
}

fn action_probe(model: &LoadedModel, env: &mut dyn crate::envs::Env, validation: &[Rollout]) -> ActionProbe {
    let spec = env.spec();
    let high = spec.action_high.clone();
    let middle: Vec<f64> = spec.action_low.iter().zip(&high).map(|(l, h)| 0.5 * (l + h)).collect();
    let mut probe = ActionProbe {
        actions: high.iter().chain(&middle).map(|a| *a as f32).collect(),
        starts: Vec::new(),
        true_deltas: Vec::new(),
    };
    for state in validation.iter().flat_map(|r| &r.states[..r.len()]) {
        let mut next = |action: &[f64]| {
            env.set_state(state);
            env.step(action);
            model.features(&env.state())
        };
        let (true_high, true_middle) = (next(&high), next(&middle));
        probe.true_deltas.extend(true_high.iter().zip(&true_middle).map(|(h, m)| h - m));
        probe.starts.push(model.features(state));
    }
    probe
}

/// How the model's one-step prediction under `beta` responds to the action, against the simulator:
/// Σ⟨Δ_model, Δ_true⟩ / Σ‖Δ_true‖². 1: the response is right; 0: the model ignores the action (its context did not
/// tell it how the action acts here); negative: the wrong direction. It separates a model that cannot use a
/// context from a context that holds nothing, which the prediction MSE alone does not.
fn action_response(model: &LoadedModel, beta: &[f32], probe: &ActionProbe) -> f64 {
    let s = model.fast.state_dim;
    let betas: Vec<f32> = beta.iter().chain(beta).copied().collect();
    let mut predicted = vec![0.0f32; 2 * s];
    let mut scratch = RolloutScratch::default();
    let (mut along, mut norm) = (0.0, 0.0);
    for (start, true_delta) in probe.starts.iter().zip(probe.true_deltas.chunks_exact(s)) {
        model.fast.rollout_means(start, &probe.actions, &betas, 2, 1, None, &mut predicted, &mut scratch);
        for (d, t) in true_delta.iter().enumerate() {
            along += ((predicted[d] - predicted[s + d]) * t) as f64;
            norm += (t * t) as f64;
        }
    }
    if norm > 0.0 {
        along / norm
    } else {
        f64::NAN
    }
}

/// Per-step MSE of open-loop predictions with context `beta`, averaged over the validation rollouts.
fn mse_by_horizon(model: &LoadedModel, beta: &[f32], validation: &[Rollout], steps: usize) -> Vec<f64> {
    let errors: Vec<Vec<f64>> = validation.iter().map(|r| prediction_errors(model, beta, r)).collect();
    (0..steps).map(|t| errors.iter().map(|e| e[t]).sum::<f64>() / errors.len() as f64).collect()
}

/// Wilcoxon signed-rank tests of open-loop and MPC against random and of MPC against open-loop, on the per-context
/// values `metric(strategy index)`, for the strategies that were run; one CSV row each.
fn paired_tests(
    strategies: &[Strategy],
    metric: &dyn Fn(usize) -> Vec<f64>,
    alternative: Alternative,
    label: &str,
) -> Result<Vec<PairTest>> {
    let position = |s: Strategy| strategies.iter().position(|x| *x == s);
    let mut tests = Vec::new();
    for (better, worse) in
        [(Strategy::OpenLoop, Strategy::Random), (Strategy::Mpc, Strategy::Random), (Strategy::Mpc, Strategy::OpenLoop)]
    {
        let (Some(a), Some(b)) = (position(better), position(worse)) else { continue };
        let result = wilcoxon_signed_rank(&metric(a), &metric(b), alternative)?;
        tests.push(PairTest {
            better,
            worse,
            label: label.into(),
            n: result.n,
            statistic: result.statistic,
            p_value: result.p_value,
        });
    }
    Ok(tests)
}

/// The figures of the report from what every context gave.
fn summarize(
    model: &LoadedModel,
    env: &EnvName,
    settings: &ContextEvalSettings,
    provenance: &Provenance,
    outcomes: Vec<Vec<Outcome>>,
    no_calibration: Vec<NoCalibration>,
    ground_truth_returns: Vec<f64>,
) -> Result<ContextEvalSummary> {
    let strategies = &settings.strategies;
    let per_context_mse =
        |j: usize| -> Vec<f64> { outcomes.iter().map(|o| mean(&o[j].mse_by_horizon).unwrap_or(f64::NAN)).collect() };
    let mean_mse: Vec<f64> = (0..strategies.len()).map(|j| mean(&per_context_mse(j)).unwrap_or(f64::NAN)).collect();
    let empty_per_context: Vec<f64> =
        no_calibration.iter().map(|n| mean(&n.mse_by_horizon).unwrap_or(f64::NAN)).collect();
    let empty_context_mse = mean(&empty_per_context).unwrap_or(f64::NAN);
    let prior_entropy = gaussian_entropy(&model.fast.belief(&model.fast.pool(&[]), 1).std);
    let action_response: Vec<f64> = (0..strategies.len())
        .map(|j| median(&outcomes.iter().map(|o| o[j].action_response).collect::<Vec<_>>()))
        .collect();
    let empty_context_action_response = median(&no_calibration.iter().map(|n| n.action_response).collect::<Vec<_>>());
    // Paired one-sided tests between strategies, per context: lower MSE, and (pendulum) higher swing-up return.
    let tests = paired_tests(strategies, &per_context_mse, Alternative::Less, "MSE lower")?;
    let against_empty = (0..strategies.len())
        .map(|j| Ok(wilcoxon_signed_rank(&per_context_mse(j), &empty_per_context, Alternative::Less)?.p_value))
        .collect::<Result<Vec<f64>>>()?;
    let swingup = if settings.swingup.is_some() {
        let per_context_return =
            |j: usize| -> Vec<f64> { outcomes.iter().map(|o| o[j].swingup_return.unwrap_or(f64::NAN)).collect() };
        let tests = paired_tests(strategies, &per_context_return, Alternative::Greater, "swing-up return higher")?;
        Some(SwingupSummary {
            mean_return: (0..strategies.len()).map(|j| mean(&per_context_return(j)).unwrap_or(f64::NAN)).collect(),
            ground_truth_mean_return: mean(&ground_truth_returns).unwrap_or(f64::NAN),
            tests,
        })
    } else {
        None
    };
    let toy = if let EnvName::Toy(sq) = env {
        let actions: Vec<f64> = (0..=80).map(|i| -2.0 + 0.05 * i as f64).collect();
        let entropies = entropy_after_one_action(model, &actions, 20, 11);
        let informative = |a: f64| sq.name() == "inner" && a.abs() < 0.9 || sq.name() == "outer" && a.abs() > 1.1;
        let non_informative = |a: f64| sq.name() == "inner" && a.abs() > 1.1 || sq.name() == "outer" && a.abs() < 0.9;
        let pick = |f: &dyn Fn(f64) -> bool| {
            mean(&actions.iter().zip(&entropies).filter(|(a, _)| f(**a)).map(|(_, e)| *e).collect::<Vec<_>>())
                .unwrap_or(f64::NAN)
        };
        Some(ToyEntropy {
            informative: pick(&informative),
            non_informative: pick(&non_informative),
            prior: gaussian_entropy(&model.fast.belief(&vec![0.0; model.fast.transition_features], 1).std),
            curve: actions.iter().copied().zip(entropies.iter().copied()).collect(),
        })
    } else {
        None
    };
    Ok(ContextEvalSummary {
        provenance: provenance.clone(),
        settings: settings.clone(),
        env: env.canonical(),
        model: model.progress.name_model(&model.dir),
        angular: model.run.details.model.angular.iter().any(|a| *a),
        prior_entropy,
        outcomes,
        no_calibration,
        ground_truth_returns,
        mean_mse,
        empty_context_mse,
        action_response,
        empty_context_action_response,
        tests,
        against_empty,
        swingup,
        toy,
    })
}

fn test_row(t: &PairTest) -> Vec<String> {
    vec![
        format!("{} ({})", t.better.name(), t.label),
        t.worse.name().to_string(),
        t.n.to_string(),
        format!("{}", t.statistic),
        format!("{:.4e}", t.p_value),
    ]
}

/// Writes per_context.csv, mse_vs_horizon.csv/.png, wilcoxon.csv, the toy's entropy_vs_action.csv/.png and
/// report.md of `summary` into `dir`.
pub fn render(summary: &ContextEvalSummary, dir: &Path) -> Result<()> {
    let settings = &summary.settings;
    let strategies = &settings.strategies;
    let (outcomes, no_calibration) = (&summary.outcomes, &summary.no_calibration);
    if outcomes.is_empty() || outcomes.iter().any(|o| o.len() != strategies.len()) {
        return Err(Error::config(format!(
            "outcomes: expected {} per context over at least one context",
            strategies.len()
        )));
    }
    let horizon = settings.validation_steps;
    if outcomes
        .iter()
        .flatten()
        .map(|o| &o.mse_by_horizon)
        .chain(no_calibration.iter().map(|n| &n.mse_by_horizon))
        .any(|m| m.len() != horizon)
        || no_calibration.len() != outcomes.len()
    {
        return Err(Error::config(format!("mse_by_horizon: expected {horizon} values per context")));
    }
    let empty_per_context: Vec<f64> =
        no_calibration.iter().map(|n| mean(&n.mse_by_horizon).unwrap_or(f64::NAN)).collect();
    let prior_entropy = summary.prior_entropy;
    let file = |name: &str| dir.join(name);

    // Per-context table.
    let mut rows = Vec::new();
    for (k, o) in outcomes.iter().enumerate() {
        rows.push(vec![
            k.to_string(),
            EMPTY_CONTEXT.to_string(),
            format!("{:.6e}", empty_per_context[k]),
            format!("{prior_entropy:.4}"),
            String::new(),
            String::new(),
            format!("{:.4}", no_calibration[k].action_response),
        ]);
        for (j, s) in strategies.iter().enumerate() {
            rows.push(vec![
                k.to_string(),
                s.name().to_string(),
                format!("{:.6e}", mean(&o[j].mse_by_horizon).unwrap_or(f64::NAN)),
                format!("{:.4}", o[j].final_entropy),
                o[j].quadrants.map(|q| q.to_string()).unwrap_or_default(),
                o[j].swingup_return.map(|r| format!("{r:.3}")).unwrap_or_default(),
                format!("{:.4}", o[j].action_response),
            ]);
        }
    }
    write_csv(
        &file("per_context.csv"),
        &["context", "strategy", "mean_mse", "final_entropy", "quadrants", "swingup_return", "action_response"],
        &rows,
    )?;

    // MSE against the horizon.
    let by_horizon: Vec<Vec<f64>> = (0..strategies.len())
        .map(|j| {
            (0..horizon)
                .map(|t| outcomes.iter().map(|o| o[j].mse_by_horizon[t]).sum::<f64>() / outcomes.len() as f64)
                .collect()
        })
        .collect();
    let mut header = vec!["horizon".to_string()];
    header.extend(strategies.iter().map(|s| format!("mse_{}", s.name().replace('-', "_"))));
    header.push(format!("mse_{}", EMPTY_CONTEXT.replace('-', "_")));
    let empty_by_horizon: Vec<f64> = (0..horizon)
        .map(|t| no_calibration.iter().map(|n| n.mse_by_horizon[t]).sum::<f64>() / no_calibration.len() as f64)
        .collect();
    let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let rows: Vec<Vec<String>> = (0..horizon)
        .map(|t| {
            let mut row = vec![(t + 1).to_string()];
            row.extend(by_horizon.iter().map(|v| format!("{:.6e}", v[t])));
            row.push(format!("{:.6e}", empty_by_horizon[t]));
            row
        })
        .collect();
    write_csv(&file("mse_vs_horizon.csv"), &header_refs, &rows)?;
    let curve = |v: &[f64]| v.iter().enumerate().map(|(t, m)| ((t + 1) as f64, *m)).collect();
    let mut series: Vec<Series> =
        strategies.iter().zip(&by_horizon).map(|(s, v)| Series { name: s.name().into(), points: curve(v) }).collect();
    series.push(Series { name: "no calibration (empty context)".into(), points: curve(&empty_by_horizon) });
    rising_line_plot(
        &file("mse_vs_horizon.png"),
        &format!("{}: prediction MSE after calibration ({} contexts)", summary.env, outcomes.len()),
        "prediction horizon [steps]",
        "MSE (model space, mean over dims)",
        &series,
    )?;

    let mut test_rows: Vec<Vec<String>> = summary.tests.iter().map(test_row).collect();
    if let Some(sw) = &summary.swingup {
        test_rows.extend(sw.tests.iter().map(test_row));
    }
    write_csv(&file("wilcoxon.csv"), &["better", "than", "n_nonzero", "statistic", "p_value_one_sided"], &test_rows)?;

    if let Some(toy) = &summary.toy {
        write_csv(
            &file("entropy_vs_action.csv"),
            &["action", "entropy"],
            &toy.curve.iter().map(|(a, e)| vec![format!("{a:.2}"), format!("{e:.5}")]).collect::<Vec<_>>(),
        )?;
        line_plot(
            &file("entropy_vs_action.png"),
            &format!("{}: entropy of q(β | one transition from s = 0) vs action", summary.env),
            "action a",
            "entropy [nats]",
            &[Series { name: "learned model".into(), points: toy.curve.clone() }],
        )?;
    }
    write_text(&file("report.md"), &markdown(summary))
}

fn markdown(summary: &ContextEvalSummary) -> String {
    let settings = &summary.settings;
    let strategies = &settings.strategies;
    let outcomes = &summary.outcomes;
    let swingup = &summary.swingup;
    let mut md = String::new();
    let c = &settings.calibration;
    let _ = writeln!(md, "# Explore the Context: calibration on {}\n", summary.env);
    let _ = writeln!(
        md,
        "Model {}. {} unseen contexts (instances), per context {} random validation rollouts of {} \
         steps; every strategy starts from the same state and collects {} transitions. EIG planning: CEM {} candidates / \
         {} elites / {} iterations, {} β samples, MPC horizon min({}, N − n). Predictions: open loop from each validation \
         rollout's first state with the mean of q(β | calibration transitions); error = squared error averaged over the \
         model-space state dimensions{}.\n",
        summary.model,
        outcomes.len(),
        settings.validation_rollouts,
        settings.validation_steps,
        c.transitions,
        c.candidates,
        c.elites,
        c.iterations,
        c.beta_samples,
        c.horizon_max,
        if summary.angular { " (angles as cos, sin)" } else { "" }
    );
    let has_quadrants = outcomes[0][0].quadrants.is_some();
    let _ = writeln!(
        md,
        "| strategy | mean MSE | median final entropy [nats] | action response (model / simulator) |{}{}",
        if has_quadrants { " contexts visiting all 4 quadrants |" } else { "" },
        if swingup.is_some() { " mean swing-up return |" } else { "" }
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|{}{}",
        if has_quadrants { "---|" } else { "" },
        if swingup.is_some() { "---|" } else { "" }
    );
    let _ = writeln!(
        md,
        "| no calibration (empty context, reference) | {:.4e} | {:.3} | \
         {:.3} |{}{}",
        summary.empty_context_mse,
        summary.prior_entropy,
        summary.empty_context_action_response,
        if has_quadrants { " - |" } else { "" },
        if swingup.is_some() { " - |" } else { "" }
    );
    for (j, s) in strategies.iter().enumerate() {
        let entropies: Vec<f64> = outcomes.iter().map(|o| o[j].final_entropy).collect();
        let quad = outcomes[0][j].quadrants.map(|_| {
            format!(" {} / {} |", outcomes.iter().filter(|o| o[j].quadrants == Some(4)).count(), outcomes.len())
        });
        let _ = writeln!(
            md,
            "| {} | {:.4e} | {:.3} | {:.3} |{}{}",
            s.name(),
            summary.mean_mse.get(j).copied().unwrap_or(f64::NAN),
            median(&entropies),
            summary.action_response.get(j).copied().unwrap_or(f64::NAN),
            quad.unwrap_or_default(),
            swingup
                .as_ref()
                .map(|sw| format!(" {:.1} |", sw.mean_return.get(j).copied().unwrap_or(f64::NAN)))
                .unwrap_or_default()
        );
    }
    if let (Some(sw), Some(settings)) = (swingup, &settings.swingup) {
        let _ = writeln!(
            md,
            "\nSwing-up after calibration (thesis 4.5.3): MPC on the model conditioned on each strategy's transitions \
             (context mean), {} agent steps from hanging, CEM {} / {} / {}, horizon {}, scored by the env's reward in \
             the same instance. Ground truth (CEM on the simulator's own equations, same instances and seeds): mean \
             return {:.1} (thesis: about −215).\n",
            settings.steps,
            settings.cem.candidates,
            settings.cem.elites,
            settings.cem.iterations,
            settings.cem.horizon,
            sw.ground_truth_mean_return
        );
        let _ = writeln!(md, "| higher return | than | p |\n|---|---|---|");
        for t in &sw.tests {
            let _ = writeln!(md, "| {} | {} | {:.3e} |", t.better.name(), t.worse.name(), t.p_value);
        }
    }
    let _ = writeln!(
        md,
        "\nPaired Wilcoxon signed-rank tests on the per-context mean MSE (one-sided: the first strategy lower):\n"
    );
    let _ = writeln!(md, "| lower | than | p |\n|---|---|---|");
    for t in &summary.tests {
        let _ = writeln!(md, "| {} | {} | {:.3e} |", t.better.name(), t.worse.name(), t.p_value);
    }
    for (s, p) in strategies.iter().zip(&summary.against_empty) {
        let _ = writeln!(md, "| {} | no calibration | {p:.3e} |", s.name());
    }
    let _ = writeln!(
        md,
        "\nThe reference row conditions the model on no transitions at all. A strategy no better than it means the \
         model draws nothing usable from that strategy's context set. The action response (median over contexts) \
         compares the model's one-step prediction under the highest minus the middle action with the simulator's, \
         from every validation state: 1 is the true response, 0 a model that ignores the action."
    );
    if let Some(toy) = &summary.toy {
        let _ = writeln!(
            md,
            "\nEntropy after one transition from s = 0 (model-imagined next state, 20 prior β samples; Fig. 4.4a): \
             {:.3} nats for informative actions, {:.3} for non-informative ones \
             (prior: {:.3}). See entropy_vs_action.png.",
            toy.informative, toy.non_informative, toy.prior
        );
    }
    let _ = writeln!(
        md,
        "\nFiles: per_context.csv, mse_vs_horizon.csv/.png, wilcoxon.csv{}.",
        if summary.toy.is_some() { ", entropy_vs_action.csv/.png" } else { "" }
    );
    md
}

/// The median of the finite values (NaN when there are none).
fn median(values: &[f64]) -> f64 {
    super::stats::quantile(values, 0.5).unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::collect::{collect_instance_pairs, InstancePairSettings};
    use crate::data::write_dataset;
    use crate::envs::toy::Squash;
    use crate::models::context::{self, ContextConfig, EnvFamily, Preset};
    use crate::run::NullMonitor;

    /// The small-scale claims of thesis 4.5.2 on the δ<1 toy: after one calibration transition, open-loop EIG
    /// calibration predicts better than random actions, and an informative action (|u| < 1) leaves a narrower
    /// belief than a non-informative one. A short `small`-preset run (about 20 s in release) must get there.
    #[test]
    fn open_loop_calibration_beats_random_on_the_toy() {
        let dir = tempfile::tempdir().unwrap();
        let env = EnvName::Toy(Squash::Inner);
        let data = dir.path().join("pairs.mcap");
        let collect =
            InstancePairSettings { env: env.clone(), instances: 400, steps: 100, seed: 7, command_line: String::new() };
        write_dataset(&data, &collect_instance_pairs(&collect, &NullMonitor).unwrap()).unwrap();
        let mut config = ContextConfig::preset(Preset::Small, EnvFamily::Toy);
        config.steps = 1000;
        let provenance = Provenance::new(String::new(), 3, 1);
        let request = crate::train::Request::<context::Context> {
            env: None,
            data: vec![data],
            seed: 3,
            config,
            variant: (),
            provenance: provenance.clone(),
        };
        let out = dir.path().join("model");
        crate::train::job::start(&out, &request, &NullMonitor).unwrap();
        let model = context::load(&out, &env, crate::train::Accept::Finished).unwrap();
        let settings = ContextEvalSettings {
            contexts: 20,
            validation_rollouts: 10,
            validation_steps: 30,
            strategies: vec![Strategy::Random, Strategy::OpenLoop],
            calibration: CalibrationSettings {
                candidates: 100,
                elites: 10,
                iterations: 4,
                ..CalibrationSettings::thesis(Strategy::Random, 1, 1)
            },
            swingup: None,
        };
        let config = ContextEvalConfig { model: out.clone(), env: env.canonical(), allow_incomplete: false, settings };
        let summary = evaluate(&model, &env, &config, &provenance, &dir.path().join("eval"), &NullMonitor).unwrap();
        let (better, worse, p) = (summary.tests[0].better, summary.tests[0].worse, summary.tests[0].p_value);
        assert_eq!((better, worse), (Strategy::OpenLoop, Strategy::Random));
        assert!(p < 0.05, "open-loop vs random: p = {p}, mean MSE {:?}", summary.mean_mse);
        let toy = summary.toy.as_ref().unwrap();
        let (informative, non_informative) = (toy.informative, toy.non_informative);
        assert!(informative < non_informative, "entropy {informative} (informative) vs {non_informative}");
        // Without a context the model cannot know the sign of α, so it predicts little action effect (the
        // median over contexts is noisy where α is near 0); one informative transition tells it.
        let (empty, open_loop) = (summary.empty_context_action_response, summary.action_response[1]);
        assert!(
            open_loop > 0.6 && open_loop - empty > 0.4,
            "action response: no context {empty}, open-loop {open_loop}"
        );
    }
}
