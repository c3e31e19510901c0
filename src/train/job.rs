//! A training run in its checkpoint directory, fresh or resumed: the part of every `mbrl train` that is the
//! same for all methods.

use std::path::Path;

use serde_json::Value;

use super::checkpoint::{CheckpointDir, FileEntry};
use super::fit::{fit, DirCheckpointer, FitSettings, TrainingMethod, CONFIG_FILE, STATE_FILE};
use super::method::{Method, Prepared, Request, RunConfig, RunRecord, Trained};
use super::run_dir::Decision;
use super::OpenedCheckpoint;
use crate::error::{Error, ErrorKind, Result};
use crate::run::dir::{Provenance, METRICS_FILE};
use crate::run::lock::RunLock;
use crate::run::{Event, JsonlMonitor, Monitor, Tee};

/// A billion optimizer steps: beyond any training budget, so a larger count is a typo or a corrupt config.
pub const MAX_TRAIN_STEPS: u64 = 1_000_000_000;

/// How [`run_training`] treats what is already in the checkpoint directory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// A new run: from its first moment nothing in the directory passes for a model.
    Fresh,
    /// The unfinished run in the directory goes on with its own config.
    Resume,
    /// The run in the directory, finished or not, goes on to a larger total of steps. Its config changes in
    /// that total only (the caller builds it from the checkpoint's), and only for methods whose training does
    /// not depend on the total, so the run ends as one started with the larger total would have.
    Extend,
}

/// `train --resume DIR --steps N`: the total asked for, and the command, which the run's provenance keeps.
#[derive(Clone, Debug)]
pub struct Extension {
    pub steps: u64,
    pub command_line: String,
}

/// How a resumed run goes on: plainly, or extended to a new total with the extending command in its provenance.
pub struct Continuation {
    pub start: Start,
    pub steps: u64,
    pub provenance: Provenance,
}

/// The continuation of the run in `opened` (whose config asks for `config_steps`) that `requested` asks for. A
/// smaller total is refused: a run is never cut short.
pub fn continuation(
    opened: &OpenedCheckpoint,
    config_steps: u64,
    provenance: &Provenance,
    requested: Option<&Extension>,
) -> Result<Continuation> {
    let plain = Continuation { start: Start::Resume, steps: config_steps, provenance: provenance.clone() };
    let Some(extension) = requested else {
        return Ok(plain);
    };
    let total = extension.steps;
    if total == config_steps {
        return Ok(plain);
    }
    if total < config_steps {
        return Err(Error::bad_file(
            opened.dir.path(),
            format!(
                "was started for {config_steps} steps; --steps {total} would shorten it (with --resume, --steps only \
                 extends a run)"
            ),
        ));
    }
    if total > MAX_TRAIN_STEPS {
        return Err(Error::config(format!(
            "--steps {total}: at most {MAX_TRAIN_STEPS} (months on any machine mbrl runs on)"
        )));
    }
    let mut provenance = provenance.clone();
    provenance.extended_by.push(extension.command_line.clone());
    Ok(Continuation { start: Start::Extend, steps: total, provenance })
}

/// Starts a new run of `request` in `out`, replacing whatever is there (callers first [`super::run_dir::decide`]
/// whether a stopped run must be kept).
pub fn start<M: Method>(out: &Path, request: &Request<M>, monitor: &dyn Monitor) -> Result<Trained<M>> {
    run(out, request, Start::Fresh, monitor)
}

/// Continues the run in `dir` from its last checkpoint with the config, data and seed it was started with;
/// with `extension`, on to a larger total (only for [`Method::EXTENDABLE`] methods).
pub fn resume<M: Method>(dir: &Path, extension: Option<&Extension>, monitor: &dyn Monitor) -> Result<Trained<M>> {
    // A run still going is named as such before its half-written state is judged.
    if dir.is_dir() {
        RunLock::ensure_free(dir)?;
    }
    let opened = OpenedCheckpoint::open(dir)?;
    opened.expect_method(M::NAME)?;
    let record = RunRecord::<M>::read(&opened)?;
    let steps = record.config.total_steps();
    opened.expect_total_steps(steps)?;
    if extension.is_some_and(|e| e.steps != steps) && !M::EXTENDABLE {
        return Err(Error::config(format!(
            "{}: --steps with --resume extends a run, which works for pets and dlgpd runs; a {} run's training \
             depends on its total, so start a new run with the steps you want",
            dir.display(),
            M::NAME
        )));
    }
    let next = continuation(&opened, steps, &record.provenance, extension)?;
    for file in &record.data {
        file.verify_unchanged()?;
    }
    let request = Request::<M> {
        env: record.env.clone(),
        data: record.data_paths(),
        seed: record.seed,
        config: if next.steps == steps {
            record.config.clone()
        } else {
            M::with_total_steps(&record.config, next.steps)
        },
        variant: M::variant_of(&record)?,
        provenance: next.provenance,
    };
    drop(opened);
    run(dir, &request, next.start, monitor)
}

/// Starts or continues a run as [`super::run_dir::decide`] decided.
pub fn carry_out<M: Method>(
    out: &Path,
    request: &Request<M>,
    decision: &Decision,
    monitor: &dyn Monitor,
) -> Result<Trained<M>> {
    match decision {
        Decision::Fresh => start(out, request, monitor),
        Decision::Resume(extension) => resume(out, extension.as_ref(), monitor),
    }
}

/// Runs `request` to the end in `dir`. A fresh run writes its record (the full description a resumed run is
/// rebuilt from) and starts the metrics log with the live view. To resume, `dir` must hold an unfinished
/// checkpoint of the same record, and the run continues from it so that it ends with the bytes an
/// uninterrupted run would. To extend, the new record is staged with the next checkpoint, so until that
/// checkpoint the directory still holds the run as it was.
fn run<M: Method>(dir: &Path, request: &Request<M>, start: Start, monitor: &dyn Monitor) -> Result<Trained<M>> {
    request.config.check()?;
    let total_steps = request.config.total_steps();
    if total_steps > MAX_TRAIN_STEPS {
        return Err(Error::config(format!(
            "{total_steps} training steps; at most {MAX_TRAIN_STEPS} (months on any machine mbrl runs on)"
        )));
    }
    let Prepared { env, data, details, mut trainer, view } = M::prepare(request)?;
    let record = RunRecord::<M> {
        method: M::NAME.to_string(),
        env,
        data,
        seed: request.seed,
        config: request.config.clone(),
        details,
        provenance: request.provenance.clone(),
    };
    let (validate_every, checkpoint_every) = request.config.schedule();
    let settings = FitSettings {
        method: M::NAME.to_string(),
        env: record.env.clone(),
        total_steps,
        validate_every,
        checkpoint_every,
    };
    let config = record.to_value()?;
    let config_bytes = config_bytes(&config)?;
    for event in &view {
        monitor.emit(event);
    }
    // Taken once the data is ready and before the first write: a run that fails to prepare leaves nothing.
    let _lock = RunLock::acquire(dir)?;
    let stopped_dir = dir.to_path_buf();
    let _note = crate::util::interrupt::explain_interruption(move || {
        Some(name_the_stop(Error::cancelled(), &stopped_dir)).filter(|e| e.path().is_some()).map(|e| e.to_string())
    });
    if start == Start::Fresh {
        let ckpt = CheckpointDir::start(dir)?;
        let entry = ckpt.write_file(CONFIG_FILE, &config_bytes)?;
        let metrics_path = ckpt.file(METRICS_FILE);
        let metrics = JsonlMonitor::create(&metrics_path).map_err(|e| Error::io(&metrics_path, e))?;
        for event in &view {
            metrics.emit(event);
        }
        let tee = Tee { first: monitor, second: &metrics };
        let mut checkpoints = DirCheckpointer { dir: &ckpt, config_entry: &entry, metrics: &metrics };
        let outcome = fit(&mut trainer, &settings, &mut checkpoints, None, &tee).map_err(|e| name_the_stop(e, dir))?;
        metrics.emit(&Event::Finished { ok: true });
        return Ok(Trained { record, outcome, trainer });
    }
    let opened = OpenedCheckpoint::open(dir)?;
    // The config entry the run keeps: the checkpoint's own when resuming; when extending, none yet (the new
    // record is staged once everything has been read from the checkpoint).
    let kept_entry = if start == Start::Resume {
        Some(check_resumable::<M>(&opened, &settings, &config)?)
    } else if settings.total_steps <= opened.manifest.total_steps {
        return Err(Error::config(format!(
            "extending {} to {} steps: the run already has {}",
            dir.display(),
            settings.total_steps,
            opened.manifest.total_steps
        )));
    } else {
        None
    };
    // A checkpoint killed halfway into place is finished first, so this run stages its own cleanly.
    opened.dir.settle()?;
    trainer.restore(&opened.tensors(STATE_FILE)?)?;
    let point = opened.resume_point()?;
    let entry = match kept_entry {
        Some(entry) => entry,
        None => opened.dir.write_file(CONFIG_FILE, &config_bytes)?,
    };
    let metrics_path = opened.dir.file(METRICS_FILE);
    let metrics =
        JsonlMonitor::resume(&metrics_path, opened.manifest.metrics_bytes).map_err(|e| Error::io(&metrics_path, e))?;
    monitor.message(&format!("resuming at step {} of {}", point.step, settings.total_steps));
    let tee = Tee { first: monitor, second: &metrics };
    let mut checkpoints = DirCheckpointer { dir: &opened.dir, config_entry: &entry, metrics: &metrics };
    let outcome =
        fit(&mut trainer, &settings, &mut checkpoints, Some(point), &tee).map_err(|e| name_the_stop(e, dir))?;
    metrics.emit(&Event::Finished { ok: true });
    Ok(Trained { record, outcome, trainer })
}

/// A run the user stopped says where it stands and how to go on, from the checkpoint it keeps; one stopped
/// before its first checkpoint has nothing to go on from and stays a plain cancellation.
fn name_the_stop(err: Error, dir: &Path) -> Error {
    if !matches!(err.kind(), ErrorKind::Cancelled) {
        return err;
    }
    match OpenedCheckpoint::open(dir) {
        Ok(opened) if !opened.manifest.complete => {
            Error::stopped(opened.manifest.step, opened.manifest.total_steps).at(dir)
        }
        _ => err,
    }
}

/// A plain resume needs an unfinished checkpoint of exactly this config; returns the config's manifest entry.
fn check_resumable<M: Method>(opened: &OpenedCheckpoint, settings: &FitSettings, config: &Value) -> Result<FileEntry> {
    if opened.manifest.total_steps != settings.total_steps {
        return Err(Error::bad_file(
            &opened.dir.file(CONFIG_FILE),
            format!(
                "asks for {} steps, but the checkpoint belongs to a run of {}: the config was changed",
                settings.total_steps, opened.manifest.total_steps
            ),
        ));
    }
    if opened.manifest.complete {
        return Err(Error::bad_file(
            opened.dir.path(),
            format!(
                "training already finished ({} of {} steps); nothing to resume",
                opened.manifest.step, opened.manifest.total_steps
            ),
        ));
    }
    let entry = opened.manifest.files.get(CONFIG_FILE).cloned().expect("checked by OpenedCheckpoint::open");
    // Compared as the record it reads as today, so a run stopped under an older layout still resumes.
    let mut stored: Value = serde_json::from_slice(&opened.dir.read_verified(CONFIG_FILE, &entry)?)
        .map_err(|e| Error::bad_file(&opened.dir.file(CONFIG_FILE), format!("not valid JSON: {e}")))?;
    M::upgrade(&mut stored);
    if stored != *config {
        return Err(Error::bad_file(&opened.dir.file(CONFIG_FILE), "differs from the run being resumed"));
    }
    Ok(entry)
}

fn config_bytes(config: &serde_json::Value) -> Result<Vec<u8>> {
    let mut bytes = serde_json::to_vec_pretty(config).map_err(|e| Error::config(format!("config.json: {e}")))?;
    bytes.push(b'\n');
    Ok(bytes)
}

/// What the live view shows of a training run from its start: the title and chart panels, and a
/// text panel of the settings that stay fixed through the run (learning rate, batch, data), one
/// `name value` pair a line. Metrics that no panel draws (a loss's terms, a schedule) are offered in
/// the Curves panel.
pub fn training_view(title: &str, panels: Vec<crate::run::PanelSpec>, settings: &[(&str, String)]) -> Vec<Event> {
    let width = settings.iter().map(|(name, _)| name.chars().count()).max().unwrap_or(0);
    let lines: Vec<String> = settings.iter().map(|(name, value)| format!("{name:<width$}  {value}")).collect();
    vec![Event::Layout { title: title.to_string(), panels }, Event::text("settings", lines.join("\n"))]
}

/// The training loss per step, with the validation loss beside it where both measure the same
/// objective (the curves then share one scale and overfitting shows as their gap).
pub fn loss_panel(title: &str, with_validation: bool) -> crate::run::PanelSpec {
    let mut series = vec!["train/loss".to_string()];
    if with_validation {
        series.push("valid/loss".into());
    }
    crate::run::PanelSpec { title: title.into(), x_label: "step".into(), series, restart_on_rewind: false, path: None }
}

/// The validation panel of methods that hold data back.
pub fn validation_panel(title: &str) -> crate::run::PanelSpec {
    crate::run::PanelSpec {
        title: title.into(),
        x_label: "step".into(),
        series: vec!["valid/loss".into()],
        restart_on_rewind: false,
        path: None,
    }
}
