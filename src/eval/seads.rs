//! `mbrl eval seads`: what a trained SEADS checkpoint can do (thesis 7.4): which game move each skill executes
//! from test-split boards (skill coverage, Table 7.3), how often boards of depth 1..D are solved by planning
//! over the forward model and executing with the skills, with and without replanning (Fig. 7.9/7.10), how long
//! skills take, and planning time.

use std::path::Path;

use rand::seq::IndexedRandom;
use serde::{Deserialize, Serialize};

use crate::envs::boards::{BoardGame, GameSpec, LightsOut, Split, TileSwap};
use crate::error::{Error, ErrorKind, Result};
use crate::eval::num;
use crate::eval::plot::{box_plot, line_plot_in, Series};
use crate::eval::summary::{publish, write_config};
use crate::models::seads::boards::BoardPool;
use crate::models::seads::collect::{Collector, Starts};
use crate::models::seads::planner::{solve_with_skills, LoadedSeads};
use crate::planning::bfs::SearchLimits;
use crate::run::dir::{Provenance, RunDir};
use crate::run::{Event, Monitor, NullMonitor, Tee};
use crate::util::atomic::write_text;
use crate::util::domain::Domain;
use crate::util::seeding::rng_for;
use crate::util::table::write_csv;

pub const PROTOCOL: &str = "seads";
pub const COMPARE_PROTOCOL: &str = "seads-compare";

/// `mbrl eval seads`'s settings, as config.json records them.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeadsEvalConfig {
    /// The checkpoints evaluated (several: compared).
    pub models: Vec<std::path::PathBuf>,
    pub allow_incomplete: bool,
    pub settings: SeadsEvalSettings,
}

/// The name a checkpoint directory gets in reports and comparisons.
pub fn run_name(dir: &Path) -> String {
    dir.file_name().and_then(|n| n.to_str()).unwrap_or("model").to_string()
}

const BOARDS: Domain = Domain::count(1, 20_000);
const COVERAGE_BOARDS: Domain = Domain::count(1, 100_000);

impl SeadsEvalConfig {
    pub fn validate(&self) -> Result<()> {
        let s = &self.settings;
        if s.max_depth == 0 || s.max_depth > 10 || s.boards_per_depth == 0 || s.coverage_boards == 0 {
            return Err(Error::config("--max-depth must be 1..=10 and --boards, --coverage-boards at least 1"));
        }
        // Boards are sampled into memory before any is solved: a count near 2^64 was an allocation that
        // aborted. The bounds are a thousand times the thesis' 20 boards per depth and our default 100.
        for (flag, value, domain) in
            [("--boards", s.boards_per_depth, BOARDS), ("--coverage-boards", s.coverage_boards, COVERAGE_BOARDS)]
        {
            domain.check_count(flag, value as u64).map_err(|e| Error::config(e.to_string()))?;
        }
        if self.models.is_empty() {
            return Err(Error::config("eval seads needs at least one --model"));
        }
        let mut names: Vec<String> = self.models.iter().map(|m| run_name(m)).collect();
        names.sort();
        if self.models.len() > 1 && names.windows(2).any(|w| w[0] == w[1]) {
            return Err(Error::config(
                "--model directories to compare need distinct names (each gets a report subdirectory of that name)",
            ));
        }
        Ok(())
    }

    /// The report directory when none is given: reports/seads-<checkpoint name>, or reports/seads-compare.
    pub fn default_out(&self) -> std::path::PathBuf {
        std::path::PathBuf::from(if self.models.len() == 1 {
            format!("reports/seads-{}", run_name(&self.models[0]))
        } else {
            "reports/seads-compare".into()
        })
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeadsEvalSettings {
    pub max_depth: u8,
    pub boards_per_depth: usize,
    /// Boards each skill is executed from for the coverage table.
    pub coverage_boards: usize,
    pub max_replans: usize,
    pub split: Split,
    /// Stored search states after which a board counts as unsolved: a model that lacks a move can leave the
    /// goal unreachable, and the search would then walk the whole reachable space (2²³ LightsOut boards).
    pub max_search_nodes: usize,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SkillRow {
    pub skill: usize,
    /// The game move this skill performs most often, if it performs any.
    pub mode_move: Option<usize>,
    #[serde(with = "num::real")]
    pub mode_share: f64,
    /// Share of executions that changed nothing before the step limit.
    #[serde(with = "num::real")]
    pub no_move_share: f64,
    #[serde(with = "num::real")]
    pub mean_steps: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DepthRow {
    pub depth: usize,
    pub boards: usize,
    pub solved_with_replanning: usize,
    pub solved_without_replanning: usize,
    #[serde(with = "num::real")]
    pub mean_planning_seconds: f64,
    #[serde(with = "num::real")]
    pub mean_control_steps: f64,
    /// Searches (with and without replanning) that hit the node budget; their boards count as unsolved.
    pub search_budget_exhausted: usize,
    /// Manipulator steps of every skill executed on the boards solved with replanning (Fig. 7.9).
    pub skill_lengths: Vec<usize>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SeadsEvalSummary {
    pub provenance: Provenance,
    pub settings: SeadsEvalSettings,
    /// The checkpoint directory's name.
    pub name: String,
    pub env: String,
    /// The game's move names, by move index.
    pub move_names: Vec<String>,
    /// The checkpoint and how far it was trained, as the report names it.
    pub model: String,
    pub skills: Vec<SkillRow>,
    /// Distinct game moves among the skills' most frequent moves (Table 7.3's figure).
    pub distinct_moves: usize,
    pub moves: usize,
    pub depths: Vec<DepthRow>,
}

impl std::fmt::Display for SeadsEvalSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{} ({}): the skills' most frequent moves cover {} of {} game moves",
            self.name, self.env, self.distinct_moves, self.moves
        )?;
        for r in &self.depths {
            let n = r.boards.max(1) as f64;
            write!(
                f,
                "\n  depth {}: {:.1} % solved with ≤ {} replans, {:.1} % without; planning {:.4} s per board",
                r.depth,
                100.0 * r.solved_with_replanning as f64 / n,
                self.settings.max_replans,
                100.0 * r.solved_without_replanning as f64 / n,
                r.mean_planning_seconds
            )?;
        }
        Ok(())
    }
}

fn coverage<G: BoardGame>(
    game: &G,
    loaded: &LoadedSeads,
    boards: &[G::State],
    seed: u64,
    monitor: &dyn Monitor,
) -> Result<Vec<SkillRow>> {
    let k = loaded.run.config.skills;
    let mut collector = Collector::new(game, loaded.env.embodiment, boards.len().clamp(1, 64), k)?;
    let layout = collector.layout;
    let rows = (0..k)
        .map(|skill| {
            let mut rng = rng_for(seed, &[10, skill as u64]);
            let labels = vec![skill; boards.len()];
            let episodes = collector.collect(&labels, Starts::Boards(boards), &mut rng, |inputs, rows, rng| {
                loaded.policy.act(inputs, rows, true, rng)
            });
            let mut counts = vec![0usize; game.num_moves()];
            let mut none = 0;
            for e in &episodes {
                match e.performed {
                    Some(m) => counts[m] += 1,
                    None => none += 1,
                }
            }
            let best =
                counts.iter().enumerate().max_by_key(|&(m, &c)| (c, std::cmp::Reverse(m))).filter(|(_, &c)| c > 0);
            let n = episodes.len().max(1) as f64;
            monitor.progress("skill coverage", skill as u64 + 1, k as u64);
            SkillRow {
                skill,
                mode_move: best.map(|(m, _)| m),
                mode_share: best.map_or(0.0, |(_, &c)| c as f64 / n),
                no_move_share: none as f64 / n,
                mean_steps: episodes.iter().map(|e| layout.steps(e) as f64).sum::<f64>() / n,
            }
        })
        .collect::<Vec<_>>();
    Ok(rows)
}

fn success_rows<G: BoardGame>(
    game: &G,
    loaded: &LoadedSeads,
    pool: &BoardPool<G>,
    settings: &SeadsEvalSettings,
    seed: u64,
    monitor: &dyn Monitor,
) -> Result<Vec<DepthRow>> {
    let limits = SearchLimits { max_nodes: settings.max_search_nodes, ..SearchLimits::default() };
    let mut rows = Vec::new();
    for depth in 1..=pool.max_depth() {
        let mut rng = rng_for(seed, &[20, depth as u64]);
        let boards: Vec<G::State> =
            pool.layer(depth).choose_multiple(&mut rng, settings.boards_per_depth).copied().collect();
        let mut row = DepthRow {
            depth,
            boards: boards.len(),
            solved_with_replanning: 0,
            solved_without_replanning: 0,
            mean_planning_seconds: 0.0,
            mean_control_steps: 0.0,
            search_budget_exhausted: 0,
            skill_lengths: Vec::new(),
        };
        for (i, &board) in boards.iter().enumerate() {
            for replans in [settings.max_replans, 0] {
                let mut episode_rng = rng_for(seed, &[21, depth as u64, i as u64]);
                let out = match solve_with_skills(
                    game,
                    loaded,
                    board,
                    true,
                    &limits,
                    replans,
                    &mut episode_rng,
                    &NullMonitor,
                ) {
                    Ok(out) => out,
                    Err(e) if matches!(e.kind(), ErrorKind::Budget { .. }) => {
                        row.search_budget_exhausted += 1;
                        continue;
                    }
                    Err(e) => return Err(e),
                };
                if replans == 0 {
                    row.solved_without_replanning += out.solved as usize;
                } else {
                    row.solved_with_replanning += out.solved as usize;
                    if out.solved {
                        row.skill_lengths.extend(out.executed.iter().map(|e| e.steps));
                    }
                    row.mean_planning_seconds += out.planning_seconds;
                    row.mean_control_steps += out.control_steps as f64;
                }
            }
            monitor.progress(&format!("depth {depth} boards"), i as u64 + 1, boards.len() as u64);
        }
        let n = row.boards.max(1) as f64;
        row.mean_planning_seconds /= n;
        row.mean_control_steps /= n;
        monitor.scalar("seads/success_rate", depth as u64, row.solved_with_replanning as f64 / n);
        rows.push(row);
    }
    Ok(rows)
}

/// Runs the protocol on a loaded checkpoint and writes report.md, skills.csv, success.csv, success.png,
/// skill_lengths.csv and skill_lengths.png.
/// `config` is what this report's config.json records: the one checkpoint evaluated here.
pub fn seads_report(
    loaded: &LoadedSeads,
    config: &SeadsEvalConfig,
    provenance: &Provenance,
    out_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<SeadsEvalSummary> {
    config.validate()?;
    match loaded.env.game {
        GameSpec::TileSwap => report_game(&TileSwap::new(), loaded, config, provenance, out_dir, monitor),
        GameSpec::LightsOut(n) => report_game(&LightsOut::new(n)?, loaded, config, provenance, out_dir, monitor),
    }
}

fn report_game<G: BoardGame>(
    game: &G,
    loaded: &LoadedSeads,
    config: &SeadsEvalConfig,
    provenance: &Provenance,
    out_dir: &Path,
    monitor: &dyn Monitor,
) -> Result<SeadsEvalSummary> {
    let settings = &config.settings;
    let run = RunDir::create(out_dir)?;
    write_config(config, provenance, run.path())?;
    let metrics = run.metrics()?;
    let monitor = Tee { first: monitor, second: &metrics };
    let seed = provenance.seed;
    let pool = BoardPool::new(game, settings.max_depth, settings.split)?;
    // Coverage boards: an even mix of the evaluated depths.
    let mut rng = rng_for(seed, &[30]);
    let coverage_boards: Vec<G::State> = (0..settings.coverage_boards).map(|_| pool.sample(&mut rng)).collect();
    let skills = coverage(game, loaded, &coverage_boards, seed, &monitor)?;
    let mut modes: Vec<usize> = skills.iter().filter_map(|s| s.mode_move).collect();
    modes.sort_unstable();
    modes.dedup();
    let depths = success_rows(game, loaded, &pool, settings, seed, &monitor)?;
    let summary = SeadsEvalSummary {
        provenance: provenance.clone(),
        settings: settings.clone(),
        name: run_name(&loaded.dir),
        env: loaded.env.name(),
        move_names: (0..game.num_moves()).map(|m| game.move_name(m)).collect(),
        model: loaded.progress.name_model(&loaded.dir),
        distinct_moves: modes.len(),
        moves: game.num_moves(),
        skills,
        depths,
    };
    publish(PROTOCOL, &summary, run.path(), render)?;
    metrics.emit(&Event::Finished { ok: true });
    Ok(summary)
}

/// Writes skills.csv, success.csv/.png, skill_lengths.csv/.png and report.md of `s` into `dir`.
pub fn render(s: &SeadsEvalSummary, dir: &Path) -> Result<()> {
    let settings = &s.settings;
    let move_name = |m: usize| {
        s.move_names.get(m).cloned().ok_or_else(|| {
            Error::config(format!("skills: move {m} is not among the {} move_names", s.move_names.len()))
        })
    };
    let skill_rows: Vec<Vec<String>> = s
        .skills
        .iter()
        .map(|r| {
            Ok(vec![
                r.skill.to_string(),
                r.mode_move.map(move_name).transpose()?.unwrap_or_else(|| "none".into()),
                format!("{:.4}", r.mode_share),
                format!("{:.4}", r.no_move_share),
                format!("{:.2}", r.mean_steps),
            ])
        })
        .collect::<Result<_>>()?;
    write_csv(
        &dir.join("skills.csv"),
        &["skill", "most_frequent_move", "share", "no_move_share", "mean_steps"],
        &skill_rows,
    )?;
    let depth_rows: Vec<Vec<String>> = s
        .depths
        .iter()
        .map(|r| {
            vec![
                r.depth.to_string(),
                r.boards.to_string(),
                r.solved_with_replanning.to_string(),
                r.solved_without_replanning.to_string(),
                format!("{:.5}", r.mean_planning_seconds),
                format!("{:.2}", r.mean_control_steps),
                r.search_budget_exhausted.to_string(),
            ]
        })
        .collect();
    write_csv(
        &dir.join("success.csv"),
        &[
            "depth",
            "boards",
            "solved_with_replanning",
            "solved_without_replanning",
            "mean_planning_s",
            "mean_control_steps",
            "searches_over_budget",
        ],
        &depth_rows,
    )?;
    let rate = |f: fn(&DepthRow) -> usize| -> Vec<(f64, f64)> {
        s.depths.iter().map(|r| (r.depth as f64, 100.0 * f(r) as f64 / r.boards.max(1) as f64)).collect()
    };
    line_plot_in(
        &dir.join("success.png"),
        &format!("{}: boards solved by planning with learned skills", s.env),
        "solution depth",
        "solved (%)",
        &[
            Series {
                name: format!("≤ {} replans", settings.max_replans), points: rate(|r| r.solved_with_replanning)
            },
            Series {
                name: "no replanning (drawn over the other where equal)".into(),
                points: rate(|r| r.solved_without_replanning),
            },
        ],
        (0.0, 105.0),
    )?;
    let length_rows: Vec<Vec<String>> = s
        .depths
        .iter()
        .flat_map(|r| r.skill_lengths.iter().map(move |l| vec![r.depth.to_string(), l.to_string()]))
        .collect();
    write_csv(&dir.join("skill_lengths.csv"), &["depth", "steps"], &length_rows)?;
    let lengths = |r: &DepthRow| r.skill_lengths.iter().map(|&l| l as f64).collect::<Vec<f64>>();
    let mut groups: Vec<(String, Vec<f64>)> =
        s.depths.iter().map(|r| (format!("depth {}", r.depth), lengths(r))).collect();
    groups.push(("all".into(), s.depths.iter().flat_map(lengths).collect()));
    box_plot(
        &dir.join("skill_lengths.png"),
        &format!("{}: skill lengths on solved boards", s.env),
        "solution depth of the board",
        "manipulator steps per skill",
        &groups,
    )?;
    let mut md = format!(
        "# SEADS on {}\n\nModel {}.\n\nSkill coverage (thesis Table 7.3): {} of {} game moves are the most frequent move of some skill, \
         each skill executed with its deterministic policy from {} {}-split boards of depth 1-{}. \
         Thesis (Cursor, 500k steps): 24.94 / 25 LightsOut, 11.99 / 12 TileSwap.\n\n\
         | skill | most frequent move | share | no move | mean steps |\n|---|---|---|---|---|\n",
        s.env,
        s.model,
        s.distinct_moves,
        s.moves,
        settings.coverage_boards,
        settings.split.as_str(),
        settings.max_depth
    );
    for (r, cells) in s.skills.iter().zip(&skill_rows) {
        md.push_str(&format!(
            "| {} | {} | {:.1} % | {:.1} % | {:.1} |\n",
            r.skill,
            cells[1],
            100.0 * r.mode_share,
            100.0 * r.no_move_share,
            r.mean_steps
        ));
    }
    md.push_str(&format!(
        "\n## Solving boards (thesis Fig. 7.9/7.10; Cursor: 100 %)\n\n{} boards per depth from the {} split; BFS over the \
         forward model's most likely successors (bidirectional where the model proves self-inverse on every state it \
         expands), each skill executed by the policy until the board changes or the step limit, a new plan when the \
         board differs from the prediction. A search that stores more than {} states counts as a failure.\n\n\
         | depth | boards | solved (≤ {} replans) | solved (no replanning) | planning s / board | control steps / board | searches over budget |\n\
         |---|---|---|---|---|---|---|\n",
        settings.boards_per_depth,
        settings.split.as_str(),
        settings.max_search_nodes,
        settings.max_replans
    ));
    for r in &s.depths {
        let n = r.boards.max(1) as f64;
        md.push_str(&format!(
            "| {} | {} | {:.1} % | {:.1} % | {:.4} | {:.1} | {} |\n",
            r.depth,
            r.boards,
            100.0 * r.solved_with_replanning as f64 / n,
            100.0 * r.solved_without_replanning as f64 / n,
            r.mean_planning_seconds,
            r.mean_control_steps,
            r.search_budget_exhausted
        ));
    }
    md.push_str("\n![success](success.png)\n");
    let all = &groups.last().expect("the all group is pushed above").1;
    md.push_str(&format!(
        "\n## Skill lengths (thesis Fig. 7.9)\n\nManipulator steps per executed skill on the boards solved with \
         replanning: median {}, quartiles {} / {} over {} skill executions (skill_lengths.csv). Thesis medians: 3 \
         LightsOutCursor, 2 TileSwapCursor, 11 LightsOutReacher, 9 TileSwapReacher.\n\n![skill lengths](skill_lengths.png)\n",
        fmt_quantile(all, 0.5),
        fmt_quantile(all, 0.25),
        fmt_quantile(all, 0.75),
        all.len()
    ));
    write_text(&dir.join("report.md"), &md)
}

fn fmt_quantile(values: &[f64], q: f64) -> String {
    crate::eval::stats::quantile(values, q).map_or_else(|| "–".into(), |v| format!("{v:.1}"))
}

/// The ablation a run belongs to, from its config: `full`, or the reward terms and relabelling it switched off.
pub fn variant_label(config: &crate::models::seads::SeadsConfig) -> String {
    let mut off = Vec::new();
    if !config.relabel {
        off.push("no-relabel");
    }
    if !config.reward.second_best {
        off.push("no-second-best");
    }
    if !config.reward.novelty {
        off.push("no-novelty");
    }
    if off.is_empty() {
        "full".into()
    } else {
        off.join("+")
    }
}

/// One evaluated checkpoint in a comparison.
pub struct ComparedRun {
    pub name: String,
    pub variant: String,
    pub seed: u64,
    pub summary: SeadsEvalSummary,
}

impl ComparedRun {
    /// Boards solved (with replanning) over all depths.
    pub fn success_rate(&self) -> f64 {
        let (boards, solved) =
            self.summary.depths.iter().fold((0, 0), |(b, s), r| (b + r.boards, s + r.solved_with_replanning));
        solved as f64 / boards.max(1) as f64
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VariantTest {
    pub better: String,
    pub worse: String,
    pub metric: String,
    #[serde(with = "num::real")]
    pub u: f64,
    #[serde(with = "num::real")]
    pub p_value: f64,
}

/// One run in a comparison's table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunRow {
    pub name: String,
    pub variant: String,
    pub seed: u64,
    pub distinct_moves: usize,
    #[serde(with = "num::real")]
    pub success_rate: f64,
}

/// Several SEADS runs compared over seeds (each run's own report is in a subdirectory).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SeadsComparison {
    pub provenance: Provenance,
    pub runs: Vec<RunRow>,
    pub tests: Vec<VariantTest>,
}

impl std::fmt::Display for SeadsComparison {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        for (i, t) in self.tests.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(
                f,
                "{} > {} on {}: Mann-Whitney U = {}, one-sided p = {:.3e}",
                t.better, t.worse, t.metric, t.u, t.p_value
            )?;
        }
        Ok(())
    }
}

/// Seeds of each variant against the `full` method (one-sided Mann-Whitney U: full is better), or, without a
/// `full` group, every ordered pair of variants. Writes config.json, summary.json, runs.csv, tests.csv and
/// report.md in `out_dir`.
pub fn compare_runs(
    runs: &[ComparedRun],
    config: &SeadsEvalConfig,
    provenance: &Provenance,
    out_dir: &Path,
) -> Result<SeadsComparison> {
    use crate::eval::stats::{mann_whitney_u, Alternative};
    let envs: Vec<&str> = runs.iter().map(|r| r.summary.env.as_str()).collect();
    if envs.iter().any(|e| *e != envs[0]) {
        return Err(Error::config(format!("runs to compare must share one env, got {}", envs.join(", "))));
    }
    let mut variants: Vec<String> = runs.iter().map(|r| r.variant.clone()).collect();
    variants.sort();
    variants.dedup();
    let pairs: Vec<(String, String)> = if variants.iter().any(|v| v == "full") {
        variants.iter().filter(|v| *v != "full").map(|v| ("full".to_string(), v.clone())).collect()
    } else {
        variants
            .iter()
            .flat_map(|a| variants.iter().filter(move |b| *b != a).map(move |b| (a.clone(), b.clone())))
            .collect()
    };
    type Metric = fn(&ComparedRun) -> f64;
    let metrics: [(&str, Metric); 2] =
        [("success_rate", ComparedRun::success_rate), ("distinct_moves", |r| r.summary.distinct_moves as f64)];
    let mut tests = Vec::new();
    for (better, worse) in &pairs {
        for (metric, f) in metrics {
            let a: Vec<f64> = runs.iter().filter(|r| &r.variant == better).map(f).collect();
            let b: Vec<f64> = runs.iter().filter(|r| &r.variant == worse).map(f).collect();
            let result = mann_whitney_u(&a, &b, Alternative::Greater)?;
            tests.push(VariantTest {
                better: better.clone(),
                worse: worse.clone(),
                metric: metric.into(),
                u: result.statistic,
                p_value: result.p_value,
            });
        }
    }
    let comparison = SeadsComparison {
        provenance: provenance.clone(),
        runs: runs
            .iter()
            .map(|r| RunRow {
                name: r.name.clone(),
                variant: r.variant.clone(),
                seed: r.seed,
                distinct_moves: r.summary.distinct_moves,
                success_rate: r.success_rate(),
            })
            .collect(),
        tests,
    };
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    write_config(config, provenance, out_dir)?;
    publish(COMPARE_PROTOCOL, &comparison, out_dir, render_comparison)?;
    Ok(comparison)
}

/// Writes runs.csv, tests.csv and report.md of a comparison into `dir`.
pub fn render_comparison(c: &SeadsComparison, dir: &Path) -> Result<()> {
    let rows: Vec<Vec<String>> = c
        .runs
        .iter()
        .map(|r| {
            vec![
                r.name.clone(),
                r.variant.clone(),
                r.seed.to_string(),
                r.distinct_moves.to_string(),
                format!("{:.4}", r.success_rate),
            ]
        })
        .collect();
    write_csv(&dir.join("runs.csv"), &["run", "variant", "seed", "distinct_moves", "success_rate"], &rows)?;
    let test_rows: Vec<Vec<String>> = c
        .tests
        .iter()
        .map(|t| {
            vec![t.better.clone(), t.worse.clone(), t.metric.clone(), format!("{}", t.u), format!("{:.4e}", t.p_value)]
        })
        .collect();
    write_csv(&dir.join("tests.csv"), &["better", "worse", "metric", "u", "p_value"], &test_rows)?;
    let mut md = String::from(
        "# SEADS runs compared\n\nEach run evaluated as in its own report (subdirectory of the same name). Success \
         rate = boards of every depth solved with replanning.\n\n| run | variant | seed | distinct moves | success rate |\n\
         |---|---|---|---|---|\n",
    );
    for r in &rows {
        md.push_str(&format!("| {} | {} | {} | {} | {} |\n", r[0], r[1], r[2], r[3], r[4]));
    }
    md.push_str(
        "\n## One-sided Mann-Whitney U tests over seeds (thesis 7.4.6)\n\nH1: the first variant's values tend to be \
         larger. With three seeds per variant the smallest attainable p is 0.05.\n\n| better | worse | metric | U | p |\n\
         |---|---|---|---|---|\n",
    );
    for t in &test_rows {
        md.push_str(&format!("| {} | {} | {} | {} | {} |\n", t[0], t[1], t[2], t[3], t[4]));
    }
    write_text(&dir.join("report.md"), &md)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--coverage-boards 18446744073709551615` sized a vector of boards and aborted on capacity overflow
    /// (found by the extremes fuzzer); counts beyond their domain are a one-line error naming the flag.
    #[test]
    fn board_counts_are_bounded_before_any_board_is_sampled() {
        let settings = SeadsEvalSettings {
            max_depth: 1,
            boards_per_depth: 1,
            coverage_boards: 1,
            max_replans: 1,
            split: Split::Test,
            max_search_nodes: 1000,
        };
        let config = |settings| SeadsEvalConfig { models: vec!["m".into()], allow_incomplete: false, settings };
        assert!(config(settings.clone()).validate().is_ok());
        let huge = SeadsEvalSettings { coverage_boards: usize::MAX, ..settings.clone() };
        let err = config(huge).validate().unwrap_err().to_string();
        assert!(
            err.contains("--coverage-boards = 18446744073709551615: expected a whole number in 1..=100000"),
            "{err}"
        );
        let huge = SeadsEvalSettings { boards_per_depth: 1 << 40, ..settings };
        let err = config(huge).validate().unwrap_err().to_string();
        assert!(err.contains("--boards = 1099511627776: expected a whole number in 1..=20000"), "{err}");
    }
}
