//! A path panel: the (x, y) pairs of two series drawn on a fixed plane over an optional grid, such as
//! an effector's path over the board it plays on; a second pair of series is a second path (a robot's plan
//! beside the path it drove).

use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType};

use super::plot::bounds;
use super::series::Series;
use crate::run::PathView;

/// Finer grids are not drawn: their cells would be thinner than a braille dot, and a corrupt layout in
/// a replayed file must not make the view allocate without bound.
const MAX_GRID: u32 = 64;

/// What a path panel draws: its plane, the path on it and the grid under it.
pub(crate) struct PathPlot {
    x: [f64; 2],
    y: [f64; 2],
    points: Vec<(f64, f64)>,
    second: Vec<(f64, f64)>,
    grid: Vec<(f64, f64)>,
}

impl PathPlot {
    pub(crate) fn new(xs: &Series, ys: &Series, second: Option<(&Series, &Series)>, view: &PathView) -> Self {
        let x = plane(view.x, xs);
        let y = plane(view.y, ys);
        PathPlot {
            x,
            y,
            points: path_points(xs, ys, view.y_down, y),
            second: second.map_or_else(Vec::new, |(sx, sy)| path_points(sx, sy, view.y_down, y)),
            grid: grid_polyline(x, y, view.grid),
        }
    }

    /// The grid in grey, the path in cyan, its newest point as a yellow block, a second path in magenta.
    pub(crate) fn chart<'a>(&'a self, block: Block<'a>) -> Chart<'a> {
        let line = |points: &'a [(f64, f64)], color: Color| {
            Dataset::default()
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(Style::default().fg(color))
                .data(points)
        };
        let mut datasets = vec![
            line(&self.grid, Color::DarkGray),
            line(&self.second, Color::Magenta),
            line(&self.points, Color::Cyan),
        ];
        if let Some(last) = self.points.len().checked_sub(1) {
            datasets.push(
                Dataset::default()
                    .marker(Marker::Block)
                    .graph_type(GraphType::Scatter)
                    .style(Style::default().fg(Color::Yellow))
                    .data(&self.points[last..]),
            );
        }
        Chart::new(datasets).block(block).x_axis(Axis::default().bounds(self.x)).y_axis(Axis::default().bounds(self.y))
    }
}

/// The points of `xs` and `ys` recorded at the same step, oldest first, with y mirrored inside
/// `[y_lo, y_hi]` where the plane's y grows downwards. Both series are fed together, so their newest
/// points line up; a point without a partner (one series trimmed further) is dropped.
fn path_points(xs: &Series, ys: &Series, y_down: bool, [y_lo, y_hi]: [f64; 2]) -> Vec<(f64, f64)> {
    let mut pairs: Vec<(f64, f64)> = xs
        .points()
        .iter()
        .rev()
        .zip(ys.points().iter().rev())
        .filter(|(x, y)| x.0 == y.0)
        .map(|(x, y)| (x.1, if y_down { y_lo + y_hi - y.1 } else { y.1 }))
        .collect();
    pairs.reverse();
    pairs
}

/// The plane's range along one axis: the declared one when it is a real interval, else the data's.
fn plane(declared: [f64; 2], series: &Series) -> [f64; 2] {
    let [lo, hi] = declared;
    if lo.is_finite() && hi.is_finite() && lo < hi {
        declared
    } else {
        bounds(series.points().iter().map(|p| p.1), 0.0)
    }
}

/// Every line of an n × n grid over the plane as one polyline: the horizontal lines walked
/// alternately left and right, then the vertical ones up and down, so each connecting stroke runs along
/// the border, itself a grid line.
fn grid_polyline([x_lo, x_hi]: [f64; 2], [y_lo, y_hi]: [f64; 2], cells: u32) -> Vec<(f64, f64)> {
    if cells == 0 || cells > MAX_GRID {
        return Vec::new();
    }
    let at = |lo: f64, hi: f64, k: u32| lo + (hi - lo) * f64::from(k) / f64::from(cells);
    let mut points = Vec::with_capacity(4 * (cells as usize + 1));
    for k in 0..=cells {
        let y = at(y_lo, y_hi, k);
        let (a, b) = if k % 2 == 0 { (x_lo, x_hi) } else { (x_hi, x_lo) };
        points.extend([(a, y), (b, y)]);
    }
    // The horizontal walk ends on the top edge, at the right end when it made an odd number of
    // turns; the vertical walk starts there, so no stroke cuts across the grid.
    let ends_right = cells.is_multiple_of(2);
    for j in 0..=cells {
        let k = if ends_right { cells - j } else { j };
        let x = at(x_lo, x_hi, k);
        let (a, b) = if j % 2 == 0 { (y_hi, y_lo) } else { (y_lo, y_hi) };
        points.extend([(x, a), (x, b)]);
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(points: &[(u64, f64)]) -> Series {
        let mut s = Series::default();
        for &(step, value) in points {
            s.push(step, value);
        }
        s
    }

    fn board(y_down: bool) -> PathView {
        PathView { x: [0.0, 1.0], y: [0.0, 1.0], grid: 5, y_down, background: None }
    }

    #[test]
    fn points_pair_by_step_and_mirror_a_downward_y() {
        let xs = series(&[(1, 0.1), (2, 0.2), (3, 0.3)]);
        let ys = series(&[(2, 0.9), (3, 0.7)]);
        assert_eq!(PathPlot::new(&xs, &ys, None, &board(false)).points, vec![(0.2, 0.9), (0.3, 0.7)]);
        let flipped = PathPlot::new(&xs, &ys, None, &board(true)).points;
        assert!((flipped[0].1 - 0.1).abs() < 1e-12 && (flipped[1].1 - 0.3).abs() < 1e-12, "{flipped:?}");
    }

    #[test]
    fn the_grid_walks_every_line_once_along_the_border() {
        let grid = grid_polyline([0.0, 1.0], [0.0, 1.0], 2);
        assert_eq!(grid.len(), 12);
        // Every stroke is axis-parallel and lies on a grid line (0, 0.5 or 1 in the coordinate held).
        for w in grid.windows(2) {
            let ((x0, y0), (x1, y1)) = (w[0], w[1]);
            assert!(x0 == x1 || y0 == y1, "{w:?}");
            let held = if x0 == x1 { x0 } else { y0 };
            assert!([0.0, 0.5, 1.0].contains(&held), "{w:?}");
        }
        for cells in 1..6 {
            let grid = grid_polyline([0.0, 1.0], [0.0, 1.0], cells);
            assert!(grid.windows(2).all(|w| w[0].0 == w[1].0 || w[0].1 == w[1].1), "{cells}: {grid:?}");
        }
        assert!(grid_polyline([0.0, 1.0], [0.0, 1.0], 0).is_empty());
        assert!(grid_polyline([0.0, 1.0], [0.0, 1.0], u32::MAX).is_empty(), "absurd grids are not drawn");
    }

    #[test]
    fn an_empty_or_inverted_plane_falls_back_to_the_data() {
        let ys = series(&[(1, 2.0), (2, 4.0)]);
        assert_eq!(plane([1.0, 1.0], &ys), [2.0, 4.0]);
        assert_eq!(plane([f64::NAN, 1.0], &ys), [2.0, 4.0]);
        assert_eq!(plane([0.0, 1.0], &ys), [0.0, 1.0]);
    }
}
