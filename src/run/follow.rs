//! Reads a run's `metrics.jsonl` incrementally, for `mbrl watch` on a run that may still be writing it.

use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::event::Event;
use crate::error::{Error, Result};

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
