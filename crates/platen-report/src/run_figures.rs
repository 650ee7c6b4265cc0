//! The figures of a run without a recording (`platen simulate SCENARIO --plot DIR`): the
//! motion and the actuator force over time, the force decomposition over time, and the
//! hysteresis loops (actuator force against displacement, velocity and acceleration), and for
//! a run with a specimen its base shear and storey drifts over time.
//!
//! A closed-loop run (a scenario with a `table_system`) adds the loop's figures: the command
//! and the achieved displacement and acceleration (whole run, and zoomed on the command's
//! largest acceleration), the tracking errors, the drive and the spool opening, the pressure
//! difference and the chamber pressures, the valves' flow against their capacity and the
//! supply pressure, over time.
//!
//! A [`RunRecorder`] is a [`SampleSink`] that keeps, while the run goes, only what the
//! figures draw: per channel the smallest and largest sample of each of [`BUCKETS`] equal
//! time buckets (the same points [`envelope`] picks from the whole record), and every k-th
//! sample for the loops; for a closed-loop run also its loop's channels and every sample of
//! the zoomed interval (at most [`ZOOM_S`]). Its memory does not grow with the run's length,
//! so a one-hour run can be plotted as it streams to CSV.

use platen_integrate::{Sample, SampleSink};
use platen_model::TableLimits;
use platen_scenario::{PlatenScenario, Run};
use platen_system::{Supply, TableSystem};

use crate::figure::{Dash, Figure, Panel, MODEL, RECORDED, RESIDUAL, SIMULATED};
use crate::series::{envelope, every, line, patterned, Points, MAX_LOOP_POINTS};
use crate::text::significant;

/// Time buckets of the envelopes (about the pixels of a full-width panel).
pub const BUCKETS: usize = 1100;

/// A peak at least this fraction of its table limit draws the limit's lines (below it the
/// lines would stretch the axis far beyond the data: at most 1/0.6 ≈ 1.7 times).
const LIMIT_SHOWN_FROM: f64 = 0.6;

/// The envelope of one channel, built one sample at a time.
#[derive(Debug, Clone)]
pub(crate) struct Envelope {
    /// Every sample is kept (a record of at most `2·BUCKETS` samples).
    all: bool,
    t0_s: f64,
    width_s: f64,
    points: Points,
    bucket: Option<f64>,
    /// The bucket's first smallest and last largest sample: (index, t, y).
    lo: (usize, f64, f64),
    hi: (usize, f64, f64),
}

impl Envelope {
    /// An envelope over `span_s` of a channel of `samples` samples.
    pub(crate) fn new(span_s: (f64, f64), samples: usize) -> Self {
        Self {
            all: samples <= 2 * BUCKETS,
            t0_s: span_s.0,
            width_s: (span_s.1 - span_s.0) / BUCKETS as f64,
            points: Vec::with_capacity((2 * BUCKETS + 2).min(samples)),
            bucket: None,
            lo: (0, 0.0, 0.0),
            hi: (0, 0.0, 0.0),
        }
    }

    /// Sample `index`, `(t, y)`.
    pub(crate) fn push(&mut self, index: usize, t: f64, y: f64) {
        if self.all {
            self.points.push((t, y));
            return;
        }
        let bucket = ((t - self.t0_s) / self.width_s).floor();
        if self.bucket != Some(bucket) {
            self.flush();
            self.bucket = Some(bucket);
            self.lo = (index, t, y);
            self.hi = (index, t, y);
            return;
        }
        // The first of equal smallest and the last of equal largest, as `envelope` picks.
        if y.total_cmp(&self.lo.2).is_lt() {
            self.lo = (index, t, y);
        }
        if y.total_cmp(&self.hi.2).is_ge() {
            self.hi = (index, t, y);
        }
    }

    fn flush(&mut self) {
        if self.bucket.take().is_none() {
            return;
        }
        let (first, second) = if self.lo.0 <= self.hi.0 {
            (self.lo, self.hi)
        } else {
            (self.hi, self.lo)
        };
        self.points.push((first.1, first.2));
        if second.0 != first.0 {
            self.points.push((second.1, second.2));
        }
    }

    /// The envelope's points.
    pub(crate) fn finish(mut self) -> Points {
        self.flush();
        self.points
    }
}

/// Longest zoomed interval of a closed-loop run's tracking figure, s (a quarter of a shorter
/// run).
pub const ZOOM_S: f64 = 2.0;

/// The closed loop's channels a recorder keeps the envelopes of, in this order.
const LOOP_CHANNELS: usize = 11;
/// Indices into the closed loop's envelopes.
const CMD_U: usize = 0;
const ERR_U: usize = 1;
const CMD_A: usize = 2;
const ERR_A: usize = 3;
const DRIVE: usize = 4;
const SPOOL: usize = 5;
const DELTA_P: usize = 6;
const P_A: usize = 7;
const P_B: usize = 8;
const FLOW: usize = 9;
const SUPPLY: usize = 10;

/// The prescribed motion of a run, which a closed-loop run reads as its displacement command.
#[derive(Debug, Clone)]
struct Command<'a> {
    /// The command's acceleration at each output sample, m/s².
    a_m_s2: &'a [f64],
    /// The interval the tracking figure zooms on: at most [`ZOOM_S`] (a quarter of the run)
    /// around the command's largest |acceleration|, inside the run.
    zoom_s: (f64, f64),
}

impl<'a> Command<'a> {
    fn new(t_s: &[f64], a_m_s2: &'a [f64]) -> Option<Self> {
        Some(Self {
            a_m_s2,
            zoom_s: zoom_window(t_s, a_m_s2)?,
        })
    }
}

/// The interval a figure zooms on: at most [`ZOOM_S`] (a quarter of the record) around the
/// largest |`a`|, inside the record of times `t_s` (`None` for an empty one).
pub(crate) fn zoom_window(t_s: &[f64], a: &[f64]) -> Option<(f64, f64)> {
    let (&t0, &t1) = (t_s.first()?, t_s.last()?);
    let peak = a
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |best, (i, a)| {
            if a.abs() > best.1 {
                (i, a.abs())
            } else {
                best
            }
        })
        .0;
    let width = ZOOM_S.min(0.25 * (t1 - t0));
    let start = (t_s.get(peak).copied().unwrap_or(t0) - 0.5 * width).clamp(t0, t1 - width);
    Some((start, start + width))
}

/// Collects, while a run goes, what its figures draw (see the module's documentation). It
/// borrows the run's prescribed motion (`'a`), which a closed-loop run reads as its command.
#[derive(Debug, Clone)]
pub struct RunRecorder<'a> {
    /// Envelopes of u, v, a, F_A, F_I, F_E, F_D (SI units).
    channels: [Envelope; 7],
    /// Every `stride`-th sample's (u, v, a, F_A).
    loops: Vec<[f64; 4]>,
    stride: usize,
    /// Samples seen.
    samples: usize,
    /// The run's span and sample count, for the specimen's envelopes.
    span_s: (f64, f64),
    expected: usize,
    /// Envelopes of the base shear (N) and of each storey's drift (m), for a run with a
    /// specimen (made at its first sample).
    specimen: Vec<Envelope>,
    /// The run's prescribed motion (`None` for a forward run).
    command: Option<Command<'a>>,
    /// Envelopes of the closed loop's channels (SI units; `CMD_U` … `SUPPLY`), for a
    /// closed-loop run (made at its first sample).
    system: Vec<Envelope>,
    /// Every sample of a closed-loop run inside the command's zoomed interval:
    /// `(t, u, a, u_ref, a_ref)`.
    zoom: Vec<[f64; 5]>,
}

impl<'a> RunRecorder<'a> {
    /// A recorder for `run` (its time span and sample count are known before it runs).
    pub fn new(run: &'a Run) -> Self {
        match run {
            Run::Forward { samples, .. } => Self::with_span(run.time_span_s(), *samples),
            Run::Inverse { motion }
            | Run::ClosedLoop {
                command: motion, ..
            } => Self {
                command: Command::new(motion.t_s(), motion.a_m_s2()),
                ..Self::with_span(run.time_span_s(), motion.len())
            },
        }
    }

    /// A recorder for `samples` samples over `span_s`.
    pub fn with_span(span_s: (f64, f64), samples: usize) -> Self {
        let stride = samples.div_ceil(MAX_LOOP_POINTS).max(1);
        Self {
            channels: std::array::from_fn(|_| Envelope::new(span_s, samples)),
            loops: Vec::with_capacity(samples.div_ceil(stride)),
            stride,
            samples: 0,
            span_s,
            expected: samples,
            specimen: Vec::new(),
            command: None,
            system: Vec::new(),
            zoom: Vec::new(),
        }
    }
}

impl SampleSink for RunRecorder<'_> {
    fn accept(&mut self, s: &Sample) {
        let terms = &s.terms;
        let values = [
            s.u_m,
            s.v_m_s,
            s.a_m_s2,
            terms.actuator_n,
            terms.inertial_n,
            terms.elastic_n,
            terms.dissipative_n,
        ];
        for (channel, y) in self.channels.iter_mut().zip(values) {
            channel.push(self.samples, s.t_s, y);
        }
        if let Some(sp) = &s.specimen {
            if self.specimen.is_empty() {
                self.specimen = (0..=sp.storeys)
                    .map(|_| Envelope::new(self.span_s, self.expected))
                    .collect();
            }
            let values =
                std::iter::once(sp.base_shear_n).chain(sp.drift_m[..sp.storeys].iter().copied());
            for (channel, y) in self.specimen.iter_mut().zip(values) {
                channel.push(self.samples, s.t_s, y);
            }
        }
        if let Some(sys) = &s.system {
            if self.system.is_empty() {
                self.system = (0..LOOP_CHANNELS)
                    .map(|_| Envelope::new(self.span_s, self.expected))
                    .collect();
            }
            let a_ref = self
                .command
                .as_ref()
                .and_then(|c| c.a_m_s2.get(s.index))
                .copied()
                .unwrap_or(f64::NAN);
            let mut values = [0.0; LOOP_CHANNELS];
            values[CMD_U] = sys.command_u_m;
            values[ERR_U] = s.u_m - sys.command_u_m;
            values[CMD_A] = a_ref;
            values[ERR_A] = s.a_m_s2 - a_ref;
            values[DRIVE] = sys.drive;
            values[SPOOL] = sys.spool_opening;
            values[DELTA_P] = sys.delta_p_pa;
            values[P_A] = sys.p_a_pa;
            values[P_B] = sys.p_b_pa;
            values[FLOW] = sys.flow_m3_s;
            values[SUPPLY] = sys.supply_pressure_pa;
            for (channel, y) in self.system.iter_mut().zip(values) {
                channel.push(self.samples, s.t_s, y);
            }
            if let Some(c) = &self.command {
                if s.t_s >= c.zoom_s.0 && s.t_s <= c.zoom_s.1 {
                    self.zoom
                        .push([s.t_s, s.u_m, s.a_m_s2, sys.command_u_m, a_ref]);
                }
            }
        }
        if self.samples % self.stride == 0 {
            self.loops
                .push([s.u_m, s.v_m_s, s.a_m_s2, terms.actuator_n]);
        }
        self.samples += 1;
    }
}

/// What a recorder kept, in display units.
struct Recorded {
    /// Envelopes: u (m), v (m/s), a (m/s²), F_A, F_I, F_E, F_D (kN).
    channels: Vec<Points>,
    loops: Vec<[f64; 4]>,
    stride: usize,
    samples: usize,
    /// Base shear (kN) and storey drifts (mm), for a run with a specimen.
    specimen: Vec<Points>,
}

/// A channel of a run: name, symbol, unit, display scale, its limit (SI) if the table has one.
struct Channel {
    quantity: &'static str,
    symbol: &'static str,
    unit: &'static str,
    limit: Option<f64>,
    /// What the limit is, in its legend entry (`table limit`).
    limit_name: &'static str,
    /// The limit's lines are drawn when the peak reaches this fraction of it.
    limit_shown_from: f64,
}

/// The figures of a run: the motion and force over time, the force decomposition, the
/// hysteresis loops, and those of the specimen and of the closed loop when the run has them.
/// `scenario` gives the name, the table's limits and the table system.
pub fn figures(recorder: RunRecorder<'_>, scenario: &PlatenScenario) -> Vec<Figure> {
    let stride = recorder.stride;
    let samples = recorder.samples;
    let closed_loop = match (&scenario.run, &scenario.rig.table_system, &recorder.command) {
        (Run::ClosedLoop { .. }, Some(system), Some(command)) if !recorder.system.is_empty() => {
            Some(LoopRecord {
                system: *system,
                channels: recorder.system.into_iter().map(Envelope::finish).collect(),
                zoom_s: command.zoom_s,
                zoom: recorder.zoom,
            })
        }
        _ => None,
    };
    let kn = [false, false, false, true, true, true, true];
    let channels: Vec<Points> = recorder
        .channels
        .into_iter()
        .zip(kn)
        .map(|(c, in_kn)| {
            let mut points = c.finish();
            if in_kn {
                for p in &mut points {
                    p.1 *= 1e-3;
                }
            }
            points
        })
        .collect();
    let specimen = recorder
        .specimen
        .into_iter()
        .enumerate()
        .map(|(i, c)| {
            // Base shear in kN, drifts in mm.
            let scale = if i == 0 { 1e-3 } else { 1e3 };
            c.finish()
                .into_iter()
                .map(|(t, y)| (t, y * scale))
                .collect()
        })
        .collect();
    let r = Recorded {
        channels,
        loops: recorder.loops,
        stride,
        samples,
        specimen,
    };
    if r.samples == 0 {
        return Vec::new();
    }
    let mut out = vec![
        motion(&r, scenario),
        decomposition(&r, scenario),
        hysteresis(&r, scenario),
    ];
    if !r.specimen.is_empty() {
        out.push(specimen_figure(&r, scenario));
    }
    if let Some(lo) = &closed_loop {
        out.extend(loop_figures(&r, lo, scenario));
    }
    out
}

/// The specimen's base shear and storey drifts over time (a run with a specimen).
fn specimen_figure(r: &Recorded, scenario: &PlatenScenario) -> Figure {
    let storeys = r.specimen.len() - 1;
    let panels: Vec<Panel> = r
        .specimen
        .iter()
        .enumerate()
        .map(|(i, points)| {
            let (quantity, symbol, unit) = if i == 0 {
                ("base shear".to_string(), "B".to_string(), "kN")
            } else {
                (format!("storey {i} drift"), format!("d_{i}"), "mm")
            };
            Panel {
                x_range: Some(span(points)),
                ..Panel::new(
                    format!(
                        "{quantity} {symbol}: peak |{symbol}| {} {unit}",
                        significant(peak_magnitude(points), 4)
                    ),
                    "time t (s)",
                    format!("{symbol} ({unit})"),
                    vec![line("", points.clone(), SIMULATED, 1)],
                )
            }
        })
        .collect();
    let height = if storeys > 3 { 240 } else { 300 } * panels.len() as u32 + 120;
    Figure {
        name: "specimen".into(),
        title: format!(
            "{}: the specimen's base shear and storey drifts",
            scenario.name
        ),
        caption: format!(
            "Base shear B (the force the platen exerts on the specimen, part of the actuator \
             force F_A = F_I + F_E + F_D + B) and the drift d_i = z_i − z_(i−1) of each of the \
             {storeys} storey(s) over time ({} samples; the smallest and largest sample of each \
             of {BUCKETS} equal time intervals).",
            r.samples
        ),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1200, height),
    }
}

/// The largest magnitude of the points' values.
fn peak_magnitude(points: &Points) -> f64 {
    points.iter().map(|p| p.1.abs()).fold(0.0, f64::max)
}

/// The time span of the points (the first and last sample).
fn span(points: &Points) -> (f64, f64) {
    match (points.first(), points.last()) {
        (Some(a), Some(b)) if b.0 > a.0 => (a.0, b.0),
        (Some(a), _) => (a.0 - 0.5, a.0 + 0.5),
        _ => (0.0, 1.0),
    }
}

/// A time-history panel of one channel, with the table's ±limit when the peak comes near it.
fn channel_panel(c: &Channel, points: &Points, color: plotters::style::RGBColor) -> Panel {
    let peak = peak_magnitude(points);
    let t = span(points);
    // " m", or nothing for a dimensionless channel.
    let unit = if c.unit.is_empty() {
        String::new()
    } else {
        format!(" {}", c.unit)
    };
    let mut series = vec![line("", points.clone(), color, 1)];
    let mut title = format!(
        "{} {}: peak |{}| {}{unit}",
        c.quantity,
        c.symbol,
        c.symbol,
        significant(peak, 4),
    );
    if let Some(limit) = c
        .limit
        .filter(|l| *l > 0.0 && peak >= c.limit_shown_from * l)
    {
        series.push(patterned(
            format!(
                "{} ±{}{unit}",
                c.limit_name,
                crate::sweep_figures::limit_text(limit),
            ),
            vec![(t.0, limit), (t.1, limit)],
            MODEL,
            2,
            Dash::Dashed,
        ));
        series.push(patterned(
            "",
            vec![(t.0, -limit), (t.1, -limit)],
            MODEL,
            2,
            Dash::Dashed,
        ));
        if peak > limit {
            title.push_str(" (EXCEEDS the limit)");
        }
    }
    let y_label = if c.unit.is_empty() {
        c.symbol.to_owned()
    } else {
        format!("{} ({})", c.symbol, c.unit)
    };
    Panel {
        x_range: Some(t),
        ..Panel::new(title, "time t (s)", y_label, series)
    }
}

/// u, v, a and F_A over time.
fn motion(r: &Recorded, scenario: &PlatenScenario) -> Figure {
    let l: &TableLimits = &scenario.rig.limits;
    let channels = [
        ("displacement", "u", "m", Some(l.stroke_m)),
        ("velocity", "v", "m/s", Some(l.velocity_m_s)),
        ("acceleration", "a", "m/s²", Some(l.acceleration_m_s2)),
        ("actuator force", "F_A", "kN", Some(l.force_n * 1e-3)),
    ];
    let panels = channels
        .iter()
        .zip(&r.channels)
        .map(|(&(quantity, symbol, unit, limit), points)| {
            channel_panel(
                &Channel {
                    quantity,
                    symbol,
                    unit,
                    limit,
                    limit_name: "table limit",
                    limit_shown_from: LIMIT_SHOWN_FROM,
                },
                points,
                SIMULATED,
            )
        })
        .collect();
    Figure {
        name: "time-history".into(),
        title: format!("{}: motion and actuator force", scenario.name),
        caption: format!(
            "Displacement, velocity, acceleration and actuator force of the run ({} samples; \
             the smallest and largest sample of each of {BUCKETS} equal time intervals), \
             with the table's limits (dashed) where a peak reaches {:.0} % of one.",
            r.samples,
            100.0 * LIMIT_SHOWN_FROM
        ),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1200, 1200),
    }
}

/// F_A and its decomposition F_I + F_E + F_D over time, each on its own scale.
fn decomposition(r: &Recorded, scenario: &PlatenScenario) -> Figure {
    let actuator = peak_magnitude(&r.channels[3]);
    let terms = [
        ("actuator force", "F_A", 3),
        ("inertial force", "F_I", 4),
        ("elastic force", "F_E", 5),
        ("dissipative force", "F_D", 6),
    ];
    let panels = terms
        .iter()
        .map(|&(quantity, symbol, i)| {
            let points = &r.channels[i];
            let peak = peak_magnitude(points);
            let share = if actuator > 0.0 && i != 3 {
                format!(" ({:.1} % of |F_A|'s)", 100.0 * peak / actuator)
            } else {
                String::new()
            };
            Panel {
                x_range: Some(span(points)),
                ..Panel::new(
                    format!(
                        "{quantity} {symbol}: peak |{symbol}| {} kN{share}",
                        significant(peak, 4)
                    ),
                    "time t (s)",
                    format!("{symbol} (kN)"),
                    vec![line("", points.clone(), SIMULATED, 1)],
                )
            }
        })
        .collect();
    Figure {
        name: "force-decomposition".into(),
        title: format!("{}: actuator force F_A = F_I + F_E + F_D", scenario.name),
        caption: "The actuator force and its inertial, elastic and dissipative parts over \
                  time, each on its own scale (its peak, and its share of the actuator's, \
                  in the panel's title)."
            .into(),
        panels,
        columns: 1,
        rows: Vec::new(),
        size: (1200, 1200),
    }
}

/// F_A against u, v and a.
fn hysteresis(r: &Recorded, scenario: &PlatenScenario) -> Figure {
    let panels = [
        ("displacement", "u", "m"),
        ("velocity", "v", "m/s"),
        ("acceleration", "a", "m/s²"),
    ]
    .iter()
    .enumerate()
    .map(|(i, &(quantity, symbol, unit))| {
        let points = r.loops.iter().map(|s| (s[i], s[3] * 1e-3)).collect();
        Panel::new(
            format!("Actuator force against {quantity}"),
            format!("{quantity} {symbol} ({unit})"),
            "actuator force F_A (kN)",
            vec![line("", points, SIMULATED, 1)],
        )
    })
    .collect();
    let thinning = if r.stride > 1 {
        format!(" ({} drawn)", every(r.stride))
    } else {
        String::new()
    };
    Figure {
        name: "hysteresis".into(),
        title: format!("{}: actuator force against the motion", scenario.name),
        caption: format!(
            "Actuator force against displacement, velocity and acceleration over the whole \
             run{thinning}."
        ),
        panels,
        columns: 3,
        rows: Vec::new(),
        size: (1260, 520),
    }
}

/// What a recorder kept of a closed-loop run (SI units).
struct LoopRecord {
    /// The table system.
    system: TableSystem,
    /// Envelopes of the loop's channels (`CMD_U` … `SUPPLY`).
    channels: Vec<Points>,
    /// The zoomed interval, s.
    zoom_s: (f64, f64),
    /// Every sample inside it: `(t, u, a, u_ref, a_ref)`.
    zoom: Vec<[f64; 5]>,
}

/// `points` with every value times `k`.
fn times(points: &Points, k: f64) -> Points {
    points.iter().map(|&(t, y)| (t, y * k)).collect()
}

/// The smallest value of the points.
fn lowest(points: &Points) -> f64 {
    points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min)
}

/// The figures of a closed-loop run: tracking, tracking errors, valve, pressures, flow,
/// supply.
fn loop_figures(r: &Recorded, lo: &LoopRecord, scenario: &PlatenScenario) -> Vec<Figure> {
    vec![
        tracking(r, lo, scenario),
        tracking_errors(r, lo, scenario),
        valve(lo, scenario),
        pressures(lo, scenario),
        flow(lo, scenario),
        supply(&times(&lo.channels[SUPPLY], 1e-6), &lo.system, scenario),
    ]
}

/// A channel without a limit, in `unit`.
fn unlimited(quantity: &'static str, symbol: &'static str, unit: &'static str) -> Channel {
    Channel {
        quantity,
        symbol,
        unit,
        limit: None,
        limit_name: "",
        limit_shown_from: 1.0,
    }
}

/// The displacement and acceleration errors of the closed loop.
fn tracking_errors(r: &Recorded, lo: &LoopRecord, scenario: &PlatenScenario) -> Figure {
    let c = &lo.channels;
    Figure {
        name: "tracking-error".into(),
        title: format!("{}: tracking errors (achieved − command)", scenario.name),
        caption: format!(
            "The displacement error u − u_ref (mm) and the acceleration error a − a_ref \
             (m/s²) of the closed loop over the run ({} samples; the smallest and largest \
             sample of each of {BUCKETS} equal time intervals).",
            r.samples
        ),
        panels: vec![
            channel_panel(
                &unlimited("displacement error", "u − u_ref", "mm"),
                &times(&c[ERR_U], 1e3),
                RESIDUAL,
            ),
            channel_panel(
                &unlimited("acceleration error", "a − a_ref", "m/s²"),
                &c[ERR_A],
                RESIDUAL,
            ),
        ],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 800),
    }
}

/// The controller's drive and the spool opening, fractions of full opening.
fn valve(lo: &LoopRecord, scenario: &PlatenScenario) -> Figure {
    let full = |quantity, symbol| Channel {
        quantity,
        symbol,
        unit: "",
        limit: Some(1.0),
        limit_name: "full opening",
        limit_shown_from: LIMIT_SHOWN_FROM,
    };
    Figure {
        name: "valve".into(),
        title: format!("{}: drive and spool opening", scenario.name),
        caption: format!(
            "The controller's drive d (held between its samples, |d| ≤ 1) and the spool \
             opening x_v the valves' flow sees (clamped to ±1), fractions of full opening, \
             with ±1 (dashed) where a peak reaches {:.0} % of it.",
            100.0 * LIMIT_SHOWN_FROM
        ),
        panels: [("drive", "d", DRIVE), ("spool opening", "x_v", SPOOL)]
            .iter()
            .map(|&(quantity, symbol, i)| Panel {
                y_label: format!("{symbol} (1 = full opening)"),
                ..channel_panel(&full(quantity, symbol), &lo.channels[i], SIMULATED)
            })
            .collect(),
        columns: 1,
        rows: Vec::new(),
        size: (1200, 800),
    }
}

/// The pressure difference across the pistons and the chambers' absolute pressures.
fn pressures(lo: &LoopRecord, scenario: &PlatenScenario) -> Figure {
    let c = &lo.channels;
    let mut dp = channel_panel(
        &unlimited("pressure difference", "Δp", "MPa"),
        &times(&c[DELTA_P], 1e-6),
        SIMULATED,
    );
    dp.y_label = "Δp = p_a − p_b (MPa)".into();
    let (p_a, p_b) = (times(&c[P_A], 1e-6), times(&c[P_B], 1e-6));
    let floor = lowest(&p_a).min(lowest(&p_b));
    let chambers = Panel {
        x_range: Some(span(&p_a)),
        ..Panel::new(
            format!(
                "chamber pressures (absolute): lowest {} MPa{}",
                significant(floor, 4),
                if floor <= 0.0 { " (CAVITATION)" } else { "" }
            ),
            "time t (s)",
            "pressure p (MPa)",
            vec![
                line("p_a (cap side)", p_a, SIMULATED, 1),
                patterned("p_b (rod side)", p_b, RESIDUAL, 1, Dash::Dashed),
            ],
        )
    };
    Figure {
        name: "pressure-difference".into(),
        title: format!("{}: actuator chamber pressures", scenario.name),
        caption: "The pressure difference Δp = p_a − p_b across the pistons, and the \
                  absolute pressures of the cap-side and rod-side chambers (a chamber at 0 \
                  cavitates), over time."
            .into(),
        panels: vec![dp, chambers],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 800),
    }
}

/// The valves' flow against their capacity.
fn flow(lo: &LoopRecord, scenario: &PlatenScenario) -> Figure {
    let c = &lo.channels;
    let capacity = lo.system.capacities().valve_flow_m3_s;
    let mut panel = channel_panel(
        &Channel {
            quantity: "valve flow",
            symbol: "Q",
            unit: "m³/s",
            limit: Some(capacity),
            limit_name: "valve capacity",
            limit_shown_from: 0.0,
        },
        &c[FLOW],
        SIMULATED,
    );
    panel.title.push_str(&format!(
        ", {:.0} % of the capacity",
        100.0 * peak_magnitude(&c[FLOW]) / capacity
    ));
    Figure {
        name: "flow".into(),
        title: format!("{}: valve flow against the valves' capacity", scenario.name),
        caption: "The flow of all servo-valves into the cap-side chambers (negative: out of \
                  them) over time, against the valves' capacity ±Q_max (dashed): their flow \
                  at full opening with the null pressure drop on each land."
            .into(),
        panels: vec![panel],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 520),
    }
}

/// The command and the achieved displacement and acceleration, whole and zoomed.
fn tracking(r: &Recorded, lo: &LoopRecord, scenario: &PlatenScenario) -> Figure {
    let c = &lo.channels;
    let (u, a) = (&r.channels[0], &r.channels[2]);
    let whole = span(u);
    let (z0, z1) = lo.zoom_s;
    let t: Vec<f64> = lo.zoom.iter().map(|z| z[0]).collect();
    let zoomed = |k: usize| -> Points {
        let y: Vec<f64> = lo.zoom.iter().map(|z| z[k]).collect();
        envelope(&t, &y, lo.zoom_s, BUCKETS)
    };
    let pair = |command: Points, achieved: Points| {
        vec![
            line("command", command, RECORDED, 4),
            patterned("achieved (simulated)", achieved, SIMULATED, 2, Dash::Dashed),
        ]
    };
    let mut panels = Vec::new();
    for (quantity, symbol, unit, achieved, command, k) in [
        ("displacement", "u", "m", u, &c[CMD_U], 1),
        ("acceleration", "a", "m/s²", a, &c[CMD_A], 2),
    ] {
        panels.push(Panel {
            x_range: Some(whole),
            shade_x: (!lo.zoom.is_empty()).then_some(lo.zoom_s),
            ..Panel::new(
                format!(
                    "{quantity}, whole run: peak |{symbol}_ref| {} {unit}, peak |{symbol}| {} {unit}",
                    significant(peak_magnitude(command), 4),
                    significant(peak_magnitude(achieved), 4)
                ),
                "time t (s)",
                format!("{quantity} {symbol} ({unit})"),
                pair(command.clone(), achieved.clone()),
            )
        });
        if !lo.zoom.is_empty() {
            panels.push(Panel {
                x_range: Some((z0, z1)),
                ..Panel::new(
                    format!(
                        "{quantity}, zoom {z0:.2}–{z1:.2} s (around the command's largest \
                         acceleration)"
                    ),
                    "time t (s)",
                    format!("{quantity} {symbol} ({unit})"),
                    pair(zoomed(k + 2), zoomed(k)),
                )
            });
        }
    }
    Figure {
        name: "tracking".into(),
        title: format!("{}: command and achieved motion", scenario.name),
        caption: format!(
            "The displacement command u_ref and its acceleration a_ref (solid blue, drawn \
             wider) and the table's displacement u and acceleration a (dashed orange, on top), \
             over the whole run ({} samples; the smallest and largest sample of each of \
             {BUCKETS} equal time intervals) and zoomed on {:.2} s around the command's largest \
             acceleration (shaded above).",
            r.samples,
            z1 - z0
        ),
        columns: 1,
        rows: Vec::new(),
        size: (1200, 300 * panels.len() as u32 + 160),
        panels,
    }
}

/// The supply pressure over time (MPa), with the set pressure.
fn supply(points: &Points, system: &TableSystem, scenario: &PlatenScenario) -> Figure {
    let set = system.supply_pressure_pa() * 1e-6;
    let t = span(points);
    let kind = match system.supply() {
        Supply::Constant => "constant supply",
        Supply::Accumulator(_) => "accumulator bank",
    };
    Figure {
        name: "supply-pressure".into(),
        title: format!("{}: supply pressure", scenario.name),
        caption: "The pressure the valves draw their oil from over time: constant, or an \
                  accumulator bank's, which droops while the valves draw more than the pumps \
                  give; the pumps' set pressure dashed."
            .into(),
        panels: vec![Panel {
            x_range: Some(t),
            ..Panel::new(
                format!(
                    "supply pressure P_s ({kind}): lowest {} MPa",
                    significant(lowest(points), 4)
                ),
                "time t (s)",
                "P_s (MPa)",
                vec![
                    line("", points.clone(), SIMULATED, 1),
                    patterned(
                        format!("set pressure {} MPa", crate::sweep_figures::limit_text(set)),
                        vec![(t.0, set), (t.1, set)],
                        MODEL,
                        2,
                        Dash::Dashed,
                    ),
                ],
            )
        }],
        columns: 1,
        rows: Vec::new(),
        size: (1200, 520),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::series::envelope;

    /// The envelope built sample by sample is the one `envelope` picks from the whole
    /// record, ties included (a flat stretch, repeated extremes), for records longer and
    /// shorter than `2·BUCKETS`.
    #[test]
    fn online_envelope_is_the_batch_envelope() {
        for n in [10, 2 * BUCKETS, 2 * BUCKETS + 1, 7919, 50_000] {
            let t: Vec<f64> = (0..n).map(|i| 0.25 + i as f64 / 1024.0).collect();
            let y: Vec<f64> = (0..n)
                .map(|i| {
                    let x = i as f64 / 1024.0;
                    // Rounded, so that equal values (ties) occur within buckets.
                    ((3.0 * x).sin() * 40.0 + (17.0 * x).cos() * 9.0).round()
                })
                .collect();
            let span = (t[0], t[n - 1]);
            let mut online = Envelope::new(span, n);
            for (i, (&ti, &yi)) in t.iter().zip(&y).enumerate() {
                online.push(i, ti, yi);
            }
            assert_eq!(online.finish(), envelope(&t, &y, span, BUCKETS), "n = {n}");
        }
    }
}
