//! `mbrl collect` end to end: replaying action files, instance-pair datasets for context models, and the
//! errors bad action files and start states give.

use std::path::Path;

use crate::common::*;
use mbrl::data::{instance_pairs, read_dataset, DatasetLayout};
use mbrl::envs::pendulum::{Pendulum, PendulumVariant};
use mbrl::envs::{instance_env, parse_env, Env};

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

#[test]
fn pendulum_replay_records_the_given_actions_and_the_simulator_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let actions = [0.5, -2.0, 3.5, 1.25, 0.0, -0.75];
    let csv: String = actions.iter().map(|a| format!("{a}\n")).collect();
    write(dir.path(), "actions.csv", &format!("torque\n{csv}"));
    succeed(
        dir.path(),
        &["--env", "pendulum:heavy", "--actions", "actions.csv", "--init-state", "-2.5,1", "--out", "r.mcap"],
    );

    let data = read_dataset(&dir.path().join("r.mcap")).unwrap();
    assert_eq!(data.meta.env, "pendulum:heavy");
    assert_eq!(data.meta.layout, DatasetLayout::Rollouts);
    let recorded: Vec<f64> = data.steps.iter().map(|s| s.action[0]).collect();
    assert_eq!(recorded, actions, "the file's actions as given; the env clips 3.5 when it steps");

    let mut env = Pendulum::new(PendulumVariant::Mass(1.5));
    env.set_state(&[-2.5, 1.0]);
    assert_eq!(data.steps[0].state, vec![-2.5, 1.0]);
    for step in &data.steps {
        assert_eq!(step.state, env.state());
        let next = env.step(&step.action);
        assert_eq!((step.next_state.clone(), step.reward), (env.state(), next.reward));
        assert_eq!(step.next_obs.as_ref(), Some(&next.obs));
    }
    assert_eq!(data.meta.instances, vec![env.params()]);
}

#[test]
fn toy_replay_noise_comes_from_the_seed_and_the_instance_from_the_instance_seed() {
    let run = |seed: &str| {
        let dir = tempfile::tempdir().unwrap();
        write(dir.path(), "a.csv", "0.5\n-1.5\n0.2\n2\n");
        let args = ["--env", "toy:inner", "--actions", "a.csv", "--init-state", "0,0", "--instance-seed", "7"];
        succeed(dir.path(), &[&args[..], &["--seed", seed, "--out", "t.mcap"]].concat());
        (std::fs::read(dir.path().join("t.mcap")).unwrap(), read_dataset(&dir.path().join("t.mcap")).unwrap())
    };
    let (bytes_a, a) = run("3");
    let (bytes_b, _) = run("3");
    assert_eq!(bytes_a, bytes_b, "same seed, same bytes");
    let (_, c) = run("4");
    assert_ne!(a.steps[0].next_state, c.steps[0].next_state, "another seed, other noise");
    assert_eq!(a.meta.instances, c.meta.instances, "the instance follows --instance-seed alone");

    let expected = instance_env(&parse_env("toy:inner").unwrap(), 7).unwrap().params();
    assert_eq!(a.meta.instances, vec![expected.clone()]);
    let alpha = expected["alpha"].as_f64().unwrap();
    // From rest the first step is the squashed push plus noise of std 0.01.
    let first = &a.steps[0].next_state;
    assert!((first[0] - alpha * 0.5).abs() < 0.05 && first[1].abs() < 0.05, "{first:?} for α = {alpha}");
    assert!(a.steps[0].obs.is_none(), "the toy's observation is its state: not stored twice");
}

#[test]
fn mountaincar_replay_starts_from_a_seeded_reset_state_without_init_state() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.csv", "u\n3\n3\n-3\n");
    succeed(dir.path(), &["--env", "mountaincar", "--actions", "a.csv", "--seed", "5", "--out", "m.mcap"]);
    let data = read_dataset(&dir.path().join("m.mcap")).unwrap();
    assert_eq!(data.steps.len(), 3);
    let [x, v] = [data.steps[0].state[0], data.steps[0].state[1]];
    assert!(x.abs() <= 0.8 && v.abs() <= 2.0, "reset distribution: {x}, {v}");
    assert!(data.meta.instances[0]["bumps"].as_array().is_some_and(|b| b.len() >= 4));
}

#[test]
fn instances_give_paired_rollouts_of_shared_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["collect", "--env", "toy:outer", "--instances", "4", "--steps", "12", "--no-tui", "--out", "p.mcap"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("8 rollouts (4 instance pairs)"), "{}", stdout_of(&out));
    assert!(stderr_of(&out).contains("collect instance pairs"), "progress goes through the monitor");

    let data = read_dataset(&dir.path().join("p.mcap")).unwrap();
    assert_eq!(data.meta.layout, DatasetLayout::InstancePairs);
    assert_eq!(data.meta.instances.len(), 8);
    let pairs = instance_pairs(&data).unwrap();
    assert_eq!(pairs.len(), 4);
    for (k, (a, b)) in pairs.iter().enumerate() {
        assert_eq!(data.meta.instances[2 * k], data.meta.instances[2 * k + 1]);
        assert_ne!(a.states[0], b.states[0]);
        assert!(a.actions.iter().chain(&b.actions).all(|u| u[0].abs() <= 2.0));
    }
    let alphas: Vec<&serde_json::Value> = data.meta.instances.iter().step_by(2).map(|p| &p["alpha"]).collect();
    assert!(alphas.windows(2).all(|w| w[0] != w[1]), "every instance its own α: {alphas:?}");
}

#[test]
fn instances_and_rollouts_exclude_each_other_and_actions_excludes_both() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.csv", "0\n");
    for args in [
        &["--env", "toy:inner", "--instances", "2", "--rollouts", "3"][..],
        &["--env", "toy:inner", "--actions", "a.csv", "--instances", "2"][..],
        &["--env", "toy:inner", "--actions", "a.csv", "--rollouts", "2"][..],
        &["--env", "toy:inner", "--init-state", "0,0"][..],
    ] {
        let out = collect(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr_of(&out));
    }
    assert_eq!(files_in(dir.path()).len(), 1, "nothing written");
}

/// Runs a replay that must fail with one error line mentioning `needles`, and leave no dataset behind.
fn rejected(files: &[(&str, &str)], args: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        write(dir.path(), name, text);
    }
    let out = collect(dir.path(), &[args, &["--out", "bad.mcap"]].concat());
    assert_one_line_error(&out, needles);
    assert!(!dir.path().join("bad.mcap").exists(), "no output for bad input");
}

#[test]
fn bad_action_files_name_file_row_and_column() {
    let pendulum = ["--env", "pendulum", "--actions", "a.csv"];
    rejected(&[("a.csv", "u\n0.5\n1,2\n")], &pendulum, &["a.csv", "row 3", "2 column(s)", "expected 1"]);
    rejected(&[("a.csv", "0.5\nNaN\n")], &pendulum, &["a.csv", "row 2, column 1 = NaN", "expected a finite number"]);
    rejected(&[("a.csv", "0.5\n1e400\n")], &pendulum, &["a.csv", "row 2, column 1 = inf", "finite number"]);
    // Finite but beyond what any dataset reader takes back: the replay would record it as given.
    rejected(&[("a.csv", "0.5\n1e300\n")], &pendulum, &["a.csv", "row 2, column 1 = 1e300", "[-1e9, 1e9]"]);
    rejected(&[("a.csv", "u\n0.5\nfast\n")], &pendulum, &["a.csv", "row 3, column 1", "'fast' is not a number"]);
    rejected(&[("a.csv", "")], &pendulum, &["a.csv", "no action rows"]);
    rejected(&[], &pendulum, &["a.csv"]);
}

#[test]
fn bad_init_states_are_explained() {
    let files = [("a.csv", "0.5\n")];
    rejected(
        &files,
        &["--env", "pendulum", "--actions", "a.csv", "--init-state", "1,2,3"],
        &["--init-state", "3 value(s)", "theta,theta_dot"],
    );
    rejected(
        &files,
        &["--env", "mountaincar", "--actions", "a.csv", "--init-state", "0.1,nan"],
        &["--init-state", "not finite", "x,x_dot"],
    );
    rejected(
        &files,
        &["--env", "toy:outer", "--actions", "a.csv", "--init-state", "0,zero"],
        &["'zero' is not a number"],
    );
    // Finite starts outside the env's bounds (its clipping, its walls), or beyond what a dataset holds.
    let pendulum = ["--env", "pendulum", "--actions", "a.csv", "--init-state"];
    rejected(&files, &[&pendulum[..], &["0,9"]].concat(), &["theta_dot = 9", "[-8, 8] rad/s"]);
    rejected(&files, &[&pendulum[..], &["1e300,0"]].concat(), &["theta = 1e300", "[-1000, 1000] rad"]);
    let car = ["--env", "mountaincar", "--actions", "a.csv", "--init-state"];
    rejected(&files, &[&car[..], &["1.5,0"]].concat(), &["x = 1.5", "[-1, 1] m"]);
    rejected(&files, &[&car[..], &["0,-11"]].concat(), &["x_dot = -11", "[-10, 10] m/s"]);
    let toy = ["--env", "toy:inner", "--actions", "a.csv", "--init-state", "-1e300,0"];
    rejected(&files, &toy, &["s1 = -1e300", "[-1e9, 1e9]"]);
}

#[test]
fn images_store_a_rendered_frame_of_every_state() {
    let dir = tempfile::tempdir().unwrap();
    succeed(
        dir.path(),
        &["--env", "pendulum:inverted", "--images", "--rollouts", "3", "--steps", "4", "--out", "i.mcap"],
    );
    let data = read_dataset(&dir.path().join("i.mcap")).unwrap();
    let info = data.meta.frames.clone().expect("frames declared in the metadata");
    assert_eq!((info.width, info.height), (64, 64));
    assert_eq!(data.frames.len(), 3 * 5, "one frame per state: 4 transitions + 1 per rollout");
    let mut renderer = mbrl::envs::pendulum::render::PendulumRenderer::new();
    assert_eq!(data.frames[0], renderer.frame(data.steps[0].state[0]));
    assert_eq!(data.frames[4], renderer.frame(data.steps[3].next_state[0]), "the last frame is the last next state");

    let out = collect(dir.path(), &["--env", "toy:inner", "--images", "--rollouts", "2", "--out", "t.mcap"]);
    assert_one_line_error(&out, &["--images", "toy:inner"]);
    let out = collect(dir.path(), &["--env", "pendulum", "--images", "--rollouts", "100000000", "--out", "b.mcap"]);
    assert_one_line_error(&out, &["--images", "GiB"]);
    assert!(!dir.path().join("t.mcap").exists() && !dir.path().join("b.mcap").exists());
}
