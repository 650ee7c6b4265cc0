//! Channel skew: each record's acceleration channel is checked for a delay against its
//! displacement, and corrected (to a fraction of a sample) before the fits; delays given
//! with the record are applied as given.
//!
//! A data system that samples (or filters) the accelerometer later than the displacement
//! transducer — two samples is common — biases the inertial term `Mₑ·a` and, through it,
//! every parameter: on an earthquake record a two-sample lag at 204.8 Hz makes `Mₑ` and `Kₑ`
//! 2 % low and wrecks the dissipative law, with intervals that exclude the truth.
//!
//! * **What is estimated.** The delay of `a_m_s2` against the second derivative of `u_m`
//!   ([`platen_signal::DelayEstimator::acceleration_against_displacement`]: the slope of the
//!   cross-spectrum phase over the band where the two are coherent). The force is not
//!   estimated (its relation to the motion is the model being identified); a known force or
//!   velocity delay may be given ([`TestRecord::with_channel_delay_s`]).
//! * **When an estimate is applied.** When it is significant: more than [`SIGNIFICANT`]
//!   standard errors and more than [`MIN_APPLIED_SAMPLES`] of a sample. Otherwise it is
//!   reported and the channel is used as recorded.
//! * **Intervals.** The delay used is itself uncertain: by the estimate's standard error when
//!   applied, by the estimate itself (and its error) when not. The equation error is refitted
//!   with the channel shifted by `±h` (twice the delay's RMS error, at least a quarter
//!   sample) to get the estimates' derivative `g = ∂θ/∂τ`, and
//!   `g·gᵀ·MSE(τ)` is added to their covariance, `MSE = se² + (τ̂ − τ_used)²`.
//! * **Given delays** (a column map's `delay_s`) are applied as given, exactly (no estimate,
//!   no added variance); a given delay of 0 turns the estimate off.

use platen_signal::DelayEstimator;

use crate::error::{IdentError, Result};
use crate::record::{TestRecord, DELAYABLE_CHANNELS};

/// An estimated delay is applied only beyond this many standard errors.
pub const SIGNIFICANT: f64 = 3.0;

/// An estimated delay is applied only beyond this fraction of a sample (the bias a tenth of
/// a sample leaves is a small part of a two-sample lag's 2 %, and the variance added for it
/// covers it).
pub const MIN_APPLIED_SAMPLES: f64 = 0.1;

/// Smallest step of the delay, samples, over which the estimates' derivative is taken.
const STEP_SAMPLES: f64 = 0.25;

/// A channel's delay against the displacement in one record (channel skew).
///
/// The any-record method estimates the acceleration's delay against the second derivative of
/// the displacement in every record
/// ([`platen_signal::DelayEstimator::acceleration_against_displacement`]) and advances the
/// channel by it ([`platen_signal::advance`]) when it is significant: beyond [`SIGNIFICANT`]
/// standard errors and [`MIN_APPLIED_SAMPLES`] of a sample. A delay given with the record
/// ([`TestRecord::with_channel_delay_s`], a column map's `delay_s`) is applied as given
/// instead (0: used as recorded, not estimated). The variance of an estimated delay (its
/// standard error², plus its square when not applied) is carried into the equation error's
/// covariance through the estimates' derivative over the delay, found by refitting with the
/// channel shifted both ways. The force's delay is not estimated: its relation to the motion
/// is the model being identified.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelDelay {
    /// The channel: `a_m_s2`, `force_n` or `v_m_s`.
    pub column: &'static str,
    /// The delay, s (positive: the channel lags `u_m`): as given, or as estimated.
    pub delay_s: f64,
    /// Standard error of an estimated delay, s (`None` when given).
    pub std_error_s: Option<f64>,
    /// Whether the channel was advanced by it before the fits.
    pub applied: bool,
}

impl ChannelDelay {
    /// Whether the delay was estimated (rather than given).
    pub fn estimated(&self) -> bool {
        self.std_error_s.is_some()
    }
}

/// The records as fitted (channels advanced), and each one's delays.
pub(crate) struct Corrected {
    pub records: Vec<TestRecord>,
    pub delays: Vec<Vec<ChannelDelay>>,
}

fn signal_error(rec: &TestRecord) -> impl Fn(platen_signal::SignalError) -> IdentError + '_ {
    move |source| IdentError::Signal {
        test: rec.name().to_owned(),
        source,
    }
}

/// The delays of one record's channels: those given with it, and the acceleration's
/// estimate unless given (none when the record has too little coherent motion to tell), each
/// marked applied when the any-record method advances the channel by it.
pub(crate) fn delays_of(rec: &TestRecord) -> Vec<ChannelDelay> {
    let fs = rec.sample_rate_hz();
    let mut delays = Vec::new();
    for column in DELAYABLE_CHANNELS {
        let delay = match rec.channel_delay_s(column) {
            Some(d) => ChannelDelay {
                column,
                delay_s: d,
                std_error_s: None,
                applied: d != 0.0 && (column != "v_m_s" || rec.v_m_s().is_some()),
            },
            None if column == "a_m_s2" => {
                let est = DelayEstimator::new(fs)
                    .and_then(|e| e.acceleration_against_displacement(rec.a_m_s2(), rec.u_m()));
                // A record without coherent motion (at rest, or too short) cannot say: its
                // channel is used as recorded and no delay is reported.
                let Ok(est) = est else { continue };
                ChannelDelay {
                    column,
                    delay_s: est.delay_s,
                    std_error_s: Some(est.std_error_s),
                    applied: est.delay_s.abs() > SIGNIFICANT * est.std_error_s
                        && est.delay_s.abs() * fs > MIN_APPLIED_SAMPLES,
                }
            }
            None => continue,
        };
        delays.push(delay);
    }
    delays
}

/// Applies given delays and estimates (and, when significant, applies) the acceleration's.
pub(crate) fn correct(records: &[TestRecord]) -> Result<Corrected> {
    let mut out = Corrected {
        records: Vec::with_capacity(records.len()),
        delays: Vec::with_capacity(records.len()),
    };
    for rec in records {
        let delays = delays_of(rec);
        let mut fixed = rec.clone();
        for d in delays.iter().filter(|d| d.applied) {
            fixed = fixed
                .with_channel_advanced(d.column, d.delay_s * rec.sample_rate_hz())
                .map_err(signal_error(rec))?;
        }
        out.records.push(fixed);
        out.delays.push(delays);
    }
    Ok(out)
}

/// For each record with an estimated delay: that record (index `record`) with the channel
/// shifted by `±h` from the delay used (the other records stay as corrected), `h` (s), and
/// the mean square error of the delay used, s².
pub(crate) struct Perturbation {
    pub record: usize,
    pub minus: TestRecord,
    pub plus: TestRecord,
    pub h_s: f64,
    pub mse_s2: f64,
}

/// The perturbed record sets, one per estimated delay.
pub(crate) fn perturbations(corrected: &Corrected) -> Result<Vec<Perturbation>> {
    let mut out = Vec::new();
    for (r, delays) in corrected.delays.iter().enumerate() {
        for d in delays {
            let Some(se) = d.std_error_s else { continue };
            let rec = &corrected.records[r];
            let fs = rec.sample_rate_hz();
            let used = if d.applied { d.delay_s } else { 0.0 };
            let mse_s2 = se * se + (d.delay_s - used).powi(2);
            // The secant over ±2 root-mean-square errors, and over at least a quarter sample:
            // the fit stops its (α, b) search within a tolerance, which makes its estimates
            // jitter by a few kg of Mₑ between nearby delays; a shorter step would measure
            // the jitter, not the slope (~100 kg per sample near the true delay).
            let h_s = (2.0 * mse_s2.sqrt()).max(STEP_SAMPLES / fs);
            let shifted = |sign: f64| -> Result<TestRecord> {
                rec.with_channel_advanced(d.column, sign * h_s * fs)
                    .map_err(signal_error(rec))
            };
            out.push(Perturbation {
                record: r,
                minus: shifted(-1.0)?,
                plus: shifted(1.0)?,
                h_s,
                mse_s2,
            });
        }
    }
    Ok(out)
}
