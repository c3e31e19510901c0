//! Which key does what, kept apart from the state it acts on so the bindings read as one table.

use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Action {
    Quit,
    NextMetric,
    PreviousMetric,
}

pub(crate) fn action_for(key: KeyEvent) -> Option<Action> {
    // Some terminals (Windows) report releases too; acting on them would double every keystroke.
    if key.kind == KeyEventKind::Release {
        return None;
    }
    match key.code {
        KeyCode::Char('c') if key.modifiers.contains(KeyModifiers::CONTROL) => Some(Action::Quit),
        KeyCode::Char('q') | KeyCode::Esc => Some(Action::Quit),
        KeyCode::Right | KeyCode::Tab | KeyCode::Char('j') => Some(Action::NextMetric),
        KeyCode::Left | KeyCode::BackTab | KeyCode::Char('k') => Some(Action::PreviousMetric),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn press(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    #[test]
    fn bindings() {
        assert_eq!(action_for(press(KeyCode::Char('q'))), Some(Action::Quit));
        assert_eq!(action_for(press(KeyCode::Esc)), Some(Action::Quit));
        let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
        assert_eq!(action_for(ctrl_c), Some(Action::Quit));
        assert_eq!(action_for(press(KeyCode::Char('c'))), None);
        assert_eq!(action_for(press(KeyCode::Tab)), Some(Action::NextMetric));
        assert_eq!(action_for(press(KeyCode::Char('k'))), Some(Action::PreviousMetric));
    }

    #[test]
    fn releases_are_ignored() {
        let mut key = press(KeyCode::Char('q'));
        key.kind = KeyEventKind::Release;
        assert_eq!(action_for(key), None);
    }
}
