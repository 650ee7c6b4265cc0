//! How well a simulated series reproduces a recorded one: RMS error, NRMSE, signed peaks and
//! their ratio, Pearson correlation and the lag found by cross-correlation, optionally over a
//! time window.
//!
//! Both series are on one uniform time base (sample `i` at `start_s + i/sample_rate_hz`); put
//! a series on another's time stamps first with [`interpolate_linear`]. A [`Comparator`] is
//! planned once (rate, start time, window, lag search bound) and compares any number of
//! channels:
//!
//! ```
//! use platen_signal::metrics::Comparator;
//! use std::f64::consts::PI;
//!
//! // A 0.5 Hz displacement recorded at 512 Hz, and a simulation 3 % too small and 5 ms late.
//! let fs_hz = 512.0;
//! let t_s: Vec<f64> = (0..20 * 512).map(|i| i as f64 / fs_hz).collect();
//! let recorded: Vec<f64> = t_s.iter().map(|t| 0.38 * (PI * t).sin()).collect();
//! let simulated: Vec<f64> = t_s.iter().map(|t| 0.97 * 0.38 * (PI * (t - 0.005)).sin()).collect();
//!
//! let comparator = Comparator::new(fs_hz, 0.0, 0.25)?;
//! let m = comparator.compare(&recorded, &simulated)?;
//! assert!((m.lag.unwrap().lag_s - 0.005).abs() < 1e-5);
//! assert!((m.peak_ratio.unwrap() - 0.97).abs() < 1e-4);
//! assert!(m.correlation.unwrap() > 0.999);
//! // The error is the 3 % in amplitude and the 0.9° phase lag together: about 3.4 %.
//! assert!((m.nrmse.unwrap() - 0.0337).abs() < 5e-4);
//! # Ok::<(), platen_signal::SignalError>(())
//! ```
//!
//! # Conventions
//!
//! * **Error** is `simulated − recorded`, sample by sample. `rms_error = √(mean(error²))`;
//!   `nrmse = rms_error / rms(recorded)`, a fraction (multiply by 100 for percent), with the
//!   recorded RMS taken about zero (not about the mean): a simulation `s·recorded` has
//!   `nrmse = |1 − s|`.
//! * **Peaks** are signed: the sample of largest magnitude (the first one on a tie) and its
//!   time. `peak_ratio = |peak simulated| / |peak recorded|`.
//! * **Correlation** is Pearson's coefficient at zero lag.
//! * **Lag** is positive when the simulation is *late*: `simulated(t) ≈ recorded(t − lag)`.
//!   It maximises Pearson's coefficient of the overlapping parts of the two series over the
//!   integer lags `|k| ≤ max_lag`; ties go to the smallest `|k|`. The integer peak is refined
//!   by the vertex of the parabola through it and its two neighbours (at most half a sample
//!   either way), unless it sits on the search bound, which [`Lag::at_search_limit`] reports.
//!   The coefficients of all lags come from one FFT cross-correlation and running sums, so
//!   the cost is `O(n log n)` whatever the bound.
//! * **Undefined values are `None`**, never NaN: NRMSE of an all-zero record, a peak ratio
//!   against a zero peak, the correlation or lag of a constant series.
//! * **Window** `[t0, t1]` (s, inclusive; a sample counts if it lies within a millionth of
//!   a sample interval of the window) restricts every metric, the lag search included, to the
//!   samples inside it.

use std::ops::Range;

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

use crate::error::{Result, SignalError};
use crate::SampleRate;

/// A signed peak: the value of largest magnitude and its time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignedPeak {
    /// The value, in the channel's unit (signed).
    pub value: f64,
    /// Its time, s.
    pub t_s: f64,
}

/// The lag of a simulated series behind a recorded one, by cross-correlation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lag {
    /// The lag, s: positive when the simulation is late (`simulated(t) ≈ recorded(t − lag)`).
    pub lag_s: f64,
    /// Pearson's coefficient of the overlapping parts at the best integer lag.
    pub peak_correlation: f64,
    /// Whether the best integer lag is on the search bound `±max_lag_s` (the true lag may be
    /// beyond it; the value is then not refined).
    pub at_search_limit: bool,
}

/// The metrics of one channel (see the [module documentation](self) for the definitions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelMetrics {
    /// Samples compared.
    pub samples: usize,
    /// Times of the first and last sample compared, s.
    pub span_s: [f64; 2],
    /// RMS of the recorded series (about zero), in the channel's unit.
    pub rms_recorded: f64,
    /// RMS of `simulated − recorded`, in the channel's unit.
    pub rms_error: f64,
    /// `rms_error / rms_recorded` (a fraction); `None` if the record is all zero.
    pub nrmse: Option<f64>,
    /// Peak of the recorded series.
    pub peak_recorded: SignedPeak,
    /// Peak of the simulated series.
    pub peak_simulated: SignedPeak,
    /// `|peak_simulated| / |peak_recorded|`; `None` if the record is all zero.
    pub peak_ratio: Option<f64>,
    /// Pearson's correlation coefficient; `None` if either series is constant.
    pub correlation: Option<f64>,
    /// Lag by cross-correlation; `None` if no lag has a defined coefficient (a constant
    /// series).
    pub lag: Option<Lag>,
}

/// Compares simulated channels with recorded ones on a common uniform time base: planned
/// once, applied to any number of channels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparator {
    rate: SampleRate,
    start_s: f64,
    max_lag_s: f64,
    window_s: Option<[f64; 2]>,
}

impl Comparator {
    /// A comparator for series sampled at `sample_rate_hz` whose first sample is at
    /// `start_s`, searching lags up to `max_lag_s` either way, over the whole series.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] unless `sample_rate_hz` is finite and > 0,
    /// `start_s` is finite and `max_lag_s` is finite and ≥ 0.
    pub fn new(sample_rate_hz: f64, start_s: f64, max_lag_s: f64) -> Result<Self> {
        let rate = SampleRate::new(sample_rate_hz)?;
        if !start_s.is_finite() {
            return Err(SignalError::InvalidParameter {
                name: "start_s",
                value: start_s,
                expected: "a finite time",
            });
        }
        if !(max_lag_s.is_finite() && max_lag_s >= 0.0) {
            return Err(SignalError::InvalidParameter {
                name: "max_lag_s",
                value: max_lag_s,
                expected: "a finite duration >= 0 s",
            });
        }
        Ok(Self {
            rate,
            start_s,
            max_lag_s,
            window_s: None,
        })
    }

    /// Restricts the comparison to the samples with `t0_s ≤ t ≤ t1_s`.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] unless both are finite and `t0_s < t1_s`.
    pub fn with_window_s(mut self, t0_s: f64, t1_s: f64) -> Result<Self> {
        if !t0_s.is_finite() {
            return Err(SignalError::InvalidParameter {
                name: "window start t0_s",
                value: t0_s,
                expected: "a finite time",
            });
        }
        if !(t1_s.is_finite() && t1_s > t0_s) {
            return Err(SignalError::InvalidParameter {
                name: "window end t1_s",
                value: t1_s,
                expected: "a finite time after the window start t0_s",
            });
        }
        self.window_s = Some([t0_s, t1_s]);
        Ok(self)
    }

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.rate.hz()
    }

    /// The time of sample 0, s.
    pub fn start_s(&self) -> f64 {
        self.start_s
    }

    /// The lag search bound, s.
    pub fn max_lag_s(&self) -> f64 {
        self.max_lag_s
    }

    /// The window, if any, s.
    pub fn window_s(&self) -> Option<[f64; 2]> {
        self.window_s
    }

    /// The time of sample `i`, s.
    pub fn time_s(&self, i: usize) -> f64 {
        self.start_s + i as f64 * self.rate.interval_s()
    }

    /// The indices of the samples of an `n`-sample series that the comparison uses (all of
    /// them without a window; empty if the window misses the series).
    pub fn indices(&self, n: usize) -> Range<usize> {
        let Some([t0, t1]) = self.window_s else {
            return 0..n;
        };
        let fs = self.rate.hz();
        let slack = 1e-6;
        let first = ((t0 - self.start_s) * fs - slack).ceil().max(0.0);
        let last = ((t1 - self.start_s) * fs + slack).floor();
        if last < 0.0 || first >= n as f64 || first > last {
            return 0..0;
        }
        // Both are whole numbers in [0, n) here (`last` clipped below).
        let first = first as usize;
        let last = (last as usize).min(n - 1);
        first..last + 1
    }

    /// Compares `simulated` with `recorded` (same length, sample `i` of both at
    /// [`time_s(i)`](Self::time_s)).
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] if the lengths differ;
    /// [`SignalError::RecordTooShort`] if fewer than 2 samples are compared (a window that
    /// misses the series, or a series shorter than 2).
    pub fn compare(&self, recorded: &[f64], simulated: &[f64]) -> Result<ChannelMetrics> {
        if simulated.len() != recorded.len() {
            return Err(SignalError::LengthMismatch {
                what: "simulated",
                expected: recorded.len(),
                found: simulated.len(),
                reference: "recorded",
            });
        }
        let range = self.indices(recorded.len());
        if range.len() < 2 {
            return Err(SignalError::RecordTooShort {
                what: "samples compared (inside the window)",
                found: range.len(),
                min: 2,
            });
        }
        let offset = range.start;
        let (rec, sim) = (&recorded[range.clone()], &simulated[range.clone()]);
        let rms_recorded = rms(rec);
        let rms_error = rms_difference(sim, rec)?;
        let (i_rec, peak_rec) = signed_peak(rec);
        let (i_sim, peak_sim) = signed_peak(sim);
        let max_lag = (self.max_lag_s * self.rate.hz()).round() as usize;
        let lag = best_lag(rec, sim, max_lag).map(|b| Lag {
            lag_s: b.lag_samples * self.rate.interval_s(),
            peak_correlation: b.correlation,
            at_search_limit: b.at_limit,
        });
        Ok(ChannelMetrics {
            samples: range.len(),
            span_s: [self.time_s(range.start), self.time_s(range.end - 1)],
            rms_recorded,
            rms_error,
            nrmse: (rms_recorded > 0.0).then(|| rms_error / rms_recorded),
            peak_recorded: SignedPeak {
                value: peak_rec,
                t_s: self.time_s(offset + i_rec),
            },
            peak_simulated: SignedPeak {
                value: peak_sim,
                t_s: self.time_s(offset + i_sim),
            },
            peak_ratio: (peak_rec != 0.0).then(|| peak_sim.abs() / peak_rec.abs()),
            correlation: pearson(rec, sim)?,
            lag,
        })
    }
}

/// Root mean square of `x` about zero; 0 for an empty series.
pub fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Root mean square of `a − b`.
///
/// # Errors
/// [`SignalError::LengthMismatch`] if the lengths differ.
pub fn rms_difference(a: &[f64], b: &[f64]) -> Result<f64> {
    same_length(a, b)?;
    if a.is_empty() {
        return Ok(0.0);
    }
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    Ok((sum / a.len() as f64).sqrt())
}

/// The sample of largest magnitude, `(index, signed value)`: the first one on a tie;
/// `(0, 0.0)` for an empty series.
pub fn signed_peak(x: &[f64]) -> (usize, f64) {
    let mut best = (0, 0.0f64);
    for (i, &v) in x.iter().enumerate() {
        if v.abs() > best.1.abs() {
            best = (i, v);
        }
    }
    best
}

/// Pearson's correlation coefficient of `x` and `y`; `None` if either is constant (or has
/// fewer than 2 samples).
///
/// # Errors
/// [`SignalError::LengthMismatch`] if the lengths differ.
pub fn pearson(x: &[f64], y: &[f64]) -> Result<Option<f64>> {
    same_length(x, y)?;
    let n = x.len();
    if n < 2 {
        return Ok(None);
    }
    let mx = x.iter().sum::<f64>() / n as f64;
    let my = y.iter().sum::<f64>() / n as f64;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        let (dx, dy) = (a - mx, b - my);
        sxy += dx * dy;
        sxx += dx * dx;
        syy += dy * dy;
    }
    if !(sxx > 0.0 && syy > 0.0) {
        return Ok(None);
    }
    Ok(Some((sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0)))
}

/// The lag of `simulated` behind `recorded`, by cross-correlation over `|lag| ≤ max_lag_s`,
/// for series sampled at `sample_rate_hz` (see the [module documentation](self)).
///
/// # Errors
/// [`SignalError::LengthMismatch`] if the lengths differ; [`SignalError::InvalidParameter`]
/// for a rate that is not finite and > 0 or a bound that is not finite and ≥ 0.
pub fn lag_by_cross_correlation(
    recorded: &[f64],
    simulated: &[f64],
    sample_rate_hz: f64,
    max_lag_s: f64,
) -> Result<Option<Lag>> {
    same_length(recorded, simulated)?;
    let plan = Comparator::new(sample_rate_hz, 0.0, max_lag_s)?;
    let max_lag = (max_lag_s * plan.rate.hz()).round() as usize;
    Ok(best_lag(recorded, simulated, max_lag).map(|b| Lag {
        lag_s: b.lag_samples * plan.rate.interval_s(),
        peak_correlation: b.correlation,
        at_search_limit: b.at_limit,
    }))
}

/// Pearson's coefficient of the overlapping parts of `recorded[i]` and `simulated[i + k]`
/// for every integer lag `k` in `−max_lag ..= max_lag` (clipped so that at least 2 samples
/// overlap), as `(k, coefficient)`; `None` where either part is constant.
///
/// This is the function whose maximum [`lag_by_cross_correlation`] refines; it is public so
/// that the lag can be checked, or plotted, against it.
///
/// # Errors
/// [`SignalError::LengthMismatch`] if the lengths differ.
pub fn correlation_by_lag(
    recorded: &[f64],
    simulated: &[f64],
    max_lag: usize,
) -> Result<Vec<(isize, Option<f64>)>> {
    same_length(recorded, simulated)?;
    let n = recorded.len();
    if n < 2 {
        return Ok(Vec::new());
    }
    let k_max = max_lag.min(n - 2) as isize;
    let table = LagTable::new(recorded, simulated, k_max as usize);
    Ok((-k_max..=k_max).map(|k| (k, table.rho(k))).collect())
}

/// Linear interpolation of the series `(t_from, y_from)` at the times `t_to`.
///
/// A time equal to a stamp of `t_from` gets that sample's value exactly; times before the
/// first stamp or after the last get the first or last value (constant extrapolation: check
/// coverage first if it matters).
///
/// # Errors
/// [`SignalError::LengthMismatch`] if `y_from` and `t_from` differ in length;
/// [`SignalError::RecordTooShort`] if they are empty; [`SignalError::InvalidParameter`] if
/// a stamp of `t_from` is not finite or not larger than the one before, or a time of `t_to`
/// is not finite.
pub fn interpolate_linear(t_from: &[f64], y_from: &[f64], t_to: &[f64]) -> Result<Vec<f64>> {
    if y_from.len() != t_from.len() {
        return Err(SignalError::LengthMismatch {
            what: "y_from",
            expected: t_from.len(),
            found: y_from.len(),
            reference: "t_from",
        });
    }
    if t_from.is_empty() {
        return Err(SignalError::RecordTooShort {
            what: "t_from (interpolation)",
            found: 0,
            min: 1,
        });
    }
    if let Some(&bad) = t_from.iter().find(|t| !t.is_finite()) {
        return Err(SignalError::InvalidParameter {
            name: "t_from",
            value: bad,
            expected: "finite times",
        });
    }
    if let Some(w) = t_from.windows(2).find(|w| w[1] <= w[0]) {
        return Err(SignalError::InvalidParameter {
            name: "t_from",
            value: w[1],
            expected: "strictly increasing times",
        });
    }
    let last = t_from.len() - 1;
    t_to.iter()
        .map(|&t| {
            if !t.is_finite() {
                return Err(SignalError::InvalidParameter {
                    name: "t_to",
                    value: t,
                    expected: "finite times",
                });
            }
            // First stamp after `t`: the segment is [j − 1, j].
            let j = t_from.partition_point(|&s| s <= t);
            Ok(if j == 0 {
                y_from[0]
            } else if j > last {
                y_from[last]
            } else {
                let (t0, t1) = (t_from[j - 1], t_from[j]);
                let (y0, y1) = (y_from[j - 1], y_from[j]);
                y0 + (y1 - y0) * ((t - t0) / (t1 - t0))
            })
        })
        .collect()
}

fn same_length(a: &[f64], b: &[f64]) -> Result<()> {
    if a.len() == b.len() {
        Ok(())
    } else {
        Err(SignalError::LengthMismatch {
            what: "second series",
            expected: a.len(),
            found: b.len(),
            reference: "first series",
        })
    }
}

/// The best lag in samples (refined), its integer peak's coefficient, and whether that peak
/// is on the search bound.
struct BestLag {
    lag_samples: f64,
    correlation: f64,
    at_limit: bool,
}

fn best_lag(recorded: &[f64], simulated: &[f64], max_lag: usize) -> Option<BestLag> {
    let n = recorded.len();
    if n < 2 {
        return None;
    }
    let k_max = max_lag.min(n - 2) as isize;
    let table = LagTable::new(recorded, simulated, k_max as usize);
    // Scan 0, 1, −1, 2, −2, …: a strict improvement is needed, so ties go to small |k|.
    let mut best: Option<(isize, f64)> = None;
    for step in 0..=2 * k_max {
        let k = if step % 2 == 1 {
            (step + 1) / 2
        } else {
            -(step / 2)
        };
        if let Some(r) = table.rho(k) {
            if best.is_none_or(|(_, b)| r > b) {
                best = Some((k, r));
            }
        }
    }
    let (k, r) = best?;
    let at_limit = k_max > 0 && k.abs() == k_max;
    let mut lag = k as f64;
    if !at_limit && k_max > 0 {
        if let (Some(left), Some(right)) = (table.rho(k - 1), table.rho(k + 1)) {
            let curvature = left - 2.0 * r + right;
            if curvature < 0.0 {
                lag += (0.5 * (left - right) / curvature).clamp(-0.5, 0.5);
            }
        }
    }
    Some(BestLag {
        lag_samples: lag,
        correlation: r,
        at_limit,
    })
}

/// Sums for Pearson's coefficient of `x[i]` against `y[i + k]` at every lag `|k| ≤ k_max`:
/// the cross products by one zero-padded FFT correlation, the segment sums by prefix sums.
/// Both series are centred on their means first, which leaves every coefficient unchanged
/// and keeps the sums small.
struct LagTable {
    n: usize,
    k_max: usize,
    /// `cross[k + k_max] = Σ x[i]·y[i + k]` over the overlap.
    cross: Vec<f64>,
    px: Vec<f64>,
    pxx: Vec<f64>,
    py: Vec<f64>,
    pyy: Vec<f64>,
}

impl LagTable {
    fn new(x: &[f64], y: &[f64], k_max: usize) -> Self {
        let n = x.len();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / n as f64;
        let (mx, my) = (mean(x), mean(y));
        let xc: Vec<f64> = x.iter().map(|v| v - mx).collect();
        let yc: Vec<f64> = y.iter().map(|v| v - my).collect();
        let prefix = |v: &[f64], square: bool| {
            let mut p = Vec::with_capacity(n + 1);
            let mut s = 0.0;
            p.push(0.0);
            for &a in v {
                s += if square { a * a } else { a };
                p.push(s);
            }
            p
        };
        let cross = if k_max == 0 {
            vec![xc.iter().zip(&yc).map(|(a, b)| a * b).sum()]
        } else {
            fft_cross(&xc, &yc, k_max)
        };
        Self {
            n,
            k_max,
            cross,
            px: prefix(&xc, false),
            pxx: prefix(&xc, true),
            py: prefix(&yc, false),
            pyy: prefix(&yc, true),
        }
    }

    /// Pearson's coefficient at lag `k` (|k| ≤ k_max), or `None` for a constant part.
    fn rho(&self, k: isize) -> Option<f64> {
        if k.unsigned_abs() > self.k_max {
            return None;
        }
        let n = self.n as isize;
        let (i0, i1) = (0.max(-k), n.min(n - k));
        let m = (i1 - i0) as f64;
        let (a, b) = (i0 as usize, i1 as usize);
        let (c, d) = ((i0 + k) as usize, (i1 + k) as usize);
        let sx = self.px[b] - self.px[a];
        let sxx = self.pxx[b] - self.pxx[a];
        let sy = self.py[d] - self.py[c];
        let syy = self.pyy[d] - self.pyy[c];
        let sxy = self.cross[(k + self.k_max as isize) as usize];
        let vx = sxx - sx * sx / m;
        let vy = syy - sy * sy / m;
        // Rounding of the prefix sums leaves ~1e-16 of the totals: below that is constant.
        let floor = 64.0 * f64::EPSILON;
        if !(vx > floor * self.pxx[self.n] && vy > floor * self.pyy[self.n]) {
            return None;
        }
        Some(((sxy - sx * sy / m) / (vx * vy).sqrt()).clamp(-1.0, 1.0))
    }
}

/// `Σ x[i]·y[i + k]` for `k = −k_max ..= k_max` (index `k + k_max`), by FFT.
fn fft_cross(x: &[f64], y: &[f64], k_max: usize) -> Vec<f64> {
    let n = x.len();
    let size = (n + k_max).next_power_of_two();
    let mut planner = FftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(size);
    let backward = planner.plan_fft_inverse(size);
    let padded = |v: &[f64]| {
        let mut buf = vec![Complex::new(0.0, 0.0); size];
        for (b, &a) in buf.iter_mut().zip(v) {
            b.re = a;
        }
        buf
    };
    let (mut fx, mut fy) = (padded(x), padded(y));
    forward.process(&mut fx);
    forward.process(&mut fy);
    for (a, b) in fx.iter_mut().zip(&fy) {
        *a = a.conj() * b;
    }
    backward.process(&mut fx);
    let scale = 1.0 / size as f64;
    (-(k_max as isize)..=k_max as isize)
        .map(|k| fx[k.rem_euclid(size as isize) as usize].re * scale)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fft_cross_products_equal_the_direct_sums() {
        let x: Vec<f64> = (0..37).map(|i| ((i * 7919) % 31) as f64 - 15.0).collect();
        let y: Vec<f64> = (0..37)
            .map(|i| ((i * 104_729) % 29) as f64 - 14.0)
            .collect();
        let k_max = 9;
        let fast = fft_cross(&x, &y, k_max);
        for k in -(k_max as isize)..=k_max as isize {
            let direct: f64 = (0..37isize)
                .filter(|i| (0..37).contains(&(i + k)))
                .map(|i| x[i as usize] * y[(i + k) as usize])
                .sum();
            let got = fast[(k + k_max as isize) as usize];
            assert!((got - direct).abs() < 1e-9, "k = {k}: {got} vs {direct}");
        }
    }

    #[test]
    fn a_window_selects_the_samples_inside_it_inclusive() {
        let c = Comparator::new(10.0, 1.0, 0.0)
            .unwrap()
            .with_window_s(1.2, 1.5)
            .unwrap();
        assert_eq!(c.indices(100), 2..6);
        assert_eq!(c.indices(4), 2..4);
        assert_eq!(c.indices(2), 0..0);
        let outside = Comparator::new(10.0, 1.0, 0.0)
            .unwrap()
            .with_window_s(-5.0, 0.5)
            .unwrap();
        assert_eq!(outside.indices(100), 0..0);
    }
}
