//! Channel skew: the delay of one recorded channel against another, and the fractional
//! shift that removes it.
//!
//! A data system may sample (or filter) one channel later than another: a lab's
//! accelerometer channel that lags the displacement by two samples (9.8 ms at 204.8 Hz) makes
//! an identified mass several per cent low. [`DelayEstimator`] measures such a delay from the
//! records themselves, to a fraction of a sample, with a standard error; [`advance`] shifts a
//! channel by any (non-integer) number of samples to remove it.
//!
//! # The estimate
//!
//! The channel `y` is modelled as the reference `x` delayed by `τ`: `y(t) = g·x(t − τ)` plus
//! noise, with `g` any real, zero-phase gain (a central-difference second derivative of a
//! displacement has the gain `(2 sin(πf/f_s)·f_s)²` instead of `(2πf)²`, and no phase). The
//! cross spectrum `S_xy(f) = ⟨X*·Y⟩` then has the phase `φ(f) = −2πf·τ`, and `τ` is the
//! weighted least-squares slope of that line through the origin:
//!
//! 1. **Whole samples first.** The lag `L` of the cross-correlation's peak (searched within
//!    ±[`MAX_LAG_S`], at most an eighth of the record) is removed by indexing, so the phase
//!    left to fit is that of less than a sample and never wraps.
//! 2. **Cross spectrum.** Welch averages over Hann-windowed segments with 50 % overlap, each
//!    de-meaned: segments of about [`SEGMENT_S`] (a power of two, 1024 samples at 204.8 Hz:
//!    0.2 Hz bins), shorter if the record holds fewer than seven of them.
//! 3. **The band.** Bins from two bins above DC (the offsets and the de-meaning disturb the
//!    lowest two) up to [`MAX_RELATIVE_FREQUENCY`]·`f_s` (0.4·f_s: a data system's
//!    anti-alias filter rolls off and turns its phase above that; between channels that share
//!    the same filter this cancels, but a channel filtered differently is not a pure delay
//!    there), and of those only the ones whose magnitude-squared coherence
//!    `γ² = |S_xy|²/(S_xx·S_yy)` is at least [`MIN_COHERENCE`]: where both channels hold more
//!    signal than noise. At the low end this drops the bins where the channel's own noise
//!    and offset drift dominate the little acceleration a slow motion has; at the high end the
//!    bins where the displacement transducer's noise, amplified by `(2πf)²` in a second
//!    derivative, swamps the test's content. Only every other bin is used: Hann-windowed
//!    estimates of neighbouring bins are correlated (coefficient 2/3), bins two apart nearly
//!    not (1/6), so the fit's weights may treat them as independent.
//! 4. **Weights.** The phase of an averaged cross spectrum has the variance
//!    `(1 − γ²)/(2·n_d·γ²)` over `n_d` segments (Bendat & Piersol, *Random Data*, 4th ed.,
//!    Table 9.6); each bin is weighted by its inverse.
//! 5. **Standard error.** `1/(2π·√Σ wₖfₖ²)` from those weights, multiplied by the square root
//!    of the reduced χ² of the fit when it exceeds 1 (the phase scatters more than the
//!    coherence says: a channel that is not a pure delay of the reference, or overlapping
//!    segments counted as independent).

use std::f64::consts::PI;

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

use crate::error::{Result, SignalError};
use crate::extend::odd_extension_at;
use crate::{SampleRate, Window};

/// Segment length aimed at, s (rounded to a power of two of samples).
pub const SEGMENT_S: f64 = 5.0;

/// Largest lag searched for the whole-sample part, s (and at most an eighth of the record).
/// A data system's skew is milliseconds; a quarter of a second is a wrong channel.
pub const MAX_LAG_S: f64 = 0.25;

/// Highest frequency used, as a fraction of the sample rate (0.4·f_s, 82 Hz at 204.8 Hz).
pub const MAX_RELATIVE_FREQUENCY: f64 = 0.4;

/// Smallest magnitude-squared coherence of a bin used in the fit.
pub const MIN_COHERENCE: f64 = 0.9;

/// Fewest bins the fit needs.
pub const MIN_BINS: usize = 3;

/// Fewest samples a record must hold for a delay estimate: seven segments of 64 samples
/// with 50 % overlap.
pub const MIN_DELAY_SAMPLES: usize = 256;

/// The delay of a channel against a reference ([`DelayEstimator::estimate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DelayEstimate {
    /// The delay, s: positive when the channel lags the reference (`y(t) = x(t − τ)`).
    pub delay_s: f64,
    /// Its standard error, s.
    pub std_error_s: f64,
    /// Lowest and highest frequency of the bins fitted, Hz.
    pub band_hz: [f64; 2],
    /// Bins fitted.
    pub bins: usize,
    /// Segments averaged per bin.
    pub segments: usize,
    /// Reduced χ² of the phase fit (≈ 1 when the channel is a pure delay of the reference).
    pub reduced_chi2: f64,
}

/// Estimates the delay of a channel against a reference (see the module docs).
#[derive(Debug, Clone)]
pub struct DelayEstimator {
    rate: SampleRate,
}

impl DelayEstimator {
    /// Plans estimates for records sampled at `sample_rate_hz`.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] for a rate that is not finite and > 0.
    pub fn new(sample_rate_hz: f64) -> Result<Self> {
        Ok(Self {
            rate: SampleRate::new(sample_rate_hz)?,
        })
    }

    /// The delay of `channel` against `reference` (same length, uniformly sampled at the
    /// planned rate).
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] for records of different lengths,
    /// [`SignalError::RecordTooShort`] below [`MIN_DELAY_SAMPLES`], and
    /// [`SignalError::Incoherent`] when fewer than [`MIN_BINS`] bins are coherent (a record
    /// at rest, or channels that do not hold the same motion).
    pub fn estimate(&self, channel: &[f64], reference: &[f64]) -> Result<DelayEstimate> {
        if channel.len() != reference.len() {
            return Err(SignalError::LengthMismatch {
                what: "channel",
                expected: reference.len(),
                found: channel.len(),
                reference: "reference",
            });
        }
        let n = reference.len();
        if n < MIN_DELAY_SAMPLES {
            return Err(SignalError::RecordTooShort {
                what: "record (delay estimate)",
                found: n,
                min: MIN_DELAY_SAMPLES,
            });
        }
        if channel.iter().chain(reference).any(|x| !x.is_finite()) {
            return Err(SignalError::InvalidParameter {
                name: "sample",
                value: f64::NAN,
                expected: "finite samples in both records",
            });
        }
        let fs = self.rate.hz();
        let max_lag = ((MAX_LAG_S * fs).ceil() as usize).min(n / 8);
        let mut lag = peak_lag(channel, reference, max_lag);
        // The fit below sees only what the whole-sample lag left; when that is more than
        // half a sample the peak was one off (a broad correlation): move and fit again.
        let mut fit = self.fine(channel, reference, lag)?;
        for _ in 0..2 {
            let extra = (fit.delay_s * fs).round() as isize;
            if extra == 0 || (lag + extra).unsigned_abs() > max_lag {
                break;
            }
            lag += extra;
            fit = self.fine(channel, reference, lag)?;
        }
        fit.delay_s += lag as f64 / fs;
        Ok(fit)
    }

    /// The delay of an accelerometer's channel `a_m_s2` against the second derivative of
    /// the displacement `u_m` (central differences, whose gain differs from `(2πf)²` but
    /// whose phase is zero), s.
    ///
    /// # Errors
    /// As [`DelayEstimator::estimate`].
    pub fn acceleration_against_displacement(
        &self,
        a_m_s2: &[f64],
        u_m: &[f64],
    ) -> Result<DelayEstimate> {
        if a_m_s2.len() != u_m.len() {
            return Err(SignalError::LengthMismatch {
                what: "a_m_s2",
                expected: u_m.len(),
                found: a_m_s2.len(),
                reference: "u_m",
            });
        }
        self.estimate(a_m_s2, &second_difference(u_m, self.rate.hz()))
    }

    /// The phase fit of `channel[i + lag]` against `reference[i]`: the delay left, s.
    fn fine(&self, channel: &[f64], reference: &[f64], lag: isize) -> Result<DelayEstimate> {
        let n = reference.len();
        let (start, end) = if lag >= 0 {
            (0, n - lag as usize)
        } else {
            (lag.unsigned_abs(), n)
        };
        let x = &reference[start..end];
        let y = &channel[(start as isize + lag) as usize..(end as isize + lag) as usize];
        let fs = self.rate.hz();
        let len = segment_length(x.len(), fs);
        let spectra = CrossSpectra::welch(x, y, len);
        spectra.phase_fit(fs)
    }
}

/// The Welch segments' length for `samples` samples at `fs` Hz: the power of two nearest
/// [`SEGMENT_S`] (at least 64 samples), halved until at least four fit.
fn segment_length(samples: usize, fs: f64) -> usize {
    let target = (SEGMENT_S * fs).max(64.0) as usize;
    let mut len = target.next_power_of_two();
    if len > 2 * target {
        len /= 2;
    }
    while len > 64 && samples < 4 * len {
        len /= 2;
    }
    len
}

/// The auto- and cross-spectra of two records summed over half-overlapping Hann segments.
struct CrossSpectra {
    /// The segments' length, samples.
    len: usize,
    /// How many segments were summed.
    segments: usize,
    /// `Σ|X|²` per bin.
    sxx: Vec<f64>,
    /// `Σ|Y|²` per bin.
    syy: Vec<f64>,
    /// `Σ X̄·Y` per bin.
    sxy: Vec<Complex<f64>>,
}

impl CrossSpectra {
    /// The spectra of `x` and `y` (of equal length, at least `len`) over segments of `len`
    /// samples stepped by `len / 2`, each de-meaned and windowed.
    fn welch(x: &[f64], y: &[f64], len: usize) -> Self {
        let step = len / 2;
        let segments = (x.len() - len) / step + 1;
        let window = Window::Hann.periodic(len);
        let fft = FftPlanner::<f64>::new().plan_fft_forward(len);
        let mut scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
        let bins = len / 2 + 1;
        let (mut sxx, mut syy) = (vec![0.0; bins], vec![0.0; bins]);
        let mut sxy = vec![Complex::new(0.0, 0.0); bins];
        let mut bx = vec![Complex::new(0.0, 0.0); len];
        let mut by = bx.clone();
        for s in 0..segments {
            for (seg, buf) in [
                (&x[s * step..][..len], &mut bx),
                (&y[s * step..][..len], &mut by),
            ] {
                let mean = seg.iter().sum::<f64>() / len as f64;
                for ((c, v), w) in buf.iter_mut().zip(seg).zip(&window) {
                    *c = Complex::new((v - mean) * w, 0.0);
                }
                fft.process_with_scratch(buf, &mut scratch);
            }
            for k in 0..bins {
                sxx[k] += bx[k].norm_sqr();
                syy[k] += by[k].norm_sqr();
                sxy[k] += bx[k].conj() * by[k];
            }
        }
        CrossSpectra {
            len,
            segments,
            sxx,
            syy,
            sxy,
        }
    }

    /// The delay `τ` of the weighted least-squares line `phase = −2πf·τ` through the even
    /// bins from 2 up to [`MAX_RELATIVE_FREQUENCY`] of `fs` with a coherence of at least
    /// [`MIN_COHERENCE`], each weighted by the inverse of its phase's variance.
    ///
    /// # Errors
    /// [`SignalError::Incoherent`] with fewer than [`MIN_BINS`] such bins.
    fn phase_fit(&self, fs: f64) -> Result<DelayEstimate> {
        let CrossSpectra {
            len,
            segments,
            ref sxx,
            ref syy,
            ref sxy,
        } = *self;
        let bins = len / 2 + 1;
        let df = fs / len as f64;
        let (mut swff, mut swfp) = (0.0, 0.0);
        let mut used = Vec::new();
        for k in (2..bins).step_by(2) {
            let f = k as f64 * df;
            if f > MAX_RELATIVE_FREQUENCY * fs {
                break;
            }
            let denom = sxx[k] * syy[k];
            if denom <= 0.0 {
                continue;
            }
            let coh = sxy[k].norm_sqr() / denom;
            if coh < MIN_COHERENCE {
                continue;
            }
            // The formula's variance vanishes as γ² → 1; a cap keeps one bin from taking all
            // the weight (γ̂² from a few segments is itself uncertain).
            let coh = coh.min(0.9999);
            let w = 2.0 * segments as f64 * coh / (1.0 - coh);
            let phase = sxy[k].arg();
            swff += w * f * f;
            swfp += w * f * phase;
            used.push((f, w, phase));
        }
        if used.len() < MIN_BINS {
            return Err(SignalError::Incoherent {
                bins: used.len(),
                min_bins: MIN_BINS,
                min_coherence: MIN_COHERENCE,
            });
        }
        let tau = -swfp / (2.0 * PI * swff);
        let chi2: f64 = used
            .iter()
            .map(|&(f, w, p)| w * (p + 2.0 * PI * f * tau).powi(2))
            .sum();
        let reduced_chi2 = chi2 / (used.len() - 1) as f64;
        let std_error_s = (reduced_chi2.max(1.0) / swff).sqrt() / (2.0 * PI);
        Ok(DelayEstimate {
            delay_s: tau,
            std_error_s,
            band_hz: [used[0].0, used[used.len() - 1].0],
            bins: used.len(),
            segments,
            reduced_chi2,
        })
    }
}

/// `(x[i+1] − 2x[i] + x[i−1])·f_s²`, the end samples copied from their neighbours.
fn second_difference(x: &[f64], fs: f64) -> Vec<f64> {
    let n = x.len();
    let mut d = vec![0.0; n];
    for i in 1..n - 1 {
        d[i] = (x[i + 1] - 2.0 * x[i] + x[i - 1]) * fs * fs;
    }
    d[0] = d[1];
    d[n - 1] = d[n - 2];
    d
}

/// The lag `L` (|L| ≤ `max_lag`) maximising `Σ y[i+L]·x[i]` of the de-meaned records.
fn peak_lag(y: &[f64], x: &[f64], max_lag: usize) -> isize {
    let n = x.len();
    let size = (2 * n).next_power_of_two();
    let mut planner = FftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(size);
    let inv = planner.plan_fft_inverse(size);
    let load = |v: &[f64]| {
        let mean = v.iter().sum::<f64>() / n as f64;
        let mut b: Vec<Complex<f64>> = v.iter().map(|s| Complex::new(s - mean, 0.0)).collect();
        b.resize(size, Complex::new(0.0, 0.0));
        b
    };
    let (mut bx, mut by) = (load(x), load(y));
    fwd.process(&mut bx);
    fwd.process(&mut by);
    let mut r: Vec<Complex<f64>> = bx.iter().zip(&by).map(|(a, b)| a.conj() * b).collect();
    inv.process(&mut r);
    let value = |l: isize| r[l.rem_euclid(size as isize) as usize].re;
    let m = max_lag as isize;
    (-m..=m).fold(0, |best, l| if value(l) > value(best) { l } else { best })
}

/// The record `x` advanced by `shift_samples` samples: `y[i] = x(i + shift_samples)`, the
/// band-limited interpolant (a positive shift removes a delay of that many samples; a
/// negative one delays).
///
/// The shift is the exact phase `e^{i2πf·shift/f_s}` applied to the FFT of the record,
/// padded at each end by its odd extension (`x(−k) = 2x(0) − x(k)`, value and slope
/// continuous) over `64 + ⌈|shift|⌉` samples tapered to the line through the end samples by a
/// raised cosine, the line itself shifted exactly; the Nyquist bin of an even length takes
/// the real part `cos(π·shift)` so the result is real. A record whose content lies below
/// the Nyquist frequency and that is quiet at both ends (as a test record that starts and
/// ends at rest) is shifted to rounding; elsewhere the samples within a few tens of the ends
/// carry the error of the odd extension, which is not the record's true continuation, and
/// the last `⌈shift⌉` samples (the first, for a negative shift) are extrapolated: their
/// values lie beyond the record. Measured on two sines cut anywhere and advanced 2.37
/// samples: 2·10⁻⁷ of the amplitude beyond 100 samples of the ends, 10⁻³ nearer, 0.2 on
/// the three extrapolated samples.
///
/// # Errors
/// [`SignalError::InvalidParameter`] for a shift that is not finite or whose magnitude is a
/// quarter of the record or more; [`SignalError::RecordTooShort`] for fewer than 4 samples.
pub fn advance(x: &[f64], shift_samples: f64) -> Result<Vec<f64>> {
    let n = x.len();
    if n < 4 {
        return Err(SignalError::RecordTooShort {
            what: "record (fractional shift)",
            found: n,
            min: 4,
        });
    }
    if !(shift_samples.is_finite() && shift_samples.abs() < n as f64 / 4.0) {
        return Err(SignalError::InvalidParameter {
            name: "shift_samples",
            value: shift_samples,
            expected: "a finite shift smaller than a quarter of the record",
        });
    }
    if shift_samples == 0.0 {
        return Ok(x.to_vec());
    }
    // The line through the end samples is shifted exactly; the rest starts and ends at 0.
    let (x0, slope) = (x[0], (x[n - 1] - x[0]) / (n - 1) as f64);
    let line = |i: f64| x0 + slope * i;
    let pad = 64 + shift_samples.abs().ceil() as usize;
    let size = (n + 2 * pad).next_power_of_two();
    let mut buf = vec![Complex::new(0.0, 0.0); size];
    // Layout: record at [pad, pad + n), its odd extension on both sides, tapered to 0 over
    // the pads; the zeros beyond wrap around smoothly.
    for (j, c) in buf.iter_mut().enumerate().take(n + 2 * pad) {
        let i = j as isize - pad as isize;
        let r = odd_extension_at(x, i) - line(i as f64);
        let taper = if i < 0 {
            0.5 + 0.5 * (PI * (-i) as f64 / pad as f64).cos()
        } else if i >= n as isize {
            0.5 + 0.5 * (PI * (i - n as isize + 1) as f64 / pad as f64).cos()
        } else {
            1.0
        };
        *c = Complex::new(r * taper, 0.0);
    }
    let mut planner = FftPlanner::<f64>::new();
    planner.plan_fft_forward(size).process(&mut buf);
    for (k, c) in buf.iter_mut().enumerate() {
        // Signed frequency in cycles per sample.
        let f = if k <= size / 2 {
            k as f64
        } else {
            k as f64 - size as f64
        } / size as f64;
        let turn = 2.0 * PI * f * shift_samples;
        *c *= if 2 * k == size {
            Complex::new(turn.cos(), 0.0)
        } else {
            Complex::from_polar(1.0, turn)
        };
    }
    planner.plan_fft_inverse(size).process(&mut buf);
    let scale = 1.0 / size as f64;
    Ok((0..n)
        .map(|i| buf[i + pad].re * scale + line(i as f64 + shift_samples))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_shifted_exactly() {
        let x: Vec<f64> = (0..300).map(|i| 3.0 - 0.25 * i as f64).collect();
        let y = advance(&x, 1.7).unwrap();
        for (i, v) in y.iter().enumerate() {
            let e = 3.0 - 0.25 * (i as f64 + 1.7);
            assert!((v - e).abs() < 1e-11, "{i}: {v} vs {e}");
        }
    }

    #[test]
    fn bad_shifts_and_short_records_are_rejected() {
        let x = vec![0.0; 100];
        assert!(advance(&x, f64::NAN).is_err());
        assert!(advance(&x, 25.0).is_err());
        assert!(advance(&x[..3], 0.5).is_err());
        assert_eq!(advance(&x, 0.0).unwrap(), x);
    }

    #[test]
    fn whole_sample_lag_of_a_shifted_sequence() {
        // A deterministic broadband sequence, y[i] = x[i − 5].
        let x: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 1013) as f64 / 1013.0 - 0.5)
            .collect();
        let y: Vec<f64> = (0..1000)
            .map(|i| if i >= 5 { x[i - 5] } else { 0.0 })
            .collect();
        assert_eq!(peak_lag(&y, &x, 50), 5);
        assert_eq!(peak_lag(&x, &y, 50), -5);
    }
}
