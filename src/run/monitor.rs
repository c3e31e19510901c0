//! Where events go: the console, a metrics file, the TUI, or several at once.

use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::event::Event;

/// A sink for progress and metrics. Long work reports through it and polls `is_cancelled` so that a user
/// quitting the live view stops the job cleanly instead of killing it mid-write.
pub trait Monitor: Send + Sync {
    fn emit(&self, event: &Event);

    fn is_cancelled(&self) -> bool {
        false
    }

    fn scalar(&self, name: &str, step: u64, value: f64) {
        self.emit(&Event::scalar(name, step, value));
    }

    fn progress(&self, phase: &str, done: u64, total: u64) {
        self.emit(&Event::progress(phase, done, total));
    }

    fn message(&self, text: &str) {
        self.emit(&Event::message(text));
    }
}

/// Discards everything (library callers that want no reporting, benchmarks).
pub struct NullMonitor;

impl Monitor for NullMonitor {
    fn emit(&self, _event: &Event) {}
}

/// Plain progress lines on stderr, for scripts and pipes. Each phase is throttled on its own, so a tight
/// inner loop neither floods a log nor silences the outer phase around it: a phase prints on its first
/// update (or when its counter restarts), when it completes, and otherwise at most once per `min_interval`.
pub struct ConsoleMonitor {
    phases: Mutex<PhaseTracker>,
    min_interval: Duration,
}

impl ConsoleMonitor {
    pub fn new() -> Self {
        ConsoleMonitor { phases: Mutex::new(PhaseTracker::default()), min_interval: Duration::from_secs(1) }
    }

    /// The line to print for a progress update at `now`, or `None` when the throttle holds it back.
    fn progress_line(&self, phase: &str, done: u64, total: u64, now: Instant) -> Option<String> {
        let mut phases = self.phases.lock().unwrap_or_else(|e| e.into_inner());
        let (progress, change) = phases.update(phase, done, total, now);
        let due = progress.reported.is_none_or(|t| now.duration_since(t) >= self.min_interval);
        if !(change.started || change.completed || due) {
            return None;
        }
        progress.reported = Some(now);
        Some(progress.summary())
    }
}

impl Default for ConsoleMonitor {
    fn default() -> Self {
        Self::new()
    }
}

impl Monitor for ConsoleMonitor {
    fn emit(&self, event: &Event) {
        match event {
            Event::Progress { phase, done, total } => {
                if let Some(line) = self.progress_line(phase, *done, *total, Instant::now()) {
                    eprintln!("{line}");
                }
            }
            Event::Message { text } => eprintln!("{text}"),
            Event::Finished { ok: false } => eprintln!("job failed"),
            _ => {}
        }
    }
}

/// Phases tracked at most; beyond this the least recently updated one is forgotten, so a job that names a
/// phase per episode cannot grow the tracker without bound.
const PHASE_CAP: usize = 32;

/// One progress phase on its own clock. Both instants come from the updates, so rate and ETA are a
/// function of the events alone.
#[derive(Clone, Debug)]
pub(crate) struct PhaseProgress {
    pub(crate) name: String,
    done: u64,
    total: u64,
    /// The phase's first update, or the update at which its counter last went backwards.
    started: Instant,
    /// The counter at `started`: a resumed run's phase starts part-way, and only what this process did
    /// since then says how fast it goes.
    done_at_start: u64,
    updated: Instant,
    /// When the console last printed this phase (its throttle); unused by the live view.
    reported: Option<Instant>,
    /// Position in the stream of updates to any phase: orders phases by recency even when instants tie.
    sequence: u64,
}

impl PhaseProgress {
    pub(crate) fn ratio(&self) -> f64 {
        if self.total == 0 {
            return 0.0;
        }
        (self.done as f64 / self.total as f64).clamp(0.0, 1.0)
    }

    /// `phase: done/total (pct) rate/s, ETA`, with the rate measured from this phase's own start.
    pub(crate) fn summary(&self) -> String {
        let elapsed = self.updated.duration_since(self.started).as_secs_f64();
        format_progress(&self.name, self.done, self.total, self.done - self.done_at_start, elapsed)
    }
}

/// What an update did to its phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PhaseChange {
    /// The phase's clock (re)started: its first update, or its counter went backwards.
    pub(crate) started: bool,
    /// The phase reached its total with this update.
    pub(crate) completed: bool,
}

/// Progress phases keyed by name, in order of first appearance, each on its own clock, so interleaved
/// phases (the episodes and the MPC steps inside each) do not reset each other's rate.
#[derive(Clone, Debug, Default)]
pub(crate) struct PhaseTracker {
    phases: Vec<PhaseProgress>,
    updates: u64,
}

impl PhaseTracker {
    /// Records an update of `name`, creating the phase on its first update.
    pub(crate) fn update(
        &mut self,
        name: &str,
        done: u64,
        total: u64,
        now: Instant,
    ) -> (&mut PhaseProgress, PhaseChange) {
        self.updates += 1;
        let sequence = self.updates;
        let Some(index) = self.phases.iter().position(|p| p.name == name) else {
            if self.phases.len() >= PHASE_CAP {
                let stalest = self.phases.iter().enumerate().min_by_key(|(_, p)| p.sequence).map_or(0, |(i, _)| i);
                self.phases.remove(stalest);
            }
            let name = name.to_string();
            self.phases.push(PhaseProgress {
                name,
                done,
                total,
                started: now,
                done_at_start: done,
                updated: now,
                reported: None,
                sequence,
            });
            let change = PhaseChange { started: true, completed: is_complete(done, total) };
            return (self.phases.last_mut().expect("just pushed"), change);
        };
        let phase = &mut self.phases[index];
        // A counter going backwards means the phase was restarted, so its rate must be measured afresh.
        let started = done < phase.done;
        if started {
            phase.started = now;
            phase.done_at_start = done;
        }
        let completed = is_complete(done, total) && (started || !is_complete(phase.done, phase.total));
        phase.done = done;
        phase.total = total;
        phase.updated = now;
        phase.sequence = sequence;
        (phase, PhaseChange { started, completed })
    }

    /// The `count` most recently updated phases, in order of first appearance (outer phases, which
    /// start first, above the inner ones they contain).
    pub(crate) fn recent(&self, count: usize) -> Vec<&PhaseProgress> {
        let mut newest: Vec<u64> = self.phases.iter().map(|p| p.sequence).collect();
        newest.sort_unstable_by(|a, b| b.cmp(a));
        newest.truncate(count);
        let Some(&cutoff) = newest.last() else {
            return Vec::new();
        };
        self.phases.iter().filter(|p| p.sequence >= cutoff).collect()
    }
}

/// A phase with an unknown (zero) total never completes, so it cannot bypass the throttle on every update.
fn is_complete(done: u64, total: u64) -> bool {
    total > 0 && done >= total
}

/// `phase: done/total (pct) rate/s, ETA` as one line; shared by the console and the TUI. The rate is
/// `progressed` (the units done in the `elapsed_s` measured) per second. With (next to) no time elapsed
/// there is no meaningful rate, so it is left out rather than shown as `0.0/s`.
pub fn format_progress(phase: &str, done: u64, total: u64, progressed: u64, elapsed_s: f64) -> String {
    let pct = if total > 0 { 100.0 * done as f64 / total as f64 } else { 0.0 };
    if elapsed_s.is_nan() || elapsed_s < MIN_RATE_ELAPSED_S {
        return format!("{phase}: {done}/{total} ({pct:.0}%)");
    }
    let rate = progressed as f64 / elapsed_s;
    let eta = if rate > 0.0 && total > done {
        format!(", ETA {}", format_duration((total - done) as f64 / rate))
    } else {
        String::new()
    };
    format!("{phase}: {done}/{total} ({pct:.0}%) {rate:.1}/s{eta}")
}

/// Shorter spans than this (1 ms) give no rate worth printing.
const MIN_RATE_ELAPSED_S: f64 = 1e-3;

pub fn format_duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

/// Appends every event as one JSON line (`metrics.jsonl`). Lines are flushed as they come so that
/// `mbrl watch` can follow a run that is still going.
pub struct JsonlMonitor {
    out: Mutex<BufWriter<std::fs::File>>,
}

impl JsonlMonitor {
    pub fn create(path: &Path) -> std::io::Result<Self> {
        let file = std::fs::File::create(path)?;
        Ok(JsonlMonitor { out: Mutex::new(BufWriter::new(file)) })
    }

    /// Continues a log after its first `keep_bytes` bytes, dropping what a stopped run wrote after its last
    /// checkpoint, so that a resumed run's log equals an uninterrupted one.
    pub fn resume(path: &Path, keep_bytes: u64) -> std::io::Result<Self> {
        use std::io::{Seek, SeekFrom};
        let mut file = std::fs::OpenOptions::new().write(true).open(path)?;
        if file.metadata()?.len() < keep_bytes {
            return Err(std::io::Error::new(
                std::io::ErrorKind::UnexpectedEof,
                format!("shorter than the {keep_bytes} bytes the checkpoint recorded"),
            ));
        }
        file.set_len(keep_bytes)?;
        file.seek(SeekFrom::End(0))?;
        Ok(JsonlMonitor { out: Mutex::new(BufWriter::new(file)) })
    }

    /// Flushes and returns the log's length.
    pub fn flush_position(&self) -> std::io::Result<u64> {
        use std::io::Seek;
        let mut out = self.out.lock().unwrap_or_else(|e| e.into_inner());
        out.flush()?;
        out.get_mut().stream_position()
    }
}

impl Monitor for JsonlMonitor {
    fn emit(&self, event: &Event) {
        let mut out = self.out.lock().unwrap_or_else(|e| e.into_inner());
        // A metrics line that cannot be written must not abort the computation it describes.
        if let Ok(line) = serde_json::to_string(event) {
            let _ = writeln!(out, "{line}");
            if !matches!(event, Event::Scalar { .. }) {
                let _ = out.flush();
            }
        }
    }
}

impl Drop for JsonlMonitor {
    fn drop(&mut self) {
        if let Ok(mut out) = self.out.lock() {
            let _ = out.flush();
        }
    }
}

/// Forwards events to the live view running on another thread; the view sets `cancel` when the user quits.
pub struct ChannelMonitor {
    sender: Mutex<Sender<Event>>,
    cancel: Arc<AtomicBool>,
}

impl ChannelMonitor {
    pub fn new(sender: Sender<Event>, cancel: Arc<AtomicBool>) -> Self {
        ChannelMonitor { sender: Mutex::new(sender), cancel }
    }
}

impl Monitor for ChannelMonitor {
    fn emit(&self, event: &Event) {
        let sender = self.sender.lock().unwrap_or_else(|e| e.into_inner());
        let _ = sender.send(event.clone());
    }

    fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// Sends each event to every member.
pub struct Fanout {
    members: Vec<Box<dyn Monitor>>,
}

impl Fanout {
    pub fn new(members: Vec<Box<dyn Monitor>>) -> Self {
        Fanout { members }
    }

    pub fn push(&mut self, member: Box<dyn Monitor>) {
        self.members.push(member);
    }
}

impl Monitor for Fanout {
    fn emit(&self, event: &Event) {
        for m in &self.members {
            m.emit(event);
        }
    }

    fn is_cancelled(&self) -> bool {
        self.members.iter().any(|m| m.is_cancelled())
    }
}

/// Sends each event to two borrowed monitors (a caller's console or TUI, plus a run's metrics file).
pub struct Tee<'a> {
    pub first: &'a dyn Monitor,
    pub second: &'a dyn Monitor,
}

impl Monitor for Tee<'_> {
    fn emit(&self, event: &Event) {
        self.first.emit(event);
        self.second.emit(event);
    }

    fn is_cancelled(&self) -> bool {
        self.first.is_cancelled() || self.second.is_cancelled()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_line_reports_rate_and_eta() {
        let line = format_progress("mpc", 50, 150, 50, 10.0);
        assert_eq!(line, "mpc: 50/150 (33%) 5.0/s, ETA 20s");
    }

    #[test]
    fn a_phase_that_starts_part_way_is_timed_from_where_it_started() {
        let mut tracker = PhaseTracker::default();
        let t0 = Instant::now();
        tracker.update("env steps", 4_000, 10_000, t0);
        let (phase, _) = tracker.update("env steps", 4_100, 10_000, t0 + std::time::Duration::from_secs(10));
        assert_eq!(phase.summary(), "env steps: 4100/10000 (41%) 10.0/s, ETA 9m50s");
    }

    #[test]
    fn no_rate_without_elapsed_time() {
        assert_eq!(format_progress("episodes", 0, 3, 0, 0.0), "episodes: 0/3 (0%)");
        assert_eq!(format_progress("episodes", 3, 3, 3, 0.0002), "episodes: 3/3 (100%)");
        assert_eq!(format_progress("episodes", 1, 3, 1, f64::NAN), "episodes: 1/3 (33%)");
        assert_eq!(format_progress("episodes", 0, 3, 0, 5.0), "episodes: 0/3 (0%) 0.0/s");
        assert_eq!(format_progress("episodes", 3, 3, 3, 0.002), "episodes: 3/3 (100%) 1500.0/s");
    }

    #[test]
    fn interleaved_phases_keep_their_own_clocks() {
        let mut phases = PhaseTracker::default();
        let t0 = Instant::now();
        let at = |s: u64| t0 + Duration::from_secs(s);
        phases.update("episodes", 0, 3, at(0));
        for episode in 0..3u64 {
            for t in 1..=10 {
                phases.update(&format!("episode {} MPC", episode + 1), t, 10, at(10 * episode + t));
            }
            phases.update("episodes", episode + 1, 3, at(10 * episode + 10));
        }
        let shown: Vec<String> = phases.recent(3).iter().map(|p| p.summary()).collect();
        assert_eq!(
            shown,
            vec![
                "episodes: 3/3 (100%) 0.1/s",
                "episode 2 MPC: 10/10 (100%) 1.0/s",
                "episode 3 MPC: 10/10 (100%) 1.0/s",
            ]
        );
    }

    #[test]
    fn a_rewound_counter_restarts_only_its_own_phase() {
        let mut phases = PhaseTracker::default();
        let t0 = Instant::now();
        let at = |s: u64| t0 + Duration::from_secs(s);
        phases.update("outer", 0, 4, at(0));
        phases.update("inner", 5, 10, at(0));
        phases.update("outer", 2, 4, at(10));
        let (_, change) = phases.update("inner", 10, 10, at(10));
        assert_eq!(change, PhaseChange { started: false, completed: true });
        let (inner, change) = phases.update("inner", 2, 10, at(20));
        assert_eq!(change, PhaseChange { started: true, completed: false });
        assert_eq!(inner.summary(), "inner: 2/10 (20%)");
        let (outer, _) = phases.update("outer", 3, 4, at(30));
        assert_eq!(outer.summary(), "outer: 3/4 (75%) 0.1/s, ETA 10s");
        let (inner, _) = phases.update("inner", 4, 10, at(22));
        assert_eq!(inner.summary(), "inner: 4/10 (40%) 1.0/s, ETA 6s");
    }

    #[test]
    fn recent_phases_are_listed_in_order_of_first_appearance() {
        let mut phases = PhaseTracker::default();
        let t0 = Instant::now();
        for name in ["a", "b", "c", "d"] {
            phases.update(name, 1, 2, t0);
        }
        phases.update("a", 2, 2, t0);
        let names = |n: usize| phases.recent(n).iter().map(|p| p.name.clone()).collect::<Vec<_>>();
        assert_eq!(names(3), vec!["a", "c", "d"]);
        assert_eq!(names(1), vec!["a"]);
        assert_eq!(names(10), vec!["a", "b", "c", "d"]);
        assert!(names(0).is_empty());
        assert!(PhaseTracker::default().recent(3).is_empty());
    }

    #[test]
    fn the_stalest_phase_is_forgotten_beyond_the_cap() {
        let mut phases = PhaseTracker::default();
        let t0 = Instant::now();
        phases.update("outer", 0, 100, t0);
        for k in 0..PHASE_CAP {
            phases.update(&format!("episode {k}"), 1, 1, t0);
            phases.update("outer", k as u64, 100, t0);
        }
        assert_eq!(phases.phases.len(), PHASE_CAP);
        assert!(phases.phases.iter().any(|p| p.name == "outer"), "the live outer phase stays");
        assert!(!phases.phases.iter().any(|p| p.name == "episode 0"), "the stalest phase goes");
    }

    #[test]
    fn console_throttles_each_phase_on_its_own() {
        let console = ConsoleMonitor::new();
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let mut printed = Vec::new();
        let mut update = |phase: &str, done: u64, total: u64, ms: u64| {
            if let Some(line) = console.progress_line(phase, done, total, at(ms)) {
                printed.push(line);
            }
        };
        update("episodes", 0, 2, 0);
        for episode in 0..2u64 {
            let phase = format!("episode {} MPC", episode + 1);
            // 150 steps, 20 ms apart: the first, one a second after it, and the last.
            for t in 0..150 {
                update(&phase, t + 1, 150, 3000 * episode + 20 * t);
            }
            update("episodes", episode + 1, 2, 3000 * episode + 2990);
        }
        assert_eq!(
            printed,
            vec![
                "episodes: 0/2 (0%)",
                "episode 1 MPC: 1/150 (1%)",
                "episode 1 MPC: 51/150 (34%) 50.0/s, ETA 2s",
                "episode 1 MPC: 101/150 (67%) 50.0/s, ETA 1s",
                "episode 1 MPC: 150/150 (100%) 50.0/s",
                "episodes: 1/2 (50%) 0.3/s, ETA 3s",
                "episode 2 MPC: 1/150 (1%)",
                "episode 2 MPC: 51/150 (34%) 50.0/s, ETA 2s",
                "episode 2 MPC: 101/150 (67%) 50.0/s, ETA 1s",
                "episode 2 MPC: 150/150 (100%) 50.0/s",
                "episodes: 2/2 (100%) 0.3/s",
            ]
        );
    }

    #[test]
    fn console_prints_a_restarted_phase_and_not_repeated_completions() {
        let console = ConsoleMonitor::new();
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        assert!(console.progress_line("p", 1, 0, at(0)).is_some());
        assert!(console.progress_line("p", 2, 0, at(10)).is_none(), "an unknown total is throttled");
        assert!(console.progress_line("q", 5, 5, at(20)).is_some());
        assert!(console.progress_line("q", 5, 5, at(30)).is_none(), "already reported complete");
        assert!(console.progress_line("q", 1, 5, at(40)).is_some(), "counting again restarts the phase");
        assert!(console.progress_line("q", 2, 5, at(50)).is_none());
        assert!(console.progress_line("q", 3, 5, at(1040)).is_some(), "a second after the last line");
    }

    #[test]
    fn durations_use_largest_unit() {
        assert_eq!(format_duration(59.4), "59s");
        assert_eq!(format_duration(61.0), "1m01s");
        assert_eq!(format_duration(3725.0), "1h02m");
    }

    #[test]
    fn fanout_cancels_when_any_member_does() {
        let flag = Arc::new(AtomicBool::new(false));
        let (tx, _rx) = std::sync::mpsc::channel();
        let fan = Fanout::new(vec![Box::new(NullMonitor), Box::new(ChannelMonitor::new(tx, flag.clone()))]);
        assert!(!fan.is_cancelled());
        flag.store(true, Ordering::Relaxed);
        assert!(fan.is_cancelled());
    }
}
