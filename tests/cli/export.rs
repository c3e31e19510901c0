//! `mbrl export` end to end: every data kind to CSV and .npz, read back with a Rust npy reader (and NumPy
//! where it is installed) and compared value for value with what mbrl's own readers see.

use std::fs::File;
use std::path::Path;

use crate::common::{assert_one_line_error, files_in, mbrl};
use ndarray::{ArrayD, Ix2};
use ndarray_npy::NpzReader;

fn npz(path: &Path) -> NpzReader<File> {
    NpzReader::new(File::open(path).unwrap()).unwrap()
}

fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().iter().map(String::from).collect();
    let rows = reader.records().map(|r| r.unwrap().iter().map(String::from).collect()).collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn rollouts_with_frames_export_to_npz_and_csv_with_the_same_values() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mbrl(d)
        .args(["collect", "--env", "pendulum", "--rollouts", "3", "--steps", "5", "--images"])
        .args(["--out", "p.mcap", "-q", "--no-tui"])
        .assert()
        .success();
    mbrl(d).args(["export", "--input", "p.mcap", "--out", "p.npz"]).assert().success();
    mbrl(d).args(["export", "--input", "p.mcap", "--out", "p.csv"]).assert().success();
    let data = mbrl::data::dataset::read_dataset(&d.join("p.mcap")).unwrap();

    let mut arrays = npz(&d.join("p.npz"));
    let state: ndarray::Array2<f64> = arrays.by_name("state").unwrap();
    let action: ndarray::Array2<f64> = arrays.by_name("action").unwrap();
    let rollout: ndarray::Array1<i64> = arrays.by_name("rollout").unwrap();
    let frames: ArrayD<u8> = arrays.by_name("frames").unwrap();
    assert_eq!(state.dim(), (15, 2));
    assert_eq!(action.dim(), (15, 1));
    assert_eq!(frames.shape(), &[18, 64, 64, 3]);
    for (i, step) in data.steps.iter().enumerate() {
        assert_eq!(state.row(i).to_vec(), step.state);
        assert_eq!(action.row(i).to_vec(), step.action);
        assert_eq!(rollout[i], step.rollout as i64);
    }
    let flat: Vec<u8> = data.frames.iter().flatten().copied().collect();
    assert_eq!(frames.iter().copied().collect::<Vec<u8>>(), flat);

    let (header, rows) = csv_rows(&d.join("p.csv"));
    assert_eq!(&header[..4], ["rollout", "t", "theta", "theta_dot"]);
    assert_eq!(rows.len(), 15);
    let (theta, reward) = (column(&header, "theta"), column(&header, "reward"));
    for (row, step) in rows.iter().zip(&data.steps) {
        // The CSV text reads back to the very same f64.
        assert_eq!(row[theta].parse::<f64>().unwrap(), step.state[0]);
        assert_eq!(row[reward].parse::<f64>().unwrap(), step.reward);
    }
}

#[test]
fn board_sets_export_their_fields_depths_and_splits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mbrl(d)
        .args(["collect", "--env", "lightsout", "--boards", "--max-depth", "2", "--out", "b.mcap", "-q", "--no-tui"])
        .assert()
        .success();
    mbrl(d).args(["export", "--input", "b.mcap", "--out", "b.npz"]).assert().success();
    mbrl(d).args(["export", "--input", "b.mcap", "--out", "b.csv"]).assert().success();
    let set = mbrl::data::boardset::read_board_set(&d.join("b.mcap")).unwrap();
    let mut arrays = npz(&d.join("b.npz"));
    let board: ndarray::Array2<i64> = arrays.by_name("board").unwrap();
    let depth: ndarray::Array1<i64> = arrays.by_name("depth").unwrap();
    let test_split: ndarray::Array1<bool> = arrays.by_name("test_split").unwrap();
    assert_eq!(board.dim(), (set.boards.len(), 25));
    for (i, record) in set.boards.iter().enumerate() {
        let text: Vec<String> = board.row(i).iter().map(i64::to_string).collect();
        assert_eq!(text.join(","), record.board);
        assert_eq!(depth[i], record.depth as i64);
        assert_eq!(test_split[i], record.split.as_str() == "test");
    }
    let (header, rows) = csv_rows(&d.join("b.csv"));
    assert_eq!(rows.len(), set.boards.len());
    assert_eq!(rows[0][column(&header, "board")], set.boards[0].board);
}

#[test]
fn ball_recordings_and_filter_estimates_export_with_missing_frames_as_nan() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mbrl(d)
        .args(["collect", "--env", "ball", "--trajectories", "2", "--out", "ball.mcap", "-q", "--no-tui"])
        .assert()
        .success();
    mbrl(d)
        .args([
            "filter",
            "--model",
            "thesis",
            "--input",
            "ball.mcap",
            "--out",
            "est.csv",
            "--mcap",
            "est.mcap",
            "-q",
            "--no-tui",
        ])
        .assert()
        .success();
    for stem in ["ball", "est"] {
        for ext in ["npz", "csv"] {
            mbrl(d)
                .args(["export", "--input", &format!("{stem}.mcap"), "--out", &format!("{stem}-x.{ext}")])
                .assert()
                .success();
        }
    }
    let data = mbrl::data::ball_io::read_ball_dataset(&d.join("ball.mcap")).unwrap();
    let mut arrays = npz(&d.join("ball-x.npz"));
    let position: ndarray::Array2<f64> = arrays.by_name("position").unwrap();
    let measured: ndarray::Array1<bool> = arrays.by_name("measured").unwrap();
    let positions: Vec<Option<[f64; 3]>> = data.recordings.iter().flat_map(|r| r.positions.clone()).collect();
    assert_eq!(position.nrows(), positions.len());
    for (i, p) in positions.iter().enumerate() {
        assert_eq!(measured[i], p.is_some());
        match p {
            Some(p) => assert_eq!(position.row(i).to_vec(), p.to_vec()),
            None => assert!(position.row(i).iter().all(|x| x.is_nan())),
        }
    }

    let mut arrays = npz(&d.join("est-x.npz"));
    let covariance: ArrayD<f64> = arrays.by_name("covariance").unwrap();
    let std: ndarray::Array2<f64> = arrays.by_name("std").unwrap();
    assert_eq!(&covariance.shape()[1..], &[11, 11]);
    let covariance = covariance.into_dimensionality::<ndarray::Ix3>().unwrap();
    for (i, row) in std.outer_iter().enumerate() {
        for k in 0..11 {
            assert_eq!(row[k], covariance[[i, k, k]].max(0.0).sqrt());
        }
    }
    // The exported table agrees with the filter's own CSV on the estimated positions.
    let (own_header, own) = csv_rows(&d.join("est.csv"));
    let (header, exported) = csv_rows(&d.join("est-x.csv"));
    assert_eq!(own.len(), exported.len());
    let (a, b) = (column(&own_header, "px"), column(&header, "px"));
    for (x, y) in own.iter().zip(&exported) {
        let (x, y): (f64, f64) = (x[a].parse().unwrap(), y[b].parse().unwrap());
        assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{x} vs {y}");
    }
    let _: ArrayD<f64> = npz(&d.join("est-x.npz")).by_name("mean").unwrap();
    let _: ndarray::Array<f64, Ix2> = npz(&d.join("ball-x.npz")).by_name("recording_side_info").unwrap();

    // The exported CSV goes back into the filter: both trajectories, the same estimates as from the MCAP.
    mbrl(d)
        .args(["filter", "--model", "thesis", "--input", "ball-x.csv", "--out", "est-from-csv.csv", "-q", "--no-tui"])
        .assert()
        .success();
    let (header, from_csv) = csv_rows(&d.join("est-from-csv.csv"));
    assert_eq!(from_csv.len(), own.len());
    let trajectory = column(&header, "trajectory");
    assert_eq!(from_csv.last().unwrap()[trajectory], "1");
    let (px, own_px) = (column(&header, "px"), column(&own_header, "px"));
    for (x, y) in own.iter().zip(&from_csv) {
        let (x, y): (f64, f64) = (x[own_px].parse().unwrap(), y[px].parse().unwrap());
        assert!((x - y).abs() <= 1e-9 * x.abs().max(1.0), "{x} vs {y}");
    }
}

/// NumPy itself opens the archives with the documented keys, shapes and dtypes, when it is installed.
#[test]
fn numpy_loads_the_archives() {
    let numpy = std::process::Command::new("python3").args(["-c", "import numpy"]).output();
    if !numpy.is_ok_and(|o| o.status.success()) {
        eprintln!("numpy not installed; skipped (the Rust npy reader checks the same files above)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mbrl(d)
        .args([
            "collect",
            "--env",
            "pendulum",
            "--rollouts",
            "2",
            "--steps",
            "4",
            "--images",
            "--out",
            "p.mcap",
            "-q",
            "--no-tui",
        ])
        .assert()
        .success();
    mbrl(d).args(["export", "--input", "p.mcap", "--out", "p.npz"]).assert().success();
    let script = "import numpy as np\n\
                  d = np.load('p.npz')\n\
                  print(sorted(d.files))\n\
                  print(d['state'].shape, d['state'].dtype, d['frames'].shape, d['frames'].dtype, d['rollout'].dtype)\n";
    let out = std::process::Command::new("python3").args(["-c", script]).current_dir(d).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("'frame_rollout', 'frame_t', 'frames', 'next_obs', 'next_state', 'obs'"), "{text}");
    assert!(text.contains("(8, 2) float64 (10, 64, 64, 3) uint8 int64"), "{text}");
}

#[test]
fn bad_outputs_and_inputs_are_one_line_errors_that_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mbrl(d)
        .args(["collect", "--env", "pendulum", "--rollouts", "1", "--steps", "3", "--out", "p.mcap", "-q", "--no-tui"])
        .assert()
        .success();
    std::fs::write(d.join("notes.txt"), "not mcap").unwrap();
    std::fs::create_dir(d.join("outdir")).unwrap();
    let before = files_in(d);
    let cases: [(&[&str], &[&str]); 5] = [
        (&["--input", "p.mcap", "--out", "p.mcap.out"], &["--out", ".csv or .npz"]),
        (&["--input", "p.mcap", "--out", "p.csv", "--format", "npz"], &["disagrees", "p.csv"]),
        (&["--input", "p.mcap", "--out", "x.npz", "--format", "parquet"], &["parquet", "csv, npz"]),
        (&["--input", "notes.txt", "--out", "x.npz"], &["notes.txt", "MCAP"]),
        (&["--input", "p.mcap", "--out", "outdir", "--format", "csv"], &["outdir", "directory"]),
    ];
    for (args, needles) in cases {
        let output = mbrl(d).arg("export").args(args).output().unwrap();
        assert_one_line_error(&output, needles);
    }
    assert_eq!(files_in(d), before);
}
