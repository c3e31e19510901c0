use std::collections::BTreeMap;
use std::path::Path;

use super::*;
use crate::run::job_record::{JobRecord, JobState};
use crate::run::Event;
use crate::sweep::plan::{expand, JobPlan};
use crate::sweep::Spec;

const SPEC: &str = r#"
[sweep]
name = "toy"
[[stage]]
name = "train"
command = "train context --data d.mcap"
[stage.grid]
seed = [0, 1, 2]
"--preset" = ["small", "medium"]
[[stage]]
name = "eval"
after = "train"
command = "eval context --model {train} --env toy:inner"
[[compare]]
stage = "eval"
metric = "prior_entropy"
a = { preset = "small" }
b = { "--preset" = "medium" }
test = "wilcoxon"
alternative = "greater"
[[compare]]
stage = "eval"
metric = "mean_mse[0]"
a = { preset = "small" }
b = { preset = "medium" }
"#;

fn accept(_: &[String]) -> std::result::Result<(), String> {
    Ok(())
}

fn plan(spec: &str, dir: &Path) -> Plan {
    expand(&Spec::parse(spec).unwrap(), dir, Path::new("/bin/mbrl"), &accept, false).unwrap()
}

fn record(job: &JobPlan, state: JobState, error: Option<&str>) {
    std::fs::create_dir_all(&job.run_dir).unwrap();
    let record = JobRecord { state, command: job.line.clone(), error: error.map(String::from) };
    std::fs::write(job.run_dir.join("job.json"), serde_json::to_vec_pretty(&record).unwrap()).unwrap();
}

fn summary(job: &JobPlan, prior_entropy: f64, mse: f64) {
    std::fs::create_dir_all(&job.output).unwrap();
    let json = serde_json::json!({
        "provenance": {"seed": job.seed},
        "settings": {"contexts": 50},
        "prior_entropy": prior_entropy,
        "mean_mse": [mse, mse * 2.0],
        "outcomes": (0..20).collect::<Vec<i32>>(),
        "env": "toy",
    });
    std::fs::write(job.output.join("summary.json"), serde_json::to_vec_pretty(&json).unwrap()).unwrap();
}

fn metrics(job: &JobPlan, steps: u64, offset: f64) {
    std::fs::create_dir_all(&job.output).unwrap();
    let mut text = String::new();
    for step in 1..=steps {
        for event in
            [Event::scalar("train/loss", step, offset + 10.0 / step as f64), Event::scalar("valid/loss", step, offset)]
        {
            text.push_str(&serde_json::to_string(&event).unwrap());
            text.push('\n');
        }
    }
    std::fs::write(job.output.join("metrics.jsonl"), text).unwrap();
}

/// Train: all six runs done (small seed 2 logged one step fewer). Eval: small seed 0 failed; medium's
/// `prior_entropy` is 10, 1, 2 over seeds 0, 1, 2, small's 1.5, 2.25 over seeds 1, 2; `mean_mse[0]` of
/// medium is 1, 2, 3.
fn fixture(dir: &Path) -> Plan {
    let plan = plan(SPEC, dir);
    for (i, job) in plan.stages[0].jobs.iter().enumerate() {
        record(job, JobState::Done, None);
        metrics(job, if job.name == "preset-small_seed-2" { 4 } else { 5 }, i as f64);
    }
    let values: BTreeMap<&str, (f64, f64)> = [
        ("preset-medium_seed-0", (10.0, 1.0)),
        ("preset-medium_seed-1", (1.0, 2.0)),
        ("preset-medium_seed-2", (2.0, 3.0)),
        ("preset-small_seed-1", (1.5, 0.5)),
        ("preset-small_seed-2", (2.25, 0.25)),
    ]
    .into();
    for job in &plan.stages[1].jobs {
        match values.get(job.name.as_str()) {
            Some(&(entropy, mse)) => {
                record(job, JobState::Done, None);
                summary(job, entropy, mse);
            }
            None => record(job, JobState::Failed, Some("error: the model diverged")),
        }
    }
    plan
}

fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    reader.records().map(|r| r.unwrap().iter().map(String::from).collect()).collect()
}

#[test]
fn cells_get_t_intervals_and_a_failed_run_is_named_not_counted() {
    let dir = tempfile::tempdir().unwrap();
    let plan = fixture(dir.path());
    let out = dir.path().join("report");
    let summary = write_report(&plan, &out).unwrap();
    let rows = csv_rows(&out.join(CELLS_FILE));
    let row = rows.iter().find(|r| r[0] == "eval" && r[1] == "preset=medium" && r[2] == "mean_mse[0]").unwrap();
    assert_eq!(&row[3..6], ["3", "2", "1"]);
    // t(0.975, 2) = 4.302653: half-width 4.302653 / √3 = 2.484138.
    let low: f64 = row[6].parse().unwrap();
    assert!((low - (2.0 - 2.484_138)).abs() < 1e-5, "{row:?}");
    let small = rows.iter().find(|r| r[0] == "eval" && r[1] == "preset=small" && r[2] == "prior_entropy").unwrap();
    assert_eq!(small[3], "2", "the failed run is not counted");
    assert!(rows.iter().all(|r| !r[2].starts_with("outcomes") && !r[2].starts_with("provenance")), "{rows:?}");
    assert!(rows.iter().any(|r| r[0] == "train" && r[2] == "final.valid/loss"));
    let md = std::fs::read_to_string(out.join(REPORT_FILE)).unwrap();
    assert!(md.contains("`preset-small_seed-0`: failed: error: the model diverged"), "{md}");
    assert!(md.contains("5 of 6 runs done"), "{md}");
    assert!(md.contains("95 % t interval"), "{md}");
    assert!(md.contains("![train/loss](curves-train-train_loss.png)"), "{md}");
    assert!(out.join("curves-train-valid_loss.png").is_file());
    let text = summary.to_string();
    assert!(text.contains("eval: 5 of 6 runs done, 2 cells (preset=small n=2, preset=medium n=3)"), "{text}");
}

#[test]
fn wilcoxon_pairs_runs_by_seed() {
    let dir = tempfile::tempdir().unwrap();
    let plan = fixture(dir.path());
    let out = dir.path().join("report");
    write_report(&plan, &out).unwrap();
    let rows = csv_rows(&out.join(COMPARE_FILE));
    let wilcoxon = &rows[0];
    assert_eq!(&wilcoxon[5..10], ["wilcoxon", "greater", "2", "3", "2"], "{wilcoxon:?}");
    // Seeds 1 and 2 pair as 1.5 − 1 and 2.25 − 2, both positive: W+ = 3 (by position it would be 1).
    assert_eq!(wilcoxon[10], "3", "{wilcoxon:?}");
    assert_eq!(wilcoxon[11], "0.25", "exact one-sided p of 2 positive pairs");
    assert_eq!(&rows[1][5..7], ["mann-whitney", "two-sided"]);
}

#[test]
fn one_run_has_no_interval_and_no_nan_is_printed() {
    let dir = tempfile::tempdir().unwrap();
    let plan = plan(&SPEC.replace("seed = [0, 1, 2]", "seed = [4]"), dir.path());
    for job in &plan.stages[1].jobs {
        record(job, JobState::Done, None);
        summary(job, 3.0, 0.5);
    }
    let out = dir.path().join("report");
    write_report(&plan, &out).unwrap();
    let row = csv_rows(&out.join(CELLS_FILE)).into_iter().find(|r| r[2] == "prior_entropy").unwrap();
    assert_eq!(&row[3..], ["1", "3", "", "", ""]);
    let md = std::fs::read_to_string(out.join(REPORT_FILE)).unwrap();
    assert!(!md.contains("NaN") && !md.contains("inf"), "{md}");
    assert!(md.contains("| preset=small | 1 | 0.5000 | 1 | 3 |"), "{md}");
    assert!(md.contains("### Missing runs (2 of 2)") && md.contains("not started"), "{md}");
}

#[test]
fn the_same_runs_give_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let plan = fixture(dir.path());
    let (first, second) = (dir.path().join("one"), dir.path().join("two"));
    let a = write_report(&plan, &first).unwrap();
    write_report(&plan, &second).unwrap();
    let mut names: Vec<_> = std::fs::read_dir(&first).unwrap().map(|e| e.unwrap().file_name()).collect();
    names.sort();
    assert_eq!(names.len(), a.files.len(), "{names:?} vs {:?}", a.files);
    assert!(a.files.iter().filter(|f| f.ends_with(".png")).count() == 2);
    for name in names {
        assert_eq!(std::fs::read(first.join(&name)).unwrap(), std::fs::read(second.join(&name)).unwrap(), "{name:?}");
    }
}

#[test]
fn a_comparison_naming_no_scalar_or_no_cell_is_refused_with_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut plan = fixture(dir.path());
    plan.spec.compares[0].metric = "prior_entropi".into();
    let out = dir.path().join("report");
    let err = write_report(&plan, &out).unwrap_err().to_string();
    assert!(err.contains("compare[0].metric") && err.contains("did you mean 'prior_entropy'"), "{err}");
    assert!(!out.exists(), "nothing is written before the spec is checked");
    plan.spec.compares[0].metric = "prior_entropy".into();
    plan.spec.compares[1].a = [("preset".to_string(), crate::sweep::spec::GridValue::Text("large".into()))].into();
    let err = write_report(&plan, &out).unwrap_err().to_string();
    assert!(err.contains("compare[1].a") && err.contains("preset=small"), "{err}");
    plan.spec.compares[1].a = BTreeMap::new();
    let err = write_report(&plan, &out).unwrap_err().to_string();
    assert!(err.contains("compare[1].a") && err.contains("matches 2 cells"), "{err}");
}

#[test]
fn long_curves_are_averaged_over_bins_of_steps() {
    let dir = tempfile::tempdir().unwrap();
    let plan = plan(SPEC, dir.path());
    for job in &plan.stages[0].jobs {
        record(job, JobState::Done, None);
        metrics(job, 1001, 0.0);
    }
    let out = dir.path().join("report");
    write_report(&plan, &out).unwrap();
    let md = std::fs::read_to_string(out.join(REPORT_FILE)).unwrap();
    assert!(md.contains("Each point averages 3 consecutive steps"), "{md}");
    let rows = csv_rows(&out.join(CELLS_FILE));
    let last = rows.iter().find(|r| r[1] == "preset=small" && r[2] == "final.train/loss").unwrap();
    assert_eq!(&last[3..6], ["3", &(10.0f64 / 1001.0).to_string(), "0"]);
}
