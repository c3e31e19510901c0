//! Turning (step, value) series into a ratatui line chart: axis ranges and tick labels that stay sane
//! for empty, single-point and constant series.

use ratatui::layout::Constraint;
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType, LegendPosition};

/// Fraction of the value range added above and below, so extremes do not sit on the frame.
const Y_MARGIN: f64 = 0.05;

const PALETTE: [Color; 6] =
    [Color::Cyan, Color::Yellow, Color::Magenta, Color::Green, Color::LightRed, Color::LightBlue];

pub(crate) fn color(index: usize) -> Color {
    PALETTE[index % PALETTE.len()]
}

/// One line of a chart.
pub(crate) struct Trace<'a> {
    pub(crate) name: String,
    pub(crate) points: &'a [(f64, f64)],
    pub(crate) color: Color,
}

pub(crate) fn line_chart<'a>(traces: Vec<Trace<'a>>, x_title: &'a str, block: Block<'a>) -> Chart<'a> {
    let x = bounds(traces.iter().flat_map(|t| t.points.iter().map(|p| p.0)), 0.0);
    let y = bounds(traces.iter().flat_map(|t| t.points.iter().map(|p| p.1)), Y_MARGIN);
    // A legend only tells lines apart; with one line the panel title already names it.
    let legend = (traces.len() > 1).then(|| legend_corner(&traces));
    let axis_style = Style::default().fg(Color::DarkGray);
    Chart::new(traces.into_iter().map(dataset).collect())
        .block(block)
        .x_axis(Axis::default().title(x_title).style(axis_style).bounds(x).labels(step_labels(x)))
        .y_axis(Axis::default().style(axis_style).bounds(y).labels(value_labels(y)))
        .legend_position(legend)
        .hidden_legend_constraints((Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)))
}

/// The top corner the lines leave free: top left when they end higher than they start (states stored
/// per depth), top right otherwise (a falling loss), so the legend does not hide the newest points.
fn legend_corner(traces: &[Trace<'_>]) -> LegendPosition {
    let rises = |t: &Trace<'_>| match (t.points.first(), t.points.last()) {
        (Some(first), Some(last)) => last.1 > first.1,
        _ => false,
    };
    if traces.iter().filter(|t| rises(t)).count() * 2 > traces.len() {
        LegendPosition::TopLeft
    } else {
        LegendPosition::TopRight
    }
}

fn dataset(trace: Trace<'_>) -> Dataset<'_> {
    Dataset::default()
        .name(trace.name)
        .marker(Marker::Braille)
        .graph_type(GraphType::Line)
        .style(Style::default().fg(trace.color))
        .data(trace.points)
}

/// `[lo, hi]` covering the finite values, widened by `margin` of the range. Never returns an empty
/// range: the chart divides by its width.
pub(crate) fn bounds(values: impl Iterator<Item = f64>, margin: f64) -> [f64; 2] {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return [0.0, 1.0];
    }
    // Counts, rates and other values that never go negative keep the axis at zero or above.
    let floor = if lo >= 0.0 { 0.0 } else { f64::NEG_INFINITY };
    let span = hi - lo;
    if span == 0.0 {
        let pad = if lo == 0.0 { 1.0 } else { lo.abs() * Y_MARGIN };
        return [(lo - pad).max(floor), hi + pad];
    }
    if !span.is_finite() {
        return [lo, hi];
    }
    [(lo - span * margin).max(floor), hi + span * margin]
}

fn step_labels([lo, hi]: [f64; 2]) -> Vec<String> {
    [lo, (lo + hi) / 2.0, hi].iter().map(|v| format!("{v:.0}")).collect()
}

/// Ticks share one precision, chosen from the range, so they line up and differ where it matters.
fn value_labels([lo, hi]: [f64; 2]) -> Vec<String> {
    let ticks = [lo, (lo + hi) / 2.0, hi];
    let magnitude = lo.abs().max(hi.abs());
    if !(1e-3..1e6).contains(&magnitude) {
        return ticks.iter().map(|v| format!("{v:.2e}")).collect();
    }
    let decimals = (2.0 - (hi - lo).log10().floor()).clamp(0.0, 6.0) as usize;
    ticks.iter().map(|v| format!("{v:.decimals$}")).collect()
}

/// A short rendering for tick labels and titles: few digits, scientific only at the extremes.
pub(crate) fn format_value(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() {
        format!("{v}")
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    }
}

/// Legend labels without the directory every series in the panel shares (`pendulum/angle` and
/// `pendulum/action` become `angle` and `action`), so the legend fits beside the plot.
pub(crate) fn short_names<'a>(names: &[&'a str]) -> Vec<&'a str> {
    let Some(first) = names.first() else {
        return Vec::new();
    };
    let shared = first
        .match_indices('/')
        .rev()
        .map(|(i, _)| &first[..=i])
        .find(|prefix| names.iter().all(|n| n.starts_with(prefix) && n.len() > prefix.len()))
        .unwrap_or("");
    names.iter().map(|n| &n[shared.len()..]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_of_nothing_is_unit_range() {
        assert_eq!(bounds(std::iter::empty(), Y_MARGIN), [0.0, 1.0]);
        assert_eq!(bounds([f64::NAN, f64::INFINITY].into_iter(), Y_MARGIN), [0.0, 1.0]);
    }

    #[test]
    fn bounds_of_constant_series_are_widened() {
        assert_eq!(bounds([0.0, 0.0].into_iter(), Y_MARGIN), [0.0, 1.0]);
        let [lo, hi] = bounds([4.0].into_iter(), 0.0);
        assert!(lo < 4.0 && hi > 4.0);
        let [lo, hi] = bounds([-2e-6, -2e-6].into_iter(), Y_MARGIN);
        assert!(lo < -2e-6 && hi > -2e-6 && hi < 0.0);
    }

    #[test]
    fn bounds_add_margin_and_skip_non_finite() {
        let [lo, hi] = bounds([0.0, f64::NAN, 10.0, f64::NEG_INFINITY].into_iter(), 0.1);
        assert_eq!([lo, hi], [0.0, 11.0]);
        assert_eq!(bounds([3.0, 7.0].into_iter(), 0.0), [3.0, 7.0]);
        assert_eq!(bounds([-1.0, 9.0].into_iter(), 0.1), [-2.0, 10.0]);
    }

    /// A count (states stored by a search) never gets a negative axis from the margin.
    #[test]
    fn values_that_never_go_negative_keep_the_axis_at_zero() {
        let [lo, hi] = bounds([1.0, 25.0, 30552.0].into_iter(), Y_MARGIN);
        assert_eq!(lo, 0.0);
        assert!(hi > 30552.0);
        assert!(value_labels([lo, hi]).iter().all(|l| !l.starts_with('-')));
    }

    #[test]
    fn bounds_survive_overflowing_span() {
        let [lo, hi] = bounds([-f64::MAX, f64::MAX].into_iter(), Y_MARGIN);
        assert!(lo.is_finite() && hi.is_finite() && lo < hi);
    }

    #[test]
    fn the_legend_sits_where_the_lines_are_not() {
        let rising = [(0.0, 1.0), (1.0, 5.0)];
        let falling = [(0.0, 5.0), (1.0, 1.0)];
        let trace = |points| Trace { name: String::new(), points, color: Color::Cyan };
        assert_eq!(legend_corner(&[trace(&rising), trace(&rising)]), LegendPosition::TopLeft);
        assert_eq!(legend_corner(&[trace(&falling), trace(&rising)]), LegendPosition::TopRight);
        assert_eq!(legend_corner(&[trace(&[]), trace(&falling)]), LegendPosition::TopRight);
    }

    #[test]
    fn values_format_compactly() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(12.34567), "12.346");
        assert_eq!(format_value(-0.5), "-0.5000");
        assert_eq!(format_value(123456.0), "1.23e5");
        assert_eq!(format_value(f64::NAN), "NaN");
    }

    #[test]
    fn value_ticks_share_a_precision_fitted_to_the_range() {
        assert_eq!(value_labels([98.0, 100.1]), vec!["98.00", "99.05", "100.10"]);
        assert_eq!(value_labels([0.0, 1000.0]), vec!["0", "500", "1000"]);
        assert_eq!(value_labels([-1.0, 1.0]), vec!["-1.00", "0.00", "1.00"]);
        assert_eq!(value_labels([1e-5, 3e-5]), vec!["1.00e-5", "2.00e-5", "3.00e-5"]);
    }

    #[test]
    fn legend_names_drop_the_shared_directory() {
        assert_eq!(short_names(&["pendulum/angle", "pendulum/action"]), vec!["angle", "action"]);
        assert_eq!(short_names(&["a/x/p", "a/x/q", "a/y"]), vec!["x/p", "x/q", "y"]);
        assert_eq!(short_names(&["a/x", "b/x"]), vec!["a/x", "b/x"]);
        assert_eq!(short_names(&["solo/name"]), vec!["name"]);
        assert!(short_names(&[]).is_empty());
    }
}
