//! Bad input gets one clear error line, a non-zero exit, and no output file.

use crate::common::*;

#[test]
fn unknown_env_names_what_is_supported() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["collect", "--env", "cartpole", "--out", "x.mcap"]).output().unwrap();
    assert_one_line_error(&out, &["cartpole", "pendulum"]);
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn unknown_variant_names_the_variants() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["plan", "--env", "pendulum:wobbly", "--model", "true"]).output().unwrap();
    assert_one_line_error(&out, &["wobbly", "inverted", "quadrant"]);
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn non_finite_values_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["collect", "--env", "pendulum:mass=nan", "--out", "x.mcap"]).output().unwrap();
    assert_one_line_error(&out, &["mass=nan", "finite"]);
    // Finite masses far outside a pendulum's: the torque's effect (∝ 1/m) overflows, or nothing moves.
    for mass in ["1e300", "5e-324"] {
        let env = format!("pendulum:mass={mass}");
        let out = mbrl(dir.path()).args(["collect", "--env", &env, "--out", "x.mcap"]).output().unwrap();
        assert_one_line_error(&out, &[mass, "[0.001, 1000] kg"]);
    }
    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum", "--model", "true", "--noise", "colored", "--beta", "inf"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = stderr_of(&out);
    assert!(err.lines().next().unwrap().contains("'inf' is not finite"), "{err}");
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn unsupported_model_lists_the_supported_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["plan", "--env", "pendulum", "--model", "gp"]).output().unwrap();
    assert!(!out.status.success());
    let err = stderr_of(&out);
    let first = err.lines().next().unwrap();
    assert!(first.contains("'gp'") && first.contains("true") && first.contains("mbrl train"), "{err}");
}

#[test]
fn impossible_cem_settings_are_explained() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum", "--model", "true", "--candidates", "10", "--elites", "50"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["elites", "10"]);
    assert!(files_in(dir.path()).is_empty());
}

fn collected(dir: &std::path::Path) -> Vec<u8> {
    mbrl(dir)
        .args(["collect", "--env", "pendulum", "--rollouts", "2", "--steps", "10", "-q", "--out", "ok.mcap"])
        .assert()
        .success();
    std::fs::read(dir.join("ok.mcap")).unwrap()
}

#[test]
fn truncated_mcap_is_reported_without_partial_output() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = collected(dir.path());
    std::fs::write(dir.path().join("cut.mcap"), &bytes[..bytes.len() - 40]).unwrap();
    let out = mbrl(dir.path()).args(["eval", "dataset", "--input", "cut.mcap", "--out", "rep"]).output().unwrap();
    assert_one_line_error(&out, &["cut.mcap", "truncated or corrupt"]);
    assert!(!dir.path().join("rep").exists(), "no report for bad input");
}

#[test]
fn missing_and_non_mcap_files_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["eval", "dataset", "--input", "nope.mcap"]).output().unwrap();
    assert_one_line_error(&out, &["nope.mcap", "No such file"]);
    std::fs::write(dir.path().join("text.mcap"), "episode,return\n1,2\n").unwrap();
    let out = mbrl(dir.path()).args(["eval", "dataset", "--input", "text.mcap"]).output().unwrap();
    assert_one_line_error(&out, &["text.mcap", "MCAP"]);
}

#[test]
fn wrong_format_version_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    collected(dir.path());
    let mut data = mbrl::data::read_dataset(&dir.path().join("ok.mcap")).unwrap();
    data.meta.format_version = 99;
    mbrl::data::write_dataset(&dir.path().join("v99.mcap"), &data).unwrap();
    let out = mbrl(dir.path()).args(["eval", "dataset", "--input", "v99.mcap", "--out", "rep"]).output().unwrap();
    assert_one_line_error(&out, &["v99.mcap", "format version 99", "version 1"]);
    assert!(!dir.path().join("rep").exists());
}

#[test]
fn watch_of_a_missing_run_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["watch", "models/none", "--no-tui"]).output().unwrap();
    assert_one_line_error(&out, &["models/none", "metrics.jsonl"]);
}

/// Flags that ask for absurd amounts of memory are refused by name before any work starts (each of these
/// once aborted on an allocation or ran for minutes), and the limit can be raised.
#[test]
fn absurd_sizes_are_refused_before_work_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |args: &[&str]| {
        let started = std::time::Instant::now();
        let out = mbrl(d).args(args).args(["--no-tui", "-q"]).output().unwrap();
        assert!(started.elapsed() < std::time::Duration::from_secs(10), "{args:?} took {:?}", started.elapsed());
        out
    };
    let big = "1000000000";
    let plan = ["plan", "--env", "pendulum", "--model", "true", "--steps", "2"];
    for (extra, needle) in [
        (vec!["--candidates", big], "--candidates"),
        (vec!["--horizon", big], "--horizon"),
        (vec!["--iters", big, "--elites", "10"], "iterations"),
    ] {
        let args: Vec<&str> = plan.iter().copied().chain(extra).collect();
        assert_one_line_error(&run(&args), &[needle]);
    }
    assert_one_line_error(&run(&["plan", "--env", "pendulum", "--model", "true", "--steps", big]), &["--steps"]);
    assert_one_line_error(
        &run(&["collect", "--env", "ball", "--trajectories", "2", "--augment-rotations", big, "--out", "b.mcap"]),
        &["--augment-rotations", "--max-memory-gib"],
    );
    assert_one_line_error(
        &run(&["collect", "--env", "pendulum", "--rollouts", big, "--out", "r.mcap"]),
        &["--rollouts"],
    );
    assert_one_line_error(
        &run(&["eval", "pendulum-swingup", "--model", "true", "--episodes", big, "--out", "rep"]),
        &["--episodes"],
    );
    // The same work fits once the limit allows it.
    let out = run(&["plan", "--env", "pendulum", "--model", "true", "--steps", "2", "--candidates", "20000"]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    let out = run(&[
        "--max-memory-gib",
        "0.001",
        "plan",
        "--env",
        "pendulum",
        "--model",
        "true",
        "--steps",
        "2",
        "--candidates",
        "20000",
    ]);
    assert_one_line_error(&out, &["--max-memory-gib"]);
    assert!(files_in(d).iter().all(|f| !f.ends_with(".mcap") || f.contains("plan-")), "{:?}", files_in(d));
}

/// Output names are checked before any work: a directory, or an extension that names another format than
/// the command writes, is refused at once and nothing is written.
#[test]
fn outputs_named_for_another_format_or_a_directory_are_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("sub")).unwrap();
    let cases: [(&[&str], &[&str]); 4] = [
        (&["plan", "--env", "pendulum", "--model", "true", "--out", "p.csv"], &["p.csv", "MCAP", ".mcap", "export"]),
        (&["plan", "--env", "pendulum", "--model", "true", "--out", "sub"], &["sub", "directory"]),
        (&["collect", "--env", "pendulum", "--rollouts", "2", "--out", "c.npz"], &["c.npz", ".mcap"]),
        (&["filter", "--model", "thesis", "--input", "missing.csv", "--out", "f.mcap"], &["f.mcap", "CSV", ".csv"]),
    ];
    for (args, needles) in cases {
        let started = std::time::Instant::now();
        let out = mbrl(d).args(args).output().unwrap();
        assert_one_line_error(&out, needles);
        // Refused before the 150-step episode (seconds) would have run.
        assert!(started.elapsed().as_secs_f64() < 2.0, "{args:?} took {:?}", started.elapsed());
    }
    assert_eq!(files_in(d), Vec::<String>::new());
}

/// A negative value reaches the flag's own check instead of clap's "unexpected argument '-1'".
#[test]
fn negative_values_get_a_message_about_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = mbrl(d).args(["plan", "--env", "pendulum", "--model", "true", "--steps", "-3"]).output().unwrap();
    assert_one_line_error(&out, &["'-3'", "--steps", "≥ 0"]);
    let out = mbrl(d).args(["plan", "--env", "pendulum", "--model", "true", "--beta", "-1"]).output().unwrap();
    assert!(!stderr_of(&out).contains("unexpected argument"), "{}", stderr_of(&out));
    let out =
        mbrl(d).args(["train", "--method", "pets", "--data", "x.mcap", "--lr", "-1", "--out", "m"]).output().unwrap();
    let err = stderr_of(&out);
    assert!(!out.status.success() && !err.contains("unexpected argument"), "{err}");
}

#[test]
fn gym_ids_map_to_the_same_dynamics_or_name_the_mbrl_env() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = mbrl(d).args(["plan", "--env", "Pendulum-v1", "--model", "true"]).output().unwrap();
    assert_one_line_error(&out, &["Pendulum-v1", "Pendulum-v0", "--env pendulum"]);
    let out = mbrl(d).args(["collect", "--env", "MountainCarContinuous-v0", "--instances", "2"]).output().unwrap();
    assert_one_line_error(&out, &["MountainCarContinuous-v0", "--env mountaincar"]);
    mbrl(d)
        .args(["collect", "--env", "Pendulum-v0", "--rollouts", "1", "--steps", "3", "--out", "p.mcap", "-q"])
        .assert()
        .success();
    let data = mbrl::data::dataset::read_dataset(&d.join("p.mcap")).unwrap();
    assert_eq!(data.meta.env, "pendulum");
}

#[test]
fn tui_without_a_terminal_is_one_line_and_no_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum", "--model", "true", "--tui", "--out", "p.mcap"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["--tui", "terminal", "--no-tui"]);
    assert!(!stderr_of(&out).contains('\u{1b}') && out.stdout.is_empty(), "terminal codes written: {out:?}");
    assert!(files_in(dir.path()).is_empty());
}
