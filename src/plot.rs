//! Line charts as PNG (plotters): response curves, Pareto fronts, spectra.
//! One function for every chart the tools draw, so that they all look alike.
use plotters::prelude::*;
use std::path::Path;

/// One curve: a legend label, its points, and whether to draw markers.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub markers: bool,
}

/// How one curve looks, when the caller chooses (curves of one method in one colour, an
/// estimate as hollow markers beside its filled true value).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Look {
    /// Index into the palette (Tableau 10).
    pub colour: usize,
    pub line: Line,
    /// 0 circle, 1 triangle, 2 square; `None`: no marker.
    pub marker: Option<usize>,
    /// Marker outline only.
    pub hollow: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Line {
    Solid,
    Dashed,
    /// Markers only.
    None,
    /// A vertical stem from the axis' bottom to each point (spectra), no line between points.
    Stems,
}

impl Look {
    /// The default look of curve `i` (see [`panel_chart`]).
    fn of(i: usize, markers: bool) -> Look {
        let (_, dashed, marker) = style(i);
        Look { colour: i % 10, line: if dashed { Line::Dashed } else { Line::Solid }, marker: markers.then_some(marker), hollow: false }
    }
}

/// Axis scaling.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    Linear,
    Log,
}

/// A chart: title, axis labels and scales.
pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub x_scale: Scale,
    pub y_scale: Scale,
}

/// Tableau 10: a qualitative palette whose colours stay apart (also for most colour-blind
/// readers). Beyond 10 curves the colours repeat with dashed lines and other markers.
const TABLEAU10: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The look of curve `i`: its colour, dashed or not, and its marker (0 circle, 1 triangle,
/// 2 square).
fn style(i: usize) -> (RGBColor, bool, usize) {
    (TABLEAU10[i % 10], (i / 10) % 2 == 1, (i / 10) % 3)
}

/// Marker outlines in pixels around the point: an octagon (a circle), a triangle, a square.
fn marker_shape(kind: usize) -> Vec<(i32, i32)> {
    match kind {
        0 => vec![(4, 0), (3, 3), (0, 4), (-3, 3), (-4, 0), (-3, -3), (0, -4), (3, -3)],
        1 => vec![(0, -5), (5, 4), (-5, 4)],
        _ => vec![(-4, -4), (4, -4), (4, 4), (-4, 4)],
    }
}

/// A tick of a linear axis over `lo..hi`: "2" rather than "2.0", "0.25"; 6 significant digits
/// at most; powers of ten for the whole axis when it only reaches below 1e-2 or from 1e6 on
/// ("6e-5"); "0" for a tick that is zero up to round-off.
fn tick(v: f64, lo: f64, hi: f64) -> String {
    let big = lo.abs().max(hi.abs());
    if !v.is_finite() || v.abs() <= 1e-9 * big {
        return if v.is_finite() { "0".into() } else { format!("{v}") };
    }
    let scale = 10f64.powi(5 - v.abs().log10().floor() as i32);
    let r = (v * scale).round() / scale;
    if (1e-2..1e6).contains(&big) { format!("{r}") } else { format!("{r:e}") }
}

/// The labelled ticks of a log axis over `lo..hi`: every decade (every second, third, … past 12
/// decades), with 2 and 5 inside when the axis spans three decades or fewer, and 1 … 9 when
/// fewer than three ticks would remain.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let decades = (last - first).max(1);
    let every = (decades as usize).div_ceil(12).max(1);
    let within = |m: &[f64]| -> Vec<f64> {
        (first..=last).step_by(every).flat_map(|e| m.iter().map(move |f| f * 10f64.powi(e))).filter(|v| (lo..=hi).contains(v)).collect()
    };
    let mut ticks = within(if decades <= 3 { &[1.0, 2.0, 5.0] } else { &[1.0] });
    if ticks.len() < 3 {
        ticks = within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    }
    ticks
}

/// A log axis' tick: "0.01", "200" within 1e-3 … 1e4, else "2e-7".
fn log_tick(v: f64) -> String {
    if (1e-3..1e4).contains(&v) { format!("{}", (v * 1e6).round() / 1e6) } else { format!("{v:.0e}") }
}

fn range(values: impl Iterator<Item = f64>, scale: Scale) -> (f64, f64) {
    let (lo, hi) =
        values.filter(|v| v.is_finite() && (scale == Scale::Linear || *v > 0.0)).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return (if scale == Scale::Log { 1e-3 } else { 0.0 }, 1.0);
    }
    match scale {
        Scale::Linear => {
            // A near-constant curve (spread below 1 % of its level) gets ±5 % of its level: its
            // ticks stay few and short instead of crowding in the round-off.
            let pad = if hi - lo < 1e-2 * lo.abs().max(hi.abs()) { 0.05 * lo.abs().max(hi.abs()) } else { 0.05 * (hi - lo) };
            let pad = pad.max(1e-12);
            (lo - pad, hi + pad)
        }
        Scale::Log => (lo / 1.5, hi * 1.5),
    }
}

/// A chart that could not be drawn or written: the file and plotters' reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: cannot draw the chart: {reason}")]
pub struct PlotError {
    pub file: String,
    pub reason: String,
}

impl PlotError {
    fn new(path: &Path, reason: &dyn std::fmt::Display) -> Self {
        PlotError { file: path.display().to_string(), reason: reason.to_string() }
    }
}

impl From<PlotError> for crate::Error {
    fn from(e: PlotError) -> Self {
        crate::Error::io(e.to_string())
    }
}

/// Until the sweep and study rooms' errors are typed: they return these as `String`.
/// Draws the series into a PNG of `width`×`height` pixels. Non-finite points (and
/// non-positive ones on a log axis) are skipped. The error is a [`PlotError`], in the caller's
/// error type.
pub fn line_chart(path: &Path, chart: &Chart, series: &[Series], width: u32, height: u32) -> Result<(), PlotError> {
    panel_chart(path, &[(chart, series)], 1, width, height, Legend::Default)
}

/// Where the legend goes.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Legend {
    /// plotters' default (middle right).
    Default,
    UpperRight,
    LowerLeft,
    /// The middle of the plot: inside a hysteresis loop, where no curve runs.
    Middle,
    /// Of the nine places (corners, edge middles, centre), the one whose box covers the fewest
    /// points of the panel: crowded panels (the accuracy study) keep their curves visible.
    Emptiest,
}

/// Where [`Legend::Emptiest`] puts the legend of a panel: `points` in axis fractions (0..1, y up),
/// a box of `width` × `height` fractions; the first of the least covered places wins.
fn emptiest_place(points: &[(f64, f64)], width: f64, height: f64) -> SeriesLabelPosition {
    use SeriesLabelPosition::*;
    let places = [
        (UpperRight, 1.0 - width, 1.0 - height),
        (UpperLeft, 0.0, 1.0 - height),
        (LowerLeft, 0.0, 0.0),
        (LowerRight, 1.0 - width, 0.0),
        (MiddleLeft, 0.0, 0.5 - height / 2.0),
        (MiddleRight, 1.0 - width, 0.5 - height / 2.0),
        (UpperMiddle, 0.5 - width / 2.0, 1.0 - height),
        (LowerMiddle, 0.5 - width / 2.0, 0.0),
        (MiddleMiddle, 0.5 - width / 2.0, 0.5 - height / 2.0),
    ];
    let covered = |x0: f64, y0: f64| points.iter().filter(|(x, y)| (x0..=x0 + width).contains(x) && (y0..=y0 + height).contains(y)).count();
    let best = places.iter().map(|(_, x0, y0)| covered(*x0, *y0)).min().unwrap_or(0);
    places.into_iter().find(|(_, x0, y0)| covered(*x0, *y0) == best).map_or(UpperRight, |(p, _, _)| p)
}

/// Several charts in one PNG, `columns` per row (each panel as [`line_chart`] draws it).
/// The error is a [`PlotError`], in the caller's error type.
pub fn panel_chart(path: &Path, panels: &[(&Chart, &[Series])], columns: usize, width: u32, height: u32, legend: Legend) -> Result<(), PlotError> {
    let looks: Vec<Vec<Look>> = panels.iter().map(|(_, s)| s.iter().enumerate().map(|(i, s)| Look::of(i, s.markers)).collect()).collect();
    let styled: Vec<(&Chart, &[Series], &[Look])> = panels.iter().zip(&looks).map(|((c, s), l)| (*c, *s, l.as_slice())).collect();
    draw_panels(path, &styled, columns, width, height, legend)
}

/// As [`panel_chart`], each curve with the look the caller gives (`looks[i]` for `series[i]`).
/// A series with an empty label has no legend entry (a legend-only series explains a look).
pub fn styled_panel_chart(
    path: &Path,
    panels: &[(&Chart, &[Series], &[Look])],
    columns: usize,
    width: u32,
    height: u32,
    legend: Legend,
) -> Result<(), PlotError> {
    draw_panels(path, panels, columns, width, height, legend)
}

fn draw_panels(path: &Path, panels: &[(&Chart, &[Series], &[Look])], columns: usize, width: u32, height: u32, legend: Legend) -> Result<(), PlotError> {
    let err = |e: &dyn std::fmt::Display| PlotError::new(path, e);
    let root = BitMapBackend::new(path, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    let areas = root.split_evenly((rows, columns));
    for ((chart, series, looks), area) in panels.iter().zip(&areas) {
        draw_chart(area, chart, series, looks, legend, path)?;
    }
    root.present().map_err(|e| err(&e))
}

fn draw_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart,
    series: &[Series],
    looks: &[Look],
    legend: Legend,
    path: &Path,
) -> Result<(), PlotError>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Display| PlotError::new(path, e);
    let keep =
        |(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && (chart.x_scale == Scale::Linear || *x > 0.0) && (chart.y_scale == Scale::Linear || *y > 0.0);
    let xs = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)), chart.x_scale);
    let ys = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)), chart.y_scale);
    let mut builder = ChartBuilder::on(area);
    builder.caption(chart.title, ("sans-serif", 22)).margin(12).x_label_area_size(45).y_label_area_size(70);
    macro_rules! draw {
        ($ctx:expr) => {{
            let mut ctx = $ctx;
            {
                // Log axes: ticks as 1e-3 rather than 0.0009999999.
                let log_fmt = |v: &f64| log_tick(*v);
                let mut mesh = ctx.configure_mesh();
                mesh.x_desc(chart.x_label).y_desc(chart.y_label);
                let x_tick = |v: &f64| tick(*v, xs.0, xs.1);
                let y_tick = |v: &f64| tick(*v, ys.0, ys.1);
                mesh.x_label_formatter(if chart.x_scale == Scale::Log { &log_fmt } else { &x_tick });
                mesh.y_label_formatter(if chart.y_scale == Scale::Log { &log_fmt } else { &y_tick });
                mesh.draw().map_err(|e| err(&e))?;
            }
            for (s, look) in series.iter().zip(looks) {
                let color = TABLEAU10[look.colour % 10];
                let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(keep).collect();
                let line = color.stroke_width(2);
                let drawn = match look.line {
                    Line::Dashed => ctx.draw_series(DashedLineSeries::new(pts.clone(), 8, 5, line)).map_err(|e| err(&e))?,
                    Line::Solid => ctx.draw_series(LineSeries::new(pts.clone(), line)).map_err(|e| err(&e))?,
                    Line::None => ctx.draw_series(LineSeries::new(Vec::new(), line)).map_err(|e| err(&e))?,
                    Line::Stems => ctx.draw_series(pts.iter().map(|&(x, y)| PathElement::new(vec![(x, ys.0), (x, y)], line))).map_err(|e| err(&e))?,
                };
                // Legend: two segments (a gap between them when dashed, none without a line) and the marker.
                let shape = marker_shape(look.marker.unwrap_or(0));
                let fill = if look.hollow { color.mix(0.0).filled() } else { color.filled() };
                let (has_line, gap, has_marker) = (look.line != Line::None, if look.line == Line::Dashed { 13 } else { 8 }, look.marker.is_some());
                if !s.label.is_empty() {
                    drawn.label(s.label.clone()).legend(move |(x, y)| {
                        let seg = |a: i32, b: i32| PathElement::new(if has_line { vec![(a, 0), (b, 0)] } else { vec![] }, line);
                        let marker: Vec<(i32, i32)> = if has_marker { shape.iter().chain(shape.first()).map(|(a, b)| (a + 10, *b)).collect() } else { vec![] };
                        EmptyElement::at((x, y)) + seg(0, 8) + seg(gap, 21) + Polygon::new(marker.clone(), fill) + PathElement::new(marker, line)
                    });
                }
                if let Some(m) = look.marker {
                    let shape = marker_shape(m);
                    if look.hollow {
                        let ring = |p| {
                            let mut closed = shape.clone();
                            closed.push(shape[0]);
                            EmptyElement::at(p) + PathElement::new(closed, color.stroke_width(2))
                        };
                        ctx.draw_series(pts.iter().map(|&p| ring(p))).map_err(|e| err(&e))?;
                    } else {
                        ctx.draw_series(pts.iter().map(|&p| EmptyElement::at(p) + Polygon::new(shape.clone(), color.filled()))).map_err(|e| err(&e))?;
                    }
                }
            }
            let mut labels = ctx.configure_series_labels();
            labels.background_style(WHITE.mix(0.85)).border_style(BLACK);
            match legend {
                Legend::Default => {}
                Legend::UpperRight => {
                    labels.position(SeriesLabelPosition::UpperRight);
                }
                Legend::LowerLeft => {
                    labels.position(SeriesLabelPosition::LowerLeft);
                }
                Legend::Middle => {
                    labels.position(SeriesLabelPosition::MiddleMiddle);
                }
                Legend::Emptiest => {
                    let frac = |v: f64, (lo, hi): (f64, f64), scale: Scale| match scale {
                        Scale::Linear => (v - lo) / (hi - lo),
                        Scale::Log => (v.ln() - lo.ln()) / (hi.ln() - lo.ln()),
                    };
                    let pts: Vec<(f64, f64)> = series
                        .iter()
                        .flat_map(|s| s.points.iter())
                        .filter(|p| keep(p))
                        .map(|&(x, y)| (frac(x, xs, chart.x_scale), frac(y, ys, chart.y_scale)))
                        .collect();
                    // The legend's size as a fraction of the plot: about 30 % wide, a row per entry.
                    let entries = series.iter().filter(|s| !s.label.is_empty()).count() as f64;
                    let (w, h) = area.dim_in_pixel();
                    labels.position(emptiest_place(&pts, 280.0 / f64::from(w.max(1)), (entries * 17.0 + 14.0) / f64::from(h.max(1))));
                }
            }
            labels.draw().map_err(|e| err(&e))?;
        }};
    }
    let (x_log, y_log) = ((xs.0..xs.1).log_scale().with_key_points(log_ticks(xs.0, xs.1)), (ys.0..ys.1).log_scale().with_key_points(log_ticks(ys.0, ys.1)));
    match (chart.x_scale, chart.y_scale) {
        (Scale::Linear, Scale::Linear) => draw!(builder.build_cartesian_2d(xs.0..xs.1, ys.0..ys.1).map_err(|e| err(&e))?),
        (Scale::Log, Scale::Log) => draw!(builder.build_cartesian_2d(x_log, y_log).map_err(|e| err(&e))?),
        (Scale::Linear, Scale::Log) => draw!(builder.build_cartesian_2d(xs.0..xs.1, y_log).map_err(|e| err(&e))?),
        (Scale::Log, Scale::Linear) => draw!(builder.build_cartesian_2d(x_log, ys.0..ys.1).map_err(|e| err(&e))?),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn ticks_are_short() {
        let t = |v: f64, hi: f64| super::tick(v, -0.05 * hi, hi);
        assert_eq!([t(2.0, 20.0), t(2000.0, 2700.0), t(0.25, 1.0), t(-1.5, 10.0), t(0.0, 1.0)], ["2", "2000", "0.25", "-1.5", "0"]);
        // Axes in 1e-4 m: every tick a power of ten, zero up to round-off is 0.
        assert_eq!([t(0.00006000000000001, 1e-3), t(1e-3, 1e-3), t(-2.7e-20, 1e-3), t(2.5e6, 3e6)], ["6e-5", "1e-3", "0", "2.5e6"]);
        // Log ticks: every decade over many, 1-2-5 over few, never fewer than three.
        assert_eq!(super::log_ticks(1e-9, 2.0), (-9..=0).map(|e| 10f64.powi(e)).collect::<Vec<_>>());
        let labels = |lo: f64, hi: f64| super::log_ticks(lo, hi).into_iter().map(super::log_tick).collect::<Vec<_>>();
        assert_eq!(labels(0.15, 3.0), ["0.2", "0.5", "1", "2"]);
        assert_eq!(labels(2.5e-3, 8.5e-3), ["0.003", "0.004", "0.005", "0.006", "0.007", "0.008"]);
        assert_eq!([super::log_tick(1e-2), super::log_tick(200.0), super::log_tick(2e-7)], ["0.01", "200", "2e-7"]);
        // A near-constant curve: ±5 % of its level, not ±5 % of its round-off.
        let (lo, hi) = super::range([1.0, 1.0 + 2.5e-6].into_iter(), super::Scale::Linear);
        assert!((lo - 0.95).abs() < 1e-5 && (hi - 1.05).abs() < 1e-5, "{lo} {hi}");
        // Eleven curves: eleven different looks.
        let looks: std::collections::HashSet<String> = (0..11).map(|i| format!("{:?}", super::style(i))).collect();
        assert_eq!(looks.len(), 11);
    }
}
