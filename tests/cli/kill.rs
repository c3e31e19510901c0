//! Kill tests: `collect`, `train` and `eval` interrupted with SIGINT or killed with SIGKILL at random
//! moments. After SIGINT no temporary file may remain and the exit status is 130 (or 0 when the command
//! finished first); after either signal every output is absent, the previous one, or whole: a dataset reads
//! back complete, a model either loads and equals the uninterrupted run's or is refused with the
//! "not finished" error and resumes to the uninterrupted run's bytes, and a report's files all parse.
//!
//! CI runs a short slice; `MBRL_KILL_TRIALS=60 cargo test --release --test cli kill:: -- --nocapture` runs a
//! campaign.

use std::path::Path;
use std::process::{Command, ExitStatus};
use std::time::{Duration, Instant};

use crate::common::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const TINY_PETS: &str = "hidden_layers = 2\nhidden_units = 32\nvalidate_every = 10\ncheckpoint_every = 10\n";

#[derive(Clone, Copy, Debug)]
enum Job {
    Collect,
    Train,
    Eval,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Signal {
    Int,
    Kill,
}

fn args(job: Job) -> Vec<&'static str> {
    match job {
        Job::Collect => {
            vec!["collect", "--env", "pendulum", "--images", "--rollouts", "40", "--steps", "29", "--out", "c.mcap"]
        }
        Job::Train => vec![
            "train",
            "--method",
            "pets",
            "--data",
            "train.mcap",
            "--config",
            "tiny.toml",
            "--ensemble",
            "2",
            "--steps",
            "600",
            "--out",
            "models/p",
        ],
        Job::Eval => vec![
            "eval",
            "pendulum-swingup",
            "--model",
            "true",
            "--episodes",
            "3",
            "--steps",
            "60",
            "--horizon",
            "10",
            "--candidates",
            "100",
            "--elites",
            "10",
            "--iters",
            "3",
            "--out",
            "rep",
        ],
    }
}

fn spawn(dir: &Path, args: &[&str]) -> std::process::Child {
    Command::new(assert_cmd::cargo::cargo_bin!("mbrl"))
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .args(args)
        .args(["--no-tui", "-q", "--threads", "1", "--force"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

fn wait(child: &mut std::process::Child) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "command did not end");
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn partial_files(dir: &Path) -> Vec<String> {
    files_in(dir).into_iter().filter(|f| f.contains(".mbrl-partial-")).collect()
}

/// The model's weights as the manifest vouches for them, or the load error.
fn model_bytes(dir: &Path) -> Result<Vec<u8>, String> {
    let opened = mbrl::train::OpenedCheckpoint::open(dir).map_err(|e| e.to_string())?;
    opened.expect_finished("pets").map_err(|e| e.to_string())?;
    let entry = &opened.manifest.files["model.safetensors"];
    opened.dir.read_verified("model.safetensors", entry).map_err(|e| e.to_string())
}

fn check_outputs(dir: &Path, job: Job, reference_model: &[u8]) -> String {
    match job {
        Job::Collect => {
            let path = dir.join("c.mcap");
            if !path.exists() {
                return "absent".into();
            }
            let data = mbrl::data::read_dataset(&path).unwrap_or_else(|e| panic!("broken dataset: {e}"));
            assert_eq!(data.steps.len(), 40 * 29, "dataset incomplete");
            assert_eq!(data.frames.len(), 40 * 30, "dataset frames incomplete");
            "whole".into()
        }
        Job::Train => {
            let model = dir.join("models/p");
            match model_bytes(&model) {
                Ok(bytes) => {
                    assert!(bytes == reference_model, "a finished model differs from the uninterrupted run's");
                    "whole".into()
                }
                Err(e) if e.contains("training stopped at step") => {
                    let out = mbrl(dir).args(["train", "--resume", "models/p", "--no-tui", "-q"]).output().unwrap();
                    assert!(out.status.success(), "resume failed: {}", stderr_of(&out));
                    let bytes = model_bytes(&model).expect("resumed model loads");
                    assert!(bytes == reference_model, "the resumed model differs from the uninterrupted run's");
                    "resumed".into()
                }
                Err(e) if e.contains("not a finished checkpoint") || e.contains("not a directory") => "absent".into(),
                Err(e) => panic!("a killed run left a broken model: {e}"),
            }
        }
        Job::Eval => {
            let report = dir.join("rep");
            let files = files_in(&report);
            for f in files.iter().filter(|f| !f.contains(".mbrl-partial-")) {
                let bytes = std::fs::read(f).unwrap();
                if f.ends_with(".png") {
                    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
                    let mut reader = decoder.read_info().unwrap_or_else(|e| panic!("{f}: broken PNG: {e}"));
                    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
                    reader.next_frame(&mut buf).unwrap_or_else(|e| panic!("{f}: broken PNG: {e}"));
                } else if f.ends_with(".csv") {
                    let mut reader = csv::Reader::from_reader(bytes.as_slice());
                    for row in reader.records() {
                        row.unwrap_or_else(|e| panic!("{f}: broken CSV: {e}"));
                    }
                }
            }
            format!("{} files", files.len())
        }
    }
}

fn trials() -> usize {
    std::env::var("MBRL_KILL_TRIALS").ok().and_then(|v| v.parse().ok()).unwrap_or(12)
}

#[test]
fn interrupted_and_killed_commands_leave_whole_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), TINY_PETS).unwrap();
    let out = mbrl(d)
        .args(["collect", "--env", "pendulum", "--rollouts", "20", "--steps", "30", "-q", "--out", "train.mcap"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    // The uninterrupted run, with the runtime of each job to aim the signals at.
    let mut durations = Vec::new();
    for job in [Job::Collect, Job::Train, Job::Eval] {
        let start = Instant::now();
        let status = wait(&mut spawn(d, &args(job)));
        assert!(status.success(), "{job:?} failed");
        durations.push(start.elapsed());
    }
    std::fs::rename(d.join("models/p"), d.join("models/reference")).unwrap();
    let reference = model_bytes(&d.join("models/reference")).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut outcomes = Vec::new();
    for trial in 0..trials() {
        let (job, duration) =
            [(Job::Collect, durations[0]), (Job::Train, durations[1]), (Job::Eval, durations[2])][trial % 3];
        let signal = if (trial / 3) % 2 == 0 { Signal::Int } else { Signal::Kill };
        // Mostly while the job runs, sometimes after it would have finished.
        let delay = duration.mul_f64(rng.random_range(0.0..1.1));
        // Every other round starts without the previous output, the rest replace it.
        if (trial / 6) % 2 == 1 {
            for output in ["c.mcap", "models/p", "rep"] {
                let path = d.join(output);
                let _ = if path.is_dir() { std::fs::remove_dir_all(path) } else { std::fs::remove_file(path) };
            }
        }
        let mut child = spawn(d, &args(job));
        std::thread::sleep(delay);
        match signal {
            Signal::Int => {
                Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
            }
            Signal::Kill => child.kill().unwrap_or(()),
        }
        let status = wait(&mut child);
        if signal == Signal::Int {
            let partials = partial_files(d);
            assert!(partials.is_empty(), "trial {trial} ({job:?}): SIGINT left {partials:?}");
            // A signal that lands before the handler is installed (the first milliseconds of the process, before
            // anything is written) ends it the default way, which shells also report as 130.
            use std::os::unix::process::ExitStatusExt;
            assert!(
                matches!(status.code(), Some(0 | 130)) || status.signal() == Some(2),
                "trial {trial} ({job:?}): status {status:?} after SIGINT"
            );
        } else {
            for partial in partial_files(d) {
                std::fs::remove_file(partial).unwrap();
            }
        }
        let state = check_outputs(d, job, &reference);
        outcomes.push(format!("{trial}: {job:?} {signal:?} after {:.2} s -> {state}", delay.as_secs_f64()));
    }
    println!("{}", outcomes.join("\n"));
}

/// A run directory being trained into is locked: a second `train` or a `--resume` there is refused naming the
/// process, and once that process is stopped its interruption says how to go on and the run resumes.
#[test]
fn a_run_directory_in_use_refuses_a_second_writer_naming_its_pid() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), TINY_PETS).unwrap();
    let collect = ["collect", "--env", "pendulum", "--rollouts", "20", "--steps", "30", "-q", "--out", "train.mcap"];
    let out = mbrl(d).args(collect).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let mut long_run = args(Job::Train);
    let steps = long_run.iter().position(|a| *a == "600").unwrap();
    long_run[steps] = "1000000";
    let mut child = spawn(d, &long_run);
    let first_checkpoint = d.join("models/p/checkpoint.json");
    let start = Instant::now();
    while !first_checkpoint.exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "the first run never checkpointed");
        std::thread::sleep(Duration::from_millis(20));
    }
    let pid = format!("in use by pid {}", child.id());
    for second in [&long_run[..], &["train", "--resume", "models/p"]] {
        let out = mbrl(d).args(second).args(["--no-tui", "-q"]).output().unwrap();
        assert!(!out.status.success());
        assert!(stderr_of(&out).contains(&pid), "{second:?}: {}", stderr_of(&out));
    }
    Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    let status = wait(&mut child);
    assert_eq!(status.code(), Some(130));
    let mut stderr = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
    assert!(stderr.contains("of 1000000; continue with `mbrl train --resume models/p`"), "{stderr}");
    let out = mbrl(d).args(&long_run).args(["--no-tui", "-q"]).output().unwrap();
    assert!(stderr_of(&out).contains("holds a pets run stopped at step"), "{}", stderr_of(&out));
    let out = mbrl(d).args(["watch", "models/p", "--no-tui"]).output().unwrap();
    assert!(
        stdout_of(&out).contains("status: stopped; continue with `mbrl train --resume models/p`"),
        "{}",
        stdout_of(&out)
    );
}
