//! Building series: lines, points and error-bar segments, and thinning long records to what
//! a figure can show (an envelope for time histories, every k-th sample for scatter).

use plotters::style::RGBColor;

use crate::figure::{Dash, Series, Style};

/// Points `(x, y)` of a series, in the panel's units.
pub type Points = Vec<(f64, f64)>;

/// Most points drawn for a scatter series (evenly spaced samples beyond that).
pub const MAX_SCATTER_POINTS: usize = 4000;
/// Most points drawn for a loop (hysteresis) line (evenly spaced samples beyond that).
pub const MAX_LOOP_POINTS: usize = 20_000;

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

/// A series drawn in `style`.
pub fn series(label: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Series {
    Series {
        label: label.into(),
        points,
        style,
    }
}

/// A solid line series.
pub fn line(label: impl Into<String>, points: Points, color: RGBColor, width: u32) -> Series {
    series(
        label,
        points,
        Style::Line {
            color,
            width,
            dash: Dash::Solid,
        },
    )
}

/// A line series with a stroke pattern.
pub fn patterned(
    label: impl Into<String>,
    points: Points,
    color: RGBColor,
    width: u32,
    dash: Dash,
) -> Series {
    series(label, points, Style::Line { color, width, dash })
}

/// A point series: filled circles of `radius` px.
pub fn points(label: impl Into<String>, points: Points, color: RGBColor, radius: i32) -> Series {
    series(label, points, Style::Points { color, radius })
}

/// Error bars: one segment, 2 px wide, per consecutive pair of `points`, without a legend.
pub fn segments(points: Vec<(f64, f64)>, color: RGBColor) -> Series {
    series("", points, Style::Segments { color, width: 2 })
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
