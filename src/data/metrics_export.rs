//! A run's recorded metrics (every `scalar` event of its `metrics.jsonl`) as one long CSV table,
//! `step,metric,value`, one row per point in the order the run recorded them.
//!
//! Long rather than one column per metric: metrics come at different steps (validation every few hundred
//! training steps), and some count their steps afresh per episode or planner call (CEM's iteration 0..9 at every
//! MPC step), so a table keyed by step would be mostly empty cells or would have to drop repeats. In long form
//! every point is kept exactly once; `pandas.read_csv(f).pivot_table(index="step", columns="metric",
//! values="value")` gives the wide table where steps are unique.

use std::collections::BTreeMap;
use std::path::Path;

use super::export::format_f64;
use crate::error::{Error, Result};
use crate::run::follow::MetricsFollower;
use crate::run::Event;
use crate::util::atomic::write_atomic;

/// What was written: the count of points of each metric.
#[derive(Debug, PartialEq)]
pub struct MetricsExported {
    pub points: BTreeMap<String, usize>,
}

impl MetricsExported {
    pub fn rows(&self) -> usize {
        self.points.values().sum()
    }
}

/// Reads every complete line of `metrics` (a run still writing it is read as far as it got) and writes the
/// scalars to `out`. A run without a single scalar is refused: an empty table would look like a success.
pub fn export_metrics(metrics: &Path, out: &Path) -> Result<MetricsExported> {
    let events = MetricsFollower::open(metrics)?.poll()?;
    let scalars: Vec<(&str, u64, f64)> = events
        .iter()
        .filter_map(|event| match event {
            Event::Scalar { name, step, value } => Some((name.as_str(), *step, *value)),
            _ => None,
        })
        .collect();
    if scalars.is_empty() {
        return Err(Error::bad_file(metrics, "holds no metric values yet; expected scalar events to export"));
    }
    let mut points = BTreeMap::new();
    for (name, _, _) in &scalars {
        *points.entry(name.to_string()).or_insert(0) += 1;
    }
    write_atomic(out, |sink| {
        let io = |e: csv::Error| Error::io(out, std::io::Error::other(e));
        let mut writer = csv::Writer::from_writer(sink);
        writer.write_record(["step", "metric", "value"]).map_err(io)?;
        for (name, step, value) in &scalars {
            writer.write_record([step.to_string().as_str(), name, &format_f64(*value)]).map_err(io)?;
        }
        writer.flush().map_err(|e| Error::io(out, e))
    })?;
    Ok(MetricsExported { points })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_events(path: &Path, events: &[Event]) {
        let lines: Vec<String> = events.iter().map(|e| serde_json::to_string(e).unwrap() + "\n").collect();
        std::fs::write(path, lines.concat()).unwrap();
    }

    #[test]
    fn every_scalar_becomes_one_row_in_recorded_order() {
        let dir = tempfile::tempdir().unwrap();
        let metrics = dir.path().join("metrics.jsonl");
        write_events(
            &metrics,
            &[
                Event::Layout { title: "t".into(), panels: vec![] },
                Event::scalar("train/loss", 1, -0.25),
                Event::progress("train", 1, 2),
                Event::scalar("cem/best_cost", 0, 3.0),
                Event::scalar("cem/best_cost", 0, f64::NAN),
                Event::scalar("valid/loss", 2, 1.0e-7),
                Event::message("done"),
            ],
        );
        let out = dir.path().join("m.csv");
        let exported = export_metrics(&metrics, &out).unwrap();
        assert_eq!(exported.rows(), 4);
        assert_eq!(exported.points.get("cem/best_cost"), Some(&2));
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(
            text,
            "step,metric,value\n1,train/loss,-0.25\n0,cem/best_cost,3\n0,cem/best_cost,\n2,valid/loss,1e-7\n"
        );
    }

    #[test]
    fn a_run_without_metrics_is_refused_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let metrics = dir.path().join("metrics.jsonl");
        write_events(&metrics, &[Event::progress("train", 0, 2)]);
        let out = dir.path().join("m.csv");
        let err = export_metrics(&metrics, &out).unwrap_err().to_string();
        assert!(err.contains("metrics.jsonl") && err.contains("no metric values"), "{err}");
        assert!(!out.exists());
    }
}
