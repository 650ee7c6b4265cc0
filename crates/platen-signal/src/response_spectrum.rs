//! Linear response spectra of an acceleration record: the peak response of damped
//! single-degree-of-freedom oscillators ([`SdofOscillator`], [`ResponseSpectrum`]).

use crate::error::{positive, Result, SignalError};
use crate::SampleRate;

/// The most sub-steps a sample interval is cut into (a period shorter than `10·Δt/64` is
/// resolved at `Δt/64`).
const MAX_SUBSTEPS: usize = 64;

/// A damped linear oscillator on an acceleration record sampled at a fixed rate, planned once
/// (the exact step matrices), applied to any number of records: one period of a
/// [`ResponseSpectrum`] (see there for the method).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SdofOscillator {
    period_s: f64,
    damping_ratio: f64,
    rate: SampleRate,
    /// Sub-steps per sample interval.
    substeps: usize,
    /// `A` (row-major) of one sub-step.
    a: [f64; 4],
    /// `B` (row-major) of one sub-step.
    b: [f64; 4],
}

impl SdofOscillator {
    /// Plans the oscillator of natural period `period_s` (> 0) and damping ratio
    /// `damping_ratio` (in `[0, 1)`) on records sampled at `sample_rate_hz`.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] for a period or rate that is not finite and > 0, or a
    /// damping ratio outside `[0, 1)`.
    pub fn new(period_s: f64, damping_ratio: f64, sample_rate_hz: f64) -> Result<Self> {
        positive("period_s", period_s)?;
        let rate = SampleRate::new(sample_rate_hz)?;
        if !(damping_ratio.is_finite() && (0.0..1.0).contains(&damping_ratio)) {
            return Err(SignalError::InvalidParameter {
                name: "damping_ratio",
                value: damping_ratio,
                expected: "a ratio in [0, 1) (an underdamped oscillator)",
            });
        }
        let dt = rate.interval_s();
        let substeps = ((10.0 * dt / period_s).ceil() as usize).clamp(1, MAX_SUBSTEPS);
        let (a, b) = step_matrices(period_s, damping_ratio, dt / substeps as f64);
        Ok(Self {
            period_s,
            damping_ratio,
            rate,
            substeps,
            a,
            b,
        })
    }

    /// The natural period, s.
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// The damping ratio.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio
    }

    /// The circular natural frequency `ω = 2π/T`, rad/s.
    pub fn omega_rad_s(&self) -> f64 {
        std::f64::consts::TAU / self.period_s
    }

    /// The relative displacement `u` (m) and velocity `u̇` (m/s) at every sample of the base
    /// acceleration `a_m_s2`, from rest.
    pub fn response(&self, a_m_s2: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut u = Vec::with_capacity(a_m_s2.len());
        let mut v = Vec::with_capacity(a_m_s2.len());
        self.walk(a_m_s2, |x, xd, at_sample| {
            if at_sample {
                u.push(x);
                v.push(xd);
            }
        });
        (u, v)
    }

    /// The peak relative displacement `max|u|`, m (at the samples and at sub-steps of at
    /// most a tenth of the period, see [`ResponseSpectrum`]); 0 for an empty record.
    pub fn peak_displacement_m(&self, a_m_s2: &[f64]) -> f64 {
        let mut peak = 0.0_f64;
        self.walk(a_m_s2, |x, _, _| peak = peak.max(x.abs()));
        peak
    }

    /// The pseudo-acceleration `ω²·max|u|`, m/s².
    pub fn pseudo_acceleration_m_s2(&self, a_m_s2: &[f64]) -> f64 {
        let w = self.omega_rad_s();
        w * w * self.peak_displacement_m(a_m_s2)
    }

    /// Steps through the record, calling `visit(u, u̇, at_sample)` at every sample and
    /// sub-step (the first sample at rest included).
    fn walk(&self, a_m_s2: &[f64], mut visit: impl FnMut(f64, f64, bool)) {
        if a_m_s2.is_empty() {
            return;
        }
        let [a11, a12, a21, a22] = self.a;
        let [b11, b12, b21, b22] = self.b;
        let (mut x, mut xd) = (0.0_f64, 0.0_f64);
        visit(x, xd, true);
        let m = self.substeps;
        let inv_m = 1.0 / m as f64;
        for w in a_m_s2.windows(2) {
            let (p0, p1) = (w[0], w[1]);
            let slope = (p1 - p0) * inv_m;
            for j in 0..m {
                let f0 = p0 + slope * j as f64;
                let f1 = if j + 1 == m {
                    p1
                } else {
                    p0 + slope * (j + 1) as f64
                };
                let xn = a11 * x + a12 * xd + b11 * f0 + b12 * f1;
                let vn = a21 * x + a22 * xd + b21 * f0 + b22 * f1;
                x = xn;
                xd = vn;
                visit(x, xd, j + 1 == m);
            }
        }
    }
}

/// The exact step of `ü + 2ζωu̇ + ω²u = −f(t)` over `h` with `f` linear from `f₀` to `f₁`:
/// `(A, B)` row-major, `[u, u̇]₁ = A·[u, u̇]₀ + B·[f₀, f₁]` (Nigam & Jennings, 1969).
fn step_matrices(period_s: f64, zeta: f64, h: f64) -> ([f64; 4], [f64; 4]) {
    let w = std::f64::consts::TAU / period_s;
    let root = (1.0 - zeta * zeta).sqrt();
    let wd = w * root;
    let e = (-zeta * w * h).exp();
    let (s, c) = (wd * h).sin_cos();
    let r = zeta / root;
    let a11 = e * (r * s + c);
    let a12 = e * s / wd;
    let a21 = -w / root * e * s;
    let a22 = e * (c - r * s);
    let w2 = w * w;
    let w3 = w2 * w;
    let k1 = (2.0 * zeta * zeta - 1.0) / (w2 * h);
    let k2 = 2.0 * zeta / (w3 * h);
    let decay = c - r * s;
    let rot = wd * s + zeta * w * c;
    let b11 = e * ((k1 + zeta / w) * s / wd + (k2 + 1.0 / w2) * c) - k2;
    let b12 = -e * (k1 * s / wd + k2 * c) - 1.0 / w2 + k2;
    let b21 = e * ((k1 + zeta / w) * decay - (k2 + 1.0 / w2) * rot) + 1.0 / (w2 * h);
    let b22 = -e * (k1 * decay - k2 * rot) - 1.0 / (w2 * h);
    ([a11, a12, a21, a22], [b11, b12, b21, b22])
}

/// The response spectrum of acceleration records at a set of periods, one damping ratio,
/// one sample rate: planned once, applied to any number of records.
///
/// # Method
///
/// Each oscillator of natural period `T` (`ω = 2π/T`) and damping ratio `ζ < 1` obeys
/// `ü + 2ζωu̇ + ω²u = −a(t)` (relative displacement `u` of a mass on a base that accelerates
/// by `a`). The record is taken as **straight lines between its samples** (as PEER integrates
/// it), and each step is the **exact** solution for such a piecewise-linear load (Nigam &
/// Jennings, 1969, BSSA 59(2)): `[u, u̇]ᵢ₊₁ = A·[u, u̇]ᵢ + B·[aᵢ, aᵢ₊₁]` with the 2 × 2 matrices
/// `A`, `B` of the step computed once per oscillator. There is no step-size error: the only
/// approximation is the straight line between samples.
///
/// The peak is taken over the response at the record's samples and, where the sample interval
/// is longer than a tenth of the period, at sub-steps of at most `T/10` (the straight line is
/// cut into equal pieces, exact as well), so that a short period's peak between two samples
/// is not missed by more than `1 − cos(π/10) ≈ 5 %` (the worst case, a peak halfway between
/// two sub-steps; 1.6 % on average). The response starts at rest and stops at the record's
/// last sample (no free vibration after it).
///
/// The **pseudo-acceleration** is `PSA = ω²·max|u|` ([`ResponseSpectrum::pseudo_acceleration_m_s2`]).
///
/// ```
/// use platen_signal::{ResponseSpectrum, SdofOscillator};
/// use std::f64::consts::PI;
///
/// // A 2 Hz, 1 m/s² sine for 30 s at 200 Hz on a 5 %-damped oscillator of 0.5 s: resonance,
/// // the steady amplitude is A/(2ζω²), so PSA → A/(2ζ) = 10 m/s².
/// let fs_hz = 200.0;
/// let a: Vec<f64> = (0..6000).map(|j| (2.0 * PI * 2.0 * j as f64 / fs_hz).sin()).collect();
/// let sdof = SdofOscillator::new(0.5, 0.05, fs_hz)?;
/// let psa = sdof.pseudo_acceleration_m_s2(&a);
/// assert!((psa - 10.0).abs() < 0.1, "{psa}");
///
/// let spectrum = ResponseSpectrum::new(&ResponseSpectrum::log_periods_s(0.05, 2.0, 40)?, 0.05, fs_hz)?;
/// let psa = spectrum.pseudo_acceleration_m_s2(&a);
/// assert_eq!(psa.len(), 40);
/// # Ok::<(), platen_signal::SignalError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseSpectrum {
    oscillators: Vec<SdofOscillator>,
}

impl ResponseSpectrum {
    /// Plans the spectrum at `periods_s` (each finite and > 0, in any order; at least one),
    /// damping ratio `damping_ratio` (in `[0, 1)`; 0.05 is the usual 5 %) for records sampled at
    /// `sample_rate_hz`.
    ///
    /// # Errors
    /// As [`SdofOscillator::new`]; [`SignalError::InvalidCount`] for no period.
    pub fn new(periods_s: &[f64], damping_ratio: f64, sample_rate_hz: f64) -> Result<Self> {
        if periods_s.is_empty() {
            return Err(SignalError::InvalidCount {
                name: "periods_s",
                value: 0,
                expected: "at least one period",
            });
        }
        let oscillators = periods_s
            .iter()
            .map(|&t| SdofOscillator::new(t, damping_ratio, sample_rate_hz))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { oscillators })
    }

    /// `count` periods spaced evenly in logarithm from `min_s` to `max_s` (both included).
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] unless `0 < min_s ≤ max_s` (finite);
    /// [`SignalError::InvalidCount`] for `count < 2` (unless `min_s == max_s`, where 1 is
    /// accepted).
    pub fn log_periods_s(min_s: f64, max_s: f64, count: usize) -> Result<Vec<f64>> {
        positive("min_s", min_s)?;
        positive("max_s", max_s)?;
        if max_s < min_s {
            return Err(SignalError::InvalidParameter {
                name: "max_s",
                value: max_s,
                expected: "a period >= min_s",
            });
        }
        if count == 1 && min_s == max_s {
            return Ok(vec![min_s]);
        }
        if count < 2 {
            return Err(SignalError::InvalidCount {
                name: "count",
                value: count,
                expected: "at least 2 periods",
            });
        }
        let ratio = (max_s / min_s).ln();
        Ok((0..count)
            .map(|k| {
                if k + 1 == count {
                    max_s
                } else {
                    min_s * (ratio * k as f64 / (count - 1) as f64).exp()
                }
            })
            .collect())
    }

    /// The periods, s, in the order given.
    pub fn periods_s(&self) -> Vec<f64> {
        self.oscillators.iter().map(|o| o.period_s).collect()
    }

    /// The oscillators, one per period.
    pub fn oscillators(&self) -> &[SdofOscillator] {
        &self.oscillators
    }

    /// The pseudo-acceleration `ω²·max|u|` at each period, m/s².
    pub fn pseudo_acceleration_m_s2(&self, a_m_s2: &[f64]) -> Vec<f64> {
        self.oscillators
            .iter()
            .map(|o| o.pseudo_acceleration_m_s2(a_m_s2))
            .collect()
    }

    /// The peak relative displacement `max|u|` at each period, m.
    pub fn displacement_m(&self, a_m_s2: &[f64]) -> Vec<f64> {
        self.oscillators
            .iter()
            .map(|o| o.peak_displacement_m(a_m_s2))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// RK4 at `k` steps per sample on the same straight lines between samples.
    fn brute_force(a: &[f64], period_s: f64, zeta: f64, dt: f64, k: usize) -> Vec<f64> {
        let w = 2.0 * PI / period_s;
        let rhs = |x: f64, v: f64, f: f64| (v, -f - 2.0 * zeta * w * v - w * w * x);
        let h = dt / k as f64;
        let (mut x, mut v) = (0.0, 0.0);
        let mut out = vec![0.0];
        for win in a.windows(2) {
            let f = |tau: f64| win[0] + (win[1] - win[0]) * tau / dt;
            for j in 0..k {
                let t0 = j as f64 * h;
                let (k1x, k1v) = rhs(x, v, f(t0));
                let (k2x, k2v) = rhs(x + 0.5 * h * k1x, v + 0.5 * h * k1v, f(t0 + 0.5 * h));
                let (k3x, k3v) = rhs(x + 0.5 * h * k2x, v + 0.5 * h * k2v, f(t0 + 0.5 * h));
                let (k4x, k4v) = rhs(x + h * k3x, v + h * k3v, f(t0 + h));
                x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            }
            out.push(x);
        }
        out
    }

    #[test]
    fn a_sine_gives_the_closed_form_steady_state_amplitude() {
        // a = A·sin(Ωt): steady |u| = A/√((ω² − Ω²)² + (2ζωΩ)²). 5 % damping decays the
        // transient by e^(−ζωt): after 40 s at T = 1 s, e^(−12.6) ≈ 3e-6.
        let fs = 500.0;
        let amp = 2.0;
        for &(period, forcing_hz) in &[(1.0, 0.7), (1.0, 1.0), (0.2, 3.0), (2.0, 1.3)] {
            let n = (150.0 * fs) as usize;
            let big_w = 2.0 * PI * forcing_hz;
            let a: Vec<f64> = (0..n)
                .map(|j| amp * (big_w * j as f64 / fs).sin())
                .collect();
            let sdof = SdofOscillator::new(period, 0.05, fs).unwrap();
            let w = sdof.omega_rad_s();
            let expected =
                amp / ((w * w - big_w * big_w).powi(2) + (0.1 * w * big_w).powi(2)).sqrt();
            let (u, _) = sdof.response(&a);
            let steady = u[n - (20.0 * fs) as usize..]
                .iter()
                .fold(0.0_f64, |m, x| m.max(x.abs()));
            // The straight lines between samples and the sampled peak: (ΩΔt)²/8 ≈ 2e-4 at most.
            assert!(
                (steady - expected).abs() < 5e-4 * expected,
                "T = {period}, f = {forcing_hz}: {steady} vs {expected}"
            );
        }
    }

    #[test]
    fn sub_steps_catch_the_peak_of_a_short_period_between_samples() {
        // T = 0.02 s at 100 Hz: two samples a period; the sub-steps resolve it.
        let sdof = SdofOscillator::new(0.02, 0.05, 100.0).unwrap();
        assert_eq!(sdof.substeps, 5);
        let a: Vec<f64> = (0..300).map(|j| if j == 10 { 1.0 } else { 0.0 }).collect();
        let fine = brute_force(&a, 0.02, 0.05, 0.01, 2000);
        let peak = sdof.peak_displacement_m(&a);
        let fine_peak = fine.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(
            peak >= fine_peak * (1.0 - 1e-9),
            "{peak} vs {fine_peak} at the samples"
        );
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(SdofOscillator::new(0.0, 0.05, 100.0).is_err());
        assert!(SdofOscillator::new(1.0, 1.0, 100.0).is_err());
        assert!(SdofOscillator::new(1.0, -0.1, 100.0).is_err());
        assert!(SdofOscillator::new(1.0, 0.05, f64::NAN).is_err());
        assert!(ResponseSpectrum::new(&[], 0.05, 100.0).is_err());
        assert!(ResponseSpectrum::log_periods_s(2.0, 1.0, 10).is_err());
        let p = ResponseSpectrum::log_periods_s(0.05, 2.0, 3).unwrap();
        assert_eq!(p[0], 0.05);
        assert_eq!(p[2], 2.0);
        assert!((p[1] - (0.05_f64 * 2.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn the_exact_step_matches_a_fine_rk4_integration_of_the_same_straight_lines() {
        // A decaying chirp-like record at 100 Hz, periods short and long, damping 0 to 20 %.
        let dt = 0.01;
        let a: Vec<f64> = (0..1500)
            .map(|j| {
                let t = j as f64 * dt;
                3.0 * (-0.1 * t).exp() * (2.0 * PI * (0.5 + 0.3 * t) * t).sin()
                    + if j % 37 == 0 { 1.0 } else { 0.0 }
            })
            .collect();
        for &(period, zeta) in &[(0.05, 0.05), (0.3, 0.0), (1.0, 0.05), (2.0, 0.2)] {
            // The plan at 10x the period's sub-steps would differ only by sub-stepping:
            // compare at the samples.
            let sdof = SdofOscillator::new(period, zeta, 1.0 / dt).unwrap();
            let (u, _) = sdof.response(&a);
            let reference = brute_force(&a, period, zeta, dt, 200);
            let scale = reference.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let worst = u
                .iter()
                .zip(&reference)
                .fold(0.0_f64, |m, (x, r)| m.max((x - r).abs()));
            assert!(worst < 1e-9 * scale, "T = {period}: {worst} of {scale}");
        }
    }
}
