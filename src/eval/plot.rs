//! PNG plots for reports. The font is embedded so the same data renders to the same bytes on every machine.

use std::path::Path;
use std::sync::Once;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::envs::pendulum::angle_normalize;
use crate::error::{Error, Result};

const FONT: &[u8] = include_bytes!("fonts/DejaVuSans.ttf");
const SIZE: (u32, u32) = (900, 560);

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is compiled in and known to parse; a failure would only drop text from plots.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Line colours: matplotlib's tab10, then the darker tab20b/tab20c hues, all readable on white. Plots
/// with more series than this reuse colours (and say so by dropping the legend).
const PALETTE: [(u8, u8, u8); 20] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
    (57, 59, 121),
    (99, 121, 57),
    (140, 109, 49),
    (132, 60, 57),
    (123, 65, 115),
    (49, 130, 189),
    (230, 85, 13),
    (49, 163, 84),
    (117, 107, 177),
    (99, 99, 99),
];

pub fn series_color(i: usize) -> RGBAColor {
    let (r, g, b) = PALETTE[i % PALETTE.len()];
    RGBColor(r, g, b).to_rgba()
}

/// A named series of (x, y) points.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::bad_file(path, format!("could not draw plot: {e}"))
}

/// Draws into a temporary PNG beside `path`, then renames it into place.
fn render_atomic(path: &Path, draw: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    register_font();
    let target = crate::util::atomic::Target::of(path)?;
    let tmp = crate::util::atomic::partial_file_in(&target.temp_dir()?, ".png")?;
    draw(tmp.path())?;
    target.finish(tmp)
}

/// The widest axis a plot draws: plotters steps through the tick values of a range, and a range near the
/// largest f64 (or one whose padding overflows) would never end. Values beyond it are drawn at its edge.
const AXIS_LIMIT: f64 = 1e30;

/// An axis range around the finite values, padded, never wider than ±[`AXIS_LIMIT`].
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .map(|v| v.clamp(-AXIS_LIMIT, AXIS_LIMIT))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    // A single value (one evidence size, one run) still needs an axis that reads as a range around it.
    let pad = if hi - lo > 1e-9 * lo.abs().max(1.0) { (hi - lo) * 0.05 } else { (lo.abs() * 0.1).max(1.0) };
    (lo - pad, hi + pad)
}

/// Every range a chart is built on, whoever computed it: finite, increasing and within ±[`AXIS_LIMIT`].
fn axis(range: std::ops::Range<f64>) -> std::ops::Range<f64> {
    let clamp = |v: f64, fallback: f64| if v.is_nan() { fallback } else { v.clamp(-AXIS_LIMIT, AXIS_LIMIT) };
    let (lo, hi) = (clamp(range.start, 0.0), clamp(range.end, 1.0));
    if lo < hi {
        lo..hi
    } else {
        let (lo, hi) = bounds([lo, hi].into_iter());
        lo..hi
    }
}

/// An axis label as plotters writes it, except that a tick at zero reads "0.0" and never "-0.0" (a range
/// symmetric about zero puts a tick at −1e-17 or at −0).
fn tick(value: &f64) -> String {
    let text = plotters::data::float::FloatPrettyPrinter { allow_scientific: false, min_decimal: 1, max_decimal: 5 }
        .print(*value);
    match text.strip_prefix('-') {
        Some(magnitude) if magnitude.parse::<f64>() == Ok(0.0) => magnitude.to_string(),
        _ => text,
    }
}

type XyChart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A white canvas with a title over the given ranges, its axes not yet drawn.
fn titled_chart<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    path: &Path,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<XyChart<'a, 'b>> {
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    ChartBuilder::on(root)
        .caption(title, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(axis(x), axis(y))
        .map_err(|e| plot_err(path, e))
}

/// A white canvas with a title and labelled axes over the given ranges: the frame every x–y plot shares.
fn xy_chart<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    path: &Path,
    title: &str,
    (x_label, y_label): (&str, &str),
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<XyChart<'a, 'b>> {
    let mut chart = titled_chart(root, path, title, x, y)?;
    draw_axes(&mut chart, path, x_label, y_label)?;
    Ok(chart)
}

/// The grid and both axes, labelled.
fn draw_axes(chart: &mut XyChart<'_, '_>, path: &Path, x_label: &str, y_label: &str) -> Result<()> {
    chart
        .configure_mesh()
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .x_desc(x_label)
        .y_desc(y_label)
        .draw()
        .map_err(|e| plot_err(path, e))
}

/// (t, angle wrapped to [−π, π)) for samples (t, unwrapped angle), with the line broken by a NaN wherever the
/// angle wraps. Each side of a break runs to the edge it crosses, at the time the straight line between the
/// two samples reaches it: cut at the samples instead, a trace that starts on the wrap (a pendulum hanging
/// down, θ = ±π) began with a segment of one point, drawn as a lone dot.
pub fn wrapped_angle_trace(samples: impl IntoIterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    use std::f64::consts::{PI, TAU};
    let mut points = Vec::new();
    let mut previous: Option<(f64, f64)> = None;
    for (t, raw) in samples {
        let angle = angle_normalize(raw);
        if let Some((t0, a0)) = previous.filter(|(_, a0)| (angle - a0).abs() > PI) {
            // Falling from near +π to near −π means the angle rose through +π, and the other way round.
            let (edge, step) = if a0 > angle { (PI, angle + TAU - a0) } else { (-PI, angle - TAU - a0) };
            let at = t0 + ((edge - a0) / step).clamp(0.0, 1.0) * (t - t0);
            points.extend([(at, edge), (at, f64::NAN), (at, -edge)]);
        }
        points.push((t, angle));
        previous = Some((t, angle));
    }
    points
}

pub fn line_plot(path: &Path, title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<()> {
    let y = bounds(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    line_plot_in(path, title, x_label, y_label, series, y)
}

/// A line plot of curves that rise from the lower left and level off (errors against the prediction horizon):
/// the legend goes to whichever upper or lower-right corner the curves cross least, instead of over their
/// right ends.
pub fn rising_line_plot(path: &Path, title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<()> {
    let y = bounds(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    use SeriesLabelPosition::{LowerRight, UpperLeft, UpperRight};
    let legend = emptiest_legend_place(series, y, &[UpperLeft, UpperRight, LowerRight]);
    line_plot_legend_at(path, title, (x_label, y_label), series, y, legend)
}

/// A line plot on a fixed y range: rates in percent read wrong when the axis zooms in on 95-100. The legend
/// sits middle right unless the curves pass there (a swing-up settling at 0 rad), then where they pass least.
pub fn line_plot_in(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    y: (f64, f64),
) -> Result<()> {
    use SeriesLabelPosition::{LowerLeft, LowerRight, MiddleLeft, MiddleRight, UpperLeft, UpperRight};
    let places = [MiddleRight, UpperRight, LowerRight, UpperLeft, LowerLeft, MiddleLeft];
    let legend = emptiest_legend_place(series, y, &places);
    line_plot_legend_at(path, title, (x_label, y_label), series, y, legend)
}

/// Of `places` (corners and middles of the chart), the first where the fewest points of `series` fall under
/// the legend box, taken to cover the outer 40 % of the width and a quarter of the height at its place.
fn emptiest_legend_place(series: &[Series], y: (f64, f64), places: &[SeriesLabelPosition]) -> SeriesLabelPosition {
    use SeriesLabelPosition::{LowerLeft, LowerRight, MiddleLeft, MiddleRight, UpperLeft, UpperRight};
    let x = bounds(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let fraction = |v: f64, (lo, hi): (f64, f64)| (v - lo) / (hi - lo).max(f64::MIN_POSITIVE);
    let covered = |place: &SeriesLabelPosition, (px, py): (f64, f64)| {
        let (fx, fy) = (fraction(px, x), fraction(py, y));
        let (right, height) = match place {
            UpperLeft => (false, 0.75..=1.0),
            UpperRight => (true, 0.75..=1.0),
            MiddleLeft => (false, 0.375..=0.625),
            MiddleRight => (true, 0.375..=0.625),
            LowerLeft => (false, 0.0..=0.25),
            _ => (true, 0.0..=0.25),
        };
        (if right { fx > 0.6 } else { fx < 0.4 }) && height.contains(&fy)
    };
    let crossings = |place: &SeriesLabelPosition| {
        series.iter().flat_map(|s| s.points.iter()).filter(|p| covered(place, **p)).count()
    };
    // min_by_key keeps the first of equal counts: the caller's order breaks ties.
    places.iter().min_by_key(|place| crossings(place)).cloned().unwrap_or(LowerRight)
}

fn line_plot_legend_at(
    path: &Path,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[Series],
    (y0, y1): (f64, f64),
    legend: SeriesLabelPosition,
) -> Result<()> {
    let (x0, x1) = bounds(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, SIZE).into_drawing_area();
        let mut chart = xy_chart(&root, path, title, (x_label, y_label), x0..x1, y0..y1)?;
        for (i, s) in series.iter().enumerate() {
            draw_line(
                &mut chart,
                path,
                s,
                series_color(i),
                LineLook { width: 1, mark_lone_points: true, labelled: true },
            )?;
        }
        if series.len() <= PALETTE.len() {
            draw_legend(&mut chart, path, legend, None)?;
        }
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

/// One panel of `line_panels`: its y label, series and, for rates and counts, a fixed y range.
pub struct Panel {
    pub y_label: String,
    pub series: Vec<Series>,
    pub y_range: Option<(f64, f64)>,
}

/// Line charts stacked on one x axis, each with its own y range and label (one per state dimension): the
/// series keep their colour across panels, and a legend of the first panel's series, when it stays readable
/// (2 to 10 of them), sits in a column of its own to the right: drawn inside a panel, ten rollouts' box
/// covered lines wherever it went.
pub fn line_panels(path: &Path, title: &str, x_label: &str, panels: &[Panel]) -> Result<()> {
    let (x0, x1) = bounds(panels.iter().flat_map(|p| p.series.iter().flat_map(|s| s.points.iter().map(|p| p.0))));
    let rows = panels.len().max(1);
    let legend: &[Series] = match panels.first() {
        Some(first) if (2..=10).contains(&first.series.len()) => &first.series,
        _ => &[],
    };
    let legend_width = legend_column_width(legend);
    let size = (SIZE.0 + legend_width, 50 + 230 * rows as u32);
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(|e| plot_err(path, e))?;
        let (charts, legend_area) = root.split_horizontally(SIZE.0);
        for (k, (area, panel)) in charts.split_evenly((rows, 1)).iter().zip(panels).enumerate() {
            let (y_label, series) = (&panel.y_label, &panel.series);
            let (y0, y1) =
                panel.y_range.unwrap_or_else(|| bounds(series.iter().flat_map(|s| s.points.iter().map(|p| p.1))));
            let mut chart = ChartBuilder::on(area)
                .margin(8)
                .x_label_area_size(if k + 1 == rows { 36 } else { 8 })
                .y_label_area_size(64)
                .build_cartesian_2d(axis(x0..x1), axis(y0..y1))
                .map_err(|e| plot_err(path, e))?;
            let mut mesh = chart.configure_mesh();
            mesh.x_label_formatter(&tick).y_label_formatter(&tick).y_desc(y_label.as_str());
            if k + 1 == rows {
                mesh.x_desc(x_label);
            } else {
                mesh.x_labels(0);
            }
            mesh.draw().map_err(|e| plot_err(path, e))?;
            for (i, s) in series.iter().enumerate() {
                let look = LineLook { width: 2, mark_lone_points: false, labelled: false };
                draw_line(&mut chart, path, s, series_color(i), look)?;
            }
        }
        draw_legend_column(&legend_area, path, legend)?;
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

/// Legend text size in `line_panels`' column, the width of one of its characters at most, and the longest
/// name it shows (longer ones are cut).
const LEGEND_FONT: u32 = 13;
const LEGEND_CHAR_WIDTH: u32 = 8;
const LEGEND_NAME_CHARS: usize = 24;

/// The width of a legend column for `series`' names (none without series): a line sample, the longest name,
/// margins.
fn legend_column_width(series: &[Series]) -> u32 {
    let longest = series.iter().map(|s| s.name.chars().count().min(LEGEND_NAME_CHARS) as u32).max();
    longest.map_or(0, |chars| 44 + LEGEND_CHAR_WIDTH * chars)
}

/// One row per series from the top of `area`: a short line of its colour and its name.
fn draw_legend_column(area: &DrawingArea<BitMapBackend<'_>, Shift>, path: &Path, series: &[Series]) -> Result<()> {
    for (i, s) in series.iter().enumerate() {
        let y = 16 + 20 * i as i32;
        let color = series_color(i);
        area.draw(&PathElement::new(vec![(6, y), (26, y)], color.stroke_width(2))).map_err(|e| plot_err(path, e))?;
        let name: String = s.name.chars().take(LEGEND_NAME_CHARS).collect();
        let style = TextStyle::from(("sans-serif", LEGEND_FONT).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(name, (32, y), style)).map_err(|e| plot_err(path, e))?;
    }
    Ok(())
}

/// A median line with a shaded band between a lower and an upper quantile.
pub struct Band {
    pub name: String,
    /// (x, low, middle, high)
    pub points: Vec<(f64, f64, f64, f64)>,
}

pub fn band_plot(path: &Path, title: &str, x_label: &str, y_label: &str, bands: &[Band]) -> Result<()> {
    let (x0, x1) = bounds(bands.iter().flat_map(|b| b.points.iter().map(|p| p.0)));
    let (y0, y1) = bounds(bands.iter().flat_map(|b| b.points.iter().flat_map(|p| [p.1, p.3])));
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, SIZE).into_drawing_area();
        let mut chart = xy_chart(&root, path, title, (x_label, y_label), x0..x1, y0.min(0.0)..y1)?;
        for (i, band) in bands.iter().enumerate() {
            draw_band(&mut chart, path, band, series_color(i))?;
        }
        draw_legend(&mut chart, path, SeriesLabelPosition::UpperLeft, Some(15))?;
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

/// One band chart per panel on a grid, with one y range for all so the panels compare at a glance; band k
/// has the same colour in every panel, so one legend (in the first panel) serves all.
pub fn band_panels(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[(String, Vec<Band>)],
) -> Result<()> {
    let all = || panels.iter().flat_map(|(_, bands)| bands.iter().flat_map(|b| b.points.iter()));
    let (x0, x1) = bounds(all().map(|p| p.0));
    let (_, y1) = bounds(all().flat_map(|p| [p.1, p.3]));
    let columns = panels.len().clamp(1, 3);
    let rows = panels.len().div_ceil(columns).max(1);
    let size = (420 * columns as u32, 60 + 340 * rows as u32);
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let root = root.titled(title, ("sans-serif", 24)).map_err(|e| plot_err(path, e))?;
        for (k, (area, (name, bands))) in root.split_evenly((rows, columns)).iter().zip(panels).enumerate() {
            let mut chart = ChartBuilder::on(area)
                .caption(name, ("sans-serif", 18))
                .margin(8)
                .x_label_area_size(36)
                .y_label_area_size(52)
                .build_cartesian_2d(axis(x0..x1), axis(0.0..y1))
                .map_err(|e| plot_err(path, e))?;
            draw_axes(&mut chart, path, x_label, y_label)?;
            for (i, band) in bands.iter().enumerate() {
                draw_band(&mut chart, path, band, series_color(i))?;
            }
            if k == 0 {
                draw_legend(&mut chart, path, SeriesLabelPosition::UpperLeft, Some(13))?;
            }
        }
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

/// A band's shaded 10-90 % area and its median line, labelled for the legend.
fn draw_band(chart: &mut XyChart<'_, '_>, path: &Path, band: &Band, color: RGBAColor) -> Result<()> {
    let mut outline: Vec<(f64, f64)> = band.points.iter().map(|p| (p.0, p.3)).collect();
    outline.extend(band.points.iter().rev().map(|p| (p.0, p.1)));
    chart.draw_series(std::iter::once(Polygon::new(outline, color.mix(0.15)))).map_err(|e| plot_err(path, e))?;
    chart
        .draw_series(LineSeries::new(band.points.iter().map(|p| (p.0, p.2)), color.stroke_width(2)))
        .map_err(|e| plot_err(path, e))?
        .label(band.name.clone())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
    Ok(())
}

/// The boxed legend of the labelled series drawn so far (plotters' default font when `font_size` is None).
fn draw_legend<'a, 'b: 'a>(
    chart: &mut XyChart<'a, 'b>,
    path: &Path,
    position: SeriesLabelPosition,
    font_size: Option<u32>,
) -> Result<()> {
    let mut legend = chart.configure_series_labels();
    legend.position(position).background_style(WHITE.mix(0.8)).border_style(BLACK);
    if let Some(size) = font_size {
        legend.label_font(("sans-serif", size));
    }
    legend.draw().map_err(|e| plot_err(path, e))
}

/// How `draw_line` draws a series.
#[derive(Clone, Copy)]
struct LineLook {
    width: u32,
    /// A segment of one point has no line to show it: draw a dot instead.
    mark_lone_points: bool,
    /// Give the series a legend entry.
    labelled: bool,
}

/// One series as lines, broken wherever y is not finite (wrapped angles draw no vertical jumps).
fn draw_line(chart: &mut XyChart<'_, '_>, path: &Path, s: &Series, color: RGBAColor, look: LineLook) -> Result<()> {
    let style = color.stroke_width(look.width);
    for (j, segment) in s.points.split(|p| !p.1.is_finite()).filter(|seg| !seg.is_empty()).enumerate() {
        let drawn = if look.mark_lone_points && segment.len() == 1 {
            chart.draw_series(segment.iter().map(|&p| Circle::new(p, 4, color.filled())))
        } else {
            chart.draw_series(LineSeries::new(segment.iter().copied(), style))
        }
        .map_err(|e| plot_err(path, e))?;
        if j > 0 || !look.labelled {
            continue;
        }
        if s.points.len() == 1 && look.mark_lone_points {
            drawn.label(s.name.clone()).legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
        } else {
            drawn.label(s.name.clone()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
    }
    Ok(())
}

/// The five figures a box of a box plot draws, matplotlib's convention (thesis Fig. 7.9): quartiles by
/// linear interpolation, whiskers at the farthest values within 1.5 interquartile ranges of the box, every
/// value beyond them an outlier.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxStats {
    pub q1: f64,
    pub median: f64,
    pub q3: f64,
    pub whisker_low: f64,
    pub whisker_high: f64,
    pub outliers: Vec<f64>,
}

impl BoxStats {
    /// `None` for a group without finite values.
    pub fn of(values: &[f64]) -> Option<BoxStats> {
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        let q = |p| crate::eval::stats::quantile(&finite, p);
        let (q1, median, q3) = (q(0.25)?, q(0.5)?, q(0.75)?);
        let reach = 1.5 * (q3 - q1);
        let inside = finite.iter().copied().filter(|&v| v >= q1 - reach && v <= q3 + reach);
        let (whisker_low, whisker_high) = inside.fold((q1, q3), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let outliers = finite.iter().copied().filter(|&v| v < q1 - reach || v > q3 + reach).collect();
        Some(BoxStats { q1, median, q3, whisker_low, whisker_high, outliers })
    }
}

/// The name of the category whose column sits at `x` (columns at 0, 1, …); between columns, none.
fn category_label(names: &[String], x: f64) -> String {
    let i = x.round();
    if (x - i).abs() < 1e-6 && i >= 0.0 {
        names.get(i as usize).cloned().unwrap_or_default()
    } else {
        String::new()
    }
}

/// One box per named group, left to right; groups without values leave their slot empty.
pub fn box_plot(path: &Path, title: &str, x_label: &str, y_label: &str, groups: &[(String, Vec<f64>)]) -> Result<()> {
    let stats: Vec<Option<BoxStats>> = groups.iter().map(|(_, v)| BoxStats::of(v)).collect();
    let (_, y1) = bounds(stats.iter().flatten().flat_map(|b| b.outliers.iter().copied().chain([b.whisker_high])));
    let n = groups.len().max(1);
    let names: Vec<String> = groups.iter().map(|(name, _)| name.clone()).collect();
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, SIZE).into_drawing_area();
        let mut chart = titled_chart(&root, path, title, -0.5..n as f64 - 0.5, 0.0..y1.max(1.0))?;
        chart
            .configure_mesh()
            .x_labels(n)
            .x_label_formatter(&|x| category_label(&names, *x))
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| plot_err(path, e))?;
        let (line, median_color) = (BLACK.stroke_width(1), RGBColor(0, 128, 0).stroke_width(3));
        for (i, b) in stats.iter().enumerate() {
            let Some(b) = b else { continue };
            let (x, half) = (i as f64, 0.25);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x - half, b.q1), (x + half, b.q3)],
                    RGBColor(70, 110, 190).mix(0.35).filled(),
                )))
                .map_err(|e| plot_err(path, e))?;
            let outline = vec![
                PathElement::new(
                    vec![(x - half, b.q1), (x + half, b.q1), (x + half, b.q3), (x - half, b.q3), (x - half, b.q1)],
                    line,
                ),
                PathElement::new(vec![(x, b.q3), (x, b.whisker_high)], line),
                PathElement::new(vec![(x, b.q1), (x, b.whisker_low)], line),
                PathElement::new(vec![(x - half / 2.0, b.whisker_high), (x + half / 2.0, b.whisker_high)], line),
                PathElement::new(vec![(x - half / 2.0, b.whisker_low), (x + half / 2.0, b.whisker_low)], line),
                PathElement::new(vec![(x - half, b.median), (x + half, b.median)], median_color),
            ];
            chart.draw_series(outline).map_err(|e| plot_err(path, e))?;
            chart
                .draw_series(b.outliers.iter().map(|&v| Circle::new((x, v), 4, BLACK.stroke_width(1))))
                .map_err(|e| plot_err(path, e))?;
        }
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

/// One value of `strip_plot`: its column (`group`), its sub-column and colour (`kind`), and whether it is
/// drawn filled (an outcome that reached its goal) or hollow.
pub struct StripDot {
    pub group: usize,
    pub kind: usize,
    pub value: f64,
    pub filled: bool,
}

/// Every value as its own dot, so that six runs read as six runs and not as one mean: one column per group
/// (x labels), split into one sub-column per kind (colour and legend), each sub-column's mean a bar.
pub fn strip_plot(
    path: &Path,
    title: &str,
    y_label: &str,
    groups: &[String],
    kinds: &[String],
    dots: &[StripDot],
) -> Result<()> {
    let (y0, y1) = bounds(dots.iter().map(|d| d.value));
    // Room under the lowest dots for the legend, so it never hides one.
    let y0 = y0 - 0.25 * (y1 - y0);
    let n = groups.len().max(1);
    let width = 0.7 / kinds.len().max(1) as f64;
    let column = |d: &StripDot| d.group as f64 - 0.35 + width * (d.kind as f64 + 0.5);
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, SIZE).into_drawing_area();
        let mut chart = titled_chart(&root, path, title, -0.5..n as f64 - 0.5, y0..y1)?;
        chart
            .configure_mesh()
            .x_labels(n)
            .x_label_formatter(&|x| category_label(groups, *x))
            .y_desc(y_label)
            .draw()
            .map_err(|e| plot_err(path, e))?;
        for (kind, name) in kinds.iter().enumerate() {
            let color = series_color(kind);
            let mut placed: Vec<(f64, f64, bool)> = Vec::new();
            let mut bars: Vec<PathElement<(f64, f64)>> = Vec::new();
            for group in 0..groups.len() {
                let cell: Vec<&StripDot> =
                    dots.iter().filter(|d| d.group == group && d.kind == kind && d.value.is_finite()).collect();
                let Some(first) = cell.first() else { continue };
                let center = column(first);
                // Dots fan out across the sub-column in run order, so equal returns stay visible.
                let spread = width * 0.6;
                for (j, d) in cell.iter().enumerate() {
                    let offset = if cell.len() > 1 { spread * (j as f64 / (cell.len() - 1) as f64 - 0.5) } else { 0.0 };
                    placed.push((center + offset, d.value, d.filled));
                }
                let mean = cell.iter().map(|d| d.value).sum::<f64>() / cell.len() as f64;
                let half = width * 0.45;
                bars.push(PathElement::new(vec![(center - half, mean), (center + half, mean)], color.stroke_width(3)));
            }
            // A hollow dot is a white disc inside a ring: a thick stroked circle alone renders as a blot.
            chart
                .draw_series(placed.iter().filter(|p| !p.2).map(|&(x, y, _)| Circle::new((x, y), 5, WHITE.filled())))
                .map_err(|e| plot_err(path, e))?;
            chart
                .draw_series(placed.iter().map(|&(x, y, filled)| {
                    Circle::new((x, y), 5, if filled { color.filled() } else { color.stroke_width(1) })
                }))
                .map_err(|e| plot_err(path, e))?
                .label(name.clone())
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, color.filled()));
            chart.draw_series(bars).map_err(|e| plot_err(path, e))?;
        }
        draw_legend(&mut chart, path, SeriesLabelPosition::LowerRight, None)?;
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

pub fn histogram(path: &Path, title: &str, x_label: &str, values: &[f64], bins: usize) -> Result<()> {
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let (lo, hi) = bounds(finite.iter().copied());
    let bins = bins.max(1);
    let width = (hi - lo) / bins as f64;
    let mut counts = vec![0u32; bins];
    for v in &finite {
        let b = (((v - lo) / width) as usize).min(bins - 1);
        counts[b] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(0).max(1);
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 24))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(axis(lo..hi), 0u32..top + 1)
            .map_err(|e| plot_err(path, e))?;
        chart
            .configure_mesh()
            .x_label_formatter(&tick)
            .x_desc(x_label)
            .y_desc("count")
            .draw()
            .map_err(|e| plot_err(path, e))?;
        chart
            .draw_series(counts.iter().enumerate().map(|(i, &c)| {
                let x0 = lo + i as f64 * width;
                Rectangle::new([(x0, 0), (x0 + width, c)], BLUE.mix(0.6).filled())
            }))
            .map_err(|e| plot_err(path, e))?;
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

/// A square colour grid drawn under paths: `rgb[3 (i n + j)..]` is the colour of the i-th x slice and j-th y
/// slice of [0, 1]² (a terrain map, coarsened).
pub struct ColorGrid {
    pub cells: usize,
    pub rgb: Vec<u8>,
}

/// One panel of [`map_paths`]: a map, named paths on it, and the start and goal crosses.
pub struct MapPanel {
    pub title: String,
    pub grid: ColorGrid,
    pub paths: Vec<Series>,
    pub start: (f64, f64),
    pub goal: (f64, f64),
}

/// Paths over maps on [0, 1]² (x right, y up), one panel per map side by side; path k has the same colour in
/// every panel and the legend of the first panel names them. Start: white cross; goal: black cross.
pub fn map_paths(path: &Path, title: &str, panels: &[MapPanel]) -> Result<()> {
    let columns = panels.len().clamp(1, 3);
    let rows = panels.len().div_ceil(columns).max(1);
    let size = (460 * columns as u32, 60 + 460 * rows as u32);
    render_atomic(path, |tmp| {
        let root = BitMapBackend::new(tmp, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let root = root.titled(title, ("sans-serif", 24)).map_err(|e| plot_err(path, e))?;
        for (k, (panel, area)) in panels.iter().zip(root.split_evenly((rows, columns))).enumerate() {
            let mut chart = ChartBuilder::on(&area)
                .caption(&panel.title, ("sans-serif", 16))
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(36)
                .build_cartesian_2d(0.0..1.0, 0.0..1.0)
                .map_err(|e| plot_err(path, e))?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc("x [m]")
                .y_desc("y [m]")
                .draw()
                .map_err(|e| plot_err(path, e))?;
            let n = panel.grid.cells;
            if n > 0 && panel.grid.rgb.len() == n * n * 3 {
                let step = 1.0 / n as f64;
                let cells = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| {
                    let at = (i * n + j) * 3;
                    let [r, g, b] = [panel.grid.rgb[at], panel.grid.rgb[at + 1], panel.grid.rgb[at + 2]];
                    let (x, y) = (i as f64 * step, j as f64 * step);
                    Rectangle::new([(x, y), (x + step, y + step)], RGBColor(r, g, b).filled())
                });
                chart.draw_series(cells).map_err(|e| plot_err(path, e))?;
            }
            for (i, s) in panel.paths.iter().enumerate() {
                let look = LineLook { width: 3, labelled: k == 0, mark_lone_points: false };
                draw_line(&mut chart, path, s, series_color(i), look)?;
            }
            let cross = |(x, y): (f64, f64), color: RGBColor| {
                let d = 0.02;
                vec![
                    PathElement::new(vec![(x - d, y - d), (x + d, y + d)], color.stroke_width(4)),
                    PathElement::new(vec![(x - d, y + d), (x + d, y - d)], color.stroke_width(4)),
                ]
            };
            chart.draw_series(cross(panel.start, WHITE)).map_err(|e| plot_err(path, e))?;
            chart.draw_series(cross(panel.goal, BLACK)).map_err(|e| plot_err(path, e))?;
            if k == 0 {
                draw_legend(&mut chart, path, SeriesLabelPosition::UpperLeft, None)?;
            }
        }
        root.present().map_err(|e| plot_err(path, e))?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_at_zero_has_no_sign() {
        assert_eq!(tick(&-0.0), "0.0");
        assert_eq!(tick(&-1e-17), "0.0");
        assert_eq!(tick(&-0.25), "-0.25");
        assert_eq!(tick(&2.0), "2.0");
    }

    #[test]
    fn wrapped_angles_run_to_the_edge_they_cross() {
        use std::f64::consts::{PI, TAU};
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // Up through +π between t = 0 and 1: the line from 3.0 reaches π at t = (π − 3) / 0.3.
        let up = wrapped_angle_trace([(0.0, 3.0), (1.0, 3.3), (2.0, 3.4)]);
        let at = (PI - 3.0) / 0.3;
        assert_eq!(up.len(), 6);
        assert_eq!(up[0], (0.0, 3.0));
        assert!(close(up[1].0, at) && up[1].1 == PI);
        assert!(close(up[2].0, at) && up[2].1.is_nan());
        assert!(close(up[3].0, at) && up[3].1 == -PI);
        assert!(up[4].0 == 1.0 && close(up[4].1, 3.3 - TAU));
        // Down through −π: the first side ends at −π and the second starts at +π.
        let down = wrapped_angle_trace([(0.0, -3.0), (1.0, -3.3)]);
        assert!(down[1].1 == -PI && down[3].1 == PI && close(down[1].0, (PI - 3.0) / 0.3));
        // A trace that starts on the wrap opens with a segment of two points, not a lone one.
        let hanging = wrapped_angle_trace([(0.0, PI - 0.01), (0.05, PI + 0.02)]);
        assert_eq!(hanging.split(|p| p.1.is_nan()).next().unwrap().len(), 2);
        // Without a wrap, only the wrapped samples.
        assert_eq!(wrapped_angle_trace([(0.0, 0.5), (1.0, 7.0)]).len(), 2);
    }

    #[test]
    fn stacked_panels_keep_their_legend_beside_the_charts() {
        use crate::util::png::decode_rgb;
        let dir = tempfile::tempdir().unwrap();
        let series = |count: usize| -> Vec<Series> {
            (0..count)
                .map(|k| Series {
                    name: format!("rollout {k}"),
                    points: (0..40).map(|i| (i as f64, (i as f64 * 0.2 + k as f64).sin())).collect(),
                })
                .collect()
        };
        let panel = |count| Panel { y_label: "theta".into(), series: series(count), y_range: None };
        let (three, one) = (dir.path().join("three.png"), dir.path().join("one.png"));
        line_panels(&three, "t", "time [s]", &[panel(3), panel(3)]).unwrap();
        line_panels(&one, "t", "time [s]", &[panel(1)]).unwrap();
        let bytes = |path: &Path| std::fs::read(path).unwrap();
        decode_rgb(&bytes(&one), SIZE.0, 50 + 230).expect("no legend, no column");
        let width = SIZE.0 + legend_column_width(&series(3));
        let pixels = decode_rgb(&bytes(&three), width, 50 + 2 * 230).unwrap();
        let rows: Vec<&[u8]> = pixels.chunks(3 * width as usize).collect();
        for k in 0..3 {
            let c = series_color(k);
            let in_column = rows.iter().any(|row| row[3 * SIZE.0 as usize..].chunks(3).any(|p| p == [c.0, c.1, c.2]));
            assert!(in_column, "series {k}'s sample line is in the legend column");
        }
    }

    #[test]
    fn the_legend_goes_where_the_curves_are_not() {
        use SeriesLabelPosition::{MiddleRight, UpperRight};
        let series = |points: Vec<(f64, f64)>| vec![Series { name: "a".into(), points }];
        let places = [MiddleRight, UpperRight];
        let place = |points| format!("{:?}", emptiest_legend_place(&series(points), (-1.0, 1.0), &places));
        // A swing-up settling at 0 on the right: the middle right is taken, the upper right is free.
        let settling: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, (-0.2 * i as f64).exp())).collect();
        assert_eq!(place(settling), format!("{UpperRight:?}"));
        // Curves that keep out of the middle right leave the legend at the first place.
        let high: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, 0.9)).collect();
        assert_eq!(place(high), format!("{MiddleRight:?}"));
    }

    #[test]
    fn plots_are_png_and_deterministic() {
        let dir = tempfile::tempdir().unwrap();
        let s =
            vec![Series { name: "a".into(), points: (0..50).map(|i| (i as f64, (i as f64 * 0.1).sin())).collect() }];
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        line_plot(&a, "t", "x", "y", &s).unwrap();
        line_plot(&b, "t", "x", "y", &s).unwrap();
        let bytes = std::fs::read(&a).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert_eq!(bytes, std::fs::read(&b).unwrap());
        histogram(&dir.path().join("h.png"), "h", "v", &[1.0, 2.0, 2.5, f64::NAN], 5).unwrap();
        let groups = vec![("a".to_string(), vec![1.0, 2.0, 3.0, 40.0]), ("empty".to_string(), vec![])];
        box_plot(&dir.path().join("box.png"), "b", "group", "v", &groups).unwrap();
        // A group whose every value is missing, and a kind with no values at all, leave their slots empty.
        let dots = [(0, 0, -500.0, true), (0, 0, -1200.0, false), (0, 1, -1150.0, false), (1, 0, f64::NAN, false)]
            .map(|(group, kind, value, filled)| StripDot { group, kind, value, filled });
        let (groups, kinds) = (["a".to_string(), "b".to_string()], ["x".to_string(), "y".to_string(), "z".to_string()]);
        strip_plot(&dir.path().join("strip.png"), "s", "v", &groups, &kinds, &dots).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 5, "no temporary files left");
    }

    #[test]
    fn axes_stay_bounded_whatever_the_values() {
        for values in [vec![0.0, f64::MAX], vec![-f64::MAX, f64::MAX], vec![1e300], vec![f64::NAN, f64::INFINITY]] {
            let (lo, hi) = bounds(values.iter().copied());
            assert!(lo.is_finite() && hi.is_finite() && lo < hi && hi - lo <= 3.0 * AXIS_LIMIT, "{values:?}");
        }
        let r = axis(f64::NEG_INFINITY..f64::NAN);
        assert!(r.start.is_finite() && r.end.is_finite() && r.start < r.end);
        // A time axis of dt = f64::MAX: plotters ticked it without end before the limit.
        let dir = tempfile::tempdir().unwrap();
        let points = vec![(0.0, 0.0), (f64::MAX, 1e300)];
        let panel = Panel { y_label: "x".into(), series: vec![Series { name: "a".into(), points }], y_range: None };
        line_panels(&dir.path().join("p.png"), "t", "time [s]", &[panel]).unwrap();
    }

    #[test]
    fn box_stats_follow_matplotlib() {
        // numpy quartiles of 1..=9 and 30: q1 3.25, median 5.5, q3 7.75; 1.5 IQR reaches 14.5, so 30 is an
        // outlier and the upper whisker stops at 9, the farthest value inside.
        let mut values: Vec<f64> = (1..=9).map(f64::from).collect();
        values.push(30.0);
        let b = BoxStats::of(&values).unwrap();
        assert_eq!((b.q1, b.median, b.q3), (3.25, 5.5, 7.75));
        assert_eq!((b.whisker_low, b.whisker_high, b.outliers.clone()), (1.0, 9.0, vec![30.0]));
        assert!(BoxStats::of(&[f64::NAN]).is_none());
    }
}
