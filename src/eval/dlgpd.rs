//! DLGPD's adaptation experiment (thesis 3.5.3, Figs. 3.4/3.5): one trained model swings up the standard
//! pendulum and three changed ones (inverted actions, m = 0.2, m = 1.5) with no retraining, its GPs
//! conditioned on evidence rollouts either of the system at hand ("matching") or of the standard pendulum
//! ("mismatching"), for several evidence sizes. As in the authors' protocol, run r uses the same evidence
//! seeds (so matching pools differ from the standard pool only in the dynamics) and the same start state in
//! every setting.

use std::path::Path;

use serde::Serialize;

use super::plot::{line_plot, line_plot_in, Series};
use super::stats::{wilcoxon_signed_rank, Alternative};
use crate::data::collect::{collect_random, CollectSettings};
use crate::data::collect_frames::add_pendulum_frames;
use crate::data::frames_png::encode_rgb;
use crate::data::Dataset;
use crate::envs::pendulum::PendulumVariant;
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::models::dlgpd::control::{condition_on, swing_up, ControlSettings};
use crate::models::dlgpd::data::{ObservationKind, Windows};
use crate::models::dlgpd::job::TrainedDlgpd;
use crate::models::dlgpd::train::encode_rows;
use crate::nn::tensor::{inference_device, tensor};
use crate::run::dir::{Provenance, RunDir};
use crate::run::{Event, Monitor, NullMonitor, Tee};
use crate::util::seeding::derive_seed;
use crate::util::table::write_csv;

const EVIDENCE_STREAM: u64 = 1;
const CONTROL_STREAM: u64 = 2;
/// Frames per evidence rollout: the authors' 30 (29 steps, 28 transitions).
pub const EVIDENCE_STEPS: usize = 29;

#[derive(Clone, Debug, Serialize)]
pub struct DlgpdEvalSettings {
    #[serde(serialize_with = "variant_names")]
    pub variants: Vec<PendulumVariant>,
    pub evidence_rollouts: Vec<usize>,
    pub runs: usize,
    pub steps: usize,
    pub cem: crate::planning::CemConfig,
}

fn variant_names<S: serde::Serializer>(v: &[PendulumVariant], s: S) -> std::result::Result<S::Ok, S::Error> {
    s.collect_seq(v.iter().map(PendulumVariant::env_name))
}

impl DlgpdEvalSettings {
    /// The thesis' four settings.
    pub fn thesis_variants() -> Vec<PendulumVariant> {
        vec![
            PendulumVariant::Standard,
            PendulumVariant::Inverted,
            PendulumVariant::Mass(0.2),
            PendulumVariant::Mass(1.5),
        ]
    }

    fn validate(&self) -> Result<()> {
        if self.variants.is_empty() || self.evidence_rollouts.is_empty() || self.runs == 0 || self.steps == 0 {
            return Err(Error::config("eval dlgpd needs at least one variant, evidence size, run and step"));
        }
        if let Some(v) = self.variants.iter().find(|v| matches!(v, PendulumVariant::Quadrant)) {
            return Err(Error::config(format!(
                "'{}' has hidden per-instance actuators; eval dlgpd supports pendulum, :inverted, :light, :heavy, :mass=M",
                v.env_name()
            )));
        }
        if let Some(n) = self.evidence_rollouts.iter().find(|n| !(1..=1000).contains(*n)) {
            return Err(Error::config(format!("evidence sizes must be 1..=1000 rollouts, got {n}")));
        }
        self.cem.validate()
    }
}

/// One swing-up.
#[derive(Clone, Debug, Serialize)]
pub struct Outcome {
    pub env: String,
    pub evidence: &'static str,
    pub rollouts: usize,
    pub run: usize,
    pub total_return: f64,
    pub success: bool,
    pub mean_cem_iterations: f64,
}

/// One point of the figures: a setting, an evidence kind and size over the runs.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub env: String,
    pub evidence: &'static str,
    pub rollouts: usize,
    pub mean_return: f64,
    pub successes: usize,
    pub runs: usize,
}

/// Matching against mismatching evidence on one setting and evidence size: one-sided Wilcoxon signed-rank
/// test that matching evidence gives higher returns, paired by run (same start state and evidence seeds).
#[derive(Clone, Debug, Serialize)]
pub struct EvidenceTest {
    pub env: String,
    pub rollouts: usize,
    pub pairs: usize,
    pub statistic: f64,
    pub p_value: f64,
}

pub struct DlgpdEvalSummary {
    pub points: Vec<Point>,
    pub outcomes: Vec<Outcome>,
    pub tests: Vec<EvidenceTest>,
}

fn evidence_tests(outcomes: &[Outcome]) -> Result<Vec<EvidenceTest>> {
    let mut tests = Vec::new();
    let mut keys: Vec<(String, usize)> =
        outcomes.iter().filter(|o| o.evidence == "mismatching").map(|o| (o.env.clone(), o.rollouts)).collect();
    keys.sort();
    keys.dedup();
    for (env, rollouts) in keys {
        let returns = |kind: &str| -> Vec<(usize, f64)> {
            let mut v: Vec<(usize, f64)> = outcomes
                .iter()
                .filter(|o| o.env == env && o.rollouts == rollouts && o.evidence == kind)
                .map(|o| (o.run, o.total_return))
                .collect();
            v.sort_by_key(|(run, _)| *run);
            v
        };
        let (matching, mismatching) = (returns("matching"), returns("mismatching"));
        if matching.len() != mismatching.len() || matching.iter().zip(&mismatching).any(|(a, b)| a.0 != b.0) {
            continue;
        }
        let a: Vec<f64> = matching.iter().map(|x| x.1).collect();
        let b: Vec<f64> = mismatching.iter().map(|x| x.1).collect();
        let result = wilcoxon_signed_rank(&a, &b, Alternative::Greater)?;
        tests.push(EvidenceTest {
            env,
            rollouts,
            pairs: result.n,
            statistic: result.statistic,
            p_value: result.p_value,
        });
    }
    Ok(tests)
}

/// Random rollouts of `variant` from uniform start states, with frames when the model sees images.
pub fn evidence_rollouts(variant: &PendulumVariant, rollouts: usize, seed: u64, images: bool) -> Result<Dataset> {
    let settings = CollectSettings {
        env: EnvName::Pendulum(variant.clone()),
        rollouts,
        steps: EVIDENCE_STEPS,
        seed,
        command_line: "mbrl eval dlgpd (evidence)".into(),
    };
    let mut data = collect_random(&settings, &NullMonitor)?;
    if images {
        add_pendulum_frames(&mut data, &NullMonitor)?;
    }
    Ok(data)
}

pub fn evaluate(
    trained: &TrainedDlgpd,
    settings: &DlgpdEvalSettings,
    provenance: &Provenance,
    report_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<DlgpdEvalSummary> {
    settings.validate()?;
    let run_dir = RunDir::create(report_dir)?;
    run_dir.write_config(&serde_json::json!({
        "job": "eval dlgpd",
        "provenance": provenance,
        "model": trained.run,
        "settings": settings,
    }))?;
    let metrics = run_dir.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    monitor.emit(&crate::eval::swingup::layout("eval dlgpd: swing-ups on swapped evidence", false));
    let images = matches!(trained.run.observation, ObservationKind::Images { .. });
    let seed = provenance.seed;
    let largest = settings.evidence_rollouts.iter().copied().max().unwrap_or(0);
    let mut plan: Vec<(PendulumVariant, &'static str, PendulumVariant)> = Vec::new();
    for variant in &settings.variants {
        plan.push((variant.clone(), "matching", variant.clone()));
        if *variant != PendulumVariant::Standard {
            plan.push((variant.clone(), "mismatching", PendulumVariant::Standard));
        }
    }
    let total = (plan.len() * settings.evidence_rollouts.len() * settings.runs) as u64;
    let mut outcomes = Vec::new();
    for run in 0..settings.runs {
        let pool_seed = derive_seed(seed, &[EVIDENCE_STREAM, run as u64]);
        let control_seed = derive_seed(seed, &[CONTROL_STREAM, run as u64]);
        // One pool per run and source env, shared by the settings that use it; smaller evidence sets are its
        // first rollouts, as the authors' buckets.
        let mut pools: Vec<(PendulumVariant, Dataset)> = Vec::new();
        for (variant, kind, source) in &plan {
            if !pools.iter().any(|(v, _)| v == source) {
                pools.push((source.clone(), evidence_rollouts(source, largest, pool_seed, images)?));
            }
            let pool = &pools.iter().find(|(v, _)| v == source).expect("pushed above").1;
            for &rollouts in &settings.evidence_rollouts {
                if monitor.is_cancelled() {
                    return Err(Error::Cancelled);
                }
                let evidence = first_rollouts(pool, rollouts);
                let dynamics = condition_on(trained, &evidence, pool_seed)?;
                let control =
                    ControlSettings { variant: variant.clone(), steps: settings.steps, cem: settings.cem.clone() };
                let episode = swing_up(trained, &dynamics, &control, control_seed, &NullMonitor)?;
                let iterations =
                    episode.iterations.iter().sum::<usize>() as f64 / episode.iterations.len().max(1) as f64;
                let outcome = Outcome {
                    env: variant.env_name(),
                    evidence: kind,
                    rollouts,
                    run,
                    total_return: episode.total_return,
                    success: episode.success,
                    mean_cem_iterations: iterations,
                };
                monitor.scalar("episode/return", outcomes.len() as u64, outcome.total_return);
                outcomes.push(outcome);
                monitor.progress("swing-ups", outcomes.len() as u64, total);
            }
        }
    }
    let points = summarize(&outcomes);
    let tests = evidence_tests(&outcomes)?;
    write_report(trained, settings, &run_dir, &points, &outcomes, &tests)?;
    if images {
        let pool = evidence_rollouts(&settings.variants[0], 1, derive_seed(seed, &[EVIDENCE_STREAM, 0]), true)?;
        write_reconstructions(trained, &pool, &run_dir.file("reconstructions.png"))?;
    }
    metrics.emit(&Event::Finished { ok: true });
    Ok(DlgpdEvalSummary { points, outcomes, tests })
}

/// The first `count` rollouts of a dataset (its ids are 0, 1, … in order).
fn first_rollouts(pool: &Dataset, count: usize) -> Dataset {
    let steps = pool.steps.iter().take_while(|s| (s.rollout as usize) < count).count();
    // One frame per state: each rollout's transitions plus one.
    let frames = if pool.frames.is_empty() { 0 } else { (steps + count).min(pool.frames.len()) };
    Dataset { meta: pool.meta.clone(), steps: pool.steps[..steps].to_vec(), frames: pool.frames[..frames].to_vec() }
}

fn summarize(outcomes: &[Outcome]) -> Vec<Point> {
    let mut points: Vec<Point> = Vec::new();
    for o in outcomes {
        match points.iter_mut().find(|p| p.env == o.env && p.evidence == o.evidence && p.rollouts == o.rollouts) {
            Some(p) => {
                p.mean_return += o.total_return;
                p.successes += usize::from(o.success);
                p.runs += 1;
            }
            None => points.push(Point {
                env: o.env.clone(),
                evidence: o.evidence,
                rollouts: o.rollouts,
                mean_return: o.total_return,
                successes: usize::from(o.success),
                runs: 1,
            }),
        }
    }
    for p in &mut points {
        p.mean_return /= p.runs as f64;
    }
    points.sort_by(|a, b| (&a.env, a.evidence, a.rollouts).cmp(&(&b.env, b.evidence, b.rollouts)));
    points
}

fn write_report(
    trained: &TrainedDlgpd,
    settings: &DlgpdEvalSettings,
    run_dir: &RunDir,
    points: &[Point],
    outcomes: &[Outcome],
    tests: &[EvidenceTest],
) -> Result<()> {
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .map(|o| {
            vec![
                o.env.clone(),
                o.evidence.to_string(),
                o.rollouts.to_string(),
                o.run.to_string(),
                format!("{:.3}", o.total_return),
                o.success.to_string(),
                format!("{:.2}", o.mean_cem_iterations),
            ]
        })
        .collect();
    write_csv(
        &run_dir.file("results.csv"),
        &["env", "evidence", "evidence_rollouts", "run", "return", "success", "mean_cem_iterations"],
        &rows,
    )?;
    let summary_rows: Vec<Vec<String>> = points
        .iter()
        .map(|p| {
            vec![
                p.env.clone(),
                p.evidence.to_string(),
                p.rollouts.to_string(),
                format!("{:.3}", p.mean_return),
                format!("{:.4}", p.successes as f64 / p.runs as f64),
                p.runs.to_string(),
            ]
        })
        .collect();
    write_csv(
        &run_dir.file("summary.csv"),
        &["env", "evidence", "evidence_rollouts", "mean_return", "success_rate", "runs"],
        &summary_rows,
    )?;
    let curves = |value: &dyn Fn(&Point) -> f64| -> Vec<Series> {
        let mut series: Vec<Series> = Vec::new();
        for p in points {
            let name = format!("{} ({})", p.env, p.evidence);
            let point = (p.rollouts as f64, value(p));
            match series.iter_mut().find(|s| s.name == name) {
                Some(s) => s.points.push(point),
                None => series.push(Series { name, points: vec![point] }),
            }
        }
        series
    };
    line_plot(
        &run_dir.file("returns.png"),
        "DLGPD swing-up return vs evidence (Fig. 3.4 analogue)",
        "rollouts in evidence",
        &format!("mean return ({} runs per point)", settings.runs),
        &curves(&|p| p.mean_return),
    )?;
    line_plot_in(
        &run_dir.file("success.png"),
        "DLGPD swing-up success vs evidence (Fig. 3.5 analogue)",
        "rollouts in evidence",
        "success rate (last 25 rewards > -1)",
        &curves(&|p| p.successes as f64 / p.runs as f64),
        (-0.05, 1.05),
    )?;
    let mut md = String::new();
    md.push_str("# DLGPD: swing-up on swapped evidence (thesis 3.5.3, Figs. 3.4/3.5)\n\n");
    let observed = match trained.run.observation {
        ObservationKind::Images { side } => format!("{side}×{side} rendered frames (the paper's conv VAE)"),
        ObservationKind::Angles => {
            "pole angles (cos θ, sin θ) with an MLP VAE: the small preset, not the paper's images".to_string()
        }
    };
    md.push_str(&format!(
        "One model trained on {} transitions of `{}` from {observed}, {} steps at batch {}. No retraining: for \
         each setting the GPs are conditioned on encoded evidence rollouts (random actions, {} frames each) of \
         the system at hand (**matching**) or of the standard pendulum (**mismatching**). CEM: {} candidates, \
         {} elites, ≤ {} iterations (stopping at first-action std ≤ 0.01), horizon {}; {} steps from the \
         hanging position; success = each of the last 25 rewards > −1. Each point averages {} runs (run r: the \
         same evidence seeds and start state in every setting).\n\n",
        trained.run.transitions.train,
        trained.run.env,
        trained.run.config.steps,
        trained.run.config.batch_size,
        EVIDENCE_STEPS + 1,
        settings.cem.candidates,
        settings.cem.elites,
        settings.cem.iterations,
        settings.cem.horizon,
        settings.steps,
        settings.runs
    ));
    md.push_str("| env | evidence | rollouts | mean return | successes |\n|---|---|---|---|---|\n");
    for p in points {
        md.push_str(&format!(
            "| {} | {} | {} | {:.1} | {}/{} |\n",
            p.env, p.evidence, p.rollouts, p.mean_return, p.successes, p.runs
        ));
    }
    if !tests.is_empty() {
        md.push_str(
            "\nMatching vs mismatching evidence, one-sided Wilcoxon signed-rank test (matching gives higher \
             returns), paired by run (`wilcoxon.csv`):\n\n| env | rollouts | pairs | W+ | p |\n|---|---|---|---|---|\n",
        );
        for t in tests {
            md.push_str(&format!(
                "| {} | {} | {} | {} | {:.4} |\n",
                t.env, t.rollouts, t.pairs, t.statistic, t.p_value
            ));
        }
    }
    let test_rows: Vec<Vec<String>> = tests
        .iter()
        .map(|t| {
            vec![
                t.env.clone(),
                t.rollouts.to_string(),
                t.pairs.to_string(),
                t.statistic.to_string(),
                format!("{:.4e}", t.p_value),
            ]
        })
        .collect();
    write_csv(&run_dir.file("wilcoxon.csv"), &["env", "evidence_rollouts", "pairs", "w_plus", "p_value"], &test_rows)?;
    md.push_str(
        "\nThe thesis reports these as figures only (27 runs per point: 3 models × 3 evidence pools × 3 trials, \
         evidence of 10 to 200 rollouts, 1000 candidates); it states that DLGPD reaches 100 % success on the \
         standard pendulum and adapts to the changed ones with few matching rollouts. Files: `results.csv` (every \
         run), `summary.csv`, `returns.png`, `success.png`",
    );
    if matches!(trained.run.observation, ObservationKind::Images { .. }) {
        md.push_str(", `reconstructions.png` (top: observed newer frames; bottom: decoded from the encoder mean)");
    }
    md.push_str(".\n");
    std::fs::write(run_dir.file("report.md"), md).map_err(|e| Error::io(&run_dir.file("report.md"), e))
}

/// Observed frames above the model's reconstructions of them (newer frame of each pair, from the encoder mean).
fn write_reconstructions(trained: &TrainedDlgpd, pool: &Dataset, path: &Path) -> Result<()> {
    let ObservationKind::Images { side } = trained.run.observation else {
        return Ok(());
    };
    let windows = Windows::from_dataset(pool, trained.run.observation, 0)?;
    let rows: Vec<usize> = (0..windows.len()).step_by(3).take(8).collect();
    let (obs, _) = windows.observations(&rows);
    let width = trained.run.observation.input_len();
    let device = inference_device();
    let (mean, _) = encode_rows(&trained.vae, &obs, width, &device);
    let latent = trained.run.config.latent_dim;
    let decoded = trained.vae.decode(tensor(mean, [rows.len(), latent], &device));
    let plane = side * side;
    let (columns, canvas_w, canvas_h) = (rows.len(), rows.len() * side, 2 * side);
    let mut rgb = vec![0u8; canvas_w * canvas_h * 3];
    for (source, row) in [(&obs, 0), (&decoded, 1)] {
        for k in 0..columns {
            // The newer frame: channels 3..6 of the pair.
            let frame = &source[k * width + 3 * plane..(k + 1) * width];
            for y in 0..side {
                for x in 0..side {
                    let at = ((row * side + y) * canvas_w + k * side + x) * 3;
                    for c in 0..3 {
                        rgb[at + c] = (frame[c * plane + y * side + x].clamp(0.0, 1.0) * 255.0).round() as u8;
                    }
                }
            }
        }
    }
    let png = encode_rgb(canvas_w as u32, canvas_h as u32, &rgb)?;
    std::fs::write(path, png).map_err(|e| Error::io(path, e))
}
