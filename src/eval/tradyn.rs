//! `mbrl eval tradyn`: the protocol of thesis 5.5 at a chosen scale. Per task (a test map, a robot of Table 5.1,
//! start and goal in [0.1, 0.9]², heading U[−π, π], at rest): 10 random colored calibration transitions from the
//! start, then navigation with each of the four variants ±terrain lookup (two trained models) × ±calibration
//! (the calibration's context or none) on the same task with the same planner seed. Reports control energy,
//! final distance and failures (Table 5.2), pairwise Wilcoxon signed-rank tests on energies (Fig. 5.7), open-loop
//! prediction errors against the horizon on a random rollout per task (Fig. 5.5), and example paths (Fig. 5.6).

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use base64::Engine;
use rand::Rng;
use serde::{Deserialize, Serialize};

use super::num;
use super::plot::{band_panels, map_paths, Band, ColorGrid, MapPanel, Series};
use super::stats::{quantile, wilcoxon_signed_rank, Alternative};
use super::summary::{publish, write_config};
use crate::control::BatchDynamics;
use crate::data::collect::exploration_actions;
use crate::data::Rollout;
use crate::envs::terrain::TerrainMap;
use crate::envs::unicycle::{Unicycle, UnicycleTerrain};
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::models::context::calibration::{calibrate, context_rows, CalibrationSettings, Strategy};
use crate::models::tradyn::navigation::{navigate, NavigationSettings, NavigationTask};
use crate::models::tradyn::{TradynDynamics, TradynModel};
use crate::run::dir::{Provenance, RunDir};
use crate::run::{Event, Monitor, NullMonitor, PanelSpec, Tee};
use crate::util::atomic::write_text;
use crate::util::seeding::{derive_seed, rng_for};
use crate::util::table::write_csv;

const TASK_STREAM: u64 = 1;
const CALIBRATION_STREAM: u64 = 2;
const NAVIGATION_STREAM: u64 = 3;
const PREDICTION_STREAM: u64 = 4;
/// Cells per side of the maps drawn under example paths.
const PLOT_CELLS: usize = 115;

#[derive(Clone, Debug, Serialize)]
pub struct TradynEvalSettings {
    pub tasks: usize,
    /// Random colored calibration transitions from each task's start (thesis: 10).
    pub calibration_transitions: usize,
    pub navigation: NavigationSettings,
    /// Length of the random rollout per task whose open-loop prediction is scored (Fig. 5.5: 50).
    pub prediction_steps: usize,
    /// Tasks whose paths are drawn (Fig. 5.6).
    pub example_tasks: usize,
}

impl TradynEvalSettings {
    pub fn validate(&self) -> Result<()> {
        if self.tasks < 2 || self.calibration_transitions == 0 || self.prediction_steps == 0 {
            return Err(Error::config(
                "eval tradyn needs at least 2 tasks, 1 calibration transition and a prediction rollout of ≥ 1 step",
            ));
        }
        self.navigation.validate()
    }
}

/// The four variants in Table 5.2's order: (terrain lookup, calibration).
pub const VARIANTS: [(bool, bool); 4] = [(false, false), (false, true), (true, false), (true, true)];

pub fn variant_name((terrain, calibrated): (bool, bool)) -> String {
    format!("{}T,{}C", if terrain { "+" } else { "−" }, if calibrated { "+" } else { "−" })
}

pub const PROTOCOL: &str = "tradyn";

/// `mbrl eval tradyn`'s settings, as config.json records them (the command's flags).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TradynEvalConfig {
    pub model_terrain: std::path::PathBuf,
    pub model_no_terrain: std::path::PathBuf,
    pub maps: std::path::PathBuf,
    pub allow_incomplete: bool,
    pub tasks: usize,
    pub transitions: usize,
    pub steps: usize,
    pub horizon: usize,
    pub candidates: usize,
    pub elites: usize,
    pub iters: usize,
    pub prediction_steps: usize,
}

impl TradynEvalConfig {
    /// The protocol's settings; the command's range checks first.
    pub fn settings(&self) -> Result<TradynEvalSettings> {
        if !(2..=100_000).contains(&self.tasks)
            || !(1..=10_000).contains(&self.steps)
            || !(1..=10_000).contains(&self.prediction_steps)
        {
            return Err(Error::config("--tasks must be 2..=100000, --steps and --prediction-steps 1..=10000"));
        }
        if !(1..=1000).contains(&self.transitions) {
            return Err(Error::config("--transitions must be 1..=1000"));
        }
        let mut navigation = NavigationSettings::thesis();
        navigation.steps = self.steps;
        navigation.horizon = self.horizon;
        navigation.cem.candidates = self.candidates;
        navigation.cem.elites = self.elites;
        navigation.cem.iterations = self.iters;
        let settings = TradynEvalSettings {
            tasks: self.tasks,
            calibration_transitions: self.transitions,
            navigation,
            prediction_steps: self.prediction_steps,
            example_tasks: 3,
        };
        settings.validate()?;
        Ok(settings)
    }
}

/// The settings as the report states them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ReportedSettings {
    pub calibration_transitions: usize,
    pub candidates: usize,
    pub elites: usize,
    pub iterations: usize,
    pub horizon: usize,
    pub steps: usize,
    pub success_distance: f64,
    pub prediction_steps: usize,
}

/// What one variant did on one task.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Outcome {
    #[serde(with = "num::real")]
    pub energy: f64,
    #[serde(with = "num::real")]
    pub final_distance: f64,
    pub success: bool,
    #[serde(with = "num::points")]
    pub path: Vec<(f64, f64)>,
    /// Per prediction step: position error (m), speed error (m/s), heading error (rad).
    #[serde(with = "num::triples")]
    pub prediction: Vec<[f64; 3]>,
}

struct Task {
    map: Arc<TerrainMap>,
    task: NavigationTask,
    outcomes: Vec<Outcome>,
}

/// One navigation task and what the four variants did on it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TaskRecord {
    pub map: String,
    /// x, y, heading.
    pub start: [f64; 3],
    pub goal: [f64; 2],
    /// In VARIANTS order.
    pub outcomes: [Outcome; 4],
    /// The map's colours on a PLOT_CELLS² grid (RGB bytes, base64), for the tasks whose paths are drawn.
    pub map_rgb: Option<String>,
}

/// A pairwise energy test (Fig. 5.7): row − column differences over tasks and the one-sided p that the row
/// variant uses less energy.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EnergyTest {
    pub row: usize,
    pub column: usize,
    #[serde(with = "num::real")]
    pub diff_p20: f64,
    #[serde(with = "num::real")]
    pub diff_median: f64,
    #[serde(with = "num::real")]
    pub diff_p80: f64,
    #[serde(with = "num::real")]
    pub p_value: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TradynEvalSummary {
    pub provenance: Provenance,
    pub settings: ReportedSettings,
    /// The two checkpoints and how far each was trained.
    pub models: String,
    pub tasks: Vec<TaskRecord>,
    /// Per variant (VARIANTS order): median energy, median final distance (m), failures.
    #[serde(with = "num::quad")]
    pub median_energy: [f64; 4],
    #[serde(with = "num::quad")]
    pub median_distance: [f64; 4],
    pub failures: [usize; 4],
    /// Mean position error over the prediction horizon and tasks, per variant.
    #[serde(with = "num::quad")]
    pub mean_position_error: [f64; 4],
    /// Every ordered pair of distinct variants.
    pub energy_tests: Vec<EnergyTest>,
    /// One-sided p-values that terrain lookup lowers the per-task mean position error: (−C, +C).
    #[serde(with = "num::opt_pair")]
    pub prediction_tests: Option<(f64, f64)>,
}

/// A p-value as the reports print it; a test with no non-zero difference (every task equal) has none, shown
/// as "—" rather than NaN.
fn p_shown(p: f64, digits: usize) -> String {
    if p.is_nan() {
        "— (no non-zero difference)".to_string()
    } else {
        format!("{p:.digits$e}")
    }
}

impl std::fmt::Display for TradynEvalSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        for (v, variant) in VARIANTS.iter().enumerate() {
            writeln!(
                f,
                "{:<6} median energy {:.4}, median final distance {:.2} mm, failed {}/{}, mean position error {:.4} m",
                variant_name(*variant),
                self.median_energy[v],
                self.median_distance[v] * 1000.0,
                self.failures[v],
                self.tasks.len(),
                self.mean_position_error[v]
            )?;
        }
        let (without, with) = self.prediction_tests.unwrap_or((f64::NAN, f64::NAN));
        write!(
            f,
            "Wilcoxon: terrain lookup lowers the mean position error: p = {} without calibration, {} with it",
            p_shown(without, 3),
            p_shown(with, 3)
        )?;
        for t in &self.energy_tests {
            if t.row > t.column && t.row < VARIANTS.len() {
                write!(
                    f,
                    "\nWilcoxon: {} less energy than {}: p = {}",
                    variant_name(VARIANTS[t.row]),
                    variant_name(VARIANTS[t.column]),
                    p_shown(t.p_value, 3)
                )?;
            }
        }
        Ok(())
    }
}

/// The two trained models the variants come from: with terrain lookup (+T) and the ablation (−T).
pub struct TradynEvalModels {
    pub terrain: TradynModel,
    pub no_terrain: TradynModel,
}

impl TradynEvalModels {
    pub fn check(&self) -> Result<()> {
        if !self.terrain.terrain_lookup() {
            return Err(Error::bad_file(
                &self.terrain.loaded.dir,
                "was trained without terrain lookup (--no-terrain); the +T variants need a model trained with it",
            ));
        }
        if self.no_terrain.terrain_lookup() {
            return Err(Error::bad_file(
                &self.no_terrain.loaded.dir,
                "reads terrain at predicted positions; the −T variants need a model trained with --no-terrain",
            ));
        }
        Ok(())
    }

    /// Which checkpoints the report compares, and how far each was trained.
    fn describe(&self) -> String {
        let one = |m: &TradynModel| m.loaded.progress.name_model(&m.loaded.dir);
        format!("+T: {}; −T: {}", one(&self.terrain), one(&self.no_terrain))
    }

    fn of(&self, terrain: bool) -> &TradynModel {
        if terrain {
            &self.terrain
        } else {
            &self.no_terrain
        }
    }
}

/// The live view: tasks done, and the energies and distances of the latest task per variant.
fn layout(title: &str) -> Event {
    let series = |what: &str| VARIANTS.iter().map(|v| format!("{what}/{}", variant_name(*v))).collect();
    Event::Layout {
        title: title.into(),
        panels: vec![
            PanelSpec {
                title: "control energy Σ throttle² per task".into(),
                x_label: "task".into(),
                series: series("energy"),
                restart_on_rewind: false,
                path: None,
            },
            PanelSpec {
                title: "final distance to goal (m) per task".into(),
                x_label: "task".into(),
                series: series("distance"),
                restart_on_rewind: false,
                path: None,
            },
        ],
    }
}

/// Runs the protocol on the test maps `maps` and writes report.md, CSVs and PNGs into `report_dir`.
pub fn evaluate(
    models: &TradynEvalModels,
    maps: Vec<TerrainMap>,
    config: &TradynEvalConfig,
    provenance: &Provenance,
    report_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<TradynEvalSummary> {
    let settings = &config.settings()?;
    models.check()?;
    if maps.is_empty() {
        return Err(Error::config("eval tradyn needs at least one test map"));
    }
    let run = RunDir::create(report_dir)?;
    write_config(config, provenance, run.path())?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    monitor.emit(&layout("eval tradyn: ±terrain lookup × ±calibration"));
    let seed = provenance.seed;
    let terrain = Arc::new(UnicycleTerrain::new(maps));
    let mut tasks = Vec::with_capacity(settings.tasks);
    for k in 0..settings.tasks as u64 {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        monitor.progress("tasks", k, settings.tasks as u64);
        let task = run_task(models, &terrain, settings, seed, k, &monitor)?;
        for (v, o) in VARIANTS.iter().zip(&task.outcomes) {
            monitor.scalar(&format!("energy/{}", variant_name(*v)), k + 1, o.energy);
            monitor.scalar(&format!("distance/{}", variant_name(*v)), k + 1, o.final_distance);
        }
        tasks.push(task);
    }
    monitor.progress("tasks", settings.tasks as u64, settings.tasks as u64);
    let summary = summarize(settings, models.describe(), provenance, tasks)?;
    publish(PROTOCOL, &summary, run.path(), render)?;
    Ok(summary)
}

fn run_task(
    models: &TradynEvalModels,
    terrain: &Arc<UnicycleTerrain>,
    settings: &TradynEvalSettings,
    seed: u64,
    k: u64,
    monitor: &dyn Monitor,
) -> Result<Task> {
    let mut rng = rng_for(seed, &[TASK_STREAM, k]);
    let mut env = Unicycle::new(terrain.clone());
    env.sample_instance(&mut rng);
    let map = env.unicycle_dynamics().map.clone();
    let mut inner = || rng.random_range(0.1..0.9);
    let (start, goal) = ([inner(), inner()], [inner(), inner()]);
    let heading = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
    let task = NavigationTask { start: [start[0], start[1], heading], goal };

    // One calibration for both models: the same transitions condition +T and −T.
    env.set_state(&task.start_state());
    let calibration_settings = CalibrationSettings {
        strategy: Strategy::Random,
        transitions: settings.calibration_transitions,
        ..CalibrationSettings::thesis(Strategy::Random, settings.calibration_transitions, 1)
    };
    let calibration = calibrate(
        &models.terrain.loaded,
        &mut env,
        &calibration_settings,
        derive_seed(seed, &[CALIBRATION_STREAM, k]),
        &NullMonitor,
        |_| {},
    )?;
    let context = context_rows(&models.terrain.loaded, &calibration.rollout)?;

    // A random rollout of the same robot on the same map, from a reset draw, to score open-loop prediction.
    let mut prediction_rng = rng_for(seed, &[PREDICTION_STREAM, k]);
    env.reset(&mut prediction_rng);
    let actions = exploration_actions(&env, &mut prediction_rng, settings.prediction_steps);
    let mut truth = Rollout::start(env.state(), env.observe());
    for action in &actions {
        let step = env.step(action);
        truth.push(action.clone(), step.reward, env.state(), step.obs);
    }

    let mut outcomes = Vec::with_capacity(VARIANTS.len());
    for (terrain_lookup, calibrated) in VARIANTS {
        let rows = if calibrated { context.as_slice() } else { &[] };
        let dynamics = TradynDynamics::new(models.of(terrain_lookup).clone(), map.clone(), rows);
        let prediction = prediction_errors(&dynamics, &truth);
        let phase = format!("task {}: {}", k + 1, variant_name((terrain_lookup, calibrated)));
        let episode = navigate(
            &mut env,
            &dynamics,
            &task,
            &settings.navigation,
            derive_seed(seed, &[NAVIGATION_STREAM, k]),
            &ProgressOnly { inner: monitor, phase: &phase },
            |_| {},
        )?;
        outcomes.push(Outcome {
            energy: episode.energy,
            final_distance: episode.final_distance,
            success: episode.success,
            path: episode.rollout.states.iter().map(|s| (s[0], s[1])).collect(),
            prediction,
        });
    }
    Ok(Task { map, task, outcomes })
}

/// Passes a navigation's step progress on under one phase name and keeps its per-step scalars out of the
/// evaluation's metrics.
struct ProgressOnly<'a> {
    inner: &'a dyn Monitor,
    phase: &'a str,
}

impl Monitor for ProgressOnly<'_> {
    fn emit(&self, event: &Event) {
        if let Event::Progress { phase, done, total } = event {
            if phase == "navigation steps" {
                self.inner.progress(self.phase, *done, *total);
            }
        }
    }

    fn is_cancelled(&self) -> bool {
        self.inner.is_cancelled()
    }
}

/// Open-loop prediction of `truth`'s actions from its start: position error (m), |speed error| (m/s) and
/// |heading error| (rad, wrapped) per step.
fn prediction_errors(dynamics: &TradynDynamics, truth: &Rollout) -> Vec<[f64; 3]> {
    let horizon = truth.len();
    let actions: Vec<f64> = truth.actions.iter().flatten().copied().collect();
    let mut states = vec![0.0; horizon * 4];
    dynamics.rollout(&truth.states[0], &actions, horizon, 0, &mut [0.0], Some(&mut states));
    (0..horizon)
        .map(|t| {
            let (p, s) = (&states[t * 4..(t + 1) * 4], &truth.states[t + 1]);
            let position = ((p[0] - s[0]).powi(2) + (p[1] - s[1]).powi(2)).sqrt();
            let angle = (p[3] - s[3] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            [position, (p[2] - s[2]).abs(), angle.abs()]
        })
        .collect()
}

/// The figures of Table 5.2, Fig. 5.7 and the prediction tests from what every task gave.
fn summarize(
    settings: &TradynEvalSettings,
    models: String,
    provenance: &Provenance,
    tasks: Vec<Task>,
) -> Result<TradynEvalSummary> {
    let nav = &settings.navigation;
    let tasks: Vec<TaskRecord> = tasks
        .into_iter()
        .enumerate()
        .map(|(k, t)| {
            let outcomes: [Outcome; 4] = t.outcomes.try_into().map_err(|o: Vec<Outcome>| {
                Error::data(format!("task {k}: {} variant outcomes, expected {}", o.len(), VARIANTS.len()))
            })?;
            Ok(TaskRecord {
                map: t.map.name.clone(),
                start: t.task.start,
                goal: t.task.goal,
                outcomes,
                map_rgb: (k < settings.example_tasks.max(1))
                    .then(|| base64::engine::general_purpose::STANDARD.encode(t.map.coarse_rgb(PLOT_CELLS))),
            })
        })
        .collect::<Result<_>>()?;
    let column =
        |v: usize, f: &dyn Fn(&Outcome) -> f64| -> Vec<f64> { tasks.iter().map(|t| f(&t.outcomes[v])).collect() };
    let q = |values: &[f64], p: f64| quantile(values, p).unwrap_or(f64::NAN);
    // +T against −T with the same calibration: VARIANTS[2] vs [0] and [3] vs [1].
    let prediction_test = |with: usize, without: usize| {
        let a = column(with, &mean_position_error);
        let b = column(without, &mean_position_error);
        wilcoxon_signed_rank(&a, &b, Alternative::Less).map(|w| w.p_value).unwrap_or(f64::NAN)
    };
    let mut summary = TradynEvalSummary {
        provenance: provenance.clone(),
        settings: ReportedSettings {
            calibration_transitions: settings.calibration_transitions,
            candidates: nav.cem.candidates,
            elites: nav.cem.elites,
            iterations: nav.cem.iterations,
            horizon: nav.horizon,
            steps: nav.steps,
            success_distance: nav.success_distance,
            prediction_steps: settings.prediction_steps,
        },
        models,
        median_energy: [f64::NAN; 4],
        median_distance: [f64::NAN; 4],
        failures: [0; 4],
        mean_position_error: [f64::NAN; 4],
        energy_tests: Vec::new(),
        prediction_tests: Some((prediction_test(2, 0), prediction_test(3, 1))),
        tasks: Vec::new(),
    };
    for v in 0..VARIANTS.len() {
        let position = column(v, &mean_position_error);
        summary.median_energy[v] = q(&column(v, &|o| o.energy), 0.5);
        summary.median_distance[v] = q(&column(v, &|o| o.final_distance * 1000.0), 0.5) / 1000.0;
        summary.failures[v] = tasks.iter().filter(|t| !t.outcomes[v].success).count();
        summary.mean_position_error[v] = position.iter().sum::<f64>() / position.len().max(1) as f64;
    }
    for r in 0..VARIANTS.len() {
        for c in 0..VARIANTS.len() {
            if r == c {
                continue;
            }
            let (a, b) = (column(r, &|o| o.energy), column(c, &|o| o.energy));
            let diffs: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
            summary.energy_tests.push(EnergyTest {
                row: r,
                column: c,
                diff_p20: q(&diffs, 0.2),
                diff_median: q(&diffs, 0.5),
                diff_p80: q(&diffs, 0.8),
                p_value: wilcoxon_signed_rank(&a, &b, Alternative::Less).map(|w| w.p_value).unwrap_or(f64::NAN),
            });
        }
    }
    summary.tasks = tasks;
    Ok(summary)
}

/// Mean position error over the prediction horizon.
fn mean_position_error(o: &Outcome) -> f64 {
    o.prediction.iter().map(|e| e[0]).sum::<f64>() / o.prediction.len().max(1) as f64
}

/// Writes tasks.csv, table_5_2.csv, energy_wilcoxon.csv, prediction.csv/.png, paths.png and report.md of
/// `summary` into `dir`.
pub fn render(summary: &TradynEvalSummary, dir: &Path) -> Result<()> {
    let settings = &summary.settings;
    let tasks = &summary.tasks;
    let names: Vec<String> = VARIANTS.iter().map(|v| variant_name(*v)).collect();
    let column =
        |v: usize, f: &dyn Fn(&Outcome) -> f64| -> Vec<f64> { tasks.iter().map(|t| f(&t.outcomes[v])).collect() };
    let q = |values: &[f64], p: f64| quantile(values, p).unwrap_or(f64::NAN);
    let file = |name: &str| dir.join(name);
    if let Some(t) = summary.energy_tests.iter().find(|t| t.row >= VARIANTS.len() || t.column >= VARIANTS.len()) {
        return Err(Error::config(format!("energy_tests: variant index {} is not below 4", t.row.max(t.column))));
    }

    // Per task and variant.
    let mut rows = Vec::new();
    for (k, t) in tasks.iter().enumerate() {
        for (v, o) in t.outcomes.iter().enumerate() {
            rows.push(vec![
                k.to_string(),
                t.map.clone(),
                format!("{:.4}", t.start[0]),
                format!("{:.4}", t.start[1]),
                format!("{:.4}", t.start[2]),
                format!("{:.4}", t.goal[0]),
                format!("{:.4}", t.goal[1]),
                names[v].clone(),
                format!("{:.6}", o.energy),
                format!("{:.6}", o.final_distance),
                o.success.to_string(),
                format!("{:.6}", mean_position_error(o)),
            ]);
        }
    }
    write_csv(
        &file("tasks.csv"),
        &[
            "task",
            "map",
            "start_x",
            "start_y",
            "start_phi",
            "goal_x",
            "goal_y",
            "variant",
            "energy",
            "final_distance_m",
            "success",
            "mean_position_error_m",
        ],
        &rows,
    )?;

    // Table 5.2 analogue (distances in mm) with energies.
    let mut table = Vec::new();
    for (v, name) in names.iter().enumerate() {
        let distance = column(v, &|o| o.final_distance * 1000.0);
        let energy = column(v, &|o| o.energy);
        table.push(vec![
            name.clone(),
            format!("{:.2}", q(&distance, 0.2)),
            format!("{:.2}", q(&distance, 0.5)),
            format!("{:.2}", q(&distance, 0.8)),
            format!("{}/{}", summary.failures[v], tasks.len()),
            format!("{:.4}", q(&energy, 0.2)),
            format!("{:.4}", q(&energy, 0.5)),
            format!("{:.4}", q(&energy, 0.8)),
            format!("{:.4}", summary.mean_position_error[v]),
        ]);
    }
    let table_header = [
        "variant",
        "distance_p20_mm",
        "distance_median_mm",
        "distance_p80_mm",
        "failed",
        "energy_p20",
        "energy_median",
        "energy_p80",
        "mean_position_error_m",
    ];
    write_csv(&file("table_5_2.csv"), &table_header, &table)?;

    // Fig. 5.7 analogue: row − column energy differences per task, one-sided Wilcoxon (row uses less).
    let pairs: Vec<Vec<String>> = summary
        .energy_tests
        .iter()
        .map(|t| {
            vec![
                names[t.row].clone(),
                names[t.column].clone(),
                format!("{:.4}", t.diff_p20),
                format!("{:.4}", t.diff_median),
                format!("{:.4}", t.diff_p80),
                if t.p_value.is_nan() { String::new() } else { format!("{:.3e}", t.p_value) },
            ]
        })
        .collect();
    write_csv(
        &file("energy_wilcoxon.csv"),
        &["row", "column", "diff_p20", "diff_median", "diff_p80", "p_row_less"],
        &pairs,
    )?;

    // Fig. 5.5 analogue: prediction errors against the horizon (mean, P20-P80 band).
    let mut prediction_rows = Vec::new();
    let mut panels = Vec::new();
    for (d, what) in ["position error (m)", "speed error (m/s)", "heading error (rad)"].iter().enumerate() {
        let mut bands = Vec::new();
        for (v, name) in names.iter().enumerate() {
            let mut points = Vec::new();
            for step in 0..settings.prediction_steps {
                let errors: Vec<f64> =
                    tasks.iter().filter_map(|t| t.outcomes[v].prediction.get(step).map(|e| e[d])).collect();
                let mean = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
                points.push(((step + 1) as f64, q(&errors, 0.2), mean, q(&errors, 0.8)));
                if d == 0 {
                    let at = |t: &TaskRecord| t.outcomes[v].prediction.get(step).copied().unwrap_or([f64::NAN; 3]);
                    let mean_of = |i: usize| tasks.iter().map(|t| at(t)[i]).sum::<f64>() / tasks.len() as f64;
                    prediction_rows.push(vec![
                        name.clone(),
                        (step + 1).to_string(),
                        format!("{:.6}", mean_of(0)),
                        format!("{:.6}", mean_of(1)),
                        format!("{:.6}", mean_of(2)),
                    ]);
                }
            }
            bands.push(Band { name: name.clone(), points });
        }
        panels.push((what.to_string(), bands));
    }
    write_csv(
        &file("prediction.csv"),
        &["variant", "step", "mean_position_error_m", "mean_speed_error", "mean_heading_error_rad"],
        &prediction_rows,
    )?;
    band_panels(
        &file("prediction.png"),
        "Open-loop prediction error (mean, P20–P80 over tasks)",
        "prediction step",
        "error",
        &panels,
    )?;

    // Fig. 5.6 analogue: example paths of all variants on their maps.
    let mut examples = Vec::new();
    for (k, t) in tasks.iter().enumerate() {
        let Some(rgb) = &t.map_rgb else { break };
        let rgb = base64::engine::general_purpose::STANDARD
            .decode(rgb)
            .ok()
            .filter(|b| b.len() == PLOT_CELLS * PLOT_CELLS * 3)
            .ok_or_else(|| Error::config(format!("tasks[{k}].map_rgb: expected {PLOT_CELLS}² RGB pixels in base64")))?;
        examples.push(MapPanel {
            title: format!(
                "task {k} on {}: E {}",
                t.map,
                t.outcomes.iter().map(|o| format!("{:.2}", o.energy)).collect::<Vec<_>>().join(" / ")
            ),
            grid: ColorGrid { cells: PLOT_CELLS, rgb },
            paths: t
                .outcomes
                .iter()
                .zip(&names)
                .map(|(o, name)| Series { name: name.clone(), points: o.path.clone() })
                .collect(),
            start: (t.start[0], t.start[1]),
            goal: (t.goal[0], t.goal[1]),
        });
    }
    map_paths(&file("paths.png"), "Navigation paths (white ×: start, black ×: goal)", &examples)?;

    let prediction_tests = summary.prediction_tests.unwrap_or((f64::NAN, f64::NAN));
    write_text(
        &file("report.md"),
        &markdown(
            settings,
            &summary.models,
            &names,
            &table,
            &pairs,
            [prediction_tests.0, prediction_tests.1],
            tasks.len(),
        ),
    )
}

fn markdown(
    settings: &ReportedSettings,
    models: &str,
    names: &[String],
    table: &[Vec<String>],
    pairs: &[Vec<String>],
    prediction_tests: [f64; 2],
    tasks: usize,
) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# TRADYN evaluation (thesis 5.5)\n");
    let _ = writeln!(md, "Models {models}.\n");
    let _ = writeln!(
        md,
        "{tasks} tasks on test maps: a robot drawn from Table 5.1, start and goal in [0.1, 0.9]², heading U[−π, π], \
         at rest. ±T: the model with terrain lookup / the one trained with --no-terrain. +C: conditioned on {} random \
         colored transitions from the start (the same for both models); −C: the empty context. Planner: CEM {} × {} \
         elites × {} iterations, horizon min({}, {} − t), {} steps, colored noise; the same planner seed per task for \
         every variant. Failure: final distance > {} m.\n",
        settings.calibration_transitions,
        settings.candidates,
        settings.elites,
        settings.iterations,
        settings.horizon,
        settings.steps,
        settings.steps,
        settings.success_distance
    );
    let _ = writeln!(md, "## Distance to goal and failures (Table 5.2 analogue)\n");
    let _ = writeln!(
        md,
        "| variant | distance P20 [mm] | median | P80 | failed | energy P20 | median | P80 | mean position error [m] |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    for row in table {
        let _ = writeln!(md, "| {} |", row.join(" | "));
    }
    let _ = writeln!(
        md,
        "\nPrediction (mean position error over a {}-step open-loop prediction per task): terrain lookup lowers it \
         with p = {} without calibration and p = {} with it (one-sided Wilcoxon signed-rank over tasks).",
        settings.prediction_steps,
        p_shown(prediction_tests[0], 2),
        p_shown(prediction_tests[1], 2)
    );
    let _ = writeln!(md, "\nThesis Table 5.2 (150 tasks × 5 models): −T,−C 5.19 mm median, 6/750 failed; −T,+C 5.23, 0/750; +T,−C 4.22, 14/750; +T,+C 3.85, 0/750.\n");
    let _ = writeln!(md, "## Pairwise energy comparison (Fig. 5.7 analogue)\n");
    let _ = writeln!(
        md,
        "Median of E_row − E_column over tasks, and the one-sided Wilcoxon signed-rank p-value that the row variant \
         needs less energy (bold: p < 0.05).\n"
    );
    let _ = writeln!(md, "| row \\ column | {} |", names.join(" | "));
    let _ = writeln!(md, "|---|{}", "---|".repeat(names.len()));
    for r in names {
        let cells: Vec<String> = names
            .iter()
            .map(|c| {
                pairs.iter().find(|p| &p[0] == r && &p[1] == c).map_or("·".to_string(), |p| {
                    let significant = p[5].parse::<f64>().is_ok_and(|x| x < 0.05);
                    let text = format!("{} (p {})", p[3], if p[5].is_empty() { "—" } else { &p[5] });
                    if significant {
                        format!("**{text}**")
                    } else {
                        text
                    }
                })
            })
            .collect();
        let _ = writeln!(md, "| {r} | {} |", cells.join(" | "));
    }
    let _ = writeln!(
        md,
        "\nFiles: tasks.csv (every task × variant), table_5_2.csv, energy_wilcoxon.csv, prediction.csv/.png \
         (Fig. 5.5 analogue), paths.png (Fig. 5.6 analogue), config.json, metrics.jsonl."
    );
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every task equal gives no Wilcoxon p-value: the reports say so instead of printing NaN.
    #[test]
    fn an_undefined_p_value_is_shown_as_a_dash() {
        let equal = wilcoxon_signed_rank(&[1.0, 2.0], &[1.0, 2.0], Alternative::Less).map(|w| w.p_value);
        let p = equal.unwrap_or(f64::NAN);
        assert_eq!(p_shown(p, 3), "— (no non-zero difference)");
        assert_eq!(p_shown(0.25, 3), "2.500e-1");
    }
}
