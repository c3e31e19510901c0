//! Every protocol's report is drawn from its summary.json alone: `eval render DIR` rewrites report.md, the CSVs
//! and the PNGs byte for byte, `eval <protocol> --config DIR/config.json` reruns it to the same summary, and a
//! bad summary is a one-line error.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common::*;

fn run_ok(dir: &Path, args: &[&str]) -> String {
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    stdout_of(&out)
}

/// The files `render` writes: report.md, CSVs and PNGs (not the summary, config, metrics or datasets).
fn rendered(report: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(report)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| name == "report.md" || name.ends_with(".csv") || name.ends_with(".png"))
        .filter(|name| name != "reconstructions.png")
        .map(|name| (name.clone(), std::fs::read(report.join(&name)).unwrap()))
        .collect()
}

/// summary.json without what a rerun changes: the command line and wall-clock timings (SEADS' planning time).
fn summary_of(report: &Path) -> serde_json::Value {
    fn strip(value: &mut serde_json::Value) {
        match value {
            serde_json::Value::Object(map) => {
                map.remove("command_line");
                map.remove("mean_planning_seconds");
                map.values_mut().for_each(strip);
            }
            serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("summary.json")).unwrap()).unwrap();
    strip(&mut summary);
    summary
}

/// Runs `eval` (its last two arguments `--out DIR`), deletes the rendered files, renders them back from
/// summary.json and compares bytes and the printed lines; then reruns from config.json and compares summaries.
fn round_trip(d: &Path, eval: &[&str]) {
    let report = d.join(eval.last().unwrap());
    let printed = run_ok(d, eval);
    let before = rendered(&report);
    assert!(before.contains_key("report.md") && before.len() > 1, "{eval:?}: {:?}", before.keys());
    for name in before.keys() {
        std::fs::remove_file(report.join(name)).unwrap();
    }
    let again = run_ok(d, &["eval", "render", eval.last().unwrap()]);
    // A SEADS comparison printed each run's lines before its own; render prints the comparison's.
    assert!(printed.ends_with(&again), "{eval:?}: render printed {again:?}, the run {printed:?}");
    let after = rendered(&report);
    assert_eq!(before.keys().collect::<Vec<_>>(), after.keys().collect::<Vec<_>>(), "{eval:?}");
    for (name, bytes) in &before {
        assert!(after[name] == *bytes, "{eval:?}: {name} differs after render");
    }
    let config = format!("{}/config.json", eval.last().unwrap());
    run_ok(d, &["eval", eval[1], "--config", &config, "--out", "rerun"]);
    assert_eq!(summary_of(&d.join("rerun")), summary_of(&report), "{eval:?}: rerun from config.json");
    std::fs::remove_dir_all(d.join("rerun")).unwrap();
}

#[test]
fn swingup_dataset_embodied_and_ball_render_from_their_summaries() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    round_trip(
        d,
        &["eval", "pendulum-swingup", "--model", "true", "--episodes", "2", "--steps", "30"]
            .iter()
            .chain(&["--candidates", "40", "--elites", "4", "--horizon", "5", "--out", "swing"])
            .copied()
            .collect::<Vec<_>>(),
    );
    run_ok(d, &["collect", "--env", "pendulum", "--rollouts", "4", "--steps", "10", "-q", "--out", "d.mcap"]);
    round_trip(d, &["eval", "dataset", "--input", "d.mcap", "--out", "data"]);
    round_trip(
        d,
        &["eval", "embodied", "--game", "tileswap", "--embodiment", "cursor", "--max-depth", "2", "--boards", "3"]
            .iter()
            .chain(&["--out", "emb"])
            .copied()
            .collect::<Vec<_>>(),
    );
    round_trip(
        d,
        &["eval", "ball", "--model", "thesis", "--train-shots", "3", "--augment-rotations", "1", "--test-shots", "3"]
            .iter()
            .chain(&["--unseen-shots", "1", "--out", "ball"])
            .copied()
            .collect::<Vec<_>>(),
    );
}

#[test]
fn context_and_dlgpd_render_from_their_summaries() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("tiny.toml"),
        "embedding = 16\nhidden_units = 16\ntransition_features = 8\nchunk_states = 10\ncontext_max = 4\n\
         batch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n",
    )
    .unwrap();
    run_ok(d, &["collect", "--env", "toy:inner", "--instances", "12", "--steps", "20", "-q", "--out", "pairs.mcap"]);
    run_ok(d, &["train", "context", "--data", "pairs.mcap", "--config", "tiny.toml", "--steps", "20", "--out", "c"]);
    round_trip(
        d,
        &["eval", "context", "--model", "c", "--env", "toy:inner", "--contexts", "3", "--validation-rollouts", "2"]
            .iter()
            .chain(&["--validation-steps", "5", "--transitions", "1", "--candidates", "20", "--elites", "4"])
            .chain(&["--iters", "2", "--beta-samples", "3", "--out", "ctx"])
            .copied()
            .collect::<Vec<_>>(),
    );
    run_ok(d, &["collect", "--env", "pendulum", "--rollouts", "30", "--steps", "12", "-q", "--out", "train.mcap"]);
    run_ok(d, &["train", "dlgpd", "--data", "train.mcap", "--steps", "20", "--batch", "64", "--out", "dl"]);
    round_trip(
        d,
        &["eval", "dlgpd", "--model", "dl", "--env", "pendulum:inverted", "--evidence-rollouts", "2", "--runs", "1"]
            .iter()
            .chain(&["--steps", "30", "--candidates", "20", "--elites", "4", "--iters", "2", "--out", "dlgpd"])
            .copied()
            .collect::<Vec<_>>(),
    );
}

#[test]
fn tradyn_and_seads_render_from_their_summaries() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("tiny.toml"),
        "embedding = 16\nhidden_units = 16\ntransition_features = 8\nlatent_dim = 4\nchunk_states = 10\n\
         context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n",
    )
    .unwrap();
    run_ok(d, &["collect", "--env", "terrain", "--maps", "4", "--out", "maps", "-q"]);
    run_ok(
        d,
        &["collect", "--env", "unicycle", "--maps", "maps", "--split", "train", "--instances", "12", "--steps", "20"]
            .iter()
            .chain(&["-q", "--out", "uni.mcap"])
            .copied()
            .collect::<Vec<_>>(),
    );
    for (out, extra) in [("t", None), ("nt", Some("--no-terrain"))] {
        let mut args = vec!["train", "tradyn", "--data", "uni.mcap", "--config", "tiny.toml", "--steps", "10"];
        args.extend(["--out", out]);
        args.extend(extra);
        run_ok(d, &args);
    }
    round_trip(
        d,
        &["eval", "tradyn", "--model-terrain", "t", "--model-no-terrain", "nt", "--maps", "maps", "--tasks", "2"]
            .iter()
            .chain(&["--steps", "4", "--horizon", "3", "--candidates", "16", "--elites", "4", "--iters", "1"])
            .chain(&["--prediction-steps", "5", "--out", "tradyn"])
            .copied()
            .collect::<Vec<_>>(),
    );
    std::fs::write(
        d.join("seads.toml"),
        "episodes_per_epoch = 4\nsampled_episodes = 8\nepisode_memory = 8\nmodel_hidden = 8\nsac_hidden = [8]\n\
         sac_batch = 8\n",
    )
    .unwrap();
    for out in ["s1", "s2"] {
        run_ok(
            d,
            &["train", "seads", "--env", "tileswap:cursor", "--config", "seads.toml", "--env-steps", "100"]
                .iter()
                .chain(&["--out", out])
                .copied()
                .collect::<Vec<_>>(),
        );
    }
    let small = ["--max-depth", "1", "--boards", "2", "--coverage-boards", "2"];
    round_trip(d, &[&["eval", "seads", "--model", "s1"][..], &small, &["--out", "seads"]].concat());
    // A comparison: each run's report, and the comparison's own.
    let compare = [&["eval", "seads", "--model", "s1", "--model", "s2"][..], &small, &["--out", "cmp"]].concat();
    round_trip(d, &compare);
    for run in ["cmp/s1", "cmp/s2"] {
        assert!(d.join(run).join("summary.json").is_file(), "{run}");
        run_ok(d, &["eval", "render", run]);
    }
}

#[test]
fn boards_render_from_its_summary() {
    let dir = tempfile::tempdir().unwrap();
    round_trip(dir.path(), &["eval", "boards", "--out", "boards"]);
}

#[test]
fn bad_summaries_and_configs_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let report = d.join("r");
    std::fs::create_dir(&report).unwrap();
    let render = || mbrl(d).args(["eval", "render", "r"]).output().unwrap();
    assert_one_line_error(&render(), &["r/summary.json"]);
    let write = |text: &str| std::fs::write(report.join("summary.json"), text).unwrap();
    write("{ not json");
    assert_one_line_error(&render(), &["r/summary.json", "not JSON"]);
    write(r#"{"protocol": "juggling"}"#);
    assert_one_line_error(&render(), &["r/summary.json", "unknown protocol 'juggling'", "pendulum-swingup"]);
    write(r#"{"settings": {}}"#);
    assert_one_line_error(&render(), &["r/summary.json", "protocol"]);
    write("{\n  \"protocol\": \"boards\",\n  \"provenance\": {\"mbrl_version\": \"0\", \"command_line\": \"\", \"seed\": 0, \"threads\": 1},\n  \"rows\": [{\"game\": \"g\", \"depth\": 1, \"boards\": null}]\n}\n");
    assert_one_line_error(&render(), &["r/summary.json", "boards"]);
    // A number that must be finite given as NaN: the swing-up's dt needs none, but a CEM setting does.
    let swing = d.join("swing");
    run_ok(
        d,
        &["eval", "pendulum-swingup", "--model", "true", "--episodes", "1", "--steps", "25", "--out", "swing"]
            .iter()
            .chain(&["--candidates", "20", "--elites", "2", "--horizon", "3"])
            .copied()
            .collect::<Vec<_>>(),
    );
    let text = std::fs::read_to_string(swing.join("summary.json")).unwrap();
    let bad = text.replacen("\"horizon\": 3", "\"horizon\": \"NaN\"", 1);
    assert_ne!(bad, text);
    std::fs::write(swing.join("summary.json"), bad).unwrap();
    let out = mbrl(d).args(["eval", "render", "swing"]).output().unwrap();
    assert_one_line_error(&out, &["swing/summary.json", "horizon"]);
    // A config of one protocol given to another, and flags beside --config.
    let out = mbrl(d).args(["eval", "dataset", "--config", "swing/config.json"]).output().unwrap();
    assert_one_line_error(&out, &["swing/config.json", "pendulum-swingup"]);
    let out =
        mbrl(d).args(["eval", "pendulum-swingup", "--config", "swing/config.json", "--steps", "30"]).output().unwrap();
    assert_one_line_error(&out, &["--config", "--steps"]);
}
