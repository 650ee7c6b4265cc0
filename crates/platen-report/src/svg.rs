//! Drawing a [`Figure`] as SVG with plotters' SVG backend.
//!
//! Only the SVG backend is used, with plotters' built-in text-size estimate, so no font file,
//! font library or C library is needed: text is written as SVG `<text>` in the `sans-serif`
//! family and laid out by whatever displays it. Output is a pure function of the data, so the
//! same input gives the same bytes.
//!
//! Every data series is one `<polyline>` (lines) or a run of `<circle>`s (points) in its own
//! colour, and its legend entry repeats that colour once, so a figure's series can be counted
//! from the file.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::axes::{format_tick, label_count, place_legend, ranges, tick_decimals, y_label_area};
use crate::error::{ReportError, Result};
use crate::figure::{
    Figure, Panel, Series, Style, AXIS_DESC_SIZE, CAPTION_SIZE, FONT, LEGEND_SIZE, SHADE,
    TICK_SIZE, TITLE_SIZE, X_LABELS_MAX, Y_LABELS_MAX,
};

/// The SVG drawing area of a panel.
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// The axes of a panel, ready to draw series on.
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

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
            top.draw_text(
                &self.title,
                &TextStyle::from((FONT, TITLE_SIZE).into_font())
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
                (self.size.0 as i32 / 2, title_height as i32 / 2 + 2),
            )
            .map_err(draw_error)?;
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
            root.present().map_err(draw_error)?;
        }
        Ok(svg)
    }
}

fn draw_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> ReportError {
    ReportError::Draw(e.to_string())
}

/// Margins around a panel's axes (top, bottom, left, right), px.
const MARGINS: (u32, u32, u32, u32) = (6, 8, 10, 32);

/// Where a panel's axes, ticks and legend go.
struct Layout {
    /// Horizontal range.
    x: (f64, f64),
    /// Vertical range, with headroom for the legend if it needs it.
    y: (f64, f64),
    /// Height of the x label area, px.
    x_area: u32,
    /// Most tick labels on each axis.
    labels: (usize, usize),
    /// Decimals of the tick labels on each axis.
    decimals: (usize, usize),
    /// Where the legend goes.
    legend: SeriesLabelPosition,
}

impl Layout {
    fn new(panel: &Panel, area: &Area<'_>, y_area: u32) -> Self {
        let (x, y_data) = ranges(panel);
        let (margin_top, margin_bottom, margin_left, margin_right) = MARGINS;
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
        let (legend, y) = place_legend(panel, x, y_data, plot_px);
        let x_labels = label_count(plot_px.0, 55.0, X_LABELS_MAX);
        let y_labels = label_count(plot_px.1, 40.0, Y_LABELS_MAX);
        Self {
            x,
            y,
            x_area,
            labels: (x_labels, y_labels),
            decimals: (tick_decimals(x, x_labels), tick_decimals(y, y_labels)),
            legend,
        }
    }
}

fn draw_panel(panel: &Panel, area: &Area<'_>, y_area: u32) -> Result<()> {
    let layout = Layout::new(panel, area, y_area);
    let mut chart = draw_axes(panel, area, y_area, &layout)?;
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
        draw_series(&mut chart, series)?;
    }
    if panel.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .position(layout.legend)
            .margin(10)
            .legend_area_size(36)
            .label_font((FONT, LEGEND_SIZE))
            .background_style(WHITE.mix(0.88))
            .border_style(RGBColor(150, 150, 150))
            .draw()
            .map_err(draw_error)?;
    }
    Ok(())
}

/// The panel's caption, axes, grid, tick labels and axis descriptions.
fn draw_axes<'a, 'b>(
    panel: &Panel,
    area: &'a Area<'b>,
    y_area: u32,
    layout: &Layout,
) -> Result<Chart<'a, 'b>> {
    let (margin_top, margin_bottom, margin_left, margin_right) = MARGINS;
    let (x, y) = (layout.x, layout.y);
    let mut builder = ChartBuilder::on(area);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FONT, CAPTION_SIZE));
    }
    let mut chart = builder
        .margin_top(margin_top)
        .margin_bottom(margin_bottom)
        .margin_left(margin_left)
        .margin_right(margin_right)
        .x_label_area_size(layout.x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(draw_error)?;
    let (x_dec, y_dec) = layout.decimals;
    let x_fmt = move |v: &f64| format_tick(*v, x_dec);
    let y_fmt = move |v: &f64| format_tick(*v, y_dec);
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(layout.labels.0)
        .y_labels(layout.labels.1)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_DESC_SIZE))
        .bold_line_style(RGBColor(225, 225, 225))
        .light_line_style(TRANSPARENT)
        .axis_style(RGBColor(90, 90, 90))
        .draw()
        .map_err(draw_error)?;
    Ok(chart)
}

/// One series, with its legend entry if it has a label.
fn draw_series(chart: &mut Chart<'_, '_>, series: &Series) -> Result<()> {
    let label = series.label.clone();
    match series.style {
        Style::Line { color, width } => {
            let style = color.stroke_width(width);
            let drawn = chart
                .draw_series(LineSeries::new(series.points.iter().copied(), style))
                .map_err(draw_error)?;
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
                .map_err(draw_error)?;
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
                .map_err(draw_error)?;
            if !label.is_empty() {
                drawn.label(label).legend(move |(lx, ly)| {
                    PathElement::new(vec![(lx + 14, ly - 8), (lx + 14, ly + 8)], style)
                });
            }
        }
    }
    Ok(())
}
