//! `mbrl eval dataset`: what a dataset holds (rollouts, lengths, returns, state ranges), as a report.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::num;
use super::plot::{histogram, line_panels, wrapped_angle_trace, Panel, Series};
use super::stats::{mean, quantile};
use super::summary::{publish, write_config};
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

pub const PROTOCOL: &str = "dataset";

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DimensionStats {
    pub name: String,
    #[serde(with = "num::real")]
    pub min: f64,
    #[serde(with = "num::real")]
    pub max: f64,
    #[serde(with = "num::real")]
    pub mean: f64,
}

/// `mbrl eval dataset`'s settings, as config.json records them.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetConfig {
    pub input: std::path::PathBuf,
}

/// What the dataset's metadata says about it, as the report quotes it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DatasetHeader {
    pub env: String,
    pub seed: u64,
    pub mbrl_version: String,
    pub command_line: String,
    #[serde(with = "num::real")]
    pub dt: f64,
    pub state_names: Vec<String>,
    /// Which state dimensions are angles (wrapped in the plot).
    pub angular: Vec<bool>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RolloutRecord {
    pub id: u32,
    pub steps: usize,
    #[serde(with = "num::real")]
    pub total_return: f64,
}

/// The states of a plotted rollout (the first dimensions only).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlottedRollout {
    pub id: u32,
    pub states: Vec<Vec<f64>>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DatasetSummary {
    pub provenance: Provenance,
    /// The dataset file, as the command named it.
    pub input: String,
    pub header: DatasetHeader,
    pub env: String,
    pub rollouts: usize,
    pub transitions: usize,
    #[serde(with = "num::real")]
    pub mean_return: f64,
    pub dimensions: Vec<DimensionStats>,
    pub per_rollout: Vec<RolloutRecord>,
    pub plotted: Vec<PlottedRollout>,
}

impl std::fmt::Display for DatasetSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{}: {} rollouts, {} transitions of {}, mean return {:.2}",
            self.input, self.rollouts, self.transitions, self.env, self.mean_return
        )
    }
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
    write_config(&DatasetConfig { input: input.to_path_buf() }, provenance, run.path())?;
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
    let meta = &data.meta;
    let angular =
        crate::envs::parse_env(&meta.env).and_then(|env| env.build()).map(|env| env.spec().angular).unwrap_or_default();
    let summary = DatasetSummary {
        provenance: provenance.clone(),
        input: input.display().to_string(),
        header: DatasetHeader {
            env: meta.env.clone(),
            seed: meta.seed,
            mbrl_version: meta.mbrl_version.clone(),
            command_line: meta.command_line.clone(),
            dt: meta.dt,
            state_names: meta.state_names.clone(),
            angular,
        },
        env: data.meta.env.clone(),
        rollouts: grouped.len(),
        transitions: data.steps.len(),
        mean_return: mean(&returns).unwrap_or(f64::NAN),
        dimensions,
        per_rollout: grouped
            .iter()
            .map(|(id, r)| RolloutRecord { id: *id, steps: r.len(), total_return: r.total_reward() })
            .collect(),
        plotted: grouped
            .iter()
            .take(PLOTTED_ROLLOUTS)
            .map(|(id, r)| PlottedRollout {
                id: *id,
                states: r.states.iter().map(|s| s.iter().take(PLOTTED_DIMENSIONS).copied().collect()).collect(),
            })
            .collect(),
    };
    publish(PROTOCOL, &summary, run.path(), render)?;
    Ok(summary)
}

/// Writes rollouts.csv, returns.png, states.png and report.md of `summary` into `dir`.
pub fn render(summary: &DatasetSummary, dir: &Path) -> Result<()> {
    let rows: Vec<Vec<String>> = summary
        .per_rollout
        .iter()
        .map(|r| vec![r.id.to_string(), r.steps.to_string(), format!("{:.6}", r.total_return)])
        .collect();
    write_csv(&dir.join("rollouts.csv"), &["rollout", "steps", "return"], &rows)?;
    let returns: Vec<f64> = summary.per_rollout.iter().map(|r| r.total_return).collect();
    histogram(&dir.join("returns.png"), "Rollout returns", "return", &returns, 20)?;
    state_panels(&dir.join("states.png"), &summary.header, &summary.plotted, summary.rollouts)?;
    let md = markdown(&summary.input, &summary.header, summary, &returns);
    write_text(&dir.join("report.md"), &md)
}

/// One panel per state dimension over time, angles wrapped to [−π, π) with the line broken at each wrap.
fn state_panels(path: &Path, meta: &DatasetHeader, plotted: &[PlottedRollout], rollouts: usize) -> Result<()> {
    let angular = &meta.angular;
    let dims = meta.state_names.len().min(PLOTTED_DIMENSIONS);
    let panels: Vec<Panel> = (0..dims)
        .map(|d| {
            let is_angle = angular.get(d).copied().unwrap_or(false);
            let series = plotted
                .iter()
                .map(|r| Series {
                    name: format!("rollout {}", r.id),
                    points: state_trace(&r.states, d, meta.dt, is_angle),
                })
                .collect();
            let label =
                if is_angle { format!("{} [rad, wrapped]", meta.state_names[d]) } else { meta.state_names[d].clone() };
            Panel { y_label: label, series, y_range: None }
        })
        .collect();
    let shown = plotted.len();
    let mut title = format!("States over time ({shown} of {rollouts} rollouts");
    if dims < meta.state_names.len() {
        title += &format!(", first {dims} of {} dimensions", meta.state_names.len());
    }
    title.push(')');
    line_panels(path, &title, "time [s]", &panels)
}

/// (t, x_d) of a rollout; an angle is wrapped, its line broken where it crosses ±π.
fn state_trace(states: &[Vec<f64>], d: usize, dt: f64, is_angle: bool) -> Vec<(f64, f64)> {
    let samples = states.iter().enumerate().filter_map(|(t, state)| state.get(d).map(|x| (t as f64 * dt, *x)));
    if is_angle {
        wrapped_angle_trace(samples)
    } else {
        samples.collect()
    }
}

fn markdown(input: &str, meta: &DatasetHeader, s: &DatasetSummary, returns: &[f64]) -> String {
    let q = |p| quantile(returns, p).map(|x| format!("{x:.2}")).unwrap_or_else(|| "–".into());
    let mut md = format!(
        "# Dataset `{}`\n\nEnvironment `{}`, seed {}, written by mbrl {} with `{}`.\n\n\
         {} rollouts, {} transitions, dt {} s.\n\n\
         Returns: mean {:.2}, 10 % {}, median {}, 90 % {}.\n\n\
         | state | min | max | mean |\n|---|---|---|---|\n",
        input,
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
