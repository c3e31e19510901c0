//! End to end: instance pairs → a context model → calibration → planning on the calibrated model, resume, and
//! the errors a user can run into.

mod common;

use std::path::Path;

use common::*;
use mbrl::data::read_dataset;

/// Networks small enough to train in a second; checkpoints every 10 steps.
const TINY: &str = "embedding = 16\nhidden_units = 16\ntransition_features = 8\nchunk_states = 10\n\
                    context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n";

fn run_ok(dir: &Path, args: &[&str]) -> String {
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    stdout_of(&out)
}

fn train_tiny(dir: &Path, env: &str, data: &str, out: &str, steps: &str) {
    std::fs::write(dir.join("tiny.toml"), TINY).unwrap();
    run_ok(dir, &["collect", "--env", env, "--instances", "12", "--steps", "20", "-q", "--out", data]);
    run_ok(
        dir,
        &["train", "--method", "context", "--data", data, "--config", "tiny.toml", "--steps", steps, "--out", out],
    );
}

#[test]
fn collect_train_calibrate_plan() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    train_tiny(d, "pendulum:quadrant", "pairs.mcap", "models/c", "20");
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("models/c/config.json")).unwrap()).unwrap();
    assert_eq!(config["method"], "context");
    assert_eq!(config["config"]["latent_dim"], 16, "pendulum takes Table B.1's D_β");
    let schedule = &config["config"]["context_from_target"];
    assert_eq!(
        (schedule["decay_from"].as_u64(), schedule["zero_at"].as_u64()),
        (Some(6), Some(12)),
        "30 % and 60 % of 20 steps"
    );

    let out = mbrl(d)
        .args(["calibrate", "--model", "models/c", "--env", "pendulum:quadrant", "--instance-seed", "3"])
        .args(["--strategy", "mpc", "--transitions", "4", "--horizon", "3", "--candidates", "30", "--elites", "5"])
        .args(["--iters", "2", "--beta-samples", "3", "--out", "calib.mcap", "--no-tui"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let text = stdout_of(&out);
    assert!(text.contains("entropy of q(β | context)") && text.contains("4 mpc transitions"), "{text}");
    let calib = read_dataset(&d.join("calib.mcap")).unwrap();
    assert_eq!(calib.steps.len(), 4);
    assert_eq!(calib.meta.env, "pendulum:quadrant");

    let text = run_ok(
        d,
        &[
            "plan",
            "--env",
            "pendulum:quadrant",
            "--model",
            "models/c",
            "--context",
            "calib.mcap",
            "--instance-seed",
            "3",
            "--candidates",
            "30",
            "--elites",
            "5",
            "--iters",
            "2",
            "--steps",
            "5",
            "-q",
            "--out",
            "plan.mcap",
        ],
    );
    assert!(text.contains("return"), "{text}");
    assert_eq!(read_dataset(&d.join("plan.mcap")).unwrap().meta.instances[0], calib.meta.instances[0]);
}

#[test]
fn same_seed_same_weights() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    train_tiny(d, "toy:outer", "pairs.mcap", "models/a", "15");
    run_ok(
        d,
        &[
            "train",
            "--method",
            "context",
            "--data",
            "pairs.mcap",
            "--config",
            "tiny.toml",
            "--steps",
            "15",
            "--out",
            "models/b",
        ],
    );
    let a = std::fs::read(d.join("models/a/model.safetensors")).unwrap();
    let b = std::fs::read(d.join("models/b/model.safetensors")).unwrap();
    assert_eq!(a, b, "same seed, data and config give the same weights");
}

#[test]
fn wrong_inputs_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    train_tiny(d, "toy:inner", "pairs.mcap", "models/toy", "10");
    // A dataset of independent rollouts is not a context dataset.
    run_ok(d, &["collect", "--env", "toy:inner", "--rollouts", "4", "--steps", "20", "-q", "--out", "plain.mcap"]);
    let out = mbrl(d).args(["train", "--method", "context", "--data", "plain.mcap", "--no-tui"]).output().unwrap();
    assert!(!out.status.success());
    let err = stderr_of(&out);
    assert!(err.contains("instance pairs") && err.lines().count() == 1, "{err}");
    // The model of another env.
    let out = mbrl(d)
        .args([
            "calibrate",
            "--model",
            "models/toy",
            "--env",
            "toy:outer",
            "--instance-seed",
            "1",
            "--strategy",
            "random",
        ])
        .args(["--transitions", "2", "--out", "c.mcap", "--no-tui"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = stderr_of(&out);
    assert!(err.contains("toy:inner") && err.contains("toy:outer") && !d.join("c.mcap").exists(), "{err}");
    // A context file of another env.
    run_ok(d, &["collect", "--env", "pendulum", "--rollouts", "1", "--steps", "3", "-q", "--out", "pend.mcap"]);
    let out = mbrl(d)
        .args([
            "plan",
            "--env",
            "pendulum",
            "--model",
            "models/toy",
            "--context",
            "pend.mcap",
            "--steps",
            "2",
            "--no-tui",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(stderr_of(&out).contains("toy:inner"), "{}", stderr_of(&out));
    // A checkpoint of another method.
    std::fs::write(d.join("five.toml"), "steps = 5\n").unwrap();
    run_ok(d, &["collect", "--env", "pendulum", "--rollouts", "4", "--steps", "20", "-q", "--out", "pend4.mcap"]);
    run_ok(d, &["train", "--method", "pets", "--data", "pend4.mcap", "--config", "five.toml", "-q", "--out", "pets"]);
    for args in [
        &["calibrate", "--model", "pets", "--env", "pendulum:quadrant", "--instance-seed", "1", "--strategy", "random"]
            [..],
        &["eval", "context", "--model", "pets", "--env", "pendulum", "--out", "report"][..],
    ] {
        let out = mbrl(d).args(args).args(["--no-tui"]).output().unwrap();
        assert!(!out.status.success());
        let err = stderr_of(&out);
        assert!(err.contains("'pets' checkpoint") && err.lines().count() == 1, "{err}");
    }
    assert!(!d.join("report").exists());

    // A run still in training (here: a finished one's manifest marked unfinished) is refused unless asked for.
    std::fs::create_dir_all(d.join("partial")).unwrap();
    for (name, bytes) in dir_bytes(&d.join("models/toy")) {
        let bytes = if name == "checkpoint.json" {
            String::from_utf8(bytes).unwrap().replace("\"complete\": true", "\"complete\": false").into_bytes()
        } else {
            bytes
        };
        std::fs::write(d.join("partial").join(name), bytes).unwrap();
    }
    let eval = |extra: &[&str]| {
        mbrl(d)
            .args(["eval", "context", "--model", "partial", "--env", "toy:inner", "--contexts", "2"])
            .args([
                "--validation-rollouts",
                "2",
                "--validation-steps",
                "5",
                "--transitions",
                "1",
                "--strategy",
                "random",
            ])
            .args(["--out", "partial-report", "--no-tui", "-q"])
            .args(extra)
            .output()
            .unwrap()
    };
    assert_one_line_error(&eval(&[]), &["partial", "training stopped at step 10 of 10"]);
    assert!(!d.join("partial-report").exists());
    let out = eval(&["--allow-incomplete"]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    let report = std::fs::read_to_string(d.join("partial-report/report.md")).unwrap();
    assert!(report.contains("10 of 10 steps (training still in progress)"), "{report}");
}
