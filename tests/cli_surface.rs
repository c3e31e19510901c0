//! The command-line surface: help with examples on every subcommand, and committed completions that
//! match the current flags.

mod common;

use common::*;

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
    &["calibrate"],
    &["solve-board"],
    &["filter"],
    &["train"],
    &["predict"],
    &["watch"],
    &["completions"],
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
