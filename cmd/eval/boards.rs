//! `eval boards`, `eval embodied` and `eval seads`: the board-game protocols.

use std::path::PathBuf;

use clap::Args;
use mbrl::eval::boards::{self, EmbodiedConfig, EmbodiedSettings};
use mbrl::eval::seads::{
    compare_runs, run_name, seads_report, variant_label, ComparedRun, SeadsEvalConfig, SeadsEvalSettings,
};
use mbrl::run::dir::Provenance;

use super::{print, recorded};
use crate::common::{run_job, GlobalArgs};
use mbrl::jobs::choices::{EmbodimentChoice, SplitChoice};
use mbrl::jobs::model_options::{accepting, report_unfinished};

#[derive(Args, Debug)]
pub struct BoardsArgs {
    /// Report directory.
    #[arg(long, default_value = "reports/boards")]
    out: PathBuf,
    /// Rerun with the seed a boards report recorded (its config.json).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

pub fn boards(global: &GlobalArgs, provenance: Provenance, a: BoardsArgs) -> anyhow::Result<()> {
    let provenance = match &a.config {
        Some(path) => recorded::<boards::BoardsConfig>(global, path)?.1,
        None => provenance,
    };
    let summary = run_job(global, "eval boards", |monitor| boards::depth_report(&provenance, &a.out, monitor))?;
    print(&summary, &a.out);
    Ok(())
}

#[derive(Args, Debug)]
pub struct EmbodiedArgs {
    /// Game: lightsout (5x5) or tileswap.
    #[arg(long, required_unless_present = "config")]
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
    /// Report directory.
    #[arg(long, default_value = "reports/embodied")]
    out: PathBuf,
    /// Rerun the settings and seed an embodied report recorded (its config.json); no other flag but --out.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["game", "embodiment", "max_depth", "boards", "split"])]
    config: Option<PathBuf>,
}

pub fn embodied(global: &GlobalArgs, provenance: Provenance, a: EmbodiedArgs) -> anyhow::Result<()> {
    let (config, provenance) = match &a.config {
        Some(path) => recorded(global, path)?,
        None => (
            EmbodiedConfig {
                game: a.game.clone().unwrap_or_default(),
                settings: EmbodiedSettings {
                    embodiment: a.embodiment.unwrap_or(EmbodimentChoice::Cursor).into(),
                    max_depth: a.max_depth,
                    boards_per_depth: a.boards,
                    split: a.split.into(),
                },
            },
            provenance,
        ),
    };
    config.validate()?;
    let summary = run_job(global, "eval embodied", |monitor| boards::embodied(&config, &provenance, &a.out, monitor))?;
    print(&summary, &a.out);
    Ok(())
}

#[derive(Args, Debug)]
pub struct SeadsArgs {
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
    /// Rerun the settings and seed a seads report recorded (its config.json); no other flag but --out.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "max_depth", "boards", "coverage_boards", "max_replans", "split", "max_nodes", "allow_incomplete"])]
    config: Option<PathBuf>,
}

pub fn seads(global: &GlobalArgs, provenance: Provenance, a: SeadsArgs) -> anyhow::Result<()> {
    let (config, provenance) = match &a.config {
        Some(path) => recorded(global, path)?,
        None => (
            SeadsEvalConfig {
                models: a.model.clone(),
                allow_incomplete: a.allow_incomplete,
                settings: SeadsEvalSettings {
                    max_depth: a.max_depth,
                    boards_per_depth: a.boards,
                    coverage_boards: a.coverage_boards,
                    max_replans: a.max_replans,
                    split: a.split.into(),
                    max_search_nodes: a.max_nodes,
                },
            },
            provenance,
        ),
    };
    config.validate()?;
    let out = a.out.clone().unwrap_or_else(|| config.default_out());
    let loaded: Vec<_> = config
        .models
        .iter()
        .map(|m| mbrl::models::seads::planner::load(m, accepting(config.allow_incomplete)))
        .collect::<Result<_, _>>()?;
    for model in &loaded {
        report_unfinished(&model.dir, &model.progress);
    }
    let compared = config.models.len() > 1;
    let mut runs = Vec::new();
    for (dir, model) in config.models.iter().zip(&loaded) {
        let report_dir = if compared { out.join(run_name(dir)) } else { out.clone() };
        let own = SeadsEvalConfig { models: vec![dir.to_path_buf()], ..config.clone() };
        let s = run_job(global, "eval seads", |monitor| seads_report(model, &own, &provenance, &report_dir, monitor))?;
        say!("{s}");
        runs.push(ComparedRun {
            name: run_name(dir),
            variant: variant_label(&model.run.config),
            seed: model.run.seed,
            summary: s,
        });
    }
    if compared {
        print(&compare_runs(&runs, &config, &provenance, &out)?, &out);
    } else {
        say!("report: {}", out.join("report.md").display());
    }
    Ok(())
}
