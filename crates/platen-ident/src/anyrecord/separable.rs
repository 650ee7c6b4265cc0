//! The equation-error fit by separable least squares (variable projection, Golub & Pereyra
//! 1973, with Kaufman's 1975 Jacobian):
//!
//! `F = Mₑ·a + Kₑ·u + sign(v)·[F_μ + Cₑ|v|^α + a·e^(−b|v|)] + c_r`
//!
//! is linear in `θ = (Mₑ, Kₑ, F_μ, Cₑ, a, c_1…c_R)` (one offset per record) for fixed
//! `(α, b)`. For each `(α, b)` the linear parameters are solved exactly, so the search is over
//! two numbers only: a grid over `α ∈ {0.1…1}` and `b ∈ {2.5…5120} s/m` (doubling) for the
//! start, then Levenberg–Marquardt on the projected residual `r(α, b) = −P⊥(α, b)·F`.
//!
//! **Cost.** Nothing of size samples × parameters is formed. An offset's column is the
//! indicator of its record's samples, so the normal equations are an arrowhead: the model's
//! columns (at most five), dense, bordered by one diagonal entry per record.
//!
//! * The start grid's nodes work from sums formed record by record ([`Block`](super::data::Block)), once per
//!   record and grid (kept with the block, so a refit that changes one record, the
//!   channel-skew variance of module `skew`, forms them for that record only), and solve the
//!   arrowhead by eliminating the offsets (a Schur complement); where that reduced system is
//!   near singular, the dense pseudo-inverse of the whole system decides. Only the best
//!   node is used from the grid.
//! * The search's evaluations and the final solve sum the normal equations in one pass
//!   over the samples, exactly as the dense design's `XᵀX` and `Xᵀy` were summed
//!   ([`Dot8`]), and solve the whole system as before: the fit is the dense formulation's,
//!   bit for bit, at `O(samples)` plus a `(5 + records)²` eigen-decomposition.

use std::cell::RefCell;
use std::rc::Rc;

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::lm::{self, Dot8, Jacobian, LmSettings, Problem};

use super::data::{FixedSums, GridSums, NodeSums, Stacked};
use super::settings::ValidRecordSettings;

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
pub(crate) const ALPHA_BOUNDS: [f64; 2] = [0.0, 1.0];
pub(crate) const DECAY_BOUNDS: [f64; 2] = [0.1, 1e4];

/// The reduced (offsets eliminated) system, scaled by the whole system's diagonal, is solved
/// directly when its smallest eigenvalue exceeds this times the number of columns. Then the
/// whole scaled system's eigenvalues are all above ~10⁻⁹ of its largest, far above the
/// pseudo-inverse's singular threshold (10⁻¹²), so both give the same solution: the whole
/// system `[[Â, B̂], [B̂ᵀ, I]] = L·diag(S, I)·Lᵀ` with `L = [[I, B̂], [0, I]]`,
/// `‖B̂‖² ≤ λ_max(Â) ≤ 5`, has `λ_min ≥ λ_min(S)/(1 + √5)²` and `λ_max ≤` its trace.
const SCHUR_MIN_EIGENVALUE: f64 = 1e-8;

/// Singular directions of the whole system's pseudo-inverse: scaled eigenvalues below this
/// fraction of the largest.
const PSEUDO_INVERSE_SINGULAR: f64 = 1e-12;

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
    /// What `settings` fit on `records` records.
    pub(crate) fn of(settings: &ValidRecordSettings, records: usize) -> Self {
        Shape {
            alpha: settings.viscous_exponent,
            low: settings.low_velocity_term,
            records,
            nonneg_stiffness: settings.nonnegative_stiffness,
        }
    }

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

    /// Which linear parameters are bounded below by zero ([`Shape::linear`] order, the
    /// model's columns only: offsets are free).
    pub(crate) fn nonneg(&self) -> Vec<bool> {
        self.linear()
            .iter()
            .filter(|&&i| i < OFFSETS)
            .map(|&i| {
                matches!(i, COULOMB | VISCOUS | LOW_FORCE)
                    || (i == STIFFNESS && self.nonneg_stiffness)
            })
            .collect()
    }
}

/// `(α, b)` from the searched vector.
pub(crate) fn alpha_b(shape: &Shape, q: &[f64]) -> (f64, f64) {
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

/// The normal equations `G·θ = Xᵀy` of the linear parameters at one `(α, b)` in their
/// arrowhead shape: the model's columns (Mₑ, Kₑ, F_μ, Cₑ and, with the low-velocity term,
/// a: [`Shape::linear`] order), dense, and one offset per record, whose columns are
/// indicators of disjoint sets of samples. `G` holds the noise correction.
pub(crate) struct Normal {
    /// `G` among the model's columns, `k × k`.
    a: DMatrix<f64>,
    /// `G` between the model's columns and each offset, `k × R`.
    b: DMatrix<f64>,
    /// `G` of each offset with itself: its record's samples.
    d: Vec<f64>,
    /// `Xᵀy` of the model's columns.
    xm: Vec<f64>,
    /// `Xᵀy` of the offsets.
    xo: Vec<f64>,
    /// `yᵀy`.
    yy: f64,
}

impl Normal {
    /// From each block's sums, in record order.
    pub(crate) fn new<'a>(
        parts: impl ExactSizeIterator<Item = (&'a FixedSums, NodeSums)>,
        low: bool,
        noise_sums: [f64; 2],
    ) -> Self {
        let k = if low { 5 } else { 4 };
        let records = parts.len();
        let mut n = Normal {
            a: DMatrix::zeros(k, k),
            b: DMatrix::zeros(k, records),
            d: vec![0.0; records],
            xm: vec![0.0; k],
            xo: vec![0.0; records],
            yy: 0.0,
        };
        for (r, (fx, node)) in parts.enumerate() {
            let (c, e) = (&node.c, &node.e);
            for j in 0..3 {
                for l in 0..3 {
                    n.a[(j, l)] += fx.xx[j][l];
                }
                n.a[(3, j)] += c.zx[j];
                n.b[(j, r)] = fx.x[j];
                n.xm[j] += fx.xy[j];
            }
            n.a[(3, 3)] += c.zz;
            n.b[(3, r)] = c.z;
            n.xm[3] += c.zy;
            if low {
                for j in 0..3 {
                    n.a[(4, j)] += e.zx[j];
                }
                n.a[(4, 3)] += node.ce;
                n.a[(4, 4)] += e.zz;
                n.b[(4, r)] = e.z;
                n.xm[4] += e.zy;
            }
            n.d[r] = fx.n;
            n.xo[r] = fx.y;
            n.yy += fx.yy;
        }
        for j in 0..k {
            for l in j + 1..k {
                n.a[(j, l)] = n.a[(l, j)];
            }
        }
        // Corrected least squares: the sensors' noise is not motion.
        n.a[(0, 0)] -= noise_sums[0];
        n.a[(1, 1)] -= noise_sums[1];
        n
    }

    fn model_columns(&self) -> usize {
        self.a.nrows()
    }

    /// The whole `G` (model's columns, then the offsets).
    fn dense(&self) -> DMatrix<f64> {
        let (k, r) = (self.model_columns(), self.d.len());
        let mut g = DMatrix::zeros(k + r, k + r);
        g.view_mut((0, 0), (k, k)).copy_from(&self.a);
        g.view_mut((0, k), (k, r)).copy_from(&self.b);
        g.view_mut((k, 0), (r, k)).copy_from(&self.b.transpose());
        for (i, &d) in self.d.iter().enumerate() {
            g[(k + i, k + i)] = d;
        }
        g
    }

    fn xty(&self) -> DVector<f64> {
        DVector::from_iterator(
            self.xm.len() + self.xo.len(),
            self.xm.iter().chain(&self.xo).copied(),
        )
    }
}

/// How [`Solve::apply`] applies the inverse of the normal equations (restricted to the
/// columns not held at zero).
enum Inverse {
    /// The offsets eliminated: the inverse of the reduced system of the kept model columns
    /// `keep` (model indices), with the border `b` and diagonal `d` of the offsets.
    Schur {
        keep: Vec<usize>,
        reduced_inv: DMatrix<f64>,
        b: DMatrix<f64>,
        d: Vec<f64>,
    },
    /// The dense pseudo-inverse of the whole system (zero in the clamped columns).
    Dense(DMatrix<f64>),
}

/// A least-squares solve of the normal equations `G·θ = Xᵀy` with `θ_k ≥ 0` for the
/// columns marked non-negative (`F_μ`, `Cₑ`, `a`: a friction law with a negative term has no
/// physical meaning, and without the bound the three columns `1`, `|v|^α`, `e^(−b|v|)` can
/// nearly cancel at small `α` and `b`, which fits noise with huge opposite terms). Every
/// subset of the bounded columns held at zero is tried (at most 8) and the feasible solve
/// with the least residual kept. Each solve is scaled to unit diagonal and drops singular
/// directions (collinear columns).
pub(crate) struct Solve {
    /// In [`Shape::linear`] order.
    pub theta: Vec<f64>,
    /// Sum of squared residuals.
    pub ssr: f64,
    /// Columns held at their bound (zero).
    pub clamped: Vec<bool>,
    inverse: Inverse,
}

impl Inverse {
    /// `G⁺·v` for `v` in [`Shape::linear`] order, zero in the clamped columns.
    fn apply(&self, v: &[f64]) -> Vec<f64> {
        match self {
            Inverse::Dense(g_inv) => (g_inv * DVector::from_column_slice(v))
                .iter()
                .copied()
                .collect(),
            Inverse::Schur {
                keep,
                reduced_inv,
                b,
                d,
            } => {
                let k = b.nrows();
                let (vm, vo) = v.split_at(k);
                let rhs = DVector::from_iterator(
                    keep.len(),
                    keep.iter().map(|&i| {
                        vm[i] - (0..d.len()).map(|r| b[(i, r)] * vo[r] / d[r]).sum::<f64>()
                    }),
                );
                let zk = reduced_inv * rhs;
                let mut z = vec![0.0; v.len()];
                for (x, &i) in keep.iter().enumerate() {
                    z[i] = zk[x];
                }
                for r in 0..d.len() {
                    let mut t = vo[r];
                    for (x, &i) in keep.iter().enumerate() {
                        t -= b[(i, r)] * zk[x];
                    }
                    z[k + r] = t / d[r];
                }
                z
            }
        }
    }
}

impl Solve {
    /// `G⁺·v` for `v` in [`Shape::linear`] order, zero in the clamped columns.
    pub(crate) fn apply(&self, v: &[f64]) -> Vec<f64> {
        self.inverse.apply(v)
    }
}

/// The solve with the model columns `keep` (the offsets always kept) by eliminating the
/// offsets, or `None` when the reduced system is too near singular to be sure the
/// pseudo-inverse of the whole system would keep every direction
/// ([`SCHUR_MIN_EIGENVALUE`]), or a record has no samples.
fn schur(n: &Normal, keep: &[bool]) -> Option<(Vec<f64>, Inverse)> {
    let (k, records) = (n.model_columns(), n.d.len());
    let idx: Vec<usize> = (0..k).filter(|&i| keep[i]).collect();
    let p = idx.len();
    if p == 0 || n.d.iter().any(|&d| d <= 0.0) {
        return None;
    }
    // Scaled by the whole system's diagonal, as its pseudo-inverse is.
    let scale: Vec<f64> = idx.iter().map(|&i| n.a[(i, i)].sqrt()).collect();
    if scale.iter().any(|&x| !(x > 0.0 && x.is_finite())) {
        return None;
    }
    let reduced = DMatrix::from_fn(p, p, |x, y| {
        let (i, j) = (idx[x], idx[y]);
        let border: f64 = (0..records)
            .map(|r| n.b[(i, r)] * n.b[(j, r)] / n.d[r])
            .sum();
        (n.a[(i, j)] - border) / (scale[x] * scale[y])
    });
    let eig = SymmetricEigen::new(reduced);
    let smallest = eig.eigenvalues.min();
    if smallest.is_nan() || smallest <= SCHUR_MIN_EIGENVALUE * (p + records) as f64 {
        return None;
    }
    let mut inv = DMatrix::zeros(p, p);
    for e in 0..p {
        let v = eig.eigenvectors.column(e);
        inv += (v * v.transpose()) / eig.eigenvalues[e];
    }
    let reduced_inv = DMatrix::from_fn(p, p, |x, y| inv[(x, y)] / (scale[x] * scale[y]));
    let inverse = Inverse::Schur {
        keep: idx,
        reduced_inv,
        b: n.b.clone(),
        d: n.d.clone(),
    };
    let xty: Vec<f64> = n.xm.iter().chain(&n.xo).copied().collect();
    let theta = inverse.apply(&xty);
    Some((theta, inverse))
}

/// `θᵀ·G·θ` of the arrowhead.
fn quadratic_form(n: &Normal, theta: &[f64]) -> f64 {
    let k = n.model_columns();
    let (tm, to) = theta.split_at(k);
    let mut q = 0.0;
    for i in 0..k {
        for j in 0..k {
            q += tm[i] * n.a[(i, j)] * tm[j];
        }
    }
    for (r, &d) in n.d.iter().enumerate() {
        let border: f64 = (0..k).map(|i| tm[i] * n.b[(i, r)]).sum();
        q += 2.0 * border * to[r] + d * to[r] * to[r];
    }
    q
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
        if ev > PSEUDO_INVERSE_SINGULAR * max_ev {
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

/// The old dense solve of the whole system `g·θ = xty` (every column's pseudo-inverse
/// scaled to unit diagonal), `nonneg` marking the bounded columns of all of it.
fn solve_dense(g: &DMatrix<f64>, xty: &DVector<f64>, yy: f64, nonneg: &[bool]) -> Solve {
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
                ssr,
                clamped: keep.iter().map(|k| !k).collect(),
                inverse: Inverse::Dense(g_inv),
            });
        }
        if mask == 0 && best.is_some() {
            // The unconstrained solve is feasible: it is the optimum.
            break;
        }
    }
    best.expect("holding every bounded column at zero is always feasible")
}

/// The solve of the arrowhead, the offsets eliminated ([`schur`]); where that is not sure
/// to agree with the whole system's pseudo-inverse, [`solve_dense`] of the whole system.
/// `nonneg` marks the bounded model columns.
pub(crate) fn solve_normal(n: &Normal, nonneg: &[bool]) -> Solve {
    let k = n.model_columns();
    let records = n.d.len();
    let bounded: Vec<usize> = (0..k).filter(|&i| nonneg[i]).collect();
    let xty = n.xty();
    let mut best: Option<Solve> = None;
    for mask in 0..(1usize << bounded.len()) {
        let mut keep = vec![true; k];
        for (bit, &i) in bounded.iter().enumerate() {
            if mask & (1 << bit) != 0 {
                keep[i] = false;
            }
        }
        let Some((theta, inverse)) = schur(n, &keep) else {
            let mut nonneg_all = nonneg.to_vec();
            nonneg_all.extend(std::iter::repeat_n(false, records));
            return solve_dense(&n.dense(), &xty, n.yy, &nonneg_all);
        };
        if bounded.iter().any(|&i| keep[i] && theta[i] < 0.0) {
            continue;
        }
        let t = DVector::from_column_slice(&theta);
        let ssr = (n.yy - 2.0 * t.dot(&xty) + quadratic_form(n, &theta)).max(0.0);
        if best.as_ref().is_none_or(|b| ssr < b.ssr) {
            let mut clamped: Vec<bool> = keep.iter().map(|k| !k).collect();
            clamped.extend(std::iter::repeat_n(false, records));
            best = Some(Solve {
                theta,
                ssr,
                clamped,
                inverse,
            });
        }
        if mask == 0 && best.is_some() {
            break;
        }
    }
    best.expect("holding every bounded column at zero is always feasible")
}

/// The linear solve at one `(α, b)`, with the nonlinear columns `c = s·|v|^α` and
/// `e = s·e^(−b|v|)` of every sample (stacked order) for the residuals and the Jacobian.
struct Evaluation {
    alpha: f64,
    b: f64,
    solve: Solve,
    c: Vec<f64>,
    e: Vec<f64>,
}

/// The sums of [`Separable::lane_sums`]: the model columns `[a, u, s, c, e]` against each
/// other (`mm`, lower triangle), against each record's constant (`mo`) and against the force
/// (`xm`), each record's force sum (`xo`) and sample count, in lanes; the samples beyond the
/// lanes (`tail`: record, columns, force); every sample's `c` and `e`.
struct LaneSums {
    mm: Vec<Dot8>,
    mo: Vec<Dot8>,
    xm: Vec<Dot8>,
    xo: Vec<Dot8>,
    counts: Vec<f64>,
    tail: Vec<(usize, [f64; 5], f64)>,
    c: Vec<f64>,
    e: Vec<f64>,
}

impl LaneSums {
    /// `XᵀX` and `Xᵀy` of the `k` model columns and `records` constants, symmetric.
    fn normal_equations(&self, k: usize, records: usize) -> (DMatrix<f64>, DVector<f64>) {
        let mut g = DMatrix::zeros(k + records, k + records);
        let mut xty = DVector::zeros(k + records);
        for p in 0..k {
            for q in 0..=p {
                g[(p, q)] = self.mm[p * k + q].finish();
            }
            xty[p] = self.xm[p].finish();
        }
        for r in 0..records {
            for p in 0..k {
                g[(p, k + r)] = self.mo[r * k + p].finish();
            }
            g[(k + r, k + r)] = self.counts[r];
            xty[k + r] = self.xo[r].finish();
        }
        for &(r, x, f) in &self.tail {
            for p in 0..k {
                for q in 0..=p {
                    g[(p, q)] += x[p] * x[q];
                }
                g[(p, k + r)] += x[p];
                xty[p] += x[p] * f;
            }
            xty[k + r] += f;
        }
        for p in 0..k + records {
            for q in p + 1..k + records {
                if q < k {
                    g[(p, q)] = g[(q, p)];
                } else {
                    g[(q, p)] = g[(p, q)];
                }
            }
        }
        (g, xty)
    }
}

/// The equation-error problem: the stacked samples and which parameters are fitted.
pub(crate) struct Separable<'a> {
    data: &'a Stacked,
    shape: Shape,
    /// Each block's [`FixedSums`], in record order.
    fixed: Vec<FixedSums>,
    /// `Σ F²`.
    yy: f64,
    /// The last evaluation: Levenberg–Marquardt asks for the Jacobian where it has just
    /// computed the residuals.
    last: RefCell<Option<Rc<Evaluation>>>,
}

impl<'a> Separable<'a> {
    pub(crate) fn new(data: &'a Stacked, shape: Shape) -> Self {
        let fixed = data.blocks.iter().map(|b| FixedSums::cached(b)).collect();
        let yy = data
            .blocks
            .iter()
            .flat_map(|b| b.f.iter())
            .map(|f| f * f)
            .sum();
        Self {
            data,
            shape,
            fixed,
            yy,
            last: RefCell::new(None),
        }
    }

    fn normal(&self, nodes: impl ExactSizeIterator<Item = NodeSums>) -> Normal {
        Normal::new(
            self.fixed.iter().zip(nodes),
            self.shape.low,
            self.data.noise_sums,
        )
    }

    /// Model columns of the design: Mₑ, Kₑ, F_μ, Cₑ and, with the low-velocity term, a.
    fn model_columns(&self) -> usize {
        if self.shape.low {
            5
        } else {
            4
        }
    }

    /// The solve at `(α, b)` and the nonlinear columns: one pass over the samples. The
    /// normal equations are summed as the dense design's `XᵀX` and `Xᵀy` are ([`Dot8`] by
    /// the sample's row), and solved as the whole system always was, so the result is the
    /// dense formulation's, bit for bit, at `O(samples + records³)`.
    fn evaluate(&self, alpha: f64, b: f64) -> Rc<Evaluation> {
        if let Some(ev) = self.last.borrow().as_ref() {
            if ev.alpha.to_bits() == alpha.to_bits() && ev.b.to_bits() == b.to_bits() {
                return Rc::clone(ev);
            }
        }
        let k = self.model_columns();
        let records = self.data.blocks.len();
        let sums = self.lane_sums(alpha, b);
        let (mut g, xty) = sums.normal_equations(k, records);
        // Corrected least squares: the sensors' noise is not motion.
        g[(0, 0)] -= self.data.noise_sums[0];
        g[(1, 1)] -= self.data.noise_sums[1];
        let mut nonneg = self.nonneg();
        nonneg.extend(std::iter::repeat_n(false, records));
        let ev = Rc::new(Evaluation {
            alpha,
            b,
            solve: solve_dense(&g, &xty, self.yy, &nonneg),
            c: sums.c,
            e: sums.e,
        });
        *self.last.borrow_mut() = Some(Rc::clone(&ev));
        ev
    }

    /// The sums of the normal equations at `(α, b)` over every sample (the first
    /// [`Dot8::lane_rows`] in lanes, the rest apart), with each sample's `c` and `e`.
    fn lane_sums(&self, alpha: f64, b: f64) -> LaneSums {
        let k = self.model_columns();
        let records = self.data.blocks.len();
        let n = self.data.len();
        let lanes = Dot8::lane_rows(n);
        let mut sums = LaneSums {
            mm: vec![Dot8::default(); k * k],
            mo: vec![Dot8::default(); records * k],
            xm: vec![Dot8::default(); k],
            xo: vec![Dot8::default(); records],
            counts: vec![0.0; records],
            tail: Vec::new(),
            c: Vec::with_capacity(n),
            e: Vec::with_capacity(n),
        };
        let mut i = 0;
        for block in &self.data.blocks {
            let r = block.record;
            sums.counts[r] = block.len() as f64;
            for j in 0..block.len() {
                let s = block.s[j];
                let c = s * (alpha * block.ln_w[j]).exp();
                let e = if self.shape.low {
                    s * (-b * block.w[j]).exp()
                } else {
                    0.0
                };
                sums.c.push(c);
                sums.e.push(e);
                let x = [block.a[j], block.u[j], s, c, e];
                let f = block.f[j];
                if i < lanes {
                    for p in 0..k {
                        for q in 0..=p {
                            sums.mm[p * k + q].add(i, x[p] * x[q]);
                        }
                        sums.mo[r * k + p].add(i, x[p]);
                        sums.xm[p].add(i, x[p] * f);
                    }
                    sums.xo[r].add(i, f);
                } else {
                    sums.tail.push((r, x, f));
                }
                i += 1;
            }
        }
        sums
    }

    /// `X·z` at every sample for `z` in [`Shape::linear`] order (the design's columns in
    /// order: Mₑ, Kₑ, F_μ, Cₑ, [a], the sample's offset).
    fn design_times(&self, ev: &Evaluation, z: &[f64], out: &mut Vec<f64>) {
        let k = self.model_columns();
        out.clear();
        let mut at = 0;
        for block in &self.data.blocks {
            let offset = z[k + block.record];
            for i in 0..block.len() {
                let mut m = z[0] * block.a[i];
                m += z[1] * block.u[i];
                m += z[2] * block.s[i];
                m += z[3] * ev.c[at];
                if self.shape.low {
                    m += z[4] * ev.e[at];
                }
                m += offset;
                out.push(m);
                at += 1;
            }
        }
    }

    /// `Xᵀ·v` in [`Shape::linear`] order, summed as the dense design's ([`Dot8`]).
    fn design_tr_times(&self, ev: &Evaluation, v: &[f64]) -> Vec<f64> {
        let k = self.model_columns();
        let records = self.data.blocks.len();
        let lanes = Dot8::lane_rows(v.len());
        let mut model = vec![Dot8::default(); k];
        let mut offsets = vec![Dot8::default(); records];
        let mut tail = Vec::new();
        let mut at = 0;
        for block in &self.data.blocks {
            for i in 0..block.len() {
                let x = [block.a[i], block.u[i], block.s[i], ev.c[at], ev.e[at]];
                if at < lanes {
                    for p in 0..k {
                        model[p].add(at, x[p] * v[at]);
                    }
                    offsets[block.record].add(at, v[at]);
                } else {
                    tail.push((block.record, x, v[at]));
                }
                at += 1;
            }
        }
        let mut out: Vec<f64> = model.iter().chain(&offsets).map(Dot8::finish).collect();
        for (r, x, y) in tail {
            for p in 0..k {
                out[p] += x[p] * y;
            }
            out[k + r] += y;
        }
        out
    }

    fn nonneg(&self) -> Vec<bool> {
        self.shape.nonneg()
    }

    /// The start of the search: the best node of the grid.
    pub(crate) fn grid_start(&self) -> Vec<f64> {
        let alphas: Vec<f64> = match self.shape.alpha {
            Some(a) => vec![a],
            None => (1..=10).map(|k| 0.1 * f64::from(k)).collect(),
        };
        let decays: Vec<f64> = if self.shape.low {
            (0..12).map(|k| 2.5 * 2f64.powi(k)).collect()
        } else {
            vec![0.0]
        };
        let sums: Vec<Rc<GridSums>> = self
            .data
            .blocks
            .iter()
            .map(|b| GridSums::cached(b, &alphas, &decays, self.shape.low))
            .collect();
        let nonneg = self.nonneg();
        let mut best = (f64::INFINITY, alphas[0], decays[0]);
        for (ka, &a) in alphas.iter().enumerate() {
            for (kb, &b) in decays.iter().enumerate() {
                let normal = self.normal(sums.iter().map(|g| g.node(ka, kb)));
                let ssr = solve_normal(&normal, &nonneg).ssr;
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
        self.fit_from(&self.grid_start())
    }

    /// Levenberg–Marquardt on `(α, b)` from `start` (the searched parameters, in
    /// [`Shape::nonlinear`] order): a refit that starts from the joint fit's optimum.
    pub(crate) fn fit_from(&self, start: &[f64]) -> SeparableFit {
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
        let (q, iterations, stop, held) = if nonlinear.is_empty() {
            (Vec::new(), 0, lm::Stop::Tolerance, Vec::new())
        } else {
            let res = lm::minimize(self, start, &lower, &upper, LmSettings::default());
            let held = nonlinear
                .iter()
                .zip(&res.held)
                .filter(|(_, &h)| h)
                .map(|(&i, _)| i)
                .collect();
            (res.params, res.iterations, res.stop, held)
        };
        let (alpha, b) = alpha_b(&self.shape, &q);
        let ev = self.evaluate(alpha, b);
        let sol = &ev.solve;
        let mut full = vec![0.0; self.shape.full_len()];
        full[EXPONENT] = alpha;
        full[LOW_DECAY] = b;
        for (c, &i) in self.shape.linear().iter().enumerate() {
            full[i] = sol.theta[c];
        }
        let mut residual = Vec::new();
        self.residuals_at(&ev, &mut residual);
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
            jacobian: self.full_jacobian(&full, &free, &ev),
            free,
            clamped,
            full,
            residual,
            iterations,
            converged: stop != lm::Stop::IterationLimit,
            stop,
            at_bound,
            held,
        }
    }

    /// Residuals (model − data) of the solve `ev`.
    fn residuals_at(&self, ev: &Evaluation, r: &mut Vec<f64>) {
        self.design_times(ev, &ev.solve.theta, r);
        let f = self.data.blocks.iter().flat_map(|b| b.f.iter());
        for (r, f) in r.iter_mut().zip(f) {
            *r -= f;
        }
    }

    /// `∂r/∂θ` for the parameters `free` (full-vector indices: the model's, then every
    /// offset) at `full`: the model's columns shared by every sample, the offset's local to
    /// its record (a column of ones).
    fn full_jacobian(&self, full: &[f64], free: &[usize], ev: &Evaluation) -> Jacobian {
        let model: Vec<usize> = free.iter().copied().filter(|&i| i < OFFSETS).collect();
        debug_assert_eq!(free.len(), model.len() + self.data.blocks.len());
        let mut j = Jacobian::blocked(
            self.data.len(),
            model.len(),
            1,
            self.data.groups(),
            self.data.blocks.len(),
        );
        j.local.fill(1.0);
        let mut at = 0;
        for block in &self.data.blocks {
            for i in 0..block.len() {
                for (col, &which) in model.iter().enumerate() {
                    j.shared[(at, col)] = match which {
                        MASS => block.a[i],
                        STIFFNESS => block.u[i],
                        COULOMB => block.s[i],
                        VISCOUS => ev.c[at],
                        EXPONENT => full[VISCOUS] * ev.c[at] * block.ln_w[i],
                        LOW_FORCE => ev.e[at],
                        _ => -full[LOW_FORCE] * block.w[i] * ev.e[at],
                    };
                }
                at += 1;
            }
        }
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
        let ev = self.evaluate(alpha, b);
        let mut out = Vec::with_capacity(r.len());
        self.residuals_at(&ev, &mut out);
        r.copy_from_slice(&out);
    }
    /// Kaufman's Jacobian: `∂r/∂q_k ≈ P⊥·(∂X/∂q_k)·θ̂`.
    fn jacobian(&self, q: &[f64], _r: &[f64], j: &mut Jacobian) {
        let (alpha, b) = alpha_b(&self.shape, q);
        let ev = self.evaluate(alpha, b);
        let lin = self.shape.linear();
        let theta = |full: usize| ev.solve.theta[lin.iter().position(|&c| c == full).unwrap_or(0)];
        let mut dx = Vec::with_capacity(self.data.len());
        let mut proj = Vec::with_capacity(self.data.len());
        for (k, &which) in self.shape.nonlinear().iter().enumerate() {
            dx.clear();
            let mut at = 0;
            for block in &self.data.blocks {
                for i in 0..block.len() {
                    dx.push(match which {
                        EXPONENT => theta(VISCOUS) * ev.c[at] * block.ln_w[i],
                        _ => -theta(LOW_FORCE) * block.w[i] * ev.e[at],
                    });
                    at += 1;
                }
            }
            let z = ev.solve.apply(&self.design_tr_times(&ev, &dx));
            self.design_times(&ev, &z, &mut proj);
            for (i, (d, p)) in dx.iter().zip(&proj).enumerate() {
                j.shared[(i, k)] = d - p;
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
    /// `∂r/∂θ` of the parameters `free` at the optimum (the offsets local to their records).
    pub jacobian: Jacobian,
    /// The fitted parameters not held at a bound ([`Shape::free`] less `clamped`).
    pub free: Vec<usize>,
    /// Linear parameters held at zero by their bound (full-vector indices).
    pub clamped: Vec<usize>,
    /// Levenberg–Marquardt iterations over `(α, b)`.
    pub iterations: usize,
    /// Whether the search met its tolerance.
    pub converged: bool,
    /// Why the search stopped.
    pub stop: lm::Stop,
    /// Nonlinear parameters the search held on their bound at the end, the cost's gradient
    /// pushing outward (full-vector indices; a subset of `at_bound`).
    pub held: Vec<usize>,
    /// Nonlinear parameters that ended on a bound (full-vector indices).
    pub at_bound: Vec<usize>,
}

#[cfg(test)]
mod tests {
    use super::super::data::Block;
    use super::*;

    /// Exact equation-error data of a known law: the fit returns it to rounding, whatever the
    /// start grid's nearest node.
    #[test]
    fn exact_data_give_back_every_parameter() {
        let truth = [118e3, 0.95e6, 32e3, 61e3, 0.68, 9e3, 55.0, 3e3];
        let mut d = Block::default();
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
            d.time.push(i);
        }
        let data = Stacked::from_blocks(vec![Rc::new(d)]);
        let fit = Separable::new(
            &data,
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
