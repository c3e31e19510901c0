//! Helpers shared by the end-to-end tests: run the real binary in a scratch directory.

#![allow(dead_code)]

use std::path::Path;

use assert_cmd::Command;

pub fn mbrl(dir: &Path) -> Command {
    let mut cmd = Command::new(assert_cmd::cargo::cargo_bin!("mbrl"));
    cmd.current_dir(dir).env("NO_COLOR", "1");
    cmd
}

pub fn stderr_of(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

pub fn stdout_of(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Files in `dir` (recursively), for checking that a failed command left nothing behind.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                out.extend(files_in(&path));
            } else {
                out.push(path.display().to_string());
            }
        }
    }
    out.sort();
    out
}

/// The error output is one line starting with `error:`.
pub fn assert_one_line_error(output: &std::process::Output, needles: &[&str]) {
    assert!(!output.status.success(), "command should fail");
    let err = stderr_of(output);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got: {err}");
    assert!(lines[0].starts_with("error:"), "{err}");
    for needle in needles {
        assert!(lines[0].contains(needle), "error should mention '{needle}': {err}");
    }
}
