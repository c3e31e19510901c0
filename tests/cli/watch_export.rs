//! A tiny trained run's metrics read back: `export --input RUN` as a long CSV table, and `watch` over several
//! runs printing one status line each.

use std::path::Path;

use crate::common::*;

const TINY_PETS: &str = "hidden_layers = 1\nhidden_units = 8\nvalidate_every = 5\ncheckpoint_every = 10\n";

fn ok(dir: &Path, args: &[&str]) -> std::process::Output {
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    out
}

/// Two PETS runs on one dataset: `runs/a` (seed 1, 10 steps) and `other/a` (seed 2, 20 steps).
fn two_runs(d: &Path) {
    std::fs::write(d.join("tiny.toml"), TINY_PETS).unwrap();
    ok(d, &["collect", "--env", "pendulum", "--rollouts", "6", "--steps", "20", "-q", "--out", "roll.mcap"]);
    let train = ["train", "pets", "--data", "roll.mcap", "--config", "tiny.toml", "--ensemble", "2", "-q"];
    ok(d, &[&train[..], &["--steps", "10", "--seed", "1", "--out", "runs/a"]].concat());
    ok(d, &[&train[..], &["--steps", "20", "--seed", "2", "--out", "other/a"]].concat());
}

fn metric_rows(path: &Path) -> Vec<(u64, String, f64)> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    assert_eq!(reader.headers().unwrap().iter().collect::<Vec<_>>(), ["step", "metric", "value"]);
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            (r[0].parse().unwrap(), r[1].to_string(), r[2].parse().unwrap())
        })
        .collect()
}

#[test]
fn a_runs_metrics_export_as_one_long_table_and_several_runs_watch_as_status_lines() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_runs(d);

    let out = ok(d, &["export", "--input", "other/a"]);
    assert!(stdout_of(&out).contains("to other/a/metrics.csv"), "{}", stdout_of(&out));
    let rows = metric_rows(&d.join("other/a/metrics.csv"));
    let of = |name: &str| rows.iter().filter(|r| r.1 == name).map(|r| (r.0, r.2)).collect::<Vec<_>>();
    let train = of("train/loss");
    assert_eq!(train.iter().map(|r| r.0).collect::<Vec<_>>(), (1..=20).collect::<Vec<u64>>());
    assert_eq!(of("valid/loss").iter().map(|r| r.0).collect::<Vec<_>>(), vec![5, 10, 15, 20]);
    assert_eq!(rows.len(), train.len() + 4, "only the two metrics the run records: {rows:?}");
    // The values are the run's own, to the bit: the last training loss is the one metrics.jsonl holds.
    let jsonl = std::fs::read_to_string(d.join("other/a/metrics.jsonl")).unwrap();
    let last: serde_json::Value = jsonl
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .rfind(|v| v["name"] == "train/loss")
        .unwrap();
    assert_eq!(train.last().unwrap().1, last["value"].as_f64().unwrap());

    // A default name is never replaced; a named --out needs --force; a run exports as csv only.
    let again = ok(d, &["export", "--input", "other/a"]);
    assert!(stdout_of(&again).contains("other/a/metrics-"), "{}", stdout_of(&again));
    ok(d, &["export", "--input", "runs/a/metrics.jsonl", "--out", "a.csv"]);
    let refused = mbrl(d).args(["export", "--input", "runs/a", "--out", "a.csv"]).output().unwrap();
    assert_one_line_error(&refused, &["a.csv", "exists", "--force"]);
    ok(d, &["export", "--input", "runs/a", "--out", "a.csv", "--force"]);
    assert_eq!(metric_rows(&d.join("a.csv")).len(), 10 + 2);
    let npz = mbrl(d).args(["export", "--input", "runs/a", "--out", "a.npz"]).output().unwrap();
    assert_one_line_error(&npz, &["--format npz", "csv only", "runs/a"]);

    // A data file's default goes beside it, with the format's extension.
    ok(d, &["export", "--input", "roll.mcap"]);
    assert!(d.join("roll.csv").is_file());

    // Two directories named `a`: their legends keep the parent that tells them apart.
    let watch = ok(d, &["watch", "runs/a", "other/a"]);
    let lines: Vec<String> = stdout_of(&watch).lines().map(String::from).collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(lines[0].starts_with("runs/a: finished · train 10/10; train/loss "), "{lines:?}");
    assert!(lines[1].starts_with("other/a: finished · train 20/20; train/loss "), "{lines:?}");
    assert!(lines[1].contains("valid/loss") && lines[1].ends_with("at step 20"), "{lines:?}");
}

#[test]
fn watching_a_missing_run_among_several_names_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let out = mbrl(dir.path()).args(["watch", "empty", "models/none", "--no-tui"]).output().unwrap();
    assert_one_line_error(&out, &["empty", "metrics.jsonl"]);
}
