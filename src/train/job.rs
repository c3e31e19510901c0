//! A training run in its checkpoint directory, fresh or resumed: the part of every `mbrl train` that is the
//! same for all methods.

use std::path::Path;

use super::checkpoint::{CheckpointDir, FileEntry};
use super::fit::{fit, DirCheckpointer, FitOutcome, FitSettings, TrainingMethod, CONFIG_FILE, STATE_FILE};
use super::OpenedCheckpoint;
use crate::error::{Error, Result};
use crate::run::dir::{Provenance, METRICS_FILE};
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

impl Start {
    pub fn resuming(resume: bool) -> Start {
        if resume {
            Start::Resume
        } else {
            Start::Fresh
        }
    }
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

/// Runs `method` to the end in `dir`. A fresh run writes `config` (the full description a resumed run is rebuilt
/// from) and starts the metrics log with `view`. To resume, `dir` must hold an unfinished checkpoint of the same
/// config, and the run continues from it so that it ends with the bytes an uninterrupted run would. To extend,
/// the new config is staged with the next checkpoint, so until that checkpoint the directory still holds the
/// run as it was.
pub fn run_training(
    dir: &Path,
    config: &serde_json::Value,
    settings: &FitSettings,
    method: &mut dyn TrainingMethod,
    start: Start,
    view: &[Event],
    monitor: &dyn Monitor,
) -> Result<FitOutcome> {
    if settings.total_steps > MAX_TRAIN_STEPS {
        return Err(Error::config(format!(
            "{} training steps; at most {MAX_TRAIN_STEPS} (months on any machine mbrl runs on)",
            settings.total_steps
        )));
    }
    let config_bytes = config_bytes(config)?;
    for event in view {
        monitor.emit(event);
    }
    if start != Start::Fresh {
        let opened = OpenedCheckpoint::open(dir)?;
        // The config entry the run keeps: the checkpoint's own when resuming; when extending, none yet (the new
        // config is staged once everything has been read from the checkpoint).
        let kept_entry = if start == Start::Resume {
            Some(check_resumable(&opened, settings, &config_bytes)?)
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
        method.restore(&opened.tensors(STATE_FILE)?)?;
        let point = opened.resume_point()?;
        let entry = match kept_entry {
            Some(entry) => entry,
            None => opened.dir.write_file(CONFIG_FILE, &config_bytes)?,
        };
        let metrics_path = opened.dir.file(METRICS_FILE);
        let metrics = JsonlMonitor::resume(&metrics_path, opened.manifest.metrics_bytes)
            .map_err(|e| Error::io(&metrics_path, e))?;
        monitor.message(&format!("resuming at step {} of {}", point.step, settings.total_steps));
        let tee = Tee { first: monitor, second: &metrics };
        let mut checkpoints = DirCheckpointer { dir: &opened.dir, config_entry: &entry, metrics: &metrics };
        let outcome = fit(method, settings, &mut checkpoints, Some(point), &tee)?;
        metrics.emit(&Event::Finished { ok: true });
        return Ok(outcome);
    }
    let ckpt = CheckpointDir::start(dir)?;
    let entry = ckpt.write_file(CONFIG_FILE, &config_bytes)?;
    let metrics_path = ckpt.file(METRICS_FILE);
    let metrics = JsonlMonitor::create(&metrics_path).map_err(|e| Error::io(&metrics_path, e))?;
    for event in view {
        metrics.emit(event);
    }
    let tee = Tee { first: monitor, second: &metrics };
    let mut checkpoints = DirCheckpointer { dir: &ckpt, config_entry: &entry, metrics: &metrics };
    let outcome = fit(method, settings, &mut checkpoints, None, &tee)?;
    metrics.emit(&Event::Finished { ok: true });
    Ok(outcome)
}

/// A plain resume needs an unfinished checkpoint of exactly this config; returns the config's manifest entry.
fn check_resumable(opened: &OpenedCheckpoint, settings: &FitSettings, config_bytes: &[u8]) -> Result<FileEntry> {
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
    if opened.dir.read_verified(CONFIG_FILE, &entry)? != config_bytes {
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
