//! The state of `mbrl watch` over several runs: every run's metric histories, kept apart per run so that the
//! same-named curves can be drawn over each other, and each run's status. No terminal I/O here.

use std::collections::{BTreeMap, BTreeSet};

use crossterm::event::KeyEvent;

use super::keys::{action_for, Action};
use super::series::Series;
use crate::run::follow::RunUpdate;
use crate::run::watched::{Liveness, RunSummary};

/// One followed run.
pub(crate) struct RunTrack {
    pub(crate) label: String,
    pub(crate) summary: RunSummary,
    pub(crate) liveness: Liveness,
    history: BTreeMap<String, Series>,
}

impl RunTrack {
    pub(crate) fn status(&self) -> String {
        self.summary.status(self.liveness)
    }

    pub(crate) fn series(&self, metric: &str) -> Option<&Series> {
        self.history.get(metric)
    }
}

pub struct Overlay {
    runs: Vec<RunTrack>,
    /// The first metric on screen; the keys move it when the metrics do not all fit.
    first: usize,
    /// The reader stopped before every run finished (an unreadable line): nothing more will come.
    ended: bool,
}

impl Overlay {
    pub fn new(labels: Vec<String>) -> Self {
        let runs = labels
            .into_iter()
            .map(|label| RunTrack {
                label,
                summary: RunSummary::default(),
                liveness: Liveness::Unknown,
                history: BTreeMap::new(),
            })
            .collect();
        Overlay { runs, first: 0, ended: false }
    }

    pub fn update(&mut self, update: &RunUpdate) {
        match update {
            RunUpdate::Event { run, event } => {
                let Some(track) = self.runs.get_mut(*run) else { return };
                track.summary.ingest(event);
                if let crate::run::Event::Scalar { name, step, value } = event {
                    track.history.entry(name.clone()).or_insert_with(Series::indexed_on_rewind).push(*step, *value);
                }
            }
            RunUpdate::Liveness { run, liveness } => {
                if let Some(track) = self.runs.get_mut(*run) {
                    track.liveness = *liveness;
                }
            }
        }
    }

    /// Every metric any run recorded, sorted by name: one panel each.
    pub fn metric_names(&self) -> Vec<&str> {
        let names: BTreeSet<&str> = self.runs.iter().flat_map(|r| r.history.keys().map(String::as_str)).collect();
        names.into_iter().collect()
    }

    pub(crate) fn runs(&self) -> &[RunTrack] {
        &self.runs
    }

    /// The index of the first metric shown, kept within the metrics there are.
    pub(crate) fn first(&self) -> usize {
        self.first.min(self.metric_names().len().saturating_sub(1))
    }

    /// Every run has sent its end.
    pub fn all_finished(&self) -> bool {
        self.runs.iter().all(|r| r.summary.finished.is_some())
    }

    pub(crate) fn mark_ended(&mut self) {
        self.ended = true;
    }

    /// Whether the reader gave up on runs that had not finished.
    pub(crate) fn reading_stopped(&self) -> bool {
        self.ended && !self.all_finished()
    }

    /// Returns true when the user asked to quit.
    pub fn handle_key(&mut self, key: KeyEvent) -> bool {
        let count = self.metric_names().len();
        match action_for(key) {
            Some(Action::Quit) => return true,
            Some(Action::NextMetric) if count > 0 => self.first = (self.first() + 1) % count,
            Some(Action::PreviousMetric) if count > 0 => self.first = (self.first() + count - 1) % count,
            _ => {}
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::Event;
    use crossterm::event::{KeyCode, KeyModifiers};

    fn event(run: usize, event: Event) -> RunUpdate {
        RunUpdate::Event { run, event }
    }

    #[test]
    fn same_named_metrics_of_several_runs_merge_into_one_panel_each() {
        let mut overlay = Overlay::new(vec!["a".into(), "b".into()]);
        overlay.update(&event(0, Event::scalar("train/loss", 1, 2.0)));
        overlay.update(&event(1, Event::scalar("train/loss", 5, 1.0)));
        overlay.update(&event(1, Event::scalar("valid/loss", 5, 0.5)));
        overlay.update(&event(0, Event::scalar("train/loss", 2, 1.5)));
        assert_eq!(overlay.metric_names(), vec!["train/loss", "valid/loss"]);
        let points = |run: usize, metric| overlay.runs()[run].series(metric).map(|s| s.points().to_vec());
        assert_eq!(points(0, "train/loss"), Some(vec![(1.0, 2.0), (2.0, 1.5)]));
        assert_eq!(points(1, "train/loss"), Some(vec![(5.0, 1.0)]));
        assert_eq!(points(0, "valid/loss"), None, "run a has no validation yet");
    }

    #[test]
    fn each_run_keeps_its_own_status() {
        let mut overlay = Overlay::new(vec!["a".into(), "b".into()]);
        overlay.update(&event(0, Event::progress("train", 3, 10)));
        overlay.update(&RunUpdate::Liveness { run: 0, liveness: Liveness::Running });
        overlay.update(&RunUpdate::Liveness { run: 1, liveness: Liveness::Stopped });
        assert!(!overlay.all_finished());
        overlay.update(&event(0, Event::Finished { ok: true }));
        overlay.update(&event(1, Event::Finished { ok: false }));
        overlay.update(&event(7, Event::Finished { ok: true }));
        let statuses: Vec<String> = overlay.runs().iter().map(RunTrack::status).collect();
        assert_eq!(statuses, vec!["finished · train 3/10", "failed"]);
        assert!(overlay.all_finished());
    }

    #[test]
    fn keys_scroll_through_the_metrics_and_wrap() {
        let mut overlay = Overlay::new(vec!["a".into()]);
        let key = |code| KeyEvent::new(code, KeyModifiers::NONE);
        assert!(!overlay.handle_key(key(KeyCode::Right)), "no metrics: nothing to scroll");
        for name in ["a", "b", "c"] {
            overlay.update(&event(0, Event::scalar(name, 0, 1.0)));
        }
        overlay.handle_key(key(KeyCode::Right));
        assert_eq!(overlay.first(), 1);
        overlay.handle_key(key(KeyCode::Left));
        overlay.handle_key(key(KeyCode::Left));
        assert_eq!(overlay.first(), 2);
        assert!(overlay.handle_key(key(KeyCode::Char('q'))));
    }
}
