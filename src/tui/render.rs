//! Drawing an [`App`] into a frame. Layout, top to bottom: a status line, the progress gauges, the
//! curves (the selected metric beside the method panels: charts, then text) and the latest messages.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Gauge, Paragraph};
use ratatui::Frame;

use super::app::{App, Status};
use super::method::{method_rows, stack};
use super::panel::Panel;
use super::path::PathPlot;
use super::plot::{color, format_value, line_chart, short_names, Trace};
use super::text_panel::TextPanel;
use crate::run::monitor::PhaseProgress;

/// Messages shown at most; the panel collapses when there are none.
const MAX_MESSAGE_ROWS: usize = 5;

/// Progress phases shown at most: enough for a job's episodes, the steps inside one, and the phase before.
const MAX_PHASE_ROWS: usize = 3;

pub fn render(app: &App, frame: &mut Frame) {
    let [header, progress, body, messages] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(progress_height(app, frame.area().height)),
        Constraint::Min(0),
        // Max, not Length: on a short terminal the messages give way before the progress gauge does.
        Constraint::Max(messages_height(app)),
    ])
    .areas(frame.area());
    render_header(app, frame, header);
    render_progress(app, frame, progress);
    render_body(app, frame, body);
    render_messages(app, frame, messages);
}

/// Title, status and key hints on one row. A narrow terminal drops the hints first, then cuts the
/// title (marked with …); the status always shows.
fn render_header(app: &App, frame: &mut Frame, area: Rect) {
    let (status, status_color) = status_label(app.status());
    let hints = match (app.is_finished(), app.has_curves()) {
        (true, true) => "←/→ metric",
        (true, false) => "",
        (false, true) => "q quit · ←/→ metric",
        (false, false) => "q quit",
    };
    let width = usize::from(area.width);
    let title_width = app.title().chars().count();
    let status_width = status.chars().count();
    let hints_shown = !hints.is_empty() && title_width + status_width + hints.chars().count() + 4 <= width;
    let title = fit(app.title(), width.saturating_sub(status_width + 2));
    let mut spans = Vec::new();
    if !title.is_empty() {
        spans.extend([Span::styled(title, Style::default().add_modifier(Modifier::BOLD)), Span::raw("  ")]);
    }
    spans.push(Span::styled(status, Style::default().fg(status_color).add_modifier(Modifier::BOLD)));
    if hints_shown {
        spans.extend([Span::raw("  "), Span::styled(hints, Style::default().fg(Color::DarkGray))]);
    }
    frame.render_widget(Paragraph::new(Line::from(spans)), area);
}

/// `text` cut to `width` characters, the cut marked with an ellipsis.
fn fit(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        return text.to_string();
    }
    let mut cut: String = text.chars().take(width.saturating_sub(1)).collect();
    if width > 0 {
        cut.push('…');
    }
    cut
}

fn status_label(status: Status) -> (&'static str, Color) {
    match status {
        Status::Running => ("running", Color::Yellow),
        Status::Done => ("done — press q to quit", Color::Green),
        Status::Failed => ("failed — press q to quit", Color::Red),
        Status::Ended => ("ended — press q to quit", Color::Gray),
    }
}

/// The phases shown: the most recently updated ones, up to [`MAX_PHASE_ROWS`]. A short terminal shows
/// fewer (one row more for every two rows past 18) so that the curves keep room.
fn shown_phases(app: &App, screen_height: u16) -> Vec<&PhaseProgress> {
    let fit = 1 + usize::from(screen_height.saturating_sub(18) / 2);
    app.progress(fit.min(MAX_PHASE_ROWS))
}

/// One row per shown phase (one for the placeholder) inside a border.
fn progress_height(app: &App, screen_height: u16) -> u16 {
    shown_phases(app, screen_height).len().max(1) as u16 + 2
}

fn render_progress(app: &App, frame: &mut Frame, area: Rect) {
    let block = Block::bordered().title(" Progress ");
    let phases = shown_phases(app, frame.area().height);
    if phases.is_empty() {
        let waiting = Paragraph::new("waiting for progress…").style(Style::default().fg(Color::DarkGray));
        frame.render_widget(waiting.block(block), area);
        return;
    }
    let inner = block.inner(area);
    frame.render_widget(block, area);
    let rows = Layout::vertical(vec![Constraint::Length(1); phases.len()]).split(inner);
    for (phase, row) in phases.iter().zip(rows.iter()) {
        let gauge = Gauge::default()
            .ratio(phase.ratio())
            .label(phase.summary())
            .gauge_style(Style::default().fg(Color::Cyan).bg(Color::Black));
        frame.render_widget(gauge, *row);
    }
}

fn render_body(app: &App, frame: &mut Frame, area: Rect) {
    if app.panels().is_empty() && app.text_panels().is_empty() {
        render_curves(app, frame, area);
        return;
    }
    if !app.has_curves() {
        render_method_columns(app, frame, area);
        return;
    }
    let [curves, method] = Layout::horizontal([Constraint::Percentage(50); 2]).areas(area);
    // A map under a path is the view's main picture: it takes the Curves panel's place.
    if let Some(first) = app.panels().first().filter(|p| p.spec().path.as_ref().is_some_and(|v| v.background.is_some()))
    {
        render_panel(first, frame, curves);
        render_panels(&app.panels()[1..], app, frame, method);
        return;
    }
    render_curves(app, frame, curves);
    render_method(app, frame, method);
}

/// The method panels alone, with the Curves panel's half to spare: charts in the left column, text
/// panels in the right, each column to itself when the other kind is missing.
fn render_method_columns(app: &App, frame: &mut Frame, area: Rect) {
    if app.panels().is_empty() || app.text_panels().is_empty() {
        render_method(app, frame, area);
        return;
    }
    let [charts, texts] = Layout::horizontal([Constraint::Percentage(50); 2]).areas(area);
    let chart_rows = stack(charts, &method_rows(app.panels().len(), &[], charts.height));
    for (panel, row) in app.panels().iter().zip(chart_rows) {
        render_panel(panel, frame, row);
    }
    render_text_panels(app, frame, texts);
}

/// The text panels, sized to their text, using the whole of `area`.
fn render_text_panels(app: &App, frame: &mut Frame, area: Rect) {
    let heights = method_rows(0, &text_heights(app), area.height);
    for (panel, row) in app.text_panels().iter().zip(stack(area, &heights)) {
        render_text_panel(panel, frame, row);
    }
}

fn text_heights(app: &App) -> Vec<u16> {
    app.text_panels().iter().map(|p| u16::try_from(p.line_count() + 2).unwrap_or(u16::MAX)).collect()
}

/// The chart panels, then the text panels sized to their text.
fn render_method(app: &App, frame: &mut Frame, area: Rect) {
    render_panels(app.panels(), app, frame, area);
}

/// These chart panels, then the app's text panels sized to their text.
fn render_panels(panels: &[Panel], app: &App, frame: &mut Frame, area: Rect) {
    let heights = method_rows(panels.len(), &text_heights(app), area.height);
    let rows = stack(area, &heights);
    let (chart_rows, text_rows) = rows.split_at(panels.len());
    for (panel, row) in panels.iter().zip(chart_rows) {
        render_panel(panel, frame, *row);
    }
    for (panel, row) in app.text_panels().iter().zip(text_rows) {
        render_text_panel(panel, frame, *row);
    }
}

fn render_curves(app: &App, frame: &mut Frame, area: Rect) {
    let Some((name, series, position)) = app.selected_series() else {
        let empty = Paragraph::new("no metrics yet").style(Style::default().fg(Color::DarkGray));
        frame.render_widget(empty.block(Block::bordered().title(" Curves ")), area);
        return;
    };
    let last = series.last_value().map_or_else(|| "-".to_string(), format_value);
    let title = format!(" {name} = {last}  ({position}/{}) ", app.metric_count());
    let trace = Trace { name: name.to_string(), points: series.points(), color: Color::Cyan };
    frame.render_widget(line_chart(vec![trace], series.x_label(), Block::bordered().title(title)), area);
}

fn render_panel(panel: &Panel, frame: &mut Frame, area: Rect) {
    let spec = panel.spec();
    let block = Block::bordered().title(format!(" {} ", spec.title));
    if let Some(view) = &spec.path {
        let mut series = panel.series().map(|(_, s)| s);
        if let (Some(xs), Some(ys)) = (series.next(), series.next()) {
            let second = series.next().zip(series.next());
            let inner = block.inner(area);
            frame.render_widget(PathPlot::new(xs, ys, second, view).chart(block), area);
            // After the chart, whose canvas resets the background: only the cells' background changes.
            if let Some(background) = &view.background {
                paint_background(frame, inner, background, view.y_down);
            }
            return;
        }
    }
    if panel.series().all(|(_, series)| series.points().is_empty()) {
        // A metric logged every few hundred steps leaves its panel blank for a while: say so.
        let waiting = Paragraph::new("no points yet").style(Style::default().fg(Color::DarkGray));
        frame.render_widget(waiting.block(block), area);
        return;
    }
    let names: Vec<&str> = panel.series().map(|(name, _)| name).collect();
    let traces = short_names(&names)
        .into_iter()
        .zip(panel.series())
        .enumerate()
        .map(|(i, (label, (_, series)))| Trace { name: label.to_string(), points: series.points(), color: color(i) })
        .collect();
    frame.render_widget(line_chart(traces, &spec.x_label, block), area);
}

/// Colours each cell of a path panel's plot area from the panel's background grid, under the path.
fn paint_background(frame: &mut Frame, area: Rect, background: &crate::run::Background, y_down: bool) {
    let buffer = frame.buffer_mut();
    for row in 0..area.height {
        for col in 0..area.width {
            let u = (f64::from(col) + 0.5) / f64::from(area.width);
            let from_top = (f64::from(row) + 0.5) / f64::from(area.height);
            let v = if y_down { from_top } else { 1.0 - from_top };
            if let Some([r, g, b]) = background.color_at(u, v) {
                if let Some(cell) = buffer.cell_mut((area.x + col, area.y + row)) {
                    cell.set_bg(Color::Rgb(r, g, b));
                }
            }
        }
    }
}

/// The text verbatim. No wrapping: a wrapped row would break a board's grid, so long lines are cut at
/// the last whole item that fits instead, and lines beyond the panel's height are left out.
fn render_text_panel(panel: &TextPanel, frame: &mut Frame, area: Rect) {
    let block = Block::bordered().title(format!(" {} ", panel.name));
    let width = usize::from(block.inner(area).width);
    let lines: Vec<Line> = panel.text.lines().map(|line| Line::from(fit_whole_items(line, width))).collect();
    frame.render_widget(Paragraph::new(lines).block(block), area);
}

/// `line` cut to `width` characters at a space, so a value shows whole or not at all (a step range of
/// 1500-3000 never reads as 1500-300); a line that is one item (a board's row) is cut at the border. The
/// cut is marked with an ellipsis.
fn fit_whole_items(line: &str, width: usize) -> String {
    if line.chars().count() <= width {
        return line.to_string();
    }
    if width == 0 {
        return String::new();
    }
    let room = width - 1;
    let head: String = line.chars().take(room).collect();
    let cut_at_space = line.chars().nth(room).is_some_and(char::is_whitespace);
    let kept = match head.rfind(char::is_whitespace) {
        _ if cut_at_space => head.as_str(),
        Some(at) => &head[..at],
        None => head.as_str(),
    };
    format!("{}…", kept.trim_end())
}

fn messages_height(app: &App) -> u16 {
    match app.messages().len().min(MAX_MESSAGE_ROWS) {
        0 => 0,
        rows => rows as u16 + 2,
    }
}

fn render_messages(app: &App, frame: &mut Frame, area: Rect) {
    let visible = usize::from(area.height.saturating_sub(2));
    let hidden = app.messages().len().saturating_sub(visible);
    let lines: Vec<Line> = app.messages().skip(hidden).map(Line::from).collect();
    frame.render_widget(Paragraph::new(lines).block(Block::bordered().title(" Messages ")), area);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{Event, PanelSpec};
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use ratatui::backend::TestBackend;
    use ratatui::Terminal;
    use std::time::{Duration, Instant};

    fn draw(app: &App, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).expect("test terminal");
        terminal.draw(|frame| render(app, frame)).expect("draw");
        let buffer = terminal.backend().buffer();
        let width = usize::from(buffer.area().width.max(1));
        let cells: Vec<&str> = buffer.content().iter().map(|cell| cell.symbol()).collect();
        cells.chunks(width).map(|row| row.concat()).collect::<Vec<_>>().join("\n")
    }

    fn pendulum_app() -> App {
        let mut app = App::new("ignored");
        let t0 = Instant::now();
        app.ingest_at(
            &Event::Layout {
                title: "cem on pendulum".into(),
                panels: vec![PanelSpec {
                    title: "pendulum".into(),
                    x_label: "t".into(),
                    series: vec!["pendulum/angle".into(), "pendulum/action".into()],
                    restart_on_rewind: true,
                    path: None,
                }],
            },
            t0,
        );
        for step in 0..20u64 {
            let t = step as f64 * 0.1;
            app.ingest_at(&Event::scalar("cem/best_cost", step, 100.0 - t), t0);
            app.ingest_at(&Event::scalar("pendulum/angle", step, t.sin()), t0);
            app.ingest_at(&Event::scalar("pendulum/action", step, t.cos()), t0);
        }
        app.ingest_at(&Event::progress("mpc", 0, 150), t0);
        app.ingest_at(&Event::progress("mpc", 50, 150), t0 + Duration::from_secs(10));
        app
    }

    #[test]
    fn full_screen_shows_every_panel() {
        let screen = draw(&pendulum_app(), 100, 40);
        for expected in [
            "cem on pendulum",
            "running",
            "q quit",
            "mpc: 50/150 (33%) 5.0/s, ETA 20s",
            "cem/best_cost = 98.100",
            "(1/3)",
            "pendulum",
            "angle",
            "action",
        ] {
            assert!(screen.contains(expected), "missing {expected:?} in\n{screen}");
        }
        assert!(!screen.contains("Messages"), "no messages, so no Messages panel:\n{screen}");
    }

    #[test]
    fn switching_metric_changes_the_curves_title() {
        let mut app = pendulum_app();
        app.handle_key(KeyEvent::new(KeyCode::Right, KeyModifiers::NONE));
        let screen = draw(&app, 100, 40);
        assert!(screen.contains("pendulum/action = "), "{screen}");
        assert!(!screen.contains("cem/best_cost = "), "{screen}");
    }

    #[test]
    fn a_panel_without_points_says_so() {
        let mut app = pendulum_app();
        let layout = Event::Layout {
            title: "train".into(),
            panels: vec![PanelSpec {
                title: "rare metric".into(),
                x_label: "step".into(),
                series: vec!["valid/rare".into()],
                restart_on_rewind: false,
                path: None,
            }],
        };
        app.ingest(&layout);
        assert!(draw(&app, 100, 40).contains("no points yet"));
        app.ingest(&Event::scalar("valid/rare", 1, 0.5));
        assert!(!draw(&app, 100, 40).contains("no points yet"));
    }

    #[test]
    fn empty_app_renders_placeholders() {
        let screen = draw(&App::new("fresh run"), 60, 12);
        assert!(screen.contains("fresh run"), "{screen}");
        assert!(screen.contains("waiting for progress"), "{screen}");
        assert!(screen.contains("no metrics yet"), "{screen}");
    }

    #[test]
    fn finished_run_says_how_to_leave() {
        let mut app = pendulum_app();
        app.ingest(&Event::Finished { ok: true });
        let screen = draw(&app, 100, 20);
        assert!(screen.contains("done — press q to quit"), "{screen}");
        assert!(!screen.contains("running"), "{screen}");

        app.ingest(&Event::Finished { ok: false });
        assert!(draw(&app, 100, 20).contains("failed — press q to quit"));
    }

    #[test]
    fn long_text_lines_lose_whole_items_never_digits() {
        assert_eq!(fit_whole_items("kl ramp  steps 1500-3000", 22), "kl ramp  steps…");
        assert_eq!(fit_whole_items("kl ramp  steps 1500-3000", 24), "kl ramp  steps 1500-3000");
        assert_eq!(fit_whole_items("kl ramp  steps 1500-3000", 15), "kl ramp  steps…");
        assert_eq!(fit_whole_items("kl ramp  steps 1500-3000", 14), "kl ramp…");
        assert_eq!(fit_whole_items("1500-3000", 5), "1500…", "one item is cut at the border");
        assert_eq!(fit_whole_items("1500-3000", 0), "");
        let mut app = App::new("train context");
        app.ingest(&Event::text("settings", "lr           0.001\nkl schedule  steps 1500-3000, then 1"));
        let screen = draw(&app, 30, 24);
        assert!(screen.contains("kl schedule  steps…") && !screen.contains("1500"), "{screen}");
    }

    #[test]
    fn messages_show_the_newest() {
        let mut app = App::new("t");
        for i in 0..12 {
            app.ingest(&Event::message(format!("note number {i}")));
        }
        let screen = draw(&app, 60, 24);
        assert!(screen.contains("note number 11"), "{screen}");
        assert!(screen.contains("note number 7"), "{screen}");
        assert!(!screen.contains("note number 6"), "{screen}");
    }

    #[test]
    fn degenerate_series_render() {
        let mut app = App::new("t");
        app.ingest(&Event::scalar("single", 3, 1.5));
        app.ingest(&Event::scalar("constant", 0, 2.0));
        app.ingest(&Event::scalar("constant", 1, 2.0));
        app.ingest(&Event::scalar("diverged", 0, 1.0));
        app.ingest(&Event::scalar("diverged", 1, f64::NAN));
        for _ in 0..3 {
            let name = app.selected_metric().expect("a metric").to_string();
            let screen = draw(&app, 60, 20);
            assert!(screen.contains(&name), "{screen}");
            app.handle_key(KeyEvent::new(KeyCode::Tab, KeyModifiers::NONE));
        }
        while app.selected_metric() != Some("diverged") {
            app.handle_key(KeyEvent::new(KeyCode::Tab, KeyModifiers::NONE));
        }
        assert!(draw(&app, 60, 20).contains("diverged = NaN"));
    }

    /// `mbrl eval pendulum-swingup --episodes 3`, stopped in the middle of the second episode: progress
    /// of the episodes around progress of each episode's MPC steps, and CEM's iteration counting 0..9
    /// again for every MPC step.
    fn swingup_app() -> App {
        let mut app = App::new("swing-up");
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        for episode in 0..2u64 {
            app.ingest_at(&Event::progress("episodes", episode, 3), at(3000 * episode));
            let steps = if episode == 0 { 150 } else { 75 };
            for t in 0..steps {
                for iteration in 0..10 {
                    let cost = 100.0 - iteration as f64 - t as f64 * 0.1;
                    app.ingest_at(&Event::scalar("cem/best_cost", iteration, cost), at(3000 * episode + 20 * t));
                }
                let phase = format!("episode {} MPC", episode + 1);
                app.ingest_at(&Event::progress(phase, t + 1, 150), at(3000 * episode + 20 * t));
            }
        }
        app
    }

    #[test]
    fn progress_lists_the_recent_phases_with_their_own_rates() {
        let screen = draw(&swingup_app(), 100, 30);
        let rows: Vec<&str> = screen.lines().collect();
        let row_of = |text: &str| rows.iter().position(|row| row.contains(text));
        let outer = row_of("episodes: 1/3 (33%) 0.3/s, ETA 6s").unwrap_or_else(|| panic!("{screen}"));
        let done = row_of("episode 1 MPC: 150/150 (100%) 50.0/s").unwrap_or_else(|| panic!("{screen}"));
        let current = row_of("episode 2 MPC: 75/150 (50%) 50.0/s, ETA 2s").unwrap_or_else(|| panic!("{screen}"));
        assert_eq!((done, current), (outer + 1, outer + 2), "one gauge a row, in order of appearance:\n{screen}");
        assert!(!screen.contains(" 0.0/s"), "{screen}");
    }

    #[test]
    fn short_terminals_show_only_the_latest_phase() {
        let screen = draw(&swingup_app(), 100, 18);
        assert!(screen.contains("episode 2 MPC: 75/150"), "{screen}");
        assert!(!screen.contains("episodes:"), "{screen}");
        let screen = draw(&swingup_app(), 100, 20);
        assert!(screen.contains("episodes: 1/3") && screen.contains("episode 2 MPC"), "{screen}");
        assert!(!screen.contains("episode 1 MPC"), "{screen}");
    }

    #[test]
    fn a_rewinding_metric_is_drawn_against_the_sample_index() {
        let app = swingup_app();
        let (_, history, _) = app.selected_series().expect("cost is selected");
        assert_eq!(history.points().len(), 2250);
        assert!(history.points().windows(2).all(|w| w[0].0 < w[1].0));
        let screen = draw(&app, 100, 30);
        assert!(screen.contains("sample"), "{screen}");
        assert!(screen.contains("2249"), "x runs over every sample:\n{screen}");
        assert!(!screen.contains("step"), "{screen}");

        let screen = draw(&pendulum_app(), 100, 30);
        assert!(screen.contains("step") && !screen.contains("sample"), "{screen}");
    }

    const BOARD: &str = "■ · · · ■\n· ■ · · ·\n· · ■ · ·\n· · · ■ ·\n■ · · · ■";

    /// Row and column (in cells) where `text` first appears.
    fn find(screen: &str, text: &str) -> Option<(usize, usize)> {
        screen
            .lines()
            .enumerate()
            .find_map(|(row, line)| line.find(text).map(|byte| (row, line[..byte].chars().count())))
    }

    fn cell(screen: &str, row: usize, col: usize) -> Option<char> {
        screen.lines().nth(row)?.chars().nth(col)
    }

    /// `mbrl solve-board` with its board and plan, optionally beside a chart panel.
    fn board_app(with_chart: bool) -> App {
        let mut app = if with_chart { pendulum_app() } else { App::new("solve-board") };
        app.ingest(&Event::text("board", BOARD));
        app.ingest(&Event::text("plan", "plan: push (0, 1)"));
        app
    }

    /// Asserts the panel titled `title` holds `lines` verbatim, one a row, and fits them exactly: its
    /// bottom border follows the last line. Returns the rows of its top and bottom borders.
    fn assert_fitted_panel(screen: &str, title: &str, lines: &[&str]) -> (usize, usize) {
        let (top, left) = find(screen, &format!("┌ {title} ")).unwrap_or_else(|| panic!("no {title}:\n{screen}"));
        for (i, line) in lines.iter().enumerate() {
            let row = screen.lines().nth(top + 1 + i).unwrap_or_else(|| panic!("no row for {line:?}:\n{screen}"));
            let shown: String = row.chars().skip(left + 1).take(line.chars().count()).collect();
            assert_eq!(shown, *line, "line {i} of {title} misplaced:\n{screen}");
        }
        let bottom = top + 1 + lines.len();
        assert_eq!(cell(screen, bottom, left), Some('└'), "{title} must end below its text:\n{screen}");
        (top, bottom)
    }

    #[test]
    fn text_panels_show_board_and_plan_verbatim_below_the_charts() {
        let screen = draw(&board_app(true), 100, 40);
        let board: Vec<&str> = BOARD.lines().collect();
        let (board_top, board_bottom) = assert_fitted_panel(&screen, "board", &board);
        let (plan_top, _) = assert_fitted_panel(&screen, "plan", &["plan: push (0, 1)"]);
        assert_eq!(plan_top, board_bottom + 1, "text panels in order of first appearance:\n{screen}");
        let (chart_top, _) = find(&screen, "┌ pendulum ").unwrap_or_else(|| panic!("{screen}"));
        assert!(chart_top < board_top, "charts come first:\n{screen}");
        assert!(board_top - chart_top > 10, "the chart takes the rows the text does not need:\n{screen}");
        assert!(screen.contains("cem/best_cost = "), "{screen}");
    }

    #[test]
    fn later_text_replaces_the_panel_text() {
        let mut app = board_app(true);
        app.ingest(&Event::text("plan", "plan: pull (4, 4)\nthen: done"));
        let screen = draw(&app, 100, 40);
        assert!(!screen.contains("push (0, 1)"), "{screen}");
        assert_fitted_panel(&screen, "plan", &["plan: pull (4, 4)", "then: done"]);
        assert_eq!(screen.matches("┌ plan ").count(), 1, "{screen}");
    }

    #[test]
    fn with_nothing_to_chart_text_panels_take_the_whole_body() {
        let screen = draw(&board_app(false), 80, 24);
        assert!(!screen.contains("no metrics yet") && !screen.contains("metric"), "no empty Curves panel:\n{screen}");
        let (_, board_bottom) = assert_fitted_panel(&screen, "board", &BOARD.lines().collect::<Vec<_>>());
        let (plan_top, left) = find(&screen, "┌ plan ").unwrap_or_else(|| panic!("{screen}"));
        assert_eq!(plan_top, board_bottom + 1, "{screen}");
        assert_eq!(cell(&screen, 23, left), Some('└'), "the last panel reaches the bottom:\n{screen}");
        assert_eq!(left, 0, "{screen}");
    }

    /// `mbrl solve-board --embodiment reacher` halfway through its plan, on the smallest terminal the
    /// view promises to serve.
    fn solve_board_app() -> App {
        use crate::envs::boards::{BoardGame, LightsOut};
        use crate::planning::board_view::{layout, plan_text, show_boards};
        use crate::run::{ChannelMonitor, Monitor};
        let game = LightsOut::new(5).expect("5x5");
        let (sender, events) = std::sync::mpsc::channel();
        let monitor = ChannelMonitor::new(sender, Default::default());
        let start = game.pressed(&[0, 7, 12, 18, 24]);
        let mut app = App::new("t");
        app.ingest(&layout("solve-board: lightsout-5x5", 5, true));
        for depth in 1..=5u64 {
            app.ingest(&Event::scalar("bfs/stored", depth, (depth * depth * 100) as f64));
            app.ingest(&Event::scalar("bfs/expanded", depth, (depth * depth * 40) as f64));
        }
        let names: Vec<String> = [0, 7, 12, 18, 24].iter().map(|&m| game.move_name(m)).collect();
        show_boards(&monitor, &game, start, Some(("after 2/5", game.pressed(&[18, 24]))));
        monitor.emit(&Event::text("plan", plan_text(&names, 2, true)));
        for step in 1..=30u64 {
            let t = step as f64 / 30.0;
            app.ingest(&Event::scalar("effector/x", step, 0.1 + 0.8 * t));
            app.ingest(&Event::scalar("effector/y", step, 0.5));
        }
        drop(monitor);
        for event in events.try_iter() {
            app.ingest(&event);
        }
        app
    }

    #[test]
    fn a_board_solve_fits_80_by_24_without_a_duplicate_chart() {
        let screen = draw(&solve_board_app(), 80, 24);
        assert!(!screen.contains("bfs/stored ="), "the search panel draws it already:\n{screen}");
        assert!(screen.contains("┌ search: stored, expanded per depth"), "{screen}");
        let (path_top, path_left) =
            find(&screen, "┌ effector path over the board").unwrap_or_else(|| panic!("{screen}"));
        assert_eq!(path_left, 0, "charts fill the left column:\n{screen}");
        assert!(path_top + 6 < 24, "the path panel has rows to draw in:\n{screen}");
        let app = solve_board_app();
        let boards = &app.text_panels().iter().find(|p| p.name == "boards").expect("boards panel").text;
        let lines: Vec<&str> = boards.lines().collect();
        assert_eq!(lines.len(), 6, "captions and five rows:\n{boards}");
        assert!(lines[0].starts_with("start       after 2/5   goal"), "{boards}");
        let (top, _) = assert_fitted_panel(&screen, "boards", &lines);
        let (plan_top, _) = find(&screen, "┌ plan ").unwrap_or_else(|| panic!("{screen}"));
        assert!(plan_top > top, "{screen}");
        for line in ["✓  1 push (0, 0)", "▶  3 push (2, 2)", "   5 push (4, 4)"] {
            assert!(screen.contains(line), "missing {line:?}:\n{screen}");
        }
    }

    /// A replayed metrics file may carry any path plane: none of them may panic or allocate without bound.
    #[test]
    fn absurd_path_planes_render() {
        use crate::run::{PanelSpec, PathView};
        for (x, y, grid) in [
            ([f64::NAN, 1.0], [0.0, f64::INFINITY], u32::MAX),
            ([1.0, 0.0], [5.0, 5.0], 0),
            ([-f64::MAX, f64::MAX], [0.0, 1.0], 64),
        ] {
            let mut app = App::new("t");
            app.ingest(&Event::Layout {
                title: "t".into(),
                panels: vec![PanelSpec {
                    title: "path".into(),
                    x_label: "x".into(),
                    series: vec!["p/x".into(), "p/y".into()],
                    restart_on_rewind: false,
                    path: Some(PathView { x, y, grid, y_down: true, background: None }),
                }],
            });
            for step in 0..3 {
                app.ingest(&Event::scalar("p/x", step, step as f64));
                app.ingest(&Event::scalar("p/y", step, f64::NAN));
            }
            assert!(draw(&app, 80, 24).contains("┌ path "));
            draw(&app, 3, 3);
        }
    }

    #[test]
    fn the_header_drops_hints_then_cuts_the_title() {
        let mut app = App::new("train context model on pendulum:quadrant with a very long title indeed");
        app.ingest(&Event::scalar("train/loss", 1, 1.0));
        let wide = draw(&app, 120, 10);
        assert!(wide.contains("indeed  running  q quit · ←/→ metric"), "{wide}");
        let narrow = draw(&app, 60, 10);
        let header = narrow.lines().next().unwrap_or_default();
        assert!(header.contains("…  running"), "{narrow}");
        assert!(!header.contains("quit"), "{narrow}");
        assert!(draw(&app, 8, 10).lines().next().unwrap_or_default().contains("running"));
    }

    #[test]
    fn long_lines_are_cut_not_wrapped() {
        let mut app = App::new("t");
        app.ingest(&Event::text("wide", format!("{}END\nnext row", "■".repeat(60))));
        let screen = draw(&app, 60, 20);
        assert!(!screen.contains("END"), "{screen}");
        let (row, col) = find(&screen, "■■■■").unwrap_or_else(|| panic!("{screen}"));
        assert_eq!(find(&screen, "next row"), Some((row + 1, col)), "{screen}");
        assert_eq!(cell(&screen, row, 57), Some('■'), "the line runs to the border:\n{screen}");
        assert_eq!(cell(&screen, row, 58), Some('…'), "and is marked as cut there:\n{screen}");
    }

    #[test]
    fn a_tall_text_leaves_the_charts_room() {
        let mut app = pendulum_app();
        app.ingest(&Event::text("plan", (0..100).map(|i| format!("step {i}")).collect::<Vec<_>>().join("\n")));
        let screen = draw(&app, 100, 30);
        let (chart_top, _) = find(&screen, "┌ pendulum ").unwrap_or_else(|| panic!("{screen}"));
        let (plan_top, _) = find(&screen, "┌ plan ").unwrap_or_else(|| panic!("{screen}"));
        assert!(plan_top >= chart_top + 6, "{screen}");
        assert!(screen.contains("step 0") && !screen.contains("step 99"), "{screen}");
    }

    #[test]
    fn tiny_terminals_do_not_panic() {
        let mut app = pendulum_app();
        app.ingest(&Event::message("a message that is far wider than the terminal"));
        let swingup = swingup_app();
        let mut texts = board_app(true);
        for k in 0..20 {
            texts.ingest(&Event::text(format!("panel {k}"), "■ ·\n".repeat(k)));
        }
        for width in 0..=24 {
            for height in 0..=24 {
                draw(&app, width, height);
                draw(&swingup, width, height);
                draw(&App::new("empty"), width, height);
                draw(&board_app(false), width, height);
                draw(&texts, width, height);
            }
        }
        assert!(draw(&app, 20, 5).contains("cem on"));
    }
}
