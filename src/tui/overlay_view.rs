//! Drawing an [`Overlay`]: a header, the runs (one colour each, with their status) and a grid of panels, one
//! per metric, each drawing that metric of every run over a shared step axis.

use crossterm::event::KeyEvent;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;

use super::overlay::Overlay;
use super::plot::{color, line_chart, Trace};
use super::terminal::LiveState;
use crate::run::follow::RunUpdate;

/// The smallest panel worth drawing a curve in; more metrics than fit at this size scroll with ←/→.
const MIN_PANEL_WIDTH: u16 = 36;
const MIN_PANEL_HEIGHT: u16 = 8;

impl LiveState for Overlay {
    type Update = RunUpdate;
    fn ingest(&mut self, update: RunUpdate) {
        self.update(&update);
    }
    fn handle_key(&mut self, key: KeyEvent) -> bool {
        Overlay::handle_key(self, key)
    }
    fn is_finished(&self) -> bool {
        self.all_finished()
    }
    fn mark_ended(&mut self) {
        Overlay::mark_ended(self);
    }
    fn draw(&self, frame: &mut Frame) {
        render_overlay(self, frame);
    }
}

pub(crate) fn render_overlay(overlay: &Overlay, frame: &mut Frame) {
    let runs_height = overlay.runs().len() as u16 + 2;
    let [header, runs, body] =
        Layout::vertical([Constraint::Length(1), Constraint::Length(runs_height), Constraint::Min(0)])
            .areas(frame.area());
    let names = overlay.metric_names();
    let (cols, rows) = grid(names.len(), body);
    let shown = usize::from(cols) * usize::from(rows);
    // All fit: in name order. Otherwise a window that starts at the scrolled-to metric and wraps.
    let start = if shown >= names.len() { 0 } else { overlay.first() };
    let visible: Vec<&str> = names.iter().cycle().skip(start).take(shown.min(names.len())).copied().collect();
    render_header(overlay, frame, header, (start, visible.len(), names.len()));
    render_runs(overlay, frame, runs);
    if visible.is_empty() {
        let empty = Paragraph::new("no metrics yet").style(Style::default().fg(Color::DarkGray));
        frame.render_widget(empty.block(Block::bordered().title(" Curves ")), body);
        return;
    }
    let row_areas = Layout::vertical(vec![Constraint::Ratio(1, u32::from(rows)); usize::from(rows)]).split(body);
    for (row, names) in row_areas.iter().zip(visible.chunks(usize::from(cols))) {
        // A short last row keeps the column width of the rows above, so the x axes line up.
        let cells = Layout::horizontal(vec![Constraint::Ratio(1, u32::from(cols)); usize::from(cols)]).split(*row);
        for (cell, name) in cells.iter().zip(names) {
            render_metric(overlay, name, frame, *cell);
        }
    }
}

/// Columns and rows for `count` panels in `area`: as many as fit at the smallest useful size, wide rather than
/// tall (a curve reads along x), and never an empty row.
pub(crate) fn grid(count: usize, area: Rect) -> (u16, u16) {
    if count == 0 {
        return (1, 1);
    }
    let cols_fit = (area.width / MIN_PANEL_WIDTH).max(1);
    let rows_fit = (area.height / MIN_PANEL_HEIGHT).max(1);
    let shown = count.min(usize::from(cols_fit) * usize::from(rows_fit)) as u16;
    let rows = rows_fit.min(shown);
    let cols = shown.div_ceil(rows);
    (cols, shown.div_ceil(cols))
}

fn render_header(overlay: &Overlay, frame: &mut Frame, area: Rect, (start, shown, total): (usize, usize, usize)) {
    let runs = overlay.runs();
    let finished = runs.iter().filter(|r| r.summary.finished.is_some()).count();
    let (state, state_color) = if overlay.reading_stopped() {
        ("stopped reading: a metrics file has an unreadable line; q shows why".to_string(), Color::Red)
    } else if finished == runs.len() {
        ("all finished".to_string(), Color::Green)
    } else {
        (format!("{finished} of {} finished", runs.len()), Color::Yellow)
    };
    let mut spans = vec![
        Span::styled(format!("watch {} runs", runs.len()), Style::default().add_modifier(Modifier::BOLD)),
        Span::raw("  "),
        Span::styled(state, Style::default().fg(state_color)),
        Span::raw("  "),
    ];
    let hints = if shown < total {
        format!("q quit · ←/→ metrics {}-{} of {total}", start + 1, (start + shown - 1) % total + 1)
    } else {
        "q quit".to_string()
    };
    spans.push(Span::styled(hints, Style::default().fg(Color::DarkGray)));
    frame.render_widget(Paragraph::new(Line::from(spans)), area);
}

/// One row per run: its colour, its name, its status and the job's title.
fn render_runs(overlay: &Overlay, frame: &mut Frame, area: Rect) {
    let width = overlay.runs().iter().map(|r| r.label.chars().count()).max().unwrap_or(0);
    let lines: Vec<Line> = overlay
        .runs()
        .iter()
        .enumerate()
        .map(|(i, run)| {
            let mut spans = vec![
                Span::styled("━━ ", Style::default().fg(color(i))),
                Span::styled(format!("{:width$}  ", run.label), Style::default().add_modifier(Modifier::BOLD)),
                Span::raw(run.status()),
            ];
            if let Some(title) = &run.summary.title {
                spans.push(Span::styled(format!("  {title}"), Style::default().fg(Color::DarkGray)));
            }
            Line::from(spans)
        })
        .collect();
    frame.render_widget(Paragraph::new(lines).block(Block::bordered().title(" Runs ")), area);
}

/// One metric of every run that has it, each in its run's colour, over the union of their steps.
fn render_metric(overlay: &Overlay, name: &str, frame: &mut Frame, area: Rect) {
    let mut by_sample = false;
    let traces: Vec<Trace> = overlay
        .runs()
        .iter()
        .enumerate()
        .filter_map(|(i, run)| {
            let series = run.series(name)?;
            by_sample |= series.x_label() == "sample";
            Some(Trace { name: run.label.clone(), points: series.points(), color: color(i) })
        })
        .collect();
    let x_title = if by_sample { "sample" } else { "step" };
    frame.render_widget(line_chart(traces, x_title, Block::bordered().title(format!(" {name} "))), area);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::watched::Liveness;
    use crate::run::Event;
    use ratatui::backend::TestBackend;
    use ratatui::Terminal;

    fn draw(overlay: &Overlay, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).expect("test terminal");
        terminal.draw(|frame| render_overlay(overlay, frame)).expect("draw");
        let buffer = terminal.backend().buffer();
        let cells: Vec<&str> = buffer.content().iter().map(|cell| cell.symbol()).collect();
        cells.chunks(usize::from(width.max(1))).map(|row| row.concat()).collect::<Vec<_>>().join("\n")
    }

    /// Two PETS runs: `seed1` finished after 300 steps, `seed2` still running at step 120 of 200.
    fn two_runs() -> Overlay {
        let mut overlay = Overlay::new(vec!["seed1".into(), "seed2".into()]);
        let title = Event::Layout { title: "train PETS on pendulum".into(), panels: vec![] };
        for (run, steps, total) in [(0, 300u64, 300u64), (1, 120, 200)] {
            overlay.update(&RunUpdate::Event { run, event: title.clone() });
            for step in 1..=steps {
                let loss = 1.0 / step as f64 + run as f64 * 0.1;
                overlay.update(&RunUpdate::Event { run, event: Event::scalar("train/loss", step, loss) });
                if step % 50 == 0 {
                    overlay.update(&RunUpdate::Event { run, event: Event::scalar("valid/loss", step, loss / 2.0) });
                }
            }
            overlay.update(&RunUpdate::Event { run, event: Event::progress("train", steps, total) });
        }
        overlay.update(&RunUpdate::Event { run: 0, event: Event::Finished { ok: true } });
        overlay.update(&RunUpdate::Liveness { run: 1, liveness: Liveness::Running });
        overlay
    }

    #[test]
    fn each_metric_gets_one_panel_with_every_run_in_its_legend() {
        let screen = draw(&two_runs(), 120, 36);
        for expected in [
            "watch 2 runs",
            "1 of 2 finished",
            "seed1  finished · train 300/300  train PETS on pendulum",
            "seed2  running · train 120/200",
            "┌ train/loss ",
            "┌ valid/loss ",
        ] {
            assert!(screen.contains(expected), "missing {expected:?} in\n{screen}");
        }
        // Each panel's legend names both runs: two legends, two names each.
        assert_eq!(screen.matches("seed1").count(), 3, "{screen}");
        assert_eq!(screen.matches("seed2").count(), 3, "{screen}");
        // The x axis runs to the longer run's last step.
        assert!(screen.contains("300"), "{screen}");
        assert!(!screen.contains("←/→"), "both panels fit: nothing to scroll\n{screen}");
    }

    #[test]
    fn the_runs_colours_match_their_lines() {
        let overlay = two_runs();
        let mut terminal = Terminal::new(TestBackend::new(120, 36)).expect("test terminal");
        terminal.draw(|frame| render_overlay(&overlay, frame)).expect("draw");
        let buffer = terminal.backend().buffer();
        let colours_in_row = |row: u16| -> Vec<Color> {
            (0..120).map(|x| buffer[(x, row)].fg).filter(|c| [color(0), color(1)].contains(c)).collect()
        };
        // Rows 2 and 3 are the runs, each starting with its marker in its colour.
        assert_eq!(colours_in_row(2).first(), Some(&color(0)));
        assert_eq!(colours_in_row(3).first(), Some(&color(1)));
        let plotted: Vec<Color> = (5..36).flat_map(colours_in_row).collect();
        assert!(plotted.contains(&color(0)) && plotted.contains(&color(1)), "both runs are drawn");
    }

    #[test]
    fn metrics_that_do_not_fit_scroll() {
        let mut overlay = Overlay::new(vec!["a".into(), "b".into()]);
        for (i, name) in ["m1", "m2", "m3", "m4", "m5"].iter().enumerate() {
            overlay.update(&RunUpdate::Event { run: i % 2, event: Event::scalar(*name, 1, 1.0) });
        }
        let screen = draw(&overlay, 80, 24);
        assert!(screen.contains("←/→ metrics 1-4 of 5"), "{screen}");
        assert!(screen.contains("┌ m4 ") && !screen.contains("┌ m5 "), "{screen}");
        overlay.handle_key(KeyEvent::new(crossterm::event::KeyCode::Right, crossterm::event::KeyModifiers::NONE));
        let screen = draw(&overlay, 80, 24);
        assert!(
            screen.contains("metrics 2-5 of 5") && screen.contains("┌ m5 ") && !screen.contains("┌ m1 "),
            "{screen}"
        );
    }

    #[test]
    fn grid_prefers_wide_panels_and_fills_its_rows() {
        let area = |w, h| Rect::new(0, 0, w, h);
        assert_eq!(grid(2, area(120, 30)), (1, 2));
        assert_eq!(grid(4, area(120, 30)), (2, 2));
        assert_eq!(grid(7, area(120, 30)), (3, 3));
        assert_eq!(grid(30, area(120, 30)), (3, 3));
        assert_eq!(grid(3, area(20, 5)), (1, 1));
    }

    #[test]
    fn empty_and_tiny_screens_do_not_panic() {
        let overlay = Overlay::new(vec!["a".into()]);
        assert!(draw(&overlay, 60, 20).contains("no metrics yet"));
        let full = two_runs();
        for width in 0..=30 {
            for height in 0..=12 {
                draw(&full, width, height);
            }
        }
    }
}
