//! Levenberg–Marquardt nonlinear least squares on nalgebra, with box bounds by projection,
//! and the covariance of the estimate from the Jacobian at the optimum.
//!
//! The problems here are tall (up to ~10⁶ residuals) with few parameters, or with parameters
//! that each touch one group of residuals only (a record's offset or initial state), so the
//! normal equations `JᵀJ` are formed explicitly, from a Jacobian stored by blocks
//! ([`Jacobian`]), and solved by Cholesky; the damping is Marquardt's, proportional to the
//! diagonal of `JᵀJ`, which makes the iteration invariant to the parameters' units (newtons
//! next to exponents).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// A Jacobian `∂rᵢ/∂pⱼ` stored by blocks. The first `shared` parameters may move any
/// residual; the rest come in groups of `width`, one group per group of residuals (group `g`
/// at positions `shared + g·width …`), and move only the residuals of their group: a
/// record's force offset, or its initial state. Only the non-zero blocks are stored, so its
/// size and the cost of `JᵀJ` grow with the residuals, not with residuals × groups. A dense
/// Jacobian is the case `width = 0`.
#[derive(Debug, Clone)]
pub(crate) struct Jacobian {
    /// The shared parameters' columns, `residuals × shared`.
    pub shared: DMatrix<f64>,
    /// Each residual's derivatives by its own group's parameters, `residuals × width`.
    pub local: DMatrix<f64>,
    /// The group of each residual (empty when `width = 0`).
    pub group: Vec<usize>,
    /// Number of groups.
    pub groups: usize,
}

impl Jacobian {
    /// A dense `rows × cols` Jacobian (zeros).
    pub(crate) fn dense(rows: usize, cols: usize) -> Self {
        Self {
            shared: DMatrix::zeros(rows, cols),
            local: DMatrix::zeros(rows, 0),
            group: Vec::new(),
            groups: 0,
        }
    }

    /// A Jacobian (zeros) with `shared` shared columns and `width` local ones for each of
    /// `groups` groups; `group[i]` is residual `i`'s.
    pub(crate) fn blocked(
        rows: usize,
        shared: usize,
        width: usize,
        group: Vec<usize>,
        groups: usize,
    ) -> Self {
        debug_assert_eq!(group.len(), rows);
        debug_assert!(group.iter().all(|&g| g < groups));
        Self {
            shared: DMatrix::zeros(rows, shared),
            local: DMatrix::zeros(rows, width),
            group,
            groups,
        }
    }

    /// Residuals (rows).
    pub(crate) fn rows(&self) -> usize {
        self.shared.nrows()
    }

    /// Parameters (columns): the shared ones and every group's.
    pub(crate) fn cols(&self) -> usize {
        self.shared.ncols() + self.width() * self.groups
    }

    /// Local parameters per group.
    pub(crate) fn width(&self) -> usize {
        self.local.ncols()
    }

    /// Column of local parameter `k` of group `g`.
    pub(crate) fn local_column(&self, g: usize, k: usize) -> usize {
        self.shared.ncols() + g * self.width() + k
    }

    /// The dense Jacobian of a problem without local parameters.
    ///
    /// # Panics
    /// If it has local parameters.
    pub(crate) fn as_dense(&self) -> &DMatrix<f64> {
        assert_eq!(self.width(), 0, "a Jacobian with local parameters");
        &self.shared
    }

    /// `JᵀJ`, dense (`cols × cols`), each entry summed as nalgebra sums the dense
    /// Jacobian's (`Jᵀ·J` by [`Dot8`]), so the result is the dense product's, bit for bit.
    pub(crate) fn gram(&self) -> DMatrix<f64> {
        let m0 = self.shared.ncols();
        let w = self.width();
        if w == 0 {
            return self.shared.tr_mul(&self.shared);
        }
        let n = self.rows();
        let mut out = DMatrix::zeros(self.cols(), self.cols());
        out.view_mut((0, 0), (m0, m0))
            .copy_from(&self.shared.tr_mul(&self.shared));
        // Per group: (shared a, local k) at a·w + k, then (local k, local l) at m0·w + k·w + l.
        let per = (m0 + w) * w;
        let mut acc = vec![Dot8::default(); self.groups * per];
        let lanes = Dot8::lane_rows(n);
        for (i, &g) in self.group.iter().enumerate().take(lanes) {
            let acc = &mut acc[g * per..(g + 1) * per];
            for k in 0..w {
                let l = self.local[(i, k)];
                for a in 0..m0 {
                    acc[a * w + k].add(i, self.shared[(i, a)] * l);
                }
                for k2 in 0..w {
                    acc[m0 * w + k * w + k2].add(i, self.local[(i, k)] * self.local[(i, k2)]);
                }
            }
        }
        let mut values: Vec<f64> = acc.iter().map(Dot8::finish).collect();
        for i in lanes..n {
            let g = self.group[i];
            let v = &mut values[g * per..(g + 1) * per];
            for k in 0..w {
                let l = self.local[(i, k)];
                for a in 0..m0 {
                    v[a * w + k] += self.shared[(i, a)] * l;
                }
                for k2 in 0..w {
                    v[m0 * w + k * w + k2] += self.local[(i, k)] * self.local[(i, k2)];
                }
            }
        }
        for g in 0..self.groups {
            let v = &values[g * per..(g + 1) * per];
            for k in 0..w {
                let c = self.local_column(g, k);
                for a in 0..m0 {
                    out[(a, c)] = v[a * w + k];
                    out[(c, a)] = v[a * w + k];
                }
                for k2 in 0..w {
                    out[(self.local_column(g, k2), c)] = v[m0 * w + k * w + k2];
                }
            }
        }
        out
    }

    /// `Jᵀv`, summed as the dense product's (see [`Jacobian::gram`]).
    pub(crate) fn tr_mul(&self, v: &[f64]) -> DVector<f64> {
        let top = self.shared.tr_mul(&DVector::from_column_slice(v));
        let w = self.width();
        if w == 0 {
            return top;
        }
        let m0 = self.shared.ncols();
        let n = self.rows();
        let mut acc = vec![Dot8::default(); self.groups * w];
        let lanes = Dot8::lane_rows(n);
        for (i, &g) in self.group.iter().enumerate().take(lanes) {
            for k in 0..w {
                acc[g * w + k].add(i, self.local[(i, k)] * v[i]);
            }
        }
        let mut out = DVector::zeros(self.cols());
        out.rows_mut(0, m0).copy_from(&top);
        for (x, a) in acc.iter().enumerate() {
            out[m0 + x] = a.finish();
        }
        for i in lanes..n {
            for k in 0..w {
                out[m0 + self.group[i] * w + k] += self.local[(i, k)] * v[i];
            }
        }
        out
    }
}

/// A dot product `Σ xᵢ·yᵢ` over `n` rows summed as nalgebra's `dot` sums it, so that a sum
/// over some of the rows (the others being zero) equals the dense one bit for bit: eight
/// running sums by row index mod 8 over the first [`Dot8::lane_rows`] rows, combined
/// (`0 + (s₀+s₄) + (s₁+s₅) + (s₂+s₆) + (s₃+s₇)`), then the last rows added in order.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Dot8 {
    lanes: [f64; 8],
}

impl Dot8 {
    /// Rows summed in lanes out of `n` (the rest are added after [`Dot8::finish`], in order).
    pub(crate) fn lane_rows(n: usize) -> usize {
        n - n % 8
    }

    /// Adds the product of row `i` (below [`Dot8::lane_rows`]).
    #[inline(always)]
    pub(crate) fn add(&mut self, i: usize, product: f64) {
        self.lanes[i & 7] += product;
    }

    /// The lanes combined.
    pub(crate) fn finish(&self) -> f64 {
        let l = &self.lanes;
        let mut res = 0.0;
        res += l[0] + l[4];
        res += l[1] + l[5];
        res += l[2] + l[6];
        res += l[3] + l[7];
        res
    }
}

/// A least-squares problem: minimise `½·Σ rᵢ(p)²`.
pub(crate) trait Problem {
    /// Number of residuals.
    fn residual_count(&self) -> usize;
    /// Number of parameters.
    fn parameter_count(&self) -> usize;
    /// Residuals `r(p)` (model − data, weighted) into `r`.
    fn residuals(&self, p: &[f64], r: &mut [f64]);
    /// Jacobian `∂rᵢ/∂pⱼ` into `j` (shaped by [`Problem::new_jacobian`]), given the
    /// residuals `r = r(p)` already computed (a difference quotient needs not rerun them).
    fn jacobian(&self, p: &[f64], r: &[f64], j: &mut Jacobian);
    /// A Jacobian of the problem's shape: dense unless the problem has local parameters.
    fn new_jacobian(&self) -> Jacobian {
        Jacobian::dense(self.residual_count(), self.parameter_count())
    }
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
    /// The statistical stop ([`Stop::Statistical`]): stop when the Gauss–Newton model of the
    /// cost, over the parameters not held at a bound, predicts a decrease below this many
    /// units of the residual variance `s² = SSR/(n − p)`. The predicted decrease over `s²`
    /// is the squared length of the remaining step in standard errors (`δᵀJᵀJδ/s²`), so
    /// `10⁻⁶` stops when the optimum is within a thousandth of a standard error of every
    /// parameter and of every combination of them. 0 turns the rule off.
    pub statistical_tolerance: f64,
}

/// [`LmSettings::statistical_tolerance`] by default: the remaining step within 10⁻³ of a
/// standard error (computed as if the residuals were independent; serially correlated
/// residuals have larger errors, which makes the rule stricter, not looser). Far below what
/// any reported figure resolves (the estimates are printed with their errors to two or three
/// digits), and far above rounding: the search's cost is then within `10⁻⁶·s²` of its
/// minimum, `10⁻⁶/(n − p)` of the cost, where the old rule (a step gaining less than
/// [`LmSettings::cost_tolerance`] of the cost, `10⁻¹⁴`) let a search crawl along a flat valley
/// for hundreds of iterations gaining `10⁻¹²` of the cost each.
pub(crate) const STATISTICAL_TOLERANCE: f64 = 1e-6;

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            cost_tolerance: 1e-14,
            step_tolerance: 1e-12,
            statistical_tolerance: STATISTICAL_TOLERANCE,
        }
    }
}

/// Why a minimisation stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// An accepted step changed every parameter, or the cost, by less than the tolerances of
    /// [`LmSettings`] (or the cost reached zero).
    Tolerance,
    /// The Gauss–Newton model predicts a decrease of the cost below
    /// [`LmSettings::statistical_tolerance`] of the residual variance: what is left to gain is
    /// statistically nothing (a flat valley's remaining crawl included).
    Statistical,
    /// No step along the free parameters lowers the cost (every damping tried), or every
    /// parameter is held on its bound: a (possibly constrained) minimum.
    NoDescent,
    /// The iteration limit ended the run.
    IterationLimit,
}

/// Result of a minimisation.
#[derive(Debug, Clone)]
pub(crate) struct LmResult {
    /// Parameters at the optimum.
    pub params: Vec<f64>,
    /// Sum of squared residuals at the optimum.
    pub ssr: f64,
    /// Jacobian at the optimum.
    pub jacobian: Jacobian,
    /// Residuals at the optimum.
    pub residuals: Vec<f64>,
    /// Outer iterations done.
    pub iterations: usize,
    /// Whether a stopping rule (not the iteration limit) ended the run.
    pub converged: bool,
    /// Which rule ended the run.
    pub stop: Stop,
    /// The parameters held on a bound at the optimum: on it, with the cost's gradient
    /// pushing outward (the active set of [`minimize`]).
    pub held: Vec<bool>,
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

/// The parameters on a bound whose gradient `g = Jᵀr` pushes outward (a step down the cost
/// would leave the box): the active set, held where they are for the step.
fn active_set(p: &[f64], g: &DVector<f64>, lower: &[f64], upper: &[f64]) -> Vec<bool> {
    (0..p.len())
        .map(|i| (p[i] <= lower[i] && g[i] > 0.0) || (p[i] >= upper[i] && g[i] < 0.0))
        .collect()
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
    /// cost, and takes it. Returns why it stopped when a stopping rule says the minimum is
    /// reached.
    ///
    /// Bounds by an active set: a parameter on its bound whose gradient pushes outward is
    /// held, and the step is solved in the others (the damped normal equations restricted to
    /// them); the trial point is then projected onto the box. Projecting a step solved in
    /// every parameter instead (the step's held component cut off after the solve) leaves
    /// the others where the cut-off component would have taken them: along a valley that
    /// runs into the bound, such a search crawls, gaining a little each iteration, to its
    /// iteration limit.
    fn iterate<P: Problem>(
        &mut self,
        problem: &P,
        jac: &Jacobian,
        settings: &LmSettings,
    ) -> Option<Stop> {
        let m = self.p.len();
        let jtj = jac.gram();
        let g = jac.tr_mul(&self.r);
        let held = active_set(&self.p, &g, self.lower, self.upper);
        let free: Vec<usize> = (0..m).filter(|&i| !held[i]).collect();
        if free.is_empty() {
            return Some(Stop::NoDescent);
        }
        let k = free.len();
        let a0 = DMatrix::from_fn(k, k, |x, y| jtj[(free[x], free[y])]);
        let gf = DVector::from_fn(k, |x, _| g[free[x]]);
        let max_diag = a0.diagonal().max();
        let diag: Vec<f64> = (0..k)
            .map(|x| a0[(x, x)].max(1e-300 + 1e-12 * max_diag))
            .collect();
        if settings.statistical_tolerance > 0.0 {
            // The Gauss–Newton decrease gᵀ(JᵀJ)⁻¹g of the cost Σr² over the free parameters,
            // against the residual variance.
            let n = jac.rows();
            let s2 = self.cost / (n as f64 - m as f64).max(1.0);
            if let Some(chol) = a0.clone().cholesky() {
                let predicted = gf.dot(&chol.solve(&gf));
                if predicted.is_finite()
                    && predicted >= 0.0
                    && predicted <= settings.statistical_tolerance * s2
                {
                    return Some(Stop::Statistical);
                }
            }
        }
        loop {
            let mut a = a0.clone();
            for (x, d) in diag.iter().enumerate() {
                a[(x, x)] += self.lambda * d;
            }
            let Some(chol) = a.cholesky() else {
                self.lambda *= 10.0;
                if self.lambda > 1e20 {
                    return Some(Stop::NoDescent);
                }
                continue;
            };
            let step = chol.solve(&(-&gf));
            self.trial.copy_from_slice(&self.p);
            for (x, &i) in free.iter().enumerate() {
                self.trial[i] = self.p[i] + step[x];
            }
            project(&mut self.trial, self.lower, self.upper);
            problem.residuals(&self.trial, &mut self.trial_r);
            let trial_cost = sum_sq(&self.trial_r);
            if trial_cost.is_finite() && trial_cost <= self.cost {
                let mut full_diag = vec![f64::INFINITY; m];
                for (x, &i) in free.iter().enumerate() {
                    full_diag[i] = diag[x];
                }
                return self.accept(trial_cost, &full_diag, settings);
            }
            self.lambda *= 10.0;
            if self.lambda > 1e20 {
                // No descent direction left: a (possibly constrained) minimum.
                return Some(Stop::NoDescent);
            }
        }
    }

    /// Takes the trial point; [`Stop::Tolerance`] if the step or the gain was below
    /// tolerance.
    fn accept(&mut self, trial_cost: f64, diag: &[f64], settings: &LmSettings) -> Option<Stop> {
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
        (small_step || small_gain || self.cost == 0.0).then_some(Stop::Tolerance)
    }
}

/// Minimises `problem` from `start`, keeping `lower ≤ p ≤ upper`: parameters on a bound
/// with the gradient pushing outward are held for the step (an active set), and every trial
/// point is projected onto the box. Stops by the rules of [`LmSettings`] ([`Stop`]).
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
    let mut jac = problem.new_jacobian();
    debug_assert_eq!((jac.rows(), jac.cols()), (n, m));
    let mut iterations = 0;
    let mut stop = Stop::IterationLimit;
    while iterations < settings.max_iterations {
        iterations += 1;
        problem.jacobian(&search.p, &search.r, &mut jac);
        if let Some(why) = search.iterate(problem, &jac, &settings) {
            stop = why;
            break;
        }
    }
    problem.jacobian(&search.p, &search.r, &mut jac);
    let held = active_set(&search.p, &jac.tr_mul(&search.r), lower, upper);
    LmResult {
        params: search.p,
        ssr: search.cost,
        jacobian: jac,
        residuals: search.r,
        iterations,
        converged: stop != Stop::IterationLimit,
        stop,
        held,
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
    /// The covariance matrix of the parameters (its diagonal is `std_errors²`); rows and
    /// columns of singular parameters are NaN.
    pub matrix: DMatrix<f64>,
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
    let mut matrix = DMatrix::from_element(m, m, f64::NAN);
    let live: Vec<usize> = (0..m).filter(|&i| d[i] > 0.0 && d[i].is_finite()).collect();
    // A parameter the residuals do not depend on at all is singular from the start.
    let mut singular: Vec<bool> = (0..m).map(|i| !live.contains(&i)).collect();
    if live.is_empty() {
        return Covariance {
            std_errors,
            singular,
            condition: f64::INFINITY,
            dof,
            matrix,
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
            for (b, &j) in live.iter().enumerate() {
                if !singular[j] {
                    matrix[(i, j)] = l * s2 * inv[(a, b)] / (d[i] * d[j]);
                }
            }
        }
    }
    Covariance {
        std_errors,
        singular,
        condition,
        dof,
        matrix,
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
        fn jacobian(&self, p: &[f64], _r: &[f64], j: &mut Jacobian) {
            for (i, x) in self.x.iter().enumerate() {
                let e = (-p[1] * x).exp();
                j.shared[(i, 0)] = e;
                j.shared[(i, 1)] = -p[0] * x * e;
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

    /// A blocked Jacobian's `JᵀJ` and `Jᵀr` are the dense product's, bit for bit, whatever
    /// the number of rows modulo 8 and however the groups' rows fall.
    #[test]
    fn a_blocked_jacobians_normal_equations_are_the_dense_products_bit_for_bit() {
        let mut x = 0x1234_5678_9abc_def0_u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for rows in [5, 8, 61, 203] {
            let groups = 3;
            let group: Vec<usize> = (0..rows).map(|i| (i * groups) / rows).collect();
            let mut j = Jacobian::blocked(rows, 3, 2, group.clone(), groups);
            j.shared = DMatrix::from_fn(rows, 3, |_, _| next() * 1e3);
            j.local = DMatrix::from_fn(rows, 2, |_, _| next());
            let r: Vec<f64> = (0..rows).map(|_| next()).collect();
            let dense = DMatrix::from_fn(rows, j.cols(), |i, c| {
                if c < 3 {
                    j.shared[(i, c)]
                } else {
                    let (g, k) = ((c - 3) / 2, (c - 3) % 2);
                    if group[i] == g {
                        j.local[(i, k)]
                    } else {
                        0.0
                    }
                }
            });
            assert_eq!(j.gram(), dense.tr_mul(&dense), "{rows} rows");
            assert_eq!(
                j.tr_mul(&r),
                dense.tr_mul(&DVector::from_column_slice(&r)),
                "{rows} rows"
            );
        }
    }

    /// Residuals of a valley plus `noise` residuals that do not depend on the parameters
    /// (a fit's unexplained part: they set the residual variance `s² ≈ 1` and no gradient).
    struct Valley {
        /// Weight of the direction along the valley's floor.
        along: f64,
        noise: usize,
    }

    impl Problem for Valley {
        fn residual_count(&self) -> usize {
            2 + self.noise
        }
        fn parameter_count(&self) -> usize {
            2
        }
        /// Rosenbrock's valley `p1 = p0²`, its floor falling towards `p0 = 1` with weight
        /// `along`.
        fn residuals(&self, p: &[f64], r: &mut [f64]) {
            r[0] = 10.0 * (p[1] - p[0] * p[0]);
            r[1] = self.along * (1.0 - p[0]);
            for (k, x) in r[2..].iter_mut().enumerate() {
                *x = if k % 2 == 0 { 1.0 } else { -1.0 };
            }
        }
        fn jacobian(&self, p: &[f64], _r: &[f64], j: &mut Jacobian) {
            j.shared.fill(0.0);
            j.shared[(0, 0)] = -20.0 * p[0];
            j.shared[(0, 1)] = 10.0;
            j.shared[(1, 0)] = -self.along;
        }
    }

    /// The valley runs into the bound `p0 ≤ 0.5` with the cost still falling beyond it: `p0`
    /// is held there (the active set) and the search ends in a few iterations at the
    /// constrained optimum `(0.5, 0.25)`, `p0` reported held. `p1` within 10⁻⁴: a thousandth
    /// of its standard error (`s ≈ 1`, `∂r/∂p1 = 10`), what the statistical stop leaves.
    #[test]
    fn a_parameter_pinned_at_its_bound_is_held_and_the_search_stops_at_once() {
        let prob = Valley {
            along: 1.0,
            noise: 1000,
        };
        for start in [[0.2, 0.5], [0.5, 1.0], [0.5, 0.0]] {
            let fit = minimize(
                &prob,
                &start,
                &[-2.0, -2.0],
                &[0.5, 2.0],
                LmSettings::default(),
            );
            assert!(fit.converged, "{fit:?}");
            assert!(fit.iterations <= 5, "{} iterations", fit.iterations);
            assert_eq!(fit.params[0], 0.5);
            assert!((fit.params[1] - 0.25).abs() < 1e-4, "{:?}", fit.params);
            assert_eq!(fit.held, vec![true, false]);
        }
    }

    /// Along the valley's floor the cost changes by at most `along²·(1 − p0)² ≈ 4·10⁻⁷`, below
    /// a millionth of the residual variance (`s² = 10/8`): `p0` is not determined. The
    /// statistical stop ends the search once it is on the floor (3 iterations), where the old
    /// rules (a step gaining less than 10⁻¹⁴ of the cost) let it crawl along the floor to its
    /// iteration limit (200).
    #[test]
    fn a_search_along_a_statistically_flat_valley_stops_with_a_verdict() {
        let prob = Valley {
            along: 3e-4,
            noise: 10,
        };
        let (lower, upper) = ([-5.0, -5.0], [5.0, 5.0]);
        let fit = minimize(&prob, &[-1.2, 1.0], &lower, &upper, LmSettings::default());
        assert_eq!(fit.stop, Stop::Statistical, "{fit:?}");
        assert!(fit.iterations <= 5, "{} iterations", fit.iterations);
        // On the floor: the off-valley residual within a thousandth of the noise's scale.
        assert!((10.0 * (fit.params[1] - fit.params[0].powi(2))).abs() < 1e-3);
        let old = LmSettings {
            statistical_tolerance: 0.0,
            ..LmSettings::default()
        };
        let crawl = minimize(&prob, &[-1.2, 1.0], &lower, &upper, old);
        assert_eq!(crawl.stop, Stop::IterationLimit, "{crawl:?}");
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
