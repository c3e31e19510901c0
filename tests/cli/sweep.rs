//! `mbrl sweep` run locally: a spec planned into job lists, run by its run-local.sh, rerun (finished jobs
//! skipped), a training stopped by SIGTERM and resumed to the uninterrupted bytes, a failing job reported with
//! its error, and the spec errors a user can make. The Slurm side is `sweep_slurm`.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::common::*;

/// Networks small enough to train in a second; checkpoints every 10 steps.
pub(crate) const TINY: &str = "embedding = 16\nhidden_units = 16\ntransition_features = 8\nchunk_states = 10\n\
                    context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n";

/// Toy data and the tiny config, returning their absolute paths.
pub(crate) fn toy_inputs(dir: &Path) -> (PathBuf, PathBuf) {
    std::fs::write(dir.join("tiny.toml"), TINY).unwrap();
    let out = mbrl(dir)
        .args(["collect", "--env", "toy:inner", "--instances", "12", "--steps", "20", "-q", "--no-tui"])
        .args(["--out", "toy.mcap"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    (dir.join("toy.mcap").canonicalize().unwrap(), dir.join("tiny.toml").canonicalize().unwrap())
}

/// Two seeds × two sizes of a tiny context training, each evaluated on a few contexts.
pub(crate) fn two_stage_spec(data: &Path, config: &Path, steps: u32, contexts: &str) -> String {
    format!(
        r#"[sweep]
name = "toy"
[[stage]]
name = "train"
command = "train context --data {} --config {} --steps {steps}"
[stage.grid]
seed = [0, 1]
hidden_units = [8, 16]
[[stage]]
name = "eval"
after = "train"
command = "eval context --model {{train}} --env toy:inner --validation-rollouts 2 --validation-steps 5 --transitions 1 --strategy random"
[stage.grid]
"--contexts" = [{contexts}]
[slurm]
memory = "1G"
time = "00:10:00"
"#,
        data.display(),
        config.display()
    )
}

pub(crate) fn plan(dir: &Path, spec: &str, out: &str) -> std::process::Output {
    std::fs::write(dir.join("spec.toml"), spec).unwrap();
    mbrl(dir).args(["sweep", "plan", "spec.toml", "--out", out]).output().unwrap()
}

fn sweep_status(dir: &Path, sweep: &str) -> (i32, String) {
    let out = mbrl(dir).args(["sweep", "status", sweep]).output().unwrap();
    (out.status.code().unwrap_or(-1), stdout_of(&out) + &stderr_of(&out))
}

fn bash(script: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new("bash").arg(script).args(args).env("NO_COLOR", "1").output().unwrap()
}

#[test]
fn a_local_sweep_runs_reruns_and_reports_failures() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (data, config) = toy_inputs(d);
    let planned = plan(d, &two_stage_spec(&data, &config, 20, "2, 0"), "s");
    assert!(planned.status.success(), "{}", stderr_of(&planned));
    assert!(stdout_of(&planned).contains("planned 12 jobs (train 4, eval 8)"), "{}", stdout_of(&planned));
    let jobs = std::fs::read_to_string(d.join("s/jobs.txt")).unwrap();
    assert_eq!(jobs.lines().count(), 12);
    assert!(jobs.lines().all(|l| l.contains("--job-dir") && l.contains("--threads 1")), "{jobs}");
    // Planning the same spec again rewrites the same files.
    let before = std::fs::read(d.join("s/sweep.json")).unwrap();
    assert!(plan(d, &two_stage_spec(&data, &config, 20, "2, 0"), "s").status.success());
    assert_eq!(before, std::fs::read(d.join("s/sweep.json")).unwrap());

    let (code, text) = sweep_status(d, "s");
    assert_eq!(code, 3, "nothing has run: {text}");
    assert!(text.contains("0/12 jobs done") && text.contains("not started"), "{text}");

    let run = bash(&d.join("s/run-local.sh"), &["2"]);
    let text = stdout_of(&run) + &stderr_of(&run);
    // `--contexts 0` is refused by eval context: those four jobs fail, the rest finish.
    assert_eq!(run.status.code(), Some(1), "{text}");
    assert!(text.contains("8/12 jobs done, 4 failed"), "{text}");
    assert!(text.contains("contexts-0_") || text.contains("_contexts-0"), "{text}");
    assert!(text.contains("failed: error:") && text.contains("--contexts"), "{text}");
    let report = mbrl(d).args(["sweep", "report", "s"]).output().unwrap();
    assert!(report.status.success(), "{}", stderr_of(&report));
    assert!(stdout_of(&report).contains("eval: 4 of 8 runs done"), "{}", stdout_of(&report));
    let markdown = std::fs::read_to_string(d.join("s/report/report.md")).unwrap();
    assert!(markdown.contains("| hidden_units=8 | 2 |") && markdown.contains("95 % t"), "{markdown}");
    let cells = std::fs::read_to_string(d.join("s/report/cells.csv")).unwrap();
    assert!(cells.starts_with("stage,cell,metric,n,mean,sd,ci_low,ci_high"), "{cells}");
    let model = d.join("s/runs/train/hidden_units-8_seed-1/model");
    let weights = std::fs::read(model.join("metrics.jsonl")).unwrap();

    // A second run skips every finished job and leaves their outputs alone.
    let again = mbrl(d).args(["sweep", "status", "s"]).output().unwrap();
    assert_eq!(again.status.code(), Some(1));
    let line = jobs.lines().next().unwrap();
    let rerun = std::process::Command::new("bash").arg("-c").arg(line).output().unwrap();
    assert!(rerun.status.success() && stdout_of(&rerun).contains("done already"), "{}", stderr_of(&rerun));
    assert_eq!(weights, std::fs::read(model.join("metrics.jsonl")).unwrap());

    // A sweep moved elsewhere (results fetched from a cluster) is followed and reported where it lies now.
    std::fs::rename(d.join("s"), d.join("moved")).unwrap();
    let (code, text) = sweep_status(d, "moved");
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("8/12 jobs done, 4 failed"), "{text}");
    let report = mbrl(d).args(["sweep", "report", "moved", "--out", "moved-report"]).output().unwrap();
    assert!(stdout_of(&report).contains("eval: 4 of 8 runs done"), "{}", stderr_of(&report));
    assert_eq!(cells, std::fs::read_to_string(d.join("moved-report/cells.csv")).unwrap());
}

/// Whether the training at `model` checkpoints step `step` or later within `timeout`.
pub(crate) fn wait_for_step(model: &Path, step: u64, timeout: Duration) -> bool {
    let start = Instant::now();
    while start.elapsed() < timeout {
        if let Ok(text) = std::fs::read_to_string(model.join("checkpoint.json")) {
            let at = serde_json::from_str::<serde_json::Value>(&text).ok().and_then(|v| v["step"].as_u64());
            if at.is_some_and(|s| s >= step) {
                return true;
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    false
}

#[test]
fn a_stopped_job_line_resumes_to_the_uninterrupted_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (data, config) = toy_inputs(d);
    let spec = format!(
        "[[stage]]\nname = \"train\"\ncommand = \"train context --data {} --config {} --steps 400\"\n",
        data.display(),
        config.display()
    );
    for name in ["a", "b"] {
        let out = plan(d, &spec, name);
        assert!(out.status.success(), "{}", stderr_of(&out));
    }
    let line = |sweep: &str| {
        std::fs::read_to_string(d.join(sweep).join("jobs.txt")).unwrap().lines().next().unwrap().to_string()
    };
    let whole = std::process::Command::new("bash").arg("-c").arg(line("a")).output().unwrap();
    assert!(whole.status.success(), "{}", stderr_of(&whole));

    let model = d.join("b/runs/train/run/model");
    let mut child = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!("exec {}", line("b")))
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    assert!(wait_for_step(&model, 20, Duration::from_secs(60)), "no checkpoint at step 20");
    // SIGTERM is what Slurm's time-limit warning becomes (see the batch script).
    send_signal(child.id(), "TERM");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let (code, text) = sweep_status(d, "b");
    assert_eq!(code, 3, "{text}");
    assert!(text.contains("stopped at step"), "{text}");
    let resumed = std::process::Command::new("bash").arg("-c").arg(line("b")).output().unwrap();
    assert!(resumed.status.success(), "{}", stderr_of(&resumed));
    let (code, text) = sweep_status(d, "b");
    assert_eq!(code, 0, "{text}");
    for file in ["model.safetensors", "metrics.jsonl"] {
        let a = std::fs::read(d.join("a/runs/train/run/model").join(file));
        let b = std::fs::read(model.join(file));
        assert!(a.is_ok() && a.ok() == b.ok(), "{file} differs after stop and resume");
    }
}

fn send_signal(pid: u32, signal: &str) {
    let ok = std::process::Command::new("kill").arg(format!("-{signal}")).arg(pid.to_string()).status().unwrap();
    assert!(ok.success());
}

#[test]
fn spec_errors_name_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let base = "[[stage]]\nname = \"t\"\ncommand = \"train context --data x.mcap\"\n";
    let cases: &[(&str, &[&str])] = &[
        (&format!("{base}[stage.grid]\nseed = [0]\n[slurmm]\n"), &["slurmm", "line 6"]),
        (&format!("{base}[stage.grid]\nseed = []\n"), &["stage[0].grid.seed", "empty"]),
        (
            &format!(
                "{base}[stage.grid]\nseed = [{}]\n",
                (0..10_001).map(|i| i.to_string()).collect::<Vec<_>>().join(",")
            ),
            &["--allow-large", "10001"],
        ),
        (&base.replace("--data x.mcap", "--data x.mcap --bogus 3"), &["stage[0].command", "--bogus"]),
        (&base.replace("train context", "watch"), &["stage[0].command", "'watch'", "collect, train"]),
    ];
    for (spec, needles) in cases {
        let out = plan(d, spec, "s");
        assert_one_line_error(&out, needles);
        assert!(!d.join("s").exists(), "a refused plan leaves no directory: {spec}");
    }
    assert!(plan(d, base, "s").status.success());
    let other = plan(d, &base.replace("x.mcap", "y.mcap"), "s");
    assert_one_line_error(&other, &["--out", "different sweep"]);
}

/// The shipped specs (the reproduction targets' sweeps) plan with this binary's flags.
#[test]
fn shipped_specs_plan() {
    let tmp = tempfile::tempdir().unwrap();
    let specs = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps")).unwrap();
    let mut planned = 0;
    for spec in specs.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|e| e == "toml")) {
        let out = mbrl(tmp.path())
            .arg("sweep")
            .arg("plan")
            .arg(&spec)
            .arg("--out")
            .arg(spec.file_stem().unwrap())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}: {}", spec.display(), stderr_of(&out));
        planned += 1;
    }
    assert!(planned >= 2);
    let toy = std::fs::read_to_string(tmp.path().join("context-toy/jobs-eval.txt")).unwrap();
    assert_eq!(toy.lines().count(), 18);
    assert!(toy.lines().all(|l| l.contains("--env toy:inner") == l.contains("env-toy_inner")), "{toy}");
}
