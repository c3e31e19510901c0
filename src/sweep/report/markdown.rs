//! The report's text: `report.md` for reading, `cells.csv` and `compare.csv` for further analysis. Every
//! figure is formatted from the value alone, so the same runs give the same bytes.

use std::fmt::Write;

use super::compare::{Comparison, Outcome};
use super::interval::{short, Interval};
use super::StageReport;
use crate::data::export::format_f64;
use crate::error::{Error, Result};

/// Above this many scalars a stage's table lists one scalar and cell per row instead of a column each.
const WIDE_SCALARS: usize = 4;
/// Missing runs named one by one; a stage of thousands is summarised by the count of the rest.
const NAMED_MISSING: usize = 50;

pub fn report_md(title: &str, stages: &[StageReport], comparisons: &[Comparison]) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Sweep report: {}\n", esc(title));
    md.push_str(
        "Each figure is the mean over a cell's finished runs (its seeds) ± half the width of the 95 % t interval \
         (Student's t with n − 1 degrees of freedom); n is the number of runs with a finite value. One run has no \
         interval. Standard deviations and interval bounds: `cells.csv`.\n",
    );
    for stage in stages {
        stage_md(&mut md, stage, comparisons);
    }
    md
}

fn stage_md(md: &mut String, stage: &StageReport, comparisons: &[Comparison]) {
    let runs = &stage.runs;
    let jobs = runs.stage.jobs.len();
    let _ = writeln!(
        md,
        "\n## Stage `{}` ({}): {} of {jobs} runs done\n",
        esc(&runs.stage.name),
        esc(&runs.stage.subcommand),
        runs.runs.len()
    );
    let names = &runs.scalar_names;
    if names.is_empty() {
        md.push_str("| cell | n |\n|---|---|\n");
        for (cell, n, _) in &stage.stats {
            let _ = writeln!(md, "| {} | {n} |", esc(cell));
        }
        if !runs.runs.is_empty() {
            md.push_str("\nThe outputs hold no summary.json or metrics.jsonl, so there are no scalars to report.\n");
        }
    } else if names.len() <= WIDE_SCALARS {
        let header: String = names.iter().map(|n| format!(" `{}` |", esc(n))).collect();
        let _ = writeln!(md, "| cell | n |{header}\n|---|---|{}", "---|".repeat(names.len()));
        for (cell, n, intervals) in &stage.stats {
            let figures: String = intervals.iter().map(|i| format!(" {} |", figure(i, *n))).collect();
            let _ = writeln!(md, "| {} | {n} |{figures}", esc(cell));
        }
    } else {
        md.push_str("| scalar | cell | n | mean ± 95 % t |\n|---|---|---|---|\n");
        for (k, name) in names.iter().enumerate() {
            for (cell, _, intervals) in &stage.stats {
                let i = &intervals[k];
                let _ = writeln!(md, "| `{}` | {} | {} | {} |", esc(name), esc(cell), i.n, figure(i, i.n));
            }
        }
    }
    if !stage.curves.plots.is_empty() {
        md.push_str("\n### Learning curves\n\n");
        for plot in &stage.curves.plots {
            let _ = writeln!(md, "![{}]({})\n", esc(&plot.metric), plot.file);
            match plot.bins {
                (1, 1) => {}
                (low, high) if low == high => {
                    let _ = writeln!(
                        md,
                        "Each point averages {high} consecutive steps of each run before the mean over seeds.\n"
                    );
                }
                (low, high) => {
                    let _ = writeln!(
                        md,
                        "Each point averages {low} to {high} consecutive steps of each run (the longer the runs, the more) \
                         before the mean over seeds.\n"
                    );
                }
            }
        }
    }
    if !stage.curves.skipped.is_empty() {
        md.push_str("\nNot plotted:\n\n");
        for (metric, why) in &stage.curves.skipped {
            let _ = writeln!(md, "- `{}`: {why}", esc(metric));
        }
    }
    let own: Vec<&Comparison> = comparisons.iter().filter(|c| c.spec.stage == runs.stage.name).collect();
    if !own.is_empty() {
        md.push_str("\n### Comparisons\n\n| # | scalar | a | b | test | n | statistic | p |\n|---|---|---|---|---|---|---|---|\n");
        for c in own {
            let n = match c.pairs {
                Some(pairs) => format!("{pairs} pairs by seed ({} vs {} runs)", c.n_a, c.n_b),
                None => format!("{} vs {}", c.n_a, c.n_b),
            };
            let (statistic, p) = match &c.outcome {
                Outcome::Tested { statistic, p_value, method } => {
                    (format!("{} ({method})", short(*statistic)), short(*p_value))
                }
                Outcome::NotRun(why) => (format!("not run: {}", esc(why)), "n/a".to_string()),
            };
            let _ = writeln!(
                md,
                "| {} | `{}` | {} | {} | {}, {} | {n} | {statistic} | {p} |",
                c.index,
                esc(&c.spec.metric),
                esc(&c.cell_a),
                esc(&c.cell_b),
                c.test_name(),
                c.alternative_name()
            );
        }
    }
    if !runs.missing.is_empty() {
        let _ = writeln!(md, "\n### Missing runs ({} of {jobs})\n", runs.missing.len());
        for m in runs.missing.iter().take(NAMED_MISSING) {
            let _ = writeln!(md, "- `{}`: {}", esc(&m.name), esc(&m.why));
        }
        if runs.missing.len() > NAMED_MISSING {
            let _ = writeln!(md, "- and {} more", runs.missing.len() - NAMED_MISSING);
        }
    }
}

/// `mean ± half-width`, the count where it differs from the cell's, `n/a` without values.
fn figure(i: &Interval, runs: usize) -> String {
    let Some(mean) = i.mean else { return "n/a".to_string() };
    let mut text = match i.half_width {
        Some(h) => format!("{} ± {}", short(mean), short(h)),
        None => short(mean),
    };
    if i.n != runs {
        let _ = write!(text, " (n={})", i.n);
    }
    if i.non_finite > 0 {
        let _ = write!(text, " ({} not finite)", i.non_finite);
    }
    text
}

/// Table cells hold no pipes or line breaks.
fn esc(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

pub fn cells_csv(stages: &[StageReport]) -> Result<Vec<u8>> {
    let mut rows = vec![["stage", "cell", "metric", "n", "mean", "sd", "ci_low", "ci_high"].map(String::from).to_vec()];
    let opt = |x: Option<f64>| x.map(format_f64).unwrap_or_default();
    for stage in stages {
        for (cell, _, intervals) in &stage.stats {
            for (name, i) in stage.runs.scalar_names.iter().zip(intervals) {
                rows.push(vec![
                    stage.runs.stage.name.clone(),
                    cell.clone(),
                    name.clone(),
                    i.n.to_string(),
                    opt(i.mean),
                    opt(i.sd),
                    opt(i.low()),
                    opt(i.high()),
                ]);
            }
        }
    }
    csv_bytes(rows)
}

pub fn compare_csv(comparisons: &[Comparison]) -> Result<Vec<u8>> {
    let header = [
        "index",
        "stage",
        "metric",
        "a",
        "b",
        "test",
        "alternative",
        "n_a",
        "n_b",
        "pairs",
        "statistic",
        "p_value",
        "method",
        "note",
    ];
    let mut rows = vec![header.map(String::from).to_vec()];
    for c in comparisons {
        let (statistic, p, method, note) = match &c.outcome {
            Outcome::Tested { statistic, p_value, method } => {
                (format_f64(*statistic), format_f64(*p_value), method.clone(), String::new())
            }
            Outcome::NotRun(why) => (String::new(), String::new(), String::new(), why.clone()),
        };
        rows.push(vec![
            c.index.to_string(),
            c.spec.stage.clone(),
            c.spec.metric.clone(),
            c.cell_a.clone(),
            c.cell_b.clone(),
            c.test_name().to_string(),
            c.alternative_name().to_string(),
            c.n_a.to_string(),
            c.n_b.to_string(),
            c.pairs.map(|p| p.to_string()).unwrap_or_default(),
            statistic,
            p,
            method,
            note,
        ]);
    }
    csv_bytes(rows)
}

fn csv_bytes(rows: Vec<Vec<String>>) -> Result<Vec<u8>> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for row in rows {
        writer.write_record(&row).map_err(|e| Error::data(format!("report table: {e}")))?;
    }
    writer.into_inner().map_err(|e| Error::data(format!("report table: {e}")))
}
