//! End to end: collecting, planning and evaluating the pendulum from the command line.

use crate::common::*;
use mbrl::data::{read_dataset, Rollout};

#[test]
fn collect_writes_a_readable_reproducible_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["collect", "--env", "pendulum:heavy", "--rollouts", "4", "--steps", "30", "--seed", "7", "--out"];
    let out = mbrl(dir.path()).args(args).arg("a.mcap").arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("120 transitions"), "{}", stdout_of(&out));
    mbrl(dir.path()).args(args).arg("b.mcap").arg("-q").assert().success();
    let a = read_dataset(&dir.path().join("a.mcap")).unwrap();
    let b = read_dataset(&dir.path().join("b.mcap")).unwrap();
    assert_eq!(a.steps, b.steps, "same seed, same transitions");
    assert_eq!(a.meta.env, "pendulum:heavy");
    assert_eq!(a.meta.seed, 7);
    assert_eq!(a.meta.instances[0]["mass"], 1.5);
    assert_eq!(Rollout::group(&a.steps).unwrap().len(), 4);
    // Thesis collection distribution: θ ∈ [−π, π], θ̇ ∈ [−8, 8] at the start, actions in [−2, 2].
    for s in a.steps.iter().filter(|s| s.t == 0) {
        assert!(s.state[0].abs() <= std::f64::consts::PI && s.state[1].abs() <= 8.0);
    }
    assert!(a.steps.iter().all(|s| s.action[0].abs() <= 2.0));
}

#[test]
fn same_command_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let plan = || {
        mbrl(dir.path())
            .args(["plan", "--env", "pendulum", "--model", "true", "--candidates", "100", "--elites", "10"])
            .args(["--iters", "3", "--steps", "40", "--threads", "2", "-q", "--out", "p.mcap", "--force"])
            .assert()
            .success();
        std::fs::read(dir.path().join("p.mcap")).unwrap()
    };
    assert_eq!(plan(), plan());
}

#[test]
fn planned_rollout_does_not_depend_on_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    for threads in ["1", "2"] {
        mbrl(dir.path())
            .args(["plan", "--env", "pendulum", "--model", "true", "--candidates", "150", "--elites", "15"])
            .args(["--iters", "3", "--steps", "30", "-q", "--threads", threads, "--out"])
            .arg(format!("t{threads}.mcap"))
            .assert()
            .success();
    }
    let one = read_dataset(&dir.path().join("t1.mcap")).unwrap();
    let two = read_dataset(&dir.path().join("t2.mcap")).unwrap();
    assert_eq!(one.steps, two.steps);
}

#[test]
fn small_cem_swings_the_pendulum_up() {
    let dir = tempfile::tempdir().unwrap();
    for seed in ["0", "1", "2"] {
        let out = mbrl(dir.path())
            .args(["plan", "--env", "pendulum", "--model", "true", "--horizon", "20", "--candidates", "200"])
            .args(["--elites", "20", "--iters", "5", "--steps", "150", "-q", "--out", "swing.mcap", "--seed", seed])
            .arg("--force")
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr_of(&out));
        assert!(stdout_of(&out).contains("success: yes"), "seed {seed}: {}", stdout_of(&out));
        let data = read_dataset(&dir.path().join("swing.mcap")).unwrap();
        assert_eq!(data.steps.len(), 150);
        let start = &data.steps[0].state;
        assert!((start[0] - std::f64::consts::PI).abs() <= 0.05 && start[1].abs() <= 0.05, "hanging start");
    }
}

#[test]
fn colored_noise_planning_also_swings_up() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum", "--model", "true", "--candidates", "300", "--elites", "30"])
        .args(["--iters", "5", "--noise", "colored", "--beta", "0.5", "-q", "--out", "c.mcap"])
        .output()
        .unwrap();
    assert!(stdout_of(&out).contains("success: yes"), "{}{}", stdout_of(&out), stderr_of(&out));
}

#[test]
fn eval_swingup_writes_a_full_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["eval", "pendulum-swingup", "--model", "true", "--episodes", "3", "--candidates", "200"])
        .args(["--elites", "20", "--iters", "5", "--out", "rep", "--no-tui"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).starts_with("3/3 episodes succeeded"), "{}", stdout_of(&out));
    let rep = dir.path().join("rep");
    for file in
        ["report.md", "episodes.csv", "angle.png", "returns.png", "rollouts.mcap", "config.json", "metrics.jsonl"]
    {
        assert!(rep.join(file).is_file(), "missing {file}");
    }
    let csv = std::fs::read_to_string(rep.join("episodes.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "header + 3 episodes: {csv}");
    assert!(csv.lines().skip(1).all(|l| l.contains(",true,")), "{csv}");
    let metrics = std::fs::read_to_string(rep.join("metrics.jsonl")).unwrap();
    assert!(metrics.contains("\"kind\":\"layout\"") && metrics.lines().last().unwrap().contains("finished"));
    assert!(stderr_of(&out).contains("episodes: 3/3"), "progress lines go to stderr: {}", stderr_of(&out));
    // The watch summary reads the same metrics back.
    let watch = mbrl(dir.path()).args(["watch", "rep", "--no-tui"]).output().unwrap();
    assert!(stdout_of(&watch).contains("status: finished"), "{}", stdout_of(&watch));
    assert!(stdout_of(&watch).contains("episode/return"), "{}", stdout_of(&watch));
}

#[test]
fn eval_dataset_summarises_collected_data() {
    let dir = tempfile::tempdir().unwrap();
    mbrl(dir.path())
        .args(["collect", "--env", "pendulum", "--rollouts", "5", "--steps", "20", "-q", "--out", "d.mcap"])
        .assert()
        .success();
    let out = mbrl(dir.path()).args(["eval", "dataset", "--input", "d.mcap", "--out", "rep", "-q"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("5 rollouts, 100 transitions of pendulum"), "{}", stdout_of(&out));
    let report = std::fs::read_to_string(dir.path().join("rep/report.md")).unwrap();
    assert!(report.contains("| theta_dot |"), "{report}");
}
