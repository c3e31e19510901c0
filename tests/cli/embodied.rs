//! `mbrl collect` on board games played by a manipulator (lightsout:cursor, tileswap:reacher, …): replays
//! of given actions, random skill episodes, and the errors bad input gives.

use std::path::Path;

use crate::common::*;
use mbrl::data::{read_dataset, Rollout};

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn collect(dir: &Path, args: &[&str]) -> std::process::Output {
    mbrl(dir).arg("collect").args(args).arg("-q").output().unwrap()
}

fn succeed(dir: &Path, args: &[&str]) {
    let out = collect(dir, args);
    assert!(out.status.success(), "{}", stderr_of(&out));
}

/// Indices of the lit LightsOut fields in a state (cursor x, y, then 25 board bits).
fn lit(state: &[f64]) -> Vec<usize> {
    (0..25).filter(|&i| state[2 + i] == 1.0).collect()
}

#[test]
fn a_scripted_cursor_push_writes_the_expected_board_bits() {
    let dir = tempfile::tempdir().unwrap();
    // From (0.1, 0.9) up and right to (0.3, 0.7) without pushing, then on to (0.4, 0.6), which lies on the
    // edges of fields: digitize(right=True) puts it in row 2, column 1 (field 11); push there.
    write(dir.path(), "a.csv", "dx,dy,push\n0.2,-0.2,-1\n0.1,-0.1,0.9\n0,0,-1\n");
    succeed(
        dir.path(),
        &["--env", "lightsout:cursor", "--actions", "a.csv", "--init-state", "0.1,0.9", "--out", "r.mcap"],
    );
    let data = read_dataset(&dir.path().join("r.mcap")).unwrap();
    assert_eq!(data.meta.env, "lightsout:cursor");
    assert_eq!(data.meta.state_names[..2], ["cursor_x", "cursor_y"]);
    assert_eq!(data.meta.state_names.last().unwrap(), "remaining_time");
    let s = &data.steps;
    assert_eq!(s.len(), 3);
    assert_eq!(s[0].state[..2], [0.1, 0.9]);
    assert!(lit(&s[0].next_state).is_empty(), "no push yet: still the solved board");
    assert_eq!(s[0].next_state[27], 0.9, "one of ten skill steps used");
    assert!((s[1].next_state[0] - 0.4).abs() < 1e-12 && (s[1].next_state[1] - 0.6).abs() < 1e-12);
    assert_eq!(lit(&s[1].next_state), vec![6, 10, 11, 12, 16], "field 11 and its neighbours");
    // The push ended the first skill episode; the idle step is the next one.
    assert_eq!((s[1].rollout, s[2].rollout, s[2].t), (0, 1, 0));
    assert_eq!(s[1].next_state[27], 0.8, "the pushing step records the time left (the authors' time-limit wrapper)");
    assert_eq!(s[2].state[27], 1.0, "the next skill starts with the full time");
    assert_eq!(data.meta.instances.len(), 2);
    assert_eq!(data.meta.instances[0]["embodiment"], "cursor");
}

#[test]
fn replays_start_from_the_given_board_and_run_every_embodiment() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "c.csv", "0,0,-1\n");
    let board = "1,0,2,3,4,5,6,7,8";
    succeed(dir.path(), &["--env", "tileswap:cursor", "--actions", "c.csv", "--board", board, "--out", "t.mcap"]);
    let data = read_dataset(&dir.path().join("t.mcap")).unwrap();
    assert_eq!(data.meta.instances[0]["start_board"], board);
    assert_eq!(data.steps[0].state[2 + 1], 1.0, "field 0 holds chip 1");
    write(dir.path(), "r.csv", "1,-1,-1\n0.5,0.5,1\n");
    for env in ["lightsout:reacher", "tileswap:reacher"] {
        let args = ["--env", env, "--actions", "r.csv", "--init-state", "0.3,-1.2,0,0.5", "--out", "r.mcap", "--force"];
        succeed(dir.path(), &args);
        let data = read_dataset(&dir.path().join("r.mcap")).unwrap();
        assert_eq!(data.steps[0].state[..4], [0.3, -1.2, 0.0, 0.5], "{env}");
        assert_eq!(data.meta.state_names[1], "wrist_angle");
    }
}

#[test]
fn random_episodes_have_valid_boundaries_and_follow_the_seed() {
    // The metadata records the command line, so both runs write to the same name in their own directory.
    let dirs = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
    let args = ["--env", "lightsout:cursor", "--episodes", "40", "--seed", "5", "--out", "e.mcap"];
    for dir in &dirs {
        succeed(dir.path(), &args);
    }
    let bytes = |dir: &tempfile::TempDir| std::fs::read(dir.path().join("e.mcap")).unwrap();
    assert_eq!(bytes(&dirs[0]), bytes(&dirs[1]), "same seed, same bytes");
    let data = read_dataset(&dirs[0].path().join("e.mcap")).unwrap();
    let episodes = Rollout::group(&data.steps).unwrap();
    assert_eq!(episodes.len(), 40);
    assert_eq!(data.meta.instances.len(), 40);
    for (k, (id, r)) in episodes.iter().enumerate() {
        assert_eq!(*id as usize, k);
        assert_eq!(r.states[0][27], 1.0, "episode {k} starts with the full skill time");
        let changed = lit(r.states.last().unwrap()) != lit(&r.states[0]);
        assert!(changed || r.len() == 10, "episode {k}: {} steps, no board change", r.len());
        assert!((1..=10).contains(&r.len()));
    }
}

#[test]
fn bad_input_gives_one_line_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "wide.csv", "0,0,0,0\n");
    write(dir.path(), "nan.csv", "0,0,-1\n0,NaN,1\n");
    write(dir.path(), "ok.csv", "0,0,-1\n");
    let cases: [(&[&str], &[&str]); 7] = [
        (&["--env", "lightsout:cursor", "--actions", "wide.csv"], &["wide.csv", "row 1 has 4 column(s); expected 3"]),
        (&["--env", "tileswap:reacher", "--actions", "nan.csv"], &["nan.csv", "row 2, column 2", "finite number"]),
        (
            &["--env", "lightsout:cursor", "--actions", "ok.csv", "--init-state", "0.5"],
            &["--init-state", "cursor_x,cursor_y"],
        ),
        (
            &["--env", "lightsout:cursor", "--actions", "ok.csv", "--init-state", "0.5,-0.1"],
            &["cursor_y = -0.1", "[0, 1]"],
        ),
        (&["--env", "tileswap:reacher", "--actions", "ok.csv", "--init-state", "0,7,0,0"], &["wrist_angle = 7", "2π"]),
        (
            &["--env", "tileswap:reacher", "--actions", "ok.csv", "--init-state", "0,0,0,-51"],
            &["wrist_velocity = -51", "[-50, 50] rad/s"],
        ),
        (&["--env", "tileswap:cursor", "--actions", "ok.csv", "--board", "0,1,2,3,4,5,6,7,7"], &["--board", "chip 7"]),
    ];
    for (args, needles) in cases {
        let mut all = args.to_vec();
        all.extend(["--out", "bad.mcap"]);
        assert_one_line_error(&collect(dir.path(), &all), needles);
    }
    assert_one_line_error(&collect(dir.path(), &["--env", "lightsout:cursor", "--out", "bad.mcap"]), &["--episodes"]);
    let files = files_in(dir.path());
    assert!(files.iter().all(|f| !f.contains("bad")), "{files:?}");
}
