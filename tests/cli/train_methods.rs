//! `mbrl train <method>`: each method's own flags, the `--method` spelling scripts use, and
//! `--resume-if-stopped` on a directory that holds nothing, a finished run or a stopped one.

use std::path::Path;

use crate::common::*;
use mbrl::models::pets;
use mbrl::models::pets::options::PetsOptions;
use mbrl::run::dir::Provenance;
use mbrl::train::job::start;
use mbrl::train::Request;

const TINY_PETS: &str = "hidden_layers = 2\nhidden_units = 16\nvalidate_every = 10\ncheckpoint_every = 20\n";

/// Each method, a flag it takes that others do not, and flags it must not list.
const METHODS: &[(&str, &str, &[&str])] = &[
    ("pets", "--ensemble", &["--skills", "--launcher-prior", "--no-terrain", "--chunk", "--env-steps"]),
    ("ball-ekf", "--launcher-prior", &["--preset", "--env", "--ensemble", "--reward", "--skills"]),
    ("context", "--batch", &["--ensemble", "--reward", "--no-terrain", "--launcher-prior", "--skills"]),
    ("tradyn", "--no-terrain", &["--ensemble", "--reward", "--launcher-prior", "--skills", "--chunk"]),
    ("seads", "--env-steps", &["--data", "--steps", "--batch", "--lr", "--ensemble", "--launcher-prior"]),
    ("dlgpd", "--batch", &["--ensemble", "--reward", "--skills", "--env-steps", "--no-novelty", "--launcher-prior"]),
];

fn run_ok<S: AsRef<std::ffi::OsStr> + std::fmt::Debug>(dir: &Path, args: &[S]) -> std::process::Output {
    // The default thread count, as the library runs in this test process use: resumed runs end byte for byte
    // as uninterrupted ones for one thread count.
    let out = mbrl(dir).args(args).arg("--no-tui").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr_of(&out));
    out
}

fn collect_rollouts(dir: &Path) {
    std::fs::write(dir.join("tiny.toml"), TINY_PETS).unwrap();
    run_ok(dir, &["collect", "--env", "pendulum", "--rollouts", "8", "--steps", "30", "-q", "--out", "roll.mcap"]);
}

fn manifest(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("checkpoint.json")).unwrap()).unwrap()
}

/// A run directory's files, but for the two that record the command line (config.json's provenance and the
/// manifest holding its CRC) and the loss table and plot.
fn trained_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    dir_bytes(dir).into_iter().filter(|(name, _)| name != "config.json" && name != "checkpoint.json").collect()
}

#[test]
fn a_method_help_lists_its_own_flags_only() {
    let dir = tempfile::tempdir().unwrap();
    for (method, own, foreign) in METHODS {
        let out = mbrl(dir.path()).args(["train", method, "--help"]).output().unwrap();
        assert!(out.status.success(), "{method}");
        let help = stdout_of(&out);
        for flag in [*own, "--out", "--resume-if-stopped", "--seed", "--threads", "Example", "mbrl train"] {
            assert!(help.contains(flag), "`train {method} --help` lacks {flag}:\n{help}");
        }
        for flag in *foreign {
            let listed = help.lines().map(str::trim_start).any(|l| l == *flag || l.starts_with(&format!("{flag} ")));
            assert!(!listed, "`train {method} --help` lists {flag}:\n{help}");
        }
    }
}

#[test]
fn a_flag_the_method_does_not_take_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["train", "dlgpd", "--data", "x.mcap", "--skills", "3"][..],
        &["train", "--method", "dlgpd", "--data", "x.mcap", "--skills", "3"],
        &["train", "seads", "--env", "tileswap:cursor", "--data", "a.mcap"],
        &["train", "ball-ekf", "--data", "b.mcap", "--preset", "small"],
    ] {
        let out = mbrl(dir.path()).args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr_of(&out));
        let method = if args[1] == "--method" { args[2] } else { args[1] };
        assert_one_line_error(&out, &[args[args.len() - 2], &format!("mbrl train {method} --help")]);
    }
    // PETS has no paper preset.
    let out = mbrl(dir.path()).args(["train", "pets", "--data", "x.mcap", "--preset", "paper"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_one_line_error(&out, &["paper", "--preset"]);
    let out = mbrl(dir.path()).args(["train", "--resume", "m", "--data", "x.mcap"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_one_line_error(&out, &["--data"]);
}

#[test]
fn the_method_flag_trains_the_same_bytes_as_the_subcommand() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    collect_rollouts(a.path());
    collect_rollouts(b.path());
    let flags = ["--data", "roll.mcap", "--config", "tiny.toml", "--steps", "30", "--seed", "3", "--out", "m"];
    let sub = run_ok(a.path(), &[&["train", "pets"][..], &flags].concat());
    let alias = run_ok(b.path(), &[&["train", "--method", "pets"][..], &flags].concat());
    assert_eq!(stdout_of(&sub), stdout_of(&alias));
    assert!(stderr_of(&alias).lines().all(|l| !l.contains("--method")), "{}", stderr_of(&alias));
    assert_eq!(trained_bytes(&a.path().join("m")), trained_bytes(&b.path().join("m")));
    let config = |dir: &Path| {
        let mut c: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("m/config.json")).unwrap()).unwrap();
        let typed = c["provenance"]["command_line"].take();
        (c, typed.as_str().unwrap().to_string())
    };
    let ((sub_config, sub_line), (alias_config, alias_line)) = (config(a.path()), config(b.path()));
    assert_eq!(sub_config, alias_config);
    // The run records the command as typed.
    assert!(sub_line.starts_with("mbrl train pets --data") && alias_line.starts_with("mbrl train --method pets"));
}

#[test]
fn resume_if_stopped_starts_a_new_run_in_an_empty_or_finished_directory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    collect_rollouts(d);
    let args = ["train", "pets", "--data", "roll.mcap", "--config", "tiny.toml", "--steps", "20"];
    let first = run_ok(d, &[&args[..], &["--out", "m", "--resume-if-stopped"]].concat());
    assert_eq!(manifest(&d.join("m"))["complete"], true);
    let plain = run_ok(d, &[&args[..], &["--out", "plain"]].concat());
    assert_eq!(
        stdout_of(&first).replace("checkpoint: m", ""),
        stdout_of(&plain).replace("checkpoint: plain", ""),
        "a new run, as without the flag"
    );
    // A finished run in a named --out is replaced only with --force, as a plain `train` would: the same seed
    // trains the same bytes.
    let before = trained_bytes(&d.join("m"));
    let refused = mbrl(d).args(args).args(["--out", "m", "--resume-if-stopped", "--no-tui"]).output().unwrap();
    assert_one_line_error(&refused, &["holds a finished pets run (20 steps)", "--force"]);
    run_ok(d, &[&args[..], &["--out", "m", "--resume-if-stopped", "--force"]].concat());
    assert_eq!(before, trained_bytes(&d.join("m")));
}

#[test]
fn resume_if_stopped_goes_on_with_the_stopped_run_of_the_same_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    collect_rollouts(d);
    let data = d.join("roll.mcap").display().to_string();
    let tiny = d.join("tiny.toml").display().to_string();
    // The run a command line asks for, stopped by the library after 30 of its 40 steps (last checkpoint: 20).
    let options = PetsOptions {
        config_file: Some(d.join("tiny.toml")),
        steps: Some(40),
        ensemble: Some(2),
        ..PetsOptions::default()
    };
    let planned = options.plan(None, || Ok("pendulum".into()), Some(d.join("stopped"))).unwrap();
    let request = Request::<pets::Pets> {
        env: None,
        data: vec![d.join("roll.mcap")],
        seed: 4,
        config: planned.config,
        variant: (),
        provenance: Provenance::new("mbrl train …".into(), 4, 1),
    };
    let err = start(&planned.out, &request, &StopAfter::new(30)).err().unwrap();
    assert!(err.is_cancelled(), "{err}");
    assert_eq!(manifest(&d.join("stopped"))["complete"], false);
    let with_seed = |seed: &str, out: &str, extra: &[&str]| -> Vec<String> {
        let base =
            ["train", "pets", "--data", &data, "--config", &tiny, "--ensemble", "2", "--seed", seed, "--out", out];
        base.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    let args = |out: &str, extra: &[&str]| with_seed("4", out, extra);
    let fails = |args: Vec<String>, needles: &[&str]| {
        let out = mbrl(d).args(&args).arg("--no-tui").output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert_one_line_error(&out, needles);
    };

    // Without the flag a new run refuses to replace it; a different config, seed or method is refused too.
    fails(args("stopped", &["--steps", "40"]), &["stopped at step 20 of 40", "--resume-if-stopped"]);
    fails(
        args("stopped", &["--steps", "40", "--lr", "0.01", "--resume-if-stopped"]),
        &["config.json", "config.optimizer.learning_rate", "0.01"],
    );
    fails(with_seed("5", "stopped", &["--steps", "40", "--resume-if-stopped"]), &["--seed 4", "asks for 5"]);
    let dlgpd = ["train", "dlgpd", "--data", &data, "--out", "stopped", "--resume-if-stopped"];
    let out = mbrl(d).args(dlgpd).args(["--no-tui"]).output().unwrap();
    assert_one_line_error(&out, &["pets run", "not a dlgpd run", "mbrl train --resume"]);
    assert_eq!(manifest(&d.join("stopped"))["step"], 20, "refusals leave the run as it was");

    // The same command goes on from step 20 and ends as the uninterrupted run (same config, data and seed).
    let resumed = run_ok(d, &args("stopped", &["--steps", "40", "--resume-if-stopped"]));
    assert!(stdout_of(&resumed).contains("after 40 steps"), "{}", stdout_of(&resumed));
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("stopped/config.json")).unwrap()).unwrap();
    assert_eq!(config["provenance"]["command_line"], "mbrl train …", "resumed, not started over");
    run_ok(d, &args("whole", &["--steps", "40"]));
    assert_eq!(trained_bytes(&d.join("stopped")), trained_bytes(&d.join("whole")));
    assert_eq!(manifest(&d.join("stopped"))["complete"], true);
}

#[test]
fn resume_if_stopped_extends_a_stopped_pets_run_asked_for_more_steps() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    collect_rollouts(d);
    let options = PetsOptions { config_file: Some(d.join("tiny.toml")), steps: Some(40), ..PetsOptions::default() };
    let planned = options.plan(None, || Ok("pendulum".into()), Some(d.join("m"))).unwrap();
    let request = Request::<pets::Pets> {
        env: None,
        data: vec![d.join("roll.mcap")],
        seed: 0,
        config: planned.config,
        variant: (),
        provenance: Provenance::new("mbrl train …".into(), 0, 1),
    };
    start(&planned.out, &request, &StopAfter::new(25)).err().unwrap();
    let data = d.join("roll.mcap").display().to_string();
    let tiny = d.join("tiny.toml").display().to_string();
    // The Makefile's spelling.
    let args = ["train", "--method", "pets", "--data", &data, "--config", &tiny, "--steps", "60", "--out", "m"];
    run_ok(d, &[&args[..], &["--resume-if-stopped"]].concat());
    let m = manifest(&d.join("m"));
    assert_eq!((m["step"].as_u64(), m["complete"].as_bool()), (Some(60), Some(true)));
    let config: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("m/config.json")).unwrap()).unwrap();
    assert_eq!(config["config"]["steps"], 60);
    assert!(config["provenance"]["extended_by"][0].as_str().unwrap().contains("--resume-if-stopped"), "{config}");
}
