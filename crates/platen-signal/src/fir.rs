//! Windowed-sinc FIR low-pass, applied with zero phase.

use std::f64::consts::PI;
use std::fmt;
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use crate::error::{self, Result, SignalError};
use crate::extend::odd_extend_into;
use crate::{SampleRate, Window, ZeroPhaseFilter};

/// Largest accepted FIR order (2²⁴).
pub const MAX_FIR_ORDER: usize = 1 << 24;

/// Filters with at most this many taps are applied by direct convolution; longer ones by FFT
/// overlap-save (both give the same result to rounding, see the tests).
const DIRECT_MAX_TAPS: usize = 32;

/// A linear-phase windowed-sinc FIR low-pass, applied with its delay removed (zero phase).
///
/// Design: the ideal low-pass impulse response `2f_c/f_s·sinc(2f_c/f_s·(k − M/2))`,
/// `k = 0..=M`, times the window, scaled so that the taps sum to one (unit DC gain, as
/// SciPy's `firwin`). The order `M` is even, so the `M + 1` taps are symmetric about the
/// integer delay `M/2`, which is removed: output sample `i` is `Σ h[k]·x[i + k − M/2]`.
///
/// **Gain and phase.** The response is the real amplitude
/// `A(f) = h[M/2] + 2·Σ_{j=1}^{M/2} h[M/2 + j]·cos(2πf·j/f_s)` ([`ZeroPhaseFilter::amplitude`]):
/// zero phase, unit gain at DC, ≈ 0.5 (−6 dB) at the cut-off, gain within the window's ripple
/// of one in the pass band below `f_c − Δf/2` (Hamming: ≈ 0.4 %), and below the window's
/// stop-band level above `f_c + Δf/2` (Hamming: ≈ −53 dB), where the transition width is
/// `Δf ≈ 3.3·f_s/M` for Hamming (see [`Window`]). In the stop band `A(f)` changes sign from
/// lobe to lobe; where it is negative the phase is π.
///
/// Mind the rate: order 512 at 8 Hz has `Δf ≈ 3.3 Hz` at 512 Hz (gain 5·10⁻⁴ at the 10.66 Hz
/// oil-column frequency) but `Δf ≈ 6.6 Hz` at 1024 Hz (gain 0.024 there, −32 dB): scale the
/// order with the sample rate (order 1024 at 1024 Hz) to keep the same filter.
///
/// **Edges.** The record is extended by `M/2` samples at each end by odd reflection through
/// its end samples (`x(−k) = 2x(0) − x(k)`). A symmetric filter with unit DC gain reproduces any
/// straight line exactly, and the odd reflection of a line is the same line, so a DC offset or
/// a ramp passes without an edge transient; other signals see a filter that is accurate up to
/// the record's last sample, with the curvature mirrored beyond it. Because the extension is
/// point-symmetric about the end sample and the taps are symmetric, the output's end samples
/// equal the input's: noise on them is not smoothed.
///
/// The paper (§3.3) filters actuator forces with an FIR of order 512 at 8 Hz:
/// `FirLowpass::new(512, 8.0, 512.0, Window::Hamming)` (the recorder ran at 512 Hz).
#[derive(Clone)]
pub struct FirLowpass {
    taps: Vec<f64>,
    cutoff_hz: f64,
    rate: SampleRate,
    window: Window,
    fft: Option<FftConvolver>,
}

/// Overlap-save convolution plan for one kernel.
#[derive(Clone)]
struct FftConvolver {
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    /// FFT of the kernel, zero-padded to the FFT length and divided by it.
    kernel_spectrum: Vec<Complex<f64>>,
    scratch_len: usize,
}

impl fmt::Debug for FirLowpass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FirLowpass")
            .field("order", &self.order())
            .field("cutoff_hz", &self.cutoff_hz)
            .field("sample_rate_hz", &self.rate.hz())
            .field("window", &self.window)
            .field(
                "fft_len",
                &self.fft.as_ref().map(|c| c.kernel_spectrum.len()),
            )
            .finish()
    }
}

impl FirLowpass {
    /// Designs the filter.
    ///
    /// * `order` — `M`, even, in `2..=MAX_FIR_ORDER` (`M + 1` taps; delay `M/2` samples,
    ///   removed);
    /// * `cutoff_hz` — the −6 dB frequency, in `(0, sample_rate_hz/2)`;
    /// * `sample_rate_hz` — finite, > 0;
    /// * `window` — taper ([`Window::Hamming`] is the default).
    ///
    /// # Errors
    /// [`SignalError::InvalidCount`] for an odd or zero order, [`SignalError::InvalidParameter`]
    /// for a bad sample rate, [`SignalError::CutoffOutOfRange`] for a bad cut-off.
    pub fn new(order: usize, cutoff_hz: f64, sample_rate_hz: f64, window: Window) -> Result<Self> {
        let rate = SampleRate::new(sample_rate_hz)?;
        if order < 2 || order % 2 != 0 || order > MAX_FIR_ORDER {
            return Err(SignalError::InvalidCount {
                name: "order",
                value: order,
                expected:
                    "an even order in 2..=16777216 (a symmetric filter with an integer delay)",
            });
        }
        let cutoff_hz = error::cutoff("cutoff_hz", cutoff_hz, rate.hz())?;
        let w = window.symmetric(order + 1);
        let nu = 2.0 * cutoff_hz / rate.hz();
        let half = order / 2;
        // Computed on one half and mirrored, so the taps are exactly symmetric.
        let mut taps = vec![0.0; order + 1];
        for k in 0..=half {
            let h = nu * sinc(nu * (k as f64 - half as f64)) * w[k];
            taps[k] = h;
            taps[order - k] = h;
        }
        let sum: f64 = taps.iter().sum();
        for h in &mut taps {
            *h /= sum;
        }
        let fft = (taps.len() > DIRECT_MAX_TAPS).then(|| FftConvolver::new(&taps));
        Ok(FirLowpass {
            taps,
            cutoff_hz,
            rate,
            window,
            fft,
        })
    }

    /// The order `M` (the number of taps is `M + 1`).
    pub fn order(&self) -> usize {
        self.taps.len() - 1
    }

    /// The design cut-off, Hz (where the gain is ≈ 0.5).
    pub fn cutoff_hz(&self) -> f64 {
        self.cutoff_hz
    }

    /// The window used in the design.
    pub fn window(&self) -> Window {
        self.window
    }

    /// The `M + 1` symmetric taps, summing to one.
    pub fn taps(&self) -> &[f64] {
        &self.taps
    }

    /// Zero-phase convolution of an already extended record (`ext.len() == out.len() + M`).
    fn convolve_direct(&self, ext: &[f64], out: &mut [f64]) {
        let m1 = self.taps.len();
        for (i, y) in out.iter_mut().enumerate() {
            *y = self
                .taps
                .iter()
                .zip(&ext[i..i + m1])
                .map(|(h, x)| h * x)
                .sum();
        }
    }
}

impl FftConvolver {
    fn new(taps: &[f64]) -> Self {
        let fft_len = (4 * taps.len()).next_power_of_two();
        let mut planner = FftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(fft_len);
        let inverse = planner.plan_fft_inverse(fft_len);
        let scratch_len = forward
            .get_inplace_scratch_len()
            .max(inverse.get_inplace_scratch_len());
        let scale = 1.0 / fft_len as f64;
        let mut kernel_spectrum = vec![Complex::new(0.0, 0.0); fft_len];
        for (c, h) in kernel_spectrum.iter_mut().zip(taps) {
            *c = Complex::new(h * scale, 0.0);
        }
        let mut scratch = vec![Complex::new(0.0, 0.0); scratch_len];
        forward.process_with_scratch(&mut kernel_spectrum, &mut scratch);
        FftConvolver {
            forward,
            inverse,
            kernel_spectrum,
            scratch_len,
        }
    }

    /// Overlap-save: `out[i] = Σ_k h[k]·ext[i + M − k]` for a kernel of `M + 1` taps
    /// (`ext.len() == out.len() + M`). Two real blocks ride in one complex FFT (real and
    /// imaginary parts), which is exact because the kernel is real.
    fn convolve(&self, order: usize, ext: &[f64], out: &mut [f64]) {
        let fft_len = self.kernel_spectrum.len();
        let block = fft_len - order;
        let mut buf = vec![Complex::new(0.0, 0.0); fft_len];
        let mut scratch = vec![Complex::new(0.0, 0.0); self.scratch_len];
        let n = out.len();
        let at = |j: usize| ext.get(j).copied().unwrap_or(0.0);
        let mut start = 0;
        while start < n {
            let second = start + block;
            for (j, c) in buf.iter_mut().enumerate() {
                *c = Complex::new(at(start + j), at(second + j));
            }
            self.forward.process_with_scratch(&mut buf, &mut scratch);
            for (c, k) in buf.iter_mut().zip(&self.kernel_spectrum) {
                *c *= k;
            }
            self.inverse.process_with_scratch(&mut buf, &mut scratch);
            let valid = &buf[order..];
            for (y, c) in out[start..].iter_mut().zip(valid) {
                *y = c.re;
            }
            if second < n {
                for (y, c) in out[second..].iter_mut().zip(valid) {
                    *y = c.im;
                }
            }
            start += 2 * block;
        }
    }
}

impl ZeroPhaseFilter for FirLowpass {
    fn sample_rate_hz(&self) -> f64 {
        self.rate.hz()
    }

    /// `A(f) = h[M/2] + 2·Σ_{j=1}^{M/2} h[M/2 + j]·cos(2πf·j/f_s)`.
    fn amplitude(&self, frequency_hz: f64) -> f64 {
        let half = self.taps.len() / 2;
        let w = 2.0 * PI * frequency_hz / self.rate.hz();
        self.taps[half]
            + 2.0
                * self.taps[half + 1..]
                    .iter()
                    .enumerate()
                    .map(|(j, h)| h * (w * (j + 1) as f64).cos())
                    .sum::<f64>()
    }

    fn process(&self, input: &[f64], output: &mut [f64]) -> Result<()> {
        error::same_len(input, output)?;
        if input.is_empty() {
            return Ok(());
        }
        let order = self.order();
        let mut ext = Vec::new();
        odd_extend_into(input, order / 2, &mut ext);
        match &self.fft {
            Some(conv) => conv.convolve(order, &ext, output),
            None => self.convolve_direct(&ext, output),
        }
        Ok(())
    }
}

/// `sin(πx)/(πx)`, 1 at 0.
fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        let px = PI * x;
        px.sin() / px
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Naive reference: the defining sum with the odd extension evaluated sample by sample.
    fn reference(fir: &FirLowpass, x: &[f64]) -> Vec<f64> {
        let half = (fir.order() / 2) as isize;
        (0..x.len() as isize)
            .map(|i| {
                fir.taps()
                    .iter()
                    .enumerate()
                    .map(|(k, h)| h * crate::extend::odd_extension_at(x, i + k as isize - half))
                    .sum()
            })
            .collect()
    }

    fn pseudo_random(n: usize) -> Vec<f64> {
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn fft_and_direct_convolution_agree_with_the_naive_sum_on_random_records() {
        for &(order, n) in &[
            (16, 7),
            (16, 300),
            (64, 10),
            (64, 1000),
            (512, 3000),
            (512, 200),
        ] {
            let fir = FirLowpass::new(order, 20.0, 1024.0, Window::Hamming).unwrap();
            assert_eq!(fir.fft.is_some(), order + 1 > DIRECT_MAX_TAPS);
            let x = pseudo_random(n);
            let fast = fir.apply(&x).unwrap();
            let slow = reference(&fir, &x);
            let err = fast
                .iter()
                .zip(&slow)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-13, "order {order}, n {n}: max error {err}");
        }
    }

    #[test]
    fn taps_are_symmetric_and_sum_to_one() {
        let fir = FirLowpass::new(512, 8.0, 1024.0, Window::default()).unwrap();
        let h = fir.taps();
        assert_eq!(h.len(), 513);
        for k in 0..h.len() {
            assert_eq!(h[k], h[h.len() - 1 - k]);
        }
        assert!((h.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!((fir.amplitude(0.0) - 1.0).abs() < 1e-13);
    }
}
