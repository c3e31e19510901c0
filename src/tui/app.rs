//! The state of the live view, folded from the event stream. No terminal I/O here, so every rule about
//! what the user sees can be unit-tested.

use std::collections::{BTreeMap, VecDeque};
use std::time::Instant;

use crossterm::event::KeyEvent;

use super::keys::{action_for, Action};
use super::panel::Panel;
use super::series::Series;
use crate::run::monitor::format_progress;
use crate::run::{Event, PanelSpec};

/// Messages kept for the Messages panel; only the newest few fit on screen anyway.
const MESSAGE_CAP: usize = 50;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Status {
    Running,
    Done,
    Failed,
    /// The stream stopped without a `Finished` event (the job hung up or crashed).
    Ended,
}

/// The current phase. Both instants come from ingestion so that rate and ETA are a function of the
/// events alone, which keeps rendering deterministic under `ingest_at`.
#[derive(Clone, Debug)]
pub(crate) struct Progress {
    phase: String,
    done: u64,
    total: u64,
    started: Instant,
    updated: Instant,
}

impl Progress {
    pub(crate) fn ratio(&self) -> f64 {
        if self.total == 0 {
            return 0.0;
        }
        (self.done as f64 / self.total as f64).clamp(0.0, 1.0)
    }

    /// `phase: done/total (pct) rate/s, ETA`, the same line the console prints.
    pub(crate) fn summary(&self) -> String {
        let elapsed = self.updated.duration_since(self.started).as_secs_f64();
        format_progress(&self.phase, self.done, self.total, elapsed)
    }

    /// A counter going backwards means the phase was restarted, so its rate must be measured afresh.
    fn continues(&self, phase: &str, done: u64) -> bool {
        self.phase == phase && done >= self.done
    }
}

/// Everything the live view shows, built from events and keys alone.
pub struct App {
    title: String,
    status: Status,
    progress: Option<Progress>,
    /// Every metric's full (capped) history; a BTreeMap so metric order is by name, stable across runs.
    history: BTreeMap<String, Series>,
    /// Tracked by name, not index, so metrics appearing later do not move the user's selection.
    selected: Option<String>,
    panels: Vec<Panel>,
    messages: VecDeque<String>,
}

impl App {
    pub fn new(title: &str) -> Self {
        App {
            title: title.to_string(),
            status: Status::Running,
            progress: None,
            history: BTreeMap::new(),
            selected: None,
            panels: Vec::new(),
            messages: VecDeque::new(),
        }
    }

    pub fn ingest(&mut self, event: &Event) {
        self.ingest_at(event, Instant::now());
    }

    pub fn ingest_at(&mut self, event: &Event, now: Instant) {
        match event {
            Event::Layout { title, panels } => self.apply_layout(title, panels),
            Event::Scalar { name, step, value } => self.record_scalar(name, *step, *value),
            Event::Progress { phase, done, total } => self.update_progress(phase, *done, *total, now),
            Event::Message { text } => self.push_message(text),
            Event::Finished { ok } => self.status = if *ok { Status::Done } else { Status::Failed },
        }
    }

    /// Returns true when the user asked to quit.
    pub fn handle_key(&mut self, key: KeyEvent) -> bool {
        match action_for(key) {
            Some(Action::Quit) => return true,
            Some(Action::NextMetric) => self.cycle_metric(true),
            Some(Action::PreviousMetric) => self.cycle_metric(false),
            None => {}
        }
        false
    }

    pub fn is_finished(&self) -> bool {
        self.status != Status::Running
    }

    pub fn selected_metric(&self) -> Option<&str> {
        self.selected.as_deref()
    }

    /// All metrics seen so far, sorted by name.
    pub fn metric_names(&self) -> Vec<&str> {
        self.history.keys().map(String::as_str).collect()
    }

    /// The sender hung up; a stream that ended without `Finished` must not look like it is still running.
    pub(crate) fn mark_ended(&mut self) {
        if self.status == Status::Running {
            self.status = Status::Ended;
        }
    }

    pub(crate) fn title(&self) -> &str {
        &self.title
    }

    pub(crate) fn status(&self) -> Status {
        self.status
    }

    pub(crate) fn progress(&self) -> Option<&Progress> {
        self.progress.as_ref()
    }

    /// The selected metric's name, its history, and its 1-based position among all metrics.
    pub(crate) fn selected_series(&self) -> Option<(&str, &Series, usize)> {
        let name = self.selected.as_deref()?;
        let (index, (name, series)) = self.history.iter().enumerate().find(|(_, (n, _))| *n == name)?;
        Some((name, series, index + 1))
    }

    pub(crate) fn metric_count(&self) -> usize {
        self.history.len()
    }

    pub(crate) fn panels(&self) -> &[Panel] {
        &self.panels
    }

    /// Messages, oldest first.
    pub(crate) fn messages(&self) -> impl DoubleEndedIterator<Item = &str> + ExactSizeIterator {
        self.messages.iter().map(String::as_str)
    }

    fn apply_layout(&mut self, title: &str, panels: &[PanelSpec]) {
        if !title.is_empty() {
            self.title = title.to_string();
        }
        self.panels = panels.iter().cloned().map(Panel::new).collect();
    }

    fn record_scalar(&mut self, name: &str, step: u64, value: f64) {
        self.history.entry(name.to_string()).or_default().push(step, value);
        for panel in &mut self.panels {
            panel.record(name, step, value);
        }
        if self.selected.is_none() {
            self.selected = Some(name.to_string());
        }
    }

    fn update_progress(&mut self, phase: &str, done: u64, total: u64, now: Instant) {
        let started = match &self.progress {
            Some(p) if p.continues(phase, done) => p.started,
            _ => now,
        };
        self.progress = Some(Progress { phase: phase.to_string(), done, total, started, updated: now });
    }

    fn push_message(&mut self, text: &str) {
        if self.messages.len() == MESSAGE_CAP {
            self.messages.pop_front();
        }
        self.messages.push_back(text.to_string());
    }

    fn cycle_metric(&mut self, forward: bool) {
        let names = self.metric_names();
        let count = names.len();
        if count == 0 {
            return;
        }
        let current = self.selected.as_deref().and_then(|s| names.iter().position(|n| *n == s));
        let next = match (current, forward) {
            (None, _) => 0,
            (Some(i), true) => (i + 1) % count,
            (Some(i), false) => (i + count - 1) % count,
        };
        self.selected = Some(names[next].to_string());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crossterm::event::{KeyCode, KeyModifiers};
    use std::time::Duration;

    fn key(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    fn app_with_metrics(names: &[&str]) -> App {
        let mut app = App::new("test");
        for (i, name) in names.iter().enumerate() {
            app.ingest(&Event::scalar(*name, i as u64, 1.0));
        }
        app
    }

    fn pendulum_layout() -> Event {
        Event::Layout {
            title: "pendulum run".into(),
            panels: vec![PanelSpec {
                title: "pendulum".into(),
                x_label: "t".into(),
                series: vec!["pendulum/angle".into(), "pendulum/action".into()],
                restart_on_rewind: true,
            }],
        }
    }

    #[test]
    fn metrics_are_sorted_and_first_seen_is_selected() {
        let app = app_with_metrics(&["loss", "cem/best_cost", "loss"]);
        assert_eq!(app.metric_names(), vec!["cem/best_cost", "loss"]);
        assert_eq!(app.selected_metric(), Some("loss"));
    }

    #[test]
    fn keys_cycle_metrics_both_ways_and_wrap() {
        let mut app = app_with_metrics(&["a", "b", "c"]);
        assert_eq!(app.selected_metric(), Some("a"));
        assert!(!app.handle_key(key(KeyCode::Right)));
        assert_eq!(app.selected_metric(), Some("b"));
        app.handle_key(key(KeyCode::Tab));
        app.handle_key(key(KeyCode::Char('j')));
        assert_eq!(app.selected_metric(), Some("a"));
        app.handle_key(key(KeyCode::Left));
        assert_eq!(app.selected_metric(), Some("c"));
        app.handle_key(key(KeyCode::Char('k')));
        app.handle_key(key(KeyCode::BackTab));
        assert_eq!(app.selected_metric(), Some("a"));
    }

    #[test]
    fn cycling_without_metrics_is_harmless() {
        let mut app = App::new("empty");
        assert!(!app.handle_key(key(KeyCode::Right)));
        assert_eq!(app.selected_metric(), None);
    }

    #[test]
    fn quit_keys() {
        let mut app = App::new("t");
        assert!(app.handle_key(key(KeyCode::Char('q'))));
        assert!(app.handle_key(key(KeyCode::Esc)));
        assert!(app.handle_key(KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL)));
        assert!(!app.handle_key(key(KeyCode::Char('x'))));
    }

    #[test]
    fn rewind_clears_the_panel_copy_but_not_the_history() {
        let mut app = App::new("t");
        app.ingest(&pendulum_layout());
        for step in 0..5 {
            app.ingest(&Event::scalar("pendulum/angle", step, step as f64));
        }
        app.ingest(&Event::scalar("pendulum/angle", 0, 9.0));

        let (_, history, _) = app.selected_series().expect("angle is selected");
        assert_eq!(history.points().len(), 6);
        let (_, panel_copy) = app.panels()[0].series().next().expect("angle series");
        assert_eq!(panel_copy.points(), &[(0.0, 9.0)]);
    }

    #[test]
    fn layout_sets_title_and_panels() {
        let mut app = App::new("before");
        app.ingest(&pendulum_layout());
        assert_eq!(app.title(), "pendulum run");
        assert_eq!(app.panels().len(), 1);
        assert_eq!(app.panels()[0].spec().title, "pendulum");
    }

    #[test]
    fn progress_rate_is_measured_from_the_phase_start() {
        let mut app = App::new("t");
        let t0 = Instant::now();
        app.ingest_at(&Event::progress("train", 0, 150), t0);
        app.ingest_at(&Event::progress("train", 50, 150), t0 + Duration::from_secs(10));
        let progress = app.progress().expect("progress");
        assert_eq!(progress.summary(), "train: 50/150 (33%) 5.0/s, ETA 20s");
        assert!((progress.ratio() - 1.0 / 3.0).abs() < 1e-12);

        // A new phase, or the same one counting again from zero, restarts the clock.
        app.ingest_at(&Event::progress("eval", 10, 20), t0 + Duration::from_secs(20));
        assert_eq!(app.progress().expect("progress").summary(), "eval: 10/20 (50%) 0.0/s");
        app.ingest_at(&Event::progress("eval", 20, 20), t0 + Duration::from_secs(30));
        app.ingest_at(&Event::progress("eval", 4, 20), t0 + Duration::from_secs(40));
        app.ingest_at(&Event::progress("eval", 8, 20), t0 + Duration::from_secs(42));
        assert_eq!(app.progress().expect("progress").summary(), "eval: 8/20 (40%) 4.0/s, ETA 3s");
    }

    #[test]
    fn progress_ratio_handles_zero_and_overshoot() {
        let mut app = App::new("t");
        app.ingest(&Event::progress("p", 3, 0));
        assert_eq!(app.progress().expect("progress").ratio(), 0.0);
        app.ingest(&Event::progress("p", 30, 10));
        assert_eq!(app.progress().expect("progress").ratio(), 1.0);
    }

    #[test]
    fn messages_keep_only_the_newest() {
        let mut app = App::new("t");
        for i in 0..(MESSAGE_CAP + 5) {
            app.ingest(&Event::message(format!("m{i}")));
        }
        assert_eq!(app.messages().len(), MESSAGE_CAP);
        assert_eq!(app.messages().next(), Some("m5"));
        assert_eq!(app.messages().last(), Some(format!("m{}", MESSAGE_CAP + 4).as_str()));
    }

    #[test]
    fn finished_and_hang_up_statuses() {
        let mut app = App::new("t");
        assert!(!app.is_finished());
        app.ingest(&Event::Finished { ok: false });
        assert!(app.is_finished());
        assert_eq!(app.status(), Status::Failed);
        app.mark_ended();
        assert_eq!(app.status(), Status::Failed, "a hang-up after Finished keeps the real outcome");

        let mut app = App::new("t");
        app.mark_ended();
        assert!(app.is_finished());
        assert_eq!(app.status(), Status::Ended);
    }
}
