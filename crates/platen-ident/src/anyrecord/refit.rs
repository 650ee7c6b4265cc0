//! The channel-skew refits (module `skew`) without a joint search over every record each.
//!
//! The variance of an estimated delay enters through the central difference of the fitted
//! vector over the delay of one record, so each record with an estimated delay needs two
//! refits of the whole equation error with that record's channel shifted by `±h`. A refit by
//! the fit's own search (the start grid, then Levenberg–Marquardt over `(α, b)`) costs a pass
//! over every record's samples per evaluation, so the refits of `R` records cost `R` times
//! the data: the whole identification grew with the square of the records.
//!
//! A refit moves `(α, b)` little from the joint fit's `(α̂, b̂)` when the record is one of
//! several (on 34 small-table records a quarter-sample shift of one moves `b` by up to 10 %,
//! `α` by 0.01). So each record's sums are expanded once about `(α̂, b̂)`:
//! `Σ h·s·|v|^α = Σ_m (δα)^m/m!·Σ h·ĉ·(ln|v|)^m` with `ĉ = s·|v|^α̂`, and likewise in `b`
//! (the moments, [`Moments`], of order [`ORDER`]), and a refit evaluates the unchanged
//! records' sums from their moments (no pass over their samples) and the shifted record's
//! exactly. Each sum's truncation error is bounded a priori, from absolute moments, by
//! `|δ|^(K+1)/(K+1)!·e^(|δ|·max x)·Σ|gᵢ|·|xᵢ|^(K+1)` (`x = ln|v|` or `|v|`, `gᵢ` the term's
//! weight), and the expansion is used only where that is below [`TRUNCATION`] of `Σ|gᵢ|`:
//! below rounding.
//!
//! The refit's `(α, b)` is found by Newton's method on the gradient of the fitted cost
//! `C(α, b) = Σ rᵢ²` (the residuals of the linear solve at `(α, b)`, noise correction
//! included; the gradient is exact, from the sums, and the Hessian its central difference),
//! from `(α̂, b̂)`, to 10⁻¹⁰ of each parameter: the minimum the search approaches. The search
//! stops when a step gains less than 10⁻¹⁴ of the cost, which can leave it up to ~10⁻¹¹ of
//! the cost above that minimum along the flat α–b valley, so its refitted vector differs
//! from Newton's by up to ~10⁻³ of the shift the perturbation causes (`tests`), and the
//! channel-skew variance by about twice that fraction.
//!
//! Newton follows the fit's minimum as the record's channel moves; the search restarts from
//! its grid, whose best node often moves with the channel (the grid's cost is flat along the
//! valley), and could descend into another minimum, which would make the difference
//! quotient meaningless: the derivative of the estimate is that of the minimum it belongs
//! to. A nonlinear parameter the joint fit holds on its bound (the cost still falling
//! beyond it: `α` at 1 on records that barely fix it) is held there by the refits, and a
//! Newton step that would cross a bound takes its parameter to the bound and holds it: the
//! derivative is then the constrained estimator's, the one reported. Where the Newton
//! iteration cannot be used, [`Refits::refit`] says so and the caller refits by the search
//! from the joint fit's `(α, b)`: a Hessian that is not positive definite, a step leaving
//! the expansions' accuracy, a held parameter whose bound stops being active, no
//! convergence. (Before, a parameter on its bound sent every refit to the search from the
//! start grid: on 16 stand-ins for real records, α at 1, that was 32 searches of up to 200
//! iterations over every record.)
//!
//! Cost: the moments are one pass over the samples (about 800 products each); a refit is a
//! pass over the shifted record and about two thousand operations per other record per
//! evaluation, so the refits of `R` records cost a few passes over the data, not `R`. On 34
//! small-table records of 90 s: 2.0 s for the moments and the 68 refits, against 75 s by
//! the search (no refit fell back to it).

use nalgebra::{DMatrix, DVector};

use super::data::{Block, ColumnSums, FixedSums, NodeSums, Stacked};
use super::separable::{
    solve_normal, Normal, SeparableFit, Shape, ALPHA_BOUNDS, DECAY_BOUNDS, EXPONENT, LOW_DECAY,
};

/// Highest power of `δα` and `δb` kept in the expansions (total order for the cross sums).
pub(crate) const ORDER: usize = 24;

/// Moments stored per sum: powers `0 ..= ORDER + 1` (the derivative columns need one more).
const POWERS: usize = ORDER + 2;

/// The expansions are used where their truncation error is bounded by this fraction of the
/// sum of the terms' magnitudes (a direct sum's rounding error is `≥ 10⁻¹⁶` of it).
pub(crate) const TRUNCATION: f64 = 1e-17;

/// Newton iterations before giving up.
const MAX_ITERATIONS: usize = 30;

/// Newton stops when every step is below this fraction of its parameter (or of
/// [`PARAMETER_FLOOR`]).
const STEP_TOLERANCE: f64 = 1e-10;

/// Scale of a parameter near zero, for the tolerance and the difference step.
const PARAMETER_FLOOR: f64 = 1e-3;

/// Smallest fraction of a Newton step tried before giving up.
const MIN_STEP_FRACTION: f64 = 1.0 / 64.0;

/// Relative step of the Hessian's central difference.
const HESSIAN_STEP: f64 = 1e-6;

/// Sums of one block against a derivative column `x'` (`c·ln|v|` for `α`, `e·|v|` for `b`).
#[derive(Debug, Clone, Copy, Default)]
struct DerivativeSums {
    /// `Σ x'·a`, `Σ x'·u`, `Σ x'·s`.
    x: [f64; 3],
    /// `Σ x'`.
    one: f64,
    /// `Σ x'·c`.
    c: f64,
    /// `Σ x'·e`.
    e: f64,
    /// `Σ x'·y`.
    y: f64,
}

/// A block's sums at one `(α, b)`: the normal equations' and the derivative columns'.
#[derive(Debug, Clone, Copy, Default)]
struct PointSums {
    node: NodeSums,
    /// Against `c·ln|v|`.
    alpha: DerivativeSums,
    /// Against `e·|v|`.
    decay: DerivativeSums,
}

/// A block's sums at `(α, b)`, from its samples.
fn exact_sums(block: &Block, alpha: f64, b: f64, low: bool) -> PointSums {
    let mut p = PointSums::default();
    for i in 0..block.len() {
        let s = block.s[i];
        let c = s * (alpha * block.ln_w[i]).exp();
        let e = if low {
            s * (-b * block.w[i]).exp()
        } else {
            0.0
        };
        p.node.c.add(c, block, i);
        if low {
            p.node.e.add(e, block, i);
            p.node.ce += c * e;
        }
        let xa = c * block.ln_w[i];
        let xb = e * block.w[i];
        for (d, x) in [(&mut p.alpha, xa), (&mut p.decay, xb)] {
            d.x[0] += x * block.a[i];
            d.x[1] += x * block.u[i];
            d.x[2] += x * block.s[i];
            d.one += x;
            d.c += x * c;
            d.e += x * e;
            d.y += x * block.f[i];
        }
    }
    p
}

/// A block's moments about `(α̂, b̂)`: with `ĉ = s·|v|^α̂`, `ê = s·e^(−b̂|v|)`, `L = ln|v|`,
/// `W = |v|` and `h` one of `a, u, s, 1, F`: `Σ h·ĉ·Lᵐ`, `Σ h·ê·Wᵐ`, `Σ ĉ²·Lᵐ`, `Σ ê²·Wᵐ`
/// and `Σ ĉ·ê·Lʲ·Wˡ`.
#[derive(Debug, Clone)]
pub(crate) struct Moments {
    c: [[f64; POWERS]; 5],
    e: [[f64; POWERS]; 5],
    cc: [f64; POWERS],
    ee: [f64; POWERS],
    /// `[j][l]` for `j + l ≤ ORDER + 1`.
    ce: [[f64; POWERS]; POWERS],
    max_ln: f64,
    max_w: f64,
    /// For the truncation bounds, per sum and derivative shift (0 or 1): `Σ|g|·|x|^shift`
    /// and `Σ|g|·|x|^(shift + K + 1)`.
    c_bound: [[[f64; 2]; 2]; 5],
    e_bound: [[[f64; 2]; 2]; 5],
    cc_bound: [[f64; 2]; 2],
    ee_bound: [[f64; 2]; 2],
    /// Per shift `(0, 0)`, `(1, 0)`, `(0, 1)` (`|L|^j·W^l`): `Σ|ĉê|·|L|ʲWˡ`, then
    /// `Σ|ĉê|·|L|ʲWˡ·|L|ⁱ·W^(K+1−i)` for `i = 0 ..= K + 1`.
    ce_bound: [[f64; ORDER + 3]; 3],
}

impl Moments {
    /// The moments of `block` about `(alpha, b)` (the low-velocity term's sums with `low`).
    fn of(block: &Block, alpha: f64, b: f64, low: bool) -> Self {
        let mut m = Moments {
            c: [[0.0; POWERS]; 5],
            e: [[0.0; POWERS]; 5],
            cc: [0.0; POWERS],
            ee: [0.0; POWERS],
            ce: [[0.0; POWERS]; POWERS],
            max_ln: 0.0,
            max_w: 0.0,
            c_bound: [[[0.0; 2]; 2]; 5],
            e_bound: [[[0.0; 2]; 2]; 5],
            cc_bound: [[0.0; 2]; 2],
            ee_bound: [[0.0; 2]; 2],
            ce_bound: [[0.0; ORDER + 3]; 3],
        };
        for i in 0..block.len() {
            let (ln, w) = (block.ln_w[i], block.w[i]);
            m.max_ln = m.max_ln.max(ln.abs());
            m.max_w = m.max_w.max(w);
            let s = block.s[i];
            let c = s * (alpha * ln).exp();
            let h = [block.a[i], block.u[i], s, 1.0, block.f[i]];
            let p = Powers::of(ln, w);
            m.add_c(c, &h, &p);
            if low {
                let e = s * (-b * w).exp();
                m.add_e(e, c, &h, &p);
            }
        }
        m
    }

    /// One sample's `ĉ` terms (`c = ĉ`, `h` its `a, u, s, 1, F`): `Σ h·ĉ·Lᵐ`, `Σ ĉ²·Lᵐ` and
    /// their bounds.
    fn add_c(&mut self, c: f64, h: &[f64; 5], p: &Powers) {
        for (sums, &h) in self.c.iter_mut().zip(h) {
            let ch = c * h;
            for (x, &p) in sums.iter_mut().zip(&p.l) {
                *x += ch * p;
            }
        }
        for (x, &p) in self.cc.iter_mut().zip(&p.l) {
            *x += c * c * p;
        }
        let (al, lk) = (p.abs_ln, p.abs_l[POWERS - 1]);
        for (b, &h) in self.c_bound.iter_mut().zip(h) {
            add_bound(b, (c * h).abs(), al, lk);
        }
        add_bound(&mut self.cc_bound, c * c, al, lk);
    }

    /// One sample's `ê` terms (`e = ê`, with its `ĉ` = `c`): `Σ h·ê·Wᵐ`, `Σ ê²·Wᵐ`,
    /// `Σ ĉ·ê·Lʲ·Wˡ` and their bounds.
    fn add_e(&mut self, e: f64, c: f64, h: &[f64; 5], p: &Powers) {
        for (sums, &h) in self.e.iter_mut().zip(h) {
            let eh = e * h;
            for (x, &p) in sums.iter_mut().zip(&p.w) {
                *x += eh * p;
            }
        }
        for (x, &p) in self.ee.iter_mut().zip(&p.w) {
            *x += e * e * p;
        }
        let (al, aw, wk) = (p.abs_ln, p.abs_w, p.abs_w_pow[POWERS - 1]);
        for (b, &h) in self.e_bound.iter_mut().zip(h) {
            add_bound(b, (e * h).abs(), aw, wk);
        }
        add_bound(&mut self.ee_bound, e * e, aw, wk);
        let g = (c * e).abs();
        for (b, x) in self.ce_bound.iter_mut().zip([1.0, al, aw]) {
            b[0] += g * x;
            for i in 0..=ORDER + 1 {
                b[1 + i] += g * x * p.abs_l[i] * p.abs_w_pow[ORDER + 1 - i];
            }
        }
        let ce = c * e;
        for (j, (row, &lj)) in self.ce.iter_mut().zip(&p.l).enumerate() {
            let cej = ce * lj;
            for (x, &wl) in row.iter_mut().zip(&p.w).take(POWERS - j) {
                *x += cej * wl;
            }
        }
    }

    /// Whether every expansion's truncation error at `(δα, δb)` is below [`TRUNCATION`].
    fn within(&self, da: f64, db: f64, low: bool) -> bool {
        let fact: f64 = (1..=ORDER + 1).map(|k| k as f64).product();
        // |δ|^(K+1)/(K+1)!·e^(|δ|·max x).
        let factor =
            |d: f64, max: f64| d.abs().powi((ORDER + 1) as i32) / fact * (d.abs() * max).exp();
        let ok = |b: &[[f64; 2]; 2], f: f64| b.iter().all(|[a, t]| f * t <= TRUNCATION * a);
        let (fa, fa2) = (factor(da, self.max_ln), factor(2.0 * da, self.max_ln));
        if !(self.c_bound.iter().all(|b| ok(b, fa)) && ok(&self.cc_bound, fa2)) {
            return false;
        }
        if !low {
            return true;
        }
        let (fb, fb2) = (factor(db, self.max_w), factor(2.0 * db, self.max_w));
        // Σ|g|·(|δα|·|L| + |δb|·W)^(K+1) by the binomial theorem, times e^(|δα|·max|L| + |δb|·max W).
        let k1 = ORDER + 1;
        let both = (da.abs() * self.max_ln + db.abs() * self.max_w).exp() / fact;
        let cross = self.ce_bound.iter().all(|b| {
            let mut binomial = 1.0;
            let mut tail = 0.0;
            for i in 0..=k1 {
                tail +=
                    binomial * da.abs().powi(i as i32) * db.abs().powi((k1 - i) as i32) * b[1 + i];
                binomial = binomial * (k1 - i) as f64 / (i + 1) as f64;
            }
            both * tail <= TRUNCATION * b[0]
        });
        self.e_bound.iter().all(|b| ok(b, fb)) && ok(&self.ee_bound, fb2) && cross
    }

    /// The sums at `(α̂ + δα, b̂ + δb)`, or `None` where an expansion's truncation is not
    /// below rounding ([`Moments::within`]).
    fn at(&self, da: f64, db: f64, low: bool) -> Option<PointSums> {
        if !self.within(da, db, low) {
            return None;
        }
        let series = |x: f64| {
            let mut t = [0.0; ORDER + 1];
            t[0] = 1.0;
            for k in 1..=ORDER {
                t[k] = t[k - 1] * x / k as f64;
            }
            t
        };
        let (a1, a2) = (series(da), series(2.0 * da));
        let (b1, b2) = (series(-db), series(-2.0 * db));
        // Σ_k t_k·m[k + shift], smallest terms first.
        let sum = |t: &[f64; ORDER + 1], m: &[f64; POWERS], shift: usize| {
            (0..=ORDER).rev().map(|k| t[k] * m[k + shift]).sum::<f64>()
        };
        let cross = |j: usize, l: usize| {
            let mut acc = 0.0;
            for total in (0..=ORDER).rev() {
                for k in 0..=total {
                    acc += a1[k] * b1[total - k] * self.ce[k + j][total - k + l];
                }
            }
            acc
        };
        let mut p = PointSums::default();
        let column = |m: &[[f64; POWERS]; 5], t: &[f64; ORDER + 1], shift: usize| {
            let v: Vec<f64> = m.iter().map(|row| sum(t, row, shift)).collect();
            v
        };
        let c0 = column(&self.c, &a1, 0);
        let c1 = column(&self.c, &a1, 1);
        p.node.c = ColumnSums {
            zx: [c0[0], c0[1], c0[2]],
            z: c0[3],
            zz: sum(&a2, &self.cc, 0),
            zy: c0[4],
        };
        p.alpha = DerivativeSums {
            x: [c1[0], c1[1], c1[2]],
            one: c1[3],
            c: sum(&a2, &self.cc, 1),
            e: 0.0,
            y: c1[4],
        };
        if low {
            let e0 = column(&self.e, &b1, 0);
            let e1 = column(&self.e, &b1, 1);
            p.node.e = ColumnSums {
                zx: [e0[0], e0[1], e0[2]],
                z: e0[3],
                zz: sum(&b2, &self.ee, 0),
                zy: e0[4],
            };
            p.node.ce = cross(0, 0);
            p.alpha.e = cross(1, 0);
            p.decay = DerivativeSums {
                x: [e1[0], e1[1], e1[2]],
                one: e1[3],
                c: cross(0, 1),
                e: sum(&b2, &self.ee, 1),
                y: e1[4],
            };
        }
        Some(p)
    }
}

/// One sample's powers `0 ..= ORDER + 1` of `L = ln|v|`, `W = |v|`, `|L|` and `W` (again,
/// for the bounds).
struct Powers {
    l: [f64; POWERS],
    w: [f64; POWERS],
    abs_l: [f64; POWERS],
    abs_w_pow: [f64; POWERS],
    /// `|L|` and `W`.
    abs_ln: f64,
    abs_w: f64,
}

impl Powers {
    fn of(ln: f64, w: f64) -> Self {
        let mut p = Powers {
            l: [0.0; POWERS],
            w: [0.0; POWERS],
            abs_l: [0.0; POWERS],
            abs_w_pow: [0.0; POWERS],
            abs_ln: ln.abs(),
            abs_w: w,
        };
        p.l[0] = 1.0;
        p.w[0] = 1.0;
        p.abs_l[0] = 1.0;
        p.abs_w_pow[0] = 1.0;
        for k in 1..POWERS {
            p.l[k] = p.l[k - 1] * ln;
            p.w[k] = p.w[k - 1] * w;
            p.abs_l[k] = p.abs_l[k - 1] * ln.abs();
            p.abs_w_pow[k] = p.abs_w_pow[k - 1] * w;
        }
        p
    }
}

/// A term of weight `g` at `x` (`xk = |x|^(K+1)`) into a sum's bounds: `Σ|g|·|x|^shift` and
/// `Σ|g|·|x|^(shift + K + 1)` for the shifts 0 and 1.
fn add_bound(b: &mut [[f64; 2]; 2], g: f64, x: f64, xk: f64) {
    b[0][0] += g;
    b[0][1] += g * xk;
    b[1][0] += g * x;
    b[1][1] += g * x * xk;
}

/// How a refit's sums are formed: from the moments (the refits), or from the samples
/// (a reference for the tests).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sums {
    Expanded,
    #[cfg(test)]
    Exact,
}

/// What a refit found: the full vector and the fitted parameters, as [`SeparableFit`] has
/// them.
#[derive(Debug, Clone)]
pub(crate) struct Refit {
    pub full: Vec<f64>,
    pub free: Vec<usize>,
}

/// The joint fit's `(α̂, b̂)` and every record's moments about it.
pub(crate) struct Refits {
    shape: Shape,
    /// The nonlinear parameters the refits search (full-vector indices): the fitted ones
    /// not on a bound at the joint fit. Those on a bound are held there.
    searched: Vec<usize>,
    /// The nonlinear parameters held on their bound, with the sign the cost's gradient must
    /// keep for the bound to stay active (`+1` at a lower bound, `−1` at an upper one).
    held: Vec<(usize, f64)>,
    alpha: f64,
    b: f64,
    moments: Vec<Moments>,
    sums: Sums,
}

impl Refits {
    /// The expansions about `fit` over `data`. A nonlinear parameter of `fit` on its bound
    /// (the search held it there, the cost's gradient pushing outward) is held there by the
    /// refits too, and the others are searched from the joint fit: the estimates' derivative
    /// over a delay is then the constrained estimator's, which is the one reported, as long
    /// as the bound stays active ([`Refits::refit`] checks that it does).
    pub(crate) fn new(data: &Stacked, fit: &SeparableFit, shape: Shape, sums: Sums) -> Self {
        let (alpha, b) = (fit.full[EXPONENT], fit.full[LOW_DECAY]);
        let mut searched = Vec::new();
        let mut held = Vec::new();
        for i in shape.nonlinear() {
            let [lo, hi] = bounds(i);
            if fit.at_bound.contains(&i) {
                held.push((i, if fit.full[i] <= lo { 1.0 } else { -1.0 }));
            } else {
                debug_assert!(fit.full[i] > lo && fit.full[i] < hi);
                searched.push(i);
            }
        }
        let moments = data
            .blocks
            .iter()
            .map(|blk| Moments::of(blk, alpha, b, shape.low))
            .collect();
        Self {
            shape,
            searched,
            held,
            alpha,
            b,
            moments,
            sums,
        }
    }

    /// The refit of `data`, in which record `record`'s block differs from the joint fit's,
    /// or `None` where this method does not apply (see the module docs).
    ///
    /// Newton's method over the searched parameters with the held ones on their bounds; a
    /// Newton step that would take a searched parameter across its bound takes it to the
    /// bound and holds it there for the rest of the refit (the refit's minimum is then on
    /// the bound, as the search's would be). At the end every held parameter's bound must be
    /// active: the cost's gradient still pushing outward.
    pub(crate) fn refit(&self, data: &Stacked, record: usize) -> Option<Refit> {
        let mut searched = self.searched.clone();
        let mut held = self.held.clone();
        let mut ab = [self.alpha, if self.shape.low { self.b } else { 0.0 }];
        let mut point = self.point(data, record, ab, &searched, &held)?;
        let mut converged = searched.is_empty();
        for _ in 0..MAX_ITERATIONS {
            if converged {
                break;
            }
            let h = self.hessian(data, record, ab, &searched, &held)?;
            let step = h
                .cholesky()?
                .solve(&(-DVector::from_column_slice(&point.gradient)));
            // A full step across a bound: to the bound, the parameter held there from now on.
            if let Some((k, fraction, bound, sign)) = first_crossing(&searched, &step, ab) {
                let mut next = ab;
                for (&i, &d) in searched.iter().zip(&step) {
                    next[slot(i)] += fraction * d;
                }
                let i = searched.remove(k);
                next[slot(i)] = bound;
                held.push((i, sign));
                ab = next;
                point = self.point(data, record, ab, &searched, &held)?;
                converged = searched.is_empty();
                continue;
            }
            (ab, point, converged) =
                self.newton_step(data, record, ab, &step, (&searched, &held))?;
        }
        // A held parameter's bound must stay active: the cost still falls beyond it.
        if !converged
            || held
                .iter()
                .zip(&point.held_gradient)
                .any(|((_, sign), g)| sign * g < 0.0)
        {
            return None;
        }
        Some(self.refit_at(ab, &point))
    }

    /// The Hessian of the cost along the `searched` parameters at `ab`: the central
    /// difference of its gradient, symmetrised.
    fn hessian(
        &self,
        data: &Stacked,
        record: usize,
        ab: [f64; 2],
        searched: &[usize],
        held: &[(usize, f64)],
    ) -> Option<DMatrix<f64>> {
        let m = searched.len();
        let mut h = DMatrix::zeros(m, m);
        for (l, &il) in searched.iter().enumerate() {
            let step = HESSIAN_STEP * scale(ab[slot(il)]);
            let (mut abp, mut abm) = (ab, ab);
            abp[slot(il)] += step;
            abm[slot(il)] -= step;
            let (gp, gm) = (
                self.point(data, record, abp, searched, held)?.gradient,
                self.point(data, record, abm, searched, held)?.gradient,
            );
            for k in 0..m {
                h[(k, l)] = (gp[k] - gm[k]) / (2.0 * step);
            }
        }
        Some((&h + h.transpose()) * 0.5)
    }

    /// The Newton `step` from `ab` along the `searched` parameters, halved while it leaves
    /// the expansions' accuracy (`None` below [`MIN_STEP_FRACTION`]): the new `(α, b)`, its
    /// point, and whether the step was full and within [`STEP_TOLERANCE`] (converged).
    fn newton_step(
        &self,
        data: &Stacked,
        record: usize,
        ab: [f64; 2],
        step: &DVector<f64>,
        (searched, held): (&[usize], &[(usize, f64)]),
    ) -> Option<([f64; 2], Point, bool)> {
        let mut fraction = 1.0;
        loop {
            let mut next = ab;
            for (&i, &d) in searched.iter().zip(step) {
                next[slot(i)] += fraction * d;
            }
            if let Some(p) = self.point(data, record, next, searched, held) {
                let converged = fraction == 1.0
                    && searched
                        .iter()
                        .zip(step)
                        .all(|(&i, d)| d.abs() <= STEP_TOLERANCE * scale(ab[slot(i)]));
                return Some((next, p, converged));
            }
            fraction *= 0.5;
            if fraction < MIN_STEP_FRACTION {
                return None;
            }
        }
    }

    /// The refit at the converged `(α, b)` = `ab` and its `point`: the full vector and the
    /// fitted parameters (a linear one the solve clamps is not fitted).
    fn refit_at(&self, ab: [f64; 2], point: &Point) -> Refit {
        let mut full = vec![0.0; self.shape.full_len()];
        full[EXPONENT] = ab[0];
        full[LOW_DECAY] = ab[1];
        let linear = self.shape.linear();
        for (c, &i) in linear.iter().enumerate() {
            full[i] = point.theta[c];
        }
        let free = self
            .shape
            .free()
            .into_iter()
            .filter(|i| {
                linear
                    .iter()
                    .position(|x| x == i)
                    .is_none_or(|c| !point.clamped[c])
            })
            .collect();
        Refit { full, free }
    }

    /// The linear solve at `(α, b) = ab` and the cost's gradient along the `searched`
    /// parameters and the `held` ones.
    fn point(
        &self,
        data: &Stacked,
        record: usize,
        ab: [f64; 2],
        searched: &[usize],
        held: &[(usize, f64)],
    ) -> Option<Point> {
        let low = self.shape.low;
        let [alpha, b] = ab;
        let (da, db) = (alpha - self.alpha, b - self.b);
        let mut parts = Vec::with_capacity(data.blocks.len());
        for (r, blk) in data.blocks.iter().enumerate() {
            parts.push(if r == record || self.sums != Sums::Expanded {
                exact_sums(blk, alpha, b, low)
            } else {
                self.moments[r].at(da, db, low)?
            });
        }
        let fixed: Vec<FixedSums> = data.blocks.iter().map(|b| FixedSums::cached(b)).collect();
        let normal = Normal::new(
            fixed.iter().zip(parts.iter().map(|p| p.node)),
            low,
            data.noise_sums,
        );
        let sol = solve_normal(&normal, &self.shape.nonneg());
        let k = if low { 5 } else { 4 };
        let theta = &sol.theta;
        // Xᵀr = (XᵀX − G)·θ = N·θ on the solved columns: the noise correction.
        let mut n_theta = vec![0.0; theta.len()];
        n_theta[0] = data.noise_sums[0] * theta[0];
        n_theta[1] = data.noise_sums[1] * theta[1];
        let w = sol.apply(&n_theta);
        let mut gradient = Vec::new();
        let mut held_gradient = Vec::new();
        for which in searched.iter().chain(held.iter().map(|(i, _)| i)) {
            let which = *which;
            // The derivative column x' = ∂X_j/∂q (sign included) and its column j.
            let (j, sign) = if which == EXPONENT {
                (3, 1.0)
            } else {
                (4, -1.0)
            };
            let d = |p: &PointSums| if which == EXPONENT { p.alpha } else { p.decay };
            // S = Xᵀx' (model's columns, then each offset), Sy = yᵀx'.
            let mut s = vec![0.0; k + parts.len()];
            let mut sy = 0.0;
            for (r, p) in parts.iter().enumerate() {
                let d = d(p);
                let model = [d.x[0], d.x[1], d.x[2], d.c, d.e];
                for (x, &v) in s.iter_mut().zip(&model[..k]) {
                    *x += sign * v;
                }
                s[k + r] = sign * d.one;
                sy += sign * d.y;
            }
            // t = rᵀx' = θᵀS − Sy; ∂C/∂q = 2·[θ_j·t − (Nθ)ᵀ·G⁺·(t·e_j + θ_j·S)].
            let t = theta.iter().zip(&s).map(|(a, b)| a * b).sum::<f64>() - sy;
            let mut v: Vec<f64> = s.iter().map(|x| theta[j] * x).collect();
            v[j] += t;
            let wv: f64 = w.iter().zip(&v).map(|(a, b)| a * b).sum();
            let d = 2.0 * (theta[j] * t - wv);
            if gradient.len() < searched.len() {
                gradient.push(d);
            } else {
                held_gradient.push(d);
            }
        }
        Some(Point {
            theta: sol.theta.clone(),
            clamped: sol.clamped.clone(),
            gradient,
            held_gradient,
        })
    }
}

/// The bounds of nonlinear parameter `i` (full-vector index): `α`'s or `b`'s.
fn bounds(i: usize) -> [f64; 2] {
    if i == EXPONENT {
        ALPHA_BOUNDS
    } else {
        DECAY_BOUNDS
    }
}

/// Where nonlinear parameter `i` is in an `(α, b)` pair.
fn slot(i: usize) -> usize {
    usize::from(i != EXPONENT)
}

/// The scale of a parameter's value `q`, for the tolerance and the difference step.
fn scale(q: f64) -> f64 {
    q.abs().max(PARAMETER_FLOOR)
}

/// The first bound the full Newton `step` from `ab` crosses, if any: the searched
/// parameter's position in `searched`, the fraction of the step to the bound, the bound and
/// the sign the gradient must keep there (`+1` at a lower bound, `−1` at an upper one).
fn first_crossing(
    searched: &[usize],
    step: &DVector<f64>,
    ab: [f64; 2],
) -> Option<(usize, f64, f64, f64)> {
    searched
        .iter()
        .zip(step)
        .enumerate()
        .filter_map(|(k, (&i, &d))| {
            let [lo, hi] = bounds(i);
            let x = ab[slot(i)];
            if x + d >= hi {
                Some((k, (hi - x) / d, hi, -1.0))
            } else if x + d <= lo {
                Some((k, (lo - x) / d, lo, 1.0))
            } else {
                None
            }
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// The linear solve and the cost's gradient at one `(α, b)`.
struct Point {
    theta: Vec<f64>,
    clamped: Vec<bool>,
    /// Along the searched parameters (in the order given).
    gradient: Vec<f64>,
    /// Along the held ones (in the order given).
    held_gradient: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use std::rc::Rc;

    use super::*;
    use crate::anyrecord::separable::{Separable, COULOMB, MASS, STIFFNESS, VISCOUS};

    /// A deterministic uniform generator (xorshift) and Gaussian pairs (Box–Muller).
    struct Rng(u64);
    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn normal(&mut self) -> f64 {
            let (u1, u2) = (self.uniform(), self.uniform());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        }
    }

    /// Equation-error samples of record `record` of a table with a known law, sensor and
    /// force noise, and an offset of its own.
    fn block(record: usize, samples: usize, rng: &mut Rng) -> Block {
        block_with(record, samples, 0.68, rng)
    }

    /// [`block`] with the viscous exponent `exponent`.
    fn block_with(record: usize, samples: usize, exponent: f64, rng: &mut Rng) -> Block {
        let truth = [118e3, 0.95e6, 32e3, 61e3, exponent, 9e3, 55.0];
        let (f1, f2) = (0.9 + 0.3 * record as f64, 2.3 + 0.4 * record as f64);
        let mut b = Block {
            record,
            noise_var: [0.03f64.powi(2), 2e-5f64.powi(2)],
            ..Block::default()
        };
        for i in 0..samples {
            let t = i as f64 / 204.8;
            let (w1, w2) = (std::f64::consts::TAU * f1, std::f64::consts::TAU * f2);
            // A slow swing under a faster one: speeds from rest to ~0.4 m/s.
            let env = 0.2 + 0.8 * (0.05 * w1 * t).sin().abs();
            let u = 0.05 * env * (w1 * t).sin() + 0.004 * (w2 * t + 1.0).sin();
            let v = 0.05 * env * w1 * (w1 * t).cos() + 0.004 * w2 * (w2 * t + 1.0).cos();
            let a = -0.05 * env * w1 * w1 * (w1 * t).sin() - 0.004 * w2 * w2 * (w2 * t + 1.0).sin();
            if v.abs() < 2e-3 {
                continue;
            }
            let w = v.abs();
            let f = truth[0] * a
                + truth[1] * u
                + v.signum()
                    * (truth[2] + truth[3] * w.powf(truth[4]) + truth[5] * (-truth[6] * w).exp())
                + 1e3 * record as f64
                + 300.0 * rng.normal();
            b.a.push(a + 0.03 * rng.normal());
            b.u.push(u + 2e-5 * rng.normal());
            b.s.push(v.signum());
            b.w.push(w);
            b.ln_w.push(w.ln());
            b.f.push(f);
            b.time.push(i);
        }
        b
    }

    fn data(records: usize) -> Stacked {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        Stacked::from_blocks(
            (0..records)
                .map(|r| Rc::new(block(r, 6000, &mut rng)))
                .collect(),
        )
    }

    fn shape(records: usize) -> Shape {
        Shape {
            alpha: None,
            low: true,
            records,
            nonneg_stiffness: false,
        }
    }

    /// Record `record` with its acceleration a twentieth of a sample early (a refit's
    /// perturbation, to first order).
    fn perturbed(data: &Stacked, record: usize) -> Stacked {
        let b = &data.blocks[record];
        let mut a = b.a.clone();
        for i in 1..a.len() - 1 {
            a[i] = b.a[i] + 0.05 * (b.a[i + 1] - b.a[i - 1]) / 2.0;
        }
        let moved = Block {
            record,
            a,
            u: b.u.clone(),
            s: b.s.clone(),
            w: b.w.clone(),
            ln_w: b.ln_w.clone(),
            f: b.f.clone(),
            time: b.time.clone(),
            noise_var: b.noise_var,
            ..Block::default()
        };
        data.with_block(record, moved)
    }

    /// The expanded sums agree with the samples' to rounding inside the radius.
    #[test]
    fn the_expanded_sums_are_the_samples_sums_to_rounding() {
        let d = data(1);
        let blk = &d.blocks[0];
        let m = Moments::of(blk, 0.6, 50.0, true);
        for (da, db) in [(0.0, 0.0), (1e-3, 0.02), (-4e-3, -0.3), (0.008, 0.6)] {
            let got = m.at(da, db, true).expect("inside the radius");
            let want = exact_sums(blk, 0.6 + da, 50.0 + db, true);
            let pairs = [
                (got.node.c.zx[0], want.node.c.zx[0]),
                (got.node.c.zz, want.node.c.zz),
                (got.node.c.zy, want.node.c.zy),
                (got.node.e.zx[1], want.node.e.zx[1]),
                (got.node.e.zz, want.node.e.zz),
                (got.node.ce, want.node.ce),
                (got.alpha.y, want.alpha.y),
                (got.alpha.c, want.alpha.c),
                (got.alpha.e, want.alpha.e),
                (got.decay.x[2], want.decay.x[2]),
                (got.decay.c, want.decay.c),
                (got.decay.e, want.decay.e),
            ];
            for (k, (g, w)) in pairs.into_iter().enumerate() {
                assert!(
                    (g - w).abs() <= 1e-12 * w.abs().max(1e-300),
                    "sum {k} at ({da}, {db}): {g} vs {w}"
                );
            }
        }
        assert!(m.at(0.5, 0.0, true).is_none());
        assert!(m.at(0.0, 50.0, true).is_none());
    }

    /// The gradient from the sums is the central difference of the fitted cost `Σ r²` that
    /// the search minimises (noise correction included).
    #[test]
    fn the_gradient_is_the_fitted_costs_derivative() {
        let d = data(2);
        let s = shape(2);
        let fit = Separable::new(&d, s).fit();
        let refits = Refits::new(&d, &fit, s, Sums::Exact);
        let sep = Separable::new(&d, s);
        let cost = |q: &[f64]| {
            let mut r = vec![0.0; d.len()];
            crate::lm::Problem::residuals(&sep, q, &mut r);
            r.iter().map(|x| x * x).sum::<f64>()
        };
        let q = [fit.full[EXPONENT] + 0.02, fit.full[LOW_DECAY] * 1.1];
        let g = refits
            .point(&d, 0, q, &refits.searched, &refits.held)
            .unwrap()
            .gradient;
        for k in 0..2 {
            let h = 1e-5 * q[k];
            let (mut qp, mut qm) = (q, q);
            qp[k] += h;
            qm[k] -= h;
            let fd = (cost(&qp) - cost(&qm)) / (2.0 * h);
            assert!((g[k] / fd - 1.0).abs() < 1e-5, "{k}: {} vs {fd}", g[k]);
        }
    }

    /// A refit by Newton's method lands at the optimum the search approaches: its fitted
    /// cost is no higher than the search's (to the costs' rounding), and the search's is
    /// above it by what the search leaves when its steps gain less than 10⁻¹⁴ of the cost
    /// (here up to 3·10⁻¹¹ of it, on one record). The vectors then
    /// differ by where the search stopped along the flat directions: within 1 % of the
    /// shift the perturbation causes (on one record 3·10⁻⁴ of it in Mₑ, 1.4·10⁻³ in b).
    /// Newton applies here both from the samples' sums and from the expansions (one record
    /// of six moves α by 0.03 and b by 4 s/m, within their accuracy at order 24).
    #[test]
    fn a_refit_lands_at_the_searchs_optimum() {
        for (records, record) in [(4, 1), (6, 4), (1, 0)] {
            let d = data(records);
            let s = shape(records);
            let fit = Separable::new(&d, s).fit();
            let moved = perturbed(&d, record);
            let search = Separable::new(&moved, s).fit();
            let problem = Separable::new(&moved, s);
            let cost = |full: &[f64]| {
                let mut r = vec![0.0; moved.len()];
                crate::lm::Problem::residuals(&problem, &[full[EXPONENT], full[LOW_DECAY]], &mut r);
                r.iter().map(|x| x * x).sum::<f64>()
            };
            for sums in [Sums::Exact, Sums::Expanded] {
                let refits = Refits::new(&d, &fit, s, sums);
                let newton = refits
                    .refit(&moved, record)
                    .unwrap_or_else(|| panic!("{records} records, {sums:?}"));
                assert_eq!(newton.free, search.free);
                let (cn, cs) = (cost(&newton.full), cost(&search.full));
                assert!(cn <= cs * (1.0 + 1e-13), "{records} records: {cn} vs {cs}");
                assert!(cs - cn <= 1e-10 * cs, "{records} records: {cn} vs {cs}");
                for i in [MASS, STIFFNESS, COULOMB, VISCOUS, EXPONENT, LOW_DECAY] {
                    let shift = (search.full[i] - fit.full[i]).abs();
                    let diff = (newton.full[i] - search.full[i]).abs();
                    assert!(
                        diff <= 1e-2 * shift,
                        "{records} records, {sums:?}, parameter {i}: Newton {} search {} joint {}",
                        newton.full[i],
                        search.full[i],
                        fit.full[i]
                    );
                }
            }
        }
    }

    /// Data whose viscous law is steeper than the model's range (`α = 1.3`): the joint fit
    /// holds `α` on its bound 1. Every refit is then made by Newton's method with `α` held
    /// (before, a parameter on its bound sent every refit to the full search from the start
    /// grid, passes over every record each: the cost that grew with the square of the
    /// records), and lands where the search from the joint fit lands: its cost no higher (to
    /// the costs' rounding, 10⁻¹³) and below by at most what the search's statistical stop
    /// leaves (10⁻⁶ of the residual variance as predicted, 2·10⁻⁶ allowed: here 2·10⁻¹⁰ of
    /// the cost).
    #[test]
    fn refits_with_alpha_on_its_bound_hold_it_and_need_no_search() {
        for records in [1, 3] {
            let mut rng = Rng(0x2545_F491_4F6C_DD1D);
            let d = Stacked::from_blocks(
                (0..records)
                    .map(|r| Rc::new(block_with(r, 6000, 1.3, &mut rng)))
                    .collect(),
            );
            let s = shape(records);
            let fit = Separable::new(&d, s).fit();
            assert_eq!(fit.at_bound, vec![EXPONENT], "{:?}", fit.full);
            assert_eq!(fit.held, vec![EXPONENT]);
            let refits = Refits::new(&d, &fit, s, Sums::Expanded);
            let mut searched = 0;
            for record in 0..records {
                let moved = perturbed(&d, record);
                let Some(newton) = refits.refit(&moved, record) else {
                    searched += 1;
                    continue;
                };
                assert_eq!(newton.full[EXPONENT], 1.0);
                let problem = Separable::new(&moved, s);
                let search = problem.fit_from(&[fit.full[EXPONENT], fit.full[LOW_DECAY]]);
                assert_eq!(search.full[EXPONENT], 1.0);
                let cost = |full: &[f64]| {
                    let mut r = vec![0.0; moved.len()];
                    crate::lm::Problem::residuals(
                        &problem,
                        &[full[EXPONENT], full[LOW_DECAY]],
                        &mut r,
                    );
                    r.iter().map(|x| x * x).sum::<f64>()
                };
                let (cn, cs) = (cost(&newton.full), cost(&search.full));
                assert!(cn <= cs * (1.0 + 1e-13), "{records} records: {cn} vs {cs}");
                // The search's statistical stop leaves up to 10⁻⁶ of s² = cost/samples as the
                // Gauss–Newton model predicts it; twice that for the model's error.
                let s2 = cs / moved.len() as f64;
                assert!(cs - cn <= 2e-6 * s2, "{records} records: {cn} vs {cs}");
            }
            assert_eq!(
                searched, 0,
                "{records} records: refits that fell back to the search"
            );
        }
    }
}
