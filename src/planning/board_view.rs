//! What `solve-board` shows in the live view: the board before, during and after the plan side by
//! side, the whole plan with the move being played marked, the search's figures, and the effector's
//! path over the board.

use super::bfs::SearchStats;
use crate::envs::boards::BoardGame;
use crate::envs::embodiments::manipulator::BoardPoint;
use crate::run::{Event, Monitor, PanelSpec, PathView};

/// Columns of the plan panel once the plan is longer than this; one column below.
const ONE_COLUMN_MOVES: usize = 6;

/// The panels of a board solve: the search per depth (`with_search`: the search reports its layers),
/// and the effector's path over an n × n board in [0, 1]², rows growing downwards as in the printed
/// board.
pub fn layout(title: &str, side: usize, with_search: bool) -> Event {
    let mut panels = Vec::new();
    if with_search {
        panels.push(PanelSpec {
            title: "search: stored, expanded per depth".into(),
            x_label: "depth".into(),
            series: vec!["bfs/stored".into(), "bfs/expanded".into()],
            // One search per solve: the panel holds its whole history.
            restart_on_rewind: false,
            path: None,
        });
    }
    panels.push(PanelSpec {
        title: "effector path over the board".into(),
        x_label: "x".into(),
        series: vec!["effector/x".into(), "effector/y".into()],
        restart_on_rewind: false,
        path: Some(PathView {
            x: [0.0, 1.0],
            y: [0.0, 1.0],
            grid: u32::try_from(side).unwrap_or(0),
            y_down: true,
            background: None,
        }),
    });
    Event::Layout { title: title.to_string(), panels }
}

/// Boards printed next to each other under their captions, two spaces of gap wider than the widest
/// line or caption of each.
pub fn side_by_side(boards: &[(&str, String)]) -> String {
    let width = |text: &str| text.chars().count();
    let columns: Vec<(usize, Vec<&str>)> = boards
        .iter()
        .map(|(caption, board)| {
            let lines: Vec<&str> = board.lines().collect();
            let widest = lines.iter().map(|l| width(l)).chain([width(caption)]).max().unwrap_or(0);
            (widest, lines)
        })
        .collect();
    let rows = columns.iter().map(|(_, lines)| lines.len()).max().unwrap_or(0);
    let row = |cells: Vec<&str>| {
        let padded: Vec<String> =
            cells.iter().zip(&columns).map(|(cell, (w, _))| format!("{cell:<w$}", w = *w)).collect();
        padded.join("   ").trim_end().to_string()
    };
    let mut out = vec![row(boards.iter().map(|(caption, _)| *caption).collect())];
    for r in 0..rows {
        out.push(row(columns.iter().map(|(_, lines)| lines.get(r).copied().unwrap_or("")).collect()));
    }
    out.join("\n")
}

/// The plan numbered from 1: moves played are ticked, the one being played is marked with ▶. Long
/// plans are set in two columns, filled top to bottom, so twenty moves fit a short terminal.
pub fn plan_text(moves: &[String], played: usize, playing: bool) -> String {
    let entries: Vec<String> = moves
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let mark = match i.cmp(&played) {
                std::cmp::Ordering::Less => '✓',
                std::cmp::Ordering::Equal if playing => '▶',
                _ => ' ',
            };
            format!("{mark}{:>3} {name}", i + 1)
        })
        .collect();
    if entries.len() <= ONE_COLUMN_MOVES {
        return entries.join("\n");
    }
    let rows = entries.len().div_ceil(2);
    let width = entries[..rows].iter().map(|e| e.chars().count()).max().unwrap_or(0);
    (0..rows)
        .map(|r| match entries.get(r + rows) {
            Some(right) => format!("{:<width$}  {right}", entries[r]),
            None => entries[r].clone(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The search's figures in two short lines, to fit beside the boards.
pub fn search_text(stats: &SearchStats) -> String {
    format!(
        "depth {}, peak {:.1} MiB\n{} expanded, {} stored",
        stats.depth,
        stats.peak_memory_bytes as f64 / (1u64 << 20) as f64,
        stats.expanded,
        stats.stored
    )
}

/// Sends the boards panel: the start, the board now under `caption` (left out while it is the start),
/// and the goal.
pub fn show_boards<G: BoardGame>(monitor: &dyn Monitor, game: &G, start: G::State, now: Option<(&str, G::State)>) {
    let mut boards = vec![("start", game.render(start))];
    if let Some((caption, board)) = now {
        boards.push((caption, game.render(board)));
    }
    boards.push(("goal", game.render(game.goal())));
    monitor.emit(&Event::text("boards", side_by_side(&boards)));
}

/// Counts control steps across the whole execution, so the path panel draws every move's stroke.
#[derive(Default)]
pub struct EffectorTrace {
    steps: u64,
}

impl EffectorTrace {
    pub fn record(&mut self, monitor: &dyn Monitor, point: BoardPoint) {
        self.steps += 1;
        monitor.scalar("effector/x", self.steps, point[0]);
        monitor.scalar("effector/y", self.steps, point[1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boards_line_up_under_their_captions() {
        let text = side_by_side(&[
            ("start", "■ ·\n· ■".into()),
            ("after 2/3 moves", "· ·\n· ■".into()),
            ("goal", "· ·\n· ·".into()),
        ]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0], "start   after 2/3 moves   goal");
        assert_eq!(lines[1], "■ ·     · ·               · ·");
        assert_eq!(lines[2], "· ■     · ■               · ·");
    }

    #[test]
    fn plan_marks_what_is_played_and_splits_long_plans() {
        let moves: Vec<String> = (0..3).map(|i| format!("push ({i}, 0)")).collect();
        assert_eq!(plan_text(&moves, 1, true), "✓  1 push (0, 0)\n▶  2 push (1, 0)\n   3 push (2, 0)");
        assert_eq!(plan_text(&moves, 0, false), "   1 push (0, 0)\n   2 push (1, 0)\n   3 push (2, 0)");
        assert_eq!(plan_text(&moves, 3, false).matches('✓').count(), 3);

        let long: Vec<String> = (0..9).map(|i| format!("m{i}")).collect();
        let text = plan_text(&long, 0, false);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 5, "{text}");
        assert_eq!(lines[0], "   1 m0     6 m5");
        assert_eq!(lines[4], "   5 m4");
        assert!(plan_text(&[], 0, true).is_empty());
    }
}
