//! `mbrl eval quick`: a small reproduction of every method, the README's first command. Each method adds
//! its slice here; the whole job stays around a minute on two cores.

use std::path::Path;

use super::ball::{self, BallEvalSettings};
use super::boards::{self, EmbodiedSettings};
use super::swingup::{self, SwingupSettings};
use crate::data::collect_ball::{collect_ball, BallCollectSettings};
use crate::envs::ball::Orientation;
use crate::envs::boards::{LightsOut, Split};
use crate::envs::embodiments::Embodiment;
use crate::envs::pendulum::PendulumVariant;
use crate::error::{Error, Result};
use crate::models::ball::checkpoint::{load_ball_model, LoadedBallModel};
use crate::models::ball::learn::{train, TrainSettings};
use crate::models::ball::BallModel;
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::util::atomic::write_text;

pub const SWINGUP_EPISODES: usize = 5;
pub const EMBODIED_BOARDS_PER_DEPTH: usize = 20;
/// Enough to see the likelihood climb; the thesis-scale run is `make repro-ball`.
pub const QUICK_BALL_TRAIN_STEPS: u64 = 150;

pub struct QuickSummary {
    pub lines: Vec<String>,
}

pub fn run_quick(provenance: &Provenance, out_dir: &Path, monitor: &dyn Monitor) -> Result<QuickSummary> {
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    let settings = SwingupSettings::thesis(PendulumVariant::Standard);
    let swing = swingup::evaluate(&settings, SWINGUP_EPISODES, provenance, &out_dir.join("pendulum-swingup"), monitor)?;
    let mut lines = vec![format!(
        "pendulum swing-up (ground-truth model, CEM {}×{}×{}): {}/{} episodes succeeded; see pendulum-swingup/report.md",
        settings.cem.candidates, settings.cem.horizon, settings.cem.iterations, swing.successes, swing.episodes
    )];
    let rows = boards::depth_report(provenance, &out_dir.join("boards"), monitor)?;
    let differing = rows.iter().filter(|r| r.thesis.is_some_and(|t| t != r.boards)).count();
    lines.push(format!(
        "board depth tables (LightsOut 5×5, TileSwap 3×3): {} depths, {differing} differ from thesis Table 7.1; see boards/report.md",
        rows.len()
    ));
    let embodied = EmbodiedSettings {
        embodiment: Embodiment::Reacher,
        max_depth: 5,
        boards_per_depth: EMBODIED_BOARDS_PER_DEPTH,
        split: Split::Test,
    };
    let played = boards::embodied_report(
        &LightsOut::new(5)?,
        &embodied,
        provenance,
        &out_dir.join("lightsout-reacher"),
        monitor,
    )?;
    let (total, solved) = played.iter().fold((0, 0), |(t, s), r| (t + r.boards, s + r.solved));
    lines.push(format!(
        "LightsOut played by the Reacher's scripted controller, depths 1-5 (test split): {solved}/{total} boards solved; see lightsout-reacher/report.md"
    ));
    lines.push(ball_slice(provenance, out_dir, monitor)?);
    let mut md = String::from("# mbrl quick reproduction\n\nSmall-scale runs of each implemented method.\n\n");
    for line in &lines {
        md.push_str(&format!("- {line}\n"));
    }
    let path = out_dir.join("report.md");
    write_text(&path, &md)?;
    Ok(QuickSummary { lines })
}

/// Ball: a short EKF training run from Table C.1 on simulated shots, then the prediction protocol for
/// the trained model, the thesis' parameters and the black-box baseline.
fn ball_slice(provenance: &Provenance, out_dir: &Path, monitor: &dyn Monitor) -> Result<String> {
    let train_settings = BallCollectSettings {
        trajectories: 12,
        orientation: Orientation::Default,
        augment_rotations: 1,
        seed: provenance.seed,
        command_line: String::new(),
    };
    let recordings = collect_ball(&train_settings, monitor)?.recordings;
    let settings = TrainSettings {
        steps: QUICK_BALL_TRAIN_STEPS,
        batch_size: 32,
        seed: provenance.seed,
        ..TrainSettings::default()
    };
    let trained = train(&recordings, &settings, monitor)?;
    let first = trained.losses.first().copied().unwrap_or(f64::NAN);
    let last = trained.losses.last().copied().unwrap_or(f64::NAN);
    let models = vec![
        (
            "trained (quick)".to_string(),
            LoadedBallModel {
                model: BallModel::new(trained.params).map_err(|e| Error::Diverged(e.to_string()))?,
                spin_net: None,
            },
        ),
        ("thesis".to_string(), load_ball_model("thesis")?),
    ];
    let eval = BallEvalSettings {
        train_shots: 20,
        augment_rotations: 3,
        test_shots_default: 30,
        test_shots_unseen: 6,
        ..BallEvalSettings::default()
    };
    let summary = ball::evaluate(&eval, models, provenance, &out_dir.join("ball"), monitor)?;
    let median = |method: &str| {
        summary.median_at(method, "unseen", 1.0).map(|m| format!("{:.1} cm", 100.0 * m)).unwrap_or_else(|| "–".into())
    };
    Ok(format!(
        "ball EKF: {QUICK_BALL_TRAIN_STEPS} training steps lowered the loss {first:.2} -> {last:.2}; median 1 s prediction error on unseen poses: \
         trained {}, thesis parameters {}, ridge baseline {}; see ball/report.md",
        median("trained (quick)"),
        median("thesis"),
        median("ridge baseline")
    ))
}
