//! Power spectral density by Welch's method.

use std::fmt;
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use crate::error::{Result, SignalError};
use crate::{SampleRate, Window};

/// Welch's averaged periodogram: Hann-windowed segments of a fixed length with 50 % overlap,
/// each with its mean removed, one-sided, scaled as a density.
///
/// Scaling: `P[k] = c_k·⟨|X_k|²⟩ / (f_s·Σw²)` with `c_k = 2` except at DC and at the Nyquist
/// bin (`c_k = 1`), so that `Σ_k P[k]·Δf` equals the (window-weighted) mean square of the
/// de-meaned segments, i.e. the variance: `∫ PSD df = σ²`. A white noise of variance `σ²`
/// has the flat level `σ²/(f_s/2)`. This is `scipy.signal.welch(x, fs, nperseg=len)` with its
/// defaults (periodic Hann window, `noverlap = len/2`, `detrend='constant'`,
/// `scaling='density'`, mean averaging). Samples after the last whole segment are not used.
#[derive(Clone)]
pub struct Welch {
    segment_len: usize,
    rate: SampleRate,
    window: Vec<f64>,
    /// `1/(f_s·Σw²)`.
    scale: f64,
    fft: Arc<dyn Fft<f64>>,
}

impl fmt::Debug for Welch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Welch")
            .field("segment_len", &self.segment_len)
            .field("sample_rate_hz", &self.rate.hz())
            .finish()
    }
}

impl Welch {
    /// Plans the estimate: `segment_len ≥ 4` samples per segment (frequency resolution
    /// `sample_rate_hz/segment_len`), `sample_rate_hz` finite and > 0.
    ///
    /// # Errors
    /// [`SignalError::InvalidCount`] for `segment_len < 4`, [`SignalError::InvalidParameter`]
    /// for a bad sample rate.
    pub fn new(segment_len: usize, sample_rate_hz: f64) -> Result<Self> {
        let rate = SampleRate::new(sample_rate_hz)?;
        if segment_len < 4 {
            return Err(SignalError::InvalidCount {
                name: "segment_len",
                value: segment_len,
                expected: "at least 4 samples per segment",
            });
        }
        let window = Window::Hann.periodic(segment_len);
        let power: f64 = window.iter().map(|w| w * w).sum();
        let fft = FftPlanner::<f64>::new().plan_fft_forward(segment_len);
        Ok(Welch {
            segment_len,
            rate,
            window,
            scale: 1.0 / (rate.hz() * power),
            fft,
        })
    }

    /// Samples per segment.
    pub fn segment_len(&self) -> usize {
        self.segment_len
    }

    /// Bin spacing `f_s/segment_len`, Hz.
    pub fn resolution_hz(&self) -> f64 {
        self.rate.hz() / self.segment_len as f64
    }

    /// Estimates the one-sided PSD of `x` (unit²/Hz for `x` in a unit).
    ///
    /// # Errors
    /// [`SignalError::RecordTooShort`] if `x` is shorter than one segment.
    pub fn estimate(&self, x: &[f64]) -> Result<Psd> {
        let (step, segments) = self.segments_of(x.len())?;
        let len = self.segment_len;
        let mut density = vec![0.0; len / 2 + 1];
        let mut buf = vec![Complex::new(0.0, 0.0); len];
        let mut scratch = vec![Complex::new(0.0, 0.0); self.fft.get_inplace_scratch_len()];
        for s in 0..segments {
            self.transform(&x[s * step..s * step + len], &mut buf, &mut scratch);
            for (p, c) in density.iter_mut().zip(&buf) {
                *p += c.norm_sqr();
            }
        }
        for (k, p) in density.iter_mut().enumerate() {
            *p *= self.bin_scale(k, segments);
        }
        Ok(Psd {
            resolution_hz: self.resolution_hz(),
            density,
            segments,
        })
    }

    /// The hop between segments and their count for a record of `n` samples (50 % overlap,
    /// samples after the last whole segment unused).
    fn segments_of(&self, n: usize) -> Result<(usize, usize)> {
        let len = self.segment_len;
        if n < len {
            return Err(SignalError::RecordTooShort {
                what: "record (one Welch segment)",
                found: n,
                min: len,
            });
        }
        let step = len - len / 2;
        Ok((step, (n - len) / step + 1))
    }

    /// The FFT of one segment, its mean removed and windowed, into `buf`.
    fn transform(&self, seg: &[f64], buf: &mut [Complex<f64>], scratch: &mut [Complex<f64>]) {
        let mean = seg.iter().sum::<f64>() / seg.len() as f64;
        for ((c, v), w) in buf.iter_mut().zip(seg).zip(&self.window) {
            *c = Complex::new((v - mean) * w, 0.0);
        }
        self.fft.process_with_scratch(buf, scratch);
    }

    /// The one-sided density's factor at bin `k` over `segments` segments:
    /// `c_k/(f_s·Σw²·segments)`, `c_k = 2` but at DC and the Nyquist bin.
    fn bin_scale(&self, k: usize, segments: usize) -> f64 {
        let len = self.segment_len;
        let nyquist = len % 2 == 0 && k == len / 2;
        let one_sided = if k == 0 || nyquist { 1.0 } else { 2.0 };
        self.scale / segments as f64 * one_sided
    }
}

impl Welch {
    /// Estimates the one-sided auto- and cross-spectral densities of `x` and `y` (same
    /// length), segment by segment as [`Welch::estimate`]: `P_xy[k] = c_k·⟨conj(X_k)·Y_k⟩ /
    /// (f_s·Σw²)`, as `scipy.signal.csd(x, y, fs, nperseg=len)` with its defaults. The
    /// transfer function from `x` to `y` is `H₁ = P_xy/P_xx` ([`CrossSpectra::transfer`]).
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] unless `x` and `y` have the same length,
    /// [`SignalError::RecordTooShort`] if they are shorter than one segment.
    pub fn cross(&self, x: &[f64], y: &[f64]) -> Result<CrossSpectra> {
        if x.len() != y.len() {
            return Err(SignalError::LengthMismatch {
                what: "y (the cross-spectrum's output channel)",
                expected: x.len(),
                found: y.len(),
                reference: "x (its input channel)",
            });
        }
        let (step, segments) = self.segments_of(x.len())?;
        let len = self.segment_len;
        let bins = len / 2 + 1;
        let (mut xx, mut yy) = (vec![0.0; bins], vec![0.0; bins]);
        let zero = Complex::new(0.0, 0.0);
        let mut xy = vec![zero; bins];
        let (mut bx, mut by) = (vec![zero; len], vec![zero; len]);
        let mut scratch = vec![zero; self.fft.get_inplace_scratch_len()];
        for s in 0..segments {
            let at = s * step..s * step + len;
            self.transform(&x[at.clone()], &mut bx, &mut scratch);
            self.transform(&y[at], &mut by, &mut scratch);
            for k in 0..bins {
                xx[k] += bx[k].norm_sqr();
                yy[k] += by[k].norm_sqr();
                xy[k] += bx[k].conj() * by[k];
            }
        }
        for k in 0..bins {
            let c = self.bin_scale(k, segments);
            xx[k] *= c;
            yy[k] *= c;
            xy[k] *= c;
        }
        Ok(CrossSpectra {
            resolution_hz: self.resolution_hz(),
            xx,
            yy,
            xy: xy.iter().map(|c| (c.re, c.im)).collect(),
            segments,
        })
    }
}

/// The one-sided auto- and cross-spectral densities of two channels ([`Welch::cross`]),
/// on the bins `f_k = k·Δf`.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossSpectra {
    resolution_hz: f64,
    xx: Vec<f64>,
    yy: Vec<f64>,
    /// `P_xy` as (real, imaginary).
    xy: Vec<(f64, f64)>,
    segments: usize,
}

impl CrossSpectra {
    /// The segment-weighted mean of estimates on the same bins (the Welch estimate of
    /// several records taken together: every segment of every record counts alike); `None`
    /// when `parts` is empty or their bins differ.
    pub fn pooled(parts: &[CrossSpectra]) -> Option<CrossSpectra> {
        let first = parts.first()?;
        let bins = first.xx.len();
        if parts
            .iter()
            .any(|p| p.xx.len() != bins || p.resolution_hz != first.resolution_hz)
        {
            return None;
        }
        let total: usize = parts.iter().map(|p| p.segments).sum();
        let mut out = CrossSpectra {
            resolution_hz: first.resolution_hz,
            xx: vec![0.0; bins],
            yy: vec![0.0; bins],
            xy: vec![(0.0, 0.0); bins],
            segments: total,
        };
        for p in parts {
            let w = p.segments as f64 / total as f64;
            for k in 0..bins {
                out.xx[k] += w * p.xx[k];
                out.yy[k] += w * p.yy[k];
                out.xy[k].0 += w * p.xy[k].0;
                out.xy[k].1 += w * p.xy[k].1;
            }
        }
        Some(out)
    }

    /// Bin spacing `Δf`, Hz.
    pub fn resolution_hz(&self) -> f64 {
        self.resolution_hz
    }

    /// Frequency of bin `k`, Hz.
    pub fn frequency_hz(&self, k: usize) -> f64 {
        k as f64 * self.resolution_hz
    }

    /// Segments averaged.
    pub fn segments(&self) -> usize {
        self.segments
    }

    /// `|H₁(f_k)| = |P_xy|/P_xx` at each bin (0 where `P_xx` is 0): the gain from `x` to
    /// `y`, unbiased by noise on `y` that is uncorrelated with `x`.
    pub fn transfer(&self) -> Vec<f64> {
        self.xx
            .iter()
            .zip(&self.xy)
            .map(|(&xx, &(re, im))| if xx > 0.0 { re.hypot(im) / xx } else { 0.0 })
            .collect()
    }

    /// The magnitude-squared coherence `|P_xy|²/(P_xx·P_yy)` at each bin (0 where either
    /// auto-spectrum is 0).
    pub fn coherence(&self) -> Vec<f64> {
        self.xx
            .iter()
            .zip(&self.yy)
            .zip(&self.xy)
            .map(|((&xx, &yy), &(re, im))| {
                if xx > 0.0 && yy > 0.0 {
                    (re * re + im * im) / (xx * yy)
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// A one-sided power spectral density on the bins `f_k = k·Δf`, `k = 0..=segment_len/2`.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    resolution_hz: f64,
    density: Vec<f64>,
    segments: usize,
}

impl Psd {
    /// Bin spacing `Δf`, Hz.
    pub fn resolution_hz(&self) -> f64 {
        self.resolution_hz
    }

    /// The density at each bin, unit²/Hz.
    pub fn density(&self) -> &[f64] {
        &self.density
    }

    /// Frequency of bin `k`, Hz.
    pub fn frequency_hz(&self, k: usize) -> f64 {
        k as f64 * self.resolution_hz
    }

    /// Frequencies of all bins, Hz.
    pub fn frequencies_hz(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.density.len()).map(|k| self.frequency_hz(k))
    }

    /// Number of segments averaged.
    pub fn segments(&self) -> usize {
        self.segments
    }

    /// `Σ_k P[k]·Δf` over all bins: the variance of the record (rectangle rule).
    pub fn variance(&self) -> f64 {
        self.density.iter().sum::<f64>() * self.resolution_hz
    }

    /// Root mean square of the content between `f_lo_hz` and `f_hi_hz`:
    /// `√(Σ P[k]·Δf)` over the bins with `f_lo_hz ≤ f_k ≤ f_hi_hz` (each bin counts its full
    /// width; `rms_in_band(0, ∞)` is the standard deviation of the record).
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] unless `0 ≤ f_lo_hz ≤ f_hi_hz` (`f_hi_hz` may be
    /// `+∞`; NaN is rejected).
    pub fn rms_in_band(&self, f_lo_hz: f64, f_hi_hz: f64) -> Result<f64> {
        if !(f_lo_hz.is_finite() && f_lo_hz >= 0.0) {
            return Err(SignalError::InvalidParameter {
                name: "f_lo_hz",
                value: f_lo_hz,
                expected: "a finite frequency >= 0",
            });
        }
        if f_hi_hz.is_nan() || f_hi_hz < f_lo_hz {
            return Err(SignalError::InvalidParameter {
                name: "f_hi_hz",
                value: f_hi_hz,
                expected: "a frequency >= f_lo_hz",
            });
        }
        let power: f64 = self
            .density
            .iter()
            .enumerate()
            .filter(|&(k, _)| {
                let f = self.frequency_hz(k);
                f >= f_lo_hz && f <= f_hi_hz
            })
            .map(|(_, p)| p)
            .sum();
        Ok((power * self.resolution_hz).sqrt())
    }
}
