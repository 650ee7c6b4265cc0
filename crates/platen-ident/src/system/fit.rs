//! Linear least squares for the loop's fits: a design matrix kept row by row with each row's
//! record and time, solved with sign constraints (a gain or a friction force that the physics
//! says is not negative), and the standard errors of the estimate from the residuals' own
//! correlation.
//!
//! **Sign constraints** are exact non-negative least squares: with at most a handful of
//! constrained columns every subset of them held at 0 is solved (normal equations, columns
//! scaled to unit norm, Cholesky) and the feasible solution of least residual kept. A
//! coefficient held at 0 this way is *clamped*: it has no standard error, and the caller says
//! why it is 0.
//!
//! **Standard errors** are the sandwich `B⁻¹·S·B⁻¹` with `B = XᵀX` and `S` the batch-means
//! estimate of the scores' long-run covariance, as the any-record method computes them
//! (`anyrecord::hac`, whose module docs give the reasons): each record is cut into blocks of
//! consecutive samples (at least [`BLOCK_SAMPLES`], between [`MIN_BLOCKS`] and [`MAX_BLOCKS`]
//! blocks in all), the scores `xᵢ·rᵢ` are summed per block, `S = K/(K−1)·Σ Gₖ·Gₖᵀ`, and the
//! 95 % interval uses Student's t with `K − 1` degrees of freedom. Filtered signals, whose
//! residuals are correlated over the filter's memory, need exactly this.

use nalgebra::{DMatrix, DVector};

use crate::estimate::Estimate;

/// Fewest samples in a block of the batch-means covariance.
pub const BLOCK_SAMPLES: usize = 400;
/// Fewest blocks (below this the t quantile widens every interval more than it gains).
pub const MIN_BLOCKS: usize = 6;
/// Most blocks.
pub const MAX_BLOCKS: usize = 30;
/// Most sign-constrained columns (every subset is solved: `2^k` small solves).
const MAX_CONSTRAINED: usize = 10;

/// Rows of a linear least-squares problem, each with the record and the sample it came from.
#[derive(Debug, Clone)]
pub(crate) struct Design {
    m: usize,
    x: Vec<f64>,
    y: Vec<f64>,
    /// `(record, sample)` of each row.
    at: Vec<(usize, usize)>,
}

/// The solution of a [`Design`].
#[derive(Debug, Clone)]
pub(crate) struct LinearFit {
    /// Coefficients (clamped ones 0).
    pub coef: Vec<f64>,
    /// Whether each coefficient was held at 0 by its sign constraint.
    pub clamped: Vec<bool>,
    /// The estimates with their standard errors (clamped: NaN error).
    pub estimates: Vec<Estimate>,
    /// Residual sum of squares.
    pub rss: f64,
    /// Sum of squares of the right-hand side.
    pub yy: f64,
    /// Rows.
    pub rows: usize,
}

impl LinearFit {
    /// RMS of the residual relative to the right-hand side's RMS.
    pub fn nrmse(&self) -> f64 {
        if self.yy > 0.0 {
            (self.rss / self.yy).sqrt()
        } else {
            f64::NAN
        }
    }

    /// RMS of the residual.
    pub fn rms_residual(&self) -> f64 {
        (self.rss / self.rows.max(1) as f64).sqrt()
    }
}

impl Design {
    /// An empty design of `m` columns.
    pub fn new(m: usize) -> Self {
        Self {
            m,
            x: Vec::new(),
            y: Vec::new(),
            at: Vec::new(),
        }
    }

    /// Appends a row.
    pub fn push(&mut self, row: &[f64], y: f64, record: usize, sample: usize) {
        debug_assert_eq!(row.len(), self.m);
        self.x.extend_from_slice(row);
        self.y.push(y);
        self.at.push((record, sample));
    }

    /// Rows so far.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// The residual sum of squares at `coef` and the right-hand side's sum of squares.
    pub fn residual_and_rhs(&self, coef: &[f64]) -> (f64, f64) {
        (0..self.len()).fold((0.0, 0.0), |(rr, yy), i| {
            let r = self.y[i] - dot(self.row(i), coef);
            (rr + r * r, yy + self.y[i] * self.y[i])
        })
    }

    fn row(&self, i: usize) -> &[f64] {
        &self.x[i * self.m..(i + 1) * self.m]
    }

    /// `XᵀX`, `Xᵀy` and `yᵀy`.
    fn normal(&self) -> (DMatrix<f64>, DVector<f64>, f64) {
        let m = self.m;
        let mut xtx = DMatrix::zeros(m, m);
        let mut xty = DVector::zeros(m);
        let mut yy = 0.0;
        for (i, &y) in self.y.iter().enumerate() {
            let r = self.row(i);
            for a in 0..m {
                xty[a] += r[a] * y;
                for b in a..m {
                    xtx[(a, b)] += r[a] * r[b];
                }
            }
            yy += y * y;
        }
        for a in 0..m {
            for b in 0..a {
                xtx[(a, b)] = xtx[(b, a)];
            }
        }
        (xtx, xty, yy)
    }

    /// Least squares with `nonneg[j]` columns constrained to `≥ 0` (and `fixed[j]` columns
    /// held at 0 whatever their sign); `None` when the rows cannot determine the free
    /// coefficients.
    pub fn fit(&self, nonneg: &[bool], fixed: &[bool]) -> Option<LinearFit> {
        let m = self.m;
        if self.len() <= m {
            return None;
        }
        let (xtx, xty, yy) = self.normal();
        let constrained: Vec<usize> = (0..m).filter(|&j| nonneg[j] && !fixed[j]).collect();
        if constrained.len() > MAX_CONSTRAINED {
            return None;
        }
        let mut best: Option<(Vec<f64>, Vec<bool>, f64)> = None;
        for mask in 0u32..(1u32 << constrained.len()) {
            let mut held: Vec<bool> = fixed.to_vec();
            for (k, &j) in constrained.iter().enumerate() {
                if mask & (1 << k) != 0 {
                    held[j] = true;
                }
            }
            let Some(coef) = solve_subset(&xtx, &xty, &held) else {
                continue;
            };
            if constrained.iter().any(|&j| coef[j] < 0.0) {
                continue;
            }
            let rss = rss_of(&xtx, &xty, yy, &coef);
            if best.as_ref().is_none_or(|b| rss < b.2) {
                best = Some((coef, held, rss));
            }
        }
        let (coef, held, _) = best?;
        // The residual sum of squares from the rows themselves (the normal equations lose
        // digits when the fit is close).
        let resid: Vec<f64> = (0..self.len())
            .map(|i| self.y[i] - dot(self.row(i), &coef))
            .collect();
        let rss = resid.iter().map(|r| r * r).sum();
        let estimates = self.sandwich(&xtx, &coef, &held, &resid);
        Some(LinearFit {
            clamped: (0..m).map(|j| held[j] && !fixed[j]).collect(),
            coef,
            estimates,
            rss,
            yy,
            rows: self.len(),
        })
    }

    /// The batch-means sandwich covariance of the free coefficients (module docs).
    fn sandwich(
        &self,
        xtx: &DMatrix<f64>,
        coef: &[f64],
        held: &[bool],
        resid: &[f64],
    ) -> Vec<Estimate> {
        let free: Vec<usize> = (0..self.m).filter(|&j| !held[j]).collect();
        let p = free.len();
        let nan = |j: usize| Estimate::new(coef[j], f64::NAN, f64::NAN);
        let b = DMatrix::from_fn(p, p, |a, c| xtx[(free[a], free[c])]);
        let Some(b_inv) = b.try_inverse() else {
            return (0..self.m).map(nan).collect();
        };
        // Blocks: consecutive samples of one record; a new block starts with a new record or
        // after `block` samples.
        let n = self.len();
        let blocks_wanted = (n / BLOCK_SAMPLES).clamp(MIN_BLOCKS, MAX_BLOCKS);
        let block = n.div_ceil(blocks_wanted).max(1);
        let mut sums: Vec<DVector<f64>> = Vec::new();
        let mut current = DVector::zeros(p);
        let mut count = 0usize;
        let mut last_record = None;
        for (i, (&(record, _), &e)) in self.at.iter().zip(resid).enumerate() {
            if count >= block || last_record.is_some_and(|r| r != record) {
                sums.push(std::mem::replace(&mut current, DVector::zeros(p)));
                count = 0;
            }
            last_record = Some(record);
            let r = self.row(i);
            for (a, &j) in free.iter().enumerate() {
                current[a] += r[j] * e;
            }
            count += 1;
        }
        if count > 0 {
            sums.push(current);
        }
        let k = sums.len();
        if k < 2 {
            return (0..self.m).map(nan).collect();
        }
        let mut s = DMatrix::zeros(p, p);
        for g in &sums {
            s += g * g.transpose();
        }
        s *= k as f64 / (k - 1) as f64;
        let cov = &b_inv * s * &b_inv;
        let dof = (k - 1) as f64;
        let mut out: Vec<Estimate> = (0..self.m).map(nan).collect();
        for (a, &j) in free.iter().enumerate() {
            out[j] = Estimate::new(coef[j], cov[(a, a)].max(0.0).sqrt(), dof);
        }
        out
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The normal equations solved with the `held` columns at 0 (columns scaled to unit
/// diagonal); `None` when singular.
fn solve_subset(xtx: &DMatrix<f64>, xty: &DVector<f64>, held: &[bool]) -> Option<Vec<f64>> {
    let m = xtx.nrows();
    let free: Vec<usize> = (0..m).filter(|&j| !held[j] && xtx[(j, j)] > 0.0).collect();
    let mut coef = vec![0.0; m];
    if free.is_empty() {
        return Some(coef);
    }
    let d: Vec<f64> = free.iter().map(|&j| xtx[(j, j)].sqrt()).collect();
    let p = free.len();
    let a = DMatrix::from_fn(p, p, |r, c| xtx[(free[r], free[c])] / (d[r] * d[c]));
    let b = DVector::from_fn(p, |r, _| xty[free[r]] / d[r]);
    // Rank: a scaled eigenvalue below 1e-12 of the largest is a direction the rows do not
    // determine.
    let eig = a.clone().symmetric_eigenvalues();
    if eig.min() <= 1e-12 * eig.max() {
        return None;
    }
    let x = a.cholesky()?.solve(&b);
    for (r, &j) in free.iter().enumerate() {
        coef[j] = x[r] / d[r];
    }
    Some(coef)
}

fn rss_of(xtx: &DMatrix<f64>, xty: &DVector<f64>, yy: f64, coef: &[f64]) -> f64 {
    let c = DVector::from_column_slice(coef);
    (yy - 2.0 * c.dot(xty) + (c.transpose() * xtx * &c)[(0, 0)]).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `y = 2·x₀ − 0.5·x₁ + 0.1·noise`: unconstrained, the fit finds both; with `x₁ ≥ 0` it
    /// holds `x₁` at 0 and refits `x₀` alone (whose value the closed form `Σx₀y/Σx₀²` gives).
    #[test]
    fn sign_constraints_clamp_and_refit() {
        let mut d = Design::new(2);
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut rows = Vec::new();
        for i in 0..4000 {
            let x0 = rnd();
            let x1 = rnd();
            let y = 2.0 * x0 - 0.5 * x1 + 0.01 * rnd();
            d.push(&[x0, x1], y, 0, i);
            rows.push((x0, x1, y));
        }
        let free = d.fit(&[false, false], &[false, false]).unwrap();
        assert!((free.coef[0] - 2.0).abs() < 1e-3, "{:?}", free.coef);
        assert!((free.coef[1] + 0.5).abs() < 1e-3, "{:?}", free.coef);
        assert!(free.estimates[0].std_error > 0.0 && free.estimates[0].std_error < 1e-3);
        let held = d.fit(&[false, true], &[false, false]).unwrap();
        assert!(held.clamped[1] && !held.clamped[0]);
        assert_eq!(held.coef[1], 0.0);
        let (sxy, sxx) = rows
            .iter()
            .fold((0.0, 0.0), |(a, b), r| (a + r.0 * r.2, b + r.0 * r.0));
        assert!((held.coef[0] - sxy / sxx).abs() < 1e-12);
        assert!(held.estimates[1].std_error.is_nan());
    }

    /// Too few rows, or a column that repeats another: no fit.
    #[test]
    fn undetermined_designs_give_none() {
        let mut d = Design::new(2);
        for i in 0..50 {
            let x = i as f64;
            d.push(&[x, 2.0 * x], x, 0, i);
        }
        assert!(d.fit(&[false, false], &[false, false]).is_none());
        assert!(Design::new(3).fit(&[false; 3], &[false; 3]).is_none());
    }
}
