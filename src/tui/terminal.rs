//! Running the live view on the real terminal. The terminal is put back (main screen, cooked mode,
//! visible cursor) on every way out: normal return, error, and panic on any thread.

use std::io::{self, Stdout};
use std::panic;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, TryRecvError};
use std::sync::{Arc, Once};
use std::time::{Duration, Instant};

use crossterm::event::{self as input, Event as InputEvent, KeyEvent};
use crossterm::{cursor, execute, terminal as term};
use ratatui::backend::CrosstermBackend;
use ratatui::{Frame, Terminal};

use super::app::App;
use super::overlay::Overlay;
use super::render::render;
use crate::run::follow::RunUpdate;
use crate::run::Event;

/// What the terminal loop drives: state folded from a stream of updates, drawn every frame.
pub(crate) trait LiveState {
    type Update;
    fn ingest(&mut self, update: Self::Update);
    /// Returns true when the user asked to quit.
    fn handle_key(&mut self, key: KeyEvent) -> bool;
    fn is_finished(&self) -> bool;
    /// The sender hung up.
    fn mark_ended(&mut self);
    fn draw(&self, frame: &mut Frame);
}

impl LiveState for App {
    type Update = Event;
    fn ingest(&mut self, event: Event) {
        App::ingest(self, &event);
    }
    fn handle_key(&mut self, key: KeyEvent) -> bool {
        App::handle_key(self, key)
    }
    fn is_finished(&self) -> bool {
        App::is_finished(self)
    }
    fn mark_ended(&mut self) {
        App::mark_ended(self);
    }
    fn draw(&self, frame: &mut Frame) {
        render(self, frame);
    }
}

/// How the live view ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LiveOutcome {
    /// The job finished (or hung up): the view closed by itself, or the user closed a held view.
    Finished,
    /// The user quit while the job was running; `cancel` has been set.
    QuitByUser,
}

/// About 15 redraws a second: smooth enough for curves, cheap enough to leave cores to the job.
const FRAME_INTERVAL: Duration = Duration::from_millis(66);

/// Longest time spent ingesting per frame, so a job flooding the channel cannot freeze the screen.
const DRAIN_BUDGET: Duration = Duration::from_millis(30);

/// Set while the terminal is in raw mode on the alternate screen. Whoever clears it restores the
/// terminal, so the guard and the panic hook never both do it, and the loop can tell that a panic on
/// another thread already gave the terminal back.
static TERMINAL_TAKEN: AtomicBool = AtomicBool::new(false);

static PANIC_HOOK: Once = Once::new();

type LiveTerminal = Terminal<CrosstermBackend<Stdout>>;

/// When the live view opens and closes.
#[derive(Clone, Copy, Debug)]
pub struct LiveOptions {
    /// Keep the view on screen after the job ends, until the user presses q, for reading its final state.
    /// Without it the view closes by itself, so `mbrl a && mbrl b` runs unattended.
    pub hold: bool,
    /// Open the view only if the job is still running after this long, so a quick command never flashes
    /// a screen; what arrived meanwhile is shown once it opens.
    pub grace: Duration,
}

/// How long a job may run before the live view opens: below about a second a full-screen flash is noise.
pub const DEFAULT_GRACE: Duration = Duration::from_secs(1);

/// Shows the job's events live until it ends (or, with `hold`, until the user quits). Quitting before the
/// job finished sets `cancel`. An `Err` means the terminal failed; the terminal is restored but `cancel` is
/// left to the caller.
pub fn run_live(
    events: Receiver<Event>,
    cancel: Arc<AtomicBool>,
    title: &str,
    options: LiveOptions,
) -> io::Result<LiveOutcome> {
    show(App::new(title), events, cancel, options)
}

/// `mbrl watch` over several runs: their same-named curves overlaid, one colour per run named by `labels`,
/// until the user quits. Quitting never stops the runs themselves; `cancel` tells the reader to stop reading.
pub fn run_overlay(updates: Receiver<RunUpdate>, cancel: Arc<AtomicBool>, labels: Vec<String>) -> io::Result<()> {
    let options = LiveOptions { hold: true, grace: Duration::ZERO };
    show(Overlay::new(labels), updates, cancel, options).map(drop)
}

fn show<S: LiveState>(
    mut state: S,
    events: Receiver<S::Update>,
    cancel: Arc<AtomicBool>,
    options: LiveOptions,
) -> io::Result<LiveOutcome> {
    if !options.hold && ends_within(&events, &mut state, options.grace) {
        return Ok(LiveOutcome::Finished);
    }
    let mut screen = Screen::take()?;
    let outcome = event_loop(&mut screen.terminal, &mut state, &events, options.hold)?;
    if outcome == LiveOutcome::QuitByUser {
        cancel.store(true, Ordering::Relaxed);
    }
    screen.give_back()?;
    Ok(outcome)
}

/// The terminal while the live view owns it; dropping it gives the terminal back.
struct Screen {
    terminal: LiveTerminal,
    /// Declared after `terminal` so the restore happens after the terminal's last write.
    _restore: RestoreOnDrop,
}

impl Screen {
    fn take() -> io::Result<Self> {
        install_panic_hook();
        crate::util::interrupt::on_interrupt(release_after_interrupt);
        TERMINAL_TAKEN.store(true, Ordering::SeqCst);
        // Armed before the first switch, so failing halfway still undoes what was switched on.
        let restore = RestoreOnDrop;
        term::enable_raw_mode()?;
        execute!(io::stdout(), term::EnterAlternateScreen, cursor::Hide)?;
        let terminal = Terminal::new(CrosstermBackend::new(io::stdout()))?;
        Ok(Screen { terminal, _restore: restore })
    }

    /// The normal way out, which unlike the guard's `Drop` can report a failure to restore.
    fn give_back(self) -> io::Result<()> {
        release_terminal()
    }
}

struct RestoreOnDrop;

impl Drop for RestoreOnDrop {
    fn drop(&mut self) {
        // Nothing to report to from a drop; on the error paths that get here the caller sees the cause.
        let _ = release_terminal();
    }
}

fn release_terminal() -> io::Result<()> {
    if !TERMINAL_TAKEN.swap(false, Ordering::SeqCst) {
        return Ok(());
    }
    let raw = term::disable_raw_mode();
    execute!(io::stdout(), term::LeaveAlternateScreen, cursor::Show)?;
    raw
}

fn release_after_interrupt() {
    let _ = release_terminal();
}

/// Installed once per process and inert while no live view runs, so repeated `run_live` calls do not
/// stack hooks. Restoring first makes the panic message land on the normal screen, where it stays.
fn install_panic_hook() {
    PANIC_HOOK.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            let _ = release_terminal();
            previous(info);
        }));
    });
}

/// Ingests events for up to `grace`; true when the job ended within it.
fn ends_within<S: LiveState>(events: &Receiver<S::Update>, app: &mut S, grace: Duration) -> bool {
    let deadline = Instant::now() + grace;
    loop {
        match events.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            Ok(event) => {
                app.ingest(event);
                if app.is_finished() {
                    return true;
                }
            }
            Err(RecvTimeoutError::Timeout) => return false,
            Err(RecvTimeoutError::Disconnected) => {
                app.mark_ended();
                return true;
            }
        }
    }
}

fn event_loop<S: LiveState>(
    terminal: &mut LiveTerminal,
    app: &mut S,
    events: &Receiver<S::Update>,
    hold: bool,
) -> io::Result<LiveOutcome> {
    let mut connected = true;
    loop {
        if !TERMINAL_TAKEN.load(Ordering::SeqCst) {
            return Err(io::Error::other("live view closed: a thread panicked"));
        }
        if connected {
            connected = drain(events, app, DRAIN_BUDGET);
        }
        if app.is_finished() && !hold {
            return Ok(LiveOutcome::Finished);
        }
        terminal.draw(|frame| app.draw(frame))?;
        if wait_for_quit(app, FRAME_INTERVAL)? {
            return Ok(outcome_on_quit(app));
        }
    }
}

/// Ingests what has arrived; returns false once the sender has hung up.
fn drain<S: LiveState>(events: &Receiver<S::Update>, app: &mut S, budget: Duration) -> bool {
    let deadline = Instant::now() + budget;
    while Instant::now() < deadline {
        match events.try_recv() {
            Ok(event) => app.ingest(event),
            Err(TryRecvError::Empty) => return true,
            Err(TryRecvError::Disconnected) => {
                app.mark_ended();
                return false;
            }
        }
    }
    true
}

/// Handles input for up to `timeout`; returns true when the user asked to quit. Returns early after a
/// key so the screen reflects it at once.
fn wait_for_quit<S: LiveState>(app: &mut S, timeout: Duration) -> io::Result<bool> {
    let mut timeout = timeout;
    while input::poll(timeout)? {
        if let InputEvent::Key(key) = input::read()? {
            if app.handle_key(key) {
                return Ok(true);
            }
        }
        timeout = Duration::ZERO;
    }
    Ok(false)
}

fn outcome_on_quit<S: LiveState>(app: &S) -> LiveOutcome {
    if app.is_finished() {
        LiveOutcome::Finished
    } else {
        LiveOutcome::QuitByUser
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;

    const GENEROUS: Duration = Duration::from_secs(5);

    #[test]
    fn drain_ingests_pending_events_and_stays_connected() {
        let (tx, rx) = mpsc::channel();
        tx.send(Event::scalar("loss", 0, 1.0)).expect("send");
        tx.send(Event::scalar("reward", 0, 2.0)).expect("send");
        let mut app = App::new("t");
        assert!(drain(&rx, &mut app, GENEROUS));
        assert_eq!(app.metric_names(), vec!["loss", "reward"]);
        assert!(!app.is_finished());
    }

    #[test]
    fn a_job_that_ends_within_the_grace_never_opens_the_view() {
        let (tx, rx) = mpsc::channel();
        tx.send(Event::message("quick")).expect("send");
        tx.send(Event::Finished { ok: true }).expect("send");
        let mut app = App::new("t");
        assert!(ends_within(&rx, &mut app, GENEROUS));
        assert!(app.is_finished());
    }

    #[test]
    fn a_job_still_running_after_the_grace_opens_the_view_with_what_it_sent() {
        let (tx, rx) = mpsc::channel();
        tx.send(Event::scalar("loss", 0, 1.0)).expect("send");
        let mut app = App::new("t");
        assert!(!ends_within(&rx, &mut app, Duration::from_millis(20)));
        assert_eq!(app.metric_names(), vec!["loss"]);
        drop(tx);
    }

    #[test]
    fn hang_up_ends_the_run() {
        let (tx, rx) = mpsc::channel();
        tx.send(Event::message("last words")).expect("send");
        drop(tx);
        let mut app = App::new("t");
        assert!(!drain(&rx, &mut app, GENEROUS));
        assert!(app.is_finished());
        assert_eq!(outcome_on_quit(&app), LiveOutcome::Finished);
    }

    #[test]
    fn drain_respects_its_budget() {
        let (tx, rx) = mpsc::channel();
        for step in 0..10 {
            tx.send(Event::scalar("loss", step, 1.0)).expect("send");
        }
        let mut app = App::new("t");
        assert!(drain(&rx, &mut app, Duration::ZERO));
        assert!(app.metric_names().is_empty(), "nothing may be ingested with no time left");
    }

    #[test]
    fn quitting_a_running_job_is_a_user_quit() {
        let mut app = App::new("t");
        assert_eq!(outcome_on_quit(&app), LiveOutcome::QuitByUser);
        app.ingest(&Event::Finished { ok: false });
        assert_eq!(outcome_on_quit(&app), LiveOutcome::Finished);
    }
}
