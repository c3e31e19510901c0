//! End to end: collect → train DLGPD → plan a swing-up on evidence, resume, and the errors a user can run into.

use std::path::Path;

use crate::common::*;
use mbrl::data::read_dataset;
use mbrl::models::dlgpd::config::{DlgpdConfig, Preset};
use mbrl::models::dlgpd::job as dlgpd;
use mbrl::run::dir::Provenance;
use mbrl::train::job::start;
use mbrl::train::Request;

fn collect(dir: &Path, name: &str, env: &str, rollouts: &str, images: bool) {
    let mut cmd = mbrl(dir);
    cmd.args(["collect", "--env", env, "--rollouts", rollouts, "--steps", "12", "-q", "--out", name]);
    if images {
        cmd.arg("--images");
    }
    cmd.assert().success();
}

#[test]
fn train_on_angles_then_plan_on_swapped_evidence() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "train.mcap", "pendulum", "30", false);
    collect(dir.path(), "evidence.mcap", "pendulum:inverted", "3", false);
    let out = mbrl(dir.path())
        .args(["train", "--method", "dlgpd", "--data", "train.mcap", "--steps", "40", "--batch", "64"])
        .args(["--out", "models/d", "--no-tui"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let text = stdout_of(&out);
    assert!(text.contains("pole angles") && text.contains("best validation loss"), "{text}");
    for file in ["loss.png", "losses.csv", "model.safetensors", "state.safetensors"] {
        assert!(dir.path().join("models/d").join(file).is_file(), "{file} missing");
    }

    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum:inverted", "--model", "models/d", "--evidence", "evidence.mcap"])
        .args(["--candidates", "40", "--elites", "5", "--iters", "2", "--steps", "8", "-q", "--out", "plan.mcap"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let text = stdout_of(&out);
    assert!(text.contains("return") && text.contains("33 transitions of pendulum:inverted"), "{text}");
    let plan = read_dataset(&dir.path().join("plan.mcap")).unwrap();
    assert_eq!(plan.steps.len(), 8);
    assert_eq!(plan.meta.env, "pendulum:inverted");

    // The same seed plans the same actions.
    let again = mbrl(dir.path())
        .args(["plan", "--env", "pendulum:inverted", "--model", "models/d", "--evidence", "evidence.mcap"])
        .args(["--candidates", "40", "--elites", "5", "--iters", "2", "--steps", "8", "-q", "--out", "again.mcap"])
        .output()
        .unwrap();
    assert!(again.status.success(), "{}", stderr_of(&again));
    let actions =
        |p: &str| read_dataset(&dir.path().join(p)).unwrap().steps.iter().map(|s| s.action[0]).collect::<Vec<_>>();
    assert_eq!(actions("plan.mcap"), actions("again.mcap"));

    // The prediction check alone: no swing-ups, a reward-RMSE curve per setting over the held-out rollouts'
    // 28 windows, and the same bytes from the same seed.
    let check = |out: &str| {
        let run = mbrl(dir.path())
            .args(["eval", "dlgpd", "--model", "models/d", "--env", "pendulum:inverted", "--evidence-rollouts", "3"])
            .args(["--prediction-only", "--no-tui", "--out", out])
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", stderr_of(&run));
        assert!(stdout_of(&run).contains("reward RMSE, held-out rollouts"), "{}", stdout_of(&run));
        std::fs::read_to_string(dir.path().join(out).join("prediction.csv")).unwrap()
    };
    let csv = check("check");
    assert_eq!(csv.lines().count(), 1 + 2 * 28, "{csv}");
    assert!(csv.lines().nth(1).unwrap().starts_with("pendulum:inverted,matching,3,0,"), "{csv}");
    assert_eq!(csv, check("again"));
    let report = std::fs::read_to_string(dir.path().join("check/report.md")).unwrap();
    assert!(report.contains("## Reward prediction") && !report.contains("## Swing-ups"), "{report}");
    assert!(!dir.path().join("check/results.csv").exists());

    // The action response: the standard pendulum's evidence answers a held action the same way on both systems,
    // while the inverted system answers it the other way round, so that setting mirrors the standard one.
    let run = mbrl(dir.path())
        .args(["eval", "dlgpd", "--model", "models/d", "--env", "pendulum", "--env", "pendulum:inverted"])
        .args(["--evidence-rollouts", "3", "--prediction-only", "-q", "--out", "mirror"])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", stderr_of(&run));
    let csv = std::fs::read_to_string(dir.path().join("mirror/action_response.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(csv.lines().next(), Some("env,evidence,horizon,response,true_effect"));
    assert_eq!(rows.len(), 3 * 3, "{csv}");
    let response = |env: &str, evidence: &str, horizon: &str| -> f64 {
        let row = rows.iter().find(|r| r[0] == env && r[1] == evidence && r[2] == horizon).expect("row");
        row[3].parse().unwrap()
    };
    for horizon in ["1", "5", "10"] {
        let (standard, mirrored) =
            (response("pendulum", "matching", horizon), response("pendulum:inverted", "mismatching", horizon));
        assert!(standard.is_finite() && (standard + mirrored).abs() <= 0.15 * standard.abs() + 0.05, "{csv}");
    }

    // Planning without evidence, or an image model's evidence without frames, is a one-line error.
    let out = mbrl(dir.path()).args(["plan", "--env", "pendulum", "--model", "models/d", "-q"]).output().unwrap();
    assert_one_line_error(&out, &["DLGPD", "--evidence"]);
    let out = mbrl(dir.path())
        .args(["plan", "--env", "pendulum", "--model", "true", "--evidence", "evidence.mcap", "-q"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["--evidence", "not a DLGPD"]);
}

#[test]
fn resume_ends_with_the_bytes_of_an_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "train.mcap", "pendulum", "16", false);
    let config = DlgpdConfig {
        steps: 30,
        batch_size: 32,
        validate_every: 5,
        checkpoint_every: 10,
        ..DlgpdConfig::preset(Preset::Small)
    };
    let request = Request::<dlgpd::Dlgpd> {
        env: None,
        data: vec![dir.path().join("train.mcap")],
        seed: 4,
        config: config.clone(),
        variant: (),
        provenance: Provenance::new("mbrl train …".into(), 4, 1),
    };
    let run_dir = |name: &str| dir.path().join(name);
    start(&run_dir("whole"), &request, &mbrl::run::NullMonitor).unwrap();
    let stop = StopAfter::new(25);
    let err = start(&run_dir("stopped"), &request, &stop).err().unwrap();
    assert!(err.is_cancelled(), "{err}");

    // A run still in training is refused, unless asked for; its report then says how far it got.
    let eval = |extra: &[&str]| {
        mbrl(dir.path())
            .args(["eval", "dlgpd", "--model", "stopped", "--env", "pendulum", "--evidence-rollouts", "2"])
            .args(["--prediction-only", "-q", "--out", "partial"])
            .args(extra)
            .output()
            .unwrap()
    };
    assert_one_line_error(&eval(&[]), &["stopped", "training stopped at step 20 of 30"]);
    assert!(!dir.path().join("partial").exists());
    let out = eval(&["--allow-incomplete"]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    let report = std::fs::read_to_string(dir.path().join("partial/report.md")).unwrap();
    assert!(report.contains("20 of 30 steps (training still in progress)"), "{report}");

    // Starting a new run over the stopped one is refused and leaves it as it was: the resumed run below
    // still ends with the uninterrupted run's bytes.
    let fresh = mbrl(dir.path())
        .args(["train", "--method", "dlgpd", "--data", "train.mcap", "--steps", "30", "--out", "stopped", "--no-tui"])
        .output()
        .unwrap();
    assert_one_line_error(&fresh, &["stopped", "stopped at step 20 of 30", "mbrl train --resume stopped"]);

    let out = mbrl(dir.path()).args(["train", "--resume", "stopped", "--no-tui"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    // The CLI adds its loss report after training; the library run writes none.
    let model_files = |d: &str| -> Vec<(String, Vec<u8>)> {
        dir_bytes(&dir.path().join(d)).into_iter().filter(|(n, _)| !n.starts_with("loss")).collect()
    };
    let whole = model_files("whole");
    let names = |files: &[(String, Vec<u8>)]| files.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    let same_as_whole = |run: &str| {
        let files = model_files(run);
        assert_eq!(names(&whole), names(&files));
        for ((name, a), (_, b)) in whole.iter().zip(&files) {
            assert!(a == b, "{name} of {run} differs from the uninterrupted run");
        }
    };
    same_as_whole("stopped");

    // A finished run of 20 steps, trained on to 30, is the run that was started with 30.
    let short = Request { config: DlgpdConfig { steps: 20, ..config.clone() }, ..request };
    start(&run_dir("short"), &short, &mbrl::run::NullMonitor).unwrap();
    let extend = |steps: &str| {
        mbrl(dir.path()).args(["train", "--resume", "short", "--steps", steps, "--no-tui"]).output().unwrap()
    };
    assert_one_line_error(&extend("10"), &["short", "started for 20 steps", "--steps 10 would shorten it"]);
    assert_one_line_error(&extend("20"), &["short", "already finished"]);
    let out = extend("30");
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert_extended_like(&dir.path().join("whole"), &dir.path().join("short"));
}

#[test]
fn image_presets_need_frames_and_say_how_to_get_them() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "train.mcap", "pendulum", "4", false);
    let out = mbrl(dir.path())
        .args(["train", "--method", "dlgpd", "--data", "train.mcap", "--preset", "medium", "--out", "m", "-q"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["train.mcap", "--images"]);
    assert!(!dir.path().join("m").exists());
    let out = mbrl(dir.path())
        .args(["train", "--method", "dlgpd", "--data", "train.mcap", "--skills", "3", "--out", "m", "-q"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["--skills", "dlgpd"]);
}

#[test]
fn an_image_model_trains_a_few_steps_on_rendered_frames() {
    let dir = tempfile::tempdir().unwrap();
    collect(dir.path(), "frames.mcap", "pendulum", "6", true);
    let out = mbrl(dir.path())
        .args(["train", "--method", "dlgpd", "--data", "frames.mcap", "--preset", "medium", "--steps", "3"])
        .args(["--batch", "16", "--out", "m", "--no-tui"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert!(stdout_of(&out).contains("64×64 frames"), "{}", stdout_of(&out));
    let trained = dlgpd::load(&dir.path().join("m"), mbrl::train::Accept::Finished).unwrap();
    assert_eq!(trained.scale.mean.len(), 3);
}
