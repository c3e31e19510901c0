//! The state of the live view, folded from the event stream. No terminal I/O here, so every rule about
//! what the user sees can be unit-tested.

use std::collections::{BTreeMap, VecDeque};
use std::time::Instant;

use crossterm::event::KeyEvent;

use super::keys::{action_for, Action};
use super::panel::Panel;
use super::series::Series;
use super::text_panel::{TextPanel, TextPanels};
use crate::run::monitor::{PhaseProgress, PhaseTracker};
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

/// Everything the live view shows, built from events and keys alone.
pub struct App {
    title: String,
    status: Status,
    /// Every phase on its own clock, so interleaved phases do not reset each other's rate.
    progress: PhaseTracker,
    /// Every metric's full (capped) history; a BTreeMap so metric order is by name, stable across runs.
    history: BTreeMap<String, Series>,
    /// Tracked by name, not index, so metrics appearing later do not move the user's selection.
    selected: Option<String>,
    panels: Vec<Panel>,
    /// Kept apart from `panels`: text arrives under any name, with no `Layout` announcing it.
    texts: TextPanels,
    messages: VecDeque<String>,
}

impl App {
    pub fn new(title: &str) -> Self {
        App {
            title: title.to_string(),
            status: Status::Running,
            progress: PhaseTracker::default(),
            history: BTreeMap::new(),
            selected: None,
            panels: Vec::new(),
            texts: TextPanels::default(),
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
            Event::Text { panel, text } => self.texts.set(panel, text),
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

    /// The metrics the Curves panel offers, sorted by name: all but those a chart panel already draws
    /// in full, so the same curve is never shown twice.
    pub fn metric_names(&self) -> Vec<&str> {
        self.history.keys().map(String::as_str).filter(|name| self.is_selectable(name)).collect()
    }

    fn is_selectable(&self, name: &str) -> bool {
        !self.panels.iter().any(|panel| panel.draws_full_history(name))
    }

    /// Whether the Curves panel has anything to offer. Without, the method panels take the whole body;
    /// before any metric or panel arrives the Curves placeholder stays, so a fresh run is not blank.
    pub(crate) fn has_curves(&self) -> bool {
        !self.metric_names().is_empty() || (self.panels.is_empty() && self.texts.as_slice().is_empty())
    }

    /// A metric's whole (capped) history, whether or not the Curves panel offers it.
    #[cfg(test)]
    pub(crate) fn history(&self, name: &str) -> Option<&Series> {
        self.history.get(name)
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

    /// The `count` most recently updated phases, in order of first appearance.
    pub(crate) fn progress(&self, count: usize) -> Vec<&PhaseProgress> {
        self.progress.recent(count)
    }

    /// The selected metric's name, its history, and its 1-based position among the offered metrics.
    pub(crate) fn selected_series(&self) -> Option<(&str, &Series, usize)> {
        let selected = self.selected.as_deref()?;
        let position = self.metric_names().iter().position(|n| *n == selected)?;
        let (name, series) = self.history.get_key_value(selected)?;
        Some((name.as_str(), series, position + 1))
    }

    pub(crate) fn metric_count(&self) -> usize {
        self.metric_names().len()
    }

    pub(crate) fn panels(&self) -> &[Panel] {
        &self.panels
    }

    /// Text panels in order of first appearance, each with its latest text.
    pub(crate) fn text_panels(&self) -> &[TextPanel] {
        self.texts.as_slice()
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
        if self.selected.as_deref().is_some_and(|name| !self.is_selectable(name)) {
            self.selected = self.metric_names().first().map(|name| name.to_string());
        }
    }

    fn record_scalar(&mut self, name: &str, step: u64, value: f64) {
        self.history.entry(name.to_string()).or_insert_with(Series::indexed_on_rewind).push(step, value);
        for panel in &mut self.panels {
            panel.record(name, step, value);
        }
        if self.selected.is_none() && self.is_selectable(name) {
            self.selected = Some(name.to_string());
        }
    }

    fn update_progress(&mut self, phase: &str, done: u64, total: u64, now: Instant) {
        self.progress.update(phase, done, total, now);
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
                path: None,
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

        assert_eq!(app.history("pendulum/angle").expect("kept").points().len(), 6);
        let (_, panel_copy) = app.panels()[0].series().next().expect("angle series");
        assert_eq!(panel_copy.points(), &[(0.0, 9.0)]);
    }

    #[test]
    fn metrics_a_panel_draws_in_full_are_not_offered_again() {
        let mut app = App::new("t");
        app.ingest(&Event::scalar("pendulum/angle", 0, 1.0));
        app.ingest(&pendulum_layout());
        assert_eq!(app.selected_metric(), Some("pendulum/angle"), "the panel shows one episode, Curves all");
        let Event::Layout { title, mut panels } = pendulum_layout() else { unreachable!() };
        panels[0].restart_on_rewind = false;
        app.ingest(&Event::Layout { title, panels });
        assert_eq!(app.selected_metric(), None, "the panel draws it now");
        assert!(!app.has_curves(), "nothing left to offer");
        app.ingest(&Event::scalar("pendulum/action", 0, 1.0));
        app.ingest(&Event::scalar("cem/best_cost", 0, 5.0));
        assert_eq!(app.metric_names(), vec!["cem/best_cost"]);
        assert_eq!(app.selected_metric(), Some("cem/best_cost"));
        assert_eq!(app.metric_count(), 1);
        app.handle_key(key(KeyCode::Right));
        assert_eq!(app.selected_metric(), Some("cem/best_cost"));
        assert!(app.has_curves());
    }

    #[test]
    fn layout_sets_title_and_panels() {
        let mut app = App::new("before");
        app.ingest(&pendulum_layout());
        assert_eq!(app.title(), "pendulum run");
        assert_eq!(app.panels().len(), 1);
        assert_eq!(app.panels()[0].spec().title, "pendulum");
    }

    fn summaries(app: &App) -> Vec<String> {
        app.progress(3).iter().map(|p| p.summary()).collect()
    }

    #[test]
    fn progress_rate_is_measured_from_the_phase_start() {
        let mut app = App::new("t");
        let t0 = Instant::now();
        app.ingest_at(&Event::progress("train", 0, 150), t0);
        app.ingest_at(&Event::progress("train", 50, 150), t0 + Duration::from_secs(10));
        let progress = app.progress(3);
        assert_eq!(progress.len(), 1);
        assert_eq!(progress[0].summary(), "train: 50/150 (33%) 5.0/s, ETA 20s");
        assert!((progress[0].ratio() - 1.0 / 3.0).abs() < 1e-12);

        // A new phase has no rate yet; the same one counting again from zero restarts its clock.
        app.ingest_at(&Event::progress("eval", 10, 20), t0 + Duration::from_secs(20));
        assert_eq!(summaries(&app)[1], "eval: 10/20 (50%)");
        app.ingest_at(&Event::progress("eval", 20, 20), t0 + Duration::from_secs(30));
        app.ingest_at(&Event::progress("eval", 4, 20), t0 + Duration::from_secs(40));
        app.ingest_at(&Event::progress("eval", 8, 20), t0 + Duration::from_secs(42));
        assert_eq!(summaries(&app), vec!["train: 50/150 (33%) 5.0/s, ETA 20s", "eval: 8/20 (40%) 2.0/s, ETA 6s"]);
    }

    #[test]
    fn interleaved_phases_keep_separate_rates() {
        // The shape of `mbrl eval pendulum-swingup --episodes 3`: an outer count of episodes around an
        // inner count of MPC steps, one inner phase per episode.
        let mut app = App::new("t");
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        for episode in 0..3u64 {
            app.ingest_at(&Event::progress("episodes", episode, 3), at(3000 * episode));
            for t in 0..150 {
                let phase = format!("episode {} MPC", episode + 1);
                app.ingest_at(&Event::progress(phase, t + 1, 150), at(3000 * episode + 20 * t));
            }
        }
        app.ingest_at(&Event::progress("episodes", 3, 3), at(9000));
        assert_eq!(
            summaries(&app),
            vec![
                "episodes: 3/3 (100%) 0.3/s",
                "episode 2 MPC: 150/150 (100%) 50.0/s",
                "episode 3 MPC: 150/150 (100%) 50.0/s"
            ]
        );
    }

    #[test]
    fn progress_ratio_handles_zero_and_overshoot() {
        let mut app = App::new("t");
        app.ingest(&Event::progress("p", 3, 0));
        assert_eq!(app.progress(3)[0].ratio(), 0.0);
        app.ingest(&Event::progress("p", 30, 10));
        assert_eq!(app.progress(3)[0].ratio(), 1.0);
    }

    #[test]
    fn rewinding_history_is_plotted_against_a_monotone_sample_index() {
        let mut app = App::new("t");
        for _ in 0..4 {
            for iteration in 0..10 {
                app.ingest(&Event::scalar("cem/best_cost", iteration, 100.0 - iteration as f64));
            }
        }
        let (_, history, _) = app.selected_series().expect("cost is selected");
        let xs: Vec<f64> = history.points().iter().map(|p| p.0).collect();
        assert_eq!(xs.len(), 40);
        assert!(xs.windows(2).all(|w| w[0] < w[1]), "x must increase strictly: {xs:?}");
        assert_eq!(history.x_label(), "sample");
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
    fn text_events_fill_panels_in_order_of_first_appearance() {
        let mut app = App::new("t");
        app.ingest(&Event::text("board", "■ ·"));
        app.ingest(&Event::text("plan", "push (0, 1)"));
        app.ingest(&Event::text("board", "· ■"));
        app.ingest(&pendulum_layout());
        let texts: Vec<(&str, &str)> = app.text_panels().iter().map(|p| (p.name.as_str(), p.text.as_str())).collect();
        assert_eq!(texts, vec![("board", "· ■"), ("plan", "push (0, 1)")], "a layout keeps the text panels");
        assert_eq!(app.panels().len(), 1);
        assert!(app.metric_names().is_empty());
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
