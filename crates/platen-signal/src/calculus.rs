//! Differentiation and integration of uniformly sampled records, with baseline correction.

use crate::error::{Result, SignalError};
use crate::motion::{check_finite, Motion};
use crate::SampleRate;

/// Derivative of a uniformly sampled record by second-order finite differences.
///
/// Interior samples use the central difference `(x[i+1] − x[i−1])/(2Δt)`; the end samples use
/// the one-sided second-order formulas `(−3x[0] + 4x[1] − x[2])/(2Δt)` and
/// `(3x[n−1] − 4x[n−2] + x[n−3])/(2Δt)` (as NumPy's `gradient(…, edge_order=2)`). The result is
/// exact for quadratics. Two samples give the first-order difference at both ends; one sample
/// gives 0; an empty record gives an empty result.
///
/// Gain and phase: for a sine at `f` the interior result has zero phase and the gain
/// `sin(2πfΔt)/(2πfΔt) ≈ 1 − (2πfΔt)²/6` relative to the exact derivative.
pub fn differentiate(x: &[f64], rate: SampleRate) -> Vec<f64> {
    let n = x.len();
    let inv_2dt = 0.5 * rate.hz();
    match n {
        0 => Vec::new(),
        1 => vec![0.0],
        2 => {
            let d = (x[1] - x[0]) * rate.hz();
            vec![d, d]
        }
        _ => {
            let mut d = Vec::with_capacity(n);
            d.push((-3.0 * x[0] + 4.0 * x[1] - x[2]) * inv_2dt);
            d.extend(x.windows(3).map(|w| (w[2] - w[0]) * inv_2dt));
            d.push((3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) * inv_2dt);
            d
        }
    }
}

/// Cumulative trapezoidal integral of a uniformly sampled record, starting from `initial`:
/// `y[0] = initial`, `y[i] = y[i−1] + Δt·(x[i−1] + x[i])/2`.
///
/// The error after a time `T` is at most `T·Δt²·max|x''|/12`. For a sine the cumulative
/// trapezoid has exactly the −90° phase of the ideal integral and the gain
/// `(πfΔt)/tan(πfΔt) ≈ 1 − (2πfΔt)²/12` relative to it (plus the constant set by `initial`).
pub fn cumulative_trapezoid(x: &[f64], rate: SampleRate, initial: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(x.len());
    if x.is_empty() {
        return y;
    }
    let half_dt = 0.5 * rate.interval_s();
    let mut acc = initial;
    y.push(acc);
    for w in x.windows(2) {
        acc += half_dt * (w[0] + w[1]);
        y.push(acc);
    }
    y
}

/// Largest polynomial order accepted for baseline correction.
pub const MAX_BASELINE_ORDER: usize = 8;

/// Baseline correction applied while integrating an acceleration record.
///
/// The polynomial is the least-squares fit over the whole record (time normalised to
/// `[−1, 1]`, fitted with discrete orthogonal polynomials, so any order up to
/// [`MAX_BASELINE_ORDER`] is well conditioned).
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Baseline {
    /// No correction: plain trapezoidal integration from the initial values.
    #[default]
    None,
    /// Subtract the least-squares polynomial of this order from the **acceleration** before
    /// integrating. Order 0 removes a constant bias (which would otherwise grow into a linear
    /// velocity drift and a quadratic displacement drift); order 1 also removes a linear trend.
    /// The initial velocity and displacement are kept.
    Acceleration {
        /// Polynomial order, `0..=MAX_BASELINE_ORDER`.
        order: usize,
    },
    /// Integrate the acceleration from the initial velocity, then subtract the least-squares
    /// polynomial of this order from the **velocity**, then integrate that to displacement from
    /// the initial displacement. Suited to records known to carry no velocity trend (a periodic
    /// test, a record that starts and ends at rest). The corrected velocity generally no longer
    /// starts at the given initial velocity: order 0 makes its mean zero.
    Velocity {
        /// Polynomial order, `0..=MAX_BASELINE_ORDER`.
        order: usize,
    },
}

/// Initial values for integrating an acceleration record.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InitialMotion {
    /// Displacement at the first sample, m (default 0).
    pub u_m: f64,
    /// Velocity at the first sample, m/s (default 0).
    pub v_m_s: f64,
}

/// Integrates acceleration to velocity and displacement (trapezoidal rule) with an optional
/// [`Baseline`] correction. Plan once with [`new`](Self::new), integrate many records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionIntegrator {
    rate: SampleRate,
    baseline: Baseline,
}

impl MotionIntegrator {
    /// Plans the integration at `sample_rate_hz` with the given baseline correction.
    ///
    /// # Errors
    /// [`SignalError::InvalidParameter`] for a bad sample rate, [`SignalError::InvalidCount`]
    /// for a baseline order above [`MAX_BASELINE_ORDER`].
    pub fn new(sample_rate_hz: f64, baseline: Baseline) -> Result<Self> {
        let rate = SampleRate::new(sample_rate_hz)?;
        match baseline {
            Baseline::Acceleration { order } | Baseline::Velocity { order }
                if order > MAX_BASELINE_ORDER =>
            {
                Err(SignalError::InvalidCount {
                    name: "baseline order",
                    value: order,
                    expected: "a polynomial order in 0..=8",
                })
            }
            _ => Ok(MotionIntegrator { rate, baseline }),
        }
    }

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.rate.hz()
    }

    /// The baseline correction.
    pub fn baseline(&self) -> Baseline {
        self.baseline
    }

    /// The motion of the acceleration record `a_m_s2` from `initial`: sample `i` at
    /// `t_s = i/sample_rate_hz`, the velocity the cumulative trapezoid of the acceleration
    /// and the displacement that of the velocity, after the [`Baseline`] correction.
    ///
    /// The motion's acceleration is the one whose integral its velocity is: the record as
    /// given ([`Baseline::None`]), the record less its polynomial
    /// ([`Baseline::Acceleration`]), or the record less the derivative of the polynomial
    /// taken out of the velocity ([`Baseline::Velocity`]), so the three channels stay one
    /// motion.
    ///
    /// # Errors
    /// [`SignalError::TooFewSamples`] for fewer than two samples,
    /// [`SignalError::NonFiniteInput`] for a sample that is not finite (as [`Motion::new`]).
    pub fn integrate(&self, a_m_s2: &[f64], initial: InitialMotion) -> Result<Motion> {
        if a_m_s2.len() < 2 {
            return Err(SignalError::TooFewSamples {
                found: a_m_s2.len(),
                needed: 2,
            });
        }
        check_finite("a_m_s2", a_m_s2)?;
        let rate_hz = self.rate.hz();
        let t_s: Vec<f64> = (0..a_m_s2.len()).map(|i| i as f64 / rate_hz).collect();
        let mut a_m_s2 = a_m_s2.to_vec();
        if let Baseline::Acceleration { order } = self.baseline {
            remove_polynomial(&mut a_m_s2, order);
        }
        let mut v_m_s = cumulative_trapezoid(&a_m_s2, self.rate, initial.v_m_s);
        if let (Baseline::Velocity { order }, n @ 2..) = (self.baseline, v_m_s.len()) {
            // The polynomial's slope per sample, into m/s².
            let mut slope = vec![0.0; n];
            fit_and_remove(&mut v_m_s, order, Some(&mut slope));
            for (a, s) in a_m_s2.iter_mut().zip(&slope) {
                *a -= s * rate_hz;
            }
        }
        let u_m = cumulative_trapezoid(&v_m_s, self.rate, initial.u_m);
        Motion::new(t_s, u_m, v_m_s, a_m_s2)
    }
}

/// Subtracts from `x` its least-squares polynomial of degree `order` in the sample index.
///
/// Uses the discrete orthogonal polynomials of the sample points (Stieltjes recurrence on the
/// abscissae mapped to `[−1, 1]`), projecting each out of the residual in turn (modified
/// Gram–Schmidt), with three work vectors. A degree at or above the number of samples removes
/// everything (the fit interpolates).
pub fn remove_polynomial(x: &mut [f64], order: usize) {
    fit_and_remove(x, order, None);
}

/// [`remove_polynomial`], and where `slope` is given (as long as `x`, at least two samples)
/// the derivative of the removed polynomial per sample index added to it, carried through
/// the same recurrence (`p′ₖ₊₁ = pₖ + (s − α)·p′ₖ − β·p′ₖ₋₁`). `x` comes out the same to the
/// bit either way.
fn fit_and_remove(x: &mut [f64], order: usize, mut slope: Option<&mut [f64]>) {
    let n = x.len();
    if n == 0 {
        return;
    }
    let t: Vec<f64> = if n == 1 {
        vec![0.0]
    } else {
        let scale = 2.0 / (n - 1) as f64;
        (0..n).map(|i| i as f64 * scale - 1.0).collect()
    };
    let mut p_prev = vec![0.0; n];
    let mut p = vec![1.0; n];
    let mut p_next = vec![0.0; n];
    // Derivatives of the three polynomials in the mapped abscissa (only with `slope`).
    let derivatives = if slope.is_some() { n } else { 0 };
    let mut dp_prev = vec![0.0; derivatives];
    let mut dp = vec![0.0; derivatives];
    let mut dp_next = vec![0.0; derivatives];
    let mut norm_prev = 1.0;
    // Polynomials whose norm falls to this fraction of the first one are numerically zero
    // (the degree has reached the number of points).
    let tiny = 1e-24 * n as f64;
    for degree in 0..=order {
        let norm: f64 = p.iter().map(|v| v * v).sum();
        if norm <= tiny {
            break;
        }
        let c = x.iter().zip(&p).map(|(a, b)| a * b).sum::<f64>() / norm;
        for (xi, pi) in x.iter_mut().zip(&p) {
            *xi -= c * pi;
        }
        if let Some(slope) = slope.as_deref_mut() {
            for (si, dpi) in slope.iter_mut().zip(&dp) {
                *si += c * dpi;
            }
        }
        if degree == order {
            break;
        }
        let alpha = t.iter().zip(&p).map(|(ti, pi)| ti * pi * pi).sum::<f64>() / norm;
        let beta = if degree == 0 { 0.0 } else { norm / norm_prev };
        for i in 0..n {
            p_next[i] = (t[i] - alpha) * p[i] - beta * p_prev[i];
        }
        for i in 0..derivatives {
            dp_next[i] = p[i] + (t[i] - alpha) * dp[i] - beta * dp_prev[i];
        }
        std::mem::swap(&mut p_prev, &mut p);
        std::mem::swap(&mut p, &mut p_next);
        std::mem::swap(&mut dp_prev, &mut dp);
        std::mem::swap(&mut dp, &mut dp_next);
        norm_prev = norm;
    }
    // From the mapped abscissa (−1 … 1 over the record) to the sample index.
    if let Some(slope) = slope {
        let per_index = 2.0 / (n.max(2) - 1) as f64;
        for si in slope.iter_mut() {
            *si *= per_index;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removing_a_polynomial_leaves_nothing_of_a_polynomial_of_that_degree() {
        for order in 0..=MAX_BASELINE_ORDER {
            let mut x: Vec<f64> = (0..1000)
                .map(|i| {
                    let s = i as f64 / 999.0;
                    (0..=order)
                        .map(|k| (k as f64 + 1.0) * s.powi(k as i32))
                        .sum()
                })
                .collect();
            remove_polynomial(&mut x, order);
            let worst = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            assert!(worst < 1e-10, "order {order}: residual {worst}");
        }
    }

    #[test]
    fn removing_a_polynomial_keeps_what_is_orthogonal_to_it() {
        // An odd function on symmetric abscissae is orthogonal to every even polynomial, and
        // the residual of any fit is orthogonal to the constant: its mean is zero.
        let mut x: Vec<f64> = (0..501).map(|i| (i as f64 - 250.0).powi(3)).collect();
        let original = x.clone();
        remove_polynomial(&mut x, 0);
        assert_eq!(x, original);
        let mut y: Vec<f64> = (0..100).map(|i| (i as f64 * 0.37).sin()).collect();
        remove_polynomial(&mut y, 2);
        assert!(y.iter().sum::<f64>().abs() < 1e-12);
    }

    /// The slope of the removed polynomial is its exact derivative per sample: for a
    /// polynomial of the fitted degree, the derivative of what was there.
    #[test]
    fn the_slope_of_the_removed_polynomial_is_its_derivative() {
        let n = 301;
        for order in 0..=MAX_BASELINE_ORDER {
            let p = |i: f64| -> f64 {
                (0..=order)
                    .map(|k| (k as f64 - 1.5) * (i / 300.0).powi(k as i32))
                    .sum()
            };
            let mut x: Vec<f64> = (0..n).map(|i| p(i as f64)).collect();
            let exact: Vec<f64> = (0..n)
                .map(|i| {
                    let s = i as f64 / 300.0;
                    (1..=order)
                        .map(|k| (k as f64 - 1.5) * k as f64 * s.powi(k as i32 - 1) / 300.0)
                        .sum()
                })
                .collect();
            let before = x.clone();
            let mut plain = x.clone();
            remove_polynomial(&mut plain, order);
            let mut slope = vec![0.0; n];
            fit_and_remove(&mut x, order, Some(&mut slope));
            assert_eq!(x, plain, "order {order}: x must not depend on the slope");
            let worst = slope
                .iter()
                .zip(&exact)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(worst < 1e-11, "order {order}: slope off by {worst}");
            assert_ne!(before, x);
        }
    }

    #[test]
    fn a_degree_at_or_above_the_sample_count_removes_everything() {
        let mut x = vec![3.0, -1.0, 4.0];
        remove_polynomial(&mut x, 5);
        assert!(x.iter().all(|v| v.abs() < 1e-12), "{x:?}");
        let mut one = vec![7.0];
        remove_polynomial(&mut one, 0);
        assert_eq!(one, vec![0.0]);
    }
}
