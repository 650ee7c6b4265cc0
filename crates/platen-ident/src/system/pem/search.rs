//! The Levenberg–Marquardt search of the prediction-error fit: which parameters the records
//! see (screened at the start), Marquardt's damped steps, the score test that ends it, and the
//! covariance at the end.

use nalgebra::{DMatrix, DVector};

use super::problem::{sum_squares, Problem};
use super::values::Param;

/// Most Levenberg–Marquardt iterations (Jacobians).
pub const MAX_ITERATIONS: usize = 30;
/// The fit stops when the full Gauss–Newton step would lower the sum of squares by less
/// than this many effective residual variances `σ²·τ` (the score statistic).
pub const CHI2_TOLERANCE: f64 = 0.1;
/// A Jacobian column below this fraction of the largest column's norm: not seen.
pub const MIN_COLUMN_NORM: f64 = 1e-6;
/// Multiple correlation of a Jacobian column with the others above which the parameter is
/// held (the records cannot tell it from the others).
pub const MAX_CORRELATION: f64 = 0.9999;
/// Largest Marquardt damping before the fit gives up on a lower cost.
const MAX_LAMBDA: f64 = 1e10;

/// The parameters held because the records do not see them or cannot tell them apart,
/// with why, from the Jacobian `jac` of `cols`: the kept columns' positions in `cols`.
fn screen(
    jac: &DMatrix<f64>,
    cols: &[usize],
    params: &[Param],
) -> (Vec<usize>, Vec<(usize, String)>) {
    let norms: Vec<f64> = (0..jac.ncols()).map(|k| jac.column(k).norm()).collect();
    let largest = norms.iter().copied().fold(0.0, f64::max);
    let mut held = Vec::new();
    let mut kept: Vec<usize> = Vec::new();
    for (k, &n) in norms.iter().enumerate() {
        if n.is_finite() && n > MIN_COLUMN_NORM * largest && n > 0.0 {
            kept.push(k);
        } else {
            held.push((
                k,
                format!(
                    "the records do not see it: the predicted accelerations change by {:.1e} \
                     of the largest parameter's effect for the same relative change",
                    n / largest.max(f64::MIN_POSITIVE)
                ),
            ));
        }
    }
    loop {
        let m = kept.len();
        if m < 2 {
            break;
        }
        let c = DMatrix::from_fn(m, m, |a, b| {
            jac.column(kept[a]).dot(&jac.column(kept[b])) / (norms[kept[a]] * norms[kept[b]])
        });
        let inflation: Vec<f64> = match c.clone().cholesky() {
            Some(ch) => {
                let inv = ch.inverse();
                (0..m).map(|a| inv[(a, a)]).collect()
            }
            None => vec![f64::INFINITY; m],
        };
        // The largest inflation (the last of equals) goes first.
        let (worst, vif) =
            inflation
                .iter()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |best, (a, &v)| {
                    if v >= best.1 || v.is_nan() {
                        (a, v)
                    } else {
                        best
                    }
                });
        let r2 = 1.0 - 1.0 / vif;
        if vif.is_finite() && r2 <= MAX_CORRELATION * MAX_CORRELATION {
            break;
        }
        // Its strongest partner, for the message.
        let partner = (0..m)
            .filter(|&b| b != worst)
            .max_by(|&a, &b| c[(worst, a)].abs().total_cmp(&c[(worst, b)].abs()))
            .map_or(String::new(), |b| {
                format!(
                    "; most with {} (correlation {:.4})",
                    params[cols[kept[b]]].key,
                    c[(worst, b)]
                )
            });
        held.push((
            kept[worst],
            format!(
                "the other parameters reproduce its effect on the predicted accelerations \
                 (multiple correlation {:.6}{partner}): held at the equation error's value",
                r2.max(0.0).sqrt()
            ),
        ));
        kept.remove(worst);
    }
    held.sort_by_key(|h| h.0);
    (kept, held)
}

/// What the Levenberg–Marquardt search ends with.
pub(super) struct Outcome {
    /// The final coordinates and their residuals.
    pub theta: Vec<f64>,
    pub residuals: Vec<f64>,
    /// The free parameters (indices into the problem's) and their covariance in `θ`.
    pub free: Vec<usize>,
    pub covariance: Option<DMatrix<f64>>,
    /// The parameters held at the start, with why.
    pub held: Vec<(usize, String)>,
    /// Iterations (Jacobians that led to a step), whether the score test ended the search
    /// and why it stopped.
    pub iterations: usize,
    pub converged: bool,
    pub stop_reason: String,
    /// Steps rejected and runs failed.
    pub rejected: usize,
    pub failed: usize,
    /// The final residuals' correlation time, samples.
    pub tau: f64,
}

/// The damped Gauss–Newton step of `a`, `g` at damping `lambda`.
fn damped_step(a: &DMatrix<f64>, g: &DVector<f64>, lambda: f64) -> Option<DVector<f64>> {
    let mut m = a.clone();
    for k in 0..m.nrows() {
        m[(k, k)] += lambda * a[(k, k)].max(f64::MIN_POSITIVE);
    }
    let step = m.cholesky()?.solve(&(-g));
    step.iter().all(|x| x.is_finite()).then_some(step)
}

/// Levenberg–Marquardt on `problem` from its start (module docs); `None` when the start's
/// own run fails.
pub(super) fn levenberg_marquardt(problem: &Problem<'_>) -> Option<Outcome> {
    let theta: Vec<f64> = problem.params.iter().map(Param::theta0).collect();
    let r = problem.residuals(&theta)?;
    let mut s = Search {
        problem,
        n: r.len(),
        ss: sum_squares(&r),
        theta,
        r,
        free: (0..problem.params.len()).collect(),
        held: Vec::new(),
        lambda: 1e-3,
        iterations: 0,
        rejected: 0,
        failed: 0,
    };
    let mut last_jac: Option<DMatrix<f64>> = None;
    let (converged, stop_reason) = loop {
        let (jac, f) = problem.jacobian(&s.theta, &s.r, &s.free);
        s.failed += f;
        let Some(mut jac) = jac else {
            break (
                false,
                "a run of the Jacobian failed both ways: stopped at the last values".into(),
            );
        };
        if s.iterations == 0 {
            jac = s.screen_start(&jac);
        }
        last_jac = Some(jac.clone());
        if s.free.is_empty() {
            break (false, "no parameter the records can tell apart".into());
        }
        if s.iterations >= MAX_ITERATIONS {
            break (false, format!("{MAX_ITERATIONS} iterations"));
        }
        let a = jac.tr_mul(&jac);
        let rv = DVector::from_column_slice(&s.r);
        let g = jac.tr_mul(&rv);
        if let Some(reason) = s.score_converged(&a, &g) {
            break (true, reason);
        }
        s.iterations += 1;
        if !s.descend(&a, &g) {
            // No step along the (finite-difference) gradient lowers the cost: a minimum as
            // far as the runs can tell, though the score says a better point may exist. The
            // Jacobian at these values is the last one: no further run needed.
            break (
                false,
                "no damping gives a lower cost: stopped where the runs can no \
                 longer tell a better point (not converged by the score test)"
                    .into(),
            );
        }
    };
    Some(s.outcome(last_jac, converged, stop_reason))
}

/// The state of the Levenberg–Marquardt search between its iterations.
struct Search<'p, 'a> {
    problem: &'p Problem<'a>,
    /// Residuals' count.
    n: usize,
    /// The current coordinates, their residuals and sum of squares.
    theta: Vec<f64>,
    r: Vec<f64>,
    ss: f64,
    /// The parameters moved (indices into the problem's), and those held with why.
    free: Vec<usize>,
    held: Vec<(usize, String)>,
    /// Marquardt's damping.
    lambda: f64,
    iterations: usize,
    rejected: usize,
    failed: usize,
}

impl Search<'_, '_> {
    /// At the start: holds the parameters the records do not see or cannot tell apart
    /// ([`screen`]), and returns the Jacobian `jac` of the free ones kept.
    fn screen_start(&mut self, jac: &DMatrix<f64>) -> DMatrix<f64> {
        let (kept, h) = screen(jac, &self.free, &self.problem.params);
        self.held = h.into_iter().map(|(k, why)| (self.free[k], why)).collect();
        let cols: Vec<usize> = kept.iter().map(|&k| self.free[k]).collect();
        let kept_jac = DMatrix::from_fn(self.n, kept.len(), |i, k| jac[(i, kept[k])]);
        self.free = cols;
        kept_jac
    }

    /// The residuals' variance `σ²` over `N − p`.
    fn sigma2(&self) -> f64 {
        self.ss / (self.n.saturating_sub(self.free.len())).max(1) as f64
    }

    /// The stop reason when the score statistic (what the full Gauss–Newton step of `a`, `g`
    /// would lower the sum of squares by, in effective residual variances) is below
    /// [`CHI2_TOLERANCE`].
    fn score_converged(&self, a: &DMatrix<f64>, g: &DVector<f64>) -> Option<String> {
        let sigma2 = self.sigma2();
        let tau = self.problem.correlation_time(&self.r);
        let gn = damped_step(a, g, 0.0)?;
        let score = -g.dot(&gn) / (sigma2 * tau);
        (score < CHI2_TOLERANCE).then(|| {
            format!(
                "converged: the Gauss–Newton step would lower the sum of squares by \
                 {score:.3} effective residual variances (< {CHI2_TOLERANCE})"
            )
        })
    }

    /// Marquardt's damped steps of `a`, `g` from the least damping up until one lowers the
    /// cost (taken, the damping divided by 10) or the damping passes [`MAX_LAMBDA`];
    /// whether a step was taken.
    fn descend(&mut self, a: &DMatrix<f64>, g: &DVector<f64>) -> bool {
        let params = &self.problem.params;
        while self.lambda <= MAX_LAMBDA {
            let Some(step) = damped_step(a, g, self.lambda) else {
                self.lambda *= 10.0;
                continue;
            };
            let mut trial = self.theta.clone();
            for (k, &j) in self.free.iter().enumerate() {
                trial[j] = params[j].project(self.theta[j] + step[k]);
            }
            match self.problem.residuals(&trial) {
                Some(rt) if sum_squares(&rt) < self.ss => {
                    self.theta = trial;
                    self.r = rt;
                    self.ss = sum_squares(&self.r);
                    self.lambda = (self.lambda / 10.0).max(1e-12);
                    return true;
                }
                Some(_) => {
                    self.rejected += 1;
                    self.lambda *= 10.0;
                }
                None => {
                    self.rejected += 1;
                    self.failed += 1;
                    self.lambda *= 10.0;
                }
            }
        }
        false
    }

    /// The search's end, the covariance `σ²·τ·(JᵀJ)⁻¹` from the last Jacobian `last_jac`
    /// (when it is the free parameters').
    fn outcome(
        self,
        last_jac: Option<DMatrix<f64>>,
        converged: bool,
        stop_reason: String,
    ) -> Outcome {
        let tau = self.problem.correlation_time(&self.r);
        let covariance = last_jac
            .filter(|j| j.ncols() == self.free.len() && !self.free.is_empty())
            .and_then(|jac| {
                let sigma2 = self.sigma2();
                let a = jac.tr_mul(&jac);
                let inv = a.cholesky()?.inverse();
                Some(inv * (sigma2 * tau))
            });
        Outcome {
            theta: self.theta,
            residuals: self.r,
            free: self.free,
            covariance,
            held: self.held,
            iterations: self.iterations,
            converged,
            stop_reason,
            rejected: self.rejected,
            failed: self.failed,
            tau,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::values::{Coordinate, Kind};
    use super::*;

    fn params(n: usize) -> Vec<Param> {
        (0..n)
            .map(|j| Param {
                kind: Kind::Mass,
                key: format!("p{j}"),
                start: 1.0,
                coordinate: Coordinate::Log,
            })
            .collect()
    }

    /// Two identical columns: one is held, the other kept; a zero column is held.
    #[test]
    fn a_column_the_others_reproduce_or_a_zero_column_is_held() {
        let n = 50;
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
        let jac = DMatrix::from_fn(n, 4, |i, k| match k {
            0 => x[i],
            1 => y[i],
            2 => 2.0 * x[i],
            _ => 0.0,
        });
        let (kept, held) = screen(&jac, &[0, 1, 2, 3], &params(4));
        assert_eq!(held.len(), 2, "{held:?}");
        assert!(held.iter().any(|h| h.0 == 3));
        assert!(kept.contains(&1));
        assert_eq!(kept.len(), 2);
    }
}
