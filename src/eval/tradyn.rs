//! `mbrl eval tradyn`: the protocol of thesis 5.5 at a chosen scale. Per task (a test map, a robot of Table 5.1,
//! start and goal in [0.1, 0.9]², heading U[−π, π], at rest): 10 random colored calibration transitions from the
//! start, then navigation with each of the four variants ±terrain lookup (two trained models) × ±calibration
//! (the calibration's context or none) on the same task with the same planner seed. Reports control energy,
//! final distance and failures (Table 5.2), pairwise Wilcoxon signed-rank tests on energies (Fig. 5.7), open-loop
//! prediction errors against the horizon on a random rollout per task (Fig. 5.5), and example paths (Fig. 5.6).

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use rand::Rng;
use serde::Serialize;

use super::plot::{band_panels, map_paths, Band, ColorGrid, MapPanel, Series};
use super::stats::{quantile, wilcoxon_signed_rank, Alternative};
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

/// What one variant did on one task.
#[derive(Clone, Debug)]
struct Outcome {
    energy: f64,
    final_distance: f64,
    success: bool,
    path: Vec<(f64, f64)>,
    /// Per prediction step: position error (m), speed error (m/s), heading error (rad).
    prediction: Vec<[f64; 3]>,
}

impl Outcome {
    /// Mean position error over the prediction horizon.
    fn mean_position_error(&self) -> f64 {
        self.prediction.iter().map(|e| e[0]).sum::<f64>() / self.prediction.len().max(1) as f64
    }
}

struct Task {
    map: Arc<TerrainMap>,
    task: NavigationTask,
    outcomes: Vec<Outcome>,
}

pub struct TradynEvalSummary {
    /// Per variant (VARIANTS order): median energy, median final distance (m), failures.
    pub median_energy: Vec<f64>,
    pub median_distance: Vec<f64>,
    pub failures: Vec<usize>,
    /// Mean position error over the prediction horizon and tasks, per variant.
    pub mean_position_error: Vec<f64>,
    /// One-sided p-values that the row variant uses less energy than the column variant (row ≠ col).
    pub energy_tests: Vec<(usize, usize, f64)>,
    /// One-sided p-values that terrain lookup lowers the per-task mean position error: (−C, +C).
    pub prediction_tests: [f64; 2],
    pub tasks: usize,
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
    settings: &TradynEvalSettings,
    provenance: &Provenance,
    report_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<TradynEvalSummary> {
    settings.validate()?;
    models.check()?;
    if maps.is_empty() {
        return Err(Error::config("eval tradyn needs at least one test map"));
    }
    let run = RunDir::create(report_dir)?;
    run.write_config(&serde_json::json!({
        "job": "eval tradyn",
        "provenance": provenance,
        "model_terrain": models.terrain.loaded.dir,
        "model_no_terrain": models.no_terrain.loaded.dir,
        "training": {"terrain": models.terrain.loaded.progress, "no_terrain": models.no_terrain.loaded.progress},
        "maps": maps.iter().map(|m| serde_json::json!({"name": m.name, "crc32": m.crc32})).collect::<Vec<_>>(),
        "settings": settings,
    }))?;
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
    write_report(&run, settings, &models.describe(), &tasks)
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

fn write_report(
    run: &RunDir,
    settings: &TradynEvalSettings,
    models: &str,
    tasks: &[Task],
) -> Result<TradynEvalSummary> {
    let names: Vec<String> = VARIANTS.iter().map(|v| variant_name(*v)).collect();
    let column =
        |v: usize, f: &dyn Fn(&Outcome) -> f64| -> Vec<f64> { tasks.iter().map(|t| f(&t.outcomes[v])).collect() };
    let q = |values: &[f64], p: f64| quantile(values, p).unwrap_or(f64::NAN);

    // Per task and variant.
    let mut rows = Vec::new();
    for (k, t) in tasks.iter().enumerate() {
        for (v, o) in t.outcomes.iter().enumerate() {
            rows.push(vec![
                k.to_string(),
                t.map.name.clone(),
                format!("{:.4}", t.task.start[0]),
                format!("{:.4}", t.task.start[1]),
                format!("{:.4}", t.task.start[2]),
                format!("{:.4}", t.task.goal[0]),
                format!("{:.4}", t.task.goal[1]),
                names[v].clone(),
                format!("{:.6}", o.energy),
                format!("{:.6}", o.final_distance),
                o.success.to_string(),
                format!("{:.6}", o.mean_position_error()),
            ]);
        }
    }
    write_csv(
        &run.file("tasks.csv"),
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
    let mut summary = TradynEvalSummary {
        median_energy: Vec::new(),
        median_distance: Vec::new(),
        failures: Vec::new(),
        mean_position_error: Vec::new(),
        energy_tests: Vec::new(),
        prediction_tests: [f64::NAN; 2],
        tasks: tasks.len(),
    };
    // +T against −T with the same calibration: VARIANTS[2] vs [0] and [3] vs [1].
    for (slot, (with, without)) in summary.prediction_tests.iter_mut().zip([(2, 0), (3, 1)]) {
        let a = column(with, &|o| o.mean_position_error());
        let b = column(without, &|o| o.mean_position_error());
        *slot = wilcoxon_signed_rank(&a, &b, Alternative::Less).map(|w| w.p_value).unwrap_or(f64::NAN);
    }
    let mut table = Vec::new();
    for (v, name) in names.iter().enumerate() {
        let distance = column(v, &|o| o.final_distance * 1000.0);
        let energy = column(v, &|o| o.energy);
        let failures = tasks.iter().filter(|t| !t.outcomes[v].success).count();
        let position = column(v, &|o| o.mean_position_error());
        let mean_position = position.iter().sum::<f64>() / position.len().max(1) as f64;
        summary.median_energy.push(q(&energy, 0.5));
        summary.median_distance.push(q(&distance, 0.5) / 1000.0);
        summary.failures.push(failures);
        summary.mean_position_error.push(mean_position);
        table.push(vec![
            name.clone(),
            format!("{:.2}", q(&distance, 0.2)),
            format!("{:.2}", q(&distance, 0.5)),
            format!("{:.2}", q(&distance, 0.8)),
            format!("{failures}/{}", tasks.len()),
            format!("{:.4}", q(&energy, 0.2)),
            format!("{:.4}", q(&energy, 0.5)),
            format!("{:.4}", q(&energy, 0.8)),
            format!("{mean_position:.4}"),
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
    write_csv(&run.file("table_5_2.csv"), &table_header, &table)?;

    // Fig. 5.7 analogue: row − column energy differences per task, one-sided Wilcoxon (row uses less).
    let mut pairs = Vec::new();
    for r in 0..VARIANTS.len() {
        for c in 0..VARIANTS.len() {
            if r == c {
                continue;
            }
            let (a, b) = (column(r, &|o| o.energy), column(c, &|o| o.energy));
            let diffs: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
            let p = wilcoxon_signed_rank(&a, &b, Alternative::Less).map(|w| w.p_value).unwrap_or(f64::NAN);
            summary.energy_tests.push((r, c, p));
            pairs.push(vec![
                names[r].clone(),
                names[c].clone(),
                format!("{:.4}", q(&diffs, 0.2)),
                format!("{:.4}", q(&diffs, 0.5)),
                format!("{:.4}", q(&diffs, 0.8)),
                format!("{p:.3e}"),
            ]);
        }
    }
    write_csv(
        &run.file("energy_wilcoxon.csv"),
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
                    let at = |t: &Task| t.outcomes[v].prediction.get(step).copied().unwrap_or([f64::NAN; 3]);
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
        &run.file("prediction.csv"),
        &["variant", "step", "mean_position_error_m", "mean_speed_error", "mean_heading_error_rad"],
        &prediction_rows,
    )?;
    band_panels(
        &run.file("prediction.png"),
        "Open-loop prediction error (mean, P20–P80 over tasks)",
        "prediction step",
        "error",
        &panels,
    )?;

    // Fig. 5.6 analogue: example paths of all variants on their maps.
    let examples: Vec<MapPanel> = tasks
        .iter()
        .take(settings.example_tasks.max(1))
        .enumerate()
        .map(|(k, t)| MapPanel {
            title: format!(
                "task {k} on {}: E {}",
                t.map.name,
                t.outcomes.iter().map(|o| format!("{:.2}", o.energy)).collect::<Vec<_>>().join(" / ")
            ),
            grid: ColorGrid { cells: PLOT_CELLS, rgb: t.map.coarse_rgb(PLOT_CELLS) },
            paths: t
                .outcomes
                .iter()
                .zip(&names)
                .map(|(o, name)| Series { name: name.clone(), points: o.path.clone() })
                .collect(),
            start: (t.task.start[0], t.task.start[1]),
            goal: (t.task.goal[0], t.task.goal[1]),
        })
        .collect();
    map_paths(&run.file("paths.png"), "Navigation paths (white ×: start, black ×: goal)", &examples)?;

    write_text(
        &run.file("report.md"),
        &markdown(settings, models, &names, &table, &pairs, summary.prediction_tests, tasks.len()),
    )?;
    Ok(summary)
}

fn markdown(
    settings: &TradynEvalSettings,
    models: &str,
    names: &[String],
    table: &[Vec<String>],
    pairs: &[Vec<String>],
    prediction_tests: [f64; 2],
    tasks: usize,
) -> String {
    let nav = &settings.navigation;
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
        nav.cem.candidates,
        nav.cem.elites,
        nav.cem.iterations,
        nav.horizon,
        nav.steps,
        nav.steps,
        nav.success_distance
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
         with p = {:.2e} without calibration and p = {:.2e} with it (one-sided Wilcoxon signed-rank over tasks).",
        settings.prediction_steps, prediction_tests[0], prediction_tests[1]
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
                    let text = format!("{} (p {})", p[3], p[5]);
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
