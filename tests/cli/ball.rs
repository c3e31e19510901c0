//! End to end: simulated ball shots, filtering and prediction from the command line, bad recordings.

use crate::common::*;
use mbrl::data::ball_io::read_ball_dataset;

#[test]
fn collect_filter_predict_pipeline() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["collect", "--env", "ball", "--trajectories", "6", "--augment-rotations", "2", "--out", "b.mcap", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let data = read_ball_dataset(&dir.path().join("b.mcap")).unwrap();
    assert_eq!(data.recordings.len(), 18, "6 shots + 2 rotated copies each");
    assert!(data.recordings.iter().all(|r| r.info.side_info.is_some() && r.truth.is_some()));
    assert_eq!(data.recordings[6].info.rotated_from.map(|r| r.0), Some(0));

    let out = mbrl(dir.path())
        .args(["filter", "--model", "thesis", "--input", "b.mcap", "--mcap", "f.mcap", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let csv = std::fs::read_to_string(dir.path().join("filtered.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.starts_with("trajectory,frame,t,mx,my,mz,px,py,pz") && header.contains("std_a_m"), "{header}");
    assert!(dir.path().join("f.mcap").is_file());

    let out = mbrl(dir.path())
        .args(["predict", "--model", "thesis", "--input", "b.mcap", "--horizon", "1s", "--plane-y", "0.5", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let text = stdout_of(&out);
    let errors: Vec<f64> = text
        .lines()
        .filter_map(|l| l.split("error ").nth(1))
        .filter_map(|rest| rest.split(" cm").next()?.parse().ok())
        .collect();
    assert_eq!(errors.len(), 18, "{text}");
    let median = {
        let mut e = errors.clone();
        e.sort_by(f64::total_cmp);
        e[e.len() / 2]
    };
    assert!(median < 25.0, "median 1 s prediction error {median} cm with the thesis parameters");
    assert!(text.contains("lands at") && text.contains("crosses y = 0.500"), "{text}");
}

#[test]
fn csv_recordings_are_filtered_and_bad_ones_rejected() {
    let dir = tempfile::tempdir().unwrap();
    // A falling ball sampled at 180 Hz with one lost frame; estimates start at the second measurement.
    let text = falling_ball_csv();
    std::fs::write(dir.path().join("ok.csv"), &text).unwrap();
    let out = mbrl(dir.path()).args(["filter", "--model", "thesis", "--input", "ok.csv", "-q"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("trajectory 0: 39 frames filtered"), "{}", stdout_of(&out));

    let bad = [
        ("nan.csv", "frame,x,y,z\n0,0,0,0\n1,nan,0,0\n2,0,0,0\n", "row 3: x is NaN"),
        ("order.csv", "frame,x,y,z\n0,0,0,0\n2,0,0,0\n1,0,0,0\n", "row 4: frame 1 does not follow"),
        ("one.csv", "frame,x,y,z\n0,0,0,0\n1,,,\n", "1 measured positions"),
        ("cols.csv", "frame,x,y,z\n0,0,0,0\n1,0,0\n", "row 3: 3 columns, expected 4"),
    ];
    for (name, content, needle) in bad {
        std::fs::write(dir.path().join(name), content).unwrap();
        let out =
            mbrl(dir.path()).args(["filter", "--model", "thesis", "--input", name, "--out", "x.csv"]).output().unwrap();
        assert_one_line_error(&out, &[name, needle]);
        assert!(!dir.path().join("x.csv").exists());
    }
    let out = mbrl(dir.path())
        .args(["predict", "--model", "thesis", "--input", "ok.csv", "--horizon", "soon"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["--horizon 'soon'", "1s"]);
    let out = mbrl(dir.path()).args(["filter", "--model", "nowhere", "--input", "ok.csv"]).output().unwrap();
    assert_one_line_error(&out, &["nowhere", "thesis"]);
    let out = mbrl(dir.path())
        .args(["collect", "--env", "ball", "--trajectories", "2", "--orientation", "sideways"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["sideways", "unseen-5"]);
}

#[test]
fn eval_ball_compares_models_and_the_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args([
            "eval",
            "ball",
            "--model",
            "thesis",
            "--model",
            "initial",
            "--train-shots",
            "25",
            "--augment-rotations",
            "3",
        ])
        .args(["--test-shots", "25", "--unseen-shots", "6", "--out", "rep", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    for file in ["report.md", "summary.csv", "errors.csv", "error_vs_horizon.png", "trajectories.png", "config.json"] {
        assert!(dir.path().join("rep").join(file).is_file(), "missing {file}");
    }
    let summary = std::fs::read_to_string(dir.path().join("rep/summary.csv")).unwrap();
    let median_column = summary.lines().next().unwrap().split(',').position(|c| c == "median_m").unwrap();
    let median = |method: &str, group: &str| -> f64 {
        summary
            .lines()
            .find(|l| l.starts_with(&format!("{method},{group},1.000,")))
            .and_then(|l| l.split(',').nth(median_column))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no 1 s row for {method}/{group}:\n{summary}"))
    };
    // The generating parameters (the thesis' Table C.1, reported as the oracle they are on simulated shots)
    // predict far better than the untrained initial ones.
    let oracle = mbrl::models::ball::checkpoint::ORACLE_NAME;
    for group in ["default", "unseen"] {
        assert!(median(oracle, group) < 0.5 * median("initial", group), "{summary}");
    }
    let report = std::fs::read_to_string(dir.path().join("rep/report.md")).unwrap();
    assert!(report.contains(&format!("Impact matrix C of `{oracle}`")) && report.contains("-0.92"), "{report}");
    assert!(report.contains("not a competitor"), "{report}");
}

#[test]
fn trained_checkpoints_are_usable_models() {
    let dir = tempfile::tempdir().unwrap();
    mbrl(dir.path())
        .args(["collect", "--env", "ball", "--trajectories", "8", "--out", "t.mcap", "-q"])
        .assert()
        .success();
    let out = mbrl(dir.path())
        .args([
            "train", "--method", "ball-ekf", "--data", "t.mcap", "--out", "models/b", "--steps", "15", "--batch", "16",
            "-q",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("learned C"), "{}", stdout_of(&out));
    for file in ["params.json", "config.json", "metrics.jsonl", "losses.csv", "loss.png"] {
        assert!(dir.path().join("models/b").join(file).is_file(), "missing {file}");
    }
    let losses = std::fs::read_to_string(dir.path().join("models/b/losses.csv")).unwrap();
    assert_eq!(losses.lines().count(), 16, "header + one loss per step");
    let out = mbrl(dir.path()).args(["predict", "--model", "models/b", "--input", "t.mcap", "-q"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let out =
        mbrl(dir.path()).args(["train", "--method", "ball-ekf", "--data", "t.mcap", "--lr", "nan"]).output().unwrap();
    assert!(!out.status.success());
}

#[cfg(not(feature = "hdf5"))]
#[test]
fn hdf5_input_without_the_feature_says_how_to_get_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("release.hdf5"), "x").unwrap();
    let out = mbrl(dir.path()).args(["filter", "--model", "thesis", "--input", "release.hdf5"]).output().unwrap();
    assert_one_line_error(&out, &["release.hdf5", "--features hdf5", "libhdf5-dev"]);
}

#[test]
fn ball_training_resumes_to_the_same_bytes_and_stopped_runs_are_not_models() {
    use mbrl::models::ball::learn::job::{BallEkf, CHECKPOINT_EVERY};
    use mbrl::models::ball::learn::TrainSettings;
    use mbrl::train::job::start;
    let dir = tempfile::tempdir().unwrap();
    mbrl(dir.path())
        .args(["collect", "--env", "ball", "--trajectories", "6", "--out", "t.mcap", "-q"])
        .assert()
        .success();
    let request = mbrl::train::Request::<BallEkf> {
        env: None,
        data: vec![dir.path().join("t.mcap")],
        seed: 3,
        config: TrainSettings { steps: CHECKPOINT_EVERY + 20, batch_size: 8, seed: 3, ..TrainSettings::default() },
        variant: (),
        provenance: mbrl::run::dir::Provenance::new("mbrl train …".into(), 3, 1),
    };
    start(&dir.path().join("whole"), &request, &mbrl::run::NullMonitor).unwrap();
    let stop = StopAfter::new(CHECKPOINT_EVERY + 10);
    assert!(start(&dir.path().join("stopped"), &request, &stop).is_err_and(|e| e.is_cancelled()));
    let out = mbrl(dir.path()).args(["predict", "--model", "stopped", "--input", "t.mcap", "-q"]).output().unwrap();
    assert!(!out.status.success() && stderr_of(&out).contains("--resume"), "{}", stderr_of(&out));
    // The filter's validation schedule hangs on the total, so a run cannot be lengthened.
    let out = mbrl(dir.path()).args(["train", "--resume", "stopped", "--steps", "500", "-q"]).output().unwrap();
    assert_one_line_error(&out, &["stopped", "--steps with --resume extends", "pets and dlgpd"]);
    let out = mbrl(dir.path()).args(["train", "--resume", "stopped", "-q"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    for file in
        ["checkpoint.json", "config.json", "params.json", "model.safetensors", "state.safetensors", "metrics.jsonl"]
    {
        let a = std::fs::read(dir.path().join("whole").join(file)).unwrap();
        let b = std::fs::read(dir.path().join("stopped").join(file)).unwrap();
        assert!(a == b, "{file} differs after resuming");
    }
    // A parameter file edited after training no longer matches the manifest.
    let params = dir.path().join("stopped/params.json");
    let mut text = std::fs::read_to_string(&params).unwrap();
    text.push(' ');
    std::fs::write(&params, text).unwrap();
    let out = mbrl(dir.path()).args(["predict", "--model", "stopped", "--input", "t.mcap", "-q"]).output().unwrap();
    assert!(stderr_of(&out).contains("params.json") && stderr_of(&out).contains("CRC-32"), "{}", stderr_of(&out));
}
