//! `eval boards`, `eval embodied` and `eval seads`: the board-game protocols.

use std::path::PathBuf;

use clap::Args;

use super::{recorded, report_job, EvalSummary};
use crate::eval::boards::{self, EmbodiedConfig, EmbodiedSettings};
use crate::eval::seads::{
    compare_runs, run_name, seads_report, variant_label, ComparedRun, SeadsEvalConfig, SeadsEvalSettings,
};
use crate::eval::summary::Summary;
use crate::jobs::choices::{EmbodimentChoice, SplitChoice};
use crate::jobs::model_options::{accepting, report_unfinished};
use crate::jobs::overrides::Overrides;
use crate::jobs::{output_dir, Invocation, Job};
use crate::Result;

#[derive(Args, Debug)]
pub struct BoardsOptions {
    /// Report directory (default: reports/boards; when that exists, the first free reports/boards-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun with the seed a boards report recorded (its config.json).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

pub fn boards(options: BoardsOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let provenance = match &options.config {
        Some(path) => recorded::<boards::BoardsConfig>(invocation, path)?.1,
        None => invocation.provenance(),
    };
    Ok(report_job(
        "eval boards",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/boards"), invocation)?,
        move |monitor, out| Ok(Summary::Boards(boards::depth_report(&provenance, out, monitor)?)),
    ))
}

#[derive(Args, Debug)]
pub struct EmbodiedOptions {
    /// Game: lightsout (5x5) or tileswap.
    #[arg(long, required_unless_present = "config", value_parser = crate::jobs::names::games(), hide_possible_values = true)]
    game: Option<String>,
    /// Manipulator.
    #[arg(long, value_enum, required_unless_present = "config")]
    embodiment: Option<EmbodimentChoice>,
    /// Boards of depth 1..=max-depth are evaluated.
    #[arg(long, default_value_t = 5)]
    max_depth: u8,
    /// Boards drawn per depth (fewer when the split has fewer).
    #[arg(long, default_value_t = 100)]
    boards: usize,
    /// Split the boards come from.
    #[arg(long, value_enum, default_value_t = SplitChoice::Test)]
    split: SplitChoice,
    /// Report directory (default: reports/embodied; when that exists, the first free reports/embodied-2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rerun the settings and seed an embodied report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["game", "embodiment", "max_depth", "boards", "split"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

pub fn embodied(options: EmbodiedOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => (
            EmbodiedConfig {
                game: options.game.clone().unwrap_or_default(),
                settings: EmbodiedSettings {
                    embodiment: options.embodiment.unwrap_or(EmbodimentChoice::Cursor).into(),
                    max_depth: options.max_depth,
                    boards_per_depth: options.boards,
                    split: options.split.into(),
                },
            },
            invocation.provenance(),
        ),
    };
    let config = options.set.apply(config)?;
    config.validate()?;
    config.settings.embodiment.ensure_buildable()?;
    Ok(report_job(
        "eval embodied",
        output_dir("--out", options.out.as_deref(), || PathBuf::from("reports/embodied"), invocation)?,
        move |monitor, out| Ok(Summary::Embodied(boards::embodied(&config, &provenance, out, monitor)?)),
    ))
}

#[derive(Args, Debug)]
pub struct SeadsOptions {
    /// A SEADS checkpoint directory (`mbrl train seads`); repeat it to compare runs (seeds of the full
    /// method and of ablations: one-sided Mann-Whitney U tests of each ablation against `full`).
    #[arg(long, required_unless_present = "config")]
    model: Vec<PathBuf>,
    /// Boards of depth 1..=max-depth are solved.
    #[arg(long, default_value_t = 5)]
    max_depth: u8,
    /// Boards per depth (thesis: 20).
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// Boards every skill is executed from for the coverage table.
    #[arg(long, default_value_t = 100)]
    coverage_boards: usize,
    /// Replans allowed per board (thesis: 10).
    #[arg(long, default_value_t = 10)]
    max_replans: usize,
    /// Split the boards come from.
    #[arg(long, value_enum, default_value_t = SplitChoice::Test)]
    split: SplitChoice,
    /// A search storing more states than this counts as a failure (a model lacking a move can make the goal
    /// unreachable).
    #[arg(long, default_value_t = 2_000_000)]
    max_nodes: usize,
    /// Report directory (default: reports/seads-<checkpoint name>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Take runs still in training (the weights of their last checkpoint); the report says how far each got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Rerun the settings and seed a seads report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "max_depth", "boards", "coverage_boards", "max_replans", "split", "max_nodes", "allow_incomplete"])]
    config: Option<PathBuf>,
    #[command(flatten)]
    set: Overrides,
}

/// One report per checkpoint; with several, each goes in a subdirectory named for its run and the top
/// directory holds their comparison.
pub fn seads(options: SeadsOptions, invocation: &Invocation) -> Result<Job<'static, EvalSummary>> {
    let (config, provenance) = match &options.config {
        Some(path) => recorded(invocation, path)?,
        None => (
            SeadsEvalConfig {
                models: options.model.clone(),
                allow_incomplete: options.allow_incomplete,
                settings: SeadsEvalSettings {
                    max_depth: options.max_depth,
                    boards_per_depth: options.boards,
                    coverage_boards: options.coverage_boards,
                    max_replans: options.max_replans,
                    split: options.split.into(),
                    max_search_nodes: options.max_nodes,
                },
            },
            invocation.provenance(),
        ),
    };
    let config = options.set.apply(config)?;
    config.validate()?;
    let out = output_dir("--out", options.out.as_deref(), || config.default_out(), invocation)?;
    let loaded: Vec<_> = config
        .models
        .iter()
        .map(|m| crate::models::seads::planner::load(m, accepting(config.allow_incomplete)))
        .collect::<Result<_>>()?;
    for model in &loaded {
        report_unfinished(&model.dir, &model.progress);
    }
    Ok(Job::new("eval seads", move |monitor| {
        if let [model] = &loaded[..] {
            let summary = Summary::Seads(seads_report(model, &config, &provenance, &out, monitor)?);
            return Ok(EvalSummary { compared: Vec::new(), summary, out });
        }
        let mut runs = Vec::new();
        for (dir, model) in config.models.iter().zip(&loaded) {
            let own = SeadsEvalConfig { models: vec![dir.to_path_buf()], ..config.clone() };
            runs.push(ComparedRun {
                name: run_name(dir),
                variant: variant_label(&model.run.config),
                seed: model.run.seed,
                summary: seads_report(model, &own, &provenance, &out.join(run_name(dir)), monitor)?,
            });
        }
        let summary = Summary::SeadsCompare(compare_runs(&runs, &config, &provenance, &out)?);
        Ok(EvalSummary { compared: runs.into_iter().map(|r| r.summary).collect(), summary, out })
    }))
}
