//! Crossover (complementary-filter) velocity estimate from displacement and acceleration.

use std::f64::consts::PI;

use crate::butterworth::ButterworthLowpass;
use crate::calculus::{cumulative_trapezoid, differentiate, remove_polynomial};
use crate::error::{Result, SignalError};
use crate::{SampleRate, ZeroPhaseFilter};

/// The crossover frequency platen uses wherever a record has no velocity channel, Hz: a motion
/// file with `u_m` and `a_m_s2`, `compare` against such a recording, recorded-like data and
/// identification's default. Table tests put their displacement content below it and the
/// accelerometer's drift is far below it, so each path is used where it is accurate.
pub const DEFAULT_CROSSOVER_HZ: f64 = 2.0;

/// Velocity from a displacement record and an acceleration record by a crossover filter (the
/// paper's §1.5, ref. \[14\]):
///
/// `v̂ = L(d/dt u) + (I − L)(∫ a dt)`,
///
/// where `L` is a zero-phase low-pass and `I − L` its exact complement, so the two weights add
/// to one at every frequency. The displacement transducer is accurate at low frequencies and
/// its derivative is noisy at high frequencies; the integrated accelerometer is accurate at high
/// frequencies and drifts at low ones.
///
/// **How it is computed.** The crossover is made on displacement and then differentiated:
/// `v̂ = d/dt[L u + (I − L) W]` with `W = ∬a` (two [`cumulative_trapezoid`]s from zero) and
/// [`differentiate`]. Away from the record edges this is the formula above, since
/// differentiation, integration and `L` are linear and time-invariant and commute. At the edges
/// it is far better: the odd extension of a zero-phase filter passes the end sample through
/// unsmoothed, and on displacement that sample carries the transducer noise `σ_u`, where on the
/// differentiated displacement it would carry the noise of a one-sided derivative, ≈ 2.5·σ_u·f_s.
/// It is evaluated as `L u + (I − L)W = u − (I − L) r`, where `r` is `u − W` with its
/// least-squares quadratic removed: the integration constants (`u₀ + v₀t`) and an acceleration
/// bias (`b·t²/2`) make exactly such a quadratic, which `I − L` would remove in the interior
/// anyway (up to a constant, which differentiation removes) but which the odd extension would
/// bend at the edges.
///
/// **Gain and phase of each path** (relative to the true velocity, for a sine at `f`, away from
/// the edges):
/// * displacement path: `L(f)·sin(2πfΔt)/(2πfΔt)` (central difference), zero phase;
/// * acceleration path: `(1 − L(f))·(πfΔt)/tan(πfΔt)·cos²(πfΔt)` (two trapezoids and a central
///   difference), zero phase;
///
/// the weights [`displacement_weight`](Self::displacement_weight) `= L(f)` and
/// [`acceleration_weight`](Self::acceleration_weight) `= 1 − L(f)` sum to one exactly; the
/// discretisation factors differ from one by less than `(2πfΔt)²/3` (0.5 % at 20 Hz on 1024 Hz
/// data). With the Butterworth `L` of order `N` ([`butterworth`](Self::butterworth)),
/// `1 − L(f) = (f/f_c)^{2N}/(1 + (f/f_c)^{2N})` (prewarped), both weights are 0.5 at the
/// crossover frequency.
///
/// **Drift.** The unknown initial velocity and displacement and an acceleration bias are the
/// quadratic removed above, so they do not reach the estimate, edges included. Slower drifts
/// (integrated accelerometer noise) are high-passed by `I − L`.
#[derive(Debug, Clone)]
pub struct CrossoverVelocity<L = ButterworthLowpass> {
    low_pass: L,
    rate: SampleRate,
}

impl CrossoverVelocity<ButterworthLowpass> {
    /// The crossover platen uses wherever a record has no velocity: 2nd-order Butterworth at
    /// [`DEFAULT_CROSSOVER_HZ`].
    ///
    /// # Errors
    /// As [`butterworth`](Self::butterworth) (a rate of at most 4 Hz).
    pub fn standard(sample_rate_hz: f64) -> Result<Self> {
        Self::butterworth(2, DEFAULT_CROSSOVER_HZ, sample_rate_hz)
    }

    /// Crossover with a forward–backward Butterworth low-pass of `order` at `crossover_hz`
    /// (both paths weigh 0.5 there). Order 2 is a good default: a weight falling off as
    /// `(f/f_c)⁴` on each side.
    ///
    /// # Errors
    /// As [`ButterworthLowpass::new`], with the cut-off named `crossover_hz`.
    pub fn butterworth(order: usize, crossover_hz: f64, sample_rate_hz: f64) -> Result<Self> {
        let low_pass =
            ButterworthLowpass::new(order, crossover_hz, sample_rate_hz).map_err(|e| match e {
                SignalError::CutoffOutOfRange {
                    cutoff_hz,
                    sample_rate_hz,
                    nyquist_hz,
                    ..
                } => SignalError::CutoffOutOfRange {
                    name: "crossover_hz",
                    cutoff_hz,
                    sample_rate_hz,
                    nyquist_hz,
                },
                other => other,
            })?;
        Self::new(low_pass)
    }
}

impl<L: ZeroPhaseFilter> CrossoverVelocity<L> {
    /// Crossover with any zero-phase low-pass `L` (its sample rate is the records').
    ///
    /// The complement is exact for any linear `L`; `L` should have unit DC gain for the
    /// acceleration path to reject drift.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] if `L` reports a sample rate that is not finite and
    /// positive (the filters of this crate never do).
    pub fn new(low_pass: L) -> Result<Self> {
        let rate = SampleRate::new(low_pass.sample_rate_hz())?;
        Ok(CrossoverVelocity { low_pass, rate })
    }

    /// The low-pass `L` of the displacement path.
    pub fn low_pass(&self) -> &L {
        &self.low_pass
    }

    /// Weight `L(f)` of the displacement path at `frequency_hz`.
    pub fn displacement_weight(&self, frequency_hz: f64) -> f64 {
        self.low_pass.amplitude(frequency_hz)
    }

    /// Weight `1 − L(f)` of the acceleration path at `frequency_hz`.
    pub fn acceleration_weight(&self, frequency_hz: f64) -> f64 {
        1.0 - self.low_pass.amplitude(frequency_hz)
    }

    /// Gain of the displacement path relative to the true velocity, including the central
    /// difference: `L(f)·sin(2πfΔt)/(2πfΔt)` (zero phase).
    pub fn displacement_path_gain(&self, frequency_hz: f64) -> f64 {
        let x = 2.0 * PI * frequency_hz / self.rate.hz();
        let diff = if x == 0.0 { 1.0 } else { x.sin() / x };
        self.displacement_weight(frequency_hz) * diff
    }

    /// Gain of the acceleration path relative to the true velocity, including the two
    /// trapezoids and the central difference: `(1 − L(f))·(πfΔt)/tan(πfΔt)·cos²(πfΔt)`
    /// (zero phase).
    pub fn acceleration_path_gain(&self, frequency_hz: f64) -> f64 {
        let x = PI * frequency_hz / self.rate.hz();
        let trap = if x == 0.0 { 1.0 } else { x / x.tan() };
        self.acceleration_weight(frequency_hz) * trap * x.cos().powi(2)
    }

    /// Velocity estimate, m/s, from the displacement `u_m` (m) and acceleration `a_m_s2`
    /// (m/s²) sampled together at the low-pass's rate.
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] if the records differ in length, or any error of the
    /// low-pass's [`ZeroPhaseFilter::process`] (a [`SpectralLowpass`](crate::SpectralLowpass)
    /// planned for another length).
    pub fn estimate(&self, u_m: &[f64], a_m_s2: &[f64]) -> Result<Vec<f64>> {
        if u_m.len() != a_m_s2.len() {
            return Err(SignalError::LengthMismatch {
                what: "a_m_s2",
                expected: u_m.len(),
                found: a_m_s2.len(),
                reference: "u_m",
            });
        }
        let w = cumulative_trapezoid(a_m_s2, self.rate, 0.0);
        let big_w = cumulative_trapezoid(&w, self.rate, 0.0);
        let mut r: Vec<f64> = u_m.iter().zip(&big_w).map(|(u, w)| u - w).collect();
        remove_polynomial(&mut r, 2);
        let mut low = w;
        self.low_pass.process(&r, &mut low)?;
        // û = u − (I − L) r, reusing `low` for û.
        for ((l, u), r) in low.iter_mut().zip(u_m).zip(&r) {
            *l += u - r;
        }
        let v = differentiate(&low, self.rate);
        Ok(v)
    }
}
