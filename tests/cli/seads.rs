//! End to end: SEADS trained from the command line on tileswap:cursor with the small preset learns the game's
//! moves and solves test boards through its own forward model and skills; resume continues bit for bit; the
//! errors a user can run into.

use std::path::Path;

use crate::common::*;
use mbrl::envs::embodiments::Embodiment;
use mbrl::models::seads::{self, EmbodiedGame, Preset, SeadsConfig};
use mbrl::run::dir::Provenance;
use mbrl::train::job::start;
use mbrl::train::Request;

fn run_ok(dir: &Path, args: &[&str]) -> String {
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    stdout_of(&out)
}

fn run_err(dir: &Path, args: &[&str]) -> String {
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(!out.status.success(), "{args:?} should fail");
    stderr_of(&out)
}

/// The small-scale claim: at least 10 of 12 TileSwap moves learned and depth 1-3 test boards solved.
#[test]
fn small_preset_learns_tileswap_moves_and_solves_test_boards() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run_ok(d, &["train", "--method", "seads", "--env", "tileswap:cursor", "--preset", "small", "--out", "models/s"]);
    let out = run_ok(
        d,
        &[
            "eval",
            "seads",
            "--model",
            "models/s",
            "--max-depth",
            "3",
            "--boards",
            "10",
            "--coverage-boards",
            "40",
            "--out",
            "rep",
        ],
    );
    let covered: usize = out
        .split("cover ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no coverage line in {out}"));
    assert!(covered >= 10, "only {covered} of 12 moves learned:\n{out}");
    let csv = std::fs::read_to_string(d.join("rep/success.csv")).unwrap();
    for line in csv.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells[1], cells[2], "not every board of depth {} solved: {line}", cells[0]);
    }
    let solved = run_ok(d, &["solve-board", "--model", "models/s", "--board", "1,0,2,3,4,5,6,7,8"]);
    assert!(solved.contains("solved: yes"), "{solved}");
}

#[test]
fn resume_ends_with_the_bytes_of_an_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let env = EmbodiedGame::parse("lightsout:cursor").unwrap();
    let mut config = SeadsConfig::preset(Preset::Small, 25, Embodiment::Cursor);
    config = mbrl::train::config::apply_toml(
        &config,
        "episodes_per_epoch = 8\nsampled_episodes = 16\nepisode_memory = 32\nmodel_hidden = 16\n\
         sac_hidden = [16, 16]\nsac_batch = 16\nsac_updates = 2\nmodel_updates = 2\ncheckpoint_every = 4\n\
         env_steps = 400\n",
    )
    .unwrap();
    let request = Request::<seads::Seads> {
        env: Some(env.name()),
        data: Vec::new(),
        seed: 3,
        config: config.clone(),
        variant: (),
        provenance: Provenance::new("mbrl train …".into(), 3, 1),
    };
    let run_dir = |name: &str| dir.path().join(name);
    let whole = start(&run_dir("whole"), &request, &mbrl::run::NullMonitor).unwrap();
    assert!(whole.outcome.steps > 7, "too few epochs to test resuming: {}", whole.outcome.steps);
    // Stopped after epoch 6: the last checkpoint is epoch 4, so epochs 5 and 6 are redone after resuming.
    let stop = StopAfter::new(6);
    let err = start(&run_dir("stopped"), &request, &stop).err().unwrap();
    assert!(err.is_cancelled(), "{err}");
    let out = mbrl(dir.path()).args(["train", "--resume", "stopped", "--no-tui"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let (a, b) = (dir_bytes(&dir.path().join("whole")), dir_bytes(&dir.path().join("stopped")));
    assert_eq!(a.iter().map(|f| &f.0).collect::<Vec<_>>(), b.iter().map(|f| &f.0).collect::<Vec<_>>());
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{name} differs after resuming");
    }
}

#[test]
fn bad_input_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let err = run_err(d, &["train", "--method", "seads", "--env", "lightsout", "--out", "x"]);
    assert!(err.contains("lightsout:cursor") && err.trim().lines().count() == 1, "{err}");
    let err = run_err(d, &["train", "--method", "seads", "--env", "tileswap:cursor", "--data", "a.mcap", "--out", "x"]);
    assert!(err.contains("--data") && err.trim().lines().count() == 1, "{err}");
    let err = run_err(d, &["solve-board", "--model", "nowhere", "--random-depth", "2"]);
    assert!(err.contains("nowhere") && err.trim().lines().count() == 1, "{err}");
    // A checkpoint of another method.
    std::fs::write(d.join("tiny.toml"), "episodes_per_epoch = 4\nsampled_episodes = 8\nepisode_memory = 8\nmodel_hidden = 8\nsac_hidden = [8]\nsac_batch = 8\n").unwrap();
    run_ok(
        d,
        &[
            "train",
            "--method",
            "seads",
            "--env",
            "tileswap:cursor",
            "--config",
            "tiny.toml",
            "--env-steps",
            "100",
            "--out",
            "s",
        ],
    );
    let err = run_err(d, &["solve-board", "--model", "s", "--game", "lightsout", "--random-depth", "2"]);
    assert!(err.contains("differs from the checkpoint") && err.trim().lines().count() == 1, "{err}");
    let err = run_err(d, &["solve-board", "--model", "s", "--board", "0,1"]);
    assert!(err.contains("--board") && err.trim().lines().count() == 1, "{err}");
    // A stopped run is not a model.
    let manifest = d.join("s/checkpoint.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("\"complete\": true", "\"complete\": false")).unwrap();
    let err = run_err(d, &["solve-board", "--model", "s", "--random-depth", "1"]);
    assert!(err.contains("--resume") && err.trim().lines().count() == 1, "{err}");
    let eval = ["eval", "seads", "--model", "s", "--max-depth", "1", "--boards", "1", "--coverage-boards", "1"];
    let err = run_err(d, &[&eval[..], &["--out", "partial-report"]].concat());
    assert!(err.contains("--resume") && err.trim().lines().count() == 1, "{err}");
    assert!(!d.join("partial-report").exists());
    // ...unless the user asks to look at it while it trains: then every output says how far it got.
    let out = mbrl(d)
        .args(["solve-board", "--model", "s", "--board", "0,1,2,3,4,5,6,7,8", "--allow-incomplete", "--no-tui"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("warning: s: "), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("(training still in progress)"), "{}", stderr_of(&out));
    run_ok(d, &[&eval[..], &["--out", "partial-report", "--allow-incomplete"]].concat());
    let report = std::fs::read_to_string(d.join("partial-report/report.md")).unwrap();
    assert!(report.contains("(training still in progress)"), "{report}");
    let err = run_err(
        d,
        &["solve-board", "--model", "true", "--game", "tileswap", "--random-depth", "1", "--allow-incomplete"],
    );
    assert!(err.contains("--allow-incomplete") && err.trim().lines().count() == 1, "{err}");
    std::fs::write(&manifest, text).unwrap();
    run_ok(d, &[&eval[..], &["--out", "report"]].concat());
    let report = std::fs::read_to_string(d.join("report/report.md")).unwrap();
    assert!(report.contains("Model `s`, trained ") && !report.contains("in progress"), "{report}");
    let err = run_err(d, &["plan", "--env", "pendulum", "--model", "s"]);
    assert!(err.trim().lines().count() == 1, "{err}");
}

#[test]
fn ablation_runs_are_compared_with_mann_whitney() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("tiny.toml"),
        "episodes_per_epoch = 4\nsampled_episodes = 8\nepisode_memory = 8\nmodel_hidden = 8\nsac_hidden = [8]\nsac_batch = 8\n",
    )
    .unwrap();
    let mut models = Vec::new();
    for (name, seed, extra) in [
        ("full-1", "1", None),
        ("full-2", "2", None),
        ("nonov-1", "1", Some("--no-novelty")),
        ("nonov-2", "2", Some("--no-novelty")),
    ] {
        let mut args = vec![
            "--seed",
            seed,
            "train",
            "--method",
            "seads",
            "--env",
            "tileswap:cursor",
            "--config",
            "tiny.toml",
            "--env-steps",
            "150",
            "--out",
            name,
        ];
        args.extend(extra);
        run_ok(d, &args);
        models.extend(["--model", name]);
    }
    let mut args = vec!["eval", "seads", "--max-depth", "1", "--boards", "2", "--coverage-boards", "2", "--out", "cmp"];
    args.extend(models);
    let out = run_ok(d, &args);
    assert!(out.contains("full > no-novelty on success_rate"), "{out}");
    let tests = std::fs::read_to_string(d.join("cmp/tests.csv")).unwrap();
    assert_eq!(tests.lines().count(), 3, "{tests}");
    assert!(tests.lines().nth(1).unwrap().starts_with("full,no-novelty,success_rate,"), "{tests}");
    for name in ["full-1", "nonov-2"] {
        assert!(d.join("cmp").join(name).join("report.md").exists());
    }
    let runs = std::fs::read_to_string(d.join("cmp/runs.csv")).unwrap();
    assert!(runs.contains("nonov-1,no-novelty,1,"), "{runs}");
}
