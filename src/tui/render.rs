//! Drawing an [`App`] into a frame. Layout, top to bottom: a status line, the progress gauge, the
//! curves (the selected metric beside the method panels) and the latest messages.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Gauge, Paragraph};
use ratatui::Frame;

use super::app::{App, Status};
use super::panel::Panel;
use super::plot::{color, format_value, line_chart, short_names, Trace};

/// Messages shown at most; the panel collapses when there are none.
const MAX_MESSAGE_ROWS: usize = 5;

pub fn render(app: &App, frame: &mut Frame) {
    let [header, progress, body, messages] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(3),
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

fn render_header(app: &App, frame: &mut Frame, area: Rect) {
    let (status, status_color) = status_label(app.status());
    let hints = if app.is_finished() { "←/→ metric" } else { "q quit · ←/→ metric" };
    let line = Line::from(vec![
        Span::styled(app.title(), Style::default().add_modifier(Modifier::BOLD)),
        Span::raw("  "),
        Span::styled(status, Style::default().fg(status_color).add_modifier(Modifier::BOLD)),
        Span::raw("  "),
        Span::styled(hints, Style::default().fg(Color::DarkGray)),
    ]);
    frame.render_widget(Paragraph::new(line), area);
}

fn status_label(status: Status) -> (&'static str, Color) {
    match status {
        Status::Running => ("running", Color::Yellow),
        Status::Done => ("done — press q to quit", Color::Green),
        Status::Failed => ("failed — press q to quit", Color::Red),
        Status::Ended => ("ended — press q to quit", Color::Gray),
    }
}

fn render_progress(app: &App, frame: &mut Frame, area: Rect) {
    let block = Block::bordered().title(" Progress ");
    let Some(progress) = app.progress() else {
        let waiting = Paragraph::new("waiting for progress…").style(Style::default().fg(Color::DarkGray));
        frame.render_widget(waiting.block(block), area);
        return;
    };
    let gauge = Gauge::default()
        .block(block)
        .ratio(progress.ratio())
        .label(progress.summary())
        .gauge_style(Style::default().fg(Color::Cyan).bg(Color::Black));
    frame.render_widget(gauge, area);
}

fn render_body(app: &App, frame: &mut Frame, area: Rect) {
    if app.panels().is_empty() {
        render_curves(app, frame, area);
        return;
    }
    let [curves, panels] = Layout::horizontal([Constraint::Percentage(50); 2]).areas(area);
    render_curves(app, frame, curves);
    let rows = Layout::vertical(vec![Constraint::Fill(1); app.panels().len()]).split(panels);
    for (panel, row) in app.panels().iter().zip(rows.iter()) {
        render_panel(panel, frame, *row);
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
    frame.render_widget(line_chart(vec![trace], "step", Block::bordered().title(title)), area);
}

fn render_panel(panel: &Panel, frame: &mut Frame, area: Rect) {
    let names: Vec<&str> = panel.series().map(|(name, _)| name).collect();
    let traces = short_names(&names)
        .into_iter()
        .zip(panel.series())
        .enumerate()
        .map(|(i, (label, (_, series)))| Trace { name: label.to_string(), points: series.points(), color: color(i) })
        .collect();
    let spec = panel.spec();
    let block = Block::bordered().title(format!(" {} ", spec.title));
    frame.render_widget(line_chart(traces, &spec.x_label, block), area);
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

    #[test]
    fn tiny_terminals_do_not_panic() {
        let mut app = pendulum_app();
        app.ingest(&Event::message("a message that is far wider than the terminal"));
        for width in 0..=24 {
            for height in 0..=8 {
                draw(&app, width, height);
                draw(&App::new("empty"), width, height);
            }
        }
        assert!(draw(&app, 20, 5).contains("cem on"));
    }
}
