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

/// Stops a training run after `stop_after` steps, as quitting the live view does.
#[allow(dead_code)]
pub struct StopAfter {
    stop_after: u64,
    seen: std::sync::atomic::AtomicU64,
}

#[allow(dead_code)]
impl StopAfter {
    pub fn new(stop_after: u64) -> Self {
        StopAfter { stop_after, seen: 0.into() }
    }
}

impl mbrl::run::Monitor for StopAfter {
    fn emit(&self, event: &mbrl::run::Event) {
        // The training loss is logged once per step under every method; progress may count other units
        // (SEADS reports environment steps).
        if let mbrl::run::Event::Scalar { name, step, .. } = event {
            if name == "train/loss" {
                self.seen.store(*step, std::sync::atomic::Ordering::Relaxed);
            }
        }
    }

    fn is_cancelled(&self) -> bool {
        self.seen.load(std::sync::atomic::Ordering::Relaxed) >= self.stop_after
    }
}

/// Every file of a run directory but the loss table and plot, which only the command line draws, and the
/// lock file, which names the process that last wrote there.
#[allow(dead_code)]
pub fn dir_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n != "loss.png" && n != "losses.csv" && n != ".mbrl-lock")
        .collect();
    names.sort();
    names.into_iter().map(|n| (n.clone(), std::fs::read(dir.join(&n)).unwrap())).collect()
}

/// A run trained on to a larger total (`train --resume DIR --steps N`) against the run started with that total:
/// the same files with the same weights, optimizer state and config. Only the record of the extension differs:
/// the config's provenance lists the extending command, and the metrics log's progress records keep the total
/// they were written under (so the manifest's CRC of the config and length of the log may differ).
#[allow(dead_code)]
pub fn assert_extended_like(whole: &Path, extended: &Path) {
    let (a, b) = (dir_bytes(whole), dir_bytes(extended));
    let names = |files: &[(String, Vec<u8>)]| files.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b));
    let without_progress = |bytes: &[u8]| -> Vec<String> {
        String::from_utf8_lossy(bytes)
            .lines()
            .filter(|l| !l.contains(r#""kind":"progress""#))
            .map(String::from)
            .collect()
    };
    let json = |bytes: &[u8]| -> serde_json::Value { serde_json::from_slice(bytes).unwrap() };
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        match name.as_str() {
            "metrics.jsonl" => assert_eq!(without_progress(x), without_progress(y), "{name} of {}", extended.display()),
            "checkpoint.json" => {
                let (mut x, mut y) = (json(x), json(y));
                for manifest in [&mut x, &mut y] {
                    manifest.as_object_mut().unwrap().remove("metrics_bytes");
                    manifest["files"].as_object_mut().unwrap().remove("config.json");
                }
                assert_eq!(x, y, "{name}");
            }
            "config.json" => {
                let (x, mut y) = (json(x), json(y));
                let extensions = y["provenance"].as_object_mut().unwrap().remove("extended_by").unwrap();
                let commands: Vec<&str> = extensions.as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
                assert!(commands.len() == 1 && commands[0].contains("--resume"), "{commands:?}");
                assert_eq!(x, y, "{name}");
            }
            _ => assert!(x == y, "{name} of {} differs from {}", extended.display(), whole.display()),
        }
    }
}

/// A falling ball sampled at 180 Hz for 40 frames, frame 5 lost: a ball CSV recording.
pub fn falling_ball_csv() -> String {
    let mut text = String::from("frame,x,y,z\n");
    for f in 0..40u32 {
        let t = f as f64 / 180.0;
        if f == 5 {
            text += &format!("{f},,,\n");
        } else {
            text += &format!("{f},{:.5},{:.5},{:.5}\n", 0.1, 2.5 - 4.0 * t, 0.3 + 1.0 * t - 4.9 * t * t);
        }
    }
    text
}
