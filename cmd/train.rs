//! `mbrl train`: fit a model to a dataset and write a checkpoint directory.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use mbrl::data::ball_io::read_recordings;
use mbrl::eval::plot::{line_plot, Series};
use mbrl::models::ball::checkpoint::save_ball_params;
use mbrl::models::ball::learn::{train, TrainSettings};
use mbrl::models::ball::BallModelParams;
use mbrl::run::dir::{Provenance, RunDir};
use mbrl::run::{Event, Monitor, PanelSpec, Tee};
use mbrl::util::atomic::write_json;
use mbrl::util::table::write_csv;

use crate::common::{command_line, run_job, GlobalArgs};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Gray-box table-tennis ball EKF: learn the impact matrix, noise levels and initial values by
    /// maximizing the filter's marginal likelihood (thesis 6.4.4, eq. 6.24).
    BallEkf,
}

/// Train a model and write it to a checkpoint directory (config.json, metrics.jsonl, weights).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl collect --env ball --trajectories 108 --augment-rotations 19 --out datasets/ball-train.mcap
  mbrl train --method ball-ekf --data datasets/ball-train.mcap --out models/ball-ekf --steps 2000
  mbrl predict --model models/ball-ekf --input datasets/ball-default.mcap --horizon 1s")]
pub struct TrainArgs {
    /// What to train.
    #[arg(long, value_enum)]
    method: Method,
    /// Training data (ball: a .mcap ball dataset or a .csv recording).
    #[arg(long)]
    data: PathBuf,
    /// Checkpoint directory.
    #[arg(long, default_value = "models/ball-ekf")]
    out: PathBuf,
    /// Optimizer steps.
    #[arg(long, default_value_t = 1000)]
    steps: u64,
    /// Chunks per batch (thesis: 64).
    #[arg(long, default_value_t = 64)]
    batch: usize,
    /// Frames per chunk (thesis: 50).
    #[arg(long, default_value_t = 50)]
    chunk: usize,
    /// Adam learning rate (thesis: 5e-3).
    #[arg(long, default_value_t = 5e-3, value_parser = crate::common::finite_f64)]
    lr: f64,
    /// Learn the spin prior from launcher settings (thesis C.1.3); recordings need side information.
    #[arg(long)]
    launcher_prior: bool,
}

pub fn run(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    let Method::BallEkf = args.method;
    let recordings = read_recordings(&args.data)?;
    let settings = TrainSettings {
        steps: args.steps,
        batch_size: args.batch,
        chunk_len: args.chunk,
        learning_rate: args.lr,
        seed: global.seed,
        launcher_prior: args.launcher_prior,
        ..TrainSettings::default()
    };
    let provenance = Provenance::new(command_line(), global.seed, global.thread_count());
    let outcome = run_job(global, "train ball-ekf", |monitor| {
        let run = RunDir::create(&args.out)?;
        run.write_config(&serde_json::json!({
            "job": "train ball-ekf",
            "data": args.data.display().to_string(),
            "recordings": recordings.len(),
            "settings": settings,
            "provenance": provenance,
        }))?;
        let metrics = run.metrics()?;
        let monitor = Tee { first: monitor, second: &metrics };
        monitor.emit(&Event::Layout {
            title: "train ball EKF (negative log-likelihood per measurement)".into(),
            panels: vec![PanelSpec {
                title: "loss".into(),
                x_label: "step".into(),
                series: vec!["train/loss".into()],
                restart_on_rewind: false,
            }],
        });
        let outcome = train(&recordings, &settings, &monitor)?;
        save_ball_params(run.path(), &outcome.params)?;
        if let Some(net) = &outcome.spin_net {
            write_json(&run.file("spin_net.json"), net)?;
        }
        let rows: Vec<Vec<String>> =
            outcome.losses.iter().enumerate().map(|(k, l)| vec![k.to_string(), format!("{l:.6}")]).collect();
        write_csv(&run.file("losses.csv"), &["step", "loss"], &rows)?;
        let curve = Series {
            name: "batch loss".into(),
            points: outcome.losses.iter().enumerate().map(|(k, l)| (k as f64, *l)).collect(),
        };
        line_plot(
            &run.file("loss.png"),
            "Training loss (eq. 6.24, per measurement)",
            "step",
            "negative log-likelihood",
            &[curve],
        )?;
        metrics.emit(&Event::Finished { ok: true });
        Ok(outcome)
    })?;
    let p = &outcome.params;
    let thesis = BallModelParams::thesis_learned();
    println!("trained on {} chunks of {} frames from {} recordings", outcome.chunks, args.chunk, recordings.len());
    if let (Some(first), Some(last)) = (outcome.losses.first(), outcome.losses.last()) {
        println!("loss {first:.3} -> {last:.3}");
    }
    println!("learned C (thesis eq. 6.26 in brackets):");
    for (row, thesis_row) in p.c.iter().zip(&thesis.c) {
        let cells: Vec<String> = row.iter().zip(thesis_row).map(|(v, t)| format!("{v:6.2} [{t:5.2}]")).collect();
        println!("  {}", cells.join(" "));
    }
    println!(
        "a_d {:.4} (k_d {:.4}), a_m {:.4} (k_m {:.4})",
        p.a_d0,
        p.a_d0 * p.a_d0 + 0.05,
        p.a_m0,
        p.a_m0 * p.a_m0 + 0.05
    );
    println!("checkpoint: {}", args.out.display());
    Ok(())
}
