//! Butterworth low-pass, designed by the bilinear transform and run forward and backward.

use std::f64::consts::PI;

use crate::error::{self, Result, SignalError};
use crate::extend::odd_extend_into;
use crate::{SampleRate, ZeroPhaseFilter};

/// Largest accepted order; beyond it the second-order sections of a low cut-off are
/// ill-conditioned in `f64` and nothing in shake-table practice asks for it.
pub const MAX_BUTTERWORTH_ORDER: usize = 16;

/// One second-order section in transposed direct form II:
/// `H(z) = (b₀ + b₁z⁻¹ + b₂z⁻²)/(1 + a₁z⁻¹ + a₂z⁻²)`, normalised to unit gain at DC.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Section {
    b: [f64; 3],
    a: [f64; 2],
    /// State after an infinite run of a unit constant (SciPy's `sosfilt_zi` row).
    zi: [f64; 2],
}

impl Section {
    fn new(b: [f64; 3], a: [f64; 2]) -> Self {
        // Unit DC gain: for x ≡ 1 the output is y ≡ 1, so z₂ = b₂ − a₂ and z₁ = b₁ − a₁ + z₂.
        let z2 = b[2] - a[1];
        let z1 = b[1] - a[0] + z2;
        Section { b, a, zi: [z1, z2] }
    }

    /// Filters `buf` in place, starting from the steady state of the constant `buf[0]`.
    fn run(&self, buf: &mut [f64]) {
        let Some(&x0) = buf.first() else { return };
        let [b0, b1, b2] = self.b;
        let [a1, a2] = self.a;
        let (mut z1, mut z2) = (self.zi[0] * x0, self.zi[1] * x0);
        for v in buf.iter_mut() {
            let x = *v;
            let y = b0 * x + z1;
            z1 = b1 * x - a1 * y + z2;
            z2 = b2 * x - a2 * y;
            *v = y;
        }
    }
}

/// A Butterworth low-pass of order `N` run forward and backward (filtfilt): zero phase and
/// magnitude `|H|²`.
///
/// Design: the analog Butterworth prototype, cut-off prewarped to
/// `Ω_c = 2f_s·tan(πf_c/f_s)`, mapped by the bilinear transform and factored into second-order
/// sections (plus one first-order section for odd `N`), each with unit DC gain.
///
/// **Gain and phase.** The forward–backward amplitude is
/// `A(f) = |H(f)|² = 1 / (1 + (tan(πf/f_s)/tan(πf_c/f_s))^{2N})`: zero phase everywhere,
/// exactly 0.5 (−6 dB) at the cut-off, maximally flat at DC with
/// `1 − A(f) ≈ (f/f_c)^{2N}` in the pass band. Because `1 − A` vanishes to order `2N` at DC,
/// the filter passes polynomials of degree below `2N` unchanged away from the record edges.
/// For example `N = 4`, `f_c = 0.6 Hz`: `A(0.5 Hz) = 1/(1 + (5/6)⁸) = 0.811`.
///
/// **Edges** (as SciPy's `sosfiltfilt`, with a longer extension). The record is extended at
/// each end by odd reflection through its end sample ([`ButterworthLowpass::pad_len`]
/// samples), and each pass starts every section from the steady state of a constant equal to
/// the first sample it sees (SciPy's `sosfilt_zi` scaled by that sample), so a constant passes
/// with no transient at all. SciPy extends by `3·(N + 1)` samples, far shorter than
/// the impulse response when `f_c ≪ f_s` (15 samples for `N = 4`, against ≈ 700 samples for
/// the slowest pole's time constant at 0.6 Hz on 1024 Hz data), which leaves an edge transient
/// of the size of the ramp's lag `slope·τ_g` on any ramp. Here the default extension is
/// `3·ℓ`, with the filter length `ℓ = 3τ` the time the slowest pole takes to decay to
/// `e⁻³ ≈ 5 %`: the start-up mismatch has decayed by `e⁻⁹ ≈ 1.2·10⁻⁴` before the record begins.
/// An extension longer than the record is made by repeated reflection (see
/// [`with_pad_len`](Self::with_pad_len) to choose another length, e.g. SciPy's). As for
/// [`FirLowpass`](crate::FirLowpass), the end samples come out (nearly) unchanged, noise
/// included.
#[derive(Debug, Clone, PartialEq)]
pub struct ButterworthLowpass {
    order: usize,
    cutoff_hz: f64,
    rate: SampleRate,
    /// `tan(πf_c/f_s)`.
    warped: f64,
    sections: Vec<Section>,
    pad_len: usize,
}

impl ButterworthLowpass {
    /// Designs the filter: `order` `N` in `1..=16`, `cutoff_hz` `f_c` in
    /// `(0, sample_rate_hz/2)`, `sample_rate_hz` finite and > 0.
    ///
    /// # Errors
    /// [`SignalError::InvalidCount`] for an order outside `1..=16`,
    /// [`SignalError::InvalidParameter`] for a bad sample rate,
    /// [`SignalError::CutoffOutOfRange`] for a bad cut-off.
    pub fn new(order: usize, cutoff_hz: f64, sample_rate_hz: f64) -> Result<Self> {
        let rate = SampleRate::new(sample_rate_hz)?;
        if !(1..=MAX_BUTTERWORTH_ORDER).contains(&order) {
            return Err(SignalError::InvalidCount {
                name: "order",
                value: order,
                expected: "a Butterworth order in 1..=16",
            });
        }
        let cutoff_hz = error::cutoff("cutoff_hz", cutoff_hz, rate.hz())?;
        let k = (PI * cutoff_hz / rate.hz()).tan();
        let mut sections = Vec::with_capacity(order.div_ceil(2));
        let mut slowest_radius: f64 = 0.0;
        // Left-half-plane prototype poles p_j = exp(iπ(2j + N + 1)/(2N)), j = 0..N−1; pole j
        // pairs with its conjugate N−1−j. The bilinear image of Ω_c·p is
        // z = (1 + k·p)/(1 − k·p); written out, with d = |1 − k·p|² = 1 − 2k·Re p + k²:
        // a₁ = −2(1 − k²)/d, a₂ = (1 + 2k·Re p + k²)/d, and the gain g = k²/d on (1 + z⁻¹)².
        for j in 0..order / 2 {
            let re_p = (PI * (2 * j + order + 1) as f64 / (2 * order) as f64).cos();
            let d = 1.0 - 2.0 * k * re_p + k * k;
            let a1 = -2.0 * (1.0 - k * k) / d;
            let a2 = (1.0 + 2.0 * k * re_p + k * k) / d;
            // g = k²/d = (1 + a₁ + a₂)/4; taken from the stored a₁, a₂ (the sums are exact in
            // floating point when the poles are near z = 1, by Sterbenz's lemma) so that the
            // section's DC gain is one to rounding even for f_c ≪ f_s.
            let g = ((1.0 + a1) + a2) / 4.0;
            slowest_radius = slowest_radius.max(a2.sqrt());
            sections.push(Section::new([g, 2.0 * g, g], [a1, a2]));
        }
        if order % 2 == 1 {
            // Real pole p = −1: z = (1 − k)/(1 + k), gain k/(1 + k) = (1 − z)/2 on (1 + z⁻¹).
            let z = (1.0 - k) / (1.0 + k);
            let g = (1.0 - z) / 2.0;
            slowest_radius = slowest_radius.max(z.abs());
            sections.push(Section::new([g, g, 0.0], [-z, 0.0]));
        }
        // Time constant of the slowest pole, samples: r^τ = e⁻¹.
        let tau = -1.0 / slowest_radius.ln();
        let scipy_pad = 3 * (order + 1);
        let pad_len = ((9.0 * tau).ceil() as usize).max(scipy_pad);
        Ok(ButterworthLowpass {
            order,
            cutoff_hz,
            rate,
            warped: k,
            sections,
            pad_len,
        })
    }

    /// Sets the number of samples of odd extension at each end (at least 1).
    ///
    /// `3·(N + 1)` reproduces SciPy's `sosfiltfilt` default (`padtype='odd'`,
    /// `padlen = 3·ntaps`); the default of [`new`](Self::new) is much longer when `f_c ≪ f_s`
    /// (see the type's docs).
    ///
    /// # Errors
    /// [`SignalError::InvalidCount`] for `pad_len = 0`.
    pub fn with_pad_len(mut self, pad_len: usize) -> Result<Self> {
        if pad_len == 0 {
            return Err(SignalError::InvalidCount {
                name: "pad_len",
                value: pad_len,
                expected: "at least 1 sample of extension",
            });
        }
        self.pad_len = pad_len;
        Ok(self)
    }

    /// The order `N` of the single-pass filter. A single pass rolls off at `6N` dB per octave;
    /// the forward–backward magnitude `|H|²` at `12N` dB per octave.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The cut-off `f_c`, Hz: single-pass −3 dB, forward–backward −6 dB.
    pub fn cutoff_hz(&self) -> f64 {
        self.cutoff_hz
    }

    /// Samples of odd extension at each end of the record.
    pub fn pad_len(&self) -> usize {
        self.pad_len
    }

    /// The second-order sections in SciPy's `sos` layout `[b₀, b₁, b₂, 1, a₁, a₂]`, for
    /// cross-checks against `scipy.signal.butter(N, f_c, output='sos', fs=f_s)`.
    pub fn sos(&self) -> Vec<[f64; 6]> {
        self.sections
            .iter()
            .map(|s| [s.b[0], s.b[1], s.b[2], 1.0, s.a[0], s.a[1]])
            .collect()
    }

    /// Gain of a single (causal) pass, `|H(f)| = 1/√(1 + (tan(πf/f_s)/tan(πf_c/f_s))^{2N})`.
    pub fn single_pass_gain(&self, frequency_hz: f64) -> f64 {
        self.amplitude(frequency_hz).sqrt()
    }
}

impl ZeroPhaseFilter for ButterworthLowpass {
    fn sample_rate_hz(&self) -> f64 {
        self.rate.hz()
    }

    /// `|H(f)|² = 1 / (1 + (tan(πf/f_s)/tan(πf_c/f_s))^{2N})`, never negative.
    fn amplitude(&self, frequency_hz: f64) -> f64 {
        let ratio = (PI * frequency_hz / self.rate.hz()).tan().abs() / self.warped;
        1.0 / (1.0 + ratio.powi(2 * self.order as i32))
    }

    fn process(&self, input: &[f64], output: &mut [f64]) -> Result<()> {
        error::same_len(input, output)?;
        if input.is_empty() {
            return Ok(());
        }
        let mut ext = Vec::new();
        odd_extend_into(input, self.pad_len, &mut ext);
        for s in &self.sections {
            s.run(&mut ext);
        }
        ext.reverse();
        for s in &self.sections {
            s.run(&mut ext);
        }
        ext.reverse();
        output.copy_from_slice(&ext[self.pad_len..self.pad_len + input.len()]);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evaluates the product of the sections at `z = e^{iω}` (forward–backward: `|H|²`).
    fn sos_power(filter: &ButterworthLowpass, frequency_hz: f64) -> f64 {
        use rustfft::num_complex::Complex;
        let w = 2.0 * PI * frequency_hz / filter.sample_rate_hz();
        let zi = Complex::from_polar(1.0, -w);
        let mut h = Complex::new(1.0, 0.0);
        for s in filter.sos() {
            let num = s[0] + s[1] * zi + s[2] * zi * zi;
            let den = 1.0 + s[4] * zi + s[5] * zi * zi;
            h *= num / den;
        }
        h.norm_sqr()
    }

    #[test]
    fn sections_reproduce_the_closed_form_magnitude() {
        for order in 1..=8 {
            let f = ButterworthLowpass::new(order, 0.6, 1024.0).unwrap();
            for &hz in &[0.0, 0.1, 0.3, 0.6, 1.0, 3.0, 50.0] {
                let (a, b) = (f.amplitude(hz), sos_power(&f, hz));
                assert!(
                    (a - b).abs() < 1e-9 * (1.0 + a),
                    "N = {order}, {hz} Hz: closed form {a}, sections {b}"
                );
            }
            assert!((f.amplitude(0.6) - 0.5).abs() < 1e-12);
        }
    }

    /// `scipy.signal.butter(4, 8.0, output='sos', fs=512.0)` (SciPy 1.17): SciPy distributes
    /// the overall gain differently, so compare the denominators and each section's DC gain.
    #[test]
    fn denominators_match_scipy_for_order_4_at_8_hz_on_512_hz() {
        let f = ButterworthLowpass::new(4, 8.0, 512.0).unwrap();
        let mut den: Vec<[f64; 2]> = f.sos().iter().map(|s| [s[4], s[5]]).collect();
        den.sort_by(|x, y| x[1].total_cmp(&y[1]));
        let scipy = [
            [-1.825_096_005_140_963_3, 0.833_926_864_255_554_6],
            [-1.918_410_756_598_004_2, 0.927_693_125_891_298],
        ];
        for (ours, theirs) in den.iter().zip(&scipy) {
            for (a, b) in ours.iter().zip(theirs) {
                assert!((a - b).abs() < 1e-12, "{ours:?} vs {theirs:?}");
            }
        }
    }
}
