//! Board-game evaluations: the depth and split tables (thesis Tables 7.1, 7.2), and how reliably a
//! manipulator's scripted controller plays optimal plans to the goal.

use std::path::Path;

use rand::seq::IndexedRandom;
use serde::{Deserialize, Serialize};

use super::num;
use super::plot::{line_panels, Panel, Series};
use super::summary::{publish, write_config};
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

/// Thesis Table 7.1: boards per solution depth (depths 0..).
pub const LIGHTSOUT_TABLE_7_1: [u64; 16] =
    [1, 25, 300, 2300, 12650, 53130, 176176, 467104, 982335, 1596279, 1935294, 1684446, 1004934, 383670, 82614, 7350];
pub const TILESWAP_TABLE_7_1: [u64; 17] =
    [1, 12, 88, 470, 1978, 6658, 18081, 38936, 65246, 83000, 76688, 48316, 18975, 4024, 382, 24, 1];
/// Thesis Table 7.2: (train, test) boards at depths 1-5.
pub const LIGHTSOUT_TABLE_7_2: [(u64, u64); 5] = [(7, 18), (99, 201), (785, 1515), (4200, 8450), (17849, 35281)];
pub const TILESWAP_TABLE_7_2: [(u64, u64); 5] = [(7, 5), (31, 57), (179, 291), (683, 1295), (2237, 4421)];

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DepthRow {
    pub game: String,
    pub depth: usize,
    pub boards: u64,
    pub train: u64,
    pub test: u64,
    /// Table 7.1's count at this depth.
    pub thesis: Option<u64>,
    /// Table 7.2's (train, test) at this depth (depths 1-5).
    pub thesis_split: Option<(u64, u64)>,
}

fn depth_rows<G: DenseIndex>(
    game: &G,
    thesis: &[u64],
    thesis_split: &[(u64, u64)],
    monitor: &dyn Monitor,
) -> Result<Vec<DepthRow>> {
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
        rows.push(DepthRow {
            game: game.name(),
            depth,
            boards,
            train,
            test,
            thesis: thesis.get(depth).copied(),
            thesis_split: depth.checked_sub(1).and_then(|d| thesis_split.get(d)).copied(),
        });
        monitor.progress(&format!("{} depths", game.name()), depth as u64 + 1, counts.len() as u64);
    }
    Ok(rows)
}

pub const BOARDS_PROTOCOL: &str = "boards";
pub const EMBODIED_PROTOCOL: &str = "embodied";

/// `mbrl eval boards` has no settings: the tables are exhaustive.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardsConfig {}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BoardsSummary {
    pub provenance: Provenance,
    pub rows: Vec<DepthRow>,
}

impl std::fmt::Display for BoardsSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "game        depth   boards    train     test   thesis")?;
        for r in &self.rows {
            let thesis = r.thesis.map(|t| t.to_string()).unwrap_or_else(|| "-".into());
            write!(f, "\n{:<11} {:>5} {:>8} {:>8} {:>8} {:>8}", r.game, r.depth, r.boards, r.train, r.test, thesis)?;
        }
        Ok(())
    }
}

/// `mbrl eval boards`: depth and split tables of LightsOut 5×5 and TileSwap 3×3.
pub fn depth_report(provenance: &Provenance, out_dir: &Path, monitor: &dyn Monitor) -> Result<BoardsSummary> {
    let run = RunDir::create(out_dir)?;
    write_config(&BoardsConfig {}, provenance, run.path())?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    let mut rows = depth_rows(&LightsOut::new(5)?, &LIGHTSOUT_TABLE_7_1, &LIGHTSOUT_TABLE_7_2, &monitor)?;
    rows.extend(depth_rows(&TileSwap::new(), &TILESWAP_TABLE_7_1, &TILESWAP_TABLE_7_2, &monitor)?);
    let summary = BoardsSummary { provenance: provenance.clone(), rows };
    publish(BOARDS_PROTOCOL, &summary, run.path(), render_depths)?;
    // Only the run's own file is told it finished: the caller's view may have more jobs to show.
    metrics.emit(&Event::Finished { ok: true });
    Ok(summary)
}

/// Writes depth_table.csv, depths.png and report.md of `summary` into `dir`.
pub fn render_depths(summary: &BoardsSummary, dir: &Path) -> Result<()> {
    let rows = &summary.rows;
    let csv_rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let thesis = r.thesis.map(|t| t.to_string()).unwrap_or_default();
            let (thesis_train, thesis_test) =
                r.thesis_split.map(|(a, b)| (a.to_string(), b.to_string())).unwrap_or_default();
            vec![
                r.game.clone(),
                r.depth.to_string(),
                r.boards.to_string(),
                r.train.to_string(),
                r.test.to_string(),
                thesis,
                thesis_train,
                thesis_test,
            ]
        })
        .collect();
    write_csv(
        &dir.join("depth_table.csv"),
        &[
            "game",
            "depth",
            "boards",
            "train",
            "test",
            "thesis_table_7_1",
            "thesis_table_7_2_train",
            "thesis_table_7_2_test",
        ],
        &csv_rows,
    )?;
    let mut md = String::from(
        "# Board games: solution depths and splits\n\n\
         Boards per optimal solution depth (LightsOut: every press set enumerated; TileSwap: breadth-first search\n\
         from the solved board), and the train/test split by CRC32 of the canonical board string mod 3 (appendix\n\
         D.1.4). `7.1` is the thesis' Table 7.1 (boards per depth), `7.2 train`/`7.2 test` its Table 7.2 (depths 1-5).\n\n\
         | game | depth | boards | train | test | 7.1 | 7.2 train | 7.2 test |\n|---|---|---|---|---|---|---|---|\n",
    );
    let dash = || "–".to_string();
    for r in rows {
        let thesis = r.thesis.map(|t| t.to_string()).unwrap_or_else(dash);
        let (a, b) = r.thesis_split.map(|(a, b)| (a.to_string(), b.to_string())).unwrap_or_else(|| (dash(), dash()));
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {thesis} | {a} | {b} |\n",
            r.game, r.depth, r.boards, r.train, r.test
        ));
    }
    let mismatches = rows.iter().filter(|r| r.thesis.is_some_and(|t| t != r.boards)).count();
    let split_mismatches = rows.iter().filter(|r| r.thesis_split.is_some_and(|t| t != (r.train, r.test))).count();
    md.push_str(&format!(
        "\nRows differing from Table 7.1: {mismatches}. Rows differing from Table 7.2: {split_mismatches}.\n\n\
         ![boards per depth](depths.png)\n"
    ));
    depth_plot(&dir.join("depths.png"), rows)?;
    write_text(&dir.join("report.md"), &md)
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmbodiedSettings {
    pub embodiment: Embodiment,
    pub max_depth: u8,
    pub boards_per_depth: usize,
    pub split: Split,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct EmbodiedRow {
    pub depth: u8,
    pub boards: usize,
    pub solved: usize,
    #[serde(with = "num::real")]
    pub mean_control_steps: f64,
}

/// `mbrl eval embodied`'s settings, as config.json records them.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmbodiedConfig {
    /// lightsout (5x5), lightsout:N or tileswap.
    pub game: String,
    pub settings: EmbodiedSettings,
}

impl EmbodiedConfig {
    pub fn validate(&self) -> Result<()> {
        if self.settings.max_depth == 0 || self.settings.boards_per_depth == 0 {
            return Err(crate::error::Error::config("--max-depth and --boards must be at least 1"));
        }
        Ok(())
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EmbodiedSummary {
    pub provenance: Provenance,
    /// The game as the report names it (`LightsOut 5x5`).
    pub game: String,
    pub settings: EmbodiedSettings,
    pub rows: Vec<EmbodiedRow>,
}

impl EmbodiedSummary {
    /// (boards, solved) over every depth.
    pub fn totals(&self) -> (usize, usize) {
        self.rows.iter().fold((0, 0), |(t, s), r| (t + r.boards, s + r.solved))
    }
}

impl std::fmt::Display for EmbodiedSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        for (i, r) in self.rows.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(
                f,
                "depth {}: {}/{} solved ({:.1} %), {:.1} control steps per board",
                r.depth,
                r.solved,
                r.boards,
                100.0 * r.solved as f64 / r.boards.max(1) as f64,
                r.mean_control_steps
            )?;
        }
        Ok(())
    }
}

/// `mbrl eval embodied` from its recorded settings.
pub fn embodied(
    config: &EmbodiedConfig,
    provenance: &Provenance,
    out_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<EmbodiedSummary> {
    config.validate()?;
    match crate::envs::boards::GameSpec::parse(&config.game)? {
        crate::envs::boards::GameSpec::LightsOut(n) => {
            embodied_report(&LightsOut::new(n)?, config, provenance, out_dir, monitor)
        }
        crate::envs::boards::GameSpec::TileSwap => {
            embodied_report(&TileSwap::new(), config, provenance, out_dir, monitor)
        }
    }
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
    config: &EmbodiedConfig,
    provenance: &Provenance,
    out_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<EmbodiedSummary> {
    let settings = &config.settings;
    let run = RunDir::create(out_dir)?;
    write_config(config, provenance, run.path())?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    let rows = embodied_rows(game, settings, provenance.seed, &monitor)?;
    let summary =
        EmbodiedSummary { provenance: provenance.clone(), game: game.name(), settings: settings.clone(), rows };
    publish(EMBODIED_PROTOCOL, &summary, run.path(), render_embodied)?;
    // Only the run's own file is told it finished: the caller's view may have more jobs to show.
    metrics.emit(&Event::Finished { ok: true });
    Ok(summary)
}

/// Writes embodied.csv, embodied.png and report.md of `summary` into `dir`.
pub fn render_embodied(summary: &EmbodiedSummary, dir: &Path) -> Result<()> {
    let (rows, settings) = (&summary.rows, &summary.settings);
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
        &dir.join("embodied.csv"),
        &["depth", "boards", "solved", "success_rate", "mean_control_steps"],
        &csv_rows,
    )?;
    let (total, solved) = summary.totals();
    let mut md = format!(
        "# {} played by the {} scripted controller\n\n\
         Boards of each depth drawn from the {} split; plans by bidirectional BFS with the true rules, executed\n\
         move by move (skill step limit per move). Overall: {solved}/{total} solved ({:.2} %).\n\n\
         | depth | boards | solved | success rate | mean control steps |\n|---|---|---|---|---|\n",
        summary.game,
        settings.embodiment.name(),
        settings.split.as_str(),
        100.0 * solved as f64 / total.max(1) as f64
    );
    for r in rows {
        md.push_str(&format!(
            "| {} | {} | {} | {:.2} % | {:.1} |\n",
            r.depth,
            r.boards,
            r.solved,
            100.0 * r.solved as f64 / r.boards.max(1) as f64,
            r.mean_control_steps
        ));
    }
    md.push_str("\n![success and control steps per depth](embodied.png)\n");
    embodied_plot(&dir.join("embodied.png"), &summary.game, settings.embodiment.name(), rows)?;
    write_text(&dir.join("report.md"), &md)
}

/// Boards per depth on a log scale, all and per split, one panel per game.
fn depth_plot(path: &Path, rows: &[DepthRow]) -> Result<()> {
    let mut games: Vec<String> = rows.iter().map(|r| r.game.clone()).collect();
    games.dedup();
    let panels: Vec<Panel> = games
        .iter()
        .map(|game| {
            let of = |name: &str, count: &dyn Fn(&DepthRow) -> u64| Series {
                name: name.to_string(),
                points: rows
                    .iter()
                    .filter(|r| &r.game == game)
                    .map(|r| (r.depth as f64, if count(r) > 0 { (count(r) as f64).log10() } else { f64::NAN }))
                    .collect(),
            };
            let series =
                vec![of("all boards", &|r| r.boards), of("train split", &|r| r.train), of("test split", &|r| r.test)];
            Panel { y_label: format!("{game}: log10 boards"), series, y_range: None }
        })
        .collect();
    line_panels(path, "Boards per optimal solution depth (Tables 7.1, 7.2)", "depth [moves]", &panels)
}

/// Success rate and mean control steps against the plan depth.
fn embodied_plot(path: &Path, game: &str, embodiment: &str, rows: &[EmbodiedRow]) -> Result<()> {
    let points = |f: &dyn Fn(&EmbodiedRow) -> f64| rows.iter().map(|r| (r.depth as f64, f(r))).collect::<Vec<_>>();
    let most_steps = rows.iter().map(|r| r.mean_control_steps).fold(0.0, f64::max);
    let panels = vec![
        Panel {
            y_label: "success rate [%]".into(),
            series: vec![Series {
                name: "solved".into(),
                points: points(&|r| 100.0 * r.solved as f64 / r.boards.max(1) as f64),
            }],
            y_range: Some((0.0, 105.0)),
        },
        Panel {
            y_label: "mean control steps".into(),
            series: vec![Series { name: "control steps".into(), points: points(&|r| r.mean_control_steps) }],
            y_range: Some((0.0, 1.1 * most_steps.max(1.0))),
        },
    ];
    line_panels(path, &format!("{game} played by the {embodiment}"), "depth [moves]", &panels)
}
