//! What `mbrl watch` knows of each run it follows: a name for the legend, whether the run is still going, how
//! far it got and the last value of each metric, folded from its events and its lock.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::dir::METRICS_FILE;
use super::event::Event;
use super::lock::{RunLock, LOCK_FILE};

/// A run directory's metrics file; a path that is not a directory is taken as the metrics file itself.
pub fn metrics_path(arg: &Path) -> PathBuf {
    if arg.is_dir() {
        arg.join(METRICS_FILE)
    } else {
        arg.to_path_buf()
    }
}

/// The run directory of a `watch` argument: the directory itself, or the folder holding a metrics file.
pub fn run_dir(arg: &Path) -> PathBuf {
    if arg.is_dir() {
        return arg.to_path_buf();
    }
    arg.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf()
}

/// Legend names for runs: each directory's own name, lengthened by its parents where two runs would share it
/// (`x/seed1/run` and `y/seed1/run` keep `x/` and `y/`), and numbered when one directory is named twice.
pub fn run_labels(dirs: &[PathBuf]) -> Vec<String> {
    let parts: Vec<Vec<String>> = dirs
        .iter()
        .map(|dir| {
            let absolute = std::path::absolute(dir).unwrap_or_else(|_| dir.clone());
            let mut names: Vec<String> = absolute
                .components()
                .filter_map(|c| match c {
                    std::path::Component::Normal(name) => Some(name.to_string_lossy().into_owned()),
                    _ => None,
                })
                .collect();
            names.reverse();
            if names.is_empty() {
                names.push(dir.display().to_string());
            }
            names
        })
        .collect();
    let label = |names: &[String], depth: usize| {
        let take = depth.min(names.len());
        names[..take].iter().rev().cloned().collect::<Vec<_>>().join("/")
    };
    let mut depth = vec![1; dirs.len()];
    // Lengthen every label in a clash until it is unique or cannot grow any more.
    loop {
        let labels: Vec<String> = parts.iter().zip(&depth).map(|(names, &d)| label(names, d)).collect();
        let mut grew = false;
        for i in 0..labels.len() {
            // The same directory named twice cannot be told apart by its parents: it is numbered below.
            let clashes = (0..labels.len()).any(|j| labels[j] == labels[i] && parts[j] != parts[i]);
            if clashes && depth[i] < parts[i].len() {
                depth[i] += 1;
                grew = true;
            }
        }
        if !grew {
            break;
        }
    }
    let labels: Vec<String> = parts.iter().zip(&depth).map(|(names, &d)| label(names, d)).collect();
    labels
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let same: Vec<usize> = (0..labels.len()).filter(|&j| labels[j] == *l).collect();
            match same.iter().position(|&j| j == i) {
                Some(k) if same.len() > 1 => format!("{l} #{}", k + 1),
                _ => l.clone(),
            }
        })
        .collect()
}

/// Whether a run without its `finished` event is still being written, told by its lock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Liveness {
    Running,
    /// The lock is there but free: the run was stopped (or killed) before it finished.
    Stopped,
    /// No lock: eval reports keep none, so running and stopped cannot be told apart.
    Unknown,
}

impl Liveness {
    pub fn of(dir: &Path) -> Self {
        if RunLock::is_held(dir) {
            Liveness::Running
        } else if dir.join(LOCK_FILE).is_file() {
            Liveness::Stopped
        } else {
            Liveness::Unknown
        }
    }

    pub fn describe(self) -> &'static str {
        match self {
            Liveness::Running => "running",
            Liveness::Stopped => "stopped",
            Liveness::Unknown => "unfinished",
        }
    }
}

/// A run's events folded to what its status line says.
#[derive(Clone, Debug, Default)]
pub struct RunSummary {
    /// The job's title from its layout (`train PETS on pendulum`), which tells methods apart.
    pub title: Option<String>,
    /// Per metric: the last step, the last value and how many points came.
    pub last: BTreeMap<String, (u64, f64, usize)>,
    /// Each phase's latest progress, in order of first appearance.
    pub progress: Vec<(String, u64, u64)>,
    /// `Some(ok)` once the run sent its `finished` event.
    pub finished: Option<bool>,
}

impl RunSummary {
    pub fn ingest(&mut self, event: &Event) {
        match event {
            Event::Layout { title, .. } if !title.is_empty() => self.title = Some(title.clone()),
            Event::Scalar { name, step, value } => {
                let entry = self.last.entry(name.clone()).or_insert((0, 0.0, 0));
                *entry = (*step, *value, entry.2 + 1);
            }
            Event::Progress { phase, done, total } => match self.progress.iter_mut().find(|p| p.0 == *phase) {
                Some(p) => (p.1, p.2) = (*done, *total),
                None => self.progress.push((phase.clone(), *done, *total)),
            },
            Event::Finished { ok } => self.finished = Some(*ok),
            _ => {}
        }
    }

    /// `finished`, `failed`, or how the lock says an unfinished run stands.
    pub fn state(&self, liveness: Liveness) -> &'static str {
        match self.finished {
            Some(true) => "finished",
            Some(false) => "failed",
            None => liveness.describe(),
        }
    }

    /// The outer phase's progress (`train 120/300`): the first phase a run reports counts its whole work
    /// (training steps, evaluation episodes), later ones the parts inside it.
    pub fn position(&self) -> Option<String> {
        self.progress.first().map(|(phase, done, total)| format!("{phase} {done}/{total}"))
    }

    /// `finished · train 300/300`: the state and, where the run reports progress, how far it got.
    pub fn status(&self, liveness: Liveness) -> String {
        match self.position() {
            Some(position) => format!("{} · {position}", self.state(liveness)),
            None => self.state(liveness).to_string(),
        }
    }

    /// One line for `watch --no-tui` over several runs: the label, the status, and each metric's last value.
    pub fn status_line(&self, label: &str, liveness: Liveness) -> String {
        let mut line = format!("{label}: {}", self.status(liveness));
        for (i, (name, (step, value, _))) in self.last.iter().enumerate() {
            let _ = write!(line, "{} {name} {value:.6} at step {step}", if i == 0 { ";" } else { "," });
        }
        line
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(paths: &[&str]) -> Vec<String> {
        run_labels(&paths.iter().map(PathBuf::from).collect::<Vec<_>>())
    }

    #[test]
    fn labels_are_directory_names_lengthened_only_where_they_clash() {
        assert_eq!(labels(&["models/a", "models/b"]), vec!["a", "b"]);
        assert_eq!(labels(&["x/seed1/run", "y/seed1/run", "z"]), vec!["x/seed1/run", "y/seed1/run", "z"]);
        assert_eq!(labels(&["x/run", "y/run", "x/other"]), vec!["x/run", "y/run", "other"]);
        assert_eq!(labels(&["m/run", "./m/run/"]), vec!["run #1", "run #2"]);
    }

    #[test]
    fn status_line_names_state_progress_and_last_values() {
        let mut summary = RunSummary::default();
        for event in [
            Event::Layout { title: "train PETS on pendulum".into(), panels: vec![] },
            Event::scalar("train/loss", 1, 0.5),
            Event::progress("train", 1, 300),
            Event::scalar("train/loss", 2, 0.25),
            Event::progress("train", 2, 300),
            Event::progress("inner", 5, 9),
            Event::scalar("valid/loss", 2, 0.125),
        ] {
            summary.ingest(&event);
        }
        assert_eq!(summary.title.as_deref(), Some("train PETS on pendulum"));
        assert_eq!(
            summary.status_line("runA", Liveness::Stopped),
            "runA: stopped · train 2/300; train/loss 0.250000 at step 2, valid/loss 0.125000 at step 2"
        );
        assert_eq!(summary.status(Liveness::Running), "running · train 2/300");
        summary.ingest(&Event::Finished { ok: true });
        assert_eq!(summary.status(Liveness::Stopped), "finished · train 2/300");
        assert_eq!(RunSummary::default().status_line("e", Liveness::Unknown), "e: unfinished");
    }

    #[test]
    fn liveness_reads_the_lock() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(Liveness::of(dir.path()), Liveness::Unknown);
        let lock = RunLock::acquire(dir.path()).unwrap();
        assert_eq!(Liveness::of(dir.path()), Liveness::Running);
        drop(lock);
        assert_eq!(Liveness::of(dir.path()), Liveness::Stopped);
    }

    #[test]
    fn a_metrics_file_argument_names_its_folder() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join(METRICS_FILE);
        assert_eq!(metrics_path(dir.path()), file);
        assert_eq!(metrics_path(&file), file);
        assert_eq!(run_dir(&file), dir.path());
        assert_eq!(run_dir(Path::new("metrics.jsonl")), Path::new("."));
    }
}
