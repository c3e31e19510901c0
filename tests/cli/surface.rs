//! The command-line surface: help with examples on every subcommand, and committed completions that
//! match the current flags.

use crate::common::*;

const SUBCOMMANDS: &[&[&str]] = &[
    &["collect"],
    &["plan"],
    &["eval"],
    &["eval", "quick"],
    &["eval", "dataset"],
    &["eval", "pendulum-swingup"],
    &["eval", "boards"],
    &["eval", "embodied"],
    &["eval", "ball"],
    &["eval", "context"],
    &["eval", "render"],
    &["calibrate"],
    &["solve-board"],
    &["filter"],
    &["train"],
    &["predict"],
    &["watch"],
    &["completions"],
    &["list"],
];

#[test]
fn every_subcommand_help_has_an_example() {
    let dir = tempfile::tempdir().unwrap();
    for sub in SUBCOMMANDS {
        let out = mbrl(dir.path()).args(*sub).arg("--help").output().unwrap();
        assert!(out.status.success());
        let help = stdout_of(&out);
        assert!(help.contains("Example"), "{sub:?} help lacks an example:\n{help}");
        assert!(help.contains("mbrl "), "{sub:?} example should show a command line");
        for global in ["--seed", "--threads", "--no-tui", "--quiet"] {
            assert!(help.contains(global), "{sub:?} help lacks global flag {global}");
        }
    }
}

#[test]
fn committed_completions_are_current() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for (shell, file) in [("bash", "mbrl.bash"), ("zsh", "_mbrl"), ("fish", "mbrl.fish")] {
        let out = mbrl(dir.path()).args(["completions", shell]).output().unwrap();
        assert!(out.status.success());
        let committed = std::fs::read(root.join("completions").join(file))
            .unwrap_or_else(|_| panic!("completions/{file} is missing; run `make completions`"));
        assert!(committed == out.stdout, "completions/{file} is stale; run `make completions`");
    }
}

#[test]
fn usage_errors_are_one_line_with_where_to_read_more() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["collect", "--bogus"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_one_line_error(&out, &["'--bogus'", "mbrl collect --help"]);
    let out = mbrl(dir.path()).args(["--threads", "100000", "collect", "--env", "pendulum"]).output().unwrap();
    assert_one_line_error(&out, &["--threads 100000", "at most"]);
}

#[test]
fn control_characters_from_inputs_are_escaped_in_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["collect", "--env", "pend\x1b[31mulum\nx", "--out", "x.mcap"]).output().unwrap();
    assert_one_line_error(&out, &["unknown env", "\\u{1b}"]);
    assert!(!stderr_of(&out).contains('\x1b'));
}

/// `mbrl … | head -1`: the reader goes away, the command ends quietly.
#[test]
fn a_closed_stdout_is_not_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin!("mbrl"))
        .current_dir(dir.path())
        .args(["completions", "zsh"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}: {}", out.status, stderr_of(&out));
    assert!(stderr_of(&out).is_empty(), "{}", stderr_of(&out));
}
