//! Covariance of a least-squares estimate whose residuals are serially correlated: the
//! sandwich `B⁻¹·S·B⁻¹` with `B = JᵀJ` and `S` the Newey–West (Bartlett kernel) long-run
//! covariance of the scores `g_t = J_tᵀ·r_t`, with Andrews' (1991) AR(1) plug-in bandwidth,
//! and the fixed-b critical value of Kiefer & Vogelsang (2005) for the 95 % interval.
//!
//! Residuals of a test record are correlated: the force transducer's and the hydraulics'
//! noise is coloured, the model's own error follows the motion, and an output-error residual
//! is the plant's response to them. Counting every sample as independent would make the
//! intervals too narrow by the square root of the correlation length (a factor 5–10 on the
//! test records). The sandwich needs no model of the correlation, only that it dies out
//! within the bandwidth.
//!
//! Residuals that share a time index (several channels of one record) are summed into one
//! score; records (groups) are independent of each other, and samples left out of a fit
//! score zero, so lags are counted in the record's own time.

use nalgebra::{DMatrix, SymmetricEigen};

/// Scaled `JᵀJ` eigenvalues below this fraction of the largest are singular directions (as
/// [`crate::lm::SINGULAR_RELATIVE_EIGENVALUE`]).
const SINGULAR: f64 = 1e-10;

/// Largest first-order autocorrelation used in the bandwidth rule. Andrews truncates the
/// plug-in's estimate near 1, where the rule's bandwidth grows without bound; 0.97 gives
/// bandwidths up to ~20 times the correlation time of an AR(1) score.
const MAX_RHO: f64 = 0.97;

/// The covariance of the estimate.
#[derive(Debug, Clone)]
pub(crate) struct Hac {
    /// Covariance matrix of the parameters (rows/columns of singular parameters are NaN).
    pub cov: DMatrix<f64>,
    /// Whether each parameter lies in a singular direction of `JᵀJ`.
    pub singular: Vec<bool>,
    /// Condition number of `JᵀJ` scaled to unit diagonal.
    pub condition: f64,
    /// Bartlett bandwidth: lags up to `bandwidth − 1` are weighted `1 − l/bandwidth`.
    pub bandwidth: usize,
    /// Critical value of the 95 % two-sided interval (1.96 for independent residuals).
    pub critical_value: f64,
    /// Effective number of independent observations, `n·s²_white / s²_long-run` in the
    /// score of the first parameter, for reporting.
    pub effective_samples: f64,
}

/// Kiefer & Vogelsang (2005), Table 1 polynomial for the Bartlett kernel: the 97.5 % quantile
/// of the fixed-b limit of the t statistic is `1.96 + 2.9694·b + 0.4160·b² − 0.5324·b³`,
/// `b = bandwidth/n`. For the small `b` here (≤ 0.05) it adds up to 8 % to 1.96.
pub(crate) fn fixed_b_critical_value(b: f64) -> f64 {
    let b = b.clamp(0.0, 1.0);
    1.96 + 2.9694 * b + 0.4160 * b * b - 0.5324 * b * b * b
}

/// The scores summed per (group, time): one `T × m` matrix per group, over its time span.
fn score_series(
    jac: &DMatrix<f64>,
    resid: &[f64],
    time: &[usize],
    group: &[usize],
    scale: &[f64],
) -> Vec<DMatrix<f64>> {
    let m = jac.ncols();
    let groups = group.iter().copied().max().map_or(0, |g| g + 1);
    let mut span = vec![(usize::MAX, 0usize); groups];
    for (&t, &g) in time.iter().zip(group) {
        span[g].0 = span[g].0.min(t);
        span[g].1 = span[g].1.max(t);
    }
    let mut series: Vec<DMatrix<f64>> = span
        .iter()
        .map(|&(lo, hi)| DMatrix::zeros(if lo > hi { 0 } else { hi - lo + 1 }, m))
        .collect();
    for i in 0..resid.len() {
        let (g, t) = (group[i], time[i]);
        let row = t - span[g].0;
        for k in 0..m {
            series[g][(row, k)] += jac[(i, k)] / scale[k] * resid[i];
        }
    }
    series
}

/// Andrews' AR(1) plug-in bandwidth for the Bartlett kernel,
/// `1.1447·(α̂(1)·n)^(1/3)` with `α̂(1) = Σ 4ρ²σ⁴/((1−ρ)⁶(1+ρ)²) / Σ σ⁴/(1−ρ)⁴` over the
/// score components (equal weights), at most a fifth of the `n` samples.
fn andrews_bandwidth(series: &[DMatrix<f64>], m: usize, n: usize) -> usize {
    let mut num = 0.0;
    let mut den = 0.0;
    for k in 0..m {
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for s in series {
            for t in 1..s.nrows() {
                sxy += s[(t, k)] * s[(t - 1, k)];
                sxx += s[(t - 1, k)] * s[(t - 1, k)];
            }
        }
        if sxx <= 0.0 {
            continue;
        }
        let rho = (sxy / sxx).clamp(-MAX_RHO, MAX_RHO);
        let (mut e2, mut cnt) = (0.0, 0.0);
        for s in series {
            for t in 1..s.nrows() {
                let e = s[(t, k)] - rho * s[(t - 1, k)];
                e2 += e * e;
                cnt += 1.0;
            }
        }
        let s2 = e2 / f64::max(cnt, 1.0);
        let s4 = s2 * s2;
        num += 4.0 * rho * rho * s4 / ((1.0 - rho).powi(6) * (1.0 + rho).powi(2));
        den += s4 / (1.0 - rho).powi(4);
    }
    let alpha1 = if den > 0.0 { num / den } else { 0.0 };
    let l = 1.1447 * (alpha1 * n as f64).cbrt();
    let cap = (n / 5).max(1) as f64;
    l.ceil().clamp(1.0, cap) as usize
}

/// The sandwich covariance of the parameters of a fit with Jacobian `jac` (rows: residuals)
/// and residuals `resid`; residual `i` belongs to record `group[i]` at sample `time[i]`.
pub(crate) fn covariance(
    jac: &DMatrix<f64>,
    resid: &[f64],
    time: &[usize],
    group: &[usize],
) -> Hac {
    let n_res = jac.nrows();
    let m = jac.ncols();
    debug_assert_eq!(resid.len(), n_res);
    let jtj = jac.tr_mul(jac);
    let scale: Vec<f64> = (0..m)
        .map(|k| {
            let d = jtj[(k, k)].sqrt();
            if d > 0.0 && d.is_finite() {
                d
            } else {
                1.0
            }
        })
        .collect();
    let bread = DMatrix::from_fn(m, m, |i, j| jtj[(i, j)] / (scale[i] * scale[j]));
    let eig = SymmetricEigen::new(bread);
    let max_ev = eig.eigenvalues.max();
    let min_ev = eig.eigenvalues.min();
    let condition = if min_ev > 0.0 {
        max_ev / min_ev
    } else {
        f64::INFINITY
    };
    let mut singular: Vec<bool> = (0..m).map(|k| jtj[(k, k)] <= 0.0).collect();
    let mut inv = DMatrix::zeros(m, m);
    for e in 0..m {
        let ev = eig.eigenvalues[e];
        let vec = eig.eigenvectors.column(e);
        if ev <= SINGULAR * max_ev {
            for k in 0..m {
                if vec[k].abs() > 0.1 {
                    singular[k] = true;
                }
            }
            continue;
        }
        inv += (vec * vec.transpose()) / ev;
    }

    let series = score_series(jac, resid, time, group, &scale);
    let n_time: usize = series.iter().map(DMatrix::nrows).sum();
    let bandwidth = andrews_bandwidth(&series, m, n_time);
    let mut meat = DMatrix::<f64>::zeros(m, m);
    for s in &series {
        let rows = s.nrows();
        for l in 0..bandwidth.min(rows) {
            let w = 1.0 - l as f64 / bandwidth as f64;
            let gamma = s.rows(l, rows - l).tr_mul(&s.rows(0, rows - l));
            if l == 0 {
                meat += gamma;
            } else {
                meat += (&gamma + gamma.transpose()) * w;
            }
        }
    }
    let white: f64 = series
        .iter()
        .map(|s| s.column(0).norm_squared())
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    let effective_samples = n_time as f64 * white / meat[(0, 0)].max(f64::MIN_POSITIVE);
    // Small-sample factor n/(n − m), as the usual s² has.
    let dof_factor = n_res as f64 / (n_res as f64 - m as f64).max(1.0);
    let scaled = &inv * meat * &inv * dof_factor;
    let cov = DMatrix::from_fn(m, m, |i, j| {
        if singular[i] || singular[j] {
            f64::NAN
        } else {
            scaled[(i, j)] / (scale[i] * scale[j])
        }
    });
    Hac {
        cov,
        singular,
        condition,
        bandwidth,
        critical_value: fixed_b_critical_value(bandwidth as f64 / n_time.max(1) as f64),
        effective_samples: effective_samples.min(n_time as f64),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic uniform generator (splitmix64) and Gaussian pairs (Box–Muller).
    struct Rng(u64);
    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn normal(&mut self) -> f64 {
            let u1 = self.uniform().max(1e-300);
            let u2 = self.uniform();
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        }
    }

    /// The mean of an AR(1) series, `x_t = ρx_{t−1} + e_t`, has the long-run variance
    /// `σ_e²/(1−ρ)²/n`; with ρ = 0.9 that is 100 times the white-noise value `σ_x²/n·…`.
    /// The sandwich's standard error must be within 25 % of the truth (averaged over 200
    /// series: the estimate of one series scatters by ~20 %), the i.i.d. one a factor ~4
    /// short.
    #[test]
    fn the_standard_error_of_the_mean_of_an_ar1_series_is_its_long_run_value() {
        let (n, rho) = (4000, 0.9);
        let mut rng = Rng(7);
        let mut ratio = 0.0;
        let reps = 200;
        for _ in 0..reps {
            let mut x = vec![0.0; n];
            x[0] = rng.normal() / (1.0f64 - rho * rho).sqrt();
            for t in 1..n {
                x[t] = rho * x[t - 1] + rng.normal();
            }
            let mean = x.iter().sum::<f64>() / n as f64;
            let resid: Vec<f64> = x.iter().map(|v| mean - v).collect();
            let jac = DMatrix::from_element(n, 1, 1.0);
            let time: Vec<usize> = (0..n).collect();
            let hac = covariance(&jac, &resid, &time, &vec![0; n]);
            let truth = 1.0 / (1.0 - rho) / (n as f64).sqrt();
            ratio += hac.cov[(0, 0)].sqrt() / truth;
        }
        ratio /= reps as f64;
        assert!((ratio - 1.0).abs() < 0.25, "mean ratio {ratio}");
    }

    #[test]
    fn the_fixed_b_critical_value_starts_at_the_normal_quantile_and_grows_with_b() {
        assert_eq!(fixed_b_critical_value(0.0), 1.96);
        let mut last = 1.96;
        for k in 1..=20 {
            let c = fixed_b_critical_value(0.05 * f64::from(k));
            assert!(c > last, "b = {}: {c}", 0.05 * f64::from(k));
            last = c;
        }
    }
}
