//! `mbrl list` and the names it shares with the parsers: every listed name is accepted where it is used,
//! typos are answered with the nearest name, and completion offers the names.

use crate::common::*;

fn listed(dir: &std::path::Path, what: &str) -> Vec<String> {
    let out = mbrl(dir).args(["list", what]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let text = stdout_of(&out);
    // The header, then one row per name until the blank line before the notes.
    text.lines().skip(1).take_while(|l| !l.is_empty()).map(|l| l.split("  ").next().unwrap().to_string()).collect()
}

#[test]
fn every_listed_env_and_method_is_accepted_by_its_parser() {
    let dir = tempfile::tempdir().unwrap();
    let envs = listed(dir.path(), "envs");
    assert_eq!(envs, mbrl::envs::ENV_NAMES);
    for name in &envs {
        mbrl::envs::parse_env(name).unwrap();
    }
    let methods = listed(dir.path(), "methods");
    assert!(methods.contains(&"pets".to_string()) && methods.contains(&"ball-ekf".to_string()), "{methods:?}");
    for method in &methods {
        let out = mbrl(dir.path()).args(["train", method, "--help"]).output().unwrap();
        assert!(out.status.success(), "`mbrl train {method}` is not accepted: {}", stderr_of(&out));
    }
    for name in listed(dir.path(), "embodiments") {
        mbrl::envs::parse_env(&format!("tileswap:{name}")).unwrap();
    }
}

#[test]
fn presets_show_sizes_and_a_cost_from_the_preset() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["list", "presets"]).output().unwrap();
    let text = stdout_of(&out);
    let pets_small = text.lines().find(|l| l.starts_with("pets") && l.contains("small")).unwrap();
    for cell in ["3×64", "2000", "256", "2.56M transitions", "MEASURED (2 cores)"] {
        assert!(pets_small.contains(cell) || text.contains(cell), "{cell} missing: {pets_small}");
    }
    let bad = mbrl(dir.path()).args(["list", "presest"]).output().unwrap();
    assert_one_line_error(&bad, &["'presest'", "presets"]);
}

#[test]
fn mistyped_names_get_the_nearest_one_and_the_full_list() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["collect", "--env", "pendlum", "--rollouts", "1"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert_one_line_error(&out, &["unknown env 'pendlum' (did you mean 'pendulum'?)", "supported: pendulum"]);
    let out = mbrl(dir.path()).args(["collect", "--env", "tileswap:cursr", "--rollouts", "1"]).output().unwrap();
    assert_one_line_error(&out, &["did you mean 'tileswap:cursor'?"]);
    let out = mbrl(dir.path())
        .args(["solve-board", "--game", "lightsot", "--random-depth", "2", "--model", "true"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["unknown board game 'lightsot' (did you mean 'lightsout'?)", "tileswap"]);
    let out = mbrl(dir.path()).args(["train", "seads", "--env", "lightsout:cursr"]).output().unwrap();
    assert_one_line_error(&out, &["did you mean 'lightsout:cursor'?"]);
}

#[test]
fn completion_offers_env_names_and_help_stays_short() {
    let dir = tempfile::tempdir().unwrap();
    let bash = stdout_of(&mbrl(dir.path()).args(["completions", "bash"]).output().unwrap());
    assert!(bash.contains("pendulum:quadrant") && bash.contains("tileswap:reacher"), "no env names in bash completion");
    let help = stdout_of(&mbrl(dir.path()).args(["collect", "--help"]).output().unwrap());
    assert!(!help.contains("possible values: pendulum"), "collect --help lists every env name again:\n{help}");
}
