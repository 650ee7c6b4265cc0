//! Drive iteration of several coupled axes at once, through the transfer matrix
//! ([`iterate_mimo`]), as controllers of multi-axis tables do it (MTS's OLI works in DOF space
//! with a matrix FRF).
//!
//! # The iteration
//!
//! On a multi-axis table the x drive moves z and pitch through the specimen's overturning
//! moment, so correcting each axis alone, each through its own diagonal term, stalls where
//! the coupling is strong. With `p` axes, drives `D` (displacement commands), achieved
//! accelerations `R_k`, target accelerations `T` (zero on the axes held still), per
//! frequency:
//!
//! ```text
//!   D_{k+1}(f) = D_k(f) + g · w(f) · Ĥ⁺(f) · (T(f) − R_k(f)) / (−(2πf)²)
//!   Ĥ⁺ = (Ĥᴴ·Ĥ + ε²·max‖Ĥ‖²_F · I)⁻¹ · Ĥᴴ
//! ```
//!
//! * `Ĥ(f)` (`p × p`) maps the commands' displacements to the achieved displacements (and
//!   equally accelerations to accelerations); element `(i, j)` is axis `i`'s response to
//!   axis `j`'s command.
//! * `Ĥ⁺` is the Tikhonov-regularised inverse: where `Ĥ` is well conditioned it is `Ĥ⁻¹`;
//!   along directions whose singular value falls to `ε·max‖Ĥ‖_F` it gives half the exact
//!   inverse and it never exceeds `1/(2ε·max‖Ĥ‖_F)` (`‖·‖_F` the Frobenius norm, the
//!   largest over the band). For one axis it is the single-axis iteration's inverse exactly
//!   ([`crate::iterate()`]).
//! * The band `w(f)`, the gain `g`, the padding, the taper at the record's ends and the stop
//!   criteria are those of [`crate::IterationSettings`], the criteria judged on the **overall**
//!   acceleration NRMSE, `√(Σ_axes Σ_t (R − T)²/Σ_axes Σ_t T²)`, so that the cross-talk on
//!   the axes held still counts as error.
//! * On a linear plant whose `Ĥ` is exact and invertible, every axis's in-band error
//!   shrinks by exactly `1 − g` per iteration, cross-coupled or not (tested).
//!
//! # Reported per iteration
//!
//! Per axis: the acceleration NRMSE (`null` on an axis held still, whose error is its
//! cross-talk, reported as `rms_acceleration_error_m_s2`), the displacement NRMSE, the
//! response-spectrum error (as the single-axis iteration's), the drive's peak and the
//! achieved peak acceleration; overall: the acceleration NRMSE and the time saturated.

use std::collections::BTreeMap;
use std::sync::Arc;

use rustfft::num_complex::Complex64 as C64;
use rustfft::{Fft, FftPlanner};
use serde::Serialize;

use crate::baseline::{peak, rms};
use crate::error::{PlanError, Result};
use crate::iterate::{
    checked, fft_size, half_cosine_taper, nrmse, signed_peak, Band, BestRun, IterationSettings,
    Progress, SpectrumCheck, SpectrumSettings, Stop,
};

/// One axis of a multi-axis target: its name and its target motion at the common samples.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisTarget {
    /// The axis: `x`, `y` or `z`.
    pub name: &'static str,
    /// Target displacement (the drive of iteration 0), m.
    pub u_m: Vec<f64>,
    /// Target acceleration, m/s² (all zero on an axis held still).
    pub a_m_s2: Vec<f64>,
}

impl AxisTarget {
    /// An axis held still: zero displacement and acceleration over `samples`.
    pub fn still(name: &'static str, samples: usize) -> Self {
        Self {
            name,
            u_m: vec![0.0; samples],
            a_m_s2: vec![0.0; samples],
        }
    }

    /// The same axis at `level` times its size.
    pub fn scaled(&self, level: f64) -> Self {
        Self {
            name: self.name,
            u_m: self.u_m.iter().map(|u| u * level).collect(),
            a_m_s2: self.a_m_s2.iter().map(|a| a * level).collect(),
        }
    }

    /// Whether the axis is held still (its target acceleration is zero throughout).
    pub fn is_still(&self) -> bool {
        self.a_m_s2.iter().all(|&a| a == 0.0)
    }
}

/// What the plant returns for the drives of all axes: per axis the achieved displacement and
/// acceleration at the target's samples, and what the stall diagnosis reads.
pub trait MimoResponse {
    /// Achieved displacement of axis `i` (in the targets' order), m.
    fn u_m(&self, i: usize) -> &[f64];
    /// Achieved acceleration of axis `i`, m/s².
    fn a_m_s2(&self, i: usize) -> &[f64];
    /// Time with any valve saturated, s.
    fn saturated_time_s(&self) -> f64 {
        0.0
    }
    /// First cavitation, s.
    fn cavitation_at_s(&self) -> Option<f64> {
        None
    }
}

/// The transfer matrix `Ĥ(f)` of `p` axes: `h[i][j]` is axis `i`'s response to axis `j`'s
/// command.
pub type TransferMatrix = Vec<Vec<C64>>;

/// One axis's figures in one iteration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisRecord {
    /// `rms(R − T)/rms(T)` on the acceleration (`null` on an axis held still).
    pub acceleration_nrmse: Option<f64>,
    /// `rms(R − T)`, m/s²: on an axis held still, its cross-talk.
    pub rms_acceleration_error_m_s2: f64,
    /// The same NRMSE on the displacement (`null` on an axis held still).
    pub displacement_nrmse: Option<f64>,
    /// Largest relative error of the achieved 5 %-damped response spectrum against the
    /// target's (`null` on an axis held still).
    pub spectrum_error: Option<f64>,
    /// The period where it occurs, s.
    pub spectrum_error_period_s: Option<f64>,
    /// The drive's largest displacement, m.
    pub peak_drive_u_m: f64,
    /// The achieved signed peak acceleration, m/s².
    pub peak_a_m_s2: f64,
}

/// One iteration's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MimoRecord {
    /// 0 for the target's own command, then 1, 2, …
    pub iteration: usize,
    /// The overall acceleration NRMSE (all axes' errors over all axes' targets).
    pub acceleration_nrmse: f64,
    /// Per axis.
    pub axes: BTreeMap<&'static str, AxisRecord>,
    /// Time with any valve saturated, s.
    pub valve_saturated_time_s: f64,
}

/// The finished iteration.
#[derive(Debug, Clone)]
pub struct MimoIteration<R> {
    /// The best drives (lowest overall acceleration NRMSE), m, per axis in the targets'
    /// order, at the target's samples.
    pub drive_u_m: Vec<Vec<f64>>,
    /// Its iteration.
    pub best: usize,
    /// What it achieved.
    pub achieved: R,
    /// Every iteration's figures, from 0.
    pub records: Vec<MimoRecord>,
    /// Why it stopped.
    pub stop: Stop,
    /// The correction band used, Hz.
    pub band_hz: (f64, f64),
    /// The FFT length (record plus padding), samples.
    pub fft_len: usize,
    /// The largest condition number of `Ĥ` in the band (ratio of its largest to its smallest
    /// singular value, from the Hermitian `ĤᴴĤ`'s eigenvalues): how ill-conditioned the
    /// inverse the regularisation guards was.
    pub max_condition: f64,
}

impl<R> MimoIteration<R> {
    /// The best iteration's figures.
    pub fn best_record(&self) -> &MimoRecord {
        &self.records[self.best]
    }
}

/// The correction operator of `p` coupled axes: `ΔD = IFFT(W·FFT(E))`, `W` a `p × p` matrix
/// per bin; planned once per record length.
pub struct MimoCorrection {
    p: usize,
    n: usize,
    m: usize,
    /// `g·w·Ĥ⁺/(−ω²)` per positive bin `1..=m/2` (row-major `p × p`; zero outside the band).
    weights: Vec<Vec<C64>>,
    in_band: Vec<bool>,
    taper: Vec<f64>,
    max_condition: f64,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for MimoCorrection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MimoCorrection")
            .field("axes", &self.p)
            .field("samples", &self.n)
            .field("fft_len", &self.m)
            .finish()
    }
}

impl MimoCorrection {
    /// Plans the correction of `p` axes' records of `samples` samples at `sample_rate_hz`,
    /// with `Ĥ` = `frf` (`p × p` at each frequency) and `settings`' gain, band,
    /// regularisation, padding and taper.
    ///
    /// # Errors
    /// [`PlanError::Setting`] for settings out of range, a band with no FFT bin, or an `frf`
    /// that is not `p × p` or not finite.
    pub fn new(
        p: usize,
        samples: usize,
        sample_rate_hz: f64,
        frf: &dyn Fn(f64) -> TransferMatrix,
        settings: &IterationSettings,
    ) -> Result<Self> {
        let s = checked(settings, sample_rate_hz, samples)?;
        let n = samples;
        let pad = (s.pad_s * sample_rate_hz).round() as usize;
        let m = if pad == 0 { n } else { fft_size(n + pad) };
        let half = m / 2;
        let df = sample_rate_hz / m as f64;
        let band = Band {
            hz: s.band_hz,
            edge_fraction: settings.edge_fraction,
        };
        let zero = vec![C64::new(0.0, 0.0); p * p];
        let mut h = vec![zero.clone(); half + 1];
        let mut max_norm = 0.0_f64;
        for (k, slot) in h.iter_mut().enumerate().skip(1) {
            let f = k as f64 * df;
            if band.weight(f) <= 0.0 {
                continue;
            }
            let hf = frf(f);
            if hf.len() != p || hf.iter().any(|row| row.len() != p) {
                return Err(PlanError::Setting {
                    name: "frf",
                    value: f,
                    expected: "a square transfer matrix of the axes' count at every frequency",
                });
            }
            *slot = hf.into_iter().flatten().collect();
            if slot.iter().any(|c| !c.re.is_finite() || !c.im.is_finite()) {
                return Err(PlanError::Setting {
                    name: "frf",
                    value: f,
                    expected: "a finite transfer matrix in the band",
                });
            }
            max_norm = max_norm.max(slot.iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt());
        }
        let floor = (settings.regularisation * max_norm).powi(2);
        let mut weights = vec![zero; half + 1];
        let mut in_band = vec![false; half + 1];
        let mut max_condition = 1.0_f64;
        for k in 1..=half {
            // The Nyquist bin of an even length has no conjugate partner: leave it out.
            if m % 2 == 0 && k == half {
                continue;
            }
            let f = k as f64 * df;
            let w = band.weight(f);
            if w <= 0.0 {
                continue;
            }
            let hk = &h[k];
            max_condition = max_condition.max(condition(hk, p));
            let Some(inverse) = regularised_inverse(hk, p, floor) else {
                continue;
            };
            let omega = std::f64::consts::TAU * f;
            let scale = settings.gain * w / -(omega * omega);
            weights[k] = inverse.into_iter().map(|c| c * scale).collect();
            in_band[k] = true;
        }
        if !in_band.iter().any(|&b| b) {
            return Err(PlanError::Setting {
                name: "band_hz",
                value: s.band_hz.0,
                expected: "a band holding at least one FFT bin of the record (a longer record or \
                           a wider band)",
            });
        }
        let taper_n = ((settings.taper_s * sample_rate_hz).round() as usize).min(n / 2);
        let mut planner = FftPlanner::<f64>::new();
        Ok(Self {
            p,
            n,
            m,
            weights,
            in_band,
            taper: half_cosine_taper(n, taper_n),
            max_condition,
            forward: planner.plan_fft_forward(m),
            inverse: planner.plan_fft_inverse(m),
        })
    }

    /// The FFT length, samples.
    pub fn fft_len(&self) -> usize {
        self.m
    }

    /// The largest condition number of `Ĥ` over the band's bins.
    pub fn max_condition(&self) -> f64 {
        self.max_condition
    }

    /// The drives' corrections for the acceleration errors `errors_m_s2` (`T − R` per axis),
    /// and the fraction of the errors' energy on bins inside the band.
    pub fn apply(&self, errors_m_s2: &[Vec<f64>]) -> (Vec<Vec<f64>>, f64) {
        let (p, m) = (self.p, self.m);
        let spectra: Vec<Vec<C64>> = errors_m_s2
            .iter()
            .map(|e| {
                let mut buf = vec![C64::new(0.0, 0.0); m];
                for (b, v) in buf.iter_mut().zip(e.iter().take(self.n)) {
                    b.re = *v;
                }
                self.forward.process(&mut buf);
                buf
            })
            .collect();
        let (mut total, mut inside) = (0.0, 0.0);
        for spectrum in &spectra {
            for (c, &inside_band) in spectrum[..=m / 2].iter().zip(&self.in_band).skip(1) {
                let e = c.norm_sqr();
                total += e;
                if inside_band {
                    inside += e;
                }
            }
        }
        let mut out = vec![vec![C64::new(0.0, 0.0); m]; p];
        for k in 1..=m / 2 {
            if !self.in_band[k] {
                continue;
            }
            let w = &self.weights[k];
            for (i, out_i) in out.iter_mut().enumerate() {
                let mut v = C64::new(0.0, 0.0);
                for (j, spectrum) in spectra.iter().enumerate() {
                    v += w[i * p + j] * spectrum[k];
                }
                out_i[k] = v;
                out_i[m - k] = v.conj();
            }
        }
        let scale = 1.0 / m as f64;
        let deltas = out
            .into_iter()
            .map(|mut buf| {
                self.inverse.process(&mut buf);
                (0..self.n)
                    .map(|j| buf[j].re * scale * self.taper[j])
                    .collect()
            })
            .collect();
        (deltas, if total > 0.0 { inside / total } else { 1.0 })
    }
}

/// `(ĤᴴĤ + floor·I)⁻¹·Ĥᴴ` of the row-major `p × p` `h`, or `None` if singular (a zero `Ĥ`
/// without regularisation).
fn regularised_inverse(h: &[C64], p: usize, floor: f64) -> Option<Vec<C64>> {
    // a = ĤᴴĤ + floor·I, b = Ĥᴴ; solve a·x = b.
    let mut a = vec![C64::new(0.0, 0.0); p * p];
    let mut b = vec![C64::new(0.0, 0.0); p * p];
    for i in 0..p {
        for j in 0..p {
            let mut s = C64::new(0.0, 0.0);
            for r in 0..p {
                s += h[r * p + i].conj() * h[r * p + j];
            }
            a[i * p + j] = s;
            b[i * p + j] = h[j * p + i].conj();
        }
        a[i * p + i] += floor;
    }
    solve(&mut a, &mut b, p)
}

/// Solves `a·x = b` in place (`b` becomes `x`; both row-major `p × p`) by Gaussian
/// elimination with partial pivoting; `None` if `a` is singular.
fn solve(a: &mut [C64], b: &mut [C64], p: usize) -> Option<Vec<C64>> {
    for col in 0..p {
        let pivot =
            (col..p).max_by(|&r, &s| a[r * p + col].norm().total_cmp(&a[s * p + col].norm()))?;
        if a[pivot * p + col].norm() == 0.0 {
            return None;
        }
        if pivot != col {
            for c in 0..p {
                a.swap(pivot * p + c, col * p + c);
                b.swap(pivot * p + c, col * p + c);
            }
        }
        let d = a[col * p + col];
        for r in 0..p {
            if r == col {
                continue;
            }
            let factor = a[r * p + col] / d;
            if factor == C64::new(0.0, 0.0) {
                continue;
            }
            for c in 0..p {
                let (ac, bc) = (a[col * p + c], b[col * p + c]);
                a[r * p + c] -= factor * ac;
                b[r * p + c] -= factor * bc;
            }
        }
    }
    for r in 0..p {
        let d = a[r * p + r];
        for c in 0..p {
            b[r * p + c] /= d;
        }
    }
    Some(b.to_vec())
}

/// The condition number of the row-major `p × p` `h`: the square root of the ratio of the
/// largest to the smallest eigenvalue of the Hermitian `ĤᴴĤ` (Jacobi rotations on its real
/// `2p × 2p` embedding, whose eigenvalues are those of `ĤᴴĤ`, each twice); infinite when
/// singular.
fn condition(h: &[C64], p: usize) -> f64 {
    let n = 2 * p;
    let mut g = vec![0.0; n * n];
    for i in 0..p {
        for j in 0..p {
            let mut s = C64::new(0.0, 0.0);
            for r in 0..p {
                s += h[r * p + i].conj() * h[r * p + j];
            }
            // [[Re, −Im], [Im, Re]]
            g[i * n + j] = s.re;
            g[i * n + (j + p)] = -s.im;
            g[(i + p) * n + j] = s.im;
            g[(i + p) * n + (j + p)] = s.re;
        }
    }
    let eig = jacobi_eigenvalues(&mut g, n);
    let (lo, hi) = eig.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &e| {
        (lo.min(e), hi.max(e))
    });
    if lo <= 0.0 {
        f64::INFINITY
    } else {
        (hi / lo).sqrt()
    }
}

/// The eigenvalues of the real symmetric `n × n` `g` (destroyed) by cyclic Jacobi sweeps.
fn jacobi_eigenvalues(g: &mut [f64], n: usize) -> Vec<f64> {
    for _sweep in 0..50 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| g[i * n + j].powi(2))
            .sum();
        let diag: f64 = (0..n).map(|i| g[i * n + i].powi(2)).sum();
        if off <= 1e-30 * diag.max(f64::MIN_POSITIVE) {
            break;
        }
        for i in 0..n {
            for j in i + 1..n {
                let gij = g[i * n + j];
                if gij == 0.0 {
                    continue;
                }
                let theta = (g[j * n + j] - g[i * n + i]) / (2.0 * gij);
                let sign = if theta >= 0.0 { 1.0 } else { -1.0 };
                let t = sign / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (gki, gkj) = (g[k * n + i], g[k * n + j]);
                    g[k * n + i] = c * gki - s * gkj;
                    g[k * n + j] = s * gki + c * gkj;
                }
                for k in 0..n {
                    let (gik, gjk) = (g[i * n + k], g[j * n + k]);
                    g[i * n + k] = c * gik - s * gjk;
                    g[j * n + k] = s * gik + c * gjk;
                }
            }
        }
    }
    (0..n).map(|i| g[i * n + i]).collect()
}

/// The overall acceleration NRMSE of `r` against `targets`.
fn overall_nrmse<R: MimoResponse>(targets: &[AxisTarget], r: &R) -> f64 {
    let (mut err, mut reference) = (0.0, 0.0);
    for (i, t) in targets.iter().enumerate() {
        for (x, y) in r.a_m_s2(i).iter().zip(&t.a_m_s2) {
            err += (x - y).powi(2);
            reference += y * y;
        }
    }
    if reference > 0.0 {
        (err / reference).sqrt()
    } else if err == 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// Iterates the drives of the axes `targets` (all at the same samples, `interval_s` apart)
/// on any plant: `plant(drives, k)` runs the drives of iteration `k` (per axis, in the
/// targets' order) and returns what they achieved; `frf` is `Ĥ` (see the [module
/// documentation](self)).
///
/// # Errors
/// Bad settings; targets of different lengths or none; any error of `plant`.
pub fn iterate_mimo<R: MimoResponse>(
    targets: &[AxisTarget],
    interval_s: f64,
    frf: &dyn Fn(f64) -> TransferMatrix,
    settings: &IterationSettings,
    mut plant: impl FnMut(&[Vec<f64>], usize) -> Result<R>,
) -> Result<MimoIteration<R>> {
    let p = targets.len();
    let n = targets.first().map_or(0, |t| t.a_m_s2.len());
    if p == 0
        || targets
            .iter()
            .any(|t| t.a_m_s2.len() != n || t.u_m.len() != n)
    {
        return Err(PlanError::Target {
            origin: "the axes' targets".into(),
            message: "every axis needs a target of the same length, and at least one axis".into(),
        });
    }
    let fs = 1.0 / interval_s;
    let correction = MimoCorrection::new(p, n, fs, frf, settings)?;
    let band_hz = checked(settings, fs, n)?.band_hz;
    let spectra = spectrum_checks(targets, fs, &settings.spectrum)?;
    let mut drives: Vec<Vec<f64>> = targets.iter().map(|t| t.u_m.clone()).collect();
    let mut records = Vec::new();
    let mut progress = Progress::<R, Vec<Vec<f64>>> {
        best: None,
        without_improvement: 0,
    };
    let mut k = 0;
    let stop = loop {
        let r = plant(&drives, k)?;
        let overall = overall_nrmse(targets, &r);
        records.push(mimo_record(k, targets, &r, &drives, &spectra));
        let errors: Vec<Vec<f64>> = targets
            .iter()
            .enumerate()
            .map(|(i, t)| {
                t.a_m_s2
                    .iter()
                    .zip(r.a_m_s2(i))
                    .map(|(t, a)| t - a)
                    .collect()
            })
            .collect();
        let is_best = progress.judge(overall, settings.min_improvement);
        let converged = overall <= settings.target_nrmse;
        let at_max = k >= settings.max_iterations;
        let stalled = progress.without_improvement >= settings.stall_iterations;
        let c = (!converged).then(|| correction.apply(&errors));
        let reason = match (&c, stalled) {
            (Some((_, in_band)), true) => Some(stall_reason(&r, *in_band, band_hz)),
            _ => None,
        };
        if is_best {
            progress.best = Some(BestRun {
                k,
                drive: drives.clone(),
                achieved: r,
                nrmse: overall,
            });
        }
        if converged {
            break Stop::Converged;
        }
        if let Some(reason) = reason {
            break Stop::Stalled { reason };
        }
        if at_max {
            break Stop::MaxIterations;
        }
        let Some((deltas, _)) = c else {
            unreachable!("a correction is made unless the iteration stops")
        };
        for (d, dd) in drives.iter_mut().zip(&deltas) {
            for (x, dx) in d.iter_mut().zip(dd) {
                *x += dx;
            }
        }
        k += 1;
    };
    let Some(best) = progress.best else {
        unreachable!("iteration 0 always runs")
    };
    Ok(MimoIteration {
        drive_u_m: best.drive,
        best: best.k,
        achieved: best.achieved,
        records,
        stop,
        band_hz,
        fft_len: correction.fft_len(),
        max_condition: correction.max_condition(),
    })
}

/// The response-spectrum checks of `targets` at `sample_rate_hz` (`None` for an axis held
/// still).
fn spectrum_checks(
    targets: &[AxisTarget],
    sample_rate_hz: f64,
    spectrum: &SpectrumSettings,
) -> Result<Vec<Option<SpectrumCheck>>> {
    targets
        .iter()
        .map(|t| {
            (!t.is_still())
                .then(|| SpectrumCheck::new(spectrum, sample_rate_hz, &t.a_m_s2))
                .transpose()
        })
        .collect()
}

/// The record of a run `r` of `drives` against `targets` (as iteration `k`'s).
fn mimo_record<R: MimoResponse>(
    k: usize,
    targets: &[AxisTarget],
    r: &R,
    drives: &[Vec<f64>],
    spectra: &[Option<SpectrumCheck>],
) -> MimoRecord {
    MimoRecord {
        iteration: k,
        acceleration_nrmse: overall_nrmse(targets, r),
        axes: targets
            .iter()
            .enumerate()
            .map(|(i, t)| (t.name, axis_record(t, r, i, &drives[i], &spectra[i])))
            .collect(),
        valve_saturated_time_s: r.saturated_time_s(),
    }
}

/// The record of a run `r` of `drives` against `targets` at `interval_s` (as iteration
/// `k`'s), made outside the iteration (drives scaled up).
///
/// # Errors
/// Bad spectrum settings.
pub(crate) fn record_of_run<R: MimoResponse>(
    k: usize,
    targets: &[AxisTarget],
    interval_s: f64,
    r: &R,
    drives: &[Vec<f64>],
    spectrum: &SpectrumSettings,
) -> Result<MimoRecord> {
    let spectra = spectrum_checks(targets, 1.0 / interval_s, spectrum)?;
    Ok(mimo_record(k, targets, r, drives, &spectra))
}

/// Axis `i`'s figures: target `t`, achieved `r`, drive `drive`.
fn axis_record<R: MimoResponse>(
    t: &AxisTarget,
    r: &R,
    i: usize,
    drive: &[f64],
    spectrum: &Option<SpectrumCheck>,
) -> AxisRecord {
    let still = t.is_still();
    let error: Vec<f64> = r
        .a_m_s2(i)
        .iter()
        .zip(&t.a_m_s2)
        .map(|(a, t)| a - t)
        .collect();
    let spectrum_error = spectrum.as_ref().map(|s| s.error(r.a_m_s2(i)));
    AxisRecord {
        acceleration_nrmse: (!still).then(|| nrmse(r.a_m_s2(i), &t.a_m_s2)),
        rms_acceleration_error_m_s2: rms(&error),
        displacement_nrmse: (!still && t.u_m.iter().any(|&u| u != 0.0))
            .then(|| nrmse(r.u_m(i), &t.u_m)),
        spectrum_error: spectrum_error.map(|e| e.0),
        spectrum_error_period_s: spectrum_error.map(|e| e.1),
        peak_drive_u_m: peak(drive),
        peak_a_m_s2: signed_peak(r.a_m_s2(i)),
    }
}

/// Why the iteration no longer improves, from the last run.
fn stall_reason<R: MimoResponse>(r: &R, in_band_fraction: f64, band_hz: (f64, f64)) -> String {
    let mut reasons = Vec::new();
    if r.saturated_time_s() > 0.0 {
        reasons.push(format!(
            "valves were saturated (drive at ±1) for {:.3} s: the table cannot deliver more \
             flow there",
            r.saturated_time_s()
        ));
    }
    if let Some(t) = r.cavitation_at_s() {
        reasons.push(format!("a chamber cavitated at {t:.3} s"));
    }
    if in_band_fraction < 0.5 {
        reasons.push(format!(
            "{:.0} % of the remaining error lies outside the correction band [{}, {}] Hz",
            100.0 * (1.0 - in_band_fraction),
            band_hz.0,
            band_hz.1
        ));
    }
    if reasons.is_empty() {
        reasons.push(
            "the linear inverse no longer reduces the remaining error (nonlinearity of the \
             loop, friction, or Ĥ off from the table in the band: try a smaller gain)"
                .to_owned(),
        );
    }
    format!(
        "no improvement for the last iterations: {}",
        reasons.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> C64 {
        C64::new(re, im)
    }

    #[test]
    fn the_unregularised_inverse_is_the_inverse() {
        let h = [c(1.0, 0.5), c(0.3, -0.2), c(-0.1, 0.4), c(2.0, 0.1)];
        let x = regularised_inverse(&h, 2, 0.0).unwrap();
        for i in 0..2 {
            for j in 0..2 {
                let mut s = c(0.0, 0.0);
                for r in 0..2 {
                    s += x[i * 2 + r] * h[r * 2 + j];
                }
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((s - c(want, 0.0)).norm() < 1e-14, "{i}{j}: {s}");
            }
        }
    }

    #[test]
    fn one_axis_is_the_single_axis_inverse() {
        // Ĥ*/(|Ĥ|² + floor)
        let h = [c(0.8, -0.6)];
        let x = regularised_inverse(&h, 1, 0.25).unwrap();
        let want = h[0].conj() / (h[0].norm_sqr() + 0.25);
        assert!((x[0] - want).norm() < 1e-15);
    }

    #[test]
    fn the_condition_number_is_the_singular_values_ratio() {
        // diag(3, 0.5i) (unitary columns scaled): σ = 3 and 0.5.
        let h = [c(3.0, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(0.0, 0.5)];
        assert!((condition(&h, 2) - 6.0).abs() < 1e-12);
        let singular = [c(1.0, 0.0), c(2.0, 0.0), c(0.5, 0.0), c(1.0, 0.0)];
        assert!(condition(&singular, 2) > 1e7);
    }
}
