//! The figures of a sweep (`platen sweep … --plot DIR`): for each axis that takes more than
//! one value (the excitation scale, the hold-down pressure, each `--set` parameter), the
//! peak displacement, velocity, acceleration and actuator force of every case against that
//! axis, one line per combination of the other axes' values, with the table's limits drawn
//! as dashed lines. Failed cases are left out (their rows say why).

use plotters::style::RGBColor;

use platen_scenario::sweep::{Case, Outcome};
use platen_scenario::PlatenScenario;

use crate::figure::{Dash, Figure, Panel, Series, MODEL};
use crate::series::{patterned, series};
use crate::text::significant;

/// Colours of the lines (ColorBrewer Dark2: tell apart in print and by most colour-blind
/// readers).
const LINE_COLORS: [RGBColor; 7] = [
    RGBColor(27, 158, 119),
    RGBColor(217, 95, 2),
    RGBColor(117, 112, 179),
    RGBColor(231, 41, 138),
    RGBColor(102, 166, 30),
    RGBColor(230, 171, 2),
    RGBColor(166, 118, 29),
];

/// Most lines that get their own colour and legend entry; beyond, every line is grey and one
/// legend entry says what a line is.
const MAX_LABELLED: usize = LINE_COLORS.len();

/// A limit is drawn when the largest peak reaches this fraction of it (the axis then spans
/// at most 1/0.25 = 4 times the data); below, the panel's title gives the limit instead.
const LIMIT_DRAWN_FROM: f64 = 0.25;

/// Colour of the lines when there are too many to tell apart.
const MANY: RGBColor = RGBColor(120, 120, 120);

/// One axis of the grid: its column name, description with unit, how a value reads in a
/// legend, and each case's value.
struct Axis {
    name: String,
    label: String,
    value_text: fn(&str, f64) -> String,
    values: Vec<f64>,
}

/// A limit without trailing zeros: 0.75, 1.8, 41.19, 6800.
pub(crate) fn limit_text(x: f64) -> String {
    let s = significant(x, 4);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// The figures of a sweep: one per axis with more than one value (none for a single case).
pub fn figures(
    scenario: &PlatenScenario,
    set_names: &[String],
    cases: &[Case],
    outcomes: &[Outcome],
) -> Vec<Figure> {
    let mut axes = vec![
        Axis {
            name: "scale".into(),
            label: "excitation scale".into(),
            value_text: |_, v| format!("scale {v}"),
            values: cases.iter().map(|c| c.scale).collect(),
        },
        Axis {
            name: "hold_down_pressure_mpa".into(),
            label: "hold-down pressure (MPa)".into(),
            value_text: |_, v| format!("{v} MPa"),
            values: cases.iter().map(|c| c.pressure_mpa).collect(),
        },
    ];
    for (k, name) in set_names.iter().enumerate() {
        axes.push(Axis {
            name: name.clone(),
            label: name.clone(),
            value_text: |name, v| format!("{name} = {v}"),
            values: cases.iter().map(|c| c.sets[k]).collect(),
        });
    }
    let varying: Vec<usize> = (0..axes.len())
        .filter(|&a| distinct(&axes[a].values) > 1)
        .collect();
    varying
        .iter()
        .map(|&a| axis_figure(scenario, &axes, &varying, a, outcomes))
        .collect()
}

/// A peak plotted: name, display unit, display units per SI unit, the table's limit (SI),
/// and the signed peak of an outcome (SI).
type Quantity = (&'static str, &'static str, f64, f64, fn(&Outcome) -> f64);

/// How many different values.
fn distinct(values: &[f64]) -> usize {
    let mut v: Vec<f64> = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v.len()
}

/// The peaks against axis `a`, one line per combination of the other varying axes.
fn axis_figure(
    scenario: &PlatenScenario,
    axes: &[Axis],
    varying: &[usize],
    a: usize,
    outcomes: &[Outcome],
) -> Figure {
    let others: Vec<usize> = varying.iter().copied().filter(|&o| o != a).collect();
    let groups = case_groups(axes, &others, outcomes.len());
    let many = groups.len() > MAX_LABELLED;
    let styles = group_styles(axes, &others, &groups);
    let l = &scenario.rig.limits;
    let quantities: [Quantity; 4] = [
        ("displacement", "m", 1.0, l.stroke_m, |o| o.peaks.u_m.value),
        ("velocity", "m/s", 1.0, l.velocity_m_s, |o| {
            o.peaks.v_m_s.value
        }),
        ("acceleration", "m/s²", 1.0, l.acceleration_m_s2, |o| {
            o.peaks.a_m_s2.value
        }),
        ("actuator force", "kN", 1e-3, l.force_n, |o| {
            o.peaks.force_n.value
        }),
    ];
    let axis = &axes[a];
    let panels = quantities
        .iter()
        .map(|&q| {
            let (_, _, scale, _, peak) = q;
            let lines = peak_lines(axis, &groups, &styles, outcomes, |o| peak(o).abs() * scale);
            peak_panel(q, lines, axis)
        })
        .collect();
    let failed = outcomes.iter().filter(|o| o.error.is_some()).count();
    Figure {
        name: format!("peaks-against-{}", axis.name),
        title: format!("{}: peak responses against {}", scenario.name, axis.label),
        caption: format!(
            "The largest magnitude of displacement, velocity, acceleration and actuator force \
             of each case (markers) against {}, {}, with the table's limits (dashed) where \
             a peak reaches a quarter of one{}.",
            axis.label,
            if others.is_empty() {
                "the other axes held".to_owned()
            } else if many {
                format!(
                    "one grey line per combination of the other axes ({})",
                    groups.len()
                )
            } else {
                "one line per combination of the other axes".to_owned()
            },
            if failed > 0 {
                format!("; {failed} failed cases left out")
            } else {
                String::new()
            }
        ),
        panels,
        columns: 2,
        rows: Vec::new(),
        size: (1400, 1000),
    }
}

/// One line per group of cases in its style: `shown` of each of its cases (failed cases
/// left out) against the axis's value.
fn peak_lines(
    axis: &Axis,
    groups: &[(Vec<f64>, Vec<usize>)],
    styles: &[(String, RGBColor)],
    outcomes: &[Outcome],
    shown: impl Fn(&Outcome) -> f64,
) -> Vec<Series> {
    groups
        .iter()
        .zip(styles)
        .map(|((_, members), (label, color))| {
            let mut pts: Vec<(f64, f64)> = members
                .iter()
                .filter(|&&c| outcomes[c].error.is_none())
                .map(|&c| (axis.values[c], shown(&outcomes[c])))
                .collect();
            pts.sort_by(|p, q| p.0.total_cmp(&q.0));
            series(
                label.clone(),
                pts,
                crate::figure::Style::Line {
                    color: *color,
                    width: 2,
                    dash: Dash::Solid,
                },
            )
        })
        .collect()
}

/// The cases (of `cases` in all) grouped by their values on the axes `others`, in case
/// order: each group's values and members.
fn case_groups(axes: &[Axis], others: &[usize], cases: usize) -> Vec<(Vec<f64>, Vec<usize>)> {
    let mut groups: Vec<(Vec<f64>, Vec<usize>)> = Vec::new();
    for case in 0..cases {
        let key: Vec<f64> = others.iter().map(|&o| axes[o].values[case]).collect();
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(case),
            None => groups.push((key, vec![case])),
        }
    }
    groups
}

/// The legend label and colour of each group's line: its values on the other axes in its
/// own colour, or, with too many groups, grey lines under one legend entry.
fn group_styles(
    axes: &[Axis],
    others: &[usize],
    groups: &[(Vec<f64>, Vec<usize>)],
) -> Vec<(String, RGBColor)> {
    let many = groups.len() > MAX_LABELLED;
    (groups.iter().enumerate())
        .map(|(g, (key, _))| {
            if many {
                let label = if g == 0 {
                    format!(
                        "one line per combination of the other axes ({})",
                        groups.len()
                    )
                } else {
                    String::new()
                };
                (label, MANY)
            } else {
                let label = others
                    .iter()
                    .zip(key)
                    .map(|(&o, &v)| (axes[o].value_text)(&axes[o].name, v))
                    .collect::<Vec<_>>()
                    .join(", ");
                let label = if label.is_empty() {
                    "cases".to_owned()
                } else {
                    label
                };
                (label, LINE_COLORS[g % LINE_COLORS.len()])
            }
        })
        .collect()
}

/// The panel of one quantity against `axis`: the `lines` of its peaks, markers on every
/// case, and the table's limit when a peak reaches [`LIMIT_DRAWN_FROM`] of it.
fn peak_panel(q: Quantity, mut lines: Vec<Series>, axis: &Axis) -> Panel {
    let (quantity, unit, scale, limit_si, _) = q;
    let x_range = {
        let lo = axis.values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = axis
            .values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let pad = 0.04 * (hi - lo);
        (lo - pad, hi + pad)
    };
    // Markers on every case, so a line of two points still shows its cases.
    let markers: Vec<Series> = lines
        .iter()
        .map(|s| {
            let color = match s.style {
                crate::figure::Style::Line { color, .. } => color,
                _ => MANY,
            };
            crate::series::points("", s.points.clone(), color, 4)
        })
        .collect();
    let limit = limit_si * scale;
    let largest = lines
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(0.0, f64::max);
    let drawn = largest >= LIMIT_DRAWN_FROM * limit;
    // The same legend text in every panel (the limit's value is in the title), so
    // the figure's panels share one legend.
    lines.push(patterned(
        "table limit",
        vec![(x_range.0, limit), (x_range.1, limit)],
        MODEL,
        2,
        Dash::Dashed,
    ));
    if !drawn {
        if let Some(limit_line) = lines.last_mut() {
            limit_line.points.clear();
        }
    }
    lines.extend(markers);
    let top = if drawn { largest.max(limit) } else { largest };
    let title = if drawn {
        format!(
            "peak |{quantity}|, table limit {} {unit}",
            limit_text(limit)
        )
    } else {
        format!(
            "peak |{quantity}| (table limit {} {unit}, off the scale: {:.0} % of it at most)",
            limit_text(limit),
            100.0 * largest / limit
        )
    };
    Panel {
        x_range: Some(x_range),
        y_range: Some((0.0, 1.04 * top.max(f64::MIN_POSITIVE))),
        ..Panel::new(
            title,
            axis.label.clone(),
            format!("|peak {quantity}| ({unit})"),
            lines,
        )
    }
}
