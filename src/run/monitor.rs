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

/// Plain progress lines on stderr, for scripts and pipes. Progress is throttled so a tight loop does not
/// flood a log; the first and last update of a phase always print.
pub struct ConsoleMonitor {
    state: Mutex<ConsoleState>,
    min_interval: Duration,
}

struct ConsoleState {
    last_print: Option<Instant>,
    phase: String,
    phase_started: Instant,
}

impl ConsoleMonitor {
    pub fn new() -> Self {
        ConsoleMonitor {
            state: Mutex::new(ConsoleState { last_print: None, phase: String::new(), phase_started: Instant::now() }),
            min_interval: Duration::from_secs(1),
        }
    }
}

impl Default for ConsoleMonitor {
    fn default() -> Self {
        Self::new()
    }
}

impl Monitor for ConsoleMonitor {
    fn emit(&self, event: &Event) {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match event {
            Event::Progress { phase, done, total } => {
                let now = Instant::now();
                let new_phase = *phase != state.phase;
                if new_phase {
                    state.phase = phase.clone();
                    state.phase_started = now;
                }
                let finished = done >= total;
                let due = state.last_print.is_none_or(|t| now.duration_since(t) >= self.min_interval);
                if new_phase || finished || due {
                    state.last_print = Some(now);
                    let elapsed = now.duration_since(state.phase_started).as_secs_f64();
                    eprintln!("{}", format_progress(phase, *done, *total, elapsed));
                }
            }
            Event::Message { text } => eprintln!("{text}"),
            Event::Finished { ok: false } => eprintln!("job failed"),
            _ => {}
        }
    }
}

/// `phase: done/total (pct) rate/s, ETA` as one line; shared by the console and the TUI.
pub fn format_progress(phase: &str, done: u64, total: u64, elapsed_s: f64) -> String {
    let pct = if total > 0 { 100.0 * done as f64 / total as f64 } else { 0.0 };
    let rate = if elapsed_s > 0.0 { done as f64 / elapsed_s } else { 0.0 };
    let eta = if rate > 0.0 && total > done {
        format!(", ETA {}", format_duration((total - done) as f64 / rate))
    } else {
        String::new()
    };
    format!("{phase}: {done}/{total} ({pct:.0}%) {rate:.1}/s{eta}")
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_line_reports_rate_and_eta() {
        let line = format_progress("mpc", 50, 150, 10.0);
        assert_eq!(line, "mpc: 50/150 (33%) 5.0/s, ETA 20s");
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
