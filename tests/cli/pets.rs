//! End to end: collect → train a PETS ensemble → plan with it, resume, and the errors a user can run into.

use std::path::Path;

use crate::common::*;
use mbrl::data::{read_dataset, write_dataset};
use mbrl::models::pets::{Pets, PetsConfig, Preset};
use mbrl::run::dir::Provenance;
use mbrl::train::job::start;
use mbrl::train::Request;

/// A network small enough to train in a second; checkpoints every 20 steps.
const TINY: &str = "hidden_layers = 2\nhidden_units = 16\nvalidate_every = 10\ncheckpoint_every = 20\n";

fn collect(dir: &Path, name: &str, env: &str, rollouts: &str) {
    mbrl(dir)
        .args(["collect", "--env", env, "--rollouts", rollouts, "--steps", "30", "-q", "--out", name])
        .assert()
        .success();
}

fn tiny_config(dir: &Path) {
    std::fs::write(dir.join("tiny.toml"), TINY).unwrap();
}

#[test]
fn collect_train_plan_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "random.mcap", "pendulum", "30");
    tiny_config(dir.path());
    let out = mbrl(dir.path())
        .args(["train", "--method", "pets", "--env", "pendulum", "--data", "random.mcap", "--config", "tiny.toml"])
        .args(["--ensemble", "2", "--steps", "60", "--out", "models/p", "--no-tui"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let text = stdout_of(&out);
    assert!(text.contains("PETS ensemble of 2") && text.contains("best validation MSE"), "{text}");
    for file in ["checkpoint.json", "config.json", "model.safetensors", "state.safetensors", "metrics.jsonl"] {
        assert!(dir.path().join("models/p").join(file).is_file(), "{file} missing");
    }
    // The held-out metric is an MSE, not the NLL being trained: its own column (and panel of loss.png).
    let losses = std::fs::read_to_string(dir.path().join("models/p/losses.csv")).unwrap();
    assert!(losses.starts_with("step,loss,validation_mse\n"), "{losses}");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("models/p/checkpoint.json")).unwrap()).unwrap();
    assert_eq!(manifest["complete"], true);
    assert_eq!(manifest["method"], "pets");
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("models/p/config.json")).unwrap()).unwrap();
    assert_eq!(config["config"]["hidden_units"], 16);
    assert_eq!(config["config"]["optimizer"]["epsilon"], 1e-8);

    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum", "--model", "models/p", "--candidates", "40", "--elites", "5"])
        .args(["--iters", "2", "--steps", "10", "--particles", "4", "-q", "--out", "plan.mcap"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("return"), "{}", stdout_of(&out));
    assert_eq!(read_dataset(&dir.path().join("plan.mcap")).unwrap().steps.len(), 10);
}

#[test]
fn resume_ends_with_the_bytes_of_an_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "random.mcap", "pendulum", "20");
    let mut config = PetsConfig::preset(Preset::Small);
    config = mbrl::train::config::apply_toml(&config, TINY).unwrap();
    config.ensemble = 2;
    config.steps = 70;
    let request = Request::<Pets> {
        env: None,
        data: vec![dir.path().join("random.mcap")],
        seed: 5,
        config: config.clone(),
        variant: (),
        provenance: Provenance::new("mbrl train …".into(), 5, 1),
    };
    let run_dir = |name: &str| dir.path().join(name);
    start(&run_dir("whole"), &request, &mbrl::run::NullMonitor).unwrap();
    // Stopped after step 50: the last checkpoint is step 40, so steps 41–50 are redone after resuming.
    let stop = StopAfter::new(50);
    let err = start(&run_dir("stopped"), &request, &stop).err().unwrap();
    assert!(err.is_cancelled(), "{err}");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("stopped/checkpoint.json")).unwrap()).unwrap();
    assert_eq!((manifest["step"].as_u64(), manifest["complete"].as_bool()), (Some(40), Some(false)));
    // A stopped run is not a model.
    let plan = mbrl(dir.path()).args(["plan", "--env", "pendulum", "--model", "stopped", "-q"]).output().unwrap();
    assert!(!plan.status.success() && stderr_of(&plan).contains("--resume"), "{}", stderr_of(&plan));

    let out = mbrl(dir.path()).args(["train", "--resume", "stopped", "--no-tui"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let whole = dir_bytes(&dir.path().join("whole"));
    let names = |files: &[(String, Vec<u8>)]| files.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    let same_as_whole = |files: &[(String, Vec<u8>)]| {
        assert_eq!(names(&whole), names(files));
        for ((name, a), (_, b)) in whole.iter().zip(files) {
            assert!(
                a == b,
                "{name} differs from the uninterrupted run:\n{}\n---\n{}",
                String::from_utf8_lossy(a).chars().take(600).collect::<String>(),
                String::from_utf8_lossy(b).chars().take(600).collect::<String>()
            );
        }
    };
    same_as_whole(&dir_bytes(&dir.path().join("stopped")));

    // A finished run of 40 steps, trained on to 70, is the run that was started with 70.
    let short = Request { config: PetsConfig { steps: 40, ..config.clone() }, ..request };
    start(&run_dir("short"), &short, &mbrl::run::NullMonitor).unwrap();
    let out = mbrl(dir.path()).args(["train", "--resume", "short", "--steps", "70", "--no-tui"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert_extended_like(&dir.path().join("whole"), &dir.path().join("short"));
}

#[test]
fn config_errors_name_the_key_and_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "random.mcap", "pendulum", "4");
    for (text, expected) in [("hiden_units = 3", "unknown key 'hiden_units'"), ("steps = \"many\"", "wrong value type")]
    {
        std::fs::write(dir.path().join("bad.toml"), text).unwrap();
        let out = mbrl(dir.path())
            .args(["train", "--method", "pets", "--data", "random.mcap", "--config", "bad.toml", "--out", "m", "-q"])
            .output()
            .unwrap();
        let err = stderr_of(&out);
        assert!(!out.status.success() && err.contains("bad.toml") && err.contains(expected), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!dir.path().join("m").exists());
    }
}

#[test]
fn unusable_data_and_mismatched_checkpoints_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "random.mcap", "pendulum", "4");
    let mut data = read_dataset(&dir.path().join("random.mcap")).unwrap();
    // A dataset without actions.
    let mut no_actions = data.clone();
    no_actions.meta.action_dim = 0;
    no_actions.steps.iter_mut().for_each(|s| s.action.clear());
    write_dataset(&dir.path().join("no-actions.mcap"), &no_actions).unwrap();
    // NaN in a state (JSON has no NaN: it is written as null, which the reader refuses by name).
    data.steps[3].next_state[1] = f64::NAN;
    write_dataset(&dir.path().join("nan.mcap"), &data).unwrap();
    for (file, expected) in [("no-actions.mcap", "no actions"), ("nan.mcap", "null, expected f64")] {
        let out =
            mbrl(dir.path()).args(["train", "--method", "pets", "--data", file, "--out", "m", "-q"]).output().unwrap();
        let err = stderr_of(&out);
        assert!(!out.status.success() && err.contains(expected), "{file}: {err}");
        assert!(!dir.path().join("m/checkpoint.json").exists());
    }
    // --env disagreeing with the data.
    let out = mbrl(dir.path())
        .args(["train", "--method", "pets", "--env", "pendulum:heavy", "--data", "random.mcap", "-q"])
        .output()
        .unwrap();
    assert!(stderr_of(&out).contains("'pendulum' rollouts"), "{}", stderr_of(&out));

    tiny_config(dir.path());
    mbrl(dir.path())
        .args(["train", "--method", "pets", "--data", "random.mcap", "--config", "tiny.toml", "--steps", "5"])
        .args(["--ensemble", "1", "--out", "m", "-q"])
        .assert()
        .success();
    // A model of another env.
    let out = mbrl(dir.path()).args(["plan", "--env", "pendulum:heavy", "--model", "m", "-q"]).output().unwrap();
    assert!(stderr_of(&out).contains("is a model of 'pendulum'"), "{}", stderr_of(&out));
    // A checkpoint of another method: the ball EKF's parameter directory.
    std::fs::create_dir_all(dir.path().join("ball")).unwrap();
    std::fs::write(dir.path().join("ball/params.json"), "{}").unwrap();
    let out = mbrl(dir.path()).args(["plan", "--env", "pendulum", "--model", "ball", "-q"]).output().unwrap();
    assert!(stderr_of(&out).contains("ball EKF"), "{}", stderr_of(&out));
    // Weights changed after training: the manifest no longer vouches for them.
    let weights = dir.path().join("m/model.safetensors");
    let mut bytes = std::fs::read(&weights).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&weights, bytes).unwrap();
    let out = mbrl(dir.path()).args(["plan", "--env", "pendulum", "--model", "m", "-q"]).output().unwrap();
    assert!(stderr_of(&out).contains("CRC-32"), "{}", stderr_of(&out));
}
