//! Frequency-domain (brick-wall) low-pass for periodic records, and trimming a record to whole
//! periods.

use std::fmt;
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use crate::error::{self, Result, SignalError};
use crate::{SampleRate, ZeroPhaseFilter};

/// A brick-wall low-pass for records of one fixed length: FFT, zero every bin above the
/// cut-off, inverse FFT.
///
/// **Gain and phase.** For a component on the record's frequency grid `f_k = k·f_s/n` (a
/// component that makes a whole number of cycles in the record) the gain is exactly 1 at and
/// below the cut-off and exactly 0 above it, with zero phase: a pass-band sine comes out
/// unchanged to rounding, with none of the attenuation a smooth filter has near its cut-off.
///
/// **Edges.** The FFT treats the record as one period of a periodic signal, so this filter
/// assumes the record holds whole periods of the motion (trim it first with
/// [`trim_to_whole_periods`]). Otherwise the jump from the last sample back to the first acts
/// as a step, which the brick wall turns into Gibbs ripples at both ends of the record (at the
/// very edge the output sits near the midpoint of the jump), and an off-grid frequency leaks
/// into the neighbouring bins. A constant passes exactly; a ramp does not (it is a saw-tooth to
/// the FFT).
#[derive(Clone)]
pub struct SpectralLowpass {
    len: usize,
    cutoff_hz: f64,
    rate: SampleRate,
    /// Highest kept bin: bins `0..=kept` and `len−kept..len` are kept.
    kept: usize,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    scratch_len: usize,
}

impl fmt::Debug for SpectralLowpass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SpectralLowpass")
            .field("len", &self.len)
            .field("cutoff_hz", &self.cutoff_hz)
            .field("sample_rate_hz", &self.rate.hz())
            .field("highest_kept_bin", &self.kept)
            .finish()
    }
}

impl SpectralLowpass {
    /// Plans the filter for records of `len ≥ 2` samples: keeps the bins at frequencies
    /// `k·f_s/len ≤ cutoff_hz` (to within 10⁻⁹ of a bin), `cutoff_hz` in `(0, f_s/2)`.
    /// A cut-off below the first bin `f_s/len` keeps only the mean.
    ///
    /// # Errors
    /// [`SignalError::RecordTooShort`] for `len < 2`, [`SignalError::InvalidParameter`] for a
    /// bad sample rate, [`SignalError::CutoffOutOfRange`] for a bad cut-off.
    pub fn new(len: usize, cutoff_hz: f64, sample_rate_hz: f64) -> Result<Self> {
        let rate = SampleRate::new(sample_rate_hz)?;
        let cutoff_hz = error::cutoff("cutoff_hz", cutoff_hz, rate.hz())?;
        if len < 2 {
            return Err(SignalError::RecordTooShort {
                what: "len (samples per record of a spectral low-pass)",
                found: len,
                min: 2,
            });
        }
        // cutoff < f_s/2 ⇒ kept < len/2: the Nyquist bin is never kept.
        let kept = ((cutoff_hz * len as f64 / rate.hz()) + 1e-9).floor() as usize;
        let kept = kept.min((len - 1) / 2);
        let mut planner = FftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(len);
        let inverse = planner.plan_fft_inverse(len);
        let scratch_len = forward
            .get_inplace_scratch_len()
            .max(inverse.get_inplace_scratch_len());
        Ok(SpectralLowpass {
            len,
            cutoff_hz,
            rate,
            kept,
            forward,
            inverse,
            scratch_len,
        })
    }

    /// The record length this plan is for.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always `false`: a plan is for records of at least 2 samples.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The cut-off, Hz.
    pub fn cutoff_hz(&self) -> f64 {
        self.cutoff_hz
    }

    /// The highest kept frequency `kept_bins·f_s/len`, Hz (≤ the cut-off).
    pub fn highest_kept_hz(&self) -> f64 {
        self.kept as f64 * self.rate.hz() / self.len as f64
    }
}

impl ZeroPhaseFilter for SpectralLowpass {
    fn sample_rate_hz(&self) -> f64 {
        self.rate.hz()
    }

    /// 1 at and below the highest kept bin frequency, 0 above (frequencies folded into
    /// `[0, f_s/2]`). Exact for components on the record's bin grid; others leak.
    fn amplitude(&self, frequency_hz: f64) -> f64 {
        let fs = self.rate.hz();
        let f = frequency_hz.abs().rem_euclid(fs);
        let f = f.min(fs - f);
        let bin = f * self.len as f64 / fs;
        if bin <= self.kept as f64 + 1e-9 {
            1.0
        } else {
            0.0
        }
    }

    /// # Errors
    /// [`SignalError::LengthMismatch`] if `input` does not have the planned length or `output`
    /// not the length of `input`.
    fn process(&self, input: &[f64], output: &mut [f64]) -> Result<()> {
        if input.len() != self.len {
            return Err(SignalError::LengthMismatch {
                what: "input",
                expected: self.len,
                found: input.len(),
                reference: "the SpectralLowpass plan",
            });
        }
        error::same_len(input, output)?;
        let mut buf: Vec<Complex<f64>> = input.iter().map(|&x| Complex::new(x, 0.0)).collect();
        let mut scratch = vec![Complex::new(0.0, 0.0); self.scratch_len];
        self.forward.process_with_scratch(&mut buf, &mut scratch);
        for c in &mut buf[self.kept + 1..self.len - self.kept] {
            *c = Complex::new(0.0, 0.0);
        }
        self.inverse.process_with_scratch(&mut buf, &mut scratch);
        let scale = 1.0 / self.len as f64;
        for (y, c) in output.iter_mut().zip(&buf) {
            *y = c.re * scale;
        }
        Ok(())
    }
}

/// How much of a record holds a whole number of periods of a fundamental frequency.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WholePeriods {
    /// Number of whole periods.
    pub periods: usize,
    /// Samples that hold them: `round(periods·f_s/f₀)`.
    pub len: usize,
}

/// The largest number of whole periods of `fundamental_hz` that fits in `record_len` samples
/// at `sample_rate_hz`, and the number of samples that hold them.
///
/// When `f_s/f₀` is not an integer the length is rounded to the nearest sample, so the trimmed
/// record is periodic to within half a sample; a brick-wall filter then sees a small residual
/// jump at the wrap-around.
///
/// # Errors
/// [`SignalError::InvalidParameter`] for a non-finite or non-positive rate or fundamental,
/// [`SignalError::RecordTooShort`] if the record holds less than one period.
pub fn whole_periods(
    record_len: usize,
    sample_rate_hz: f64,
    fundamental_hz: f64,
) -> Result<WholePeriods> {
    let rate = SampleRate::new(sample_rate_hz)?;
    let f0 = error::positive("fundamental_hz", fundamental_hz)?;
    let samples_per_period = rate.hz() / f0;
    let periods = (record_len as f64 / samples_per_period + 1e-9).floor();
    if periods < 1.0 {
        return Err(SignalError::RecordTooShort {
            what: "record (one period of the fundamental)",
            found: record_len,
            min: samples_per_period.round().max(1.0) as usize,
        });
    }
    let len = ((periods * samples_per_period).round() as usize).min(record_len);
    Ok(WholePeriods {
        periods: periods as usize,
        len,
    })
}

/// The leading part of `record` that holds a whole number of periods of `fundamental_hz`
/// (see [`whole_periods`]).
///
/// # Errors
/// As [`whole_periods`].
pub fn trim_to_whole_periods(
    record: &[f64],
    sample_rate_hz: f64,
    fundamental_hz: f64,
) -> Result<&[f64]> {
    let w = whole_periods(record.len(), sample_rate_hz, fundamental_hz)?;
    Ok(&record[..w.len])
}
