//! Reads a run's `metrics.jsonl` incrementally, for `mbrl watch` on a run that may still be writing it.

use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use super::event::Event;
use super::watched::{metrics_path, run_dir, Liveness};
use crate::error::{Error, Result};

/// How often a followed run's file and lock are read again.
const POLL_INTERVAL: Duration = Duration::from_millis(200);

pub struct MetricsFollower {
    path: PathBuf,
    offset: u64,
    line_number: usize,
    /// Bytes after the last newline: a line the writer has not finished yet.
    pending: Vec<u8>,
}

impl MetricsFollower {
    pub fn open(path: &Path) -> Result<Self> {
        if !path.is_file() {
            return Err(Error::bad_file(path, "not found; expected a run's metrics.jsonl"));
        }
        Ok(MetricsFollower { path: path.to_path_buf(), offset: 0, line_number: 0, pending: Vec::new() })
    }

    /// Events from complete lines written since the last call.
    pub fn poll(&mut self) -> Result<Vec<Event>> {
        let mut file = std::fs::File::open(&self.path).map_err(|e| Error::io(&self.path, e))?;
        file.seek(SeekFrom::Start(self.offset)).map_err(|e| Error::io(&self.path, e))?;
        let mut fresh = Vec::new();
        file.read_to_end(&mut fresh).map_err(|e| Error::io(&self.path, e))?;
        self.offset += fresh.len() as u64;
        self.pending.extend_from_slice(&fresh);
        let Some(last_newline) = self.pending.iter().rposition(|&b| b == b'\n') else {
            return Ok(Vec::new());
        };
        let complete: Vec<u8> = self.pending.drain(..=last_newline).collect();
        let mut events = Vec::new();
        for line in complete.split(|&b| b == b'\n') {
            if line.is_empty() {
                continue;
            }
            self.line_number += 1;
            let event = serde_json::from_slice(line).map_err(|e| {
                Error::bad_file(&self.path, format!("line {}: not a metrics event ({e})", self.line_number))
            })?;
            events.push(event);
        }
        Ok(events)
    }
}

/// What a followed run reported: an event from its file, or a change of its lock's state.
#[derive(Clone, Debug, PartialEq)]
pub enum RunUpdate {
    Event { run: usize, event: Event },
    Liveness { run: usize, liveness: Liveness },
}

/// One run `watch` follows: its directory (for the lock) and its metrics file.
pub struct WatchedRun {
    dir: PathBuf,
    follower: MetricsFollower,
    finished: bool,
    liveness: Option<Liveness>,
}

impl WatchedRun {
    /// A run directory, or a metrics file itself.
    pub fn open(arg: &Path) -> Result<Self> {
        let follower = MetricsFollower::open(&metrics_path(arg))?;
        Ok(WatchedRun { dir: run_dir(arg), follower, finished: false, liveness: None })
    }

    /// Everything written so far, for a summary of a run that is not followed further.
    pub fn read_all(&mut self) -> Result<Vec<Event>> {
        self.follower.poll()
    }

    pub fn liveness(&self) -> Liveness {
        Liveness::of(&self.dir)
    }
}

/// Follows `runs` until every one has finished, `stop` is set, or `send` returns false (its receiver is gone),
/// sending each new event and each change of a run's lock. The backlog each run has at the start comes with
/// only its latest progress (see [`latest_progress_only`]).
pub fn follow_runs(
    mut runs: Vec<WatchedRun>,
    stop: &AtomicBool,
    mut send: impl FnMut(RunUpdate) -> bool,
) -> Result<()> {
    let mut backlog = true;
    while !stop.load(Ordering::Relaxed) {
        for (run, watched) in runs.iter_mut().enumerate().filter(|(_, w)| !w.finished) {
            let mut events = watched.follower.poll()?;
            if backlog {
                events = latest_progress_only(events);
            }
            for event in events {
                watched.finished |= matches!(event, Event::Finished { .. });
                if !send(RunUpdate::Event { run, event }) {
                    return Ok(());
                }
            }
            let liveness = watched.liveness();
            if !watched.finished && watched.liveness != Some(liveness) {
                watched.liveness = Some(liveness);
                if !send(RunUpdate::Liveness { run, liveness }) {
                    return Ok(());
                }
            }
        }
        backlog = false;
        if runs.iter().all(|w| w.finished) {
            return Ok(());
        }
        std::thread::sleep(POLL_INTERVAL);
    }
    Ok(())
}

/// A run's backlog with each phase's progress reduced to its latest update, in place. Replayed at once,
/// the earlier updates would be timed as arriving within a millisecond and show absurd rates; from the
/// latest alone the view starts each phase's clock when the watch starts, so a finished run shows no
/// rate and a running one the rate it has from then on.
pub fn latest_progress_only(events: Vec<Event>) -> Vec<Event> {
    let mut last_update = std::collections::HashMap::new();
    for (i, event) in events.iter().enumerate() {
        if let Event::Progress { phase, .. } = event {
            last_update.insert(phase.clone(), i);
        }
    }
    events
        .into_iter()
        .enumerate()
        .filter(|(i, event)| match event {
            Event::Progress { phase, .. } => last_update.get(phase) == Some(i),
            _ => true,
        })
        .map(|(_, event)| event)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn follows_appended_lines_and_waits_for_partial_ones() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("metrics.jsonl");
        let mut f = std::fs::File::create(&path).unwrap();
        writeln!(f, "{}", serde_json::to_string(&Event::scalar("a", 1, 2.0)).unwrap()).unwrap();
        write!(f, "{{\"kind\":\"fin").unwrap();
        f.flush().unwrap();
        let mut follower = MetricsFollower::open(&path).unwrap();
        assert_eq!(follower.poll().unwrap(), vec![Event::scalar("a", 1, 2.0)]);
        writeln!(f, "ished\",\"ok\":true}}").unwrap();
        f.flush().unwrap();
        assert_eq!(follower.poll().unwrap(), vec![Event::Finished { ok: true }]);
        assert!(follower.poll().unwrap().is_empty());
    }

    #[test]
    fn malformed_line_names_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("metrics.jsonl");
        std::fs::write(&path, "{\"kind\":\"finished\",\"ok\":true}\nnot json\n").unwrap();
        let err = MetricsFollower::open(&path).unwrap().poll().unwrap_err().to_string();
        assert!(err.contains("metrics.jsonl") && err.contains("line 2"), "{err}");
    }

    #[test]
    fn following_several_runs_tags_events_and_ends_when_all_finished() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, events: &[Event]| {
            let run = dir.path().join(name);
            std::fs::create_dir(&run).unwrap();
            let lines: Vec<String> = events.iter().map(|e| serde_json::to_string(e).unwrap() + "\n").collect();
            std::fs::write(run.join("metrics.jsonl"), lines.concat()).unwrap();
            WatchedRun::open(&run).unwrap()
        };
        let a =
            write("a", &[Event::progress("train", 1, 9), Event::progress("train", 2, 9), Event::Finished { ok: true }]);
        let b = write("b", &[Event::scalar("loss", 4, 1.0), Event::Finished { ok: false }]);
        let mut updates = Vec::new();
        follow_runs(vec![a, b], &AtomicBool::new(false), |u| {
            updates.push(u);
            true
        })
        .unwrap();
        let event = |run, event| RunUpdate::Event { run, event };
        assert_eq!(
            updates,
            vec![
                event(0, Event::progress("train", 2, 9)),
                event(0, Event::Finished { ok: true }),
                event(1, Event::scalar("loss", 4, 1.0)),
                event(1, Event::Finished { ok: false }),
            ]
        );
    }

    #[test]
    fn an_unfinished_run_reports_its_lock_once_and_stops_when_told() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("metrics.jsonl"), "").unwrap();
        let run = WatchedRun::open(dir.path()).unwrap();
        let stop = AtomicBool::new(false);
        let mut updates = Vec::new();
        std::thread::scope(|scope| {
            // Several polls pass before the stop: an unchanged lock must not be sent again.
            scope.spawn(|| {
                std::thread::sleep(POLL_INTERVAL * 4);
                stop.store(true, Ordering::Relaxed);
            });
            follow_runs(vec![run], &stop, |u| {
                updates.push(u);
                true
            })
            .unwrap();
        });
        assert_eq!(updates, vec![RunUpdate::Liveness { run: 0, liveness: Liveness::Unknown }]);
    }

    #[test]
    fn a_backlog_keeps_only_the_latest_progress_of_each_phase() {
        let events = vec![
            Event::progress("train", 1, 10),
            Event::scalar("loss", 1, 0.5),
            Event::progress("eval", 1, 2),
            Event::progress("train", 2, 10),
            Event::scalar("loss", 2, 0.4),
        ];
        assert_eq!(
            latest_progress_only(events),
            vec![
                Event::scalar("loss", 1, 0.5),
                Event::progress("eval", 1, 2),
                Event::progress("train", 2, 10),
                Event::scalar("loss", 2, 0.4),
            ]
        );
    }
}
