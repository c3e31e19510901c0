//! `KEY=VALUE` overrides on `train` and `eval`, the one order settings apply in (preset < --config < flags <
//! KEY=VALUE), the errors a bad key gives, and a run's own config.json passed back to `--config`.

use std::path::Path;

use crate::common::*;

const TINY: &str = "hidden_layers = 2\nhidden_units = 16\nvalidate_every = 10\ncheckpoint_every = 20\nsteps = 100\n\
                    batch_size = 64\n";

fn run_ok(dir: &Path, args: &[&str]) {
    let out = mbrl(dir).args(args).args(["--no-tui", "-q"]).output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
}

fn config_of(path: &Path) -> serde_json::Value {
    let record: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    record["config"].clone()
}

fn setup(dir: &Path) {
    std::fs::write(dir.join("tiny.toml"), TINY).unwrap();
    run_ok(dir, &["collect", "--env", "pendulum", "--rollouts", "8", "--steps", "30", "--out", "roll.mcap"]);
}

#[test]
fn overrides_win_over_flags_which_win_over_the_file_over_the_preset() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let args = ["train", "pets", "--data", "roll.mcap", "--config", "tiny.toml", "--steps", "20", "--batch", "32"];
    run_ok(d, &[&args[..], &["steps=30", "optimizer.learning_rate=0.002", "--out", "a"]].concat());
    let config = config_of(&d.join("a/config.json"));
    assert_eq!(config["steps"], 30, "KEY=VALUE over the flag (and the file)");
    assert_eq!(config["batch_size"], 32, "the flag over the file");
    assert_eq!(config["hidden_units"], 16, "the file over the preset");
    assert_eq!(config["ensemble"], 5, "the preset where nothing else speaks");
    assert_eq!(config["optimizer"]["learning_rate"], 0.002);
    assert_eq!(config["optimizer"]["epsilon"], 1e-8, "a nested key leaves its neighbours");
}

#[test]
fn bad_overrides_are_one_line_errors_naming_the_key_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let train = |extra: &[&str]| {
        mbrl(d).args(["train", "pets", "--data", "roll.mcap", "--out", "m", "--no-tui"]).args(extra).output().unwrap()
    };
    let out = train(&["lr=3e-4"]);
    assert_one_line_error(&out, &["lr=3e-4: unknown key 'lr'", "valid keys:", "optimizer.learning_rate", "steps"]);
    assert_one_line_error(&train(&["steps=many"]), &["steps=many", "key 'steps'", "wrong value type"]);
    assert_one_line_error(&train(&["batch_size=0"]), &["batch_size must be 1..=65536, got 0"]);
    assert_one_line_error(&train(&["roll.mcap"]), &["'roll.mcap' is not KEY=VALUE"]);
    // The same checks on a config file, TOML or JSON.
    std::fs::write(d.join("bad.json"), r#"{"optimizer": {"lr": 1}}"#).unwrap();
    assert_one_line_error(&train(&["--config", "bad.json"]), &["bad.json", "unknown key 'optimizer.lr'"]);
    // Every method takes them; ball-ekf lists its own keys.
    let out = mbrl(d).args(["train", "ball-ekf", "--data", "x.mcap", "rate=1", "--no-tui"]).output().unwrap();
    assert_one_line_error(&out, &["unknown key 'rate'", "learning_rate", "chunk_len"]);
    assert!(!d.join("m").exists() && !d.join("models").exists(), "{:?}", files_in(d));
}

#[test]
fn a_runs_config_json_reruns_it_to_the_same_config_and_weights() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let first = ["train", "pets", "--data", "roll.mcap", "--config", "tiny.toml", "--ensemble", "2", "steps=40"];
    run_ok(d, &[&first[..], &["optimizer.weight_decay=0", "--seed", "5", "--out", "a"]].concat());
    run_ok(d, &["train", "pets", "--data", "roll.mcap", "--config", "a/config.json", "--seed", "5", "--out", "b"]);
    let (a, b) = (config_of(&d.join("a/config.json")), config_of(&d.join("b/config.json")));
    assert_eq!(serde_json::to_string(&a).unwrap(), serde_json::to_string(&b).unwrap());
    assert_eq!(a["optimizer"]["weight_decay"], 0.0);
    let weights = |run: &str| std::fs::read(d.join(run).join("model.safetensors")).unwrap();
    assert!(weights("a") == weights("b"), "same config, data and seed: same weights");
    // A run of another method is named, with the command that takes it.
    let out = mbrl(d).args(["train", "dlgpd", "--data", "roll.mcap", "--config", "a/config.json"]).output().unwrap();
    assert_one_line_error(&out, &["config.json of a pets run", "mbrl train pets --config"]);
}

#[test]
fn eval_overrides_change_a_recorded_config() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let eval = ["eval", "embodied", "--game", "lightsout", "--embodiment", "cursor", "--max-depth", "1"];
    run_ok(d, &[&eval[..], &["--boards", "2", "--out", "r"]].concat());
    run_ok(d, &["eval", "embodied", "--config", "r/config.json", "settings.boards_per_depth=1", "--out", "r1"]);
    let record: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("r1/config.json")).unwrap()).unwrap();
    assert_eq!(record["settings"]["settings"]["boards_per_depth"], 1);
    assert_eq!(record["settings"]["game"], "lightsout", "the rest as recorded");
    let out = mbrl(d).args([&eval[..], &["boards=1"]].concat()).output().unwrap();
    assert_one_line_error(&out, &["unknown key 'boards'", "settings.boards_per_depth", "game"]);
}

#[test]
fn each_methods_help_describes_its_own_presets_in_unwrapped_paragraphs() {
    let dir = tempfile::tempdir().unwrap();
    let help = |method: &str| {
        let out = mbrl(dir.path()).args(["train", method, "--help"]).env("COLUMNS", "400").output().unwrap();
        stdout_of(&out)
    };
    let context = help("context");
    assert!(context.contains("1200 steps") && context.contains("KEY=VALUE"), "{context}");
    assert!(help("seads").contains("500k environment steps"));
    assert!(help("dlgpd").contains("conv VAE"));
    assert!(!context.contains("SiLU"), "no PETS presets in context's help");
    // A paragraph is one line when the terminal is wide enough: clap wraps, the source does not.
    assert!(context.lines().any(|l| l.starts_with("Settings apply in this order") && l.ends_with("the method.")));
}
