//! Channel skew in closed-loop records: a data system that samples or filters a channel
//! later than another (a few samples is common) biases every fit that puts the two in one
//! equation. Measured and corrected before the fits, one delay per channel for the whole set
//! of records (they come from one data system):
//!
//! * **Table acceleration** `a_m_s2`: its delay against the second derivative of the
//!   displacement ([`platen_signal::DelayEstimator::acceleration_against_displacement`]) in
//!   each fitted record, pooled by inverse variance (significance); each record is then
//!   corrected by its own delay where that is precise ([`PER_RECORD_MAX_SE_SAMPLES`]: a data
//!   system's skew varies from record to record), else by the pooled one. The storeys'
//!   accelerations are taken to share it (the same data path; nothing in the records holds their motion independently
//!   of their own dynamics). Applied when beyond [`SIGNIFICANT`] standard errors and
//!   [`MIN_APPLIED_SAMPLES`] of a sample, as the any-record method applies it.
//! * **Pressures** (`delta_p_pa`, or the two chamber pressures together): their delay is the
//!   one that makes the platen's force balance fit best, a grid of
//!   [`PRESSURE_SHIFT_GRID`] then a parabola through the best three (the force's relation
//!   to the motion is the very model being fitted, so no spectral estimate is unbiased for
//!   it).
//!
//! Every channel is shifted with [`platen_signal::advance`] (band-limited, to a fraction of a
//! sample), and every estimate is reported ([`ChannelSkew`]), applied or not.

use platen_signal::{advance, DelayEstimator};

use super::SystemRecord;
use crate::error::{IdentError, Result};

/// An estimated acceleration delay is applied only beyond this many standard errors.
pub const SIGNIFICANT: f64 = 3.0;
/// An estimated delay is applied only beyond this fraction of a sample.
pub const MIN_APPLIED_SAMPLES: f64 = 0.1;
/// A pressure delay found by the force balance is applied only when it cuts the balance's
/// residual sum of squares to this fraction of the residual without it or less: a skew of the
/// data system shows plainly there (on the small table's records a 1-sample skew of `Δp` gives
/// 0.003 of the unshifted residual), while a force model that the records do not fit (`Δp` of a
/// single-ended actuator read as a double-ended one) moves the best shift by a fraction of a
/// sample, −0.73 on `tests/data/system_ident`'s records mapped that way, for a
/// residual 0.999 of the unshifted, and correcting by it would only move
/// its error into the gains.
pub const PRESSURE_SKEW_MAX_RESIDUAL_RATIO: f64 = 0.8;

/// The pressure shifts tried, samples (then refined by a parabola).
pub const PRESSURE_SHIFT_GRID: [f64; 13] = [
    -3.0, -2.5, -2.0, -1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0,
];

/// A channel's delay against the displacement, measured on the records.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChannelSkew {
    /// The channel (`a_m_s2`, `delta_p_pa`, …).
    pub column: String,
    /// The delay, s (positive: the channel lags `u_m`).
    pub delay_s: f64,
    /// Its standard error, s (absent for the force-balance estimate of the pressures).
    pub std_error_s: Option<f64>,
    /// The delay in samples.
    pub delay_samples: f64,
    /// Whether the channels were corrected by it.
    pub applied: bool,
    /// For the force-balance estimate: the fit's residual sum of squares at the delay over
    /// that at none.
    pub residual_ratio: Option<f64>,
    /// How it was found.
    pub method: &'static str,
    /// Each record's own delay where it was measured apart (the table's acceleration: a data
    /// system's skew varies from record to record), and what was applied to it.
    pub per_record: Vec<RecordSkew>,
}

/// One record's own delay of a channel ([`ChannelSkew::per_record`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RecordSkew {
    /// The record's name.
    pub name: String,
    /// Its own estimate, samples (absent when the record is too short or still for one).
    pub delay_samples: Option<f64>,
    /// That estimate's standard error, samples.
    pub std_error_samples: Option<f64>,
    /// The delay the record was corrected by, samples: its own when it is within
    /// [`PER_RECORD_MAX_SE_SAMPLES`], else the pooled one (0 when none was applied).
    pub applied_samples: f64,
}

/// A record's own acceleration delay is applied to it when its standard error is within
/// this many samples (a 0.05-sample error is a phase error of 0.011 rad at 7.5 Hz on
/// 204.8 Hz records, 1 % of a storey's resonant response); otherwise the pooled delay.
pub const PER_RECORD_MAX_SE_SAMPLES: f64 = 0.05;

fn signal_error(r: &SystemRecord, source: platen_signal::SignalError) -> IdentError {
    IdentError::Signal {
        test: r.name.clone(),
        source,
    }
}

/// Shifts `x` earlier by `samples` (corrects a channel recorded that many samples late).
pub(crate) fn shift(r: &SystemRecord, x: &[f64], samples: f64) -> Result<Vec<f64>> {
    if samples == 0.0 {
        return Ok(x.to_vec());
    }
    advance(x, samples).map_err(|e| signal_error(r, e))
}

/// Estimates the table acceleration's delay on the fitted records and returns the records
/// with `a_m_s2` and the storeys' accelerations corrected (when significant); the estimate
/// goes to `report`.
pub(crate) fn correct_accelerations(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    report: &mut Vec<ChannelSkew>,
) -> Result<Vec<SystemRecord>> {
    let mut out = records.to_vec();
    if fitted.iter().any(|&i| records[i].a_m_s2.is_none()) {
        return Ok(out);
    }
    // Every record's own estimate (held-out ones too: the alignment needs no model); a record
    // too short or too still for a spectral estimate has none.
    let own: Vec<Option<(f64, f64)>> = records
        .iter()
        .zip(periods)
        .map(|(r, &h)| own_acceleration_delay(r, h))
        .collect();
    let Some((delay_s, se)) = pooled(&own, fitted) else {
        return Ok(out);
    };
    let h = periods[fitted[0]];
    let samples = delay_s / h;
    let applied = delay_s.abs() > SIGNIFICANT * se && samples.abs() > MIN_APPLIED_SAMPLES;
    // Each record's delay, s: its own when precise, else the pooled one.
    let delays: Vec<f64> = own
        .iter()
        .zip(periods)
        .map(|(o, &hp)| match *o {
            Some((d, e)) if e <= PER_RECORD_MAX_SE_SAMPLES * hp => d,
            _ => delay_s,
        })
        .collect();
    let per_record = records
        .iter()
        .zip(&own)
        .zip(periods.iter().zip(&delays))
        .map(|((r, o), (&hp, &d))| RecordSkew {
            name: r.name.clone(),
            delay_samples: o.map(|o| o.0 / hp),
            std_error_samples: o.map(|o| o.1 / hp),
            applied_samples: if applied { d / hp } else { 0.0 },
        })
        .collect();
    report.push(ChannelSkew {
        column: "a_m_s2".into(),
        delay_s,
        std_error_s: Some(se),
        delay_samples: samples,
        applied,
        residual_ratio: None,
        method: "acceleration against the displacement's second derivative (cross-spectrum \
                 phase), pooled over the fitted records (each record corrected by its own \
                 where precise, see per_record); the storeys' accelerations share it",
        per_record,
    });
    if applied {
        for ((r, (c, &hp)), &d) in records.iter().zip(out.iter_mut().zip(periods)).zip(&delays) {
            shift_accelerations(r, c, d / hp)?;
        }
    }
    Ok(out)
}

/// Record `r`'s own delay of the table's acceleration against its displacement and the
/// standard error, s (period `h`); `None` without an acceleration or a usable estimate.
fn own_acceleration_delay(r: &SystemRecord, h: f64) -> Option<(f64, f64)> {
    let a = r.a_m_s2.as_ref()?;
    let e = DelayEstimator::new(1.0 / h)
        .and_then(|d| d.acceleration_against_displacement(a, &r.u_m))
        .ok()?;
    (e.std_error_s > 0.0 && e.std_error_s.is_finite()).then_some((e.delay_s, e.std_error_s))
}

/// The inverse-variance mean of the `fitted` records' `own` delays and its standard error,
/// s; `None` when none has one.
fn pooled(own: &[Option<(f64, f64)>], fitted: &[usize]) -> Option<(f64, f64)> {
    let (mut wsum, mut dsum) = (0.0, 0.0);
    for &i in fitted {
        if let Some((d, se)) = own[i] {
            let w = 1.0 / (se * se);
            wsum += w;
            dsum += w * d;
        }
    }
    if wsum <= 0.0 {
        return None;
    }
    Some((dsum / wsum, 1.0 / wsum.sqrt()))
}

/// The accelerations of `r` (the table's and the storeys') shifted earlier by `samples`,
/// into its corrected copy `c`.
fn shift_accelerations(r: &SystemRecord, c: &mut SystemRecord, samples: f64) -> Result<()> {
    if let Some(a) = &r.a_m_s2 {
        c.a_m_s2 = Some(shift(r, a, samples)?);
    }
    c.storey_a_m_s2 = r
        .storey_a_m_s2
        .iter()
        .map(|s| shift(r, s, samples))
        .collect::<Result<_>>()?;
    Ok(())
}

/// Corrects the pressure channels of every record by `samples` (at the first fitted
/// record's rate: converted to each record's own).
pub(crate) fn correct_pressures(
    records: &mut [SystemRecord],
    periods: &[f64],
    delay_s: f64,
) -> Result<()> {
    for (r, &h) in records.iter_mut().zip(periods) {
        let k = delay_s / h;
        let original = r.clone();
        for c in [
            &mut r.delta_p_pa,
            &mut r.cap_pressure_pa,
            &mut r.rod_pressure_pa,
        ] {
            if let Some(x) = c.as_ref() {
                *c = Some(shift(&original, x, k)?);
            }
        }
    }
    Ok(())
}

/// The vertex of the parabola through three equally spaced points `(x₀ − d, y₋)`,
/// `(x₀, y₀)`, `(x₀ + d, y₊)`, within `[x₀ − d, x₀ + d]`.
pub(crate) fn parabola_vertex(x0: f64, d: f64, ym: f64, y0: f64, yp: f64) -> f64 {
    let curv = ym - 2.0 * y0 + yp;
    if curv <= 0.0 {
        return x0;
    }
    (x0 + 0.5 * d * (ym - yp) / curv).clamp(x0 - d, x0 + d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertex_of_a_parabola() {
        let f = |x: f64| 3.0 * (x - 0.37).powi(2) + 1.0;
        let v = parabola_vertex(0.5, 0.5, f(0.0), f(0.5), f(1.0));
        assert!((v - 0.37).abs() < 1e-12, "{v}");
        // Flat or concave: the middle point.
        assert_eq!(parabola_vertex(1.0, 0.5, 1.0, 1.0, 1.0), 1.0);
    }
}
