//! The figures of a run without a recording (`platen simulate SCENARIO --plot DIR`): the
//! motion and the actuator force over time, the force decomposition over time, and the
//! hysteresis loops (actuator force against displacement, velocity and acceleration), and for
//! a run with a specimen its base shear and storey drifts over time.
//!
//! A [`RunRecorder`] is a [`SampleSink`] that keeps, while the run goes, only what the
//! figures draw: per channel the smallest and largest sample of each of [`BUCKETS`] equal
//! time buckets (the same points [`envelope`](crate::series::envelope) picks from the whole
//! record), and every k-th sample for the loops. Its memory does not grow with the run's
//! length, so a one-hour run can be plotted as it streams to CSV.

use platen_integrate::{Sample, SampleSink};
use platen_model::TableLimits;
use platen_scenario::{Run, Scenario};

use crate::figure::{Dash, Figure, Panel, MODEL, SIMULATED};
use crate::series::{every, line, patterned, Points, MAX_LOOP_POINTS};
use crate::text::significant;

/// Time buckets of the envelopes (about the pixels of a full-width panel).
pub const BUCKETS: usize = 1100;

/// A peak at least this fraction of its table limit draws the limit's lines (below it the
/// lines would stretch the axis far beyond the data: at most 1/0.6 ≈ 1.7 times).
const LIMIT_SHOWN_FROM: f64 = 0.6;

/// The envelope of one channel, built one sample at a time.
#[derive(Debug, Clone)]
struct Envelope {
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
    fn new(span_s: (f64, f64), samples: usize) -> Self {
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

    fn push(&mut self, index: usize, t: f64, y: f64) {
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

    fn finish(mut self) -> Points {
        self.flush();
        self.points
    }
}

/// Collects, while a run goes, what its figures draw (see the module's documentation).
#[derive(Debug, Clone)]
pub struct RunRecorder {
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
}

impl RunRecorder {
    /// A recorder for `run` (its time span and sample count are known before it runs).
    pub fn new(run: &Run) -> Self {
        let samples = match run {
            Run::Forward { samples, .. } => *samples,
            Run::Inverse { motion } => motion.len(),
        };
        Self::with_span(run.time_span_s(), samples)
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
        }
    }
}

impl SampleSink for RunRecorder {
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
}

/// The figures of a run: the motion and force over time, the force decomposition, the
/// hysteresis loops. `scenario` gives the name and the table's limits.
pub fn figures(recorder: RunRecorder, scenario: &Scenario) -> Vec<Figure> {
    let stride = recorder.stride;
    let samples = recorder.samples;
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
    out
}

/// The specimen's base shear and storey drifts over time (a run with a specimen).
fn specimen_figure(r: &Recorded, scenario: &Scenario) -> Figure {
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
    let mut series = vec![line("", points.clone(), color, 1)];
    let mut title = format!(
        "{} {}: peak |{}| {} {}",
        c.quantity,
        c.symbol,
        c.symbol,
        significant(peak, 4),
        c.unit
    );
    if let Some(limit) = c.limit.filter(|l| *l > 0.0 && peak >= LIMIT_SHOWN_FROM * l) {
        series.push(patterned(
            format!(
                "table limit ±{} {}",
                crate::sweep_figures::limit_text(limit),
                c.unit
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
    Panel {
        x_range: Some(t),
        ..Panel::new(
            title,
            "time t (s)",
            format!("{} ({})", c.symbol, c.unit),
            series,
        )
    }
}

/// u, v, a and F_A over time.
fn motion(r: &Recorded, scenario: &Scenario) -> Figure {
    let l: &TableLimits = &scenario.limits;
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
fn decomposition(r: &Recorded, scenario: &Scenario) -> Figure {
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
fn hysteresis(r: &Recorded, scenario: &Scenario) -> Figure {
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
