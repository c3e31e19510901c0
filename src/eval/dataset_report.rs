//! `mbrl eval dataset`: what a dataset holds (rollouts, lengths, returns, state ranges), as a report.

use std::path::Path;

use serde::Serialize;

use super::plot::{histogram, line_panels, Panel, Series};
use super::stats::{mean, quantile};
use crate::data::{read_dataset, Rollout};
use crate::error::{Error, Result};
use crate::run::dir::{Provenance, RunDir};
use crate::util::atomic::write_text;
use crate::util::table::write_csv;

/// Rollouts drawn in the state plot; more would be unreadable.
/// Rollouts drawn in states.png: one palette colour each, none reused.
const PLOTTED_ROLLOUTS: usize = 10;
/// State dimensions drawn (an embodied board game has dozens of board bits; the first are the manipulator's).
const PLOTTED_DIMENSIONS: usize = 6;

#[derive(Clone, Debug, Serialize)]
pub struct DimensionStats {
    pub name: String,
    pub min: f64,
    pub max: f64,
    pub mean: f64,
}

pub struct DatasetSummary {
    pub env: String,
    pub rollouts: usize,
    pub transitions: usize,
    pub mean_return: f64,
    pub dimensions: Vec<DimensionStats>,
}

pub fn report(input: &Path, provenance: &Provenance, out_dir: &Path) -> Result<DatasetSummary> {
    let data = read_dataset(input)?;
    let grouped = Rollout::group(&data.steps).map_err(|i| {
        Error::bad_file(
            input,
            format!("timestep {i} does not continue its rollout (expected t and state to follow on)"),
        )
    })?;
    let run = RunDir::create(out_dir)?;
    run.write_config(&serde_json::json!({
        "job": "eval dataset",
        "input": input.display().to_string(),
        "mbrl_version": provenance.mbrl_version,
        "command_line": provenance.command_line,
    }))?;
    let returns: Vec<f64> = grouped.iter().map(|(_, r)| r.total_reward()).collect();
    let dimensions: Vec<DimensionStats> = data
        .meta
        .state_names
        .iter()
        .enumerate()
        .map(|(d, name)| {
            let values: Vec<f64> = data.steps.iter().map(|s| s.state[d]).collect();
            DimensionStats {
                name: name.clone(),
                min: values.iter().copied().fold(f64::INFINITY, f64::min),
                max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                mean: mean(&values).unwrap_or(f64::NAN),
            }
        })
        .collect();
    let rows: Vec<Vec<String>> = grouped
        .iter()
        .map(|(id, r)| vec![id.to_string(), r.len().to_string(), format!("{:.6}", r.total_reward())])
        .collect();
    write_csv(&run.file("rollouts.csv"), &["rollout", "steps", "return"], &rows)?;
    histogram(&run.file("returns.png"), "Rollout returns", "return", &returns, 20)?;
    state_panels(&run.file("states.png"), &data.meta, &grouped)?;
    let summary = DatasetSummary {
        env: data.meta.env.clone(),
        rollouts: grouped.len(),
        transitions: data.steps.len(),
        mean_return: mean(&returns).unwrap_or(f64::NAN),
        dimensions,
    };
    let md = markdown(input, &data.meta, &summary, &returns);
    let path = run.file("report.md");
    write_text(&path, &md)?;
    Ok(summary)
}

/// One panel per state dimension over time, angles wrapped to [−π, π) with the line broken at each wrap.
fn state_panels(path: &Path, meta: &crate::data::DatasetMeta, grouped: &[(u32, Rollout)]) -> Result<()> {
    let angular =
        crate::envs::parse_env(&meta.env).and_then(|env| env.build()).map(|env| env.spec().angular).unwrap_or_default();
    let dims = meta.state_names.len().min(PLOTTED_DIMENSIONS);
    let panels: Vec<Panel> = (0..dims)
        .map(|d| {
            let is_angle = angular.get(d).copied().unwrap_or(false);
            let series = grouped
                .iter()
                .take(PLOTTED_ROLLOUTS)
                .map(|(id, r)| Series { name: format!("rollout {id}"), points: state_trace(r, d, meta.dt, is_angle) })
                .collect();
            let label =
                if is_angle { format!("{} [rad, wrapped]", meta.state_names[d]) } else { meta.state_names[d].clone() };
            Panel { y_label: label, series, y_range: None }
        })
        .collect();
    let shown = grouped.len().min(PLOTTED_ROLLOUTS);
    let mut title = format!("States over time ({shown} of {} rollouts", grouped.len());
    if dims < meta.state_names.len() {
        title += &format!(", first {dims} of {} dimensions", meta.state_names.len());
    }
    title.push(')');
    line_panels(path, &title, "time [s]", &panels)
}

/// (t, x_d) of a rollout; an angle is wrapped and a NaN breaks the line where it jumps across ±π.
fn state_trace(rollout: &Rollout, d: usize, dt: f64, is_angle: bool) -> Vec<(f64, f64)> {
    let wrap = |x: f64| (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    let mut points = Vec::with_capacity(rollout.states.len());
    let mut previous: Option<f64> = None;
    for (t, state) in rollout.states.iter().enumerate() {
        let Some(&raw) = state.get(d) else { continue };
        let value = if is_angle { wrap(raw) } else { raw };
        if is_angle && previous.is_some_and(|p| (value - p).abs() > std::f64::consts::PI) {
            points.push((t as f64 * dt, f64::NAN));
        }
        points.push((t as f64 * dt, value));
        previous = Some(value);
    }
    points
}

fn markdown(input: &Path, meta: &crate::data::DatasetMeta, s: &DatasetSummary, returns: &[f64]) -> String {
    let q = |p| quantile(returns, p).map(|x| format!("{x:.2}")).unwrap_or_else(|| "–".into());
    let mut md = format!(
        "# Dataset `{}`\n\nEnvironment `{}`, seed {}, written by mbrl {} with `{}`.\n\n\
         {} rollouts, {} transitions, dt {} s.\n\n\
         Returns: mean {:.2}, 10 % {}, median {}, 90 % {}.\n\n\
         | state | min | max | mean |\n|---|---|---|---|\n",
        input.display(),
        meta.env,
        meta.seed,
        meta.mbrl_version,
        meta.command_line,
        s.rollouts,
        s.transitions,
        meta.dt,
        s.mean_return,
        q(0.1),
        q(0.5),
        q(0.9)
    );
    for d in &s.dimensions {
        md.push_str(&format!("| {} | {:.4} | {:.4} | {:.4} |\n", d.name, d.min, d.max, d.mean));
    }
    md.push_str("\n![returns](returns.png)\n\n![states](states.png)\n\nPer-rollout values: `rollouts.csv`.\n");
    md
}
