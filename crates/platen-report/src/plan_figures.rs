//! The figures of a test plan (`platen plan … --plot DIR`, `--report FILE.html`): the target
//! against the achieved acceleration over time (the target's own command, iteration 0, and
//! the drive's iteration), their 5 %-damped response spectra, the iteration's convergence,
//! and the limits' margins (peak over allowed) of the target's own command and of the drive.
//!
//! The target is drawn solid blue ([`RECORDED`]: the reference), iteration 0 dotted purple
//! ([`RESIDUAL`]), the drive's iteration dashed orange ([`SIMULATED`]).

use std::fmt::Write as _;

use platen_plan::{Achieved, Iteration, LimitUse, Plan};
use platen_signal::ResponseSpectrum;

use crate::figure::{Dash, Figure, Panel, MODEL, RECORDED, RESIDUAL, SIMULATED};
use crate::html;
use crate::series::{envelope, patterned, points, segments, Points};
use crate::text::significant;

/// Buckets of a time history's envelope.
const BUCKETS: usize = 1200;
/// Damping ratio of the response spectra.
pub const SPECTRUM_DAMPING: f64 = 0.05;
/// Shortest and longest period of the response spectra, s.
pub const SPECTRUM_PERIODS_S: (f64, f64) = (0.02, 5.0);
/// Periods of the response spectra, evenly spaced in logarithm.
const SPECTRUM_COUNT: usize = 120;

/// The figures of `p`: `plan-acceleration`, `plan-spectra`, `plan-convergence` (when the
/// drive was iterated) and `plan-margins`.
pub fn figures(p: &Plan) -> Vec<Figure> {
    let mut out = vec![acceleration(p)];
    if let Some(f) = spectra(p) {
        out.push(f);
    }
    if let Some(f) = convergence(p) {
        out.push(f);
    }
    out.push(margins(p));
    out
}

/// The drive's iteration and its achieved acceleration, if the drive was iterated.
/// A plan figure's subject: the target (its file name), on the scenario (its name), since
/// one scenario plans many targets.
pub(crate) fn subject(target_origin: &std::path::Path, scenario_name: &str) -> String {
    format!(
        "{} on {}",
        target_origin.file_name().map_or_else(
            || target_origin.display().to_string(),
            |n| n.to_string_lossy().into_owned()
        ),
        scenario_name
    )
}

fn best(p: &Plan) -> Option<(usize, &[f64])> {
    p.iteration()
        .map(|it| (it.best, it.achieved.a_m_s2.as_slice()))
}

/// `y` at the times `t` over `range` (the whole record when `None`), enveloped for drawing.
fn history(t: &[f64], y: &[f64], range: Option<(f64, f64)>) -> Points {
    let n = t.len().min(y.len());
    if n == 0 {
        return Vec::new();
    }
    envelope(&t[..n], &y[..n], range.unwrap_or((t[0], t[n - 1])), BUCKETS)
}

/// `plan-acceleration`: the target against the achieved acceleration of iteration 0 and of
/// the drive, each over the whole record, then the interval around the target's largest |a|
/// close up.
fn acceleration(p: &Plan) -> Figure {
    let m = &p.motion;
    let zoom = crate::run_figures::zoom_window(&m.t_s, &m.a_m_s2);
    let drive = best(p);
    let mut panels = whole_accelerations(p, zoom, drive);
    if let Some(range) = zoom {
        panels.push(close_up(p, range, drive));
    }
    let rows = panels.len() as u32;
    Figure {
        name: "plan-acceleration".into(),
        title: format!(
            "{}: target and achieved table acceleration",
            subject(&p.target_origin, &p.scenario_name)
        ),
        caption: "The target acceleration against the simulated table's, for the target's own \
                  command (iteration 0) and for the drive; the shaded interval close up below."
            .into(),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1200, 120 + 330 * rows),
    }
}

/// The target against iteration 0's achieved acceleration over the whole record, then against
/// the drive's (iteration `k`, achieved `a`) when there is one, `zoom` shaded.
fn whole_accelerations(
    p: &Plan,
    zoom: Option<(f64, f64)>,
    drive: Option<(usize, &[f64])>,
) -> Vec<Panel> {
    let m = &p.motion;
    let target = history(&m.t_s, &m.a_m_s2, None);
    let zero = history(&m.t_s, &p.feasibility.achieved.a_m_s2, None);
    let mut whole = Panel::new(
        "Target and achieved, iteration 0 (the target's own command)",
        "t (s)",
        "a (m/s²)",
        vec![
            patterned("target", target.clone(), RECORDED, 1, Dash::Solid),
            patterned("iteration 0", zero, RESIDUAL, 1, Dash::Dotted),
        ],
    );
    whole.shade_x = zoom;
    let mut panels = vec![whole];
    if let Some((k, a)) = drive {
        let mut whole = Panel::new(
            format!("Target and achieved, iteration {k} (the drive)"),
            "t (s)",
            "a (m/s²)",
            vec![
                patterned("target", target, RECORDED, 1, Dash::Solid),
                patterned(
                    format!("iteration {k}"),
                    history(&m.t_s, a, None),
                    SIMULATED,
                    1,
                    Dash::Dashed,
                ),
            ],
        );
        whole.shade_x = zoom;
        panels.push(whole);
    }
    panels
}

/// The shaded interval `range` close up (around the target's largest |a|), every trace at its
/// own samples' resolution: the target, iteration 0 and the drive's (iteration `k`, achieved
/// `a`) when there is one.
fn close_up(p: &Plan, range: (f64, f64), drive: Option<(usize, &[f64])>) -> Panel {
    let m = &p.motion;
    let close = |y: &[f64]| history(&m.t_s, y, Some(range));
    let mut series = vec![
        patterned("target", close(&m.a_m_s2), RECORDED, 2, Dash::Solid),
        patterned(
            "iteration 0",
            close(&p.feasibility.achieved.a_m_s2),
            RESIDUAL,
            1,
            Dash::Dotted,
        ),
    ];
    if let Some((k, a)) = drive {
        series.push(patterned(
            format!("iteration {k}"),
            close(a),
            SIMULATED,
            2,
            Dash::Dashed,
        ));
    }
    let mut zoomed = Panel::new(
        format!(
            "Close up: {:.2}–{:.2} s, around the target's largest |a|",
            range.0, range.1
        ),
        "t (s)",
        "a (m/s²)",
        series,
    );
    zoomed.x_range = Some(range);
    zoomed
}

fn spectra(p: &Plan) -> Option<Figure> {
    let m = &p.motion;
    let rate = 1.0 / m.interval_s();
    let (lo, hi) = SPECTRUM_PERIODS_S;
    let periods = ResponseSpectrum::log_periods_s(lo, hi, SPECTRUM_COUNT).ok()?;
    let rs = ResponseSpectrum::new(&periods, SPECTRUM_DAMPING, rate).ok()?;
    let curve = |a: &[f64]| -> Points {
        periods
            .iter()
            .copied()
            .zip(rs.pseudo_acceleration_m_s2(a))
            .collect()
    };
    let mut series = vec![
        patterned("target", curve(&m.a_m_s2), RECORDED, 2, Dash::Solid),
        patterned(
            "iteration 0",
            curve(&p.feasibility.achieved.a_m_s2),
            RESIDUAL,
            2,
            Dash::Dotted,
        ),
    ];
    if let Some((k, a)) = best(p) {
        series.push(patterned(
            format!("iteration {k}"),
            curve(a),
            SIMULATED,
            2,
            Dash::Dashed,
        ));
    }
    let mut panel = Panel::new(
        "Pseudo-acceleration response spectra, 5 % damping",
        "period (s)",
        "Sa (m/s²)",
        series,
    );
    panel.x_log = true;
    Some(Figure {
        name: "plan-spectra".into(),
        title: format!(
            "{}: response spectra",
            subject(&p.target_origin, &p.scenario_name)
        ),
        caption: "5 %-damped pseudo-acceleration response spectra of the target and of the \
                  achieved acceleration, iteration 0 and the drive's."
            .into(),
        panels: vec![panel],
        columns: 1,
        rows: Vec::new(),
        size: (1000, 650),
    })
}

fn convergence(p: &Plan) -> Option<Figure> {
    let it = p.iteration()?;
    let pick = |f: fn(&platen_plan::IterationRecord) -> f64| -> Points {
        it.records
            .iter()
            .map(|r| (r.iteration as f64, 100.0 * f(r)))
            .collect()
    };
    let mut series = Vec::new();
    for (label, pts, color, dash) in [
        (
            "acceleration NRMSE",
            pick(|r| r.acceleration_nrmse),
            SIMULATED,
            Dash::Solid,
        ),
        (
            "displacement NRMSE",
            pick(|r| r.displacement_nrmse),
            RECORDED,
            Dash::Dashed,
        ),
        (
            "spectrum error (5 %)",
            pick(|r| r.spectrum_error),
            RESIDUAL,
            Dash::Dotted,
        ),
    ] {
        series.push(patterned(label, pts.clone(), color, 2, dash));
        series.push(points("", pts, color, 4));
    }
    let last = it.records.len().saturating_sub(1).max(1) as f64;
    let mut panel = Panel::new(
        format!(
            "Errors per iteration (best: {}, stop: {})",
            it.best,
            it.stop.name()
        ),
        "iteration",
        "error (%, logarithmic)",
        series,
    );
    panel.x_range = Some((-0.2, last + 0.2));
    panel.y_log = true;
    Some(Figure {
        name: "plan-convergence".into(),
        title: format!(
            "{}: drive iteration",
            subject(&p.target_origin, &p.scenario_name)
        ),
        caption: "The acceleration and displacement NRMSE and the largest response-spectrum \
                  error per iteration, in percent on a logarithmic axis."
            .into(),
        panels: vec![panel],
        columns: 1,
        rows: Vec::new(),
        size: (1000, 600),
    })
}

/// Bars of peak/allowed in percent, one per limit at x = 1, 2, … (offset by `dx`).
fn bars(uses: &[LimitUse], dx: f64) -> Points {
    uses.iter()
        .enumerate()
        .flat_map(|(i, u)| {
            let x = (i + 1) as f64 + dx;
            [(x, 0.0), (x, 100.0 * u.ratio)]
        })
        .collect()
}

fn margins(p: &Plan) -> Figure {
    let uses = &p.feasibility.uses;
    let mut zero = segments(bars(uses, -0.12), RESIDUAL);
    zero.label = "iteration 0".into();
    let mut series = vec![zero];
    if let Some(d) = &p.drive {
        let mut drive = segments(bars(&d.uses, 0.12), SIMULATED);
        drive.label = format!("drive (iteration {})", d.iteration.best);
        series.push(drive);
    }
    let n = uses.len().max(1) as f64;
    series.push(patterned(
        "limit",
        vec![(0.5, 100.0), (n + 0.5, 100.0)],
        MODEL,
        1,
        Dash::Dashed,
    ));
    for s in &mut series {
        if let crate::figure::Style::Segments { width, .. } = &mut s.style {
            *width = 14;
        }
    }
    let mut panel = Panel::new("Peak over allowed, per limit", "limit", "use (%)", series);
    panel.x_categories = uses.iter().map(|u| u.limit.to_string()).collect();
    panel.x_range = Some((0.5, n + 0.5));
    let top = uses
        .iter()
        .chain(p.drive.iter().flat_map(|d| d.uses.iter()))
        .map(|u| 100.0 * u.ratio)
        .fold(110.0_f64, f64::max);
    panel.y_range = Some((0.0, 1.05 * top));
    Figure {
        name: "plan-margins".into(),
        title: format!(
            "{}: the limits' margins",
            subject(&p.target_origin, &p.scenario_name)
        ),
        caption: "Each limit's peak over its allowed value, for the target's own command \
                  (iteration 0) and for the drive; the dashed line is the limit."
            .into(),
        panels: vec![panel],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 600),
    }
}

/// The rows of the margins table: limit, peak and allowed, use of iteration 0 and of the
/// drive.
fn margin_rows(p: &Plan) -> Vec<Vec<String>> {
    p.feasibility
        .uses
        .iter()
        .map(|u| {
            let drive = p
                .drive
                .as_ref()
                .and_then(|d| d.uses.iter().find(|v| v.limit == u.limit))
                .map_or("—".to_owned(), |v| format!("{:.1} %", 100.0 * v.ratio));
            vec![
                u.limit.to_owned(),
                significant(u.peak, 4),
                significant(u.allowed, 4),
                format!("{:.1} %", 100.0 * u.ratio),
                format!("{:.3}", u.t_s),
                drive,
            ]
        })
        .collect()
}

/// The `platen plan --report` page: what was planned, the margins, the iterations, every
/// figure and the `--json` summary; `rendered[i]` is the SVG of `figures[i]`.
pub fn page(
    p: &Plan,
    summary: serde_json::Value,
    figures: &[Figure],
    rendered: &[(String, String)],
) -> String {
    let m = &p.motion;
    let mut items = vec![
        ("Scenario".to_owned(), p.scenario_path.display().to_string()),
        ("Target".to_owned(), p.target_origin.display().to_string()),
        (
            "Samples".to_owned(),
            format!(
                "{} at {} Hz over {:.3} s",
                p.target_samples,
                p.target_rate_hz,
                m.t_s[m.len() - 1] - m.t_s[0]
            ),
        ),
        (
            "Feasible".to_owned(),
            if p.feasibility.feasible { "yes" } else { "no" }.to_owned(),
        ),
    ];
    if let Some(s) = &p.feasibility.max_scale {
        items.push((
            "Largest scale that fits".to_owned(),
            format!("{:.4}", s.scale),
        ));
    }
    let mut sections = vec![
        html::heading("Margins"),
        html::table(
            &[
                "limit",
                "peak (iteration 0)",
                "allowed",
                "use (iteration 0)",
                "at (s)",
                "use (drive)",
            ],
            &margin_rows(p),
            true,
        ),
    ];
    if let Some(it) = p.iteration() {
        sections.extend(iteration_sections(it));
    }
    for w in &p.warnings {
        sections.push(html::paragraph(&format!("Warning: {w}"), Some("note")));
    }
    html::page(&html::Page {
        title: format!("platen plan: {}", p.scenario_name),
        heading: format!("Plan of {}", p.scenario_name),
        items,
        sections,
        figures,
        rendered,
        summary,
    })
}

/// The iterations' section of the page: each iteration's errors and why they stopped.
fn iteration_sections(it: &Iteration<Achieved>) -> Vec<String> {
    let rows: Vec<Vec<String>> = it
        .records
        .iter()
        .map(|r| {
            vec![
                r.iteration.to_string(),
                format!("{:.2} %", 100.0 * r.acceleration_nrmse),
                format!("{:.2} %", 100.0 * r.displacement_nrmse),
                format!(
                    "{:.2} % at {:.3} s",
                    100.0 * r.spectrum_error,
                    r.spectrum_error_period_s
                ),
            ]
        })
        .collect();
    let mut stop = format!(
        "Stop: {}; the drive is iteration {}.",
        it.stop.name(),
        it.best
    );
    if let platen_plan::Stop::Stalled { reason } = &it.stop {
        let _ = write!(stop, " Stalled: {reason}.");
    }
    vec![
        html::heading("Iterations"),
        html::table(
            &[
                "k",
                "acceleration NRMSE",
                "displacement NRMSE",
                "spectrum error (5 %)",
            ],
            &rows,
            false,
        ),
        html::paragraph(&stop, None),
    ]
}
