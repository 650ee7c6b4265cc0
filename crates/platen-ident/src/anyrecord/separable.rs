//! The equation-error fit by separable least squares (variable projection, Golub & Pereyra
//! 1973, with Kaufman's 1975 Jacobian):
//!
//! `F = Mₑ·a + Kₑ·u + sign(v)·[F_μ + Cₑ|v|^α + a·e^(−b|v|)] + c_r`
//!
//! is linear in `θ = (Mₑ, Kₑ, F_μ, Cₑ, a, c_1…c_R)` (one offset per record) for fixed
//! `(α, b)`. For each `(α, b)` the linear parameters are solved exactly, so the search is over
//! two numbers only: a grid over `α ∈ {0.1…1}` and `b ∈ {2.5…5120} s/m` (doubling) for the
//! start, then Levenberg–Marquardt on the projected residual `r(α, b) = −P⊥(α, b)·F`.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::lm::{self, Jacobian, LmSettings, Problem};

use super::data::Stacked;

/// Index of each parameter in the full vector `[Mₑ, Kₑ, F_μ, Cₑ, α, a, b, c_1…c_R]`.
pub(crate) const MASS: usize = 0;
pub(crate) const STIFFNESS: usize = 1;
pub(crate) const COULOMB: usize = 2;
pub(crate) const VISCOUS: usize = 3;
pub(crate) const EXPONENT: usize = 4;
pub(crate) const LOW_FORCE: usize = 5;
pub(crate) const LOW_DECAY: usize = 6;
/// Index of the first offset.
pub(crate) const OFFSETS: usize = 7;

/// Bounds of the nonlinear parameters: `α ∈ [0, 1]` (the model's range), `b ∈ [0.1, 10⁴]`
/// s/m (at `b → 0` the term is a second Coulomb force, at `b > 10⁴` it dies within 0.1 mm/s,
/// below any speed a fit can use).
const ALPHA_BOUNDS: [f64; 2] = [0.0, 1.0];
const DECAY_BOUNDS: [f64; 2] = [0.1, 1e4];

/// Which parameters are fitted.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shape {
    /// `α` held at this value, or fitted.
    pub alpha: Option<f64>,
    /// Whether the low-velocity term is fitted (else `a = b = 0`).
    pub low: bool,
    /// Number of records (offsets).
    pub records: usize,
    /// Whether `Kₑ ≥ 0` is imposed.
    pub nonneg_stiffness: bool,
}

impl Shape {
    /// Full-vector indices of the linear parameters, in the order of the design's columns.
    pub(crate) fn linear(&self) -> Vec<usize> {
        let mut v = vec![MASS, STIFFNESS, COULOMB, VISCOUS];
        if self.low {
            v.push(LOW_FORCE);
        }
        v.extend((0..self.records).map(|r| OFFSETS + r));
        v
    }

    /// Full-vector indices of the nonlinear parameters searched.
    pub(crate) fn nonlinear(&self) -> Vec<usize> {
        let mut v = Vec::new();
        if self.alpha.is_none() {
            v.push(EXPONENT);
        }
        if self.low {
            v.push(LOW_DECAY);
        }
        v
    }

    /// Every fitted parameter, in full-vector order.
    pub(crate) fn free(&self) -> Vec<usize> {
        let mut v = self.linear();
        v.extend(self.nonlinear());
        v.sort_unstable();
        v
    }

    pub(crate) fn full_len(&self) -> usize {
        OFFSETS + self.records
    }
}

/// `(α, b)` from the searched vector.
fn alpha_b(shape: &Shape, q: &[f64]) -> (f64, f64) {
    let mut k = 0;
    let alpha = match shape.alpha {
        Some(a) => a,
        None => {
            k += 1;
            q[0]
        }
    };
    let b = if shape.low { q[k] } else { 0.0 };
    (alpha, b)
}

/// The value of column `full` (a linear parameter's index) at sample `i`.
#[inline]
fn column(data: &Stacked, full: usize, i: usize, alpha: f64, b: f64) -> f64 {
    match full {
        MASS => data.a[i],
        STIFFNESS => data.u[i],
        COULOMB => data.s[i],
        VISCOUS => data.s[i] * (alpha * data.ln_w[i]).exp(),
        LOW_FORCE => data.s[i] * (-b * data.w[i]).exp(),
        r => {
            if data.record[i] == r - OFFSETS {
                1.0
            } else {
                0.0
            }
        }
    }
}

/// A least-squares solve of the normal equations `G·θ = Xᵀy` with `θ_k ≥ 0` for the
/// columns marked non-negative (`F_μ`, `Cₑ`, `a`: a friction law with a negative term has no
/// physical meaning, and without the bound the three columns `1`, `|v|^α`, `e^(−b|v|)` can
/// nearly cancel at small `α` and `b`, which fits noise with huge opposite terms). Every
/// subset of the bounded columns held at zero is tried (at most 8) and the feasible solve
/// with the least residual kept. Each solve is scaled to unit diagonal and drops singular
/// directions (collinear columns).
struct Solve {
    theta: Vec<f64>,
    /// Pseudo-inverse of `G` restricted to the columns not held at zero (zero elsewhere).
    g_inv: DMatrix<f64>,
    /// Sum of squared residuals.
    ssr: f64,
    /// Columns held at their bound (zero).
    clamped: Vec<bool>,
}

fn pseudo_inverse(g: &DMatrix<f64>, keep: &[bool]) -> DMatrix<f64> {
    let idx: Vec<usize> = (0..g.nrows()).filter(|&i| keep[i]).collect();
    let p = idx.len();
    let d: Vec<f64> = idx
        .iter()
        .map(|&i| {
            let x = g[(i, i)].sqrt();
            if x > 0.0 && x.is_finite() {
                x
            } else {
                1.0
            }
        })
        .collect();
    let scaled = DMatrix::from_fn(p, p, |a, b| g[(idx[a], idx[b])] / (d[a] * d[b]));
    let mut out = DMatrix::zeros(g.nrows(), g.nrows());
    if p == 0 {
        return out;
    }
    let eig = SymmetricEigen::new(scaled);
    let max_ev = eig.eigenvalues.max();
    let mut inv = DMatrix::zeros(p, p);
    for e in 0..p {
        let ev = eig.eigenvalues[e];
        if ev > 1e-12 * max_ev {
            let v = eig.eigenvectors.column(e);
            inv += (v * v.transpose()) / ev;
        }
    }
    for a in 0..p {
        for b in 0..p {
            out[(idx[a], idx[b])] = inv[(a, b)] / (d[a] * d[b]);
        }
    }
    out
}

fn solve_normal(g: &DMatrix<f64>, xty: &DVector<f64>, yy: f64, nonneg: &[bool]) -> Solve {
    let p = g.nrows();
    let bounded: Vec<usize> = (0..p).filter(|&i| nonneg[i]).collect();
    let mut best: Option<Solve> = None;
    for mask in 0..(1usize << bounded.len()) {
        let mut keep = vec![true; p];
        for (bit, &i) in bounded.iter().enumerate() {
            if mask & (1 << bit) != 0 {
                keep[i] = false;
            }
        }
        let g_inv = pseudo_inverse(g, &keep);
        let th = &g_inv * xty;
        if bounded.iter().any(|&i| keep[i] && th[i] < 0.0) {
            continue;
        }
        let ssr = (yy - 2.0 * th.dot(xty) + th.dot(&(g * &th))).max(0.0);
        if best.as_ref().is_none_or(|b| ssr < b.ssr) {
            best = Some(Solve {
                theta: th.iter().copied().collect(),
                g_inv,
                ssr,
                clamped: keep.iter().map(|k| !k).collect(),
            });
        }
        if mask == 0 && best.is_some() {
            // The unconstrained solve is feasible: it is the optimum.
            break;
        }
    }
    best.expect("holding every bounded column at zero is always feasible")
}

/// The Gram matrix of the columns that do not depend on `(α, b)`, computed once.
struct FixedGram {
    /// Full indices of the fixed columns: Mₑ, Kₑ, F_μ, offsets.
    cols: Vec<usize>,
    g: DMatrix<f64>,
    xty: Vec<f64>,
}

impl FixedGram {
    fn new(data: &Stacked, shape: &Shape) -> Self {
        let mut cols = vec![MASS, STIFFNESS, COULOMB];
        cols.extend((0..shape.records).map(|r| OFFSETS + r));
        let k = cols.len();
        let mut g = DMatrix::zeros(k, k);
        let mut xty = vec![0.0; k];
        let mut row = vec![0.0; k];
        for i in 0..data.len() {
            for (c, &full) in cols.iter().enumerate() {
                row[c] = column(data, full, i, 0.0, 0.0);
            }
            for a in 0..k {
                if row[a] == 0.0 {
                    continue;
                }
                xty[a] += row[a] * data.f[i];
                for b in 0..k {
                    g[(a, b)] += row[a] * row[b];
                }
            }
        }
        // Corrected least squares: the sensors' noise is not motion.
        g[(0, 0)] -= data.noise_sums[0];
        g[(1, 1)] -= data.noise_sums[1];
        Self { cols, g, xty }
    }
}

/// The equation-error problem: the stacked samples and which parameters are fitted.
pub(crate) struct Separable<'a> {
    data: &'a Stacked,
    shape: Shape,
    fixed: FixedGram,
    /// `Σ F²`.
    yy: f64,
}

impl<'a> Separable<'a> {
    pub(crate) fn new(data: &'a Stacked, shape: Shape) -> Self {
        let fixed = FixedGram::new(data, &shape);
        let yy = data.f.iter().map(|f| f * f).sum();
        Self {
            data,
            shape,
            fixed,
            yy,
        }
    }

    /// The linear parameters at `(α, b)` (in [`Shape::linear`] order) and the sum of squared
    /// residuals, from Gram sums: the nonlinear columns' products are the only per-call work.
    fn linear_at(&self, alpha: f64, b: f64) -> (Vec<f64>, f64) {
        let data = self.data;
        let k = self.fixed.cols.len();
        let r_off = 3; // offsets start at fixed column 3
        let mut gc = vec![0.0; k];
        let mut ge = vec![0.0; k];
        let (mut cc, mut ee, mut ce, mut cy, mut ey) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..data.len() {
            let s = data.s[i];
            let c = s * (alpha * data.ln_w[i]).exp();
            let e = if self.shape.low {
                s * (-b * data.w[i]).exp()
            } else {
                0.0
            };
            let base = [data.a[i], data.u[i], s];
            for j in 0..3 {
                gc[j] += c * base[j];
                ge[j] += e * base[j];
            }
            let r = r_off + data.record[i];
            gc[r] += c;
            ge[r] += e;
            cc += c * c;
            ee += e * e;
            ce += c * e;
            cy += c * data.f[i];
            ey += e * data.f[i];
        }
        // Assemble in Shape::linear order: Mₑ, Kₑ, F_μ, Cₑ, [a], offsets.
        let lin = self.shape.linear();
        let p = lin.len();
        let pos =
            |full: usize| -> Option<usize> { self.fixed.cols.iter().position(|&c| c == full) };
        let entry = |x: usize, y: usize| -> f64 {
            match (x, y) {
                (VISCOUS, VISCOUS) => cc,
                (LOW_FORCE, LOW_FORCE) => ee,
                (VISCOUS, LOW_FORCE) | (LOW_FORCE, VISCOUS) => ce,
                (VISCOUS, o) | (o, VISCOUS) => gc[pos(o).expect("fixed column")],
                (LOW_FORCE, o) | (o, LOW_FORCE) => ge[pos(o).expect("fixed column")],
                (o1, o2) => {
                    self.fixed.g[(
                        pos(o1).expect("fixed column"),
                        pos(o2).expect("fixed column"),
                    )]
                }
            }
        };
        let g = DMatrix::from_fn(p, p, |i, j| entry(lin[i], lin[j]));
        let xty = DVector::from_fn(p, |i, _| match lin[i] {
            VISCOUS => cy,
            LOW_FORCE => ey,
            o => self.fixed.xty[pos(o).expect("fixed column")],
        });
        let sol = solve_normal(&g, &xty, self.yy, &self.nonneg());
        (sol.theta, sol.ssr)
    }

    /// The design matrix at `(α, b)` (columns in [`Shape::linear`] order).
    fn design(&self, alpha: f64, b: f64) -> DMatrix<f64> {
        let lin = self.shape.linear();
        DMatrix::from_fn(self.data.len(), lin.len(), |i, c| {
            column(self.data, lin[c], i, alpha, b)
        })
    }

    fn solve_design(&self, x: &DMatrix<f64>) -> Solve {
        let mut g = x.tr_mul(x);
        // Columns 0 and 1 are Mₑ and Kₑ (Shape::linear): corrected as in FixedGram.
        g[(0, 0)] -= self.data.noise_sums[0];
        g[(1, 1)] -= self.data.noise_sums[1];
        let xty = x.tr_mul(&DVector::from_column_slice(&self.data.f));
        solve_normal(&g, &xty, self.yy, &self.nonneg())
    }

    /// Which linear parameters are bounded below by zero ([`Shape::linear`] order).
    fn nonneg(&self) -> Vec<bool> {
        self.shape
            .linear()
            .iter()
            .map(|&i| {
                matches!(i, COULOMB | VISCOUS | LOW_FORCE)
                    || (i == STIFFNESS && self.shape.nonneg_stiffness)
            })
            .collect()
    }

    /// The start of the search: the best node of the grid.
    fn grid_start(&self) -> Vec<f64> {
        let alphas: Vec<f64> = match self.shape.alpha {
            Some(a) => vec![a],
            None => (1..=10).map(|k| 0.1 * f64::from(k)).collect(),
        };
        let decays: Vec<f64> = if self.shape.low {
            (0..12).map(|k| 2.5 * 2f64.powi(k)).collect()
        } else {
            vec![0.0]
        };
        let mut best = (f64::INFINITY, alphas[0], decays[0]);
        for &a in &alphas {
            for &b in &decays {
                let (_, ssr) = self.linear_at(a, b);
                if ssr < best.0 {
                    best = (ssr, a, b);
                }
            }
        }
        let mut q = Vec::new();
        if self.shape.alpha.is_none() {
            q.push(best.1);
        }
        if self.shape.low {
            q.push(best.2);
        }
        q
    }

    /// Runs the fit: grid, then Levenberg–Marquardt on `(α, b)`.
    pub(crate) fn fit(&self) -> SeparableFit {
        let start = self.grid_start();
        let nonlinear = self.shape.nonlinear();
        let lower: Vec<f64> = nonlinear
            .iter()
            .map(|&i| {
                if i == EXPONENT {
                    ALPHA_BOUNDS[0]
                } else {
                    DECAY_BOUNDS[0]
                }
            })
            .collect();
        let upper: Vec<f64> = nonlinear
            .iter()
            .map(|&i| {
                if i == EXPONENT {
                    ALPHA_BOUNDS[1]
                } else {
                    DECAY_BOUNDS[1]
                }
            })
            .collect();
        let (q, iterations, converged) = if nonlinear.is_empty() {
            (Vec::new(), 0, true)
        } else {
            let res = lm::minimize(self, &start, &lower, &upper, LmSettings::default());
            (res.params, res.iterations, res.converged)
        };
        let (alpha, b) = alpha_b(&self.shape, &q);
        let x = self.design(alpha, b);
        let sol = self.solve_design(&x);
        let mut full = vec![0.0; self.shape.full_len()];
        full[EXPONENT] = alpha;
        full[LOW_DECAY] = b;
        for (c, &i) in self.shape.linear().iter().enumerate() {
            full[i] = sol.theta[c];
        }
        let residual: Vec<f64> = (&x * DVector::from_column_slice(&sol.theta))
            .iter()
            .zip(&self.data.f)
            .map(|(m, f)| m - f)
            .collect();
        let at_bound = nonlinear
            .iter()
            .zip(&q)
            .zip(lower.iter().zip(&upper))
            .filter(|((_, &v), (&lo, &hi))| v <= lo || v >= hi)
            .map(|((&i, _), _)| i)
            .collect();
        let lin = self.shape.linear();
        let clamped: Vec<usize> = lin
            .iter()
            .zip(&sol.clamped)
            .filter(|(_, &c)| c)
            .map(|(&i, _)| i)
            .collect();
        let free: Vec<usize> = self
            .shape
            .free()
            .into_iter()
            .filter(|i| !clamped.contains(i))
            .collect();
        SeparableFit {
            jacobian: self.full_jacobian(&full, &free),
            free,
            clamped,
            full,
            residual,
            iterations,
            converged,
            at_bound,
        }
    }

    /// `∂r/∂θ` for the parameters `free` (full-vector indices) at `full`.
    fn full_jacobian(&self, full: &[f64], free: &[usize]) -> Jacobian {
        let (alpha, b) = (full[EXPONENT], full[LOW_DECAY]);
        let d = self.data;
        let mut j = Jacobian::dense(d.len(), free.len());
        j.shared = DMatrix::from_fn(d.len(), free.len(), |i, c| match free[c] {
            EXPONENT => full[VISCOUS] * d.s[i] * (alpha * d.ln_w[i]).exp() * d.ln_w[i],
            LOW_DECAY => -full[LOW_FORCE] * d.s[i] * d.w[i] * (-b * d.w[i]).exp(),
            other => column(d, other, i, alpha, b),
        });
        j
    }
}

impl Problem for Separable<'_> {
    fn residual_count(&self) -> usize {
        self.data.len()
    }
    fn parameter_count(&self) -> usize {
        self.shape.nonlinear().len()
    }
    fn residuals(&self, q: &[f64], r: &mut [f64]) {
        let (alpha, b) = alpha_b(&self.shape, q);
        let x = self.design(alpha, b);
        let sol = self.solve_design(&x);
        let model = &x * DVector::from_column_slice(&sol.theta);
        for ((r, m), f) in r.iter_mut().zip(model.iter()).zip(&self.data.f) {
            *r = m - f;
        }
    }
    /// Kaufman's Jacobian: `∂r/∂q_k ≈ P⊥·(∂X/∂q_k)·θ̂`.
    fn jacobian(&self, q: &[f64], _r: &[f64], j: &mut Jacobian) {
        let j = &mut j.shared;
        let (alpha, b) = alpha_b(&self.shape, q);
        let x = self.design(alpha, b);
        let sol = self.solve_design(&x);
        let lin = self.shape.linear();
        let theta = |full: usize| sol.theta[lin.iter().position(|&c| c == full).unwrap_or(0)];
        let d = self.data;
        for (k, &which) in self.shape.nonlinear().iter().enumerate() {
            let dx: DVector<f64> = DVector::from_fn(d.len(), |i, _| match which {
                EXPONENT => theta(VISCOUS) * d.s[i] * (alpha * d.ln_w[i]).exp() * d.ln_w[i],
                _ => -theta(LOW_FORCE) * d.s[i] * d.w[i] * (-b * d.w[i]).exp(),
            });
            let proj = &x * (&sol.g_inv * x.tr_mul(&dx));
            for i in 0..d.len() {
                j[(i, k)] = dx[i] - proj[i];
            }
        }
    }
}

/// What the separable fit found.
#[derive(Debug, Clone)]
pub(crate) struct SeparableFit {
    /// `[Mₑ, Kₑ, F_μ, Cₑ, α, a, b, c_1…c_R]` (held parameters at their held values).
    pub full: Vec<f64>,
    /// Residuals (model − data) of the stacked samples.
    pub residual: Vec<f64>,
    /// `∂r/∂θ` of the parameters `free` at the optimum.
    pub jacobian: Jacobian,
    /// The fitted parameters not held at a bound ([`Shape::free`] less `clamped`).
    pub free: Vec<usize>,
    /// Linear parameters held at zero by their bound (full-vector indices).
    pub clamped: Vec<usize>,
    /// Levenberg–Marquardt iterations over `(α, b)`.
    pub iterations: usize,
    /// Whether the search met its tolerance.
    pub converged: bool,
    /// Nonlinear parameters that ended on a bound (full-vector indices).
    pub at_bound: Vec<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact equation-error data of a known law: the fit returns it to rounding, whatever the
    /// start grid's nearest node.
    #[test]
    fn exact_data_give_back_every_parameter() {
        let truth = [118e3, 0.95e6, 32e3, 61e3, 0.68, 9e3, 55.0, 3e3];
        let mut d = Stacked::default();
        for i in 0..4000 {
            let t = i as f64 / 200.0;
            let u = 0.05 * (1.3 * t).sin() + 0.01 * (7.1 * t).cos();
            let v = 0.065 * (1.3 * t).cos() - 0.071 * (7.1 * t).sin();
            let a = -0.0845 * (1.3 * t).sin() - 0.5041 * (7.1 * t).cos();
            if v.abs() < 1e-3 {
                continue;
            }
            let w = v.abs();
            let f = truth[0] * a
                + truth[1] * u
                + v.signum()
                    * (truth[2] + truth[3] * w.powf(truth[4]) + truth[5] * (-truth[6] * w).exp())
                + truth[7];
            d.a.push(a);
            d.u.push(u);
            d.s.push(v.signum());
            d.w.push(w);
            d.ln_w.push(w.ln());
            d.f.push(f);
            d.record.push(0);
            d.time.push(i);
        }
        let fit = Separable::new(
            &d,
            Shape {
                alpha: None,
                low: true,
                records: 1,
                nonneg_stiffness: false,
            },
        )
        .fit();
        for (k, (&got, &want)) in fit.full.iter().zip(&truth).enumerate() {
            assert!(
                (got / want - 1.0).abs() < 1e-6,
                "parameter {k}: {got} vs {want}"
            );
        }
    }
}
