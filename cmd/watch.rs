//! `mbrl watch`: follow a run's metrics in the live view, or summarise them when not on a terminal.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use mbrl::run::dir::METRICS_FILE;
use mbrl::run::follow::{latest_progress_only, MetricsFollower};
use mbrl::run::lock::{RunLock, LOCK_FILE};
use mbrl::run::Event;
use mbrl::tui::{run_live, LiveOptions};

use crate::common::GlobalArgs;

/// Follow a running or finished run (training or eval) in the live view.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl watch reports/quick/pendulum-swingup
  mbrl watch models/my-run --no-tui      # print a summary of the metrics instead")]
pub struct WatchArgs {
    /// Run directory (holds metrics.jsonl) or the metrics file itself.
    run_dir: PathBuf,
}

pub fn run(global: &GlobalArgs, args: WatchArgs) -> anyhow::Result<()> {
    let path = if args.run_dir.is_dir() { args.run_dir.join(METRICS_FILE) } else { args.run_dir.clone() };
    let mut follower = MetricsFollower::open(&path)?;
    if !global.use_tui() {
        return print_summary(&follower.poll()?, &unfinished_status(&path));
    }
    let (sender, receiver) = std::sync::mpsc::channel();
    let cancel = Arc::new(AtomicBool::new(false));
    let stop = cancel.clone();
    let title = format!("watch {}", args.run_dir.display());
    std::thread::scope(|scope| {
        let reader = scope.spawn(move || -> mbrl::Result<()> {
            let mut backlog = true;
            while !stop.load(Ordering::Relaxed) {
                let mut events = follower.poll()?;
                if std::mem::take(&mut backlog) {
                    events = latest_progress_only(events);
                }
                for event in events {
                    let finished = matches!(event, Event::Finished { .. });
                    if sender.send(event).is_err() || finished {
                        return Ok(());
                    }
                }
                std::thread::sleep(Duration::from_millis(200));
            }
            Ok(())
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
fn unfinished_status(metrics: &std::path::Path) -> String {
    let dir = metrics.parent().unwrap_or(std::path::Path::new("."));
    if RunLock::is_held(dir) {
        "running".to_string()
    } else if dir.join(LOCK_FILE).is_file() {
        format!("stopped; continue with `mbrl train --resume {}`", dir.display())
    } else {
        "running (or stopped without finishing)".to_string()
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
