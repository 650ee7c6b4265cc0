//! The figures of a table system's linearised loop (`platen model --system … --plot DIR`):
//! Bode plots of the closed-loop response command → displacement and of the loop gain `L`
//! (the loop broken at the drive), on a logarithmic frequency axis from
//! [`F_MIN_HZ`] to the controller's Nyquist frequency or [`F_MAX_HZ`], whichever is lower.
//!
//! Each figure draws one curve per [`LoopCurve`] (the table bare and with a specimen as a
//! rigid payload, say); the first is the loop the titles' numbers (peak, bandwidth, margins)
//! describe. Magnitudes are in dB (`20·log10|H|`), phases in degrees, unwrapped along the
//! frequency axis from their principal value at [`F_MIN_HZ`].

use plotters::style::RGBColor;

use platen_scenario::describe::SystemAnalysis;
use platen_system::{Linearisation, Margins, TableSystem};

use crate::figure::{Dash, Figure, Panel, Series, MODEL, RESIDUAL, SIMULATED};
use crate::series::{patterned, points, Points};
use crate::text::significant;

/// Lowest frequency drawn, Hz.
pub const F_MIN_HZ: f64 = 0.1;
/// Highest frequency drawn, Hz (below the controller's Nyquist frequency if that is lower).
pub const F_MAX_HZ: f64 = 200.0;
/// Frequencies of each curve, evenly spaced on the logarithmic axis.
const POINTS: usize = 801;

/// One configuration of the loop to draw: its legend text and its linearisation.
#[derive(Debug, Clone)]
pub struct LoopCurve {
    /// Legend text (`"bare table"`; empty: no legend entry).
    pub label: String,
    /// The loop about its operating point.
    pub linearisation: Linearisation,
}

/// The frequency axis of `system`'s figures, Hz: from [`F_MIN_HZ`] to the lower of
/// [`F_MAX_HZ`] and the controller's Nyquist frequency.
pub fn frequency_range_hz(system: &TableSystem) -> (f64, f64) {
    let nyquist = 0.5 * system.controller().sample_rate_hz;
    (F_MIN_HZ, F_MAX_HZ.min(nyquist).max(2.0 * F_MIN_HZ))
}

/// How flat the closed loop's gain command → displacement is (now computed by
/// [`TableSystem::passband`]; re-exported here for the figures' callers).
pub use platen_system::Passband;

/// The [`Passband`] of the closed loop of `lin`: [`TableSystem::passband`].
pub fn passband(system: &TableSystem, lin: &Linearisation) -> Passband {
    system.passband(lin)
}

/// `POINTS` frequencies evenly spaced on a logarithmic axis over `range`, Hz.
fn frequencies(range: (f64, f64)) -> Vec<f64> {
    let ratio = range.1 / range.0;
    (0..POINTS)
        .map(|i| range.0 * ratio.powf(i as f64 / (POINTS - 1) as f64))
        .collect()
}

/// A response over the frequencies: magnitude in dB and phase in degrees, unwrapped.
struct Bode {
    magnitude_db: Points,
    phase_deg: Points,
}

impl Bode {
    /// The Bode curves of the responses `h` at the frequencies `f`.
    fn from_responses(f: &[f64], h: impl Iterator<Item = num_complex::Complex64>) -> Self {
        let values: Vec<num_complex::Complex64> = h.collect();
        let mut i = 0;
        Self::new(f, |_| {
            let x = values[i];
            i += 1;
            (x.norm(), x.arg())
        })
    }

    fn new(f: &[f64], mut response: impl FnMut(f64) -> (f64, f64)) -> Self {
        let mut magnitude_db = Vec::with_capacity(f.len());
        let mut phase_deg = Vec::with_capacity(f.len());
        let mut last: Option<f64> = None;
        for &fi in f {
            let (norm, arg) = response(fi);
            let mut deg = arg.to_degrees();
            if let Some(prev) = last {
                deg += 360.0 * ((prev - deg) / 360.0).round();
            }
            last = Some(deg);
            magnitude_db.push((fi, 20.0 * norm.log10()));
            phase_deg.push((fi, deg));
        }
        Self {
            magnitude_db,
            phase_deg,
        }
    }
}

/// The value of `points` (sorted by x) at `x`, linear in `log10 x` between neighbours.
fn at(points: &Points, x: f64) -> Option<f64> {
    let i = points.iter().position(|p| p.0 >= x)?;
    if i == 0 {
        return Some(points[0].1);
    }
    let (a, b) = (points[i - 1], points[i]);
    let w = (x.log10() - a.0.log10()) / (b.0.log10() - a.0.log10());
    Some(a.1 + w * (b.1 - a.1))
}

/// The lowest and highest values of the points.
fn extent<'a>(points: impl IntoIterator<Item = &'a Points>) -> (f64, f64) {
    points
        .into_iter()
        .flatten()
        .filter(|p| p.1.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        })
}

/// The colour and stroke of curve `i` (the first black and solid).
fn curve_style(i: usize) -> (RGBColor, Dash) {
    match i {
        0 => (MODEL, Dash::Solid),
        1 => (RESIDUAL, Dash::Dashed),
        _ => (SIMULATED, Dash::DashDot),
    }
}

/// Vertical dotted lines at each curve's oil-column frequency (mid-stroke), over `y`.
fn oil_column_lines(
    system: &TableSystem,
    curves: &[LoopCurve],
    range: (f64, f64),
    y: (f64, f64),
) -> Vec<Series> {
    curves
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let f = system.oil_column_frequency_hz(c.linearisation.mechanics.mass_kg, 0.0);
            if !(f >= range.0 && f <= range.1 && y.0.is_finite() && y.1.is_finite()) {
                return None;
            }
            // The curve's label up to its own parenthesis: "with the specimen".
            let short = c.label.split(" (").next().unwrap_or_default();
            let whose = if curves.len() > 1 && !short.is_empty() {
                format!(" ({short})")
            } else {
                String::new()
            };
            Some(patterned(
                format!("oil column {} Hz{whose}", significant(f, 4)),
                vec![(f, y.0), (f, y.1)],
                curve_style(i).0,
                2,
                Dash::Dotted,
            ))
        })
        .collect()
}

/// A horizontal reference line at `level` across `range`, dashed thin black.
fn reference(label: impl Into<String>, level: f64, range: (f64, f64)) -> Series {
    patterned(
        label,
        vec![(range.0, level), (range.1, level)],
        MODEL,
        1,
        Dash::Dashed,
    )
}

/// A panel over the frequency range on a logarithmic axis.
fn bode_panel(title: String, y_label: &str, range: (f64, f64), series: Vec<Series>) -> Panel {
    Panel {
        x_range: Some(range),
        x_log: true,
        ..Panel::new(title, "frequency f (Hz)", y_label, series)
    }
}

/// A gain in dB with its sign (`+2.3 dB`, `−4.2 dB`).
fn db(gain: f64) -> String {
    format!("{:+.1} dB", 20.0 * gain.log10()).replace('-', "−")
}

/// `"4.2 Hz"`, or `"none"`.
fn hz(f: Option<f64>) -> String {
    f.map_or("none".into(), |f| format!("{} Hz", significant(f, 3)))
}

/// The Bode figures of `system`'s loop for each of `curves` (the first described in the
/// titles, with its `margins`): `bode-closed-loop` (command → displacement, magnitude and
/// phase) and `bode-loop-gain` (`L`, with its crossovers and margins). `name` heads the
/// titles.
pub fn figures(
    name: &str,
    system: &TableSystem,
    curves: &[LoopCurve],
    margins: &Margins,
) -> Vec<Figure> {
    if curves.is_empty() {
        return Vec::new();
    }
    let range = frequency_range_hz(system);
    let f = frequencies(range);
    let closed: Vec<Bode> = curves
        .iter()
        .map(|c| {
            Bode::new(&f, |fi| {
                let h = system.closed_loop_response(&c.linearisation, fi);
                (h.norm(), h.arg())
            })
        })
        .collect();
    let open: Vec<Bode> = curves
        .iter()
        .map(|c| {
            Bode::new(&f, |fi| {
                let l = system.loop_gain(&c.linearisation, fi);
                (l.norm(), l.arg())
            })
        })
        .collect();
    vec![
        closed_loop_figure(name, system, curves, margins, range, &closed),
        loop_gain_figure(name, system, curves, margins, range, &open),
    ]
}

/// The Bode figures of a table system's [`SystemAnalysis`] (`platen model --plot`): the loop
/// with the specimen as a rigid payload first (the one the titles' numbers describe), then
/// the bare table; `name` heads the titles.
pub fn analysis_figures(name: &str, analysis: &SystemAnalysis) -> Vec<Figure> {
    let mut curves = Vec::new();
    if let (Some(lin), Some(kg)) = (analysis.loaded, analysis.specimen_mass_kg) {
        curves.push(LoopCurve {
            label: format!(
                "with the specimen (rigid, {} t)",
                crate::model_text::significant(kg / 1e3, crate::model_text::SIGNIFICANT_DIGITS)
            ),
            linearisation: lin,
        });
    }
    curves.push(LoopCurve {
        label: if curves.is_empty() {
            String::new()
        } else {
            "bare table".into()
        },
        linearisation: analysis.bare,
    });
    figures(name, &analysis.system, &curves, &analysis.margins)
}

/// The curves of one quantity (magnitude or phase) of every configuration.
fn curve_series(curves: &[LoopCurve], quantity: impl Fn(usize) -> Points) -> Vec<Series> {
    curves
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let (color, dash) = curve_style(i);
            patterned(c.label.clone(), quantity(i), color, 2, dash)
        })
        .collect()
}

fn closed_loop_figure(
    name: &str,
    system: &TableSystem,
    curves: &[LoopCurve],
    margins: &Margins,
    range: (f64, f64),
    bode: &[Bode],
) -> Figure {
    let band = passband(system, &curves[0].linearisation);
    let mag_extent = extent(bode.iter().map(|b| &b.magnitude_db));
    let phase_extent = extent(bode.iter().map(|b| &b.phase_deg));
    let mut magnitude = curve_series(curves, |i| bode[i].magnitude_db.clone());
    magnitude.push(reference("0 dB (U = R)", 0.0, range));
    magnitude.extend(oil_column_lines(
        system,
        curves,
        range,
        (mag_extent.0.min(0.0), mag_extent.1.max(0.0)),
    ));
    let mut phase = curve_series(curves, |i| bode[i].phase_deg.clone());
    phase.extend(oil_column_lines(system, curves, range, phase_extent));
    let phase_1hz = at(&bode[0].phase_deg, 1.0);
    Figure {
        name: "bode-closed-loop".into(),
        title: format!("{name}: closed loop, command → displacement (linearised)"),
        caption: format!(
            "The small-signal response U/R of the table's displacement to the displacement \
             command, magnitude (dB) and phase, from {} Hz to {} Hz (the controller samples at \
             {} Hz), with the oil-column frequency at mid-stroke (dotted). The controller's \
             hold and the valves' delay are in the phase; friction is linearised by its secant \
             damping, so stick-slip is not.",
            significant(range.0, 3),
            significant(range.1, 3),
            significant(system.controller().sample_rate_hz, 4)
        ),
        panels: vec![
            bode_panel(
                format!(
                    "magnitude |U/R|: peak {} ({}) at {}, lowest {} ({}) at {}, \
                     −3 dB bandwidth {}",
                    significant(margins.peak_gain, 3),
                    db(margins.peak_gain),
                    hz(Some(margins.peak_gain_hz)),
                    significant(band.min_gain, 3),
                    db(band.min_gain),
                    hz(Some(band.min_gain_hz)),
                    hz(band.bandwidth_hz)
                ),
                "|U/R| (dB)",
                range,
                magnitude,
            ),
            bode_panel(
                format!(
                    "phase of U/R{}",
                    phase_1hz.map_or(String::new(), |p| format!(": {p:.1}° at 1 Hz")
                        .replace('-', "−"))
                ),
                "phase of U/R (°)",
                range,
                phase,
            ),
        ],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 900),
    }
}

fn loop_gain_figure(
    name: &str,
    system: &TableSystem,
    curves: &[LoopCurve],
    margins: &Margins,
    range: (f64, f64),
    bode: &[Bode],
) -> Figure {
    let magnitude = loop_magnitude(system, curves, margins, range, bode);
    let phase = loop_phase(system, curves, margins, range, bode);
    let stability = if margins.stable { "stable" } else { "UNSTABLE" };
    Figure {
        name: "bode-loop-gain".into(),
        title: format!("{name}: loop gain L, broken at the drive ({stability})"),
        caption: format!(
            "The loop gain L of the linearised loop broken at the drive (the controller's \
             error and feedback paths through the hold, the valves, the chambers and the \
             platen), magnitude (dB) and phase, from {} Hz to {} Hz, with the oil-column \
             frequency at mid-stroke (dotted), the gain crossover (|L| = 1) and the phase \
             crossover (phase of L at −180°) of the first curve. The closed loop is {stability} by the \
             Nyquist criterion.",
            significant(range.0, 3),
            significant(range.1, 3)
        ),
        panels: vec![
            bode_panel(
                format!(
                    "magnitude |L|: gain crossover {}, phase margin {}",
                    hz(margins.gain_crossover_hz),
                    margins
                        .phase_margin_deg
                        .map_or("none".into(), |p| format!("{p:.1}°").replace('-', "−"))
                ),
                "|L| (dB)",
                range,
                magnitude,
            ),
            bode_panel(
                format!(
                    "phase of L: phase crossover {}, gain margin {}",
                    hz(margins.phase_crossover_hz),
                    margins
                        .gain_margin_db
                        .map_or("none".into(), |g| format!("{g:.1} dB").replace('-', "−"))
                ),
                "phase of L (°)",
                range,
                phase,
            ),
        ],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 900),
    }
}

/// The loop gain's magnitude: the curves, 0 dB, the oil-column frequencies and the gain
/// crossover.
fn loop_magnitude(
    system: &TableSystem,
    curves: &[LoopCurve],
    margins: &Margins,
    range: (f64, f64),
    bode: &[Bode],
) -> Vec<Series> {
    let mag_extent = extent(bode.iter().map(|b| &b.magnitude_db));
    let mut magnitude = curve_series(curves, |i| bode[i].magnitude_db.clone());
    magnitude.push(reference("0 dB (|L| = 1)", 0.0, range));
    magnitude.extend(oil_column_lines(
        system,
        curves,
        range,
        (mag_extent.0.min(0.0), mag_extent.1.max(0.0)),
    ));
    let in_range = |f: &f64| *f >= range.0 && *f <= range.1;
    if let Some(fc) = margins.gain_crossover_hz.filter(in_range) {
        magnitude.push(points("gain crossover", vec![(fc, 0.0)], SIMULATED, 6));
    }
    magnitude
}

/// The loop gain's phase: the curves, −180° and its odd multiples the phase reaches, the
/// oil-column frequencies and the phase crossover.
fn loop_phase(
    system: &TableSystem,
    curves: &[LoopCurve],
    margins: &Margins,
    range: (f64, f64),
    bode: &[Bode],
) -> Vec<Series> {
    let first = &bode[0];
    let phase_extent = extent(bode.iter().map(|b| &b.phase_deg));
    let in_range = |f: &f64| *f >= range.0 && *f <= range.1;
    let mut phase = curve_series(curves, |i| bode[i].phase_deg.clone());
    // −180° and its odd multiples that the phase reaches (at most 20).
    let levels: Vec<f64> = (0..20)
        .map(|k| -180.0 * f64::from(2 * k + 1))
        .enumerate()
        .take_while(|&(k, level)| k == 0 || level >= phase_extent.0)
        .map(|(_, level)| level)
        .collect();
    for (k, &level) in levels.iter().enumerate() {
        let label = match (k, levels.len()) {
            (0, 1) => "−180°",
            (0, _) => "−180° (mod 360°)",
            _ => "",
        };
        phase.push(reference(label, level, range));
    }
    phase.extend(oil_column_lines(
        system,
        curves,
        range,
        (phase_extent.0.min(-180.0), phase_extent.1),
    ));
    if let Some(fp) = margins.phase_crossover_hz.filter(in_range) {
        if let Some(p) = at(&first.phase_deg, fp) {
            // The crossing of −180° (mod 360°) nearest the unwrapped phase there.
            let level = -180.0 + 360.0 * ((p + 180.0) / 360.0).round();
            phase.push(points("phase crossover", vec![(fp, level)], SIMULATED, 6));
        }
    }
    phase
}

/// Colours of up to six DOFs' curves (x, y, z, roll, pitch, yaw).
const DOF_COLOURS: [RGBColor; 6] = [
    MODEL,
    SIMULATED,
    crate::figure::RECORDED,
    RESIDUAL,
    RGBColor(27, 158, 119),
    RGBColor(231, 41, 138),
];

/// The Bode figures of a multi-axis table's linearised closed loop (`platen model --plot` on
/// a scenario with a `table.controller`), from [`F_MIN_HZ`] to the lower of [`F_MAX_HZ`] and
/// the controller's Nyquist frequency (`sample_rate_hz / 2`):
///
/// * `table-loop-diagonal`: each free DOF's own response, pose over command, magnitude (dB)
///   and phase;
/// * `table-loop-cross-talk`: for each free DOF's command, the other DOF that responds the
///   most to it (the largest peak over the range), magnitude in dB of m/m, rad/rad, m/rad or
///   rad/m as numbers.
///
/// `name` heads the titles.
pub fn table_loop_figures(
    name: &str,
    lin: &platen_system::TableLinearisation,
    sample_rate_hz: f64,
) -> Vec<Figure> {
    let range = (
        F_MIN_HZ,
        F_MAX_HZ.min(0.5 * sample_rate_hz).max(2.0 * F_MIN_HZ),
    );
    let f = frequencies(range);
    let matrices: Vec<TransferMatrix> = f.iter().map(|&fi| lin.transfer_matrix(fi)).collect();
    let free = lin.free();
    let diagonal = diagonal_figure(name, free, &f, &matrices, range, sample_rate_hz);
    let cross = cross_talk_series(free, &f, &matrices);
    let mut out = vec![diagonal];
    if !cross.is_empty() {
        out.push(cross_talk_figure(name, range, cross));
    }
    out
}

/// The closed loop's response at one frequency, pose DOF × command DOF.
type TransferMatrix = [[num_complex::Complex64; 6]; 6];

/// A free DOF's colour in the table-loop figures.
fn dof_style(d: platen_model::multi_axis::Dof) -> RGBColor {
    DOF_COLOURS[d.index()]
}

/// `table-loop-diagonal`: each free DOF's own response at frequencies `f` (the transfer
/// `matrices`), magnitude and phase over `range`.
fn diagonal_figure(
    name: &str,
    free: &[platen_model::multi_axis::Dof],
    f: &[f64],
    matrices: &[TransferMatrix],
    range: (f64, f64),
    sample_rate_hz: f64,
) -> Figure {
    let (mut magnitude, mut phase) = (Vec::new(), Vec::new());
    for &d in free {
        let k = d.index();
        let b = Bode::from_responses(f, matrices.iter().map(|m| m[k][k]));
        magnitude.push(patterned(
            d.name(),
            b.magnitude_db.clone(),
            dof_style(d),
            2,
            Dash::Solid,
        ));
        phase.push(patterned(
            d.name(),
            b.phase_deg,
            dof_style(d),
            2,
            Dash::Solid,
        ));
    }
    magnitude.push(reference("0 dB (pose = command)", 0.0, range));
    Figure {
        name: "table-loop-diagonal".into(),
        title: format!("{name}: closed loop per DOF, command → pose (linearised)"),
        caption: format!(
            "Each free DOF's small-signal response to its own command, magnitude (dB) and \
             phase, from {} Hz to {} Hz (the controller samples at {} Hz), the other DOFs \
             commanded still, about neutral at rest. The hold and the valves' delay are in \
             the phase; friction is not linearised.",
            significant(range.0, 3),
            significant(range.1, 3),
            significant(sample_rate_hz, 4)
        ),
        panels: vec![
            bode_panel(
                "magnitude |pose/command|".into(),
                "|H| (dB)",
                range,
                magnitude,
            ),
            bode_panel("phase of pose/command".into(), "phase (°)", range, phase),
        ],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 900),
    }
}

/// For each free DOF's command, the other DOF whose response peaks highest over the
/// frequencies (the first of equal peaks), with that peak; `None` with one free DOF.
fn largest_cross_talk(
    free: &[platen_model::multi_axis::Dof],
    matrices: &[TransferMatrix],
    c: platen_model::multi_axis::Dof,
) -> Option<(platen_model::multi_axis::Dof, f64)> {
    let j = c.index();
    free.iter()
        .filter(|&&o| o != c)
        .map(|&o| {
            let peak = matrices
                .iter()
                .map(|m| m[o.index()][j].norm())
                .fold(0.0, f64::max);
            (o, peak)
        })
        .fold(
            None,
            |best: Option<(platen_model::multi_axis::Dof, f64)>, x| match best {
                Some(b) if b.1 >= x.1 => best,
                _ => Some(x),
            },
        )
}

/// Per free DOF's command, the magnitude (dB) over frequencies `f` of its largest
/// cross-talk ([`largest_cross_talk`]).
fn cross_talk_series(
    free: &[platen_model::multi_axis::Dof],
    f: &[f64],
    matrices: &[TransferMatrix],
) -> Vec<Series> {
    let mut cross = Vec::new();
    for &c in free {
        let j = c.index();
        let Some((o, _)) = largest_cross_talk(free, matrices, c) else {
            continue;
        };
        let points: Points = f
            .iter()
            .zip(matrices)
            .map(|(&fi, m)| (fi, 20.0 * m[o.index()][j].norm().log10()))
            .filter(|p| p.1.is_finite())
            .collect();
        cross.push(patterned(
            format!("{} → {}", c.name(), o.name()),
            points,
            dof_style(c),
            2,
            Dash::Solid,
        ));
    }
    cross
}

/// `table-loop-cross-talk`: the `cross` series over `range`.
fn cross_talk_figure(name: &str, range: (f64, f64), cross: Vec<Series>) -> Figure {
    Figure {
        name: "table-loop-cross-talk".into(),
        title: format!("{name}: cross-talk, the largest other DOF per command (linearised)"),
        caption: "For each DOF's command, the magnitude (dB) of the other DOF's response \
                  that peaks highest over the range (units as numbers: m/m, rad/rad, m/rad, \
                  rad/m). A coupling through the specimen's overturning moment shows as \
                  x → pitch or y → roll."
            .into(),
        panels: vec![bode_panel(
            "largest cross-talk per commanded DOF".into(),
            "|H| (dB)",
            range,
            cross,
        )],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 600),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_system::{preset, Mechanics};

    fn lhpost() -> (TableSystem, Vec<LoopCurve>, Margins) {
        let system = preset::lhpost_2008();
        let mech = Mechanics {
            mass_kg: 144e3,
            stiffness_n_per_m: 1.266e6,
            damping_n_s_per_m: 1e5,
        };
        let lin = system.linearise(mech, 0.0);
        let margins = system.margins(&lin);
        (
            system,
            vec![LoopCurve {
                label: String::new(),
                linearisation: lin,
            }],
            margins,
        )
    }

    /// Two figures of two logarithmic panels each, over 0.1–200 Hz for a 1024 Hz
    /// controller; the closed loop's magnitude starts at 0 dB (it tracks slow commands) and
    /// the loop gain's phase crosses −180° where the margins say.
    #[test]
    fn bode_figures_of_the_lhpost_loop() {
        let (system, curves, margins) = lhpost();
        assert_eq!(frequency_range_hz(&system), (0.1, 200.0));
        let figures = figures("lhpost-2008", &system, &curves, &margins);
        let names: Vec<&str> = figures.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["bode-closed-loop", "bode-loop-gain"]);
        for f in &figures {
            assert_eq!(f.panels.len(), 2);
            assert!(f.panels.iter().all(|p| p.x_log));
            assert!(f.to_svg().unwrap().contains("<svg"));
        }
        let closed = &figures[0].panels[0].series[0].points;
        assert_eq!(closed.len(), POINTS);
        assert!(closed[0].1.abs() < 1.0, "{:?}", closed[0]);
        let open = &figures[1].panels[1].series[0].points;
        if let Some(fp) = margins.phase_crossover_hz.filter(|f| *f < 200.0) {
            let p = at(open, fp).unwrap();
            let off = (p + 180.0).rem_euclid(360.0);
            assert!(off.min(360.0 - off) < 1.0, "∠L = {p}° at {fp} Hz");
        }
    }

    /// Ticks 1, 2, 5 × 10^k over 0.1–200 Hz, read back as those numbers.
    #[test]
    fn log_axis_labels_read_as_frequencies() {
        let (system, curves, margins) = lhpost();
        let svg = figures("t", &system, &curves, &margins)[0]
            .to_svg()
            .unwrap();
        for label in [
            "0.1", "0.2", "0.5", "1", "2", "5", "10", "20", "50", "100", "200",
        ] {
            // plotters writes each text on a line of its own.
            assert!(svg.contains(&format!("\n{label}\n")), "no tick {label}");
        }
    }
}
