//! Ctrl-C, SIGTERM and SIGHUP end every command the same way: temporary files removed, the terminal given
//! back, one line on stderr, exit status 130. Work in progress is abandoned, not finished: outputs are
//! written through temporary files renamed into place, so abandoning never leaves a broken output, and the
//! registry here lets the handler delete the temporaries a hard exit would otherwise strand.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Exit status of an interrupted command (128 + SIGINT, what shells report for Ctrl-C).
pub const INTERRUPTED_EXIT: i32 = 130;

static PARTIALS: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());
static HOOKS: Mutex<Vec<fn()>> = Mutex::new(Vec::new());

/// What the work in progress has to say when it is interrupted (a training run: where it stopped and how to
/// go on), by registration id.
type Note = Box<dyn Fn() -> Option<String> + Send>;
static NOTES: Mutex<Vec<(u64, Note)>> = Mutex::new(Vec::new());
static NEXT_NOTE: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A poisoned lock only means another thread panicked mid-update of a plain set; the set is still usable.
fn lock<T>(m: &'static Mutex<T>) -> MutexGuard<'static, T> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Starts the thread that waits for the signals. Called once, first thing in `main`.
pub fn install() -> std::io::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        if signals.forever().next().is_some() {
            abandon_and_exit();
        }
    })?;
    Ok(())
}

fn abandon_and_exit() -> ! {
    let notes: Vec<String> = lock(&NOTES).iter().filter_map(|(_, note)| note()).collect();
    let message = match notes.is_empty() {
        true => "interrupted; temporary files removed, finished outputs kept".to_string(),
        false => format!("interrupted; {}", notes.join("; ")),
    };
    abandon_and_exit_with(INTERRUPTED_EXIT, &message)
}

/// Has `note` asked, on interruption, for a line that replaces the plain "interrupted" (a training run names
/// the step its checkpoint holds and the command that continues it), until the guard drops.
pub fn explain_interruption(note: impl Fn() -> Option<String> + Send + 'static) -> NoteGuard {
    let id = NEXT_NOTE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    lock(&NOTES).push((id, Box::new(note)));
    NoteGuard { id }
}

pub struct NoteGuard {
    id: u64,
}

impl Drop for NoteGuard {
    fn drop(&mut self) {
        lock(&NOTES).retain(|(id, _)| *id != self.id);
    }
}

/// Ends the process now, the way an interruption does, with `status` and `error: {message}` on stderr.
pub fn abandon_and_exit_with(status: i32, message: &str) -> ! {
    // Held until exit, so no writer can register (or rename) a temporary file after the sweep.
    let partials = lock(&PARTIALS);
    for path in partials.iter() {
        let _ = std::fs::remove_file(path);
    }
    for hook in lock(&HOOKS).iter() {
        hook();
    }
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "error: {message}");
    std::process::exit(status)
}

/// Runs `hook` on interruption before exiting (the live view gives the terminal back this way).
pub fn on_interrupt(hook: fn()) {
    let mut hooks = lock(&HOOKS);
    if !hooks.contains(&hook) {
        hooks.push(hook);
    }
}

/// Registration of one temporary file; dropping it (after the rename or the removal) forgets the path.
pub struct PartialGuard {
    path: PathBuf,
}

impl Drop for PartialGuard {
    fn drop(&mut self) {
        lock(&PARTIALS).remove(&self.path);
    }
}

/// Creates a temporary file with `create` and registers it in one step, under the registry's lock, so an
/// interruption either finds it registered or finds it not yet created.
pub fn create_partial<T, E>(
    create: impl FnOnce() -> Result<T, E>,
    path_of: impl Fn(&T) -> &Path,
) -> Result<(T, PartialGuard), E> {
    let mut partials = lock(&PARTIALS);
    let file = create()?;
    let path = path_of(&file).to_path_buf();
    partials.insert(path.clone());
    Ok((file, PartialGuard { path }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_files_are_registered_until_their_guard_drops() {
        let dir = tempfile::tempdir().unwrap();
        let (file, guard) = create_partial(|| tempfile::NamedTempFile::new_in(dir.path()), |f| f.path()).unwrap();
        assert!(lock(&PARTIALS).contains(file.path()));
        let path = file.path().to_path_buf();
        drop(guard);
        assert!(!lock(&PARTIALS).contains(&path));
    }
}
