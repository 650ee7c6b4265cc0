//! A table motion at its sample times ([`Motion`]), and derivatives of samples on a possibly
//! non-uniform time grid.

use crate::error::{Result, SignalError};

/// A platen (table) motion: displacement, velocity and acceleration at each sample time, and
/// optionally the velocity below which the platen counts as at rest
/// ([`Motion::with_rest_velocity`]).
///
/// It is what [`MotionIntegrator`](crate::MotionIntegrator) makes of an acceleration record,
/// and what an inverse run (`platen_integrate::inverse`) or a closed-loop command takes. Every
/// constructor checks it: at least two samples, columns as long as the time column, finite
/// values, time strictly increasing.
///
/// ```
/// use platen_signal::Motion;
///
/// // u = t², given as displacement only: v and a by second-order differences (exact here).
/// let t_s: Vec<f64> = (0..5).map(|i| i as f64 * 0.25).collect();
/// let u_m: Vec<f64> = t_s.iter().map(|t| t * t).collect();
/// let m = Motion::from_displacement(t_s, u_m)?;
/// assert!(m.v_m_s().iter().zip(m.t_s()).all(|(v, t)| (v - 2.0 * t).abs() < 1e-12));
/// assert!(m.a_m_s2().iter().all(|a| (a - 2.0).abs() < 1e-12));
/// # Ok::<(), platen_signal::SignalError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    t_s: Vec<f64>,
    u_m: Vec<f64>,
    v_m_s: Vec<f64>,
    a_m_s2: Vec<f64>,
    rest_velocity_m_s: Option<f64>,
}

impl Motion {
    /// A motion with all three kinematic quantities given.
    ///
    /// # Errors
    /// [`SignalError::TooFewSamples`] for fewer than two samples,
    /// [`SignalError::ColumnLengthMismatch`] for a column not as long as `t_s`,
    /// [`SignalError::NonFiniteInput`] for a value that is not finite,
    /// [`SignalError::TimeNotIncreasing`] for time not strictly increasing.
    pub fn new(t_s: Vec<f64>, u_m: Vec<f64>, v_m_s: Vec<f64>, a_m_s2: Vec<f64>) -> Result<Self> {
        check_times(&t_s, 2)?;
        check_len("u_m", &u_m, t_s.len())?;
        check_len("v_m_s", &v_m_s, t_s.len())?;
        check_len("a_m_s2", &a_m_s2, t_s.len())?;
        Ok(Self {
            t_s,
            u_m,
            v_m_s,
            a_m_s2,
            rest_velocity_m_s: None,
        })
    }

    /// A motion given by displacement only; velocity and acceleration are derived with
    /// second-order finite differences ([`derivative`] and [`second_derivative`]).
    ///
    /// # Errors
    /// As [`Motion::new`]; at least three samples are needed.
    pub fn from_displacement(t_s: Vec<f64>, u_m: Vec<f64>) -> Result<Self> {
        check_times(&t_s, 3)?;
        check_len("u_m", &u_m, t_s.len())?;
        let v_m_s = derivative(&t_s, &u_m);
        let a_m_s2 = second_derivative(&t_s, &u_m);
        Ok(Self {
            t_s,
            u_m,
            v_m_s,
            a_m_s2,
            rest_velocity_m_s: None,
        })
    }

    /// A motion given by displacement and velocity; acceleration is the derivative of the
    /// velocity ([`derivative`]).
    ///
    /// # Errors
    /// As [`Motion::new`]; at least three samples are needed.
    pub fn from_displacement_velocity(
        t_s: Vec<f64>,
        u_m: Vec<f64>,
        v_m_s: Vec<f64>,
    ) -> Result<Self> {
        check_times(&t_s, 3)?;
        check_len("u_m", &u_m, t_s.len())?;
        check_len("v_m_s", &v_m_s, t_s.len())?;
        let a_m_s2 = derivative(&t_s, &v_m_s);
        Ok(Self {
            t_s,
            u_m,
            v_m_s,
            a_m_s2,
            rest_velocity_m_s: None,
        })
    }

    /// The same motion with a velocity dead band: where `|v| ≤ rest_velocity_m_s` the
    /// platen counts as at rest, and an inverse run (`platen_integrate::inverse`) takes the
    /// friction as the static reaction that balances the other forces within `±F_s` instead
    /// of `sign(v)·D` (which flips by `2F_s` on a noisy measured velocity while the table
    /// stands still). Without it (the default) only `v = 0` exactly is at rest.
    ///
    /// # Errors
    /// [`SignalError::InvalidRestVelocity`] unless `rest_velocity_m_s` is finite and > 0.
    pub fn with_rest_velocity(mut self, rest_velocity_m_s: f64) -> Result<Self> {
        if !(rest_velocity_m_s.is_finite() && rest_velocity_m_s > 0.0) {
            return Err(SignalError::InvalidRestVelocity {
                value: rest_velocity_m_s,
            });
        }
        self.rest_velocity_m_s = Some(rest_velocity_m_s);
        Ok(self)
    }

    /// The velocity dead band, m/s ([`Motion::with_rest_velocity`]); `None` by default.
    pub fn rest_velocity_m_s(&self) -> Option<f64> {
        self.rest_velocity_m_s
    }

    /// Sample times, s.
    pub fn t_s(&self) -> &[f64] {
        &self.t_s
    }
    /// Displacement, m.
    pub fn u_m(&self) -> &[f64] {
        &self.u_m
    }
    /// Velocity, m/s.
    pub fn v_m_s(&self) -> &[f64] {
        &self.v_m_s
    }
    /// Acceleration, m/s².
    pub fn a_m_s2(&self) -> &[f64] {
        &self.a_m_s2
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }
    /// Always false: a motion has at least two samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The first `samples` samples (all of them when there are fewer), with the same rest
    /// velocity.
    ///
    /// # Errors
    /// [`SignalError::TooFewSamples`] for `samples < 2`.
    pub fn truncated(mut self, samples: usize) -> Result<Self> {
        if samples < 2 {
            return Err(SignalError::TooFewSamples {
                found: samples,
                needed: 2,
            });
        }
        for c in [
            &mut self.t_s,
            &mut self.u_m,
            &mut self.v_m_s,
            &mut self.a_m_s2,
        ] {
            c.truncate(samples);
        }
        Ok(self)
    }

    /// The columns `(t_s, u_m, v_m_s, a_m_s2)`, taken out of the motion.
    pub fn into_columns(self) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        (self.t_s, self.u_m, self.v_m_s, self.a_m_s2)
    }
}

pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(SignalError::NonFiniteInput {
            what,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Checks a time column: at least `needed` samples, finite, strictly increasing. A
/// [`Motion`]'s times pass it; a record of another kind (a force record) checks its times
/// the same way.
///
/// # Errors
/// [`SignalError::TooFewSamples`], [`SignalError::NonFiniteInput`] naming `t_s` and the
/// index, [`SignalError::TimeNotIncreasing`].
pub fn check_times(t_s: &[f64], needed: usize) -> Result<()> {
    if t_s.len() < needed {
        return Err(SignalError::TooFewSamples {
            found: t_s.len(),
            needed,
        });
    }
    check_finite("t_s", t_s)?;
    for i in 1..t_s.len() {
        if t_s[i] <= t_s[i - 1] {
            return Err(SignalError::TimeNotIncreasing {
                index: i,
                previous_s: t_s[i - 1],
                value_s: t_s[i],
            });
        }
    }
    Ok(())
}

/// Checks a data column `what` against its time column's length `expected`: the same length,
/// every value finite.
///
/// # Errors
/// [`SignalError::ColumnLengthMismatch`], [`SignalError::NonFiniteInput`] naming `what`.
pub fn check_len(what: &'static str, column: &[f64], expected: usize) -> Result<()> {
    if column.len() != expected {
        return Err(SignalError::ColumnLengthMismatch {
            what,
            found: column.len(),
            expected,
        });
    }
    check_finite(what, column)
}

/// First derivative of samples `y(t)` by second-order finite differences on a possibly
/// non-uniform grid: the three-point central formula inside, three-point one-sided formulas
/// at both ends. Exact for quadratics. (On a uniform grid given by its rate,
/// [`differentiate`](crate::differentiate) is the same formula.)
///
/// # Panics
/// If `t.len() != y.len()` or fewer than three samples are given.
pub fn derivative(t: &[f64], y: &[f64]) -> Vec<f64> {
    assert!(
        t.len() == y.len() && t.len() >= 3,
        "derivative needs >= 3 samples of equal length"
    );
    let n = t.len();
    // Derivative at t[i] of the quadratic through points (a, b, c) = indices (i0, i0+1, i0+2).
    let quad = |i0: usize, at: f64| {
        let (t0, t1, t2) = (t[i0], t[i0 + 1], t[i0 + 2]);
        let (y0, y1, y2) = (y[i0], y[i0 + 1], y[i0 + 2]);
        y0 * (2.0 * at - t1 - t2) / ((t0 - t1) * (t0 - t2))
            + y1 * (2.0 * at - t0 - t2) / ((t1 - t0) * (t1 - t2))
            + y2 * (2.0 * at - t0 - t1) / ((t2 - t0) * (t2 - t1))
    };
    (0..n).map(|i| quad(i.clamp(1, n - 2) - 1, t[i])).collect()
}

/// Second derivative of samples `y(t)`: the second derivative of the quadratic through each
/// point and its neighbours (one-sided at the ends). Second-order accurate inside on a
/// uniform grid.
///
/// # Panics
/// If `t.len() != y.len()` or fewer than three samples are given.
pub fn second_derivative(t: &[f64], y: &[f64]) -> Vec<f64> {
    assert!(
        t.len() == y.len() && t.len() >= 3,
        "second_derivative needs >= 3 samples of equal length"
    );
    let n = t.len();
    let quad2 = |i0: usize| {
        let (t0, t1, t2) = (t[i0], t[i0 + 1], t[i0 + 2]);
        let (y0, y1, y2) = (y[i0], y[i0 + 1], y[i0 + 2]);
        2.0 * (y0 / ((t0 - t1) * (t0 - t2))
            + y1 / ((t1 - t0) * (t1 - t2))
            + y2 / ((t2 - t0) * (t2 - t1)))
    };
    (0..n).map(|i| quad2(i.clamp(1, n - 2) - 1)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_motion_keeps_what_it_is_given() {
        let m = Motion::new(
            vec![0.0, 0.5, 1.0],
            vec![1.0, 2.0, 3.0],
            vec![4.0, 5.0, 6.0],
            vec![7.0, 8.0, 9.0],
        )
        .unwrap();
        assert_eq!(m.t_s(), [0.0, 0.5, 1.0]);
        assert_eq!(m.u_m(), [1.0, 2.0, 3.0]);
        assert_eq!(m.v_m_s(), [4.0, 5.0, 6.0]);
        assert_eq!(m.a_m_s2(), [7.0, 8.0, 9.0]);
        assert_eq!((m.len(), m.is_empty()), (3, false));
        assert_eq!(m.rest_velocity_m_s(), None);
        let banded = m.with_rest_velocity(1e-3).unwrap();
        assert_eq!(banded.rest_velocity_m_s(), Some(1e-3));
    }

    /// On a non-uniform grid the derivatives of a quadratic are exact; velocity given with
    /// the displacement is kept, and the acceleration is its derivative.
    #[test]
    fn derived_channels_are_exact_for_a_quadratic_on_any_grid() {
        let t = vec![0.0, 0.1, 0.25, 0.3, 0.6, 0.65];
        let u: Vec<f64> = t.iter().map(|t| 3.0 * t * t - t + 2.0).collect();
        let v: Vec<f64> = t.iter().map(|t| 6.0 * t - 1.0).collect();
        let m = Motion::from_displacement(t.clone(), u.clone()).unwrap();
        for (i, exact) in v.iter().enumerate() {
            assert!((m.v_m_s()[i] - exact).abs() < 1e-12, "v[{i}]");
            assert!((m.a_m_s2()[i] - 6.0).abs() < 1e-9, "a[{i}]");
        }
        let m = Motion::from_displacement_velocity(t, u, v.clone()).unwrap();
        assert_eq!(m.v_m_s(), v);
        assert!(m.a_m_s2().iter().all(|a| (a - 6.0).abs() < 1e-12));
    }

    #[test]
    fn bad_records_are_named() {
        let err = |r: Result<Motion>| r.unwrap_err().to_string();
        assert_eq!(
            err(Motion::new(vec![0.0], vec![0.0], vec![0.0], vec![0.0])),
            "record has 1 samples; at least 2 are needed"
        );
        assert_eq!(
            err(Motion::from_displacement(vec![0.0, 1.0], vec![0.0, 1.0])),
            "record has 2 samples; at least 3 are needed"
        );
        assert_eq!(
            err(Motion::new(
                vec![0.0, 1.0],
                vec![0.0],
                vec![0.0; 2],
                vec![0.0; 2]
            )),
            "record columns differ in length: u_m has 1 values, expected 2"
        );
        assert_eq!(
            err(Motion::new(
                vec![0.0, 1.0],
                vec![0.0; 2],
                vec![0.0, f64::NAN],
                vec![0.0; 2]
            )),
            "v_m_s[1] = NaN is not finite"
        );
        assert_eq!(
            err(Motion::from_displacement(vec![0.0, 1.0, 1.0], vec![0.0; 3])),
            "time is not strictly increasing at sample 2: 1 s then 1 s"
        );
        let m = Motion::new(vec![0.0, 1.0], vec![0.0; 2], vec![0.0; 2], vec![0.0; 2]).unwrap();
        for bad in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
            assert!(
                matches!(
                    m.clone().with_rest_velocity(bad),
                    Err(SignalError::InvalidRestVelocity { value }) if value.to_bits() == bad.to_bits()
                ),
                "{bad}"
            );
        }
    }
}
