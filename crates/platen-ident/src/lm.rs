//! Levenberg–Marquardt nonlinear least squares on nalgebra, with box bounds by projection,
//! and the covariance of the estimate from the Jacobian at the optimum.
//!
//! The problems here are small (at most a dozen parameters) and tall (up to ~10⁵ residuals),
//! so the normal equations `JᵀJ` are formed explicitly and solved by Cholesky; the damping is
//! Marquardt's, proportional to the diagonal of `JᵀJ`, which makes the iteration invariant to
//! the parameters' units (newtons next to exponents).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// A least-squares problem: minimise `½·Σ rᵢ(p)²`.
pub(crate) trait Problem {
    /// Number of residuals.
    fn residual_count(&self) -> usize;
    /// Number of parameters.
    fn parameter_count(&self) -> usize;
    /// Residuals `r(p)` (model − data, weighted) into `r`.
    fn residuals(&self, p: &[f64], r: &mut [f64]);
    /// Jacobian `∂rᵢ/∂pⱼ` into `j` (`residual_count × parameter_count`).
    fn jacobian(&self, p: &[f64], j: &mut DMatrix<f64>);
}

/// Stopping rules.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LmSettings {
    /// Most outer iterations (Jacobian evaluations).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction of it.
    pub cost_tolerance: f64,
    /// Stop when every parameter changes by less than this fraction of its size (or of 1 for
    /// parameters near zero, scaled by the diagonal of `JᵀJ`).
    pub step_tolerance: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            cost_tolerance: 1e-14,
            step_tolerance: 1e-12,
        }
    }
}

/// Result of a minimisation.
#[derive(Debug, Clone)]
pub(crate) struct LmResult {
    /// Parameters at the optimum.
    pub params: Vec<f64>,
    /// Sum of squared residuals at the optimum.
    pub ssr: f64,
    /// Jacobian at the optimum.
    pub jacobian: DMatrix<f64>,
    /// Outer iterations done.
    pub iterations: usize,
    /// Whether a stopping rule (not the iteration limit) ended the run.
    pub converged: bool,
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Projects `p` onto the box `lower ≤ p ≤ upper`.
fn project(p: &mut [f64], lower: &[f64], upper: &[f64]) {
    for ((x, lo), hi) in p.iter_mut().zip(lower).zip(upper) {
        *x = x.clamp(*lo, *hi);
    }
}

/// The state of a minimisation between iterations.
struct Search<'a> {
    p: Vec<f64>,
    r: Vec<f64>,
    trial: Vec<f64>,
    trial_r: Vec<f64>,
    cost: f64,
    lambda: f64,
    lower: &'a [f64],
    upper: &'a [f64],
}

impl Search<'_> {
    /// One outer iteration at the Jacobian `jac`: raises the damping until a step lowers the
    /// cost, and takes it. Returns true when a stopping rule says the minimum is reached.
    fn iterate<P: Problem>(
        &mut self,
        problem: &P,
        jac: &DMatrix<f64>,
        settings: &LmSettings,
    ) -> bool {
        let m = self.p.len();
        let jtj = jac.tr_mul(jac);
        let g = jac.tr_mul(&DVector::from_column_slice(&self.r));
        let diag: Vec<f64> = (0..m)
            .map(|i| jtj[(i, i)].max(1e-300 + 1e-12 * jtj.diagonal().max()))
            .collect();
        loop {
            let mut a = jtj.clone();
            for (i, d) in diag.iter().enumerate() {
                a[(i, i)] += self.lambda * d;
            }
            let Some(chol) = a.cholesky() else {
                self.lambda *= 10.0;
                if self.lambda > 1e20 {
                    return true;
                }
                continue;
            };
            let step = chol.solve(&(-&g));
            for i in 0..m {
                self.trial[i] = self.p[i] + step[i];
            }
            project(&mut self.trial, self.lower, self.upper);
            problem.residuals(&self.trial, &mut self.trial_r);
            let trial_cost = sum_sq(&self.trial_r);
            if trial_cost.is_finite() && trial_cost <= self.cost {
                return self.accept(trial_cost, &diag, settings);
            }
            self.lambda *= 10.0;
            if self.lambda > 1e20 {
                // No descent direction left: a (possibly constrained) minimum.
                return true;
            }
        }
    }

    /// Takes the trial point; true if the step or the gain was below tolerance.
    fn accept(&mut self, trial_cost: f64, diag: &[f64], settings: &LmSettings) -> bool {
        let (p, trial) = (&self.p, &self.trial);
        let small_step = (0..p.len()).all(|i| {
            let scale = p[i].abs().max(1.0 / diag[i].sqrt().max(1e-300));
            (trial[i] - p[i]).abs() <= settings.step_tolerance * scale
        });
        let small_gain = self.cost - trial_cost <= settings.cost_tolerance * self.cost;
        std::mem::swap(&mut self.p, &mut self.trial);
        std::mem::swap(&mut self.r, &mut self.trial_r);
        self.cost = trial_cost;
        self.lambda = (self.lambda * 0.1).max(1e-15);
        small_step || small_gain || self.cost == 0.0
    }
}

/// Minimises `problem` from `start`, keeping `lower ≤ p ≤ upper` by projecting every trial
/// point onto the box.
pub(crate) fn minimize<P: Problem>(
    problem: &P,
    start: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: LmSettings,
) -> LmResult {
    let n = problem.residual_count();
    let m = problem.parameter_count();
    debug_assert_eq!(start.len(), m);
    let mut p = start.to_vec();
    project(&mut p, lower, upper);
    let mut r = vec![0.0; n];
    problem.residuals(&p, &mut r);
    let mut search = Search {
        cost: sum_sq(&r),
        p,
        r,
        trial: vec![0.0; m],
        trial_r: vec![0.0; n],
        lambda: 1e-3,
        lower,
        upper,
    };
    let mut jac = DMatrix::zeros(n, m);
    let mut iterations = 0;
    let mut converged = false;
    while iterations < settings.max_iterations {
        iterations += 1;
        problem.jacobian(&search.p, &mut jac);
        if search.iterate(problem, &jac, &settings) {
            converged = true;
            break;
        }
    }
    problem.jacobian(&search.p, &mut jac);
    LmResult {
        params: search.p,
        ssr: search.cost,
        jacobian: jac,
        iterations,
        converged,
    }
}

/// The covariance of a least-squares estimate, from the Jacobian at the optimum.
#[derive(Debug, Clone)]
pub(crate) struct Covariance {
    /// Standard error of each parameter (`+∞` for a parameter the data do not determine).
    pub std_errors: Vec<f64>,
    /// Whether each parameter lies (with a loading above 0.1) in a direction of `JᵀJ` that is
    /// singular to within [`SINGULAR_RELATIVE_EIGENVALUE`] after scaling to unit diagonal.
    pub singular: Vec<bool>,
    /// Condition number of the scaled `JᵀJ` (1 for one parameter; `∞` if singular).
    pub condition: f64,
    /// Degrees of freedom of the residual: independent observations minus parameters (≥ 1).
    pub dof: f64,
}

/// Scaled `JᵀJ` eigenvalues below this fraction of the largest count as singular: the
/// parameters cannot be told apart. `1e-10` is far above rounding (`~1e-16·n`) and far below
/// the weakest direction of a well-posed fit here (the α–Cₑ trade-off of the dissipative law
/// over the paper's velocity range has ~1e-4).
pub(crate) const SINGULAR_RELATIVE_EIGENVALUE: f64 = 1e-10;

/// Covariance `L·s²·(JᵀJ)⁻¹` with `s² = SSR/(n − p)`.
///
/// `correlation_samples` `L ≥ 1` is the number of consecutive residuals that carry one
/// independent observation: residuals of low-passed records are correlated over about
/// `f_s/(2f_c)` samples, and treating them as independent would understate the errors by
/// `√L`. The degrees of freedom are `n/L − p`, at least 1.
/// The condition number of a symmetric matrix from its eigen-decomposition: the ratio of its
/// largest to its smallest eigenvalue, infinite if the smallest is not positive.
pub(crate) fn condition_number(eig: &SymmetricEigen<f64, nalgebra::Dyn>) -> f64 {
    let (max_ev, min_ev) = (eig.eigenvalues.max(), eig.eigenvalues.min());
    if min_ev > 0.0 {
        max_ev / min_ev
    } else {
        f64::INFINITY
    }
}

pub(crate) fn covariance(jac: &DMatrix<f64>, ssr: f64, correlation_samples: f64) -> Covariance {
    let n = jac.nrows();
    let m = jac.ncols();
    let l = correlation_samples.max(1.0);
    let dof = (n as f64 / l - m as f64).max(1.0);
    let s2 = ssr / (n as f64 - m as f64).max(1.0);
    let jtj = jac.tr_mul(jac);
    let d: Vec<f64> = (0..m).map(|i| jtj[(i, i)].sqrt()).collect();
    let mut std_errors = vec![f64::INFINITY; m];
    let live: Vec<usize> = (0..m).filter(|&i| d[i] > 0.0 && d[i].is_finite()).collect();
    // A parameter the residuals do not depend on at all is singular from the start.
    let mut singular: Vec<bool> = (0..m).map(|i| !live.contains(&i)).collect();
    if live.is_empty() {
        return Covariance {
            std_errors,
            singular,
            condition: f64::INFINITY,
            dof,
        };
    }
    let k = live.len();
    let scaled = DMatrix::from_fn(k, k, |a, b| {
        let (i, j) = (live[a], live[b]);
        jtj[(i, j)] / (d[i] * d[j])
    });
    let eig = SymmetricEigen::new(scaled);
    let max_ev = eig.eigenvalues.max();
    let condition = condition_number(&eig);
    // Pseudo-inverse of the scaled matrix without its singular directions.
    let mut inv = DMatrix::zeros(k, k);
    for e in 0..k {
        let ev = eig.eigenvalues[e];
        let vec = eig.eigenvectors.column(e);
        if ev <= SINGULAR_RELATIVE_EIGENVALUE * max_ev {
            for a in 0..k {
                if vec[a].abs() > 0.1 {
                    singular[live[a]] = true;
                }
            }
            continue;
        }
        inv += (vec * vec.transpose()) / ev;
    }
    for (a, &i) in live.iter().enumerate() {
        if !singular[i] {
            std_errors[i] = (l * s2 * inv[(a, a)]).sqrt() / d[i];
        }
    }
    Covariance {
        std_errors,
        singular,
        condition,
        dof,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = p0·exp(−p1·x) on exact data.
    struct Exp {
        x: Vec<f64>,
        y: Vec<f64>,
    }

    impl Problem for Exp {
        fn residual_count(&self) -> usize {
            self.x.len()
        }
        fn parameter_count(&self) -> usize {
            2
        }
        fn residuals(&self, p: &[f64], r: &mut [f64]) {
            for ((r, x), y) in r.iter_mut().zip(&self.x).zip(&self.y) {
                *r = p[0] * (-p[1] * x).exp() - y;
            }
        }
        fn jacobian(&self, p: &[f64], j: &mut DMatrix<f64>) {
            for (i, x) in self.x.iter().enumerate() {
                let e = (-p[1] * x).exp();
                j[(i, 0)] = e;
                j[(i, 1)] = -p[0] * x * e;
            }
        }
    }

    #[test]
    fn an_exponential_decay_is_recovered_from_a_poor_start() {
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y = x.iter().map(|x| 3.0 * (-0.7 * x).exp()).collect();
        let prob = Exp { x, y };
        let fit = minimize(
            &prob,
            &[1.0, 3.0],
            &[0.0, 0.0],
            &[100.0, 100.0],
            LmSettings::default(),
        );
        assert!(fit.converged);
        assert!((fit.params[0] - 3.0).abs() < 1e-9, "{:?}", fit.params);
        assert!((fit.params[1] - 0.7).abs() < 1e-9, "{:?}", fit.params);
    }

    #[test]
    fn a_bound_holds_at_the_constrained_optimum() {
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y = x.iter().map(|x| 3.0 * (-0.7 * x).exp()).collect();
        let prob = Exp { x, y };
        let fit = minimize(
            &prob,
            &[1.0, 0.1],
            &[0.0, 0.0],
            &[100.0, 0.5],
            LmSettings::default(),
        );
        assert_eq!(fit.params[1], 0.5);
        assert!(fit.ssr > 0.0);
    }

    #[test]
    fn a_collinear_pair_is_reported_singular() {
        // Two identical columns: p0 + p1 is determined, each alone is not.
        let jac = DMatrix::from_fn(20, 2, |i, _| 1.0 + i as f64);
        let cov = covariance(&jac, 1.0, 1.0);
        assert!(cov.singular[0] && cov.singular[1]);
        assert!(cov.condition.is_infinite() || cov.condition > 1e12);
    }

    #[test]
    fn straight_line_standard_errors_match_the_textbook_formula() {
        // y = a + b·x with residuals of known size: se(b) = s/√Sxx.
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        let jac = DMatrix::from_fn(10, 2, |i, c| if c == 0 { 1.0 } else { x[i] });
        let ssr = 8.0;
        let cov = covariance(&jac, ssr, 1.0);
        let s2 = ssr / 8.0;
        let mean = 4.5;
        let sxx: f64 = x.iter().map(|x| (x - mean) * (x - mean)).sum();
        assert!((cov.std_errors[1] - (s2 / sxx).sqrt()).abs() < 1e-12);
        assert_eq!(cov.dof, 8.0);
    }
}
