//! `mbrl watch`: follow a run's metrics in the live view, or summarise them when not on a terminal.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use mbrl::run::follow::{follow_runs, RunUpdate, WatchedRun};
use mbrl::run::watched::{run_dir, run_labels, Liveness, RunSummary};
use mbrl::run::Event;
use mbrl::tui::{run_live, run_overlay, LiveOptions};

use crate::common::GlobalArgs;

/// Follow running or finished runs (training or eval) in the live view; several runs are overlaid.
#[derive(Args, Debug)]
#[command(after_help = "\
With one run the view is the run's own live view. With several, each metric gets one panel that draws it
for every run that records it, one colour per run, over a shared step axis; a Runs list names each run
(its directory name, lengthened by its parents where two would clash) with its state (running, stopped,
unfinished for a report without a lock, finished, failed) and progress. ←/→ scroll when the panels do not
all fit. Without a terminal (or with --no-tui) one run prints a summary of its metrics, several print one
status line each.

Examples:
  mbrl watch reports/quick/pendulum-swingup
  mbrl watch models/my-run --no-tui      # print a summary of the metrics instead
  mbrl watch models/pets-seed1 models/pets-seed2      # overlay two runs' curves")]
pub struct WatchArgs {
    /// Run directories (each holds metrics.jsonl) or metrics files themselves.
    #[arg(required = true, value_name = "RUN_DIR")]
    run_dirs: Vec<PathBuf>,
}

pub fn run(global: &GlobalArgs, args: WatchArgs) -> anyhow::Result<()> {
    let runs = args.run_dirs.iter().map(|dir| WatchedRun::open(dir)).collect::<mbrl::Result<Vec<_>>>()?;
    if let [single] = &args.run_dirs[..] {
        return watch_one(global, runs, single);
    }
    let labels = run_labels(&args.run_dirs.iter().map(|arg| run_dir(arg)).collect::<Vec<_>>());
    if !global.use_tui() {
        for (label, mut run) in labels.iter().zip(runs) {
            let mut summary = RunSummary::default();
            run.read_all()?.iter().for_each(|event| summary.ingest(event));
            say!("{}", summary.status_line(label, run.liveness()));
        }
        return Ok(());
    }
    let (sender, receiver) = std::sync::mpsc::channel();
    let cancel = Arc::new(AtomicBool::new(false));
    let stop = cancel.clone();
    std::thread::scope(|scope| {
        let reader = scope.spawn(move || follow_runs(runs, &stop, |update| sender.send(update).is_ok()));
        run_overlay(receiver, cancel.clone(), labels).context("terminal view failed")?;
        cancel.store(true, Ordering::Relaxed);
        reader.join().map_err(|_| anyhow::anyhow!("the metrics reader panicked"))??;
        Ok(())
    })
}

fn watch_one(global: &GlobalArgs, mut runs: Vec<WatchedRun>, arg: &std::path::Path) -> anyhow::Result<()> {
    if !global.use_tui() {
        let run = &mut runs[0];
        return print_summary(&run.read_all()?, &unfinished_status(run.liveness(), &run_dir(arg)));
    }
    let (sender, receiver) = std::sync::mpsc::channel();
    let cancel = Arc::new(AtomicBool::new(false));
    let stop = cancel.clone();
    let title = format!("watch {}", arg.display());
    std::thread::scope(|scope| {
        let reader = scope.spawn(move || {
            follow_runs(runs, &stop, |update| match update {
                RunUpdate::Event { event, .. } => sender.send(event).is_ok(),
                RunUpdate::Liveness { .. } => true,
            })
        });
        // Watching is for reading: the view stays until q, even after the run ends.
        let options = LiveOptions { hold: true, grace: Duration::ZERO };
        run_live(receiver, cancel.clone(), &title, options).context("terminal view failed")?;
        cancel.store(true, Ordering::Relaxed);
        reader.join().map_err(|_| anyhow::anyhow!("the metrics reader panicked"))??;
        Ok(())
    })
}

/// What a stream without its end means: a training run's lock tells running from stopped; other runs (eval
/// reports) keep no lock, so for them it cannot be told.
fn unfinished_status(liveness: Liveness, dir: &std::path::Path) -> String {
    match liveness {
        Liveness::Running => "running".to_string(),
        Liveness::Stopped => format!("stopped; continue with `mbrl train --resume {}`", dir.display()),
        Liveness::Unknown => "running (or stopped without finishing)".to_string(),
    }
}

/// Last value of each scalar, the latest progress, messages, the latest text of each text panel and
/// whether the run finished.
fn print_summary(events: &[Event], unfinished: &str) -> anyhow::Result<()> {
    let mut last: BTreeMap<&str, (u64, f64, usize)> = BTreeMap::new();
    let mut progress: Vec<(&str, u64, u64)> = Vec::new();
    // Printed once at the end, not as they come: a board redrawn every step would flood the summary.
    let mut texts: Vec<(&str, &str)> = Vec::new();
    let mut status = unfinished;
    for event in events {
        match event {
            Event::Layout { title, .. } => say!("{title}"),
            Event::Scalar { name, step, value } => {
                let entry = last.entry(name).or_insert((0, 0.0, 0));
                *entry = (*step, *value, entry.2 + 1);
            }
            Event::Progress { phase, done, total } => match progress.iter_mut().find(|p| p.0 == phase) {
                Some(p) => (p.1, p.2) = (*done, *total),
                None => progress.push((phase, *done, *total)),
            },
            Event::Message { text } => say!("{text}"),
            Event::Text { panel, text } => match texts.iter_mut().find(|t| t.0 == panel) {
                Some(t) => t.1 = text,
                None => texts.push((panel, text)),
            },
            Event::Finished { ok } => status = if *ok { "finished" } else { "failed" },
        }
    }
    for (phase, done, total) in progress {
        say!("{phase}: {done}/{total}");
    }
    for (name, (step, value, count)) in last {
        say!("{name}: {value:.6} at step {step} ({count} points)");
    }
    for (panel, text) in texts {
        say!("== {panel} ==");
        say!("{}", text.trim_end_matches('\n'));
    }
    say!("status: {status}");
    Ok(())
}
