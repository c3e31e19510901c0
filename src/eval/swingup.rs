//! Pendulum swing-up from the hanging position with MPC (thesis 3.5.2): success means each of the last
//! 25 of 150 rewards is above −1.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::num;
use super::plot::{histogram, line_plot, wrapped_angle_trace, Series};
use super::stats::{mean, quantile};
use super::summary::{publish, write_config};
use crate::control::BatchDynamics;
use crate::data::{write_dataset, Dataset, DatasetLayout, DatasetMeta, Rollout};
use crate::envs::pendulum::{angle_normalize, Pendulum, PendulumVariant, StartDistribution};
use crate::envs::Env;
use crate::error::Result;
use crate::planning::mpc::run_mpc_episode;
use crate::planning::{Cem, CemConfig};
use crate::run::dir::{Provenance, RunDir};
use crate::run::{Event, Monitor, PanelSpec, Tee};
use crate::util::atomic::write_text;
use crate::util::seeding::{derive_seed, rng_for};
use crate::util::table::write_csv;

use crate::envs::pendulum::swingup::{is_success, SUCCESS_MIN_REWARD, SUCCESS_WINDOW};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SwingupSettings {
    #[serde(serialize_with = "serialize_variant", deserialize_with = "deserialize_variant")]
    pub variant: PendulumVariant,
    pub cem: CemConfig,
    pub steps: usize,
    /// Plan in the instance this seed names (`--instance-seed`) instead of drawing one per episode.
    pub instance_seed: Option<u64>,
}

fn serialize_variant<S: serde::Serializer>(v: &PendulumVariant, s: S) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_str(&v.env_name())
}

fn deserialize_variant<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<PendulumVariant, D::Error> {
    let name = String::deserialize(d)?;
    match crate::envs::parse_env(&name).map_err(serde::de::Error::custom)? {
        crate::envs::EnvName::Pendulum(v) => Ok(v),
        other => Err(serde::de::Error::custom(format!("'{}' is not a pendulum env", other.canonical()))),
    }
}

impl SwingupSettings {
    /// Thesis settings: horizon 20, 1000 candidates, 100 elites, 10 iterations, 150 steps.
    pub fn thesis(variant: PendulumVariant) -> Self {
        let params = variant.fixed_params();
        let cem = CemConfig::for_box(&[-params.max_torque], &[params.max_torque]);
        SwingupSettings { variant, cem, steps: 150, instance_seed: None }
    }
}

pub struct SwingupEpisode {
    pub episode: u64,
    pub instance: serde_json::Value,
    pub rollout: Rollout,
    pub total_return: f64,
    pub success: bool,
}

/// The live-view panels of a swing-up job; with a learned model, also its one-step predictions beside what
/// happened.
pub fn layout(title: &str, learned_model: bool) -> Event {
    let mut panels = vec![
        PanelSpec {
            title: "pendulum (current episode)".into(),
            x_label: "step".into(),
            series: vec!["pendulum/angle".into(), "pendulum/action".into()],
            restart_on_rewind: true,
            path: None,
        },
        PanelSpec {
            title: "CEM (current MPC step)".into(),
            x_label: "iteration".into(),
            series: vec!["cem/best_cost".into(), "cem/elite_mean_cost".into()],
            restart_on_rewind: true,
            path: None,
        },
    ];
    if learned_model {
        panels.push(PanelSpec {
            title: "model: predicted vs executed angle".into(),
            x_label: "step".into(),
            series: vec!["model/predicted_angle".into(), "model/executed_angle".into()],
            restart_on_rewind: true,
            path: None,
        });
    }
    Event::Layout { title: title.to_string(), panels }
}

/// Runs one MPC swing-up, planning on `model` (`None`: the simulator's own equations). Episode `k` under
/// `seed` always starts from the same state and samples the same candidates.
pub fn run_episode(
    settings: &SwingupSettings,
    model: Option<&dyn BatchDynamics>,
    seed: u64,
    episode: u64,
    monitor: &dyn Monitor,
) -> Result<SwingupEpisode> {
    let model_is_learned = model.is_some();
    let mut env = Pendulum::new(settings.variant.clone()).with_start(StartDistribution::Hanging);
    let mut rng = rng_for(seed, &[episode, 0]);
    env.sample_instance(&mut rng);
    if let Some(instance_seed) = settings.instance_seed {
        let named =
            crate::envs::instance_env(&crate::envs::EnvName::Pendulum(settings.variant.clone()), instance_seed)?;
        let params = serde_json::from_value(named.params())
            .map_err(|e| crate::error::Error::config(format!("instance {instance_seed}: {e}")))?;
        env.set_params(params);
    }
    env.reset(&mut rng);
    let truth = env.pendulum_dynamics();
    let model: &dyn BatchDynamics = match model {
        Some(m) => m,
        None => &truth,
    };
    let mut cem = Cem::new(settings.cem.clone(), derive_seed(seed, &[episode, 1]))?;
    let phase = format!("episode {} MPC", episode + 1);
    let rollout = run_mpc_episode(
        &mut env,
        model,
        &mut cem,
        settings.steps,
        derive_seed(seed, &[episode, 2]),
        monitor,
        |_, it| {
            monitor.scalar("cem/best_cost", it.iteration as u64, it.best_cost);
            monitor.scalar("cem/elite_mean_cost", it.iteration as u64, it.elite_mean_cost);
        },
        |step| {
            let t = step.t as u64;
            monitor.scalar("pendulum/angle", t, angle_normalize(step.state[0]));
            monitor.scalar("pendulum/action", t, step.action[0]);
            if model_is_learned {
                monitor.scalar("model/predicted_angle", t + 1, angle_normalize(step.predicted_next[0]));
                monitor.scalar("model/executed_angle", t + 1, angle_normalize(step.next_state[0]));
            }
            monitor.progress(&phase, t + 1, settings.steps as u64);
        },
    )?;
    let total_return = rollout.total_reward();
    let success = is_success(&rollout.rewards);
    monitor.scalar("episode/return", episode, total_return);
    Ok(SwingupEpisode { episode, instance: env.params(), rollout, total_return, success })
}

/// Packs executed episodes as a dataset, so planner runs can be inspected like collected data.
pub fn episodes_dataset(
    settings: &SwingupSettings,
    seed: u64,
    command_line: &str,
    episodes: &[SwingupEpisode],
) -> Dataset {
    let env = Pendulum::new(settings.variant.clone());
    let spec = env.spec();
    Dataset {
        meta: DatasetMeta::for_env(
            &spec,
            seed,
            command_line,
            episodes.iter().map(|e| e.instance.clone()).collect(),
            DatasetLayout::Rollouts,
        ),
        steps: episodes.iter().flat_map(|e| e.rollout.timesteps(e.episode as u32)).collect(),
        frames: Vec::new(),
    }
}

pub const PROTOCOL: &str = "pendulum-swingup";

/// Which dynamics the planner used, as the command named them (`true` or a checkpoint directory).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    pub model: String,
    pub particles: usize,
    /// ts1, tsinf or expectation.
    pub propagation: String,
    pub context: Option<std::path::PathBuf>,
    pub allow_incomplete: bool,
}

/// `mbrl eval pendulum-swingup`'s settings, as config.json records them.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwingupConfig {
    pub model: ModelSpec,
    pub env: String,
    pub episodes: usize,
    pub settings: SwingupSettings,
}

impl SwingupConfig {
    /// Swing-ups planned on the simulator's own equations.
    pub fn ground_truth(settings: SwingupSettings, episodes: usize) -> Self {
        SwingupConfig {
            model: ModelSpec {
                model: "true".into(),
                particles: 20,
                propagation: "tsinf".into(),
                context: None,
                allow_incomplete: false,
            },
            env: settings.variant.env_name(),
            episodes,
            settings,
        }
    }

    /// The range checks the protocol needs before anything is loaded.
    pub fn validate(&self) -> Result<()> {
        if self.episodes == 0 || self.settings.steps < SUCCESS_WINDOW {
            return Err(crate::error::Error::config(format!(
                "--episodes must be at least 1 and --steps at least {SUCCESS_WINDOW}"
            )));
        }
        self.settings.cem.validate()
    }
}

/// One executed episode, as the report shows it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EpisodeRecord {
    pub episode: u64,
    #[serde(with = "num::real")]
    pub total_return: f64,
    pub success: bool,
    /// The pole angle θ at every state (unwrapped, as simulated).
    #[serde(with = "num::reals")]
    pub angles: Vec<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SwingupSummary {
    pub provenance: Provenance,
    pub settings: SwingupSettings,
    /// What the planner planned on, in words.
    pub model: String,
    pub episodes: Vec<EpisodeRecord>,
}

impl SwingupSummary {
    pub fn returns(&self) -> Vec<f64> {
        self.episodes.iter().map(|e| e.total_return).collect()
    }

    pub fn successes(&self) -> usize {
        self.episodes.iter().filter(|e| e.success).count()
    }

    pub fn mean_return(&self) -> f64 {
        self.returns().iter().sum::<f64>() / self.episodes.len() as f64
    }
}

impl std::fmt::Display for SwingupSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{}/{} episodes succeeded; mean return {:.1}",
            self.successes(),
            self.episodes.len(),
            self.mean_return()
        )
    }
}

/// `mbrl eval pendulum-swingup`: `episodes` MPC swing-ups, written to `report_dir` as report.md,
/// episodes.csv, angle.png, returns.png, rollouts.mcap, config.json and metrics.jsonl.
pub fn evaluate(
    config: &SwingupConfig,
    model: Option<&dyn BatchDynamics>,
    provenance: &Provenance,
    report_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<SwingupSummary> {
    config.validate()?;
    let (settings, episodes) = (&config.settings, config.episodes);
    let run = RunDir::create(report_dir)?;
    write_config(config, provenance, report_dir)?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    monitor.emit(&layout(&format!("pendulum swing-up, {} + CEM", model_description(model)), model.is_some()));
    let mut results = Vec::with_capacity(episodes);
    for k in 0..episodes as u64 {
        monitor.progress("episodes", k, episodes as u64);
        let ep = run_episode(settings, model, provenance.seed, k, &monitor)?;
        monitor.message(&format!(
            "episode {}: return {:.1}, {}",
            k + 1,
            ep.total_return,
            if ep.success { "success" } else { "failure" }
        ));
        results.push(ep);
    }
    monitor.progress("episodes", episodes as u64, episodes as u64);
    write_dataset(
        &run.file("rollouts.mcap"),
        &episodes_dataset(settings, provenance.seed, &provenance.command_line, &results),
    )?;
    let summary = SwingupSummary {
        provenance: provenance.clone(),
        settings: settings.clone(),
        model: model_description(model),
        episodes: results
            .iter()
            .map(|e| EpisodeRecord {
                episode: e.episode,
                total_return: e.total_return,
                success: e.success,
                angles: e.rollout.states.iter().map(|s| s[0]).collect(),
            })
            .collect(),
    };
    publish(PROTOCOL, &summary, run.path(), render)?;
    // Only the run's own file is told it finished: the caller's view may have more jobs to show.
    metrics.emit(&Event::Finished { ok: true });
    Ok(summary)
}

/// What the planner planned on, in words for reports.
pub fn model_description(model: Option<&dyn BatchDynamics>) -> String {
    model.map(|m| m.describe()).unwrap_or_else(|| "ground-truth model".into())
}

/// Writes episodes.csv, angle.png, returns.png and report.md of `summary` into `dir`.
pub fn render(summary: &SwingupSummary, dir: &Path) -> Result<()> {
    let settings = &summary.settings;
    let results = &summary.episodes;
    let file = |name: &str| dir.join(name);
    let rows: Vec<Vec<String>> = results
        .iter()
        .map(|e| {
            let final_angle = e.angles.last().map(|a| angle_normalize(*a)).unwrap_or(f64::NAN);
            vec![
                e.episode.to_string(),
                format!("{:.6}", e.total_return),
                e.success.to_string(),
                format!("{final_angle:.6}"),
            ]
        })
        .collect();
    write_csv(&file("episodes.csv"), &["episode", "return", "success", "final_angle"], &rows)?;
    let dt = Pendulum::new(settings.variant.clone()).spec().dt;
    let series: Vec<Series> = results
        .iter()
        .map(|e| Series {
            name: format!("episode {}", e.episode + 1),
            points: wrapped_angle_trace(e.angles.iter().enumerate().map(|(t, a)| (t as f64 * dt, *a))),
        })
        .collect();
    line_plot(&file("angle.png"), "Pendulum angle during swing-up (0 = upright)", "time [s]", "angle [rad]", &series)?;
    histogram(&file("returns.png"), "Episode returns", "return", &summary.returns(), 10)?;
    let report = report_markdown(settings, &summary.model, &summary.provenance, results);
    write_text(&file("report.md"), &report)
}

fn report_markdown(
    settings: &SwingupSettings,
    model: &str,
    provenance: &Provenance,
    results: &[EpisodeRecord],
) -> String {
    let returns: Vec<f64> = results.iter().map(|e| e.total_return).collect();
    let successes = results.iter().filter(|e| e.success).count();
    let fmt = |v: Option<f64>| v.map(|x| format!("{x:.1}")).unwrap_or_else(|| "–".into());
    let c = &settings.cem;
    let mut md = format!(
        "# Pendulum swing-up: {model} + CEM\n\n\
         Environment `{}`, start θ ∼ U[π−0.05, π+0.05], θ̇ ∼ U[−0.05, 0.05], {} steps.\n\
         CEM: horizon {}, {} candidates, {} elites, {} iterations, {} noise, warm start {}.\n\
         Seed {}, command `{}`.\n\n\
         Success = each of the last {SUCCESS_WINDOW} rewards > {SUCCESS_MIN_REWARD} (thesis 3.5.2).\n\n\
         | episodes | successes | mean return | median return | 10 % | 90 % |\n|---|---|---|---|---|---|\n\
         | {} | {} | {} | {} | {} | {} |\n\n",
        settings.variant.env_name(),
        settings.steps,
        c.horizon,
        c.candidates,
        c.elites,
        c.iterations,
        c.noise.describe(),
        c.warm_start,
        provenance.seed,
        provenance.command_line,
        results.len(),
        successes,
        fmt(mean(&returns)),
        fmt(quantile(&returns, 0.5)),
        fmt(quantile(&returns, 0.1)),
        fmt(quantile(&returns, 0.9)),
    );
    md.push_str("| episode | return | success |\n|---|---|---|\n");
    for e in results {
        md.push_str(&format!(
            "| {} | {:.1} | {} |\n",
            e.episode + 1,
            e.total_return,
            if e.success { "yes" } else { "no" }
        ));
    }
    md.push_str("\n![angle over time](angle.png)\n\n![returns](returns.png)\n\nPer-episode values: `episodes.csv`; executed rollouts: `rollouts.mcap`.\n");
    md
}
