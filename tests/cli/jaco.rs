//! The Jaco arm: with the `mujoco` feature (`make mujoco`) it plays boards end to end; without it, naming it
//! gives one line saying how to build it.

use crate::common::*;

#[cfg(not(feature = "mujoco"))]
#[test]
fn without_mujoco_naming_jaco_says_how_to_build_it() {
    let dir = tempfile::tempdir().unwrap();
    let solve = mbrl(dir.path())
        .args(["solve-board", "--game", "lightsout", "--random-depth", "2", "--model", "true", "--embodiment", "jaco"])
        .output()
        .unwrap();
    assert_one_line_error(&solve, &["Jaco", "make mujoco"]);
    let collect =
        mbrl(dir.path()).args(["collect", "--env", "lightsout:jaco", "--episodes", "1", "-q"]).output().unwrap();
    assert_one_line_error(&collect, &["Jaco", "make mujoco"]);
    let eval = mbrl(dir.path())
        .args(["eval", "embodied", "--game", "lightsout", "--embodiment", "jaco", "--boards", "2", "-q"])
        .output()
        .unwrap();
    assert_one_line_error(&eval, &["Jaco", "make mujoco"]);
    let train = mbrl(dir.path()).args(["train", "seads", "--env", "tileswap:jaco", "-q"]).output().unwrap();
    assert_one_line_error(&train, &["Jaco", "make mujoco"]);
}

#[cfg(feature = "mujoco")]
#[test]
fn scripted_jaco_solves_a_depth_5_board() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["solve-board", "--game", "lightsout", "--random-depth", "5", "--model", "true", "--embodiment", "jaco"])
        .args(["-q", "--seed", "1"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("5 of 5 moves performed"), "{}", stdout_of(&out));
}

#[cfg(feature = "mujoco")]
#[test]
fn jaco_replays_target_velocities_from_a_given_state() {
    let dir = tempfile::tempdir().unwrap();
    // Joint 1 turns at 0.3 rad/s for 0.3 s, then everything holds still.
    let rows = ["0.3,0,0,0,0,0,0,0,0"; 3].join("\n") + "\n" + &["0,0,0,0,0,0,0,0,0"; 2].join("\n") + "\n";
    std::fs::write(dir.path().join("a.csv"), rows).unwrap();
    let start = "1.5,3.0,1.5,4.0,1.5,3.0,0.2,0.2,0.2,0,0,0,0,0,0,0,0,0";
    let out = mbrl(dir.path())
        .args([
            "collect",
            "--env",
            "lightsout:jaco",
            "--actions",
            "a.csv",
            "--init-state",
            start,
            "--out",
            "j.mcap",
            "-q",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let data = mbrl::data::read_dataset(&dir.path().join("j.mcap")).unwrap();
    assert_eq!(data.meta.env, "lightsout:jaco");
    assert_eq!(data.meta.state_names.len(), 18 + 25 + 1);
    assert_eq!(data.steps.len(), 5);
    assert_eq!(data.steps[0].state[0], 1.5);
    // The velocity servo (kv 500) tracks 0.3 rad/s closely: about 0.09 rad in three steps.
    let turned = data.steps[2].next_state[0] - 1.5;
    assert!((turned - 0.09).abs() < 0.01, "joint 1 turned {turned}");
    let bad = mbrl(dir.path())
        .args(["collect", "--env", "lightsout:jaco", "--actions", "a.csv", "--init-state", "1,2,3", "--out", "k.mcap"])
        .output()
        .unwrap();
    assert_one_line_error(&bad, &["--init-state", "18"]);
}
