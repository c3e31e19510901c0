//! End to end for TRADYN: maps → unicycle pairs → a model with terrain lookup and its ablation → calibration →
//! navigation on a test map; resume; and the errors a user can run into.

use std::path::Path;

use crate::common::*;
use mbrl::data::read_dataset;

/// Networks small enough to train in seconds; checkpoints every 10 steps.
const TINY: &str = "embedding = 16\nhidden_units = 16\ntransition_features = 8\nlatent_dim = 4\nchunk_states = 10\n\
                    context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n";

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    mbrl(dir).args(args).arg("--no-tui").output().unwrap()
}

fn run_ok(dir: &Path, args: &[&str]) -> String {
    let out = run(dir, args);
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    stdout_of(&out)
}

fn fails_with(dir: &Path, args: &[&str], expected: &str) {
    let out = run(dir, args);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = stderr_of(&out);
    assert_eq!(err.trim().lines().count(), 1, "{args:?}: one line, got {err}");
    assert!(err.contains(expected), "{args:?}: expected '{expected}' in {err}");
}

/// Maps, a small pair dataset and the tiny config in `dir`.
fn world(dir: &Path) {
    std::fs::write(dir.join("tiny.toml"), TINY).unwrap();
    run_ok(dir, &["collect", "--env", "terrain", "--maps", "4", "--out", "maps", "-q"]);
    run_ok(
        dir,
        &[
            "collect",
            "--env",
            "unicycle",
            "--maps",
            "maps",
            "--split",
            "train",
            "--instances",
            "12",
            "--steps",
            "20",
            "--out",
            "uni.mcap",
        ],
    );
}

fn train(dir: &Path, out: &str, steps: &str, extra: &[&str]) -> String {
    let mut args = vec!["train", "--method", "tradyn", "--data", "uni.mcap", "--config", "tiny.toml"];
    args.extend_from_slice(&["--steps", steps, "--out", out]);
    args.extend_from_slice(extra);
    run_ok(dir, &args)
}

const SMALL_CEM: [&str; 10] = ["--candidates", "24", "--elites", "4", "--iters", "2", "--horizon", "4", "--steps", "5"];

#[test]
fn train_calibrate_and_navigate_with_and_without_terrain_lookup() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    world(d);
    let text = train(d, "models/t", "20", &[]);
    assert!(text.contains("TRADYN model with terrain lookup"), "{text}");
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("models/t/config.json")).unwrap()).unwrap();
    assert_eq!(config["method"], "tradyn");
    assert_eq!(config["model"]["local_dim"], 3, "τ is read, not predicted");
    assert_eq!(config["model"]["feature_dim"], 8);
    let text = train(d, "models/nt", "20", &["--no-terrain"]);
    assert!(text.contains("without terrain lookup"), "{text}");
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("models/nt/config.json")).unwrap()).unwrap();
    assert!(config["model"].get("local_dim").is_none(), "the ablation predicts all 8 features");

    let text = run_ok(
        d,
        &[
            "calibrate",
            "--model",
            "models/t",
            "--env",
            "unicycle",
            "--map",
            "maps/map002.png",
            "--instance-seed",
            "5",
            "--strategy",
            "random",
            "--init-state",
            "0.3,0.4,0,1",
            "--out",
            "calib.mcap",
        ],
    );
    assert!(text.contains("10 random transitions"), "TRADYN calibrates 10 transitions by default: {text}");
    let calib = read_dataset(&d.join("calib.mcap")).unwrap();
    assert_eq!((calib.steps.len(), calib.meta.env.as_str()), (10, "unicycle"));
    assert_eq!(calib.steps[0].state, vec![0.3, 0.4, 0.0, 1.0]);
    assert_eq!(calib.meta.instances[0]["map"], "map002.png");

    for (model, context) in [("models/t", Some("calib.mcap")), ("models/nt", Some("calib.mcap")), ("models/t", None)] {
        let mut args = vec!["plan", "--env", "unicycle", "--model", model, "--map", "maps/map002.png"];
        args.extend_from_slice(&["--start", "0.3,0.4,1", "--goal", "0.5,0.5", "--instance-seed", "5", "-q"]);
        args.extend_from_slice(&SMALL_CEM);
        args.extend_from_slice(&["--out", "plan.mcap"]);
        if let Some(c) = context {
            args.extend_from_slice(&["--context", c]);
        }
        let text = run_ok(d, &args);
        assert!(text.contains("energy Σ throttle²") && text.contains("final distance"), "{text}");
        let plan = read_dataset(&d.join("plan.mcap")).unwrap();
        assert_eq!(plan.steps.len(), 5);
        assert_eq!(plan.steps[0].state, vec![0.3, 0.4, 0.0, 1.0], "the robot starts at rest");
        assert_eq!(plan.meta.instances[0], calib.meta.instances[0], "the same robot");
        std::fs::remove_file(d.join("plan.mcap")).unwrap();
    }

    let mut args = vec!["eval", "tradyn", "--model-terrain", "models/t", "--model-no-terrain", "models/nt"];
    args.extend_from_slice(&["--maps", "maps", "--tasks", "2", "--steps", "4", "--horizon", "3", "--candidates", "16"]);
    args.extend_from_slice(&["--elites", "4", "--iters", "1", "--prediction-steps", "5", "--out", "report"]);
    let text = run_ok(d, &args);
    assert!(text.contains("+T,+C") && text.contains("Wilcoxon"), "{text}");
    let tasks = std::fs::read_to_string(d.join("report/tasks.csv")).unwrap();
    assert_eq!(tasks.lines().count(), 1 + 2 * 4, "two tasks × four variants:\n{tasks}");
    for file in ["report.md", "table_5_2.csv", "energy_wilcoxon.csv", "prediction.csv", "prediction.png", "paths.png"] {
        assert!(d.join("report").join(file).is_file(), "{file} missing");
    }
    let report = std::fs::read_to_string(d.join("report/report.md")).unwrap();
    assert!(report.contains("+T: `models/t`, trained 20 steps; −T: `models/nt`, trained 20 steps."), "{report}");

    // A run still in training is refused, or with --allow-incomplete evaluated with its progress in the report.
    let manifest = d.join("models/nt/checkpoint.json");
    let finished = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, finished.replace("\"complete\": true", "\"complete\": false")).unwrap();
    let partial: Vec<&str> = args.iter().map(|a| if *a == "report" { "partial-report" } else { a }).collect();
    fails_with(d, &partial, "training stopped at step 20 of 20");
    assert!(!d.join("partial-report").exists());
    let out = run(d, &[&partial[..], &["--allow-incomplete"]].concat());
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("warning: models/nt: 20 of 20 steps"), "{}", stderr_of(&out));
    let report = std::fs::read_to_string(d.join("partial-report/report.md")).unwrap();
    assert!(report.contains("−T: `models/nt`, trained 20 of 20 steps (training still in progress)."), "{report}");
    std::fs::write(&manifest, finished).unwrap();
    let swapped =
        ["eval", "tradyn", "--model-terrain", "models/nt", "--model-no-terrain", "models/t", "--maps", "maps"];
    fails_with(d, &swapped, "--no-terrain");
}

#[test]
fn resume_ends_with_the_bytes_of_an_uninterrupted_run() {
    use mbrl::models::context::{ContextConfig, EnvFamily, Preset};
    use mbrl::models::tradyn;
    use mbrl::run::dir::Provenance;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    world(d);
    let mut config = ContextConfig::preset(Preset::Small, EnvFamily::Control);
    (config.embedding, config.hidden_units, config.transition_features, config.latent_dim) = (16, 16, 8, 4);
    (config.chunk_states, config.context_max, config.batch_size, config.steps) = (10, 4, 8, 30);
    (config.validate_every, config.checkpoint_every) = (10, 10);
    let request = mbrl::train::Request::<tradyn::Tradyn> {
        env: None,
        data: vec![d.join("uni.mcap")],
        seed: 3,
        config: config.clone(),
        variant: true,
        provenance: Provenance::new("mbrl train …".into(), 3, 1),
    };
    let start = mbrl::train::job::start::<tradyn::Tradyn>;
    start(&d.join("whole"), &request, &mbrl::run::NullMonitor).unwrap();
    let err = start(&d.join("stopped"), &request, &StopAfter::new(25)).err().unwrap();
    assert!(err.is_cancelled(), "{err}");
    run_ok(d, &["train", "--resume", "stopped", "-q"]);
    // The CLI adds its loss report after training; the library run writes none.
    let model_files = |name: &str| -> Vec<(String, Vec<u8>)> {
        dir_bytes(&d.join(name)).into_iter().filter(|(n, _)| !n.starts_with("loss")).collect()
    };
    let (whole, resumed) = (model_files("whole"), model_files("stopped"));
    assert_eq!(whole.iter().map(|f| &f.0).collect::<Vec<_>>(), resumed.iter().map(|f| &f.0).collect::<Vec<_>>());
    for ((name, a), (_, b)) in whole.iter().zip(&resumed) {
        assert!(a == b, "{name} differs after resuming");
    }
}

#[test]
fn wrong_inputs_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    world(d);
    train(d, "models/t", "10", &[]);
    run_ok(d, &["collect", "--env", "toy:inner", "--instances", "4", "--steps", "5", "--out", "toy.mcap", "-q"]);
    run_ok(
        d,
        &[
            "train",
            "--method",
            "context",
            "--data",
            "toy.mcap",
            "--config",
            "tiny.toml",
            "--steps",
            "5",
            "--out",
            "models/c",
        ],
    );
    std::fs::write(d.join("not-a-map.png"), b"hello").unwrap();
    // A valid plan command with one flag's value replaced (or a flag added).
    let with = |flag: &str, value: &str, expected: &str| {
        let mut args: Vec<&str> = vec!["plan", "--env", "unicycle", "--model", "models/t", "--map", "maps/map002.png"];
        args.extend_from_slice(&["--start", "0.3,0.4,1", "--goal", "0.5,0.5"]);
        args.extend_from_slice(&SMALL_CEM);
        match args.iter().position(|a| *a == flag) {
            Some(i) => args[i + 1] = value,
            None => args.extend_from_slice(&[flag, value]),
        }
        fails_with(d, &args, expected);
    };
    with("--start", "1.3,0.4,1", "[0, 1]²");
    with("--goal", "0.5,-0.1", "goal");
    with("--goal", "0.5", "--goal x,y");
    with("--map", "not-a-map.png", "not-a-map.png");
    with("--model", "models/c", "TRADYN model");
    with("--context", "toy.mcap", "toy:inner");
    fails_with(
        d,
        &["plan", "--env", "unicycle", "--model", "models/t", "--start", "0.3,0.4,1", "--goal", "0.5,0.5"],
        "--map PNG",
    );
    fails_with(d, &["plan", "--env", "pendulum", "--model", "true", "--map", "maps/map002.png"], "unicycle");
    fails_with(
        d,
        &[
            "calibrate",
            "--model",
            "models/t",
            "--env",
            "unicycle",
            "--map",
            "maps/map002.png",
            "--instance-seed",
            "1",
            "--strategy",
            "mpc",
        ],
        "--strategy random",
    );
    fails_with(
        d,
        &[
            "calibrate",
            "--model",
            "models/c",
            "--env",
            "unicycle",
            "--map",
            "maps/map002.png",
            "--instance-seed",
            "1",
            "--strategy",
            "random",
        ],
        "mbrl train tradyn",
    );
    fails_with(
        d,
        &["calibrate", "--model", "models/t", "--env", "toy:inner", "--instance-seed", "1", "--strategy", "random"],
        "unicycle",
    );
    fails_with(d, &["train", "--method", "tradyn", "--data", "toy.mcap", "--steps", "5"], "unicycle");
    fails_with(d, &["train", "--method", "context", "--data", "uni.mcap", "--steps", "5"], "mbrl train tradyn");
    assert!(!d.join("datasets/plan-unicycle.mcap").exists(), "no output from a failed run");
}
