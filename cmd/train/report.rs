//! What `mbrl train` prints after a run, fresh or resumed, beside the loss curve it leaves with the checkpoint.

use std::path::Path;

use mbrl::eval::training::write_loss_report;
use mbrl::models::ball::learn::job::BallTrainReport;
use mbrl::models::ball::BallModelParams;
use mbrl::models::context;
use mbrl::models::dlgpd::job as dlgpd;
use mbrl::models::pets::{self, RewardSource};
use mbrl::models::seads;
use mbrl::models::tradyn;

pub fn pets(report: &pets::TrainReport, out: &Path) -> anyhow::Result<()> {
    write_loss_report(out, "PETS training loss (Gaussian NLL summed over members)", "loss")?;
    let run = &report.run;
    let c = &run.config;
    say!(
        "trained a PETS ensemble of {} ({}×{} {}, {} parameters, reward {}) on {} transitions of {} ({} rollouts; {} held out)",
        c.ensemble,
        c.hidden_layers,
        c.hidden_units,
        c.activation.name(),
        report.parameters,
        match c.reward {
            RewardSource::Known => "known",
            RewardSource::Learned => "learned",
        },
        run.transitions.train,
        run.env,
        run.transitions.train_rollouts,
        run.transitions.valid_rollouts
    );
    let o = &report.outcome;
    if let Some(loss) = o.last_train_loss {
        say!("final training loss (Gaussian NLL) {loss:.4} after {} steps", o.steps);
    }
    if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
        say!("best validation MSE {v:.3e} at step {step} (saved as model.safetensors)");
    }
    say!("checkpoint: {}", out.display());
    Ok(())
}

pub fn context(report: &context::TrainReport, out: &Path) -> anyhow::Result<()> {
    let run = &report.run;
    let (what, loss) = if run.method == tradyn::METHOD {
        let lookup = if run.model.local_dim > 0 {
            "with terrain lookup"
        } else {
            "without terrain lookup (−T: terrain predicted)"
        };
        (format!("a TRADYN model {lookup}"), "TRADYN training loss (eq. 4.32 with terrain input)")
    } else {
        ("a context model".to_string(), "Context-model training loss (eq. 4.32)")
    };
    write_loss_report(out, loss, "loss")?;
    let c = &run.config;
    say!(
        "trained {what} (embedding {}, D_F {}, D_β {}, {} parameters) on {} instances of {} ({} held out), batch {} × {} states",
        c.embedding,
        c.transition_features,
        c.latent_dim,
        report.parameters,
        run.instances.train,
        run.env,
        run.instances.valid,
        c.batch_size,
        run.chunk_states
    );
    let o = &report.outcome;
    if let Some(loss) = o.last_train_loss {
        say!("final training loss {loss:.4} after {} steps", o.steps);
    }
    if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
        say!("best validation loss {v:.4} at step {step} (saved as model.safetensors)");
    }
    say!("checkpoint: {}", out.display());
    Ok(())
}

pub fn ball(report: &BallTrainReport, out: &Path) -> anyhow::Result<()> {
    let losses = write_loss_report(out, "Training loss (eq. 6.24, per measurement)", "negative log-likelihood")?;
    let p = &report.params;
    let thesis = BallModelParams::thesis_learned();
    let run = &report.run;
    say!("trained on {} chunks of {} frames from {} recordings", run.chunks, run.settings.chunk_len, run.recordings);
    if let (Some(first), Some(last)) = (losses.first(), losses.last()) {
        say!("loss {:.3} -> {:.3}", first.1, last.1);
    }
    say!("learned C (thesis eq. 6.26 in brackets):");
    for (row, thesis_row) in p.c.iter().zip(&thesis.c) {
        let cells: Vec<String> = row.iter().zip(thesis_row).map(|(v, t)| format!("{v:6.2} [{t:5.2}]")).collect();
        say!("  {}", cells.join(" "));
    }
    let (k_d, k_m) = p.initial_coefficients();
    say!("a_d {:.4} (k_d {k_d:.4}), a_m {:.4} (k_m {k_m:.4})", p.a_d0, p.a_m0);
    say!("checkpoint: {}", out.display());
    Ok(())
}

pub fn seads(report: &seads::TrainReport, out: &Path) -> anyhow::Result<()> {
    write_loss_report(out, "SEADS forward-model NLL per bit on each epoch's new episodes", "nats per bit")?;
    let run = &report.run;
    let c = &run.config;
    say!(
        "trained SEADS on {}: {} skills, {} epochs, {} env steps (budget {}), SAC hidden layers {}, forward model {} units",
        run.env,
        c.skills,
        report.outcome.steps,
        report.env_steps,
        c.env_steps,
        c.sac_hidden.iter().map(usize::to_string).collect::<Vec<_>>().join(" × "),
        c.model_hidden
    );
    let last = &report.last;
    say!(
        "last epoch: the skills execute {} distinct game moves; forward-model NLL {:.4} nats per bit{}",
        last.distinct_moves,
        last.model_loss,
        last.mean_final_reward.map(|r| format!("; mean intrinsic reward {r:.3}")).unwrap_or_default()
    );
    say!("checkpoint: {}", out.display());
    Ok(())
}

pub fn dlgpd(report: &dlgpd::TrainReport, out: &Path) -> anyhow::Result<()> {
    write_loss_report(out, "DLGPD training loss (eq. 3.16 with the SNR penalty, per batch)", "loss")?;
    let run = &report.run;
    let c = &run.config;
    let observed = match run.observation {
        mbrl::models::dlgpd::data::ObservationKind::Images { side } => format!("{side}×{side} frames (conv VAE)"),
        mbrl::models::dlgpd::data::ObservationKind::Angles => "pole angles (MLP VAE, small preset)".to_string(),
    };
    say!(
        "trained DLGPD ({} parameters, latent {}) on {} transitions of {} from {observed} ({} rollouts; {} held out), batch {}",
        report.parameters,
        c.latent_dim,
        run.transitions.train,
        run.env,
        run.transitions.train_rollouts,
        run.transitions.valid_rollouts,
        c.batch_size
    );
    let o = &report.outcome;
    if let Some(loss) = o.last_train_loss {
        say!("final training loss {loss:.3} after {} steps", o.steps);
    }
    if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
        say!("best validation loss {v:.3} at step {step} (saved as model.safetensors)");
    }
    say!("checkpoint: {}", out.display());
    Ok(())
}
