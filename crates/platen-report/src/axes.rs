//! Axes: the data ranges of a panel, tick spacing and labels (the same search plotters makes,
//! so the decimals tell the drawn ticks apart) and the width of the y label area.

use crate::figure::{Panel, AXIS_DESC_SIZE, TICK_SIZE, Y_LABELS_MAX};

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
pub(crate) fn tick_decimals(range: (f64, f64), max_points: usize) -> usize {
    let step = tick_step(range, max_points);
    (-((step.log10() + 1e-9).floor()) as i64).clamp(0, 8) as usize
}

/// Most tick labels along an axis of `px` pixels, `px_per_label` apart.
pub(crate) fn label_count(px: f64, px_per_label: f64, max: usize) -> usize {
    ((px / px_per_label) as usize).clamp(4, max)
}

pub(crate) fn format_tick(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    // "-0.00" → "0.00"
    if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        text[1..].to_owned()
    } else {
        text.replace('-', "−")
    }
}

/// The x and y ranges of a panel: the given or data x range, and the given or data y range
/// over it.
pub(crate) fn ranges(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let x = panel.x_range.unwrap_or_else(|| {
        padded_range(
            panel
                .series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
        )
    });
    let y = panel.y_range.unwrap_or_else(|| {
        padded_range(
            panel
                .series
                .iter()
                .flat_map(|s| s.points.iter().filter(|p| p.0 >= x.0 && p.0 <= x.1))
                .map(|p| p.1),
        )
    });
    (x, y)
}

/// Width of the y label area that fits the widest tick label of `y` and the axis
/// description, px (about 0.6 em per character).
pub(crate) fn y_label_area(y: (f64, f64)) -> u32 {
    // The most labels an axis gets (see `draw_panel`): the widest text.
    let decimals = tick_decimals(y, Y_LABELS_MAX);
    let widest = [y.0, y.1, 0.5 * (y.0 + y.1)]
        .iter()
        .map(|v| format_tick(*v, decimals).chars().count())
        .max()
        .unwrap_or(4);
    (widest as f64 * 0.62 * TICK_SIZE / 1.24 + 1.9 * AXIS_DESC_SIZE) as u32 + 8
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
