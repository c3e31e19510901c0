//! `mbrl sweep report`: the finished runs of every stage, grouped into cells (the grid values without the
//! seed), as means with 95 % t intervals, learning curves over seeds, and the spec's comparisons.
//! Nothing here depends on the order files were written in or on the clock: the same runs give the same
//! bytes.

mod collect;
mod compare;
mod curves;
mod interval;
mod markdown;
#[cfg(test)]
mod tests;

use std::fmt;
use std::path::{Path, PathBuf};

use collect::StageRuns;
use curves::Curves;
use interval::Interval;

use crate::error::{Error, Result};
use crate::sweep::plan::Plan;

pub const REPORT_FILE: &str = "report.md";
pub const CELLS_FILE: &str = "cells.csv";
pub const COMPARE_FILE: &str = "compare.csv";

/// One stage's runs and what the report computed from them.
struct StageReport<'a> {
    runs: StageRuns<'a>,
    /// Per cell, in plan order: its label, its finished runs, and one interval per scalar (`scalar_names`).
    stats: Vec<(String, usize, Vec<Interval>)>,
    curves: Curves,
}

/// What `write_report` wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportSummary {
    pub out: PathBuf,
    pub stages: Vec<StageSummary>,
    pub comparisons: usize,
    /// File names written under `out`, the report first.
    pub files: Vec<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct StageSummary {
    pub name: String,
    pub jobs: usize,
    pub done: usize,
    /// Cell label and its finished runs.
    pub cells: Vec<(String, usize)>,
    pub scalars: usize,
    pub plots: usize,
}

/// Reads every stage's runs of `plan` and writes `report.md`, `cells.csv`, `compare.csv` (when the spec
/// compares) and the curve PNGs into `out`, creating it. A comparison naming an unknown scalar or a cell no
/// job has is refused before anything is written.
pub fn write_report(plan: &Plan, out: &Path) -> Result<ReportSummary> {
    let stage_runs: Vec<StageRuns> = plan.stages.iter().map(StageRuns::read).collect();
    let mut comparisons = Vec::with_capacity(plan.spec.compares.len());
    for (index, spec) in plan.spec.compares.iter().enumerate() {
        let Some(stage) = stage_runs.iter().find(|s| s.stage.name == spec.stage) else {
            return Err(Error::config(format!(
                "compare[{index}].stage: '{}' is not a stage of this sweep",
                spec.stage
            )));
        };
        comparisons.push(compare::compare(index, spec, stage)?);
    }
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let mut stages = Vec::with_capacity(stage_runs.len());
    for runs in stage_runs {
        let stats = runs
            .cells
            .iter()
            .map(|(cell, _)| {
                let done = runs.runs_of(cell);
                let intervals = runs
                    .scalar_names
                    .iter()
                    .map(|name| Interval::of(&done.iter().filter_map(|r| r.scalar(name)).collect::<Vec<f64>>()))
                    .collect();
                (cell.clone(), done.len(), intervals)
            })
            .collect();
        let curves = curves::write_curves(&runs, out)?;
        stages.push(StageReport { runs, stats, curves });
    }
    let mut files = vec![REPORT_FILE.to_string(), CELLS_FILE.to_string()];
    crate::util::atomic::write_text(
        &out.join(REPORT_FILE),
        &markdown::report_md(&plan.spec.sweep.name, &stages, &comparisons),
    )?;
    write_bytes(&out.join(CELLS_FILE), &markdown::cells_csv(&stages)?)?;
    if !comparisons.is_empty() {
        write_bytes(&out.join(COMPARE_FILE), &markdown::compare_csv(&comparisons)?)?;
        files.push(COMPARE_FILE.to_string());
    }
    files.extend(stages.iter().flat_map(|s| s.curves.plots.iter().map(|p| p.file.clone())));
    let stages = stages
        .iter()
        .map(|s| StageSummary {
            name: s.runs.stage.name.clone(),
            jobs: s.runs.stage.jobs.len(),
            done: s.runs.runs.len(),
            cells: s.stats.iter().map(|(cell, n, _)| (cell.clone(), *n)).collect(),
            scalars: s.runs.scalar_names.len(),
            plots: s.curves.plots.len(),
        })
        .collect();
    Ok(ReportSummary { out: out.to_path_buf(), stages, comparisons: comparisons.len(), files })
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::util::atomic::write_atomic(path, |w| w.write_all(bytes).map_err(|e| Error::io(path, e)))
}

/// Cells named in the console line before the rest are counted.
const CELLS_SHOWN: usize = 6;

impl fmt::Display for ReportSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plots = self.files.iter().filter(|f| f.ends_with(".png")).count();
        let tables: Vec<&str> = self.files.iter().filter(|f| !f.ends_with(".png")).map(String::as_str).collect();
        write!(f, "report in {}: {}", self.out.display(), tables.join(", "))?;
        if plots > 0 {
            write!(f, ", {plots} plot{}", if plots == 1 { "" } else { "s" })?;
        }
        for s in &self.stages {
            write!(
                f,
                "\n  {}: {} of {} runs done, {} cell{}",
                s.name,
                s.done,
                s.jobs,
                s.cells.len(),
                if s.cells.len() == 1 { "" } else { "s" }
            )?;
            let shown: Vec<String> =
                s.cells.iter().take(CELLS_SHOWN).map(|(cell, n)| format!("{cell} n={n}")).collect();
            write!(f, " ({}", shown.join(", "))?;
            if s.cells.len() > CELLS_SHOWN {
                write!(f, ", {} more", s.cells.len() - CELLS_SHOWN)?;
            }
            write!(f, "), {} scalar{}", s.scalars, if s.scalars == 1 { "" } else { "s" })?;
            if s.plots > 0 {
                write!(f, ", {} curve plot{}", s.plots, if s.plots == 1 { "" } else { "s" })?;
            }
        }
        if self.comparisons > 0 {
            write!(
                f,
                "\n  {} comparison{} ({COMPARE_FILE})",
                self.comparisons,
                if self.comparisons == 1 { "" } else { "s" }
            )?;
        }
        Ok(())
    }
}
