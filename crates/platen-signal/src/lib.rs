//! Signal processing for shake-table records, independent of the platen model: zero-phase
//! low-pass filters, differentiation and integration, the crossover velocity estimate,
//! resampling and power spectral densities.
//!
//! Every tool is planned once (parameters validated, coefficients designed, FFTs planned) and
//! then applied to any number of records, as RustFFT's planner → `process`:
//!
//! ```
//! use platen_signal::{ButterworthLowpass, FirLowpass, SpectralLowpass, Window, ZeroPhaseFilter};
//! use std::f64::consts::PI;
//!
//! // Test SR9 of the paper: T = 2 s, recorded at 1024 Hz, force low-passed at 0.6 Hz.
//! let fs_hz = 1024.0;
//! let t_s: Vec<f64> = (0..5 * 2048).map(|i| i as f64 / fs_hz).collect();
//! let x: Vec<f64> = t_s.iter().map(|t| (2.0 * PI * 0.5 * t).sin()).collect();
//!
//! // A 4th-order Butterworth run forward and backward keeps |H(0.5 Hz)|² = 81 % of the sine …
//! let butter = ButterworthLowpass::new(4, 0.6, fs_hz)?;
//! assert!((butter.gain(0.5) - 0.811).abs() < 1e-3);
//! // … the brick wall over whole periods keeps all of it, in phase.
//! let brick = SpectralLowpass::new(x.len(), 0.6, fs_hz)?;
//! let y = brick.apply(&x)?;
//! assert!(x.iter().zip(&y).all(|(a, b)| (a - b).abs() < 1e-12));
//!
//! // The paper's force filter (§3.3): FIR of order 512 with an 8 Hz cut-off on the recorder's
//! // 512 Hz data keeps the test frequencies (Hamming ripple < 0.4 %) and removes the 10.66 Hz
//! // oil-column component (gain 5·10⁻⁴).
//! let fir = FirLowpass::new(512, 8.0, 512.0, Window::Hamming)?;
//! assert!((fir.gain(1.0) - 1.0).abs() < 4e-3 && fir.gain(10.66) < 1e-3);
//! assert_eq!(fir.phase_rad(1.0), 0.0);
//! # Ok::<(), platen_signal::SignalError>(())
//! ```
//!
//! # What is here
//!
//! * Zero-phase low-pass filters, all implementing [`ZeroPhaseFilter`]:
//!   [`FirLowpass`] (windowed sinc), [`ButterworthLowpass`] (forward–backward),
//!   [`SpectralLowpass`] (FFT brick wall for periodic records; trim with
//!   [`trim_to_whole_periods`]).
//! * [`differentiate`], [`cumulative_trapezoid`], [`MotionIntegrator`] (acceleration →
//!   velocity → displacement with a [`Baseline`] correction), [`remove_polynomial`].
//! * [`Motion`]: a table motion (displacement, velocity, acceleration at checked sample
//!   times), what [`MotionIntegrator`] returns and an inverse run of `platen_integrate`
//!   takes; [`derivative`] and [`second_derivative`] on a non-uniform time grid.
//! * [`CrossoverVelocity`]: velocity from displacement and acceleration (paper §1.5, ref. \[14\]).
//! * [`DelayEstimator`]: a channel's skew (delay) against a reference, to a fraction of a
//!   sample with its standard error; [`advance`] shifts a channel by a non-integer number of
//!   samples to remove it.
//! * [`Resampler`]: band-limited change of sample rate.
//! * [`AccelerogramMotion`]: the table motion of a ground-acceleration record as PEER
//!   integrates it (straight lines between samples, exact integrals), with a [`Baseline`].
//! * [`Welch`]: power spectral density ([`Psd`], with [`Psd::rms_in_band`]) and cross-spectra
//!   ([`CrossSpectra`]: transfer functions and coherence).
//! * [`ResponseSpectrum`]: damped SDOF response spectra (pseudo-acceleration) by the exact
//!   piecewise-linear step of Nigam & Jennings ([`SdofOscillator`]).
//!
//! # Conventions
//!
//! * **Units.** SI throughout, and the unit is part of every name: `sample_rate_hz`,
//!   `cutoff_hz`, `frequency_hz`, `t_s`, `u_m`, `v_m_s`, `a_m_s2`, `phase_rad`.
//! * **Sampling.** Records are uniformly sampled; sample `i` is at `t_s = i/sample_rate_hz`
//!   from the record's start. Only [`Motion`] and the derivatives on a time grid take time
//!   columns (and [`Motion`] checks only that time increases): check uniformity first.
//! * **Zero phase, not causal.** Every low-pass here is zero-phase (non-causal): output sample
//!   `i` depends on inputs before and after it, and a pass-band sine comes out in phase with the
//!   input, with no delay. Their response is a real *amplitude* `A(f)`
//!   ([`ZeroPhaseFilter::amplitude`]); the gain is `|A(f)|` and the phase is 0 where `A ≥ 0`
//!   (the whole pass band, and everywhere for the Butterworth and brick-wall filters) and π
//!   where a windowed-sinc stop-band lobe is negative. Use them on recorded data, not inside a
//!   real-time loop.
//! * **Record edges.** The FIR and Butterworth filters extend the record by odd reflection
//!   through its end samples (`x(−k) = 2x(0) − x(k)`), which keeps value and slope continuous
//!   and reproduces constants and ramps exactly; the Butterworth also starts each pass from the
//!   steady state of the first sample, so a constant passes untouched. The price of the odd
//!   reflection: a symmetric filter returns each end sample unchanged, so noise on the first and
//!   last samples is not smoothed and leaks into the output within a filter length of the
//!   edges (the [`CrossoverVelocity`] is built to avoid this). The brick wall treats
//!   the record as periodic (the wrap-around jump of a record that does not hold whole periods
//!   leaks as Gibbs ripples). Differentiation is one-sided at the ends. See each type.
//! * **Validation.** Parameters are checked when a plan is built (cut-off in `(0, f_s/2)`,
//!   orders, finite positive rates), and processing never re-checks them; processing can fail
//!   only because a record's length does not fit ([`SignalError::LengthMismatch`],
//!   [`SignalError::RecordTooShort`]). Nothing panics on any input.
//! * **Cost.** Processing allocates a few buffers per record, never per sample; FFT plans are
//!   made once per plan. Long FIR filters run by FFT overlap-save.

#![warn(missing_docs)]

mod accelerogram;
mod butterworth;
mod calculus;
mod crossover;
mod delay;
mod error;
mod extend;
mod fir;
pub mod linalg;
pub mod metrics;
mod motion;
mod resample;
mod response_spectrum;
mod spectral;
mod welch;
mod window;

pub use accelerogram::AccelerogramMotion;
pub use butterworth::{ButterworthLowpass, MAX_BUTTERWORTH_ORDER};
pub use calculus::{
    cumulative_trapezoid, differentiate, remove_polynomial, Baseline, InitialMotion,
    MotionIntegrator, MAX_BASELINE_ORDER,
};
pub use crossover::{CrossoverVelocity, DEFAULT_CROSSOVER_HZ};
pub use delay::{
    advance, DelayEstimate, DelayEstimator, MAX_LAG_S, MAX_RELATIVE_FREQUENCY, MIN_BINS,
    MIN_COHERENCE, MIN_DELAY_SAMPLES, SEGMENT_S,
};
pub use error::{Result, SignalError};
pub use fir::{FirLowpass, MAX_FIR_ORDER};
pub use motion::{check_len, check_times, derivative, second_derivative, Motion};
pub use resample::{Interpolation, Resampler};
pub use response_spectrum::{ResponseSpectrum, SdofOscillator};
pub use spectral::{trim_to_whole_periods, whole_periods, SpectralLowpass, WholePeriods};
pub use welch::{CrossSpectra, Psd, Welch};
pub use window::Window;

/// A validated sample rate: finite and > 0, Hz.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct SampleRate(f64);

impl SampleRate {
    /// Checks `sample_rate_hz`.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] unless it is finite and > 0.
    pub fn new(sample_rate_hz: f64) -> Result<Self> {
        error::positive("sample_rate_hz", sample_rate_hz).map(SampleRate)
    }

    /// The rate, Hz.
    pub fn hz(self) -> f64 {
        self.0
    }

    /// The sample interval `Δt = 1/f_s`, s.
    pub fn interval_s(self) -> f64 {
        1.0 / self.0
    }

    /// The Nyquist frequency `f_s/2`, Hz.
    pub fn nyquist_hz(self) -> f64 {
        0.5 * self.0
    }
}

/// A linear, zero-phase (non-causal) filter applied to whole records.
///
/// Its frequency response is real: the *amplitude* `A(f)`; gain `|A(f)|`, phase 0 or π.
pub trait ZeroPhaseFilter {
    /// The sample rate the filter was designed for, Hz.
    fn sample_rate_hz(&self) -> f64;

    /// The real frequency response `A(f)` at `frequency_hz` (a sine at `f` comes out
    /// multiplied by `A(f)`, away from the record edges).
    fn amplitude(&self, frequency_hz: f64) -> f64;

    /// The gain `|A(f)|` at `frequency_hz`.
    fn gain(&self, frequency_hz: f64) -> f64 {
        self.amplitude(frequency_hz).abs()
    }

    /// The phase at `frequency_hz`, rad: 0 where `A(f) ≥ 0`, π where `A(f) < 0` (only in a
    /// windowed-sinc stop band).
    fn phase_rad(&self, frequency_hz: f64) -> f64 {
        if self.amplitude(frequency_hz) < 0.0 {
            std::f64::consts::PI
        } else {
            0.0
        }
    }

    /// Filters `input` into `output`.
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] if `output.len() != input.len()` (or, for a
    /// [`SpectralLowpass`], if `input` does not have the planned length).
    fn process(&self, input: &[f64], output: &mut [f64]) -> Result<()>;

    /// Filters `input` into a new vector.
    ///
    /// # Errors
    /// As [`process`](Self::process).
    fn apply(&self, input: &[f64]) -> Result<Vec<f64>> {
        let mut output = vec![0.0; input.len()];
        self.process(input, &mut output)?;
        Ok(output)
    }
}

impl<T: ZeroPhaseFilter + ?Sized> ZeroPhaseFilter for &T {
    fn sample_rate_hz(&self) -> f64 {
        (**self).sample_rate_hz()
    }
    fn amplitude(&self, frequency_hz: f64) -> f64 {
        (**self).amplitude(frequency_hz)
    }
    fn process(&self, input: &[f64], output: &mut [f64]) -> Result<()> {
        (**self).process(input, output)
    }
}
