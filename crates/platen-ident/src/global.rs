//! The global fit: all parameters at once from the instantaneous residual of Eq. 23 plus the
//! low-velocity term,
//! `r(t) = Mₑ·a + K_p·u + sign(v)·[F_μ,p + Cₑ|v|^α + a·e^(−b|v|)] − F_A`,
//! over every usable sample of every test, with `Kₑ` and `F_μ` per hold-down pressure `p`.
//!
//! The channels are those low-passed by the dissipative FIR (so the oil-column ringing and
//! the valve tone are gone), with the filter's smearing of the friction jump removed as the
//! hysteresis-loop law predicts it. Samples within the reversal window are left out, and on
//! triangle tests everything but the constant-velocity portions farther from the reversal
//! arcs than the filter's 0.5 % settling time (0.33 s): the arcs' inertial transients
//! (`Mₑ·A_r`, up to MN) would leak through the filter's tail. The acceleration is the second
//! derivative of the low-passed displacement, not the accelerometer: an accelerometer
//! conditioner's phase lag `τ` (2.25 ms for the paper's 100 Hz analog filter) puts a force
//! `Mₑ·τ·ω²·v` in phase with velocity into the residual, 18 kN per m/s at 1.2 Hz, which the
//! dissipative terms would absorb. (The hysteresis-loop method is immune to it: its symmetric
//! combinations cancel that part.)

use nalgebra::DMatrix;

use crate::cycle::Analysed;
use crate::estimate::{Estimate, Parameter};
use crate::law::{self, DissipativeLaw};
use crate::lm::{self, covariance, LmSettings, Problem};
use crate::result::GlobalFit;

struct Sample {
    u: f64,
    v: f64,
    a: f64,
    f: f64,
    group: usize,
}

struct GlobalProblem {
    samples: Vec<Sample>,
    free: Vec<usize>,
    base: Vec<f64>,
}

const M: usize = 0;
const C: usize = 1;
const ALPHA: usize = 2;
const A: usize = 3;
const B: usize = 4;
const fn k_index(g: usize) -> usize {
    5 + 2 * g
}
const fn f_index(g: usize) -> usize {
    6 + 2 * g
}

impl GlobalProblem {
    fn full(&self, p: &[f64]) -> Vec<f64> {
        let mut q = self.base.clone();
        for (k, &i) in self.free.iter().enumerate() {
            q[i] = p[k];
        }
        q
    }
}

impl Problem for GlobalProblem {
    fn residual_count(&self) -> usize {
        self.samples.len()
    }
    fn parameter_count(&self) -> usize {
        self.free.len()
    }
    fn residuals(&self, p: &[f64], r: &mut [f64]) {
        let q = self.full(p);
        for (r, s) in r.iter_mut().zip(&self.samples) {
            let w = s.v.abs();
            let sign = if s.v > 0.0 {
                1.0
            } else if s.v < 0.0 {
                -1.0
            } else {
                0.0
            };
            let d =
                q[f_index(s.group)] + q[C] * (q[ALPHA] * w.ln()).exp() + q[A] * (-q[B] * w).exp();
            *r = q[M] * s.a + q[k_index(s.group)] * s.u + sign * d - s.f;
        }
    }
    fn jacobian(&self, p: &[f64], j: &mut DMatrix<f64>) {
        let q = self.full(p);
        for (i, s) in self.samples.iter().enumerate() {
            let w = s.v.abs();
            let sign = if s.v > 0.0 {
                1.0
            } else if s.v < 0.0 {
                -1.0
            } else {
                0.0
            };
            let ln_w = w.ln();
            let wa = (q[ALPHA] * ln_w).exp();
            let e = (-q[B] * w).exp();
            for (k, &which) in self.free.iter().enumerate() {
                j[(i, k)] = match which {
                    M => s.a,
                    C => sign * wa,
                    ALPHA => sign * q[C] * wa * ln_w,
                    A => sign * e,
                    B => -sign * q[A] * w * e,
                    x if x == k_index(s.group) => s.u,
                    x if x == f_index(s.group) => sign,
                    _ => 0.0,
                };
            }
        }
    }
}

/// Runs the global fit from the hysteresis-loop estimates. `law_free` says which law
/// parameters were identified (the others stay held); `starts` holds `(Kₑ, F_μ)` per group.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit(
    tests: &[(&Analysed, &[f64], usize)],
    group_keys: &[Option<f64>],
    reference_group: usize,
    mass: f64,
    law: &DissipativeLaw,
    law_free: [bool; 5],
    starts: &[(f64, f64)],
    rate_hz: f64,
    cutoff_hz: f64,
) -> Option<GlobalFit> {
    let groups = group_keys.len();
    // Keep about 4 samples per period of the cut-off: the residual holds nothing faster.
    let mut samples = Vec::new();
    let mut correlation: f64 = 1.0;
    for (an, corr, g) in tests {
        let n = an.rec_u8.len();
        let stride = ((rate_hz / (4.0 * cutoff_hz)).floor() as usize).max(1);
        correlation = correlation.max(rate_hz / stride as f64 / (2.0 * cutoff_hz));
        let mut i = 0;
        while i < n {
            if an.rec_usable[i] && an.rec_v8[i] != 0.0 {
                samples.push(Sample {
                    u: an.rec_u8[i],
                    v: an.rec_v8[i],
                    a: an.rec_a8[i],
                    f: an.rec_f8[i] - corr.get(i).copied().unwrap_or(0.0),
                    group: *g,
                });
            }
            i += stride;
        }
    }
    let mut has_data = vec![false; groups];
    for s in &samples {
        has_data[s.group] = true;
    }
    let mut base = vec![0.0; 5 + 2 * groups];
    base[M] = mass;
    base[C] = law.viscous_coefficient;
    base[ALPHA] = law.viscous_exponent;
    base[A] = law.low_velocity_force_n;
    base[B] = law.low_velocity_decay_s_per_m;
    for (g, &(k, f)) in starts.iter().enumerate() {
        base[k_index(g)] = k;
        base[f_index(g)] = f;
    }
    let mut free = vec![M, C];
    if law_free[law::EXPONENT] {
        free.push(ALPHA);
    }
    if law_free[law::LOW_FORCE] {
        free.push(A);
        free.push(B);
    }
    for (g, &d) in has_data.iter().enumerate() {
        if d {
            free.push(k_index(g));
            free.push(f_index(g));
        }
    }
    if samples.len() <= free.len() * 4 || !has_data[reference_group] {
        return None;
    }
    // Mass positive; C, a, b, F_μ non-negative; α in [0, 1]; b ≤ 10⁴ s/m; stiffness free
    // (it may come out slightly negative at 0 MPa).
    let lower: Vec<f64> = free
        .iter()
        .map(|&i| match i {
            M => f64::MIN_POSITIVE,
            C | ALPHA | A | B => 0.0,
            x if (x - 5) % 2 == 0 => f64::NEG_INFINITY,
            _ => 0.0,
        })
        .collect();
    let upper: Vec<f64> = free
        .iter()
        .map(|&i| match i {
            ALPHA => 1.0,
            B => 1e4,
            _ => f64::INFINITY,
        })
        .collect();
    let problem = GlobalProblem {
        samples,
        free: free.clone(),
        base,
    };
    let start: Vec<f64> = free.iter().map(|&i| problem.base[i]).collect();
    let res = lm::minimize(&problem, &start, &lower, &upper, LmSettings::default());
    let cov = covariance(&res.jacobian, res.ssr, correlation);
    let q = problem.full(&res.params);
    let se =
        |i: usize| -> Option<f64> { free.iter().position(|&x| x == i).map(|k| cov.std_errors[k]) };
    let param = |i: usize| -> Parameter {
        match se(i) {
            Some(s) if s.is_finite() => Parameter::Estimated(Estimate::new(q[i], s, cov.dof)),
            Some(_) => Parameter::NotIdentifiable {
                reason: "singular in the global fit".into(),
            },
            None => Parameter::Fixed {
                value: q[i],
                reason: "held at the hysteresis-loop value".into(),
            },
        }
    };
    let parameters = [
        param(M),
        param(k_index(reference_group)),
        param(f_index(reference_group)),
        param(C),
        param(ALPHA),
        param(A),
        param(B),
    ];
    let group_results = (0..groups)
        .filter(|&g| has_data[g])
        .map(|g| {
            let e = |i: usize| Estimate::new(q[i], se(i).unwrap_or(f64::NAN), cov.dof);
            (group_keys[g], e(k_index(g)), e(f_index(g)))
        })
        .collect();
    Some(GlobalFit {
        parameters,
        groups: group_results,
        rms_residual_n: (res.ssr / problem.samples.len() as f64).sqrt(),
        points: problem.samples.len(),
        converged: res.converged,
        iterations: res.iterations,
        condition_number: cov.condition,
    })
}
