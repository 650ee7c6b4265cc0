//! What a figure is made of: a title over a grid of panels, each a set of axes holding line,
//! point or segment series, with its legend in a strip above the axes (never over the data;
//! one strip under the title when every panel has the same legend). Drawing is [`Figure::to_svg`], rendering and writing in
//! [`crate::render`].

use plotters::style::RGBColor;

/// Colour of recorded data.
pub const RECORDED: RGBColor = RGBColor(31, 119, 180);
/// Colour of simulated data.
pub const SIMULATED: RGBColor = RGBColor(217, 95, 2);
/// Colour of the model law and of fitted lines.
pub const MODEL: RGBColor = RGBColor(0, 0, 0);
/// Colour of a residual time history.
pub const RESIDUAL: RGBColor = RGBColor(117, 112, 179);
/// Fill of the band that marks a zoomed interval.
pub(crate) const SHADE: RGBColor = RGBColor(255, 221, 120);

/// Font sizes (plotters units; the SVG `font-size` is 1/1.24 of these).
pub(crate) const TITLE_SIZE: f64 = 26.0;
pub(crate) const CAPTION_SIZE: f64 = 22.0;
pub(crate) const AXIS_DESC_SIZE: f64 = 21.0;
pub(crate) const TICK_SIZE: f64 = 19.0;
pub(crate) const LEGEND_SIZE: f64 = 19.0;
pub(crate) const FONT: &str = "sans-serif";
/// Most tick labels on a horizontal axis.
pub(crate) const X_LABELS_MAX: usize = 14;
/// Most tick labels on a vertical axis.
pub(crate) const Y_LABELS_MAX: usize = 12;

/// The stroke pattern of a line, so that series differ without colour (a figure printed in
/// grey or read by a colour-blind reader): recorded data solid, simulated dashed, model
/// terms dotted or dash-dotted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dash {
    /// A continuous line.
    #[default]
    Solid,
    /// Dashes about five widths long.
    Dashed,
    /// Round dots.
    Dotted,
    /// Alternating dashes and dots.
    DashDot,
}

impl Dash {
    /// The SVG `stroke-dasharray` of the pattern for a line `width` px wide (`None`: solid).
    pub fn dasharray(self, width: u32) -> Option<String> {
        let w = f64::from(width.max(1));
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some(format!("{} {}", 4.0 * w + 4.0, 2.0 * w + 2.0)),
            Dash::Dotted => Some(format!("0.1 {}", 2.0 * w + 1.0)),
            Dash::DashDot => Some(format!(
                "{} {} 0.1 {}",
                4.0 * w + 4.0,
                2.0 * w + 1.0,
                2.0 * w + 1.0
            )),
        }
    }
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Style {
    /// A polyline.
    Line {
        /// Colour.
        color: RGBColor,
        /// Stroke width, px.
        width: u32,
        /// Stroke pattern.
        dash: Dash,
    },
    /// Filled circles.
    Points {
        /// Colour.
        color: RGBColor,
        /// Radius, px.
        radius: i32,
    },
    /// Separate straight segments between consecutive pairs of points (error bars); one
    /// `<polyline>` per segment.
    Segments {
        /// Colour.
        color: RGBColor,
        /// Stroke width, px.
        width: u32,
    },
}

/// One data series of a panel.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text (empty: no legend entry).
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
    /// Vertical range (default: the data's over the horizontal range, widened 4 % each way).
    pub y_range: Option<(f64, f64)>,
    /// A horizontal interval to shade (a zoomed window).
    pub shade_x: Option<(f64, f64)>,
    /// A logarithmic horizontal axis (a frequency response): the points' x, `x_range` and
    /// `shade_x` stay in the data's units (points at x ≤ 0 are not drawn), the grid has a
    /// line at every 1…9 × 10^k and labels at 1, 2 and 5 × 10^k (only at 10^k when those
    /// would crowd).
    pub x_log: bool,
    /// A logarithmic vertical axis (errors over iterations): the points' y and `y_range` stay
    /// in the data's units (points at y ≤ 0 are not drawn), with the grid and labels of
    /// `x_log`.
    pub y_log: bool,
    /// Names of categories at x = 1, 2, … (bars): the horizontal axis is labelled with them,
    /// one tick each, instead of numbers (empty: a numeric axis).
    pub x_categories: Vec<String>,
}

impl Panel {
    /// A panel with a caption, axis descriptions and series, over the data's ranges.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        series: Vec<Series>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series,
            ..Self::default()
        }
    }
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
    /// Panels in each row, top to bottom, when the rows differ (a wide panel over a row of
    /// small ones); empty: every row has `columns` panels.
    pub rows: Vec<usize>,
    /// Size in px.
    pub size: (u32, u32),
}
