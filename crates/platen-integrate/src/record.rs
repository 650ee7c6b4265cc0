//! Input records: a uniformly sampled force (forward runs) and a prescribed motion (inverse runs).

use crate::error::{IntegrateError, Result};

/// Relative tolerance on the sample intervals of a record called uniform: 0.1 % of the mean
/// interval. Time stamps printed with few digits jitter by up to half their last digit
/// (6 decimals at 1024 Hz: ±0.05 %); a dropped or repeated sample changes an interval by
/// 100 %. The record is then treated as sampled exactly at the mean interval.
pub const UNIFORM_RELATIVE_TOLERANCE: f64 = 1e-3;

fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(IntegrateError::NonFiniteInput {
            what,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

fn check_times(t_s: &[f64], needed: usize) -> Result<()> {
    if t_s.len() < needed {
        return Err(IntegrateError::TooShort {
            found: t_s.len(),
            needed,
        });
    }
    check_finite("t_s", t_s)?;
    for i in 1..t_s.len() {
        if t_s[i] <= t_s[i - 1] {
            return Err(IntegrateError::TimeNotIncreasing {
                index: i,
                previous_s: t_s[i - 1],
                value_s: t_s[i],
            });
        }
    }
    Ok(())
}

fn check_len(what: &'static str, column: &[f64], expected: usize) -> Result<()> {
    if column.len() != expected {
        return Err(IntegrateError::LengthMismatch {
            what,
            found: column.len(),
            expected,
        });
    }
    check_finite(what, column)
}

/// The sample interval of a uniformly sampled, strictly increasing time column: the mean
/// interval, after checking that every interval is within [`UNIFORM_RELATIVE_TOLERANCE`] of
/// the median one (the median, so that one dropped sample is reported where it is).
///
/// # Errors
/// [`IntegrateError::TooShort`] for fewer than two samples, [`IntegrateError::NonUniform`]
/// naming the sample that ends the first odd interval.
pub fn uniform_interval_s(t_s: &[f64]) -> Result<f64> {
    let n = t_s.len();
    if n < 2 {
        return Err(IntegrateError::TooShort {
            found: n,
            needed: 2,
        });
    }
    let mut intervals: Vec<f64> = t_s.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = intervals.len() / 2;
    let median = *intervals.select_nth_unstable_by(mid, f64::total_cmp).1;
    let tolerance = UNIFORM_RELATIVE_TOLERANCE * median.abs();
    for i in 1..n {
        let found_s = t_s[i] - t_s[i - 1];
        // Written so that a NaN interval fails the check too.
        let within = (found_s - median).abs() <= tolerance;
        if !within {
            return Err(IntegrateError::NonUniform {
                index: i,
                expected_s: median,
                found_s,
            });
        }
    }
    Ok((t_s[n - 1] - t_s[0]) / (n - 1) as f64)
}

/// A uniformly sampled actuator force, linear between samples.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceRecord {
    t_s: Vec<f64>,
    force_n: Vec<f64>,
    dt_s: f64,
}

impl ForceRecord {
    /// Builds a record from sample times and forces.
    ///
    /// # Errors
    /// Fewer than two samples, columns of different length, non-finite values, time not
    /// strictly increasing, or intervals differing from their mean by more than
    /// [`UNIFORM_RELATIVE_TOLERANCE`].
    pub fn new(t_s: Vec<f64>, force_n: Vec<f64>) -> Result<Self> {
        check_times(&t_s, 2)?;
        check_len("force_n", &force_n, t_s.len())?;
        let dt_s = uniform_interval_s(&t_s)?;
        Ok(Self { t_s, force_n, dt_s })
    }

    /// Builds a record sampled at `sample_rate_hz` from `t = 0` with the given forces. Sample
    /// `j` is at `j / sample_rate_hz` (exact for power-of-two rates).
    ///
    /// # Errors
    /// As [`ForceRecord::new`].
    pub fn from_rate(sample_rate_hz: f64, force_n: Vec<f64>) -> Result<Self> {
        let t_s = (0..force_n.len())
            .map(|j| j as f64 / sample_rate_hz)
            .collect();
        Self::new(t_s, force_n)
    }

    /// Sample times, s.
    pub fn t_s(&self) -> &[f64] {
        &self.t_s
    }

    /// Force samples, N.
    pub fn force_n(&self) -> &[f64] {
        &self.force_n
    }

    /// Sample interval (mean), s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Always false: a record has at least two samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Span of the record, s.
    pub fn span_s(&self) -> f64 {
        self.t_s[self.t_s.len() - 1] - self.t_s[0]
    }
}

/// A prescribed platen motion: displacement, velocity and acceleration at each sample time.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    t_s: Vec<f64>,
    u_m: Vec<f64>,
    v_m_s: Vec<f64>,
    a_m_s2: Vec<f64>,
}

impl Motion {
    /// A motion with all three kinematic quantities given.
    ///
    /// # Errors
    /// Fewer than two samples, columns of different length, non-finite values, time not
    /// strictly increasing.
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
        })
    }

    /// A motion given by displacement only; velocity and acceleration are derived with
    /// second-order finite differences ([`derivative`] applied once and twice).
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
        })
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
}

/// First derivative of samples `y(t)` by second-order finite differences on a possibly
/// non-uniform grid: the three-point central formula inside, three-point one-sided formulas
/// at both ends. Exact for quadratics.
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
