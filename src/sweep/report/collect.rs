//! What a stage's finished runs left behind: the scalars of an evaluation's `summary.json`, or the final
//! values and learning curves of a training's `metrics.jsonl`. Runs that did not finish are named, not
//! guessed at.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;

use crate::error::{Error, Result};
use crate::run::follow::MetricsFollower;
use crate::run::job_record::{JobRecord, JobState};
use crate::run::Event;
use crate::sweep::plan::{JobPlan, StagePlan};
use crate::util::domain::Domain;

/// Arrays longer than this are per-episode or per-step data, not results to average over seeds.
const MAX_SCALAR_ARRAY: usize = 8;
/// Summaries are kilobytes to a few megabytes (per-context outcomes); far beyond is not a summary.
const MAX_SUMMARY_BYTES: u64 = 1 << 30;
/// Top-level sections of a summary that record what was asked, not what came out.
const INPUT_SECTIONS: &[&str] = &["provenance", "settings"];

/// One finished run.
pub struct Run<'a> {
    pub job: &'a JobPlan,
    /// In the summary's own order (serde_json sorts keys; arrays keep their index order).
    pub scalars: Vec<(String, f64)>,
    /// Metric → step → value; a step recorded twice (a resumed training) keeps its last value.
    pub curves: BTreeMap<String, BTreeMap<u64, f64>>,
}

/// A planned run the report has no results of, and why.
pub struct Missing {
    pub name: String,
    pub why: String,
}

pub struct StageRuns<'a> {
    pub stage: &'a StagePlan,
    pub runs: Vec<Run<'a>>,
    pub missing: Vec<Missing>,
    /// Every scalar some run has, in order of first appearance.
    pub scalar_names: Vec<String>,
    /// Cell labels in plan order, with the stage's jobs of each.
    pub cells: Vec<(String, Vec<&'a JobPlan>)>,
}

impl<'a> StageRuns<'a> {
    pub fn read(stage: &'a StagePlan) -> StageRuns<'a> {
        let mut runs = Vec::new();
        let mut missing = Vec::new();
        for job in &stage.jobs {
            let record = JobRecord::read_checked(&job.run_dir);
            let why = match &record {
                Err(why) => format!("unreadable: {why}"),
                Ok(None) => "not started (no job.json)".to_string(),
                Ok(Some(r)) => match r.state {
                    JobState::Done => match read_output(&job.output) {
                        Ok((scalars, curves)) => {
                            runs.push(Run { job, scalars, curves });
                            continue;
                        }
                        Err(e) => format!("done, but its output is unreadable: {e}"),
                    },
                    JobState::Running => "running (or killed while running)".to_string(),
                    JobState::Stopped => "stopped; rerun the job list to continue it".to_string(),
                    JobState::Failed => match &r.error {
                        Some(line) => format!("failed: {}", line.trim()),
                        None => "failed".to_string(),
                    },
                },
            };
            missing.push(Missing { name: job.name.clone(), why });
        }
        let mut scalar_names: Vec<String> = Vec::new();
        let mut seen = std::collections::BTreeSet::new();
        for run in &runs {
            for (name, _) in &run.scalars {
                if seen.insert(name.as_str()) {
                    scalar_names.push(name.clone());
                }
            }
        }
        let mut cells: Vec<(String, Vec<&JobPlan>)> = Vec::new();
        for job in &stage.jobs {
            let label = job.cell_label();
            match cells.iter_mut().find(|(l, _)| *l == label) {
                Some((_, jobs)) => jobs.push(job),
                None => cells.push((label, vec![job])),
            }
        }
        StageRuns { stage, runs, missing, scalar_names, cells }
    }

    /// The finished runs of one cell, in plan order.
    pub fn runs_of(&self, cell: &str) -> Vec<&Run<'a>> {
        self.runs.iter().filter(|r| r.job.cell_label() == cell).collect()
    }
}

impl Run<'_> {
    pub fn scalar(&self, name: &str) -> Option<f64> {
        self.scalars.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }
}

type Read = (Vec<(String, f64)>, BTreeMap<String, BTreeMap<u64, f64>>);

/// No summary value or training metric this tool writes comes near this; a run that claims one beyond it is
/// reported as unreadable rather than averaged (its square would swamp, or overflow, every interval).
const METRIC: Domain = Domain::closed(-1e12, 1e12);

/// A report directory gives its summary's scalars, a training directory its metrics; anything else (a
/// dataset file) gives nothing and still counts as done.
fn read_output(output: &Path) -> Result<Read> {
    let summary = output.join("summary.json");
    if summary.is_file() {
        let bytes = crate::util::bounded_read::read_bounded(&summary, MAX_SUMMARY_BYTES)?;
        let value: Value =
            serde_json::from_slice(&bytes).map_err(|e| Error::bad_file(&summary, format!("is not JSON: {e}")))?;
        let mut scalars = Vec::new();
        leaves(&value, &mut String::new(), &mut scalars);
        for (name, x) in &scalars {
            METRIC.check(name, *x).map_err(|e| Error::bad_file(&summary, e.to_string()))?;
        }
        return Ok((scalars, BTreeMap::new()));
    }
    let metrics = output.join("metrics.jsonl");
    if metrics.is_file() {
        let mut last: Vec<(String, f64)> = Vec::new();
        let mut curves: BTreeMap<String, BTreeMap<u64, f64>> = BTreeMap::new();
        for event in MetricsFollower::open(&metrics)?.poll()? {
            if let Event::Scalar { name, step, value } = event {
                if !METRIC.contains(value) {
                    let e = METRIC.check(&format!("{name} at step {step}"), value).unwrap_err();
                    return Err(Error::bad_file(&metrics, e.to_string()));
                }
                curves.entry(name.clone()).or_default().insert(step, value);
                match last.iter_mut().find(|(n, _)| *n == name) {
                    Some(entry) => entry.1 = value,
                    None => last.push((name, value)),
                }
            }
        }
        last.sort_by(|a, b| a.0.cmp(&b.0));
        let scalars = last.into_iter().map(|(name, value)| (format!("final.{name}"), value)).collect();
        return Ok((scalars, curves));
    }
    Ok((Vec::new(), BTreeMap::new()))
}

/// Every numeric leaf under `value`, named by its path (`mean_mse[0]`, `tests[1].p_value`). A true/false
/// leaf counts as 1/0, so its mean over seeds is a rate (`episodes[0].success`: the swing-up success rate).
fn leaves(value: &Value, path: &mut String, out: &mut Vec<(String, f64)>) {
    match value {
        Value::Bool(flag) => out.push((path.clone(), if *flag { 1.0 } else { 0.0 })),
        Value::Number(number) => {
            if let Some(x) = number.as_f64() {
                out.push((path.clone(), x));
            }
        }
        Value::Object(map) => {
            for (key, child) in map {
                if path.is_empty() && INPUT_SECTIONS.contains(&key.as_str()) {
                    continue;
                }
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(key);
                leaves(child, path, out);
                path.truncate(len);
            }
        }
        Value::Array(items) if items.len() <= MAX_SCALAR_ARRAY => {
            for (i, child) in items.iter().enumerate() {
                let len = path.len();
                path.push_str(&format!("[{i}]"));
                leaves(child, path, out);
                path.truncate(len);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numeric_and_boolean_leaves_are_named_by_path_and_inputs_and_long_arrays_skipped() {
        let value: Value = serde_json::from_str(
            r#"{"provenance": {"seed": 3}, "settings": {"contexts": 50}, "prior_entropy": 22.5,
                "mean_mse": [0.25, 0.5], "outcomes": [1,2,3,4,5,6,7,8,9], "angular": false, "env": "x",
                "tests": [{"n": 50, "p_value": 0.03, "label": "a"}], "swingup": null}"#,
        )
        .unwrap();
        let mut out = Vec::new();
        leaves(&value, &mut String::new(), &mut out);
        let names: Vec<&str> = out.iter().map(|(n, _)| n.as_str()).collect();
        // true/false count as 1/0 (a success flag's mean is a success rate).
        assert_eq!(names, ["angular", "mean_mse[0]", "mean_mse[1]", "prior_entropy", "tests[0].n", "tests[0].p_value"]);
        assert_eq!((out[0].1, out[2].1), (0.0, 0.5));
    }

    /// A summary claiming an absurd value makes its run unreadable (named in the report), not a mean of 1e300.
    #[test]
    fn a_summary_value_beyond_any_measurement_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("summary.json"), r#"{"prior_entropy": 1.5, "mean_mse": [0.25, 1e300]}"#)
            .unwrap();
        let err = read_output(dir.path()).unwrap_err().to_string();
        assert!(err.contains("summary.json: mean_mse[1] = 1e300: expected a finite number in [-1e12, 1e12]"), "{err}");
        std::fs::write(dir.path().join("summary.json"), r#"{"prior_entropy": 1.5, "mean_mse": [0.25, 1e11]}"#).unwrap();
        assert_eq!(read_output(dir.path()).unwrap().0.len(), 3);
    }
}
