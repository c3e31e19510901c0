//! `mbrl sweep` on a real Slurm: the tests run when MBRL_SLURM_CONF names the slurm.conf of a running cluster
//! (`tests/slurm/cluster.sh start DIR` starts a one-node cluster; `.ci/run` does that), and say so and pass
//! otherwise. They need `--test-threads=1`: they share the node's two CPUs and time a requeue.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use super::sweep::{plan, toy_inputs, two_stage_spec, wait_for_step};
use crate::common::*;

fn slurm_conf() -> Option<String> {
    let conf = std::env::var("MBRL_SLURM_CONF").ok();
    if conf.is_none() {
        eprintln!("note: MBRL_SLURM_CONF is not set; the Slurm sweep test is skipped (see tests/slurm/cluster.sh)");
    }
    conf
}

fn script(path: &Path, args: &[&str], conf: &str) -> Output {
    Command::new("bash").arg(path).args(args).env("SLURM_CONF", conf).env("NO_COLOR", "1").output().unwrap()
}

fn text_of(out: &Output) -> String {
    stdout_of(out) + &stderr_of(out)
}

fn run_lines_locally(dir: &Path) -> Output {
    Command::new("bash").arg(dir.join("run-local.sh")).arg("2").output().unwrap()
}

/// The weights, metrics and tables under `dir`'s runs, by relative path, with the sweep's own directory
/// written as SWEEP (a report's title names the model by its path).
fn run_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let root = dir.join("runs");
    let own = dir.canonicalize().unwrap().display().to_string();
    let mut files: Vec<(String, Vec<u8>)> = files_in(&root)
        .into_iter()
        .filter(|p| p.ends_with(".safetensors") || p.ends_with("metrics.jsonl") || p.ends_with(".csv"))
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            let bytes = match String::from_utf8(bytes) {
                Ok(text) => text.replace(&own, "SWEEP").into_bytes(),
                Err(binary) => binary.into_bytes(),
            };
            (p.strip_prefix(&root.display().to_string()).unwrap().to_string(), bytes)
        })
        .collect();
    files.sort();
    files
}

#[test]
fn a_two_stage_sweep_runs_as_dependent_arrays_and_matches_a_local_run() {
    let Some(conf) = slurm_conf() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (data, config) = toy_inputs(d);
    let spec = two_stage_spec(&data, &config, 30, "2").replace("seed = [0, 1]", "seed = [0, 1, 2]");
    for name in ["slurm", "local"] {
        let out = plan(d, &spec, name);
        assert!(out.status.success(), "{}", stderr_of(&out));
    }
    let submitted = script(&d.join("slurm/submit.sh"), &["--wait"], &conf);
    let text = text_of(&submitted);
    assert!(submitted.status.success(), "{text}");
    assert!(text.contains("12/12 jobs done"), "{text}");
    let local = run_lines_locally(&d.join("local"));
    assert!(local.status.success(), "{}", text_of(&local));
    let (slurm_files, local_files) = (run_files(&d.join("slurm")), run_files(&d.join("local")));
    assert_eq!(slurm_files.len(), local_files.len());
    assert!(slurm_files.len() >= 12, "{:?}", slurm_files.iter().map(|f| &f.0).collect::<Vec<_>>());
    for (a, b) in slurm_files.iter().zip(&local_files) {
        assert!(a == b, "{} differs between the Slurm and the local run", a.0);
    }
    for name in ["slurm", "local"] {
        let report = mbrl(d).args(["sweep", "report", name]).output().unwrap();
        assert!(report.status.success(), "{}", stderr_of(&report));
    }
    let reports = |name: &str| {
        let dir = d.join(name).join("report");
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap()))
            .collect();
        files.sort();
        files
    };
    let (slurm_report, local_report) = (reports("slurm"), reports("local"));
    assert!(slurm_report.iter().any(|(n, _)| n == "report.md") && slurm_report.len() > 2);
    assert!(slurm_report == local_report, "the Slurm and the local sweep's reports differ");
    let markdown = String::from_utf8(slurm_report.iter().find(|(n, _)| n == "report.md").unwrap().1.clone()).unwrap();
    assert!(markdown.contains("| hidden_units=8 | 3 |"), "three seeds per cell: {markdown}");
}

#[test]
fn a_failing_task_fails_the_wait_and_names_its_error() {
    let Some(conf) = slurm_conf() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (data, config) = toy_inputs(d);
    let spec = two_stage_spec(&data, &config, 10, "0").replace("seed = [0, 1]", "seed = [0]");
    assert!(plan(d, &spec, "s").status.success());
    let submitted = script(&d.join("s/submit.sh"), &["--wait"], &conf);
    let text = text_of(&submitted);
    assert_eq!(submitted.status.code(), Some(1), "{text}");
    assert!(text.contains("failed: error:") && text.contains("--contexts"), "{text}");
}

#[test]
fn a_task_warned_of_its_time_limit_requeues_and_resumes_to_the_same_bytes() {
    let Some(conf) = slurm_conf() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (data, config) = toy_inputs(d);
    let spec = format!(
        "[[stage]]\nname = \"train\"\ncommand = \"train context --data {} --config {} --steps 600\"\n[slurm]\nwarning_seconds = 60\n",
        data.display(),
        config.display()
    );
    for name in ["slurm", "local"] {
        assert!(plan(d, &spec, name).status.success());
    }
    let submitted = script(&d.join("slurm/submit.sh"), &[], &conf);
    let text = text_of(&submitted);
    assert!(submitted.status.success(), "{text}");
    let job = text
        .split("job ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .expect("submit.sh names the job")
        .to_string();
    let model = d.join("slurm/runs/train/run/model");
    assert!(wait_for_step(&model, 20, Duration::from_secs(120)), "the task never reached step 20");
    // What Slurm sends `warning_seconds` before the time limit (--signal=B:USR1@…), sent now.
    let signalled = Command::new("scancel")
        .args(["--batch", "--signal=USR1", &format!("{job}_0")])
        .env("SLURM_CONF", &conf)
        .output()
        .unwrap();
    assert!(signalled.status.success(), "{}", text_of(&signalled));
    let start = Instant::now();
    loop {
        let status = mbrl(d).args(["sweep", "status", "slurm"]).output().unwrap();
        if status.status.success() {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(240), "not done after requeue: {}", text_of(&status));
        std::thread::sleep(Duration::from_millis(500));
    }
    let log = std::fs::read_to_string(d.join("slurm/logs/train-0.log")).unwrap_or_default();
    assert!(log.contains("interrupted"), "the task was stopped, then requeued: {log}");
    let local = run_lines_locally(&d.join("local"));
    assert!(local.status.success(), "{}", text_of(&local));
    assert_eq!(run_files(&d.join("slurm")), run_files(&d.join("local")), "resumed run differs from uninterrupted");
}
