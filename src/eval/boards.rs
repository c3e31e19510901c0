//! Board-game evaluations: the depth and split tables (thesis Tables 7.1, 7.2), and how reliably a
//! manipulator's scripted controller plays optimal plans to the goal.

use std::path::Path;

use rand::seq::IndexedRandom;
use serde::Serialize;

use crate::envs::boards::depth::{DenseIndex, DepthTable};
use crate::envs::boards::sets::boards_at;
use crate::envs::boards::{split_of, LightsOut, Split, TileSwap};
use crate::envs::embodiments::Embodiment;
use crate::error::Result;
use crate::planning::bfs::SearchLimits;
use crate::planning::solve_board::{execute_plan, plan_board, SearchKind};
use crate::run::dir::{Provenance, RunDir};
use crate::run::{Event, Monitor, NullMonitor, Tee};
use crate::util::atomic::write_text;
use crate::util::seeding::rng_for;
use crate::util::table::write_csv;

/// Thesis Table 7.1, for the comparison column of the report (depths 0..).
const THESIS_LIGHTSOUT: [u64; 16] =
    [1, 25, 300, 2300, 12650, 53130, 176176, 467104, 982335, 1596279, 1935294, 1684446, 1004934, 383670, 82614, 7350];
const THESIS_TILESWAP: [u64; 17] =
    [1, 12, 88, 470, 1978, 6658, 18081, 38936, 65246, 83000, 76688, 48316, 18975, 4024, 382, 24, 1];

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DepthRow {
    pub game: String,
    pub depth: usize,
    pub boards: u64,
    pub train: u64,
    pub test: u64,
    pub thesis: Option<u64>,
}

fn depth_rows<G: DenseIndex>(game: &G, thesis: &[u64], monitor: &dyn Monitor) -> Result<Vec<DepthRow>> {
    monitor.message(&format!("building the depth table of {}", game.name()));
    let table = DepthTable::build(game)?;
    let counts = table.counts();
    let mut rows = Vec::with_capacity(counts.len());
    for (depth, &boards) in counts.iter().enumerate() {
        let (mut train, mut test) = (0, 0);
        for index in table.indices_at(depth as u8) {
            match split_of(&game.canonical_string(game.state_at(index))) {
                Split::Train => train += 1,
                Split::Test => test += 1,
            }
        }
        rows.push(DepthRow { game: game.name(), depth, boards, train, test, thesis: thesis.get(depth).copied() });
        monitor.progress(&format!("{} depths", game.name()), depth as u64 + 1, counts.len() as u64);
    }
    Ok(rows)
}

/// `mbrl eval boards`: depth and split tables of LightsOut 5×5 and TileSwap 3×3.
pub fn depth_report(provenance: &Provenance, out_dir: &Path, monitor: &dyn Monitor) -> Result<Vec<DepthRow>> {
    let run = RunDir::create(out_dir)?;
    run.write_config(&serde_json::json!({"job": "eval boards", "provenance": provenance}))?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    let mut rows = depth_rows(&LightsOut::new(5)?, &THESIS_LIGHTSOUT, &monitor)?;
    rows.extend(depth_rows(&TileSwap::new(), &THESIS_TILESWAP, &monitor)?);
    let csv_rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let thesis = r.thesis.map(|t| t.to_string()).unwrap_or_default();
            vec![
                r.game.clone(),
                r.depth.to_string(),
                r.boards.to_string(),
                r.train.to_string(),
                r.test.to_string(),
                thesis,
            ]
        })
        .collect();
    write_csv(
        &run.file("depth_table.csv"),
        &["game", "depth", "boards", "train", "test", "thesis_table_7_1"],
        &csv_rows,
    )?;
    let mut md = String::from(
        "# Board games: solution depths and splits\n\n\
         Boards per optimal solution depth by reverse breadth-first search from the solved board, and the\n\
         train/test split by CRC32 of the canonical board string mod 3 (appendix D.1.4). `thesis` is Table 7.1.\n\n\
         | game | depth | boards | train | test | thesis |\n|---|---|---|---|---|---|\n",
    );
    for r in &rows {
        let thesis = r.thesis.map(|t| t.to_string()).unwrap_or_else(|| "–".into());
        md.push_str(&format!("| {} | {} | {} | {} | {} | {} |\n", r.game, r.depth, r.boards, r.train, r.test, thesis));
    }
    let mismatches = rows.iter().filter(|r| r.thesis.is_some_and(|t| t != r.boards)).count();
    md.push_str(&format!("\nRows differing from Table 7.1: {mismatches}.\n"));
    let path = run.file("report.md");
    write_text(&path, &md)?;
    // Only the run's own file is told it finished: the caller's view may have more jobs to show.
    metrics.emit(&Event::Finished { ok: true });
    Ok(rows)
}

#[derive(Clone, Debug, Serialize)]
pub struct EmbodiedSettings {
    pub embodiment: Embodiment,
    pub max_depth: u8,
    pub boards_per_depth: usize,
    pub split: Split,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct EmbodiedRow {
    pub depth: u8,
    pub boards: usize,
    pub solved: usize,
    pub mean_control_steps: f64,
}

fn embodied_rows<G: DenseIndex>(
    game: &G,
    settings: &EmbodiedSettings,
    seed: u64,
    monitor: &dyn Monitor,
) -> Result<Vec<EmbodiedRow>> {
    let table = DepthTable::build(game)?;
    let mut rows = Vec::new();
    for depth in 1..=settings.max_depth {
        let mut rng = rng_for(seed, &[depth as u64]);
        let pool = boards_at(game, &table, depth, Some(settings.split));
        let chosen: Vec<G::State> = pool.choose_multiple(&mut rng, settings.boards_per_depth).copied().collect();
        let (mut solved, mut steps) = (0, 0);
        for (i, &board) in chosen.iter().enumerate() {
            let result = plan_board(game, board, SearchKind::Bidirectional, &SearchLimits::default(), &NullMonitor)?;
            let plan = result.plan.unwrap_or_default();
            let mut episode_rng = rng_for(seed, &[depth as u64, i as u64, 1]);
            let run = execute_plan(game, board, &plan, settings.embodiment, &mut episode_rng, &NullMonitor)?;
            solved += run.solved as usize;
            steps += run.control_steps;
            monitor.progress(&format!("depth {depth} boards"), i as u64 + 1, chosen.len() as u64);
        }
        let row = EmbodiedRow {
            depth,
            boards: chosen.len(),
            solved,
            mean_control_steps: steps as f64 / chosen.len().max(1) as f64,
        };
        monitor.scalar("embodied/success_rate", depth as u64, row.solved as f64 / row.boards.max(1) as f64);
        rows.push(row);
    }
    Ok(rows)
}

/// `mbrl eval embodied`: the scripted controller plays optimal plans for boards of depth 1..=max_depth.
pub fn embodied_report<G: DenseIndex>(
    game: &G,
    settings: &EmbodiedSettings,
    provenance: &Provenance,
    out_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<Vec<EmbodiedRow>> {
    let run = RunDir::create(out_dir)?;
    run.write_config(&serde_json::json!({
        "job": "eval embodied", "game": game.name(), "settings": settings, "provenance": provenance
    }))?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    let rows = embodied_rows(game, settings, provenance.seed, &monitor)?;
    let csv_rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let rate = r.solved as f64 / r.boards.max(1) as f64;
            vec![
                r.depth.to_string(),
                r.boards.to_string(),
                r.solved.to_string(),
                format!("{rate:.4}"),
                format!("{:.2}", r.mean_control_steps),
            ]
        })
        .collect();
    write_csv(
        &run.file("embodied.csv"),
        &["depth", "boards", "solved", "success_rate", "mean_control_steps"],
        &csv_rows,
    )?;
    let (total, solved) = rows.iter().fold((0, 0), |(t, s), r| (t + r.boards, s + r.solved));
    let mut md = format!(
        "# {} played by the {} scripted controller\n\n\
         Boards of each depth drawn from the {} split; plans by bidirectional BFS with the true rules, executed\n\
         move by move (skill step limit per move). Overall: {solved}/{total} solved ({:.2} %).\n\n\
         | depth | boards | solved | success rate | mean control steps |\n|---|---|---|---|---|\n",
        game.name(),
        settings.embodiment.name(),
        settings.split.as_str(),
        100.0 * solved as f64 / total.max(1) as f64
    );
    for r in &rows {
        md.push_str(&format!(
            "| {} | {} | {} | {:.2} % | {:.1} |\n",
            r.depth,
            r.boards,
            r.solved,
            100.0 * r.solved as f64 / r.boards.max(1) as f64,
            r.mean_control_steps
        ));
    }
    let path = run.file("report.md");
    write_text(&path, &md)?;
    // Only the run's own file is told it finished: the caller's view may have more jobs to show.
    metrics.emit(&Event::Finished { ok: true });
    Ok(rows)
}
