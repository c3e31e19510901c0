//! `mbrl plan` with a DLGPD model: swing-up in its latent space, on GPs conditioned on --evidence.

use std::path::{Path, PathBuf};

use super::{PlanOptions, PlanSummary};
use crate::data::write_dataset;
use crate::eval::swingup::{self, SwingupEpisode, SwingupSettings};
use crate::jobs::model_options::report_unfinished;
use crate::jobs::{warn, Invocation, Job};
use crate::models::dlgpd;
use crate::{refuse, Result};

pub(super) fn prepare(
    options: &PlanOptions,
    settings: SwingupSettings,
    out: PathBuf,
    invocation: &Invocation,
) -> Result<Job<'static, PlanSummary>> {
    let Some(evidence_path) = &options.evidence else {
        refuse!(
            "{} is a DLGPD model: pass --evidence ROLLOUTS.mcap (rollouts of the system at hand, e.g. `mbrl collect \
             --env {} --rollouts 20 --steps 29`, adding --images for a model trained on frames)",
            options.model.model,
            options.env
        );
    };
    if options.instance_seed.is_some() || options.model.context.is_some() {
        refuse!("--instance-seed and --context are for context models; a DLGPD model adapts through --evidence");
    }
    let model_dir = Path::new(&options.model.model);
    let trained = dlgpd::job::load(model_dir, options.model.accept())?;
    report_unfinished(model_dir, &trained.progress);
    let evidence = crate::data::read_dataset(evidence_path)?;
    let seed = invocation.seed;
    let dynamics = dlgpd::control::condition_on(&trained, &evidence, seed).map_err(|e| e.at(evidence_path))?;
    if dynamics.jitter() > 0.0 {
        warn(&format!(
            "the evidence's kernel matrix needed diagonal jitter {:.1e} to factor (near-duplicate evidence points)",
            dynamics.jitter()
        ));
    }
    let mut control = dlgpd::control::ControlSettings::authors(settings.variant.clone());
    control.steps = settings.steps;
    control.cem = crate::planning::CemConfig { stop_std: Some(dlgpd::control::STOP_STD), ..settings.cem.clone() };
    let unfinished_note = trained.progress.unfinished_note();
    let title = format!(
        "plan: {} swing-up with DLGPD on {} evidence transitions from {}{}",
        settings.variant.env_name(),
        dynamics.evidence_len(),
        evidence.meta.env,
        unfinished_note
    );
    let evidence_env = evidence.meta.env.clone();
    let command_line = invocation.command_line.clone();
    Ok(Job::new("plan: DLGPD swing-up", move |monitor| {
        monitor.emit(&swingup::layout(&title, false));
        let episode = dlgpd::control::swing_up(&trained, &dynamics, &control, seed, monitor)?;
        let iterations = episode.iterations.iter().sum::<usize>() as f64 / episode.iterations.len().max(1) as f64;
        let record = SwingupEpisode {
            episode: 0,
            instance: serde_json::json!({}),
            rollout: episode.rollout,
            total_return: episode.total_return,
            success: episode.success,
        };
        write_dataset(&out, &swingup::episodes_dataset(&settings, seed, &command_line, std::slice::from_ref(&record)))?;
        Ok(PlanSummary::Dlgpd {
            total_return: record.total_return,
            success: record.success,
            iterations,
            evidence_transitions: dynamics.evidence_len(),
            evidence_env,
            unfinished_note,
            out,
        })
    }))
}
