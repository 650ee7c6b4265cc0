//! The figures of a three-component plan (`platen plan … --plot DIR` on a multi-axis
//! scenario): per axis the target against the achieved acceleration (the target's own
//! commands, iteration 0, and the drives' iteration), their 5 %-damped response spectra, the
//! convergence per axis with the cross-talk on the axes held still, and the limits closest
//! to failing.
//!
//! The target is drawn solid blue ([`RECORDED`]: the reference), iteration 0 dotted purple
//! ([`RESIDUAL`]), the drives' iteration dashed orange ([`SIMULATED`]).

use platen_plan::six_dof::{TableLimitUse, AXES};
use platen_plan::Response;
use platen_plan::{TablePlan, TablePlannedDrive};
use platen_signal::ResponseSpectrum;
use plotters::style::RGBColor;

use crate::figure::{Dash, Figure, Panel, Series, MODEL, RECORDED, RESIDUAL, SIMULATED};
use crate::plan_figures::{SPECTRUM_DAMPING, SPECTRUM_PERIODS_S};
use crate::series::{envelope, patterned, points, segments, Points};

/// Buckets of a time history's envelope.
const BUCKETS: usize = 1200;
/// Periods of the response spectra, evenly spaced in logarithm.
const SPECTRUM_COUNT: usize = 120;
/// The limits drawn in the margins figure: the closest to failing.
const MARGIN_BARS: usize = 8;
/// Colours of the axes in the convergence figure.
const AXIS_COLOURS: [RGBColor; 3] = [SIMULATED, RECORDED, RESIDUAL];

/// The figures of `p`: `table-plan-acceleration`, `table-plan-spectra`,
/// `table-plan-convergence` and `table-plan-margins`.
/// A plan whose target's own commands reach the end of an actuator has no drives: its
/// figure is `table-plan-margins` alone.
pub fn figures(p: &TablePlan) -> Vec<Figure> {
    let Some(d) = &p.drive else {
        return vec![margins(p, None)];
    };
    let mut out = vec![acceleration(p, d)];
    if let Some(f) = spectra(p, d) {
        out.push(f);
    }
    out.push(convergence(p, d));
    out.push(margins(p, Some(d)));
    out
}

fn history(t: &[f64], y: &[f64]) -> Points {
    let n = t.len().min(y.len());
    if n == 0 {
        return Vec::new();
    }
    envelope(&t[..n], &y[..n], (t[0], t[n - 1]), BUCKETS)
}

/// The title's subject: the target, on the scenario.
fn subject(p: &TablePlan) -> String {
    crate::plan_figures::subject(&p.target_origin, &p.scenario_name)
}

fn acceleration(p: &TablePlan, d: &TablePlannedDrive) -> Figure {
    let it = &d.iteration;
    let panels = AXES
        .iter()
        .enumerate()
        .map(|(i, axis)| {
            let target = &p.targets[i].a_m_s2;
            let held = p.targets[i].is_still();
            let mut series = Vec::new();
            if !held {
                series.push(patterned(
                    "target",
                    history(&p.t_s, target),
                    RECORDED,
                    1,
                    Dash::Solid,
                ));
            }
            series.push(patterned(
                "iteration 0",
                history(&p.t_s, &p.first_a_m_s2[i]),
                RESIDUAL,
                1,
                Dash::Dotted,
            ));
            series.push(patterned(
                format!("iteration {}", it.best),
                history(&p.t_s, it.achieved.a_m_s2(i)),
                SIMULATED,
                1,
                Dash::Dashed,
            ));
            let what = if held {
                "held at zero: the cross-talk"
            } else {
                "target and achieved"
            };
            Panel::new(
                format!("{axis}: {what}"),
                "t (s)",
                format!("a_{axis} (m/s²)"),
                series,
            )
        })
        .collect();
    Figure {
        name: "table-plan-acceleration".into(),
        title: format!("{}: acceleration per axis", subject(p)),
        caption: format!(
            "Per axis the target acceleration and the table's, for the target's own commands \
             (iteration 0) and for the drives (iteration {}); an axis held at zero shows its \
             cross-talk.",
            it.best
        ),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1100, 900),
    }
}

fn spectra(p: &TablePlan, d: &TablePlannedDrive) -> Option<Figure> {
    let dt = p.t_s.get(1).zip(p.t_s.first()).map(|(b, a)| b - a)?;
    let (lo, hi) = SPECTRUM_PERIODS_S;
    let periods = ResponseSpectrum::log_periods_s(lo, hi, SPECTRUM_COUNT).ok()?;
    let rs = ResponseSpectrum::new(&periods, SPECTRUM_DAMPING, 1.0 / dt).ok()?;
    let curve = |a: &[f64]| -> Points {
        periods
            .iter()
            .copied()
            .zip(rs.pseudo_acceleration_m_s2(a))
            .collect()
    };
    let it = &d.iteration;
    let panels = AXES
        .iter()
        .enumerate()
        .map(|(i, axis)| {
            let mut series = Vec::new();
            if !p.targets[i].is_still() {
                series.push(patterned(
                    "target",
                    curve(&p.targets[i].a_m_s2),
                    RECORDED,
                    2,
                    Dash::Solid,
                ));
            }
            series.push(patterned(
                "iteration 0",
                curve(&p.first_a_m_s2[i]),
                RESIDUAL,
                2,
                Dash::Dotted,
            ));
            series.push(patterned(
                format!("iteration {}", it.best),
                curve(it.achieved.a_m_s2(i)),
                SIMULATED,
                2,
                Dash::Dashed,
            ));
            let mut panel = Panel::new(
                format!("{axis}: pseudo-acceleration, 5 % damping"),
                "period (s)",
                "Sa (m/s²)",
                series,
            );
            panel.x_log = true;
            panel
        })
        .collect();
    Some(Figure {
        name: "table-plan-spectra".into(),
        title: format!("{}: response spectra per axis", subject(p)),
        caption: "5 %-damped pseudo-acceleration response spectra per axis of the target and \
                  of the achieved acceleration, iteration 0 and the drives'."
            .into(),
        panels,
        columns: 3,
        rows: Vec::new(),
        size: (1500, 550),
    })
}

/// `table-plan-convergence`: the acceleration NRMSE per axis and overall per iteration, and
/// the cross-talk of the axes held at zero.
fn convergence(p: &TablePlan, d: &TablePlannedDrive) -> Figure {
    let it = &d.iteration;
    let last = it.records.len().saturating_sub(1).max(1) as f64;
    let (nrmse, cross) = convergence_series(p, d);
    let mut panel = Panel::new(
        format!(
            "Acceleration NRMSE per axis (best: {}, stop: {})",
            it.best,
            it.stop.name()
        ),
        "iteration",
        "NRMSE (%, logarithmic)",
        nrmse,
    );
    panel.x_range = Some((-0.2, last + 0.2));
    panel.y_log = true;
    let mut panels = vec![panel];
    if !cross.is_empty() {
        let mut c = Panel::new(
            "Cross-talk: RMS acceleration of the axes held at zero",
            "iteration",
            "RMS a (m/s²)",
            cross,
        );
        c.x_range = Some((-0.2, last + 0.2));
        panels.push(c);
    }
    Figure {
        name: "table-plan-convergence".into(),
        title: format!("{}: drive iteration", subject(p)),
        caption: "The acceleration NRMSE per axis and overall (all axes' errors over all axes' \
                  targets) per iteration, in percent on a logarithmic axis; the RMS \
                  acceleration of the \
                  axes held at zero (their cross-talk)."
            .into(),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1000, 800),
    }
}

/// The series of the convergence figure: the acceleration NRMSE overall and of each axis
/// given, in percent (for a logarithmic axis), and the RMS acceleration of each axis held at
/// zero (its cross-talk), per iteration.
fn convergence_series(p: &TablePlan, d: &TablePlannedDrive) -> (Vec<Series>, Vec<Series>) {
    let it = &d.iteration;
    // In percent on a logarithmic axis (`y_log`), labelled in percent.
    let log = |x: f64| 100.0 * x;
    let mut nrmse = Vec::new();
    let overall: Points = it
        .records
        .iter()
        .map(|r| (r.iteration as f64, log(r.acceleration_nrmse)))
        .collect();
    nrmse.push(patterned(
        "overall",
        overall.clone(),
        MODEL,
        2,
        Dash::Dashed,
    ));
    nrmse.push(points("", overall, MODEL, 4));
    let mut cross = Vec::new();
    for (i, axis) in AXES.iter().enumerate() {
        let colour = AXIS_COLOURS[i];
        if p.targets[i].is_still() {
            let pts: Points = it
                .records
                .iter()
                .map(|r| (r.iteration as f64, r.axes[axis].rms_acceleration_error_m_s2))
                .collect();
            cross.push(patterned(*axis, pts.clone(), colour, 2, Dash::Solid));
            cross.push(points("", pts, colour, 4));
        } else {
            let pts: Points = it
                .records
                .iter()
                .filter_map(|r| {
                    r.axes[axis]
                        .acceleration_nrmse
                        .map(|e| (r.iteration as f64, log(e)))
                })
                .collect();
            nrmse.push(patterned(*axis, pts.clone(), colour, 2, Dash::Solid));
            nrmse.push(points("", pts, colour, 4));
        }
    }
    (nrmse, cross)
}

/// Bars of peak/allowed in percent, one per limit at x = 1, 2, … (offset by `dx`).
fn bars(uses: &[&TableLimitUse], dx: f64) -> Points {
    uses.iter()
        .enumerate()
        .flat_map(|(i, u)| {
            let x = (i + 1) as f64 + dx;
            [(x, 0.0), (x, 100.0 * u.ratio.min(10.0))]
        })
        .collect()
}

fn margins(p: &TablePlan, d: Option<&TablePlannedDrive>) -> Figure {
    let mut closest: Vec<&TableLimitUse> = p.feasibility.uses.iter().collect();
    closest.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    closest.truncate(MARGIN_BARS);
    let drive: Vec<&TableLimitUse> = closest
        .iter()
        .filter_map(|u| d?.uses.iter().find(|v| v.limit == u.limit))
        .collect();
    let mut zero = segments(bars(&closest, -0.12), RESIDUAL);
    zero.label = "iteration 0".into();
    let mut after = segments(bars(&drive, 0.12), SIMULATED);
    after.label = match d {
        Some(d) => format!("drives (iteration {})", d.iteration.best),
        None => "drives (not iterated)".into(),
    };
    let n = closest.len().max(1) as f64;
    let mut series = vec![
        zero,
        after,
        patterned(
            "limit",
            vec![(0.5, 100.0), (n + 0.5, 100.0)],
            MODEL,
            1,
            Dash::Dashed,
        ),
    ];
    for s in &mut series {
        if let crate::figure::Style::Segments { width, .. } = &mut s.style {
            *width = 12;
        }
    }
    let mut panel = Panel::new(
        format!(
            "Peak over allowed, the {} limits closest to failing",
            closest.len()
        ),
        "limit",
        "use (%, bars cut at 1000)",
        series,
    );
    panel.x_categories = closest.iter().map(|u| u.limit.to_string()).collect();
    panel.x_range = Some((0.5, n + 0.5));
    let top = closest
        .iter()
        .chain(&drive)
        .map(|u| 100.0 * u.ratio.min(10.0))
        .fold(110.0_f64, f64::max);
    panel.y_range = Some((0.0, 1.05 * top));
    Figure {
        name: "table-plan-margins".into(),
        title: format!("{}: the limits' margins", subject(p)),
        caption: "The limits closest to failing (per axis, per actuator, the overturning \
                  moment): each one's peak over its allowed value, for the target's own commands \
                  (iteration 0) and for the drives; the dashed line is the limit."
            .into(),
        panels: vec![panel],
        columns: 1,
        rows: Vec::new(),
        size: (1400, 650),
    }
}
