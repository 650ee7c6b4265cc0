//! Drawing a [`Figure`] as SVG with plotters' SVG backend.
//!
//! Only the SVG backend is used, with plotters' built-in text-size estimate, so no font file,
//! font library or C library is needed: text is written as SVG `<text>` in the `sans-serif`
//! family and laid out by whatever displays it. Output is a pure function of the data, so the
//! same input gives the same bytes.
//!
//! Every data series is one `<polyline>` (lines) or a run of `<circle>`s (points) in its own
//! colour, and its legend entry repeats that colour once, so a figure's series can be counted
//! from the file. A line's stroke pattern ([`Dash`]) is its `stroke-dasharray`. Legends sit
//! in a strip between a panel's caption and its axes, so they never hide data and never
//! stretch an axis.

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::axes::{format_tick, label_count, ranges, tick_decimals, y_label_area};
use crate::error::{ReportError, Result};
use crate::figure::{
    Dash, Figure, Panel, Series, Style, AXIS_DESC_SIZE, CAPTION_SIZE, FONT, LEGEND_SIZE, SHADE,
    TICK_SIZE, TITLE_SIZE, X_LABELS_MAX, Y_LABELS_MAX,
};

/// The SVG drawing area of a panel.
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// The axes of a panel with the coordinates `X` and `Y` (each linear, or logarithmic in
/// decades with its own ticks).
type AnyChart<'a, 'b, X, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>;

/// Width of a character of the title font, in em: an estimate for sans-serif text, a little
/// generous (0.47 em measured on a rendered 94-character title) so that a title that fits the
/// estimate fits the figure.
const TITLE_EM_PER_CHAR: f64 = 0.5;

/// The title and its font size for a figure `width_px` wide: the full size when the title
/// fits, else a size shrunk to fit down to 60 % of it, else that size with the title cut at a
/// word and ended with "…" (a long scenario name must not run off the figure).
fn fit_title(title: &str, width_px: f64) -> (String, f64) {
    let room = (width_px - 24.0).max(1.0);
    let chars = title.chars().count().max(1) as f64;
    let full = TITLE_EM_PER_CHAR * TITLE_SIZE * chars;
    if full <= room {
        return (title.to_owned(), TITLE_SIZE);
    }
    let smallest = 0.6 * TITLE_SIZE;
    let size = (room / (TITLE_EM_PER_CHAR * chars)).max(smallest);
    if size > smallest {
        return (title.to_owned(), size);
    }
    let fits = ((room / (TITLE_EM_PER_CHAR * size)) as usize).saturating_sub(1);
    let cut: String = title.chars().take(fits).collect();
    let cut = match cut.rfind(' ') {
        Some(i) if i > fits / 2 => cut[..i].trim_end_matches([',', ':', ';']).to_owned(),
        _ => cut,
    };
    (format!("{cut}…"), size)
}

impl Figure {
    /// Renders the figure as an SVG document.
    ///
    /// # Errors
    /// [`ReportError::Draw`] if plotters fails.
    pub fn to_svg(&self) -> Result<String> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size).into_drawing_area();
            root.fill(&WHITE).map_err(draw_error)?;
            let title_height = (TITLE_SIZE * 1.6) as u32;
            let (top, body) = root.split_vertically(title_height);
            let (title, title_size) = fit_title(&self.title, f64::from(self.size.0));
            top.draw_text(
                &title,
                &TextStyle::from((FONT, title_size).into_font())
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
                (self.size.0 as i32 / 2, title_height as i32 / 2 + 2),
            )
            .map_err(draw_error)?;
            // One y label width for the whole figure, so that stacked axes line up.
            let y_area = self
                .panels
                .iter()
                .map(|p| y_label_area(ranges(p).1))
                .max()
                .unwrap_or(60);
            let shared = self.shared_legend();
            let body = match shared {
                Some(panel) => {
                    let (_, _, margin_left, margin_right) = MARGINS;
                    let left = y_area + margin_left;
                    let rows = legend_rows(
                        panel,
                        f64::from(self.size.0) - f64::from(left + margin_right),
                    );
                    let (strip, rest) =
                        body.split_vertically(rows.len() as u32 * LEGEND_ROW_PX + 4);
                    draw_legend(&strip, &rows, left as i32, 0)?;
                    rest
                }
                None => body,
            };
            let areas = self.panel_areas(&body);
            for (panel, area) in self.panels.iter().zip(&areas) {
                draw_panel(panel, area, y_area, shared.is_none())?;
            }
            root.present().map_err(draw_error)?;
        }
        Ok(with_dash_patterns(&svg))
    }

    /// The panel whose legend every panel shares (the same labels drawn the same way, in the
    /// same order), drawn once under the title; `None` for one panel or different legends.
    fn shared_legend(&self) -> Option<&Panel> {
        let legend = |p: &'_ Panel| -> Vec<(String, Style)> {
            p.series
                .iter()
                .filter(|s| !s.label.is_empty())
                .map(|s| (s.label.clone(), s.style))
                .collect()
        };
        let first = self.panels.first()?;
        let entries = legend(first);
        (self.panels.len() > 1
            && !entries.is_empty()
            && self.panels.iter().all(|p| legend(p) == entries))
        .then_some(first)
    }

    /// The drawing area of every panel: `columns` per row, or the row lengths of `rows`.
    fn panel_areas<'a>(&self, body: &Area<'a>) -> Vec<Area<'a>> {
        if self.rows.is_empty() {
            let columns = self.columns.max(1);
            let rows = self.panels.len().div_ceil(columns);
            return body.split_evenly((rows, columns));
        }
        body.split_evenly((self.rows.len(), 1))
            .iter()
            .zip(&self.rows)
            .flat_map(|(row, &n)| row.split_evenly((1, n.max(1))))
            .collect()
    }
}

fn draw_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> ReportError {
    ReportError::Draw(e.to_string())
}

/// Margins around a panel's axes (top, bottom, left, right), px.
const MARGINS: (u32, u32, u32, u32) = (6, 8, 10, 32);

/// Height of one row of legend entries, px.
const LEGEND_ROW_PX: u32 = 26;
/// Length of a legend entry's line sample, px.
const LEGEND_SAMPLE_PX: i32 = 40;

/// The SVG `opacity` plotters writes for a line drawn with a stroke pattern: a value no other
/// element has (exact binary fractions, printed exactly), replaced after drawing by
/// `opacity="1"` and the pattern's `stroke-dasharray` ([`with_dash_patterns`]), since
/// plotters' SVG backend has no dashes of its own.
fn dash_marker(dash: Dash) -> Option<f64> {
    match dash {
        Dash::Solid => None,
        Dash::Dashed => Some(1.0 - 1.0 / 512.0),
        Dash::Dotted => Some(1.0 - 2.0 / 512.0),
        Dash::DashDot => Some(1.0 - 3.0 / 512.0),
    }
}

/// The stroke of a line series: its colour, width and (through [`dash_marker`]) pattern.
fn line_style(color: RGBColor, width: u32, dash: Dash) -> ShapeStyle {
    match dash_marker(dash) {
        Some(alpha) => color.mix(alpha).stroke_width(width),
        None => color.stroke_width(width),
    }
}

/// Gives every polyline drawn with a [`dash_marker`] opacity its `stroke-dasharray` (round
/// caps for dotted patterns). plotters writes one element per line.
fn with_dash_patterns(svg: &str) -> String {
    let markers: Vec<(String, Dash)> = [Dash::Dashed, Dash::Dotted, Dash::DashDot]
        .into_iter()
        .filter_map(|d| dash_marker(d).map(|a| (format!("opacity=\"{a}\""), d)))
        .collect();
    let mut out = String::with_capacity(svg.len() + 1024);
    for line in svg.split_inclusive('\n') {
        let found = markers.iter().find(|(m, _)| line.contains(m.as_str()));
        match found {
            Some((marker, dash)) => {
                let width = line
                    .split("stroke-width=\"")
                    .nth(1)
                    .and_then(|rest| rest.split('"').next())
                    .and_then(|w| w.parse::<u32>().ok())
                    .unwrap_or(1);
                let pattern = dash.dasharray(width).unwrap_or_default();
                let caps = if *dash == Dash::Dashed {
                    ""
                } else {
                    " stroke-linecap=\"round\""
                };
                out.push_str(&line.replacen(
                    marker.as_str(),
                    &format!("opacity=\"1\" stroke-dasharray=\"{pattern}\"{caps}"),
                    1,
                ));
            }
            None => out.push_str(line),
        }
    }
    out
}

/// Where a panel's axes, ticks and legend go.
struct Layout {
    /// Horizontal range.
    x: (f64, f64),
    /// Vertical range.
    y: (f64, f64),
    /// Height of the x label area, px.
    x_area: u32,
    /// Most tick labels on each axis.
    labels: (usize, usize),
    /// Decimals of the tick labels on each axis.
    decimals: (usize, usize),
}

impl Layout {
    fn new(panel: &Panel, area: &Area<'_>, y_area: u32) -> Self {
        let (x, y) = ranges(panel);
        let (margin_top, margin_bottom, margin_left, margin_right) = MARGINS;
        let x_area = (2.6 * AXIS_DESC_SIZE) as u32;
        let (w, h) = area.dim_in_pixel();
        let plot_px = (
            (f64::from(w) - f64::from(y_area + margin_left + margin_right)).max(50.0),
            (f64::from(h) - f64::from(x_area + margin_top + margin_bottom)).max(50.0),
        );
        let x_labels = label_count(plot_px.0, 55.0, X_LABELS_MAX);
        let y_labels = label_count(plot_px.1, 30.0, Y_LABELS_MAX);
        Self {
            x,
            y,
            x_area,
            labels: (x_labels, y_labels),
            decimals: (tick_decimals(x, x_labels), tick_decimals(y, y_labels)),
        }
    }
}

/// The legend entries of a panel laid out in rows across `width` px: per row, the series
/// and the x offset of each entry.
fn legend_rows(panel: &Panel, width: f64) -> Vec<Vec<(&Series, i32)>> {
    let em = LEGEND_SIZE / 1.24;
    let mut rows: Vec<Vec<(&Series, i32)>> = Vec::new();
    let mut x = 0.0;
    for s in panel.series.iter().filter(|s| !s.label.is_empty()) {
        // Sample, gap, text (about 0.6 em a character), space before the next entry.
        let entry = f64::from(LEGEND_SAMPLE_PX) + 8.0 + 0.6 * em * s.label.chars().count() as f64;
        if rows.is_empty() || (x > 0.0 && x + entry > width) {
            rows.push(Vec::new());
            x = 0.0;
        }
        if let Some(row) = rows.last_mut() {
            row.push((s, x as i32));
        }
        x += entry + 24.0;
    }
    rows
}

/// A panel: its caption and (with `legend`) its legend strip above the axes, then the axes
/// and the series.
fn draw_panel(panel: &Panel, area: &Area<'_>, y_area: u32, legend: bool) -> Result<()> {
    let body = draw_panel_head(panel, area, y_area, legend)?;
    let (x_log, y_log) = (panel.x_log, panel.y_log);
    let logged;
    let panel = if x_log || y_log {
        logged = log_panel(panel);
        &logged
    } else {
        panel
    };
    let layout = Layout::new(panel, &body, y_area);
    if !panel.x_categories.is_empty() {
        return draw_category_chart(panel, &body, y_area, &layout, y_log);
    }
    draw_chart(panel, &body, y_area, &layout, (x_log, y_log))
}

/// A panel's head: its caption and (with `legend`) its legend strip, drawn at the top of
/// `area`; the rest of `area`, for the axes.
fn draw_panel_head<'a>(
    panel: &Panel,
    area: &Area<'a>,
    y_area: u32,
    legend: bool,
) -> Result<Area<'a>> {
    let (w, _) = area.dim_in_pixel();
    let (_, _, margin_left, margin_right) = MARGINS;
    let left = (y_area + margin_left) as i32;
    let width = f64::from(w) - f64::from(y_area + margin_left + margin_right);
    let legend = if legend {
        legend_rows(panel, width)
    } else {
        Vec::new()
    };
    let caption_px = if panel.title.is_empty() {
        0
    } else {
        (CAPTION_SIZE * 1.3) as u32
    };
    let legend_px = if legend.is_empty() {
        0
    } else {
        legend.len() as u32 * LEGEND_ROW_PX + 4
    };
    let (head, body) = area.split_vertically(caption_px + legend_px);
    if !panel.title.is_empty() {
        head.draw_text(
            &panel.title,
            &TextStyle::from((FONT, CAPTION_SIZE).into_font())
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Center)),
            (w as i32 / 2, caption_px as i32 / 2 + 2),
        )
        .map_err(draw_error)?;
    }
    draw_legend(&head, &legend, left, caption_px as i32)?;
    Ok(body)
}

/// A linear axis over `r`.
fn linear(r: (f64, f64)) -> RangedCoordf64 {
    (r.0..r.1).into()
}

/// A panel with named categories along x (`panel.x_categories`, at 1, 2, …), its y axis
/// logarithmic with `y_log`.
fn draw_category_chart(
    panel: &Panel,
    body: &Area<'_>,
    y_area: u32,
    layout: &Layout,
    y_log: bool,
) -> Result<()> {
    let (x, y) = (layout.x, layout.y);
    let y_dec = layout.decimals.1;
    let y_fmt = move |v: &f64| format_tick(*v, y_dec);
    let log_fmt = |v: &f64| log_tick_label(*v);
    let names = &panel.x_categories;
    let name = |v: &f64| {
        let i = v.round();
        match (i >= 1.0 && (v - i).abs() < 1e-9).then(|| names.get(i as usize - 1)) {
            Some(Some(n)) => n.clone(),
            _ => String::new(),
        }
    };
    let x_axis = CategoryAxis {
        range: linear(x),
        count: names.len(),
    };
    let y_fmt_ref: &dyn Fn(&f64) -> String = if y_log { &log_fmt } else { &y_fmt };
    if y_log {
        let (y_axis, minor) = LogAxis::over(y, layout.labels.1);
        let axes = Axes::new(x_axis, y_axis, &name, y_fmt_ref).minor_y(minor);
        draw_axes_and_data(panel, body, y_area, layout, axes)
    } else {
        let axes = Axes::new(x_axis, linear(y), &name, y_fmt_ref);
        draw_axes_and_data(panel, body, y_area, layout, axes)
    }
}

/// A panel with numbers along both axes, each linear or logarithmic as `(x_log, y_log)`.
fn draw_chart(
    panel: &Panel,
    body: &Area<'_>,
    y_area: u32,
    layout: &Layout,
    (x_log, y_log): (bool, bool),
) -> Result<()> {
    let (x, y) = (layout.x, layout.y);
    let (x_dec, y_dec) = layout.decimals;
    let x_fmt = move |v: &f64| format_tick(*v, x_dec);
    let y_fmt = move |v: &f64| format_tick(*v, y_dec);
    let log_fmt = |v: &f64| log_tick_label(*v);
    match (x_log, y_log) {
        (false, false) => {
            let axes = Axes::new(linear(x), linear(y), &x_fmt, &y_fmt);
            draw_axes_and_data(panel, body, y_area, layout, axes)
        }
        (true, false) => {
            let (x_axis, minor) = LogAxis::over(x, layout.labels.0);
            let axes = Axes::new(x_axis, linear(y), &log_fmt, &y_fmt).minor_x(minor);
            draw_axes_and_data(panel, body, y_area, layout, axes)
        }
        (false, true) => {
            let (y_axis, minor) = LogAxis::over(y, layout.labels.1);
            let axes = Axes::new(linear(x), y_axis, &x_fmt, &log_fmt).minor_y(minor);
            draw_axes_and_data(panel, body, y_area, layout, axes)
        }
        (true, true) => {
            let (x_axis, minor_x) = LogAxis::over(x, layout.labels.0);
            let (y_axis, minor_y) = LogAxis::over(y, layout.labels.1);
            let axes = Axes::new(x_axis, y_axis, &log_fmt, &log_fmt)
                .minor_x(minor_x)
                .minor_y(minor_y);
            draw_axes_and_data(panel, body, y_area, layout, axes)
        }
    }
}

/// A panel's axes ([`draw_axes`]), then its series ([`draw_data`]).
fn draw_axes_and_data<X, Y>(
    panel: &Panel,
    body: &Area<'_>,
    y_area: u32,
    layout: &Layout,
    axes: Axes<'_, X, Y>,
) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let mut chart = draw_axes(panel, body, y_area, layout, axes)?;
    draw_data(&mut chart, panel, layout)
}

/// A panel's two axes with their tick labels' formats and their minor grid lines (the
/// logarithmic axes' 1…9 × 10^k, in decades).
struct Axes<'f, X, Y> {
    x: X,
    y: Y,
    x_fmt: &'f dyn Fn(&f64) -> String,
    y_fmt: &'f dyn Fn(&f64) -> String,
    minor_x: Vec<f64>,
    minor_y: Vec<f64>,
}

impl<'f, X, Y> Axes<'f, X, Y> {
    fn new(
        x: X,
        y: Y,
        x_fmt: &'f dyn Fn(&f64) -> String,
        y_fmt: &'f dyn Fn(&f64) -> String,
    ) -> Self {
        Self {
            x,
            y,
            x_fmt,
            y_fmt,
            minor_x: Vec::new(),
            minor_y: Vec::new(),
        }
    }

    fn minor_x(mut self, minor: Vec<f64>) -> Self {
        self.minor_x = minor;
        self
    }

    fn minor_y(mut self, minor: Vec<f64>) -> Self {
        self.minor_y = minor;
        self
    }
}

/// The shaded interval and the series of a panel, on its axes.
fn draw_data<X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut AnyChart<'_, '_, X, Y>,
    panel: &Panel,
    layout: &Layout,
) -> Result<()> {
    if let Some((a, b)) = panel.shade_x {
        let y = layout.y;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a, y.0), (b, y.1)],
                SHADE.mix(0.35).filled(),
            )))
            .map_err(draw_error)?;
    }
    for series in &panel.series {
        draw_series(chart, series)?;
    }
    Ok(())
}

/// A panel with its logarithmic axes in decades: every x of a logarithmic x axis (and its
/// range and shade), every y of a logarithmic y axis (and its range), replaced by its
/// `log10`, points at values ≤ 0 there dropped. A linear panel is returned as it is.
fn log_panel(panel: &Panel) -> Panel {
    let (x_log, y_log) = (panel.x_log, panel.y_log);
    let log = |(a, b): (f64, f64)| (a.log10(), b.log10());
    let positive = |(a, b): &(f64, f64)| *a > 0.0 && *b > 0.0;
    let kept = |v: f64, on: bool| !on || (v > 0.0 && v.is_finite());
    let to = |v: f64, on: bool| if on { v.log10() } else { v };
    Panel {
        series: panel
            .series
            .iter()
            .map(|s| Series {
                label: s.label.clone(),
                points: s
                    .points
                    .iter()
                    .filter(|p| kept(p.0, x_log) && kept(p.1, y_log))
                    .map(|&(x, y)| (to(x, x_log), to(y, y_log)))
                    .collect(),
                style: s.style,
            })
            .collect(),
        x_range: match x_log {
            true => panel.x_range.filter(positive).map(log),
            false => panel.x_range,
        },
        y_range: match y_log {
            true => panel.y_range.filter(positive).map(log),
            false => panel.y_range,
        },
        shade_x: match x_log {
            true => panel.shade_x.filter(positive).map(log),
            false => panel.shade_x,
        },
        ..panel.clone()
    }
}

/// The ticks of a logarithmic axis over `range` (decades, `log10` of the values): the
/// labelled ones (1, 2, 5 × 10^k, or only 10^k when more than `max_labels` of those), and
/// the other multiples 1…9 × 10^k for the minor grid.
fn log_ticks(range: (f64, f64), max_labels: usize) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (range.0.min(range.1), range.0.max(range.1));
    let tol = 1e-9 * (hi - lo).max(1e-12);
    let mut every = Vec::new();
    if lo.is_finite() && hi.is_finite() {
        for decade in (lo.floor() as i32)..=(hi.ceil() as i32) {
            for m in 1..=9 {
                let v = f64::from(decade) + f64::from(m).log10();
                if v >= lo - tol && v <= hi + tol {
                    every.push((m, v.clamp(lo, hi)));
                }
            }
        }
    }
    let pick = |ms: &[i32]| -> Vec<f64> {
        every
            .iter()
            .filter(|(m, _)| ms.contains(m))
            .map(|p| p.1)
            .collect()
    };
    let mut labelled = pick(&[1, 2, 5]);
    if labelled.len() > max_labels.max(2) {
        labelled = pick(&[1]);
    }
    let minor = every
        .iter()
        .map(|p| p.1)
        .filter(|v| !labelled.contains(v))
        .collect();
    (labelled, minor)
}

/// The label of a logarithmic tick at `log10` value `v`: `10^v` to 6 significant digits,
/// without trailing zeros (0.1, 2, 50, 200).
fn log_tick_label(v: f64) -> String {
    let x = 10f64.powf(v);
    let decimals = (5 - x.abs().log10().floor() as i64).clamp(0, 12) as usize;
    let text = format!("{x:.decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    };
    text.replace('-', "−")
}

/// A logarithmic axis in decades (`log10` of the values), with its ticks and grid lines at
/// the values given and labels as [`log_tick_label`] writes them.
struct LogAxis {
    /// The decades, mapped linearly.
    decades: RangedCoordf64,
    /// The labelled ticks, in decades.
    labelled: Vec<f64>,
}

impl Ranged for LogAxis {
    type ValueType = f64;
    type FormatOption = NoDefaultFormatting;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.decades.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            // The minor grid is drawn as series (see `draw_log_axes`).
            Vec::new()
        } else {
            self.labelled.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.decades.range()
    }
}

impl ValueFormatter<f64> for LogAxis {
    fn format(value: &f64) -> String {
        log_tick_label(*value)
    }
}

/// A linear axis whose ticks are the categories' places, 1 … `count` (each labelled with its
/// name by the panel's formatter).
struct CategoryAxis {
    range: RangedCoordf64,
    count: usize,
}

impl Ranged for CategoryAxis {
    type ValueType = f64;
    type FormatOption = NoDefaultFormatting;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.range.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            (1..=self.count).map(|i| i as f64).collect()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.range.range()
    }
}

impl ValueFormatter<f64> for CategoryAxis {
    fn format(value: &f64) -> String {
        format!("{value}")
    }
}

impl LogAxis {
    /// A logarithmic axis over `range` (decades) with at most about `max_labels` labels, and
    /// its minor grid's ticks ([`log_ticks`]).
    fn over(range: (f64, f64), max_labels: usize) -> (Self, Vec<f64>) {
        let (labelled, minor) = log_ticks(range, max_labels);
        (
            LogAxis {
                decades: (range.0..range.1).into(),
                labelled,
            },
            minor,
        )
    }
}

/// Legend rows (from [`legend_rows`]) from `left` px across and `top` px down `area`.
fn draw_legend(area: &Area<'_>, rows: &[Vec<(&Series, i32)>], left: i32, top: i32) -> Result<()> {
    for (r, row) in rows.iter().enumerate() {
        let y = top + (r as u32 * LEGEND_ROW_PX + LEGEND_ROW_PX / 2) as i32 + 2;
        for &(series, x) in row {
            draw_legend_entry(area, series, (left + x, y))?;
        }
    }
    Ok(())
}

/// One legend entry at `(x, y)` (the middle of its row): a sample drawn as the series is,
/// then its label.
fn draw_legend_entry(area: &Area<'_>, series: &Series, (x, y): (i32, i32)) -> Result<()> {
    let end = x + LEGEND_SAMPLE_PX;
    match series.style {
        Style::Line { color, width, dash } => area
            .draw(&PathElement::new(
                vec![(x, y), (end, y)],
                line_style(color, width.max(2), dash),
            ))
            .map_err(draw_error)?,
        Style::Points { color, .. } => area
            .draw(&Circle::new(
                (x + LEGEND_SAMPLE_PX / 2, y),
                5,
                color.filled(),
            ))
            .map_err(draw_error)?,
        Style::Segments { color, width } => area
            .draw(&PathElement::new(
                vec![
                    (x + LEGEND_SAMPLE_PX / 2, y - 8),
                    (x + LEGEND_SAMPLE_PX / 2, y + 8),
                ],
                color.stroke_width(width),
            ))
            .map_err(draw_error)?,
    }
    area.draw_text(
        &series.label,
        &TextStyle::from((FONT, LEGEND_SIZE).into_font())
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Center)),
        (end + 8, y),
    )
    .map_err(draw_error)
}

/// The axes of a panel: labels and grid lines at each axis's ticks (a logarithmic axis's
/// labelled ones, [`log_ticks`], with its minor grid lighter), and the axis descriptions.
fn draw_axes<'a, 'b, X, Y>(
    panel: &Panel,
    area: &'a Area<'b>,
    y_area: u32,
    layout: &Layout,
    axes: Axes<'_, X, Y>,
) -> Result<AnyChart<'a, 'b, X, Y>>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let (margin_top, margin_bottom, margin_left, margin_right) = MARGINS;
    let (x, y) = (layout.x, layout.y);
    let mut chart = ChartBuilder::on(area)
        .margin_top(margin_top)
        .margin_bottom(margin_bottom)
        .margin_left(margin_left)
        .margin_right(margin_right)
        .x_label_area_size(layout.x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(axes.x, axes.y)
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(layout.labels.0)
        .y_labels(layout.labels.1)
        .x_label_formatter(axes.x_fmt)
        .y_label_formatter(axes.y_fmt)
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_DESC_SIZE))
        .bold_line_style(RGBColor(225, 225, 225))
        .light_line_style(TRANSPARENT)
        .axis_style(RGBColor(90, 90, 90))
        .draw()
        .map_err(draw_error)?;
    let style = RGBColor(242, 242, 242).stroke_width(1);
    if !axes.minor_x.is_empty() {
        chart
            .draw_series(
                axes.minor_x
                    .into_iter()
                    .map(move |v| PathElement::new(vec![(v, y.0), (v, y.1)], style)),
            )
            .map_err(draw_error)?;
    }
    if !axes.minor_y.is_empty() {
        chart
            .draw_series(
                axes.minor_y
                    .into_iter()
                    .map(move |v| PathElement::new(vec![(x.0, v), (x.1, v)], style)),
            )
            .map_err(draw_error)?;
    }
    Ok(chart)
}

/// One series (its legend entry is drawn above the axes, by [`draw_legend_entry`]).
fn draw_series<X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut AnyChart<'_, '_, X, Y>,
    series: &Series,
) -> Result<()> {
    match series.style {
        Style::Line { color, width, dash } => {
            chart
                .draw_series(LineSeries::new(
                    series.points.iter().copied(),
                    line_style(color, width, dash),
                ))
                .map_err(draw_error)?;
        }
        Style::Points { color, radius } => {
            let style = color.mix(0.55).filled();
            chart
                .draw_series(
                    series
                        .points
                        .iter()
                        .map(move |&p| Circle::new(p, radius, style)),
                )
                .map_err(draw_error)?;
        }
        Style::Segments { color, width } => {
            let style = color.stroke_width(width);
            chart
                .draw_series(
                    series
                        .points
                        .chunks_exact(2)
                        .map(move |pair| PathElement::new(vec![pair[0], pair[1]], style)),
                )
                .map_err(draw_error)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figure::{RECORDED, SIMULATED};
    use crate::series::{line, patterned};

    #[test]
    fn a_title_that_would_run_off_the_figure_is_shrunk_then_cut_at_a_word() {
        let short = "a test";
        assert_eq!(fit_title(short, 1000.0), (short.to_owned(), TITLE_SIZE));
        let width = 1000.0;
        let room = width - 24.0;
        let long =
            "Northridge 1994 Tarzana at 120 % on the LHPOST with a two-storey frame: spectra";
        let (t, size) = fit_title(long, width);
        assert_eq!(t, long);
        assert!((0.6 * TITLE_SIZE..TITLE_SIZE).contains(&size));
        assert!(TITLE_EM_PER_CHAR * size * long.chars().count() as f64 <= room + 1e-9);
        let longer = long.repeat(3);
        let (t, size) = fit_title(&longer, width);
        assert!(t.ends_with('…') && !t.ends_with(" …"), "{t}");
        assert!((size - 0.6 * TITLE_SIZE).abs() < 1e-12);
        assert!(TITLE_EM_PER_CHAR * size * t.chars().count() as f64 <= room);
    }

    /// A panel of a recorded and a simulated sine, drawn over the data's ranges.
    fn figure(size: (u32, u32)) -> Figure {
        let t: Vec<f64> = (0..400).map(|i| f64::from(i) * 0.01).collect();
        let rec: Vec<(f64, f64)> = t.iter().map(|&t| (t, 0.38 * (3.0 * t).sin())).collect();
        let sim: Vec<(f64, f64)> = t
            .iter()
            .map(|&t| (t, 0.37 * (3.0 * t - 0.05).sin()))
            .collect();
        Figure {
            name: "test".into(),
            title: "a test".into(),
            caption: String::new(),
            panels: vec![Panel::new(
                "displacement",
                "t (s)",
                "u (m)",
                vec![
                    line("recorded", rec, RECORDED, 3),
                    patterned("simulated", sim, SIMULATED, 2, Dash::Dashed),
                ],
            )],
            columns: 1,
            rows: Vec::new(),
            size,
        }
    }

    fn points(node: roxmltree::Node<'_, '_>) -> Vec<(f64, f64)> {
        node.attribute("points")
            .unwrap_or_default()
            .split_whitespace()
            .filter_map(|p| {
                let (x, y) = p.split_once(',')?;
                Some((x.parse().ok()?, y.parse().ok()?))
            })
            .collect()
    }

    /// A logarithmic y axis (issue 38: the convergence figure's "log10 of the error (%)"
    /// read 0.47 where the value was 2.9 %): labelled in the data's own units at 1, 2, 5 ×
    /// 10^k, and a point at 2.9 drawn log-proportionally between the labels 2 and 5.
    #[test]
    fn a_logarithmic_y_axis_is_labelled_in_the_data_units_and_places_points_by_log() {
        let mut panel = Panel::new(
            "",
            "iteration",
            "error (%)",
            vec![crate::series::points(
                "",
                vec![(0.0, 60.0), (1.0, 2.9), (2.0, 1.2)],
                RECORDED,
                4,
            )],
        );
        panel.y_log = true;
        let fig = Figure {
            name: "log-y".into(),
            title: "log y".into(),
            caption: String::new(),
            panels: vec![panel],
            columns: 1,
            rows: Vec::new(),
            size: (800, 600),
        };
        let svg = fig.to_svg().unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let label_y = |text: &str| -> f64 {
            doc.descendants()
                .find(|n| n.has_tag_name("text") && n.text().map(str::trim) == Some(text))
                .and_then(|n| n.attribute("y"))
                .and_then(|y| y.parse().ok())
                .unwrap_or_else(|| panic!("no tick label {text:?} in the SVG"))
        };
        let (y2, y5, y10) = (label_y("2"), label_y("5"), label_y("10"));
        // Equal ratios, equal distances: 2 → 5 is log10(2.5) of a decade, 5 → 10 log10(2).
        let decade_px = (y2 - y5) / 2.5_f64.log10();
        assert!(
            ((y5 - y10) - decade_px * 2.0_f64.log10()).abs() < 1.5,
            "{y2} {y5} {y10}"
        );
        // Labels in the data's units up to its 60 (the old axis in decades ended at 1.8).
        assert!(label_y("50") < y10);
        let cy: Vec<f64> = doc
            .descendants()
            .filter(|n| n.has_tag_name("circle"))
            .filter_map(|n| n.attribute("cy")?.parse().ok())
            .collect();
        assert_eq!(cy.len(), 3, "{cy:?}");
        // Text baselines sit a few px below the tick; the same offset for every label, so
        // the point's place between labels 2 and 5 is its place between the ticks.
        let at = (y2 - cy[1]) / (y2 - y5);
        let want = (2.9_f64 / 2.0).log10() / 2.5_f64.log10();
        assert!((at - want).abs() < 0.02, "{at} against {want}");
    }

    /// Bars named on the axis (issue 38: plan-margins had a numeric axis 0.5 … 6.5 with the
    /// names in its description): one label per bar, under it, and no numbers.
    #[test]
    fn category_bars_are_labelled_with_their_names_under_each_bar() {
        let mut panel = Panel::new(
            "",
            "limit",
            "use (%)",
            vec![crate::series::line(
                "",
                vec![(1.0, 0.0), (1.0, 40.0), (2.0, 0.0), (2.0, 90.0)],
                RECORDED,
                2,
            )],
        );
        panel.x_categories = vec!["stroke_m".into(), "force_n".into()];
        panel.x_range = Some((0.5, 2.5));
        let fig = Figure {
            name: "bars".into(),
            title: "bars".into(),
            caption: String::new(),
            panels: vec![panel],
            columns: 1,
            rows: Vec::new(),
            size: (800, 500),
        };
        let svg = fig.to_svg().unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let texts: Vec<(String, f64)> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| {
                let x = n.attribute("x")?.parse().ok()?;
                Some((n.text()?.trim().to_owned(), x))
            })
            .collect();
        let at = |name: &str| {
            texts
                .iter()
                .find(|(t, _)| t == name)
                .map(|p| p.1)
                .unwrap_or_else(|| panic!("no {name:?} in {texts:?}"))
        };
        let (x1, x2) = (at("stroke_m"), at("force_n"));
        let line: Vec<(f64, f64)> = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some("#1F77B4"))
            .flat_map(points)
            .collect();
        // Under its bar (the bar's x to a pixel).
        assert!(
            (line[0].0 - x1).abs() <= 1.0 && (line[2].0 - x2).abs() <= 1.0,
            "{line:?}"
        );
        assert!(
            !texts.iter().any(|(t, _)| t == "1.5" || t == "0.5"),
            "{texts:?}"
        );
    }

    /// Recorded is a solid polyline, simulated a dashed one (in the data and in the legend),
    /// and nothing else is dashed.
    #[test]
    fn recorded_is_solid_and_simulated_dashed() {
        let svg = figure((900, 500)).to_svg().unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let lines = |stroke: &str| -> Vec<Option<String>> {
            doc.descendants()
                .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(stroke))
                .map(|n| n.attribute("stroke-dasharray").map(str::to_owned))
                .collect()
        };
        // The data line and its legend sample each.
        assert_eq!(lines("#1F77B4"), [None, None]);
        let dashed = lines("#D95F02");
        assert_eq!(dashed.len(), 2);
        assert!(
            dashed.iter().all(|d| d.as_deref() == Some("12 6")),
            "{dashed:?}"
        );
        assert_eq!(svg.matches("stroke-dasharray").count(), 2);
        assert!(!svg.contains("opacity=\"0.998046875\""));
    }

    /// The legend sits above the plotted data (its texts' baselines above the data's top
    /// pixel), and the y axis spans the data to within the 4 % padding each way: the data's
    /// pixel height is at least 1/1.1 of the axis's (the old legend headroom gave 0.38 m of
    /// data on 0.6 m of axis, 0.63).
    #[test]
    fn legend_is_outside_the_data_and_does_not_stretch_the_axis() {
        let svg = figure((900, 500)).to_svg().unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let data: Vec<(f64, f64)> = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline"))
            .map(points)
            .filter(|p| p.len() > 100)
            .flatten()
            .collect();
        let top = data.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let bottom = data.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        for label in ["recorded", "simulated"] {
            let text = doc
                .descendants()
                .find(|n| n.has_tag_name("text") && n.text().map(str::trim) == Some(label))
                .unwrap();
            let y: f64 = text.attribute("y").unwrap().parse().unwrap();
            // Half a line of text below the anchor at most.
            assert!(y + 10.0 < top, "{label} at y = {y}, data from {top}");
        }
        // The y axis: the vertical axis line (plotters draws it in the axis colour).
        let axis = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some("#5A5A5A"))
            .map(points)
            .find(|p| p.len() == 2 && p[0].0 == p[1].0)
            .unwrap();
        let axis_px = (axis[1].1 - axis[0].1).abs();
        let ratio = (bottom - top) / axis_px;
        assert!((1.0 / 1.1..=1.0).contains(&ratio), "data/axis {ratio}");
    }

    /// Rows of different lengths: a wide panel over three.
    #[test]
    fn rows_split_the_body_as_asked() {
        let mut f = figure((1200, 900));
        let p = f.panels[0].clone();
        f.panels = vec![p.clone(), p.clone(), p.clone(), p];
        f.rows = vec![1, 3];
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, f.size).into_drawing_area();
        let areas: Vec<_> = f
            .panel_areas(&root)
            .iter()
            .map(|a| (a.get_base_pixel(), a.dim_in_pixel()))
            .collect();
        assert_eq!(
            areas,
            [
                ((0, 0), (1200, 450)),
                ((0, 450), (400, 450)),
                ((400, 450), (400, 450)),
                ((800, 450), (400, 450)),
            ]
        );
    }
}
