//! Covariance of a least-squares estimate whose residuals are serially correlated: the
//! sandwich `B⁻¹·S·B⁻¹` with `B = JᵀJ` and `S` the batch-means estimate of the long-run
//! covariance of the scores `g_t = J_tᵀ·r_t`: each record is cut into blocks of `L`
//! consecutive samples, the scores are summed per block, and `S = K/(K−1)·Σ_k G_k·G_kᵀ` over
//! the `K` blocks. The 95 % interval uses Student's t with `K − 1` degrees of freedom (the
//! fixed-K limit of the t statistic; Ibragimov & Müller 2010, Hansen 2007).
//!
//! Residuals of a test record are correlated: the force transducer's and the hydraulics'
//! noise is coloured, the model's own error follows the motion. Counting every sample as
//! independent would make the intervals too narrow by the square root of the correlation
//! length. Plug-in kernel estimators (Newey–West with Andrews' AR(1) bandwidth) were tried
//! first and found wanting here: a force noise that is white plus a strongly correlated part
//! looks like a weakly correlated AR(1) to the plug-in rule, which then picks a bandwidth of
//! a few samples and understates the stiffness's standard error by a factor 2 (measured on
//! the coverage records: 66 % coverage). Batch means needs no model of the correlation, only
//! blocks longer than it: [`BLOCK_SAMPLES`] samples at least.
//!
//! Residuals that share a time index (several channels of one record) are summed into one
//! score; records are independent of each other, and samples left out of a fit score zero,
//! so blocks are counted in the record's own time.

use nalgebra::{DMatrix, SymmetricEigen};

use crate::estimate::student_t_975;
use crate::lm::Jacobian;

/// Scaled `JᵀJ` eigenvalues below this fraction of the largest are singular directions (as
/// [`crate::lm::SINGULAR_RELATIVE_EIGENVALUE`]).
const SINGULAR: f64 = 1e-10;

/// Fewest samples in a block (1.2 s at 204.8 Hz: forty times the correlation time of the
/// coverage study's force noise, AR(1) with ρ = 0.97, and several periods of a platen's
/// 0.5 Hz mode).
pub(crate) const BLOCK_SAMPLES: usize = 400;

/// Most blocks: more blocks estimate `S` with less scatter (its relative standard error is
/// `√(2/K)`), fewer keep each block longer than the correlation.
pub(crate) const MAX_BLOCKS: usize = 30;

/// Fewest blocks: below 8 the t quantile (2.36 at 7 degrees of freedom) widens every
/// interval more than the blocks' length gains.
pub(crate) const MIN_BLOCKS: usize = 6;

/// The covariance of the estimate.
#[derive(Debug, Clone)]
pub(crate) struct Hac {
    /// Covariance matrix of the parameters (rows/columns of singular parameters are NaN).
    pub cov: DMatrix<f64>,
    /// The same through the pseudo-inverse, singular directions dropped but not masked: the
    /// variance `gᵀ·C·g` of a combination the data determine (`g` orthogonal to the singular
    /// directions, as `F_μ + Cₑ` when `α = 0`) is right even where its terms are not.
    pub cov_estimable: DMatrix<f64>,
    /// Whether each parameter lies in a singular direction of `JᵀJ`.
    pub singular: Vec<bool>,
    /// Condition number of `JᵀJ` scaled to unit diagonal.
    pub condition: f64,
    /// Block length, samples.
    pub bandwidth: usize,
    /// Critical value of the 95 % two-sided interval: Student's t with (blocks − 1)
    /// degrees of freedom.
    pub critical_value: f64,
    /// Effective number of independent observations, `n·s²_white / s²_long-run` in the
    /// score of the first parameter, for reporting.
    pub effective_samples: f64,
}

/// The sandwich covariance of the parameters of a fit with Jacobian `jac` (rows: residuals)
/// and residuals `resid`; residual `i` belongs to record `group[i]` at sample `time[i]` (a
/// Jacobian with local parameters has them by the same groups).
///
/// Each record's scores touch the shared parameters and its own local ones only, so the
/// cost grows with the residuals and not with residuals × records.
pub(crate) fn covariance(jac: &Jacobian, resid: &[f64], time: &[usize], group: &[usize]) -> Hac {
    let m = jac.cols();
    debug_assert_eq!(resid.len(), jac.rows());
    debug_assert!(jac.width() == 0 || jac.group == group);
    let jtj = jac.gram();
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
    let (inv, singular, condition) = bread_inverse(&jtj, &scale);

    let (mut meat, blocks, white, n_time, block) = meat_of(jac, resid, time, group, &scale);
    let k = blocks.max(2) as f64;
    meat *= k / (k - 1.0);
    let bandwidth = block;
    let white = white.max(f64::MIN_POSITIVE);
    let effective_samples = if m > 0 {
        n_time as f64 * white / meat[(0, 0)].max(f64::MIN_POSITIVE)
    } else {
        n_time as f64
    };
    let scaled = &inv * meat * &inv;
    let cov = DMatrix::from_fn(m, m, |i, j| {
        if singular[i] || singular[j] {
            f64::NAN
        } else {
            scaled[(i, j)] / (scale[i] * scale[j])
        }
    });
    let cov_estimable = DMatrix::from_fn(m, m, |i, j| scaled[(i, j)] / (scale[i] * scale[j]));
    Hac {
        cov,
        cov_estimable,
        singular,
        condition,
        bandwidth,
        critical_value: student_t_975(k - 1.0),
        effective_samples: effective_samples.min(n_time as f64),
    }
}

/// The inverse of the scaled normal matrix `jtj/(scaleᵢ·scaleⱼ)` on its well-conditioned
/// eigenvectors, which parameters are singular (an eigenvector below [`SINGULAR`] of the
/// largest weighs on them), and the condition number.
fn bread_inverse(jtj: &DMatrix<f64>, scale: &[f64]) -> (DMatrix<f64>, Vec<bool>, f64) {
    let m = scale.len();
    let bread = DMatrix::from_fn(m, m, |i, j| jtj[(i, j)] / (scale[i] * scale[j]));
    let eig = SymmetricEigen::new(bread);
    let max_ev = eig.eigenvalues.max();
    let condition = crate::lm::condition_number(&eig);
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
    (inv, singular, condition)
}

/// The scaled scores' long-run covariance by blocks (the sandwich's meat, not yet
/// corrected for the number of blocks), the number of blocks, the first parameter's white
/// sum of squares, the time samples and the block length.
fn meat_of(
    jac: &Jacobian,
    resid: &[f64],
    time: &[usize],
    group: &[usize],
    scale: &[f64],
) -> (DMatrix<f64>, usize, f64, usize, usize) {
    let m = jac.cols();
    let (m0, width) = (jac.shared.ncols(), jac.width());
    // Each group's scores summed per sample index over its time span (the residuals that
    // share a time, in order), then cut into blocks of `block` consecutive sample indices.
    // The sums run in the order of the dense `residuals × parameters` form (each block's
    // column sums in time order, blocks in group order), so the result is its, bit for bit;
    // the columns of other groups' local parameters, zero there, are left out.
    let groups = group.iter().copied().max().map_or(0, |g| g + 1);
    let mut span = vec![(usize::MAX, 0usize); groups];
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); groups];
    for (i, (&t, &g)) in time.iter().zip(group).enumerate() {
        span[g].0 = span[g].0.min(t);
        span[g].1 = span[g].1.max(t);
        members[g].push(i);
    }
    let rows: Vec<usize> = span
        .iter()
        .map(|&(lo, hi)| if lo > hi { 0 } else { hi - lo + 1 })
        .collect();
    let n_time: usize = rows.iter().sum();
    let blocks_wanted = (n_time / BLOCK_SAMPLES).clamp(MIN_BLOCKS, MAX_BLOCKS);
    let block = n_time.div_ceil(blocks_wanted).max(1);
    let mut meat = DMatrix::<f64>::zeros(m, m);
    let mut blocks = 0usize;
    let mut white = 0.0;
    let cols = m0 + width;
    for g in 0..groups {
        // The group's columns: the shared ones, then its own local ones.
        let index: Vec<usize> = (0..m0)
            .chain((0..width).map(|k| jac.local_column(g, k)))
            .collect();
        let mut series = DMatrix::<f64>::zeros(rows[g], cols);
        for &i in &members[g] {
            let row = time[i] - span[g].0;
            for k in 0..m0 {
                series[(row, k)] += jac.shared[(i, k)] / scale[k] * resid[i];
            }
            for k in 0..width {
                series[(row, m0 + k)] += jac.local[(i, k)] / scale[index[m0 + k]] * resid[i];
            }
        }
        let mut start = 0;
        while start < rows[g] {
            let len = block.min(rows[g] - start);
            let sum = series.rows(start, len).row_sum();
            for (x, &i) in index.iter().enumerate() {
                for (y, &j) in index.iter().enumerate() {
                    meat[(i, j)] += sum[x] * sum[y];
                }
            }
            blocks += 1;
            start += len;
        }
        // The first parameter's column (another group's local one is zero here).
        if let Some(x) = index.iter().position(|&i| i == 0) {
            white += series.column(x).norm_squared();
        }
    }
    (meat, blocks, white, n_time, block)
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

    /// The mean of an AR(1) series `x_t = ρx_{t−1} + e_t` has the standard error
    /// `σ_e/((1−ρ)·√n)`; with ρ = 0.9 that is 4.4 times the i.i.d. value `σ_x/√n`. The
    /// sandwich's standard error, averaged over 200 series, must be within 10 % of it
    /// (batch means of 250-sample blocks miss `≈ 2ρ/((1−ρ)·250)` = 7 % of the variance,
    /// 4 % of the standard error; the average of 200 estimates scatters by 2 %).
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
            let mut jac = Jacobian::dense(n, 1);
            jac.shared.fill(1.0);
            let time: Vec<usize> = (0..n).collect();
            let hac = covariance(&jac, &resid, &time, &vec![0; n]);
            let truth = 1.0 / (1.0 - rho) / (n as f64).sqrt();
            ratio += hac.cov[(0, 0)].sqrt() / truth;
        }
        ratio /= reps as f64;
        assert!((ratio - 1.0).abs() < 0.10, "mean ratio {ratio}");
    }
}
