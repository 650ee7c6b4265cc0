//! SVG figures with plotters' SVG backend: a small layout layer (panels of line and point
//! series with labelled axes and legends) and the figures of `platen compare`; those of
//! `platen identify` are in [`crate::identify_plot`].
//!
//! Only the SVG backend is used, with plotters' built-in text-size estimate, so no font file,
//! font library or C library is needed: text is written as SVG `<text>` in the `sans-serif`
//! family and laid out by whatever displays it. Output is a pure function of the data, so the
//! same input gives the same bytes.
//!
//! PNG copies are rendered from the SVG by `resvg` (pure Rust, tiny-skia) with the text set in
//! Noto Sans, which is embedded in the binary (the `ttf-noto-sans` crate, Apache-2.0): no
//! system font is read, so the pixels are the same on every machine.
//!
//! Every data series is one `<polyline>` (lines) or a run of `<circle>`s (points) in its own
//! colour, and its legend entry repeats that colour once, so a figure's series can be counted
//! from the file.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use platen_io::write_bytes_atomic;
use platen_io::{IoAction, IoError};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::compare::{Comparison, Direction};

/// Colour of recorded data.
pub const RECORDED: RGBColor = RGBColor(31, 119, 180);
/// Colour of simulated data.
pub const SIMULATED: RGBColor = RGBColor(217, 95, 2);
/// Colour of the model law and of the residual.
pub const MODEL: RGBColor = RGBColor(0, 0, 0);
/// Colour of a residual time history.
pub const RESIDUAL: RGBColor = RGBColor(117, 112, 179);
/// Fill of the band that marks a zoomed interval.
const SHADE: RGBColor = RGBColor(255, 221, 120);

/// Font sizes (plotters units; the SVG `font-size` is 1/1.24 of these).
const TITLE_SIZE: f64 = 26.0;
const CAPTION_SIZE: f64 = 22.0;
const AXIS_DESC_SIZE: f64 = 21.0;
const TICK_SIZE: f64 = 19.0;
const LEGEND_SIZE: f64 = 19.0;
const FONT: &str = "sans-serif";
/// Most tick labels on a horizontal axis.
const X_LABELS_MAX: usize = 14;
/// Most tick labels on a vertical axis.
const Y_LABELS_MAX: usize = 12;

/// Most points drawn for a scatter series (evenly spaced samples beyond that).
pub const MAX_SCATTER_POINTS: usize = 4000;
/// Most points drawn for a loop (hysteresis) line (evenly spaced samples beyond that).
const MAX_LOOP_POINTS: usize = 20_000;

/// How a series is drawn.
#[derive(Debug, Clone, Copy)]
pub enum Style {
    /// A polyline.
    Line { color: RGBColor, width: u32 },
    /// Filled circles of radius `radius` px.
    Points { color: RGBColor, radius: i32 },
    /// Separate straight segments between consecutive pairs of points (error bars); one
    /// `<polyline>` per segment.
    Segments { color: RGBColor, width: u32 },
}

/// One data series of a panel.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points (x, y) in the panel's units, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// How to draw it.
    pub style: Style,
}

/// One set of axes.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Caption above the axes.
    pub title: String,
    /// Horizontal axis description, with its unit.
    pub x_label: String,
    /// Vertical axis description, with its unit.
    pub y_label: String,
    /// The series, drawn in order (later ones on top).
    pub series: Vec<Series>,
    /// Horizontal range (default: the data's).
    pub x_range: Option<(f64, f64)>,
    /// A horizontal interval to shade (a zoomed window).
    pub shade_x: Option<(f64, f64)>,
}

/// A figure: a title over a grid of panels.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File stem (`time-history-u_m` → `time-history-u_m.svg`).
    pub name: String,
    /// Title at the top.
    pub title: String,
    /// One sentence on what is shown, for the report.
    pub caption: String,
    /// Panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
    /// Size in px.
    pub size: (u32, u32),
}

impl Figure {
    /// Renders the figure as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size).into_drawing_area();
            root.fill(&WHITE).map_err(plot_error)?;
            let title_height = (TITLE_SIZE * 1.6) as u32;
            let (top, body) = root.split_vertically(title_height);
            top.draw_text(
                &self.title,
                &TextStyle::from((FONT, TITLE_SIZE).into_font())
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
                (self.size.0 as i32 / 2, title_height as i32 / 2 + 2),
            )
            .map_err(plot_error)?;
            let columns = self.columns.max(1);
            let rows = self.panels.len().div_ceil(columns);
            let areas = body.split_evenly((rows, columns));
            // One y label width for the whole figure, so that stacked axes line up.
            let y_area = self
                .panels
                .iter()
                .map(|p| y_label_area(ranges(p).1))
                .max()
                .unwrap_or(60);
            for (panel, area) in self.panels.iter().zip(&areas) {
                draw_panel(panel, area, y_area)?;
            }
            root.present().map_err(plot_error)?;
        }
        Ok(svg)
    }
}

fn plot_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> anyhow::Error {
    anyhow!("drawing a figure failed: {e}")
}

/// The range of `values` widened by 4 % each way (a unit band around a constant).
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * lo.abs().max(hi.abs()).max(1e-300) {
        let half = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return (lo - half, hi + half);
    }
    let pad = 0.04 * (hi - lo);
    (lo - pad, hi + pad)
}

/// The spacing plotters gives at most `max_points` ticks over `range`: the finest of
/// 1, 2 or 5 × 10^k that keeps the count (the same search as plotters' float key points).
fn tick_step(range: (f64, f64), max_points: usize) -> f64 {
    let span = range.1 - range.0;
    if !(span.is_finite() && span > 0.0) || max_points == 0 {
        return 1.0;
    }
    let rem = |a: f64, b: f64| a - (a / b).floor() * b;
    let count = |step: f64| {
        let mut left = range.0 - rem(range.0, step);
        if left < range.0 {
            left += step;
        }
        let right = range.1 - rem(range.1, step);
        (1.0 + (right - left) / step).round() as usize
    };
    let mut scale = 10f64.powf(span.log10().floor());
    if 1 + (span / scale).floor() as usize > max_points {
        scale *= 10.0;
    }
    loop {
        let old = scale;
        for next in [2.0, 5.0, 10.0] {
            if count(old / next) > max_points {
                return scale;
            }
            scale = old / next;
        }
        scale = old / 10.0;
        if scale < span * 1e-12 {
            return scale;
        }
    }
}

/// Decimals that tell the ticks of `range` apart when at most `max_points` are drawn.
fn tick_decimals(range: (f64, f64), max_points: usize) -> usize {
    let step = tick_step(range, max_points);
    (-((step.log10() + 1e-9).floor()) as i64).clamp(0, 8) as usize
}

/// Most tick labels along an axis of `px` pixels, `px_per_label` apart.
fn label_count(px: f64, px_per_label: f64, max: usize) -> usize {
    ((px / px_per_label) as usize).clamp(4, max)
}

fn format_tick(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    // "-0.00" → "0.00"
    if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        text[1..].to_owned()
    } else {
        text.replace('-', "−")
    }
}

/// The x and y ranges of a panel: the given or data x range, and the data's y range over it.
fn ranges(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let x = panel.x_range.unwrap_or_else(|| {
        padded_range(
            panel
                .series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
        )
    });
    let y = padded_range(
        panel
            .series
            .iter()
            .flat_map(|s| s.points.iter().filter(|p| p.0 >= x.0 && p.0 <= x.1))
            .map(|p| p.1),
    );
    (x, y)
}

/// Width of the y label area that fits the widest tick label of `y` and the axis
/// description, px (about 0.6 em per character).
fn y_label_area(y: (f64, f64)) -> u32 {
    // The most labels an axis gets (see `draw_panel`): the widest text.
    let decimals = tick_decimals(y, Y_LABELS_MAX);
    let widest = [y.0, y.1, 0.5 * (y.0 + y.1)]
        .iter()
        .map(|v| format_tick(*v, decimals).chars().count())
        .max()
        .unwrap_or(4);
    (widest as f64 * 0.62 * TICK_SIZE / 1.24 + 1.9 * AXIS_DESC_SIZE) as u32 + 8
}

/// Where the legend goes and the y range that leaves room for it.
///
/// The legend box (its size estimated from its text) goes in the corner of the plotting area
/// that holds the fewest data points; if every corner holds some, the y range is extended
/// upwards by the legend's height and the legend sits in that headroom, top right, so it
/// never hides data.
fn place_legend(
    panel: &Panel,
    x: (f64, f64),
    y: (f64, f64),
    plot_px: (f64, f64),
) -> (SeriesLabelPosition, (f64, f64)) {
    let labelled: Vec<&Series> = panel
        .series
        .iter()
        .filter(|s| !s.label.is_empty())
        .collect();
    let longest = labelled
        .iter()
        .map(|s| s.label.chars().count())
        .max()
        .unwrap_or(0);
    let em = LEGEND_SIZE / 1.24;
    let legend_w = longest as f64 * 0.6 * em + 36.0 + 40.0;
    let legend_h = labelled.len() as f64 * 1.55 * em + 30.0;
    let (fw, fh) = (
        (legend_w / plot_px.0).min(1.0),
        (legend_h / plot_px.1).min(0.9),
    );
    let corners = [
        ((1.0 - fw, 1.0), (1.0 - fh, 1.0)),
        ((0.0, fw), (1.0 - fh, 1.0)),
        ((1.0 - fw, 1.0), (0.0, fh)),
        ((0.0, fw), (0.0, fh)),
    ];
    let mut counts = [0usize; 4];
    for s in &panel.series {
        for &(px, py) in &s.points {
            let fx = (px - x.0) / (x.1 - x.0);
            let fy = (py - y.0) / (y.1 - y.0);
            for (count, (cx, cy)) in counts.iter_mut().zip(&corners) {
                if (cx.0..=cx.1).contains(&fx) && (cy.0..=cy.1).contains(&fy) {
                    *count += 1;
                }
            }
        }
    }
    let best = (0..4).min_by_key(|&i| counts[i]).unwrap_or(0);
    if labelled.is_empty() || counts[best] == 0 {
        let position = match best {
            0 => SeriesLabelPosition::UpperRight,
            1 => SeriesLabelPosition::UpperLeft,
            2 => SeriesLabelPosition::LowerRight,
            _ => SeriesLabelPosition::LowerLeft,
        };
        return (position, y);
    }
    // Headroom: the data keep the lower (1 − fh) of the height.
    let top = y.0 + (y.1 - y.0) / (1.0 - fh);
    (SeriesLabelPosition::UpperRight, (y.0, top))
}

fn draw_panel(panel: &Panel, area: &DrawingArea<SVGBackend<'_>, Shift>, y_area: u32) -> Result<()> {
    let (x, y_data) = ranges(panel);
    let (margin_top, margin_bottom, margin_left, margin_right) = (6u32, 8u32, 10u32, 32u32);
    let x_area = (2.6 * AXIS_DESC_SIZE) as u32;
    let caption_px = if panel.title.is_empty() {
        0.0
    } else {
        CAPTION_SIZE * 1.3
    };
    let (w, h) = area.dim_in_pixel();
    let plot_px = (
        (f64::from(w) - f64::from(y_area + margin_left + margin_right)).max(50.0),
        (f64::from(h) - f64::from(x_area + margin_top + margin_bottom) - caption_px).max(50.0),
    );
    let (legend_position, y) = place_legend(panel, x, y_data, plot_px);
    let x_labels = label_count(plot_px.0, 55.0, X_LABELS_MAX);
    let y_labels = label_count(plot_px.1, 40.0, Y_LABELS_MAX);
    let (x_dec, y_dec) = (tick_decimals(x, x_labels), tick_decimals(y, y_labels));

    let mut builder = ChartBuilder::on(area);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FONT, CAPTION_SIZE));
    }
    let mut chart = builder
        .margin_top(margin_top)
        .margin_bottom(margin_bottom)
        .margin_left(margin_left)
        .margin_right(margin_right)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(plot_error)?;
    let x_fmt = move |v: &f64| format_tick(*v, x_dec);
    let y_fmt = move |v: &f64| format_tick(*v, y_dec);
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(x_labels)
        .y_labels(y_labels)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_DESC_SIZE))
        .bold_line_style(RGBColor(225, 225, 225))
        .light_line_style(TRANSPARENT)
        .axis_style(RGBColor(90, 90, 90))
        .draw()
        .map_err(plot_error)?;

    if let Some((a, b)) = panel.shade_x {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a, y.0), (b, y.1)],
                SHADE.mix(0.35).filled(),
            )))
            .map_err(plot_error)?;
    }
    for series in &panel.series {
        let label = series.label.clone();
        match series.style {
            Style::Line { color, width } => {
                let style = color.stroke_width(width);
                let drawn = chart
                    .draw_series(LineSeries::new(series.points.iter().copied(), style))
                    .map_err(plot_error)?;
                if !label.is_empty() {
                    drawn.label(label).legend(move |(lx, ly)| {
                        PathElement::new(vec![(lx, ly), (lx + 28, ly)], color.stroke_width(3))
                    });
                }
            }
            Style::Points { color, radius } => {
                let style = color.mix(0.55).filled();
                let drawn = chart
                    .draw_series(
                        series
                            .points
                            .iter()
                            .map(move |&p| Circle::new(p, radius, style)),
                    )
                    .map_err(plot_error)?;
                if !label.is_empty() {
                    drawn
                        .label(label)
                        .legend(move |(lx, ly)| Circle::new((lx + 14, ly), 5, color.filled()));
                }
            }
            Style::Segments { color, width } => {
                let style = color.stroke_width(width);
                let drawn = chart
                    .draw_series(
                        series
                            .points
                            .chunks_exact(2)
                            .map(move |pair| PathElement::new(vec![pair[0], pair[1]], style)),
                    )
                    .map_err(plot_error)?;
                if !label.is_empty() {
                    drawn.label(label).legend(move |(lx, ly)| {
                        PathElement::new(vec![(lx + 14, ly - 8), (lx + 14, ly + 8)], style)
                    });
                }
            }
        }
    }
    if panel.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .position(legend_position)
            .margin(10)
            .legend_area_size(36)
            .label_font((FONT, LEGEND_SIZE))
            .background_style(WHITE.mix(0.88))
            .border_style(RGBColor(150, 150, 150))
            .draw()
            .map_err(plot_error)?;
    }
    Ok(())
}

/// Points of a time history, at most about `2·buckets`: per bucket of equal time the
/// smallest and largest samples in their time order, so peaks and the envelope survive.
pub fn envelope(t: &[f64], y: &[f64], range: (f64, f64), buckets: usize) -> Vec<(f64, f64)> {
    let idx: Vec<usize> = (0..t.len())
        .filter(|&i| t[i] >= range.0 && t[i] <= range.1)
        .collect();
    if idx.len() <= 2 * buckets.max(1) {
        return idx.iter().map(|&i| (t[i], y[i])).collect();
    }
    let width = (range.1 - range.0) / buckets as f64;
    let mut out = Vec::with_capacity(2 * buckets + 2);
    let mut start = 0;
    while start < idx.len() {
        let bucket = ((t[idx[start]] - range.0) / width).floor();
        let mut end = start + 1;
        while end < idx.len() && ((t[idx[end]] - range.0) / width).floor() == bucket {
            end += 1;
        }
        let slice = &idx[start..end];
        let lo = *slice
            .iter()
            .min_by(|&&a, &&b| y[a].total_cmp(&y[b]))
            .unwrap_or(&slice[0]);
        let hi = *slice
            .iter()
            .max_by(|&&a, &&b| y[a].total_cmp(&y[b]))
            .unwrap_or(&slice[0]);
        let (first, second) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push((t[first], y[first]));
        if second != first {
            out.push((t[second], y[second]));
        }
        start = end;
    }
    out
}

/// Every `k`-th point, with `k` the smallest stride that keeps at most `max` points.
pub fn thinned(x: &[f64], y: &[f64], max: usize) -> (Vec<(f64, f64)>, usize) {
    let stride = x.len().div_ceil(max.max(1)).max(1);
    (
        x.iter()
            .zip(y)
            .step_by(stride)
            .map(|(a, b)| (*a, *b))
            .collect(),
        stride,
    )
}

/// `values` times `scale` (unit conversion for display).
pub fn scaled(values: &[f64], scale: f64) -> Vec<f64> {
    values.iter().map(|v| v * scale).collect()
}

/// A line series.
pub fn line(
    label: impl Into<String>,
    points: Vec<(f64, f64)>,
    color: RGBColor,
    width: u32,
) -> Series {
    Series {
        label: label.into(),
        points,
        style: Style::Line { color, width },
    }
}

/// Horizontal pixels of a full-width panel, the number of envelope buckets.
const BUCKETS: usize = 1100;

/// The figures of a comparison, in report order.
pub fn figures(c: &Comparison) -> Vec<Figure> {
    let mut out = Vec::new();
    let (z0, z1) = c.zoom_s;
    let zoom_note = if c.window_s.is_some() {
        "the --window"
    } else {
        "around the largest residual"
    };
    let span = (c.t_s[0], c.t_s[c.t_s.len() - 1]);
    let rec_name = c.recorded_name();
    // Two time-history panels: the whole record with the zoomed interval shaded, and the zoom.
    let whole_and_zoom =
        |y_label: String, series: [(&str, &[f64], RGBColor, u32); 2], note: &str| {
            let panel = |title: String, range: (f64, f64), shade: Option<(f64, f64)>| Panel {
                title,
                x_label: "time t (s)".into(),
                y_label: y_label.clone(),
                series: series
                    .iter()
                    .map(|&(label, y, color, width)| {
                        line(label, envelope(&c.t_s, y, range, BUCKETS), color, width)
                    })
                    .collect(),
                x_range: Some(range),
                shade_x: shade,
            };
            vec![
                panel(
                    format!("whole record, {:.1}–{:.1} s", span.0, span.1),
                    span,
                    Some((z0, z1)),
                ),
                panel(format!("zoom {z0:.2}–{z1:.2} s{note}"), (z0, z1), None),
            ]
        };
    for ch in &c.channels {
        let s = ch.spec;
        let rec = scaled(&ch.recorded, s.display_scale);
        let sim = scaled(&ch.simulated, s.display_scale);
        out.push(Figure {
            name: format!("time-history-{}", s.key),
            title: format!("Recorded and simulated {} ({})", s.quantity, s.symbol),
            caption: format!(
                "{} of {rec_name} (blue, drawn wider) and of the simulation (orange, on top): \
                 whole record, and the shaded interval zoomed below ({zoom_note}).",
                capitalised(s.quantity)
            ),
            panels: whole_and_zoom(
                format!("{} {} ({})", s.quantity, s.symbol, s.display_unit),
                [
                    ("recorded", &rec, RECORDED, 4),
                    ("simulated", &sim, SIMULATED, 2),
                ],
                &format!(" ({zoom_note})"),
            ),
            columns: 1,
            size: (1200, 900),
        });
    }

    if let Some(input) = &c.input_force {
        let rec = scaled(&input.recorded_n, 1e-3);
        let drv = scaled(&c.simulated.force_n, 1e-3);
        out.push(Figure {
            name: "input-force".into(),
            title: "Actuator force: recorded and as it drives the model".into(),
            caption: format!(
                "The force column of {rec_name} as recorded (blue) and the scenario's excitation \
                 that drove the forward run, after any low-pass the scenario sets (orange)."
            ),
            panels: whole_and_zoom(
                "actuator force F_A (kN)".into(),
                [
                    ("recorded", &rec, RECORDED, 2),
                    (
                        "driving the model (scenario excitation)",
                        &drv,
                        SIMULATED,
                        2,
                    ),
                ],
                "",
            ),
            columns: 1,
            size: (1200, 900),
        });
    }

    // Residuals.
    out.push(Figure {
        name: "residual".into(),
        title: "Residual: simulated − recorded".into(),
        caption: format!(
            "Simulated minus recorded, on the recorded time base of {rec_name}; RMS and NRMSE \
             in the table above."
        ),
        panels: c
            .channels
            .iter()
            .map(|ch| {
                let s = ch.spec;
                let r: Vec<f64> = ch
                    .simulated
                    .iter()
                    .zip(&ch.recorded)
                    .map(|(a, b)| (a - b) * s.residual_scale)
                    .collect();
                Panel {
                    title: format!(
                        "{} residual, RMS {} {}",
                        s.quantity,
                        crate::compare::significant(ch.metrics.rms_error * s.residual_scale, 3),
                        s.residual_unit
                    ),
                    x_label: "time t (s)".into(),
                    y_label: format!("{} sim − rec ({})", s.symbol, s.residual_unit),
                    series: vec![line(
                        String::new(),
                        envelope(&c.t_s, &r, span, BUCKETS),
                        RESIDUAL,
                        2,
                    )],
                    x_range: Some(span),
                    shade_x: c.window_s.map(|w| (w[0], w[1])),
                }
            })
            .collect(),
        columns: 1,
        size: (1200, 420 * c.channels.len() as u32 + 60),
    });

    // Hysteresis loops: actuator force against displacement, velocity and acceleration.
    let f_rec = scaled(&c.recorded.force_n, 1e-3);
    let f_sim = scaled(&c.simulated.force_n, 1e-3);
    let mut loops = Vec::new();
    let mut stride = 1;
    // A forward run's "simulated" force is the one that drove the model (after any
    // low-pass), not an output of it: the caption says so, the legend stays short enough for
    // a third of the figure's width.
    let sim_label = "simulated";
    for (quantity, symbol, unit, rec_x, sim_x) in [
        ("displacement", "u", "m", &c.recorded.u_m, &c.simulated.u_m),
        (
            "velocity",
            "v",
            "m/s",
            &c.recorded.v_m_s,
            &c.simulated.v_m_s,
        ),
        (
            "acceleration",
            "a",
            "m/s²",
            &c.recorded.a_m_s2,
            &c.simulated.a_m_s2,
        ),
    ] {
        let (rec_points, k) = thinned(rec_x, &f_rec, MAX_LOOP_POINTS);
        let (sim_points, _) = thinned(sim_x, &f_sim, MAX_LOOP_POINTS);
        stride = k;
        loops.push(Panel {
            title: format!("Actuator force against {quantity}"),
            x_label: format!("{quantity} {symbol} ({unit})"),
            y_label: "actuator force F_A (kN)".into(),
            series: vec![
                line("recorded", rec_points, RECORDED, 1),
                line(sim_label, sim_points, SIMULATED, 2),
            ],
            x_range: None,
            shade_x: None,
        });
    }
    let thinning = if stride > 1 {
        format!(" ({} drawn)", every(stride))
    } else {
        String::new()
    };
    out.push(Figure {
        name: "hysteresis".into(),
        title: "Hysteresis loops: actuator force against the motion".into(),
        caption: format!(
            "Actuator force against displacement, velocity and acceleration (as the paper's Figs \
             4–6 and 11): recorded ({}) and simulated ({}){thinning}.",
            c.recorded.sources.loops,
            match c.direction {
                Direction::Forward =>
                    "the force that drove the model against the motion it produced",
                Direction::Inverse => "the model's force against the prescribed motion",
            }
        ),
        panels: loops,
        columns: 3,
        size: (1260, 520),
    });

    // Dissipative force against velocity, with the model's law.
    let (points, k) = thinned(
        &c.recorded.v_m_s,
        &scaled(&c.recorded_dissipative_n, 1e-3),
        MAX_SCATTER_POINTS,
    );
    let law: Vec<(f64, f64)> = c.law.iter().map(|&(v, f)| (v, f * 1e-3)).collect();
    out.push(Figure {
        name: "dissipative-force".into(),
        title: "Dissipative force against velocity".into(),
        caption: format!(
            "F_D = F_A − M·a − F_E from the recorded data ({}{}), with the model's law {} \
             (as the paper's Figs 7 and 10).",
            c.recorded.sources.dissipative,
            if k > 1 {
                format!("; {} drawn", every(k))
            } else {
                String::new()
            },
            c.law_label
        ),
        panels: vec![Panel {
            title: String::new(),
            x_label: "velocity v (m/s)".into(),
            y_label: "dissipative force F_D (kN)".into(),
            series: vec![
                Series {
                    label: "recorded: F_A − M·a − F_E".into(),
                    points,
                    style: Style::Points {
                        color: RECORDED,
                        radius: 2,
                    },
                },
                line(format!("model law {}", c.law_label), law, MODEL, 3),
            ],
            x_range: None,
            shade_x: None,
        }],
        columns: 1,
        size: (1200, 800),
    });
    out
}

/// "every 3rd sample", "every 12th sample", …
pub fn every(k: usize) -> String {
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("every {k}{suffix} sample")
}

fn capitalised(s: &str) -> String {
    let mut chars = s.chars();
    match chars.next() {
        Some(first) => first.to_uppercase().chain(chars).collect(),
        None => String::new(),
    }
}

/// The SVG of every figure, `(file name, svg)`.
pub fn render_all(figures: &[Figure]) -> Result<Vec<(String, String)>> {
    figures
        .iter()
        .map(|f| Ok((format!("{}.svg", f.name), f.to_svg()?)))
        .collect()
}

/// Writes what a verb's `--plot DIR` and `--report FILE.html` ask for: the figures (SVG and
/// PNG) to the folder and the page `html` makes of the figures and their SVG. The figures are
/// built only if one of the two is asked for. Returns the figure files written.
pub fn write_outputs(
    plot_dir: Option<&Path>,
    report: Option<&Path>,
    figures: impl FnOnce() -> Vec<Figure>,
    html: impl FnOnce(&[Figure], &[(String, String)]) -> String,
) -> Result<Vec<PathBuf>> {
    if plot_dir.is_none() && report.is_none() {
        return Ok(Vec::new());
    }
    let figures = figures();
    let rendered = render_all(&figures)?;
    let written = match plot_dir {
        Some(dir) => write_figures(dir, &rendered)?,
        None => Vec::new(),
    };
    if let Some(path) = report {
        write_bytes_atomic(path, html(&figures, &rendered).as_bytes())?;
    }
    Ok(written)
}

/// Writes every figure to `dir` (created if missing) as SVG and PNG, and returns the paths
/// written. Every PNG is rendered before the first file is written, so a rendering failure
/// leaves the folder as it was; each file is written atomically.
pub fn write_figures(dir: &Path, rendered: &[(String, String)]) -> Result<Vec<PathBuf>> {
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::with_capacity(2 * rendered.len());
    for (file, svg) in rendered {
        files.push((dir.join(file), svg.as_bytes().to_vec()));
        files.push((
            dir.join(Path::new(file).with_extension("png")),
            svg_to_png(svg)?,
        ));
    }
    fs::create_dir_all(dir).map_err(|source| IoError::Io {
        path: dir.to_path_buf(),
        action: IoAction::CreatingFolder,
        source,
    })?;
    let mut written = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        write_bytes_atomic(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// Renders an SVG document (as written by [`Figure::to_svg`]) to PNG at its own pixel size,
/// with `sans-serif` text set in the embedded Noto Sans.
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>> {
    use resvg::{tiny_skia, usvg};
    let mut options = usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_font_data(ttf_noto_sans::REGULAR.to_vec());
    fonts.set_sans_serif_family("Noto Sans");
    let tree = usvg::Tree::from_str(svg, &options)
        .map_err(|e| anyhow!("reading a figure's SVG for PNG rendering failed: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| anyhow!("a figure of {size:?} px cannot be rendered"))?;
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap
        .encode_png()
        .map_err(|e| anyhow!("encoding a figure as PNG failed: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::coord::ranged1d::Ranged;
    use plotters::coord::types::RangedCoordf64;

    /// The tick spacing assumed for the labels' decimals is the one plotters draws, over
    /// ranges of every magnitude and label counts from 4 to 14 (a label such as "0 0 1 2 2"
    /// on a 0–6 axis with 0.5 steps was the bug this guards against).
    #[test]
    fn tick_step_is_the_spacing_plotters_draws() {
        let mut checked = 0;
        for &(lo, hi) in &[
            (0.0, 6.8),
            (-0.67, 0.67),
            (-2500.0, 2500.0),
            (134.2, 148.9),
            (0.0, 1.8),
            (-3.2e-4, 7.7e-4),
            (16.0, 20.0),
            (1.2654, 1.2668),
            (-30.5, 28.1),
        ] {
            for max_points in 4..=14 {
                let keys = RangedCoordf64::from(lo..hi).key_points(max_points);
                if keys.len() < 2 {
                    continue;
                }
                let drawn = keys[1] - keys[0];
                let step = tick_step((lo, hi), max_points);
                assert!(
                    (drawn - step).abs() <= 1e-9 * step,
                    "{lo}..{hi}, {max_points} labels: plotters {drawn}, assumed {step}"
                );
                let decimals = tick_decimals((lo, hi), max_points);
                let labels: Vec<String> = keys.iter().map(|k| format_tick(*k, decimals)).collect();
                let mut unique = labels.clone();
                unique.dedup();
                assert_eq!(unique.len(), labels.len(), "{labels:?}");
                checked += 1;
            }
        }
        assert!(checked > 80, "{checked}");
    }
}
