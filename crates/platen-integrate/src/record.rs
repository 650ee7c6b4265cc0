//! Input records: a uniformly sampled force (forward runs), and the sampling grid of a time
//! column. The prescribed motion of inverse runs is [`crate::Motion`] (from `platen_signal`).

use crate::error::{IntegrateError, Result};

// The column checks a [`platen_signal::Motion`] passes; their errors convert into this
// crate's variants (`TooShort`, `NonFiniteInput`, `TimeNotIncreasing`, `LengthMismatch`) with
// the same messages.
use platen_signal::{check_len, check_times};

/// Largest deviation of a time stamp from the record's fitted sampling grid, as a fraction of
/// the fitted interval: 10 %.
///
/// A data system samples on a uniform clock; what moves its stamps off the grid is mostly the
/// rounding of the printed times. Stamps rounded to 1e-5 s at 204.8 Hz are off by up to 0.2 %
/// of the interval, 6 decimals at 1024 Hz by 0.05 %, whole milliseconds at 100 Hz by 5 %: all
/// pass, and the record is used on the fitted grid, which is closer to the clock than the
/// rounded stamps. A dropped sample moves the stamps on one side of it by at least half an
/// interval from any straight line through them (five times this tolerance), and the interval
/// that holds it is twice the typical one: both are rejected, naming the line. The name is
/// kept from when this was a tolerance on each interval.
pub const UNIFORM_RELATIVE_TOLERANCE: f64 = 0.1;

/// The sampling grid of a record fitted to its time stamps ([`sampling_grid`]):
/// sample `i` belongs at `start_s + i·interval_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplingGrid {
    /// Time of sample 0 on the fitted grid, s.
    pub start_s: f64,
    /// The fitted sample interval, s.
    pub interval_s: f64,
    /// The largest distance of a stamp from the fitted grid, s (0 for exact stamps).
    pub max_deviation_s: f64,
    /// Number of samples.
    pub samples: usize,
}

impl SamplingGrid {
    /// How precisely the stamps fix the interval, s: the largest change of the interval that
    /// keeps every stamp as close to the grid as the worst one already is
    /// (`2·max_deviation_s/(n − 1)`), and never less than 1e-9 of the interval (exact stamps).
    pub fn interval_uncertainty_s(&self) -> f64 {
        let spread = 2.0 * self.max_deviation_s / (self.samples.max(2) - 1) as f64;
        spread.max(1e-9 * self.interval_s)
    }

    /// The whole number `k` of integration steps of `step_s` per sample interval: `k·step_s`
    /// must equal the fitted interval to within [`interval_uncertainty_s`](Self::interval_uncertainty_s)
    /// (so a step that divides the interval the stamps were rounded from is accepted, and one
    /// that drifts off the grid over the record is not). The integrator then steps at
    /// `interval_s / k`.
    ///
    /// # Errors
    /// [`IntegrateError::InvalidStep`] for a step that is not finite and positive,
    /// [`IntegrateError::StepNotDivisor`] for one that does not divide the interval.
    pub fn steps_per_interval(&self, step_s: f64) -> Result<u32> {
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(IntegrateError::InvalidStep { step_s });
        }
        let k = (self.interval_s / step_s).round();
        if !(1.0..=1e9).contains(&k)
            || (k * step_s - self.interval_s).abs() > self.interval_uncertainty_s()
        {
            return Err(IntegrateError::StepNotDivisor {
                step_s,
                sample_interval_s: self.interval_s,
            });
        }
        Ok(k as u32)
    }
}

/// The sample interval of a uniformly sampled, strictly increasing time column: the interval
/// of the grid fitted over the whole record ([`sampling_grid`]), which every verb uses.
///
/// # Errors
/// As [`sampling_grid`].
pub fn uniform_interval_s(t_s: &[f64]) -> Result<f64> {
    sampling_grid(t_s).map(|grid| grid.interval_s)
}

/// The sampling grid `start_s + i·interval_s` fitted to the time stamps `t_s` by least squares
/// over the whole record, after checking that the stamps are on it.
///
/// Two checks, both against [`UNIFORM_RELATIVE_TOLERANCE`] (10 %): every interval must be
/// within twice the tolerance of the median interval (two stamps each off the grid by the
/// tolerance), which finds a dropped sample or a jump at its own sample; then every stamp must
/// be within the tolerance (of the fitted interval) of the fitted grid, which finds a slow
/// drift or a change of rate. Exact stamps (`i/1024`, …) give exactly `(t_last − t_first)/(n − 1)`.
///
/// # Errors
/// [`IntegrateError::TooShort`] for fewer than two samples,
/// [`IntegrateError::NonFiniteInput`] for a stamp that is not finite,
/// [`IntegrateError::TimeNotIncreasing`] naming the first sample that does not follow its
/// predecessor, [`IntegrateError::NonUniform`] naming the sample that ends the first odd
/// interval, [`IntegrateError::OffGrid`] naming the first stamp off the fitted grid.
pub fn sampling_grid(t_s: &[f64]) -> Result<SamplingGrid> {
    check_times(t_s, 2)?;
    let n = t_s.len();
    // The median interval: a dropped sample does not move it, so the odd interval is
    // reported where it is.
    let mut intervals: Vec<f64> = t_s.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = intervals.len() / 2;
    let median = *intervals.select_nth_unstable_by(mid, f64::total_cmp).1;
    let tolerance = 2.0 * UNIFORM_RELATIVE_TOLERANCE * median;
    if let Some(i) = (1..n).find(|&i| (t_s[i] - t_s[i - 1] - median).abs() > tolerance) {
        return Err(IntegrateError::NonUniform {
            index: i,
            expected_s: median,
            found_s: t_s[i] - t_s[i - 1],
        });
    }
    // Least squares about the line through the end stamps: residuals r_i against
    // t_0 + i·dt0, fitted by r̄ + δ·(i − (n − 1)/2). Exact stamps leave every r_i = 0, so the
    // interval is dt0 to the bit.
    let first = t_s[0];
    let dt0 = (t_s[n - 1] - first) / (n - 1) as f64;
    let residual = |i: usize| t_s[i] - (first + i as f64 * dt0);
    let centre = 0.5 * (n - 1) as f64;
    let (mut sum_r, mut sum_xr) = (0.0, 0.0);
    for i in 0..n {
        let r = residual(i);
        sum_r += r;
        sum_xr += (i as f64 - centre) * r;
    }
    let nf = n as f64;
    let sum_xx = nf * (nf * nf - 1.0) / 12.0;
    let mean_r = sum_r / nf;
    let slope = sum_xr / sum_xx;
    let interval_s = dt0 + slope;
    let deviation = |i: usize| residual(i) - mean_r - slope * (i as f64 - centre);
    let allowed = UNIFORM_RELATIVE_TOLERANCE * interval_s;
    let mut max_deviation_s: f64 = 0.0;
    for (i, &stamp) in t_s.iter().enumerate() {
        let d = deviation(i);
        if d.abs() > allowed {
            return Err(IntegrateError::OffGrid {
                index: i,
                grid_s: stamp - d,
                found_s: stamp,
                interval_s,
            });
        }
        max_deviation_s = max_deviation_s.max(d.abs());
    }
    Ok(SamplingGrid {
        start_s: first + mean_r - slope * centre,
        interval_s,
        max_deviation_s,
        samples: n,
    })
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
    /// strictly increasing, or stamps off the fitted grid ([`sampling_grid`]).
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

    /// Sample interval (fitted over the whole record, [`sampling_grid`]), s.
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
