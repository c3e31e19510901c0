//! Text panels: the latest preformatted text (a board, a plan) a job sent under each panel name. Bounded
//! in count and size, so a job that sends a new panel name or a huge text on every step cannot exhaust
//! memory.

/// Text panels kept at most; beyond this the least recently updated one is forgotten.
pub(crate) const TEXT_PANEL_CAP: usize = 16;

/// Bytes of text kept per panel: far more than fits on a screen, small enough to copy every frame.
pub(crate) const TEXT_CAP: usize = 4096;

/// Marks text cut at [`TEXT_CAP`], so a truncated plan is not mistaken for the whole of it.
const CUT_MARK: &str = "…";

#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TextPanel {
    pub(crate) name: String,
    pub(crate) text: String,
    /// Position in the stream of text updates: tells which panel is stalest when the cap is reached.
    sequence: u64,
}

impl TextPanel {
    /// Rows the text needs (at least one, so an empty panel still reads as a panel).
    pub(crate) fn line_count(&self) -> usize {
        self.text.lines().count().max(1)
    }
}

/// Text panels in order of first appearance.
#[derive(Clone, Debug, Default)]
pub(crate) struct TextPanels {
    panels: Vec<TextPanel>,
    updates: u64,
}

impl TextPanels {
    /// Replaces the text of `name`, creating the panel on its first text.
    pub(crate) fn set(&mut self, name: &str, text: &str) {
        self.updates += 1;
        let text = capped(text);
        if let Some(panel) = self.panels.iter_mut().find(|p| p.name == name) {
            panel.text = text;
            panel.sequence = self.updates;
            return;
        }
        if self.panels.len() >= TEXT_PANEL_CAP {
            let stalest = self.panels.iter().enumerate().min_by_key(|(_, p)| p.sequence).map_or(0, |(i, _)| i);
            self.panels.remove(stalest);
        }
        self.panels.push(TextPanel { name: name.to_string(), text, sequence: self.updates });
    }

    pub(crate) fn as_slice(&self) -> &[TextPanel] {
        &self.panels
    }
}

/// `text`, cut on a character boundary to at most [`TEXT_CAP`] bytes, mark included.
fn capped(text: &str) -> String {
    if text.len() <= TEXT_CAP {
        return text.to_string();
    }
    let mut end = TEXT_CAP - CUT_MARK.len();
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}{CUT_MARK}", &text[..end])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(panels: &TextPanels) -> Vec<&str> {
        panels.as_slice().iter().map(|p| p.name.as_str()).collect()
    }

    #[test]
    fn later_text_replaces_and_order_is_first_appearance() {
        let mut panels = TextPanels::default();
        panels.set("board", "■ ·");
        panels.set("plan", "push (0, 1)");
        panels.set("board", "· ■");
        assert_eq!(names(&panels), vec!["board", "plan"]);
        assert_eq!(panels.as_slice()[0].text, "· ■");
        assert_eq!(panels.as_slice()[1].text, "push (0, 1)");
    }

    #[test]
    fn the_stalest_panel_is_forgotten_beyond_the_cap() {
        let mut panels = TextPanels::default();
        panels.set("board", "b");
        for k in 0..TEXT_PANEL_CAP {
            panels.set(&format!("step {k}"), "s");
            panels.set("board", "b");
        }
        assert_eq!(panels.as_slice().len(), TEXT_PANEL_CAP);
        assert_eq!(names(&panels)[0], "board", "the live panel stays, in place");
        assert!(!names(&panels).contains(&"step 0"), "the stalest panel goes");
        assert_eq!(names(&panels).last(), Some(&format!("step {}", TEXT_PANEL_CAP - 1).as_str()));
    }

    #[test]
    fn long_text_is_cut_on_a_character_boundary() {
        let mut panels = TextPanels::default();
        let board = "■·".repeat(TEXT_CAP);
        panels.set("board", &board);
        let kept = &panels.as_slice()[0].text;
        assert!(kept.len() <= TEXT_CAP, "{} bytes kept", kept.len());
        assert!(kept.len() > TEXT_CAP - 8);
        assert!(kept.ends_with(CUT_MARK));
        assert!(board.starts_with(kept.trim_end_matches(CUT_MARK)));

        let exact = "x".repeat(TEXT_CAP);
        panels.set("plan", &exact);
        assert_eq!(panels.as_slice()[1].text, exact, "text at the cap is kept whole");
    }

    #[test]
    fn line_count_ignores_a_trailing_newline_and_is_never_zero() {
        let panel = |text: &str| TextPanel { name: "p".into(), text: text.into(), sequence: 0 };
        assert_eq!(panel("a\nb\n").line_count(), 2);
        assert_eq!(panel("a\r\nb").line_count(), 2);
        assert_eq!(panel("").line_count(), 1);
    }
}
