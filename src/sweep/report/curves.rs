//! Learning curves over seeds: per cell, the mean of its runs at each step they all recorded, shaded
//! by the 95 % t interval, one PNG per training metric of a stage.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use super::collect::StageRuns;
use super::interval::Interval;
use crate::error::Result;
use crate::eval::plot::{band_plot, Band};

/// Plots per stage; a training logs a dozen metrics at most, and a report of more is no longer read.
pub const MAX_PLOTS: usize = 12;
/// Points per curve: a training logs every step (tens of thousands), which draws as noise at 900 pixels.
/// Longer curves average each run over bins of consecutive steps first.
pub const MAX_POINTS: usize = 400;

pub struct Curves {
    /// Each PNG written, in metric order.
    pub plots: Vec<Plot>,
    /// (metric, why) of each metric with no plot.
    pub skipped: Vec<(String, String)>,
}

pub struct Plot {
    pub metric: String,
    pub file: String,
    /// Consecutive steps averaged into one point (1: every step drawn), fewest and most over the cells
    /// (a cell with shorter runs needs smaller bins).
    pub bins: (usize, usize),
}

/// Writes the stage's curve PNGs into `out`.
pub fn write_curves(stage: &StageRuns, out: &Path) -> Result<Curves> {
    let metrics: BTreeSet<&str> = stage.runs.iter().flat_map(|r| r.curves.keys().map(String::as_str)).collect();
    let mut curves = Curves { plots: Vec::new(), skipped: Vec::new() };
    let mut used_names = BTreeSet::new();
    for metric in metrics {
        let binned: Vec<(Band, usize)> =
            stage.cells.iter().filter_map(|(label, _)| band(stage, label, metric)).collect();
        let bins = (binned.iter().map(|b| b.1).min().unwrap_or(1), binned.iter().map(|b| b.1).max().unwrap_or(1));
        let bands: Vec<Band> = binned.into_iter().map(|b| b.0).collect();
        if bands.is_empty() {
            curves.skipped.push((metric.to_string(), "no cell has 2 steps that all its runs recorded".into()));
            continue;
        }
        if curves.plots.len() == MAX_PLOTS {
            curves.skipped.push((metric.to_string(), format!("over the limit of {MAX_PLOTS} plots per stage")));
            continue;
        }
        let mut file = format!("curves-{}-{}.png", stage.stage.name, file_part(metric));
        let mut k = 2;
        while !used_names.insert(file.clone()) {
            file = format!("curves-{}-{}-{k}.png", stage.stage.name, file_part(metric));
            k += 1;
        }
        let title = format!("{}: {metric}, mean over seeds, 95 % t interval", stage.stage.name);
        band_plot(&out.join(&file), &title, "step", metric, &bands)?;
        curves.plots.push(Plot { metric: metric.to_string(), file, bins });
    }
    Ok(curves)
}

/// The cell's mean curve over the steps every run of it that logged `metric` recorded with a finite value,
/// and how many steps each point averages.
fn band(stage: &StageRuns, cell: &str, metric: &str) -> Option<(Band, usize)> {
    let series: Vec<&BTreeMap<u64, f64>> =
        stage.runs_of(cell).into_iter().filter_map(|r| r.curves.get(metric)).collect();
    let (first, rest) = series.split_first()?;
    let steps: Vec<u64> = first
        .iter()
        .filter(|(step, value)| value.is_finite() && rest.iter().all(|s| s.get(step).is_some_and(|v| v.is_finite())))
        .map(|(&step, _)| step)
        .collect();
    let bin = steps.len().div_ceil(MAX_POINTS).max(1);
    let mut points = Vec::with_capacity(steps.len() / bin + 1);
    let mut values = Vec::with_capacity(series.len());
    for chunk in steps.chunks(bin) {
        values.clear();
        values.extend(series.iter().map(|s| chunk.iter().map(|step| s[step]).sum::<f64>() / chunk.len() as f64));
        let interval = Interval::of(&values);
        let (Some(mean), half) = (interval.mean, interval.half_width.unwrap_or(0.0)) else { continue };
        let x = chunk.iter().map(|&s| s as f64).sum::<f64>() / chunk.len() as f64;
        points.push((x, mean - half, mean, mean + half));
    }
    (points.len() >= 2).then(|| (Band { name: format!("{cell} (n={})", series.len()), points }, bin))
}

/// A metric name as part of a file name: `train/loss` → `train_loss`.
fn file_part(metric: &str) -> String {
    metric.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '.' { c } else { '_' }).collect()
}
