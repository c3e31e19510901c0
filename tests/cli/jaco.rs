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
    let replay = |state: &str, out: &str| {
        let args = ["collect", "--env", "lightsout:jaco", "--actions", "a.csv", "--init-state", state, "--out", out];
        mbrl(dir.path()).args(args).arg("-q").output().unwrap()
    };
    let out = replay(start, "j.mcap");
    assert!(out.status.success(), "{}", stderr_of(&out));
    let data = mbrl::data::read_dataset(&dir.path().join("j.mcap")).unwrap();
    assert_eq!(data.meta.env, "lightsout:jaco");
    assert_eq!(data.meta.state_names.len(), 18 + 25 + 1);
    assert_eq!(data.steps.len(), 5);
    assert_eq!(data.steps[0].state[0], 1.5);
    // The velocity servo (kv 500) tracks 0.3 rad/s closely: about 0.09 rad in three steps.
    let turned = data.steps[2].next_state[0] - 1.5;
    assert!((turned - 0.09).abs() < 0.01, "joint 1 turned {turned}");
    assert_one_line_error(&replay("1,2,3", "k.mcap"), &["--init-state", "18"]);
    // A joint that turns without limit still takes angles a double resolves, and no joint starts faster than
    // ten times its servo's speed.
    let spinning = "1.5,3.0,1.5,4.0,1.5,3.0,0.2,0.2,0.2,0,0,0,0,0,0,0,0,1e6";
    let far = "1e300,3.0,1.5,4.0,1.5,3.0,0.2,0.2,0.2,0,0,0,0,0,0,0,0,0";
    for (state, field) in [(spinning, "finger_3_velocity"), (far, "joint_1")] {
        assert_one_line_error(&replay(state, "k.mcap"), &["--init-state", field]);
    }
    assert!(!dir.path().join("k.mcap").exists());
}

#[cfg(feature = "mujoco")]
#[test]
fn seads_trains_on_the_jaco_and_its_skills_play_the_board() {
    let dir = tempfile::tempdir().unwrap();
    let train = mbrl(dir.path())
        .args(["--threads", "2", "train", "seads", "--env", "tileswap:jaco", "--env-steps", "1500", "--out", "m"])
        .args(["-q", "sac_hidden=[32,32]", "episode_memory=64", "sampled_episodes=32", "checkpoint_every=1000"])
        .output()
        .unwrap();
    assert!(train.status.success(), "{}", stderr_of(&train));
    assert!(stdout_of(&train).contains("trained SEADS on tileswap:jaco"), "{}", stdout_of(&train));
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("m/config.json")).unwrap()).unwrap();
    // The policy sees the authors' 42 proprioceptive values, the board's bits, the remaining time and the
    // skill's one-hot; it sets the 9 joints' target velocities.
    let field = |key: &str| config[key].as_u64().unwrap_or_else(|| panic!("config.json has {key}: {config}"));
    assert_eq!(field("policy_input"), 42 + field("board_bits") + 1 + 12);
    assert_eq!((field("action_dim"), field("step_limit")), (9, 50));
    let eval = mbrl(dir.path())
        .args(["eval", "seads", "--model", "m", "--coverage-boards", "3", "--boards", "1", "--max-depth", "1"])
        .args(["--out", "r", "-q"])
        .output()
        .unwrap();
    assert!(eval.status.success(), "{}", stderr_of(&eval));
    let skills = std::fs::read_to_string(dir.path().join("r/skills.csv")).unwrap();
    assert_eq!(skills.lines().count(), 1 + 12, "{skills}");
}
