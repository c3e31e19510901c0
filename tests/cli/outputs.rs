//! The one rule for outputs, per subcommand (README, "Outputs are never silently replaced"): a default name
//! never replaces anything (the first free numbered name is written and printed), a named output that exists
//! is refused without --force and replaced with it.

use std::path::Path;

use crate::common::*;

const TINY_PETS: &str = "hidden_layers = 1\nhidden_units = 8\nvalidate_every = 5\ncheckpoint_every = 5\n";

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    mbrl(dir).args(args).args(["--no-tui", "-q"]).output().unwrap()
}

/// `args` twice without --out: the default, then its first numbered name, each printed; then the default
/// named as --out: refused, and replaced with --force.
fn holds_to_the_rule(dir: &Path, args: &[&str], default: &str, numbered: &str) {
    for expected in [default, numbered] {
        let out = run(dir, args);
        assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
        assert!(stdout_of(&out).contains(expected), "{args:?} should name {expected}: {}", stdout_of(&out));
        assert!(dir.join(expected).exists(), "{expected} not written");
    }
    let before = std::fs::metadata(dir.join(default)).unwrap().modified().unwrap();
    let named = [args, &["--out", default]].concat();
    assert_one_line_error(&run(dir, &named), &[default, "--force"]);
    assert_eq!(std::fs::metadata(dir.join(default)).unwrap().modified().unwrap(), before, "refused, yet touched");
    let forced = run(dir, &[&named[..], &["--force"]].concat());
    assert!(forced.status.success(), "{named:?} --force: {}", stderr_of(&forced));
}

#[test]
fn collect_plan_eval_and_train_never_replace_silently() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let collect = ["collect", "--env", "pendulum", "--rollouts", "4", "--steps", "10"];
    holds_to_the_rule(d, &collect, "datasets/pendulum-random.mcap", "datasets/pendulum-random-2.mcap");
    let plan = ["plan", "--env", "pendulum", "--model", "true", "--steps", "3", "--candidates", "20"];
    let plan = [&plan[..], &["--elites", "4", "--iters", "1", "--horizon", "3"]].concat();
    holds_to_the_rule(d, &plan, "datasets/plan-pendulum-true.mcap", "datasets/plan-pendulum-true-2.mcap");
    let eval = ["eval", "dataset", "--input", "datasets/pendulum-random.mcap"];
    holds_to_the_rule(d, &eval, "reports/dataset", "reports/dataset-2");
    std::fs::write(d.join("tiny.toml"), TINY_PETS).unwrap();
    let train = ["train", "pets", "--data", "datasets/pendulum-random.mcap", "--config", "tiny.toml", "--steps", "5"];
    holds_to_the_rule(d, &train, "models/pets-pendulum", "models/pets-pendulum-2");
}

#[test]
fn ball_outputs_and_export_never_replace_silently() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let collect = run(d, &["collect", "--env", "ball", "--trajectories", "2", "--out", "ball.mcap"]);
    assert!(collect.status.success(), "{}", stderr_of(&collect));
    let filter = ["filter", "--model", "thesis", "--input", "ball.mcap"];
    holds_to_the_rule(d, &filter, "filtered.csv", "filtered-2.csv");
    let predict = ["predict", "--model", "thesis", "--input", "ball.mcap", "--horizon", "0.2s"];
    holds_to_the_rule(d, &predict, "predicted.csv", "predicted-2.csv");
    let export = ["export", "--input", "ball.mcap", "--out", "ball.csv"];
    assert!(run(d, &export).status.success());
    assert_one_line_error(&run(d, &export), &["ball.csv", "exists", "--force"]);
    assert!(run(d, &[&export[..], &["--force"]].concat()).status.success());
}

#[test]
fn calibrate_never_replaces_silently() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    crate::context::train_tiny(d, "toy:inner", "pairs.mcap", "models/c", "5");
    let calibrate = ["calibrate", "--model", "models/c", "--env", "toy:inner", "--instance-seed", "2"];
    let calibrate = [&calibrate[..], &["--strategy", "random", "--transitions", "2"]].concat();
    holds_to_the_rule(
        d,
        &calibrate,
        "datasets/calib-toy-inner-random-i2.mcap",
        "datasets/calib-toy-inner-random-i2-2.mcap",
    );
}
