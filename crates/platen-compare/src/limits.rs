//! The recording itself against the table's limits: did the recorded motion or force go
//! beyond the stroke, velocity, acceleration or force the table is rated for?

use platen_model::TableLimits;
use serde::Serialize;

use crate::Recording;

/// One of the table's four limits, and the recorded column it bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum TableLimit {
    /// Displacement stroke `stroke_m`, bounding `u_m`.
    Stroke,
    /// Peak velocity `velocity_m_s`, bounding `v_m_s`.
    Velocity,
    /// Peak acceleration `acceleration_m_s2`, bounding `a_m_s2`.
    Acceleration,
    /// Actuator force capacity `force_n`, bounding `force_n`.
    Force,
}

impl TableLimit {
    /// The four limits, in report order.
    pub const ALL: [TableLimit; 4] = [
        TableLimit::Stroke,
        TableLimit::Velocity,
        TableLimit::Acceleration,
        TableLimit::Force,
    ];

    /// The limit's key, as in a scenario's `limits` and simulate's summary: `"stroke_m"`,
    /// `"velocity_m_s"`, `"acceleration_m_s2"` or `"force_n"`.
    pub fn key(self) -> &'static str {
        match self {
            TableLimit::Stroke => "stroke_m",
            TableLimit::Velocity => "velocity_m_s",
            TableLimit::Acceleration => "acceleration_m_s2",
            TableLimit::Force => "force_n",
        }
    }

    /// The recorded column it bounds: `"u_m"`, `"v_m_s"`, `"a_m_s2"` or `"force_n"`.
    pub fn column(self) -> &'static str {
        match self {
            TableLimit::Stroke => "u_m",
            TableLimit::Velocity => "v_m_s",
            TableLimit::Acceleration => "a_m_s2",
            TableLimit::Force => "force_n",
        }
    }

    /// The plain name: `"stroke"`, `"velocity"`, `"acceleration"` or `"force"`.
    pub fn quantity(self) -> &'static str {
        match self {
            TableLimit::Stroke => "stroke",
            TableLimit::Velocity => "velocity",
            TableLimit::Acceleration => "acceleration",
            TableLimit::Force => "force",
        }
    }

    /// The SI unit: `"m"`, `"m/s"`, `"m/s²"` or `"N"`.
    pub fn unit(self) -> &'static str {
        match self {
            TableLimit::Stroke => "m",
            TableLimit::Velocity => "m/s",
            TableLimit::Acceleration => "m/s²",
            TableLimit::Force => "N",
        }
    }

    /// This limit's value in `limits`, SI unit.
    pub fn of(self, limits: &TableLimits) -> f64 {
        match self {
            TableLimit::Stroke => limits.stroke_m,
            TableLimit::Velocity => limits.velocity_m_s,
            TableLimit::Acceleration => limits.acceleration_m_s2,
            TableLimit::Force => limits.force_n,
        }
    }
}

/// One table limit against the recording's own column (`platen compare`'s
/// `recorded_limits.<key>`), over the whole record. Only a column the file has is checked:
/// no substitute (a velocity estimated from the displacement, the simulated force) counts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordedLimitCheck {
    /// Which limit.
    #[serde(skip)]
    pub kind: TableLimit,
    /// The recorded column checked ([`TableLimit::column`]).
    pub column: &'static str,
    /// The limit (the scenario's preset's, with its `limits` laid over), SI unit.
    pub limit: f64,
    /// The recording's signed peak (largest magnitude, first if repeated), SI unit.
    pub peak: f64,
    /// When the peak was recorded, s.
    pub peak_t_s: f64,
    /// Whether |peak| ≤ limit.
    pub respected: bool,
    /// The time stamp of the first recorded sample beyond the limit (|value| > limit), s;
    /// `None` when the limit is respected.
    pub first_exceeded_s: Option<f64>,
    /// Time spent beyond the limit, s: the number of recorded samples with |value| > limit
    /// times the sample interval (each sample standing for its interval); 0 when respected.
    pub time_exceeded_s: f64,
}

impl RecordedLimitCheck {
    /// Checks `values`, recorded at `t_s` every `step_s` seconds, against `limit`; `None`
    /// for an empty column.
    pub fn new(
        kind: TableLimit,
        limit: f64,
        t_s: &[f64],
        values: &[f64],
        step_s: f64,
    ) -> Option<Self> {
        let mut peak: Option<(f64, f64)> = None;
        let mut first_exceeded_s = None;
        let mut beyond = 0usize;
        for (&t, &x) in t_s.iter().zip(values) {
            if peak.is_none_or(|(p, _)| x.abs() > p.abs()) {
                peak = Some((x, t));
            }
            if x.abs() > limit {
                beyond += 1;
                first_exceeded_s.get_or_insert(t);
            }
        }
        let (peak, peak_t_s) = peak?;
        Some(Self {
            kind,
            column: kind.column(),
            limit,
            peak,
            peak_t_s,
            respected: peak.abs() <= limit,
            first_exceeded_s,
            time_exceeded_s: beyond as f64 * step_s,
        })
    }

    /// Every limit the recording has a column for, in [`TableLimit::ALL`] order.
    pub fn of_recording(recording: &Recording, limits: &TableLimits) -> Vec<Self> {
        TableLimit::ALL
            .into_iter()
            .filter_map(|kind| {
                let values = recording.table.column(kind.column())?;
                Self::new(
                    kind,
                    kind.of(limits),
                    &recording.t_s,
                    values,
                    recording.step_s,
                )
            })
            .collect()
    }

    /// The warning for a limit the recording exceeds (`None` when it is respected), e.g.
    /// "the recording's u_m reaches +0.8125 m at 12.300 s, beyond the table's stroke of
    /// 0.75 m (limits.stroke_m): first beyond it at 11.902 s, 0.4219 s beyond it in all".
    pub fn warning(&self) -> Option<String> {
        let first = self.first_exceeded_s?;
        let unit = self.kind.unit();
        Some(format!(
            "the recording's {} reaches {:+} {unit} at {:.3} s, beyond the table's {} of {} \
             {unit} (limits.{}): first beyond it at {first:.3} s, {} s beyond it in all",
            self.column,
            self.peak,
            self.peak_t_s,
            self.kind.quantity(),
            self.limit,
            self.kind.key(),
            self.time_exceeded_s,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Peak, first exceedance and time beyond of a hand-made series, worked out by hand.
    #[test]
    fn a_series_beyond_its_limit_reports_its_peak_first_time_and_duration() {
        let t = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5];
        let x = [0.1, 0.8, -0.9, 0.2, 0.76, -0.9];
        let c = RecordedLimitCheck::new(TableLimit::Stroke, 0.75, &t, &x, 0.5).unwrap();
        assert_eq!((c.peak, c.peak_t_s), (-0.9, 1.0), "first of the tied peaks");
        assert!(!c.respected);
        assert_eq!(c.first_exceeded_s, Some(0.5));
        assert_eq!(c.time_exceeded_s, 4.0 * 0.5);
        let w = c.warning().unwrap();
        for part in [
            "u_m reaches -0.9 m at 1.000 s",
            "stroke of 0.75 m",
            "at 0.500 s",
        ] {
            assert!(w.contains(part), "`{part}` not in {w}");
        }
    }

    /// A series that touches its limit exactly respects it (|peak| ≤ limit, as simulate).
    #[test]
    fn a_series_at_its_limit_respects_it() {
        let c = RecordedLimitCheck::new(TableLimit::Force, 2.0, &[0.0, 1.0], &[-2.0, 1.0], 1.0)
            .unwrap();
        assert!(c.respected);
        assert_eq!(c.first_exceeded_s, None);
        assert_eq!(c.time_exceeded_s, 0.0);
        assert_eq!(c.warning(), None);
        assert!(RecordedLimitCheck::new(TableLimit::Force, 2.0, &[], &[], 1.0).is_none());
    }
}
