//! The figures of a run of the multi-axis (six-DOF) platen
//! ([`platen_integrate::TableRun`], as [`platen_integrate::inverse_table`] makes it):
//!
//! * `pose`: the six pose coordinates over time, one panel each (x, y, z in mm; roll, pitch,
//!   yaw in mrad).
//! * `actuator_strokes`: every actuator's stroke (from its neutral length, mm) over time, one
//!   panel each, with its ±`stroke_m` limits dashed.
//! * `actuator_forces`: every actuator's force (kN, positive pushing) over time, one panel
//!   each, with its pull and push limits dashed when they are given.
//! * `overturning_moments` (a run with a specimen only): the overturning moments M_x and M_y
//!   (kN·m) and the base forces F_x, F_y and F_z (kN) over time.
//!
//! Panels are in the table's order of the actuators, each titled with the actuator's name,
//! its mount (swivel or pad) and its peak. Every channel is drawn as the smallest and largest
//! sample of each of [`BUCKETS`] equal time intervals ([`envelope`](crate::series::envelope)), so a 40 s run at
//! 1024 Hz draws about 2200 points per panel. A column the run lacks is left out (its panel
//! is not drawn, nor a figure without any); a run without `t_s` or without samples has no
//! figures.
//!
//! A [`TableRecorder`] is a [`TableSink`] that keeps, while the run goes, only these
//! envelopes, so that `platen simulate --plot` draws a run it streams to its file without
//! holding it; [`figures`] draws a run held in memory through the same recorder.
//!
//! Output is a pure function of the run and the table: the same input gives the same bytes.

use std::path::{Path, PathBuf};

use plotters::style::RGBColor;

use platen_integrate::{TableRun, TableSink};
use platen_model::multi_axis::{Dof, Mount, MultiAxisTable};

use crate::error::Result;
use crate::figure::{Dash, Figure, Panel, MODEL, SIMULATED};
use crate::render::{render_all, write_figures, FigureSize};
use crate::run_figures::{Envelope, BUCKETS};
use crate::series::{line, patterned, Points};
use crate::sweep_figures::limit_text;
use crate::text::significant;

/// The columns of the specimen's base wrench: column, quantity, symbol; forces in N first,
/// then the overturning moments in N·m.
const SPECIMEN_COLUMNS: [(&str, &str, &str); 5] = [
    ("overturning_moment_x_n_m", "overturning moment", "M_x"),
    ("overturning_moment_y_n_m", "overturning moment", "M_y"),
    ("base_force_x_n", "base force", "F_x"),
    ("base_force_y_n", "base force", "F_y"),
    ("base_force_z_n", "base force", "F_z"),
];

/// The figures of a multi-axis run (see the module's documentation): `pose`,
/// `actuator_strokes`, `actuator_forces`, and `overturning_moments` when the run has the
/// specimen's columns. `force_limits_n[i]` is actuator `i`'s `(pull limit (negative), push
/// limit)`, N, drawn dashed on its force panel (an actuator without an entry has no lines).
pub fn figures(
    run: &TableRun,
    table: &MultiAxisTable,
    force_limits_n: Option<&[(f64, f64)]>,
    flow_capacity_m3_s: Option<&[f64]>,
) -> Vec<Figure> {
    let Some(recorder) = TableRecorder::of_run(run) else {
        return Vec::new();
    };
    recorded_figures(recorder, table, force_limits_n, flow_capacity_m3_s)
}

/// [`figures`] of a run whose envelopes `recorder` kept as it went.
pub fn recorded_figures(
    recorder: TableRecorder,
    table: &MultiAxisTable,
    force_limits_n: Option<&[(f64, f64)]>,
    flow_capacity_m3_s: Option<&[f64]>,
) -> Vec<Figure> {
    if recorder.rows == 0 {
        return Vec::new();
    }
    let c = recorder.finish();
    let mut out = vec![
        pose(&c),
        actuator_strokes(&c, table),
        actuator_forces(&c, table, force_limits_n),
    ];
    out.extend(overturning_moments(&c));
    out.extend(tracking(&c));
    out.extend(flows(&c, table, flow_capacity_m3_s));
    out.extend(supply_pressure(&c));
    // A figure all of whose columns the run lacks is not drawn.
    out.retain(|f| !f.panels.is_empty());
    out
}

/// Writes the figures of a multi-axis run ([`figures`]) to `dir` (created if missing), each
/// as SVG and PNG at `size` (each file atomically, every PNG rendered before the first file
/// is written), and returns the paths written, sorted.
///
/// # Errors
/// Those of [`render_all`] and [`write_figures`]: [`ReportError::Draw`](crate::ReportError),
/// a PNG rendering error, or [`ReportError::Write`](crate::ReportError) when the folder or a
/// file cannot be written.
pub fn write_table_figures(
    run: &TableRun,
    table: &MultiAxisTable,
    force_limits_n: Option<&[(f64, f64)]>,
    flow_capacity_m3_s: Option<&[f64]>,
    dir: &Path,
    size: FigureSize,
) -> Result<Vec<PathBuf>> {
    let figures = figures(run, table, force_limits_n, flow_capacity_m3_s);
    write_all(figures, dir, size)
}

/// [`write_table_figures`] of a run whose envelopes `recorder` kept as it went.
///
/// # Errors
/// As [`write_table_figures`].
pub fn write_recorded_figures(
    recorder: TableRecorder,
    table: &MultiAxisTable,
    force_limits_n: Option<&[(f64, f64)]>,
    flow_capacity_m3_s: Option<&[f64]>,
    dir: &Path,
    size: FigureSize,
) -> Result<Vec<PathBuf>> {
    let figures = recorded_figures(recorder, table, force_limits_n, flow_capacity_m3_s);
    write_all(figures, dir, size)
}

/// Writes `figures` to `dir` at `size` (see [`write_table_figures`]).
fn write_all(mut figures: Vec<Figure>, dir: &Path, size: FigureSize) -> Result<Vec<PathBuf>> {
    for f in &mut figures {
        f.size = size.of(f.size);
    }
    let rendered = render_all(&figures)?;
    let mut written = write_figures(dir, &rendered, size.png_scale)?;
    written.sort();
    Ok(written)
}

/// The envelopes of a multi-axis run's columns, kept as the run goes (a [`TableSink`]):
/// per column the smallest and largest sample of each of [`BUCKETS`] equal time intervals of
/// the run's span, the points [`envelope`](crate::series::envelope) picks from the whole column. Its memory does not
/// grow with the run.
#[derive(Debug, Clone)]
pub struct TableRecorder {
    /// First and last time stamps (a unit interval around a single sample).
    span_s: (f64, f64),
    /// The run's rows, as announced.
    samples: usize,
    names: Vec<String>,
    envelopes: Vec<Envelope>,
    /// Rows received.
    rows: usize,
}

impl TableRecorder {
    /// A recorder for a run whose rows are at the time stamps `t_s` (known before it:
    /// `TableScenario::output_t_s`).
    pub fn new(t_s: &[f64]) -> Self {
        let span_s = match (t_s.first(), t_s.last()) {
            (Some(&t0), Some(&t1)) if t1 > t0 => (t0, t1),
            (Some(&t0), _) => (t0 - 0.5, t0 + 0.5),
            _ => (0.0, 1.0),
        };
        Self {
            span_s,
            samples: t_s.len(),
            names: Vec::new(),
            envelopes: Vec::new(),
            rows: 0,
        }
    }

    /// The envelopes of `run` (`None` without a time column or samples); a column shorter
    /// than the time column over its own samples.
    fn of_run(run: &TableRun) -> Option<Self> {
        let t = run.column("t_s").filter(|t| !t.is_empty())?;
        let mut recorder = Self::new(t);
        recorder.rows = t.len();
        for (name, y) in &run.columns {
            let mut e = Envelope::new(recorder.span_s, y.len().min(t.len()));
            for (i, (&t, &y)) in t.iter().zip(y).enumerate() {
                e.push(i, t, y);
            }
            recorder.names.push(name.clone());
            recorder.envelopes.push(e);
        }
        Some(recorder)
    }

    /// The columns' envelopes.
    fn finish(self) -> Columns {
        Columns {
            samples: self.rows,
            span_s: self.span_s,
            points: self
                .names
                .into_iter()
                .zip(self.envelopes.into_iter().map(Envelope::finish))
                .collect(),
        }
    }
}

impl TableSink for TableRecorder {
    fn start(&mut self, names: &[String], _samples: usize) {
        self.names = names.to_vec();
        self.envelopes = names
            .iter()
            .map(|_| Envelope::new(self.span_s, self.samples))
            .collect();
    }

    fn accept(&mut self, row: &[f64]) {
        let (i, t) = (self.rows, row.first().copied().unwrap_or_default());
        for (e, &y) in self.envelopes.iter_mut().zip(row) {
            e.push(i, t, y);
        }
        self.rows += 1;
    }
}

/// A run's envelopes by column.
struct Columns {
    /// Each column's name and envelope.
    points: Vec<(String, Points)>,
    /// First and last time stamps (a unit interval around a single sample).
    span_s: (f64, f64),
    samples: usize,
}

impl Columns {
    /// The envelope of column `name` times `scale` (`None` if the run lacks it).
    fn envelope(&self, name: &str, scale: f64) -> Option<Points> {
        let (_, points) = self.points.iter().find(|(n, _)| n == name)?;
        let mut points = points.clone();
        for p in &mut points {
            p.1 *= scale;
        }
        Some(points)
    }

    /// Whether the run has column `name`.
    fn has(&self, name: &str) -> bool {
        self.points.iter().any(|(n, _)| n == name)
    }

    fn samples(&self) -> usize {
        self.samples
    }
}

/// The largest magnitude of the points' values.
fn peak_magnitude(points: &Points) -> f64 {
    points.iter().map(|p| p.1.abs()).fold(0.0, f64::max)
}

/// The smallest and largest of the points' values.
fn extremes(points: &Points) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        })
}

/// A dashed horizontal line at `y` over `span`.
fn level(label: String, span: (f64, f64), y: f64) -> crate::figure::Series {
    patterned(
        label,
        vec![(span.0, y), (span.1, y)],
        MODEL,
        2,
        Dash::Dashed,
    )
}

/// A panel of one simulated channel over time, its title naming its peak magnitude.
fn peak_panel(quantity: &str, symbol: &str, unit: &str, points: Points, span: (f64, f64)) -> Panel {
    time_panel(
        format!(
            "{quantity} {symbol}: peak |{symbol}| {} {unit}",
            significant(peak_magnitude(&points), 4)
        ),
        format!("{symbol} ({unit})"),
        points,
        span,
        SIMULATED,
        None,
    )
}

/// A time-history panel: the points solid, with dashed lines at `limits` = `(low, high)`
/// (display units, legend `limit_label`), the peak in the title and "EXCEEDS" when the
/// data pass a limit.
fn time_panel(
    title: String,
    y_label: String,
    points: Points,
    span: (f64, f64),
    color: RGBColor,
    limits: Option<((f64, f64), String)>,
) -> Panel {
    let mut title = title;
    let mut series = vec![line("", points, color, 1)];
    if let Some(((low, high), label)) = limits {
        let (lo, hi) = extremes(&series[0].points);
        if lo < low || hi > high {
            title.push_str(" (EXCEEDS the limit)");
        }
        series.push(level(label, span, high));
        series.push(level(String::new(), span, low));
    }
    Panel {
        x_range: Some(span),
        ..Panel::new(title, "time t (s)", y_label, series)
    }
}

/// `swivel` or `pad`.
fn mount_name(mount: &Mount) -> &'static str {
    match mount {
        Mount::Swivel { .. } => "swivel",
        Mount::Pad(_) => "pad",
    }
}

/// The "over the run" clause of the captions.
fn sampling(c: &Columns) -> String {
    format!(
        "{} samples; the smallest and largest sample of each of {BUCKETS} equal time intervals",
        c.samples()
    )
}

/// The height of a figure of `panels` panels in `columns` columns, `per_row` px a row.
fn height(panels: usize, columns: usize, per_row: u32) -> u32 {
    per_row * panels.div_ceil(columns.max(1)).max(1) as u32 + 120
}

/// The six pose coordinates over time: x, y, z in mm (left), roll, pitch, yaw in mrad (right).
fn pose(c: &Columns) -> Figure {
    // Row by row: x | roll, y | pitch, z | yaw.
    let order = [Dof::X, Dof::Roll, Dof::Y, Dof::Pitch, Dof::Z, Dof::Yaw];
    let panels: Vec<Panel> = order
        .iter()
        .filter_map(|&d| {
            let points = c.envelope(&format!("{}_{}", d.name(), d.unit()), 1e3)?;
            let (quantity, unit) = if d.is_rotation() {
                ("rotation", "mrad")
            } else {
                ("translation", "mm")
            };
            let symbol = d.name();
            Some(peak_panel(quantity, symbol, unit, points, c.span_s))
        })
        .collect();
    Figure {
        name: "pose".into(),
        title: "Multi-axis platen: pose".into(),
        caption: format!(
            "The platen's translations x, y, z (mm, left) and rotations roll, pitch, yaw \
             (mrad, right) over the run ({}).",
            sampling(c)
        ),
        size: (1400, height(panels.len(), 2, 260)),
        columns: 2,
        rows: Vec::new(),
        panels,
    }
}

/// Every actuator's stroke over time (mm), with its ±`stroke_m` dashed.
fn actuator_strokes(c: &Columns, table: &MultiAxisTable) -> Figure {
    let panels: Vec<Panel> = table
        .actuators()
        .iter()
        .filter_map(|a| {
            let points = c.envelope(&format!("{}_stroke_m", a.name), 1e3)?;
            let limit = a.stroke_m * 1e3;
            Some(time_panel(
                format!(
                    "{} ({}): peak |stroke| {} mm of ±{} mm",
                    a.name,
                    mount_name(&a.mount),
                    significant(peak_magnitude(&points), 4),
                    limit_text(limit)
                ),
                "stroke (mm)".into(),
                points,
                c.span_s,
                SIMULATED,
                Some(((-limit, limit), format!("stroke ±{} mm", limit_text(limit)))),
            ))
        })
        .collect();
    let columns = if panels.len() > 1 { 2 } else { 1 };
    Figure {
        name: "actuator_strokes".into(),
        title: "Multi-axis platen: actuator strokes".into(),
        caption: format!(
            "Each actuator's stroke (its length from neutral for a swivel actuator, its pad's \
             travel along its axis for a pad; mm) over the run ({}), with its stroke limits \
             ±stroke_m dashed.",
            sampling(c)
        ),
        size: (1400, height(panels.len(), columns, 240)),
        columns,
        rows: Vec::new(),
        panels,
    }
}

/// Every actuator's force over time (kN), with its pull and push limits dashed when given.
fn actuator_forces(
    c: &Columns,
    table: &MultiAxisTable,
    force_limits_n: Option<&[(f64, f64)]>,
) -> Figure {
    let panels: Vec<Panel> = table
        .actuators()
        .iter()
        .enumerate()
        .filter_map(|(i, a)| {
            let points = c.envelope(&format!("{}_force_n", a.name), 1e-3)?;
            let limits = force_limits_n.and_then(|l| l.get(i)).map(|&(pull, push)| {
                let (pull, push) = (pull * 1e-3, push * 1e-3);
                (
                    (pull, push),
                    format!(
                        "limits {} / +{} kN",
                        limit_text(pull).replace('-', "−"),
                        limit_text(push)
                    ),
                )
            });
            let (lo, hi) = extremes(&points);
            Some(time_panel(
                format!(
                    "{} ({}): force {} to {} kN",
                    a.name,
                    mount_name(&a.mount),
                    significant(lo, 4).replace('-', "−"),
                    significant(hi, 4).replace('-', "−")
                ),
                "force (kN)".into(),
                points,
                c.span_s,
                SIMULATED,
                limits,
            ))
        })
        .collect();
    let columns = if panels.len() > 1 { 2 } else { 1 };
    let limits = if force_limits_n.is_some() {
        ", with its pull (negative) and push limits dashed"
    } else {
        ""
    };
    Figure {
        name: "actuator_forces".into(),
        title: "Multi-axis platen: actuator forces".into(),
        caption: format!(
            "Each actuator's force (kN, positive pushing the platen away from its base or \
             along its pad's axis) over the run ({}){limits}.",
            sampling(c)
        ),
        size: (1400, height(panels.len(), columns, 240)),
        columns,
        rows: Vec::new(),
        panels,
    }
}

/// The specimen's overturning moments (kN·m) and base forces (kN) over time, when the run
/// has the overturning moments' columns.
fn overturning_moments(c: &Columns) -> Option<Figure> {
    if !SPECIMEN_COLUMNS[..2].iter().any(|(name, ..)| c.has(name)) {
        return None;
    }
    let panels: Vec<Panel> = SPECIMEN_COLUMNS
        .iter()
        .filter_map(|&(name, quantity, symbol)| {
            let points = c.envelope(name, 1e-3)?;
            let unit = if name.ends_with("_n_m") {
                "kN·m"
            } else {
                "kN"
            };
            Some(peak_panel(quantity, symbol, unit, points, c.span_s))
        })
        .collect();
    Some(Figure {
        name: "overturning_moments".into(),
        title: "Multi-axis platen: the specimen's overturning moments and base forces".into(),
        caption: format!(
            "The overturning moments M_x, M_y (kN·m) and the base forces F_x, F_y, F_z (kN) \
             the platen exerts on the specimen, in table axes about the platen's reference point, over \
             the run ({}).",
            sampling(c)
        ),
        size: (1200, height(panels.len(), 1, 240)),
        columns: 1,
        rows: Vec::new(),
        panels,
    })
}

/// A closed loop's tracking: per DOF the command (dashed) and the achieved pose (solid), mm
/// or mrad; the DOFs commanded still show the cross-talk. `None` without command columns.
fn tracking(c: &Columns) -> Option<Figure> {
    let order = [Dof::X, Dof::Roll, Dof::Y, Dof::Pitch, Dof::Z, Dof::Yaw];
    let panels: Vec<Panel> = order
        .iter()
        .filter_map(|&d| {
            let name = format!("{}_{}", d.name(), d.unit());
            let command = c.envelope(&format!("command_{name}"), 1e3)?;
            let achieved = c.envelope(&name, 1e3)?;
            let unit = if d.is_rotation() { "mrad" } else { "mm" };
            let symbol = d.name();
            let still = peak_magnitude(&command) == 0.0;
            let title = if still {
                format!(
                    "{symbol}, commanded still: peak |{symbol}| {} {unit} (cross-talk)",
                    significant(peak_magnitude(&achieved), 4)
                )
            } else {
                format!(
                    "{symbol}: peak command {} {unit}, achieved {} {unit}",
                    significant(peak_magnitude(&command), 4),
                    significant(peak_magnitude(&achieved), 4)
                )
            };
            Some(Panel {
                x_range: Some(c.span_s),
                ..Panel::new(
                    title,
                    "time t (s)",
                    format!("{symbol} ({unit})"),
                    vec![
                        patterned("command", command, MODEL, 1, Dash::Dashed),
                        line("achieved", achieved, SIMULATED, 1),
                    ],
                )
            })
        })
        .collect();
    if panels.is_empty() {
        return None;
    }
    Some(Figure {
        name: "tracking".into(),
        title: "Multi-axis closed loop: command and achieved pose".into(),
        caption: format!(
            "Per DOF the DOF controller's command (dashed) and the platen's achieved pose \
             (solid), translations in mm (left), rotations in mrad (right), over the run ({}). \
             A DOF commanded still shows the cross-talk from the others.",
            sampling(c)
        ),
        size: (1400, height(panels.len(), 2, 260)),
        columns: 2,
        rows: Vec::new(),
        panels,
    })
}

/// A closed loop's valve flows: each actuator's flow into its chamber a (l/s) with its
/// valves' capacity at the supply pressure dashed. `None` without flow columns.
fn flows(c: &Columns, table: &MultiAxisTable, capacity: Option<&[f64]>) -> Option<Figure> {
    let panels: Vec<Panel> = table
        .actuators()
        .iter()
        .enumerate()
        .filter_map(|(i, a)| {
            let points = c.envelope(&format!("{}_flow_m3_s", a.name), 1e3)?;
            let cap = capacity.and_then(|q| q.get(i)).map(|q| q * 1e3);
            let title = match cap {
                Some(q) => format!(
                    "{}: peak |flow| {} l/s of {} l/s",
                    a.name,
                    significant(peak_magnitude(&points), 4),
                    significant(q, 4)
                ),
                None => format!(
                    "{}: peak |flow| {} l/s",
                    a.name,
                    significant(peak_magnitude(&points), 4)
                ),
            };
            Some(time_panel(
                title,
                "flow (l/s)".into(),
                points,
                c.span_s,
                SIMULATED,
                cap.map(|q| ((-q, q), format!("capacity ±{} l/s", significant(q, 4)))),
            ))
        })
        .collect();
    if panels.is_empty() {
        return None;
    }
    let columns = if panels.len() > 1 { 2 } else { 1 };
    Some(Figure {
        name: "valve_flows".into(),
        title: "Multi-axis closed loop: valve flows".into(),
        caption: format!(
            "Each actuator's flow into its cap-side chamber (l/s) over the run ({}), with its \
             valves' capacity at the supply pressure, m·Q_r·√((P_s − P_R)/Δp_r), dashed.",
            sampling(c)
        ),
        size: (1400, height(panels.len(), columns, 240)),
        columns,
        rows: Vec::new(),
        panels,
    })
}

/// A closed loop's supply pressure (MPa). `None` without the column.
fn supply_pressure(c: &Columns) -> Option<Figure> {
    let points = c.envelope("supply_pressure_pa", 1e-6)?;
    let (lo, hi) = extremes(&points);
    Some(Figure {
        name: "supply_pressure".into(),
        title: "Multi-axis closed loop: supply pressure".into(),
        caption: format!(
            "The supply pressure (MPa) the valves draw from over the run ({}): constant, or an \
             accumulator bank's as the valves draw more oil than the pumps give.",
            sampling(c)
        ),
        panels: vec![time_panel(
            format!(
                "supply pressure: {} … {} MPa",
                significant(lo, 4),
                significant(hi, 4)
            ),
            "p_s (MPa)".into(),
            points,
            c.span_s,
            SIMULATED,
            None,
        )],
        columns: 1,
        rows: Vec::new(),
        size: (1400, 500),
    })
}
