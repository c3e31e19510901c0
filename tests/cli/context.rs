//! End to end: instance pairs → a context model → calibration → planning on the calibrated model, resume, and
//! the errors a user can run into.

use std::path::Path;

use crate::common::*;
use mbrl::data::read_dataset;

/// Networks small enough to train in a second; checkpoints every 10 steps.
const TINY: &str = "embedding = 16\nhidden_units = 16\ntransition_features = 8\nchunk_states = 10\n\
                    context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n";

fn run_ok(dir: &Path, args: &[&str]) -> String {
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    stdout_of(&out)
}

pub(crate) fn train_tiny(dir: &Path, env: &str, data: &str, out: &str, steps: &str) {
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
    // A start this pendulum cannot be in (it clips θ̇ to ±8 after every step) is refused, not calibrated from.
    let out = mbrl(d)
        .args([
            "calibrate",
            "--model",
            "models/c",
            "--env",
            "pendulum:quadrant",
            "--init-state",
            "3,9",
            "--instance-seed",
            "3",
        ])
        .args(["--strategy", "random", "--transitions", "2", "--out", "bad.mcap", "--no-tui"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["--init-state", "theta_dot = 9", "[-8, 8] rad/s"]);
    assert!(!d.join("bad.mcap").exists());

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
    let mark_unfinished = |from: &str, to: &str| {
        std::fs::create_dir_all(d.join(to)).unwrap();
        for (name, bytes) in dir_bytes(&d.join(from)) {
            let bytes = if name == "checkpoint.json" {
                String::from_utf8(bytes).unwrap().replace("\"complete\": true", "\"complete\": false").into_bytes()
            } else {
                bytes
            };
            std::fs::write(d.join(to).join(name), bytes).unwrap();
        }
    };
    mark_unfinished("models/toy", "partial");
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

    // calibrate and plan take such a run with --allow-incomplete too, and say how far it got.
    let calibrate = |extra: &[&str]| {
        mbrl(d)
            .args(["calibrate", "--model", "partial", "--env", "toy:inner", "--instance-seed", "1"])
            .args(["--strategy", "random", "--transitions", "1", "--out", "partial-calib.mcap", "--no-tui"])
            .args(extra)
            .output()
            .unwrap()
    };
    assert_one_line_error(&calibrate(&[]), &["partial", "training stopped at step 10 of 10"]);
    assert!(!d.join("partial-calib.mcap").exists());
    let out = calibrate(&["--allow-incomplete"]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("trained 10 of 10 steps (training still in progress)"), "{}", stdout_of(&out));
    assert!(stderr_of(&out).contains("warning: partial"), "{}", stderr_of(&out));
    mark_unfinished("pets", "pets-partial");
    let plan = |extra: &[&str]| {
        mbrl(d)
            .args(["plan", "--env", "pendulum", "--model", "pets-partial", "--steps", "2", "--candidates", "8"])
            .args(["--elites", "2", "--iters", "1", "--particles", "2", "--out", "partial-plan.mcap", "--no-tui"])
            .args(extra)
            .output()
            .unwrap()
    };
    assert_one_line_error(&plan(&[]), &["pets-partial", "training stopped at step 5 of 5"]);
    assert!(!d.join("partial-plan.mcap").exists());
    let out = plan(&["--allow-incomplete"]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    let said = format!("{}{}", stdout_of(&out), stderr_of(&out));
    assert!(said.contains("warning: pets-partial: 5 of 5 steps (training still in progress)"), "{said}");
}
