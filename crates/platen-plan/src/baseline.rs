//! From a target to the motion the table is asked for ([`TargetMotion`]): the displacement
//! command that starts and ends at rest, with the velocity and acceleration that go with it.
//!
//! # The baseline treatment of an acceleration target
//!
//! 1. **Integration.** The acceleration is taken as straight lines between its samples and
//!    integrated exactly to velocity and displacement from rest
//!    ([`platen_signal::AccelerogramMotion`] at the target's own rate: the trapezoid for the
//!    velocity, PEER's `.VT2`), after an optional first correction `pre`
//!    ([`platen_signal::Baseline`]: none by default, as a PEER record is already corrected;
//!    `acceleration` removes a least-squares polynomial from the acceleration, `velocity`
//!    from the velocity).
//! 2. **End correction.** A polynomial `P(t)` of degree `d ≥ 3` is subtracted from the
//!    displacement, `P′` from the velocity and `P″` from the acceleration, so that the three
//!    stay one motion. `P` matches the displacement and the velocity at both ends (the cubic
//!    Hermite part), so the corrected motion **starts and ends at rest at zero**, and its
//!    remaining `d − 3` coefficients are the least-squares fit of the displacement in the
//!    basis `s²(1 − s)²·Lⱼ(2s − 1)` (`s = t/T`, Legendre `Lⱼ`), which leave the end values
//!    alone: of all such polynomials it removes the most drift, so it **keeps the
//!    displacement as small as a polynomial can**.
//! 3. **Degree.** [`EndCorrection::Auto`] (the default) takes the lowest degree from 3 to
//!    [`MAX_END_DEGREE`] whose displacement fits the stroke, or the one with the smallest
//!    peak if none does (the target is then reported infeasible on the stroke);
//!    [`EndCorrection::Degree`] fixes it.
//!
//! The correction is a smooth low-order polynomial over the whole record: its acceleration
//! `P″` has its content below about `d/(2T)` Hz (0.06 Hz for `d = 5` over 40 s), under the
//! iteration's band. The summary reports its RMS and peak next to the target's
//! ([`TargetMotion::correction_rms_m_s2`]); the iteration aims at the corrected acceleration,
//! the one a table that starts and ends at rest within its stroke can follow.
//!
//! # A displacement target
//!
//! It is the command as it is; its velocity and acceleration are its derivatives by
//! second-order finite differences on the fitted sampling grid, exactly as `simulate` derives
//! them from a `motion_csv` with `u_m` only (so a drive written to CSV and replayed is the
//! same command).

use platen_integrate::{sampling_grid, Motion};
use platen_signal::{AccelerogramMotion, Baseline, Interpolation, Resampler};

use crate::error::{check_setting, PlanError, Result};
use crate::target::{Target, TargetKind};

/// The highest degree of the end-correction polynomial.
pub const MAX_END_DEGREE: usize = 11;

/// [`EndCorrection::Auto`] takes only degrees whose correction (`P″`) has an RMS of at most
/// this fraction of the target's RMS acceleration: a polynomial of high degree over a short
/// record would remove the record's own long-period content, not its drift.
pub const AUTO_MAX_CORRECTION: f64 = 0.05;

/// The degree of the end-correction polynomial.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EndCorrection {
    /// The lowest degree in `3..=MAX_END_DEGREE` whose displacement fits the stroke (else
    /// the smallest peak).
    #[default]
    Auto,
    /// This degree (`3..=MAX_END_DEGREE`).
    Degree(usize),
}

/// How an acceleration target becomes a displacement command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BaselineSettings {
    /// A correction before integrating (default none).
    pub pre: Baseline,
    /// The end-correction polynomial's degree.
    pub end: EndCorrection,
}

/// The motion the table is asked for: the displacement command and the motion to reproduce.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetMotion {
    /// Time stamps (the target's), s.
    pub t_s: Vec<f64>,
    /// Displacement (the command of iteration 0), m.
    pub u_m: Vec<f64>,
    /// Velocity, m/s.
    pub v_m_s: Vec<f64>,
    /// Acceleration to reproduce, m/s².
    pub a_m_s2: Vec<f64>,
    /// What the target prescribed.
    pub kind: TargetKind,
    /// The end-correction degree used (acceleration targets; `None` for a displacement).
    pub end_degree: Option<usize>,
    /// RMS of the acceleration removed by the baseline treatment, m/s² (0 for a
    /// displacement target).
    pub correction_rms_m_s2: f64,
    /// Largest magnitude of the acceleration removed, m/s².
    pub correction_peak_m_s2: f64,
    /// RMS of the target's own acceleration (before the treatment), m/s².
    pub target_rms_m_s2: f64,
}

impl TargetMotion {
    /// The same motion at `level` times its size (displacement, velocity, acceleration and
    /// the treatment's figures): what a lab iterates on at a low level before scaling up.
    pub fn scaled(&self, level: f64) -> Self {
        let scale = |x: &[f64]| x.iter().map(|v| v * level).collect();
        Self {
            t_s: self.t_s.clone(),
            u_m: scale(&self.u_m),
            v_m_s: scale(&self.v_m_s),
            a_m_s2: scale(&self.a_m_s2),
            kind: self.kind,
            end_degree: self.end_degree,
            correction_rms_m_s2: self.correction_rms_m_s2 * level.abs(),
            correction_peak_m_s2: self.correction_peak_m_s2 * level.abs(),
            target_rms_m_s2: self.target_rms_m_s2 * level.abs(),
        }
    }

    /// The motion of `target` at `rate_hz` (the controller's rate: at least the target's):
    /// for an acceleration, integrated with `settings` (the auto degree aims at `stroke_m`);
    /// for a displacement, as it is. A target sampled slower than `rate_hz` is put on that
    /// rate first, from its first time stamp: an acceleration as straight lines between its
    /// samples (integrated exactly, as PEER integrates a record), a displacement by the
    /// not-a-knot cubic spline ([`platen_signal::Resampler`]).
    ///
    /// # Errors
    /// [`PlanError::Setting`] for an end degree outside `3..=MAX_END_DEGREE` or a rate below
    /// the target's; [`PlanError::Signal`] for a pre-correction order above 8.
    pub fn new(
        target: &Target,
        settings: &BaselineSettings,
        stroke_m: f64,
        rate_hz: f64,
    ) -> Result<Self> {
        let own_hz = target.sample_rate_hz();
        let rate_hz = check_setting(
            "rate_hz",
            rate_hz,
            rate_hz >= own_hz * (1.0 - 1e-9),
            "a rate at least the target's",
        )?;
        // Equal rates (to the grid's fit) keep the target's own stamps.
        let same = (rate_hz - own_hz).abs() <= 1e-9 * own_hz;
        let t_s: Vec<f64> = if same {
            target.t_s().to_vec()
        } else {
            let m =
                Resampler::new(own_hz, rate_hz, Interpolation::Linear)?.output_len(target.len());
            let t0 = target.t_s()[0];
            (0..m).map(|j| t0 + j as f64 / rate_hz).collect()
        };
        match target.kind() {
            TargetKind::Displacement => {
                let u = if same {
                    target.values().to_vec()
                } else {
                    let r = Resampler::new(own_hz, rate_hz, Interpolation::Cubic)?;
                    r.apply(target.values())?
                };
                let (v, a) = derivatives(&t_s, &u)?;
                let rms = rms(&a);
                Ok(Self {
                    t_s,
                    u_m: u,
                    v_m_s: v,
                    a_m_s2: a,
                    kind: TargetKind::Displacement,
                    end_degree: None,
                    correction_rms_m_s2: 0.0,
                    correction_peak_m_s2: 0.0,
                    target_rms_m_s2: rms,
                })
            }
            TargetKind::Acceleration => {
                acceleration_motion(target, settings, stroke_m, t_s, rate_hz)
            }
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Always false: a target has samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The sample interval, s (fitted over the whole record).
    pub fn interval_s(&self) -> f64 {
        sampling_grid(&self.t_s).map_or(f64::NAN, |g| g.interval_s)
    }

    /// The largest displacement magnitude, m.
    pub fn peak_u_m(&self) -> f64 {
        peak(&self.u_m)
    }
}

/// Velocity and acceleration of the displacement `u` at `t`, as `simulate` derives them for a
/// `motion_csv` with `u_m` only: finite differences on the fitted sampling grid.
pub(crate) fn derivatives(t_s: &[f64], u_m: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
    let m = command_motion(t_s, u_m)?;
    Ok((m.v_m_s().to_vec(), m.a_m_s2().to_vec()))
}

/// The command motion of the displacement `u_m` at the stamps `t_s`, exactly as a scenario's
/// `motion_csv` with only `t_s` and `u_m` makes it: the velocity and acceleration by
/// second-order finite differences on the grid fitted to the stamps, the stamps kept.
pub fn command_motion(t_s: &[f64], u_m: &[f64]) -> Result<Motion> {
    let wrap = |source| PlanError::Run {
        what: "the command".to_owned(),
        source,
    };
    let grid = sampling_grid(t_s).map_err(wrap)?;
    let on_grid: Vec<f64> = (0..t_s.len())
        .map(|i| grid.start_s + i as f64 * grid.interval_s)
        .collect();
    let m = Motion::from_displacement(on_grid, u_m.to_vec()).map_err(|e| wrap(e.into()))?;
    Motion::new(
        t_s.to_vec(),
        m.u_m().to_vec(),
        m.v_m_s().to_vec(),
        m.a_m_s2().to_vec(),
    )
    .map_err(|e| wrap(e.into()))
}

fn acceleration_motion(
    target: &Target,
    settings: &BaselineSettings,
    stroke_m: f64,
    t_s: Vec<f64>,
    rate_hz: f64,
) -> Result<TargetMotion> {
    let fs = target.sample_rate_hz();
    let n = t_s.len();
    let (_, mut u, mut v, mut a) = AccelerogramMotion::new(fs, rate_hz, settings.pre)?
        .process(target.values())?
        .truncated(n)?
        .into_columns();
    // The target's straight lines at the drive's samples, before any correction: what the
    // treatment's correction is measured against.
    let raw = if settings.pre == Baseline::None {
        a.clone()
    } else {
        let (_, _, _, raw) = AccelerogramMotion::new(fs, rate_hz, Baseline::None)?
            .process(target.values())?
            .truncated(n)?
            .into_columns();
        raw
    };
    let span_s = (n - 1) as f64 / rate_hz;
    let degrees = end_degrees(settings.end)?;
    let (degree, p) = choose_end(&u, &v, span_s, degrees, settings, stroke_m, rms(&raw));
    let (mut sum2, mut peak_c) = (0.0, 0.0_f64);
    for i in 0..n {
        let s = i as f64 / (n - 1) as f64;
        let (pv, pd, pdd) = p.all(s);
        u[i] -= pv;
        v[i] -= pd;
        a[i] -= pdd;
        // What the treatment removed from the target's acceleration (with `pre`).
        let removed = raw[i] - a[i];
        sum2 += removed * removed;
        peak_c = peak_c.max(removed.abs());
    }
    Ok(TargetMotion {
        t_s,
        u_m: u,
        v_m_s: v,
        a_m_s2: a,
        kind: TargetKind::Acceleration,
        end_degree: Some(degree),
        correction_rms_m_s2: (sum2 / n as f64).sqrt(),
        correction_peak_m_s2: peak_c,
        target_rms_m_s2: rms(target.values()),
    })
}

/// The end polynomial's degrees to try: the one asked for (checked), or every one for
/// [`EndCorrection::Auto`].
fn end_degrees(end: EndCorrection) -> Result<Vec<usize>> {
    Ok(match end {
        EndCorrection::Degree(d) => {
            if !(3..=MAX_END_DEGREE).contains(&d) {
                return Err(PlanError::Setting {
                    name: "end_degree",
                    value: d as f64,
                    expected: "a polynomial degree in 3..=11",
                });
            }
            vec![d]
        }
        EndCorrection::Auto => (3..=MAX_END_DEGREE).collect(),
    })
}

/// The end polynomial of `u`, `v` (sampled uniformly over `span_s`) among `degrees`, and its
/// degree. Auto: among the degrees whose correction stays small (its RMS at most
/// AUTO_MAX_CORRECTION of the target's, `target_rms`), the lowest that fits the stroke, else
/// the one with the smallest peak; degree 3 (the least correction) when none stays small.
fn choose_end(
    u: &[f64],
    v: &[f64],
    span_s: f64,
    degrees: Vec<usize>,
    settings: &BaselineSettings,
    stroke_m: f64,
    target_rms: f64,
) -> (usize, EndPolynomial) {
    let n = u.len();
    let mut chosen: Option<(usize, EndPolynomial, f64)> = None;
    for d in degrees {
        let p = EndPolynomial::fit(u, v, span_s, d);
        let (mut peak_u, mut sum2) = (0.0_f64, 0.0);
        for (i, &ui) in u.iter().enumerate() {
            let (pv, _, pdd) = p.all(i as f64 / (n - 1) as f64);
            peak_u = peak_u.max((ui - pv).abs());
            sum2 += pdd * pdd;
        }
        let small = (sum2 / n as f64).sqrt() <= AUTO_MAX_CORRECTION * target_rms;
        let fixed = settings.end != EndCorrection::Auto;
        let first = chosen.is_none();
        if fixed || first || (small && chosen.as_ref().is_none_or(|c| peak_u < c.2)) {
            chosen = Some((
                d,
                p,
                if small || fixed {
                    peak_u
                } else {
                    f64::INFINITY
                },
            ));
        }
        if small && peak_u <= stroke_m {
            break;
        }
    }
    let Some((degree, p, _)) = chosen else {
        unreachable!("at least one degree is tried")
    };
    (degree, p)
}

/// `P(s) = H(s) + w(s)·Σ cⱼLⱼ(2s − 1)`, `w = s²(1 − s)²`, `s = t/T`: the end-matching
/// polynomial (see the module docs). Values in metres; derivatives with respect to time.
#[derive(Debug, Clone)]
struct EndPolynomial {
    span_s: f64,
    /// Hermite end data: `u(0)`, `T·v(0)`, `u(T)`, `T·v(T)`.
    ends: [f64; 4],
    coefficients: Vec<f64>,
}

impl EndPolynomial {
    /// The fit of degree `degree ≥ 3` to `u` (with velocity `v` for the end slopes) sampled
    /// uniformly over `span_s`.
    fn fit(u: &[f64], v: &[f64], span_s: f64, degree: usize) -> Self {
        let n = u.len();
        let last = n - 1;
        let ends = [u[0], span_s * v[0], u[last], span_s * v[last]];
        let free = degree.saturating_sub(3).min(n.saturating_sub(4));
        let mut p = Self {
            span_s,
            ends,
            coefficients: Vec::new(),
        };
        if free == 0 {
            return p;
        }
        // Normal equations of the residual u − H in the basis w·Lⱼ.
        let mut g = vec![0.0; free * free];
        let mut b = vec![0.0; free];
        let mut basis = vec![0.0; free];
        let mut scratch = Scratch::new(free);
        for (i, &ui) in u.iter().enumerate() {
            let s = i as f64 / last as f64;
            let r = ui - hermite(&ends, s).0;
            let w = s * s * (1.0 - s) * (1.0 - s);
            scratch.legendre(2.0 * s - 1.0);
            for (slot, pj) in basis.iter_mut().zip(&scratch.p) {
                *slot = w * pj;
            }
            for (row, (br, &fr)) in b.iter_mut().zip(&basis).enumerate() {
                *br += fr * r;
                for (gc, &fc) in g[row * free..(row + 1) * free].iter_mut().zip(&basis) {
                    *gc += fr * fc;
                }
            }
        }
        p.coefficients = platen_signal::linalg::solve(&mut g, &mut b, free);
        p
    }

    /// `(P, dP/dt, d²P/dt²)` at `s = t/T`.
    fn all(&self, s: f64) -> (f64, f64, f64) {
        let (h, dh, ddh) = hermite(&self.ends, s);
        let (mut q, mut dq, mut ddq) = (0.0, 0.0, 0.0);
        if !self.coefficients.is_empty() {
            let mut scratch = Scratch::new(self.coefficients.len());
            scratch.legendre(2.0 * s - 1.0);
            for (j, c) in self.coefficients.iter().enumerate() {
                // d/ds of L(2s − 1) = 2L′, d²/ds² = 4L″.
                q += c * scratch.p[j];
                dq += c * 2.0 * scratch.dp[j];
                ddq += c * 4.0 * scratch.ddp[j];
            }
        }
        let w = s * s * (1.0 - s) * (1.0 - s);
        let dw = 2.0 * s - 6.0 * s * s + 4.0 * s * s * s;
        let ddw = 2.0 - 12.0 * s + 12.0 * s * s;
        let t = self.span_s;
        (
            h + w * q,
            (dh + dw * q + w * dq) / t,
            (ddh + ddw * q + 2.0 * dw * dq + w * ddq) / (t * t),
        )
    }
}

/// The cubic Hermite interpolant of `[u0, T·v0, u1, T·v1]` at `s` and its first two
/// derivatives with respect to `s`.
fn hermite(e: &[f64; 4], s: f64) -> (f64, f64, f64) {
    let (s2, s3) = (s * s, s * s * s);
    let h = [
        2.0 * s3 - 3.0 * s2 + 1.0,
        s3 - 2.0 * s2 + s,
        -2.0 * s3 + 3.0 * s2,
        s3 - s2,
    ];
    let dh = [
        6.0 * s2 - 6.0 * s,
        3.0 * s2 - 4.0 * s + 1.0,
        -6.0 * s2 + 6.0 * s,
        3.0 * s2 - 2.0 * s,
    ];
    let ddh = [
        12.0 * s - 6.0,
        6.0 * s - 4.0,
        -12.0 * s + 6.0,
        6.0 * s - 2.0,
    ];
    let dot = |b: &[f64; 4]| e.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    (dot(&h), dot(&dh), dot(&ddh))
}

/// Legendre polynomials and their first two derivatives at one point.
struct Scratch {
    p: Vec<f64>,
    dp: Vec<f64>,
    ddp: Vec<f64>,
}

impl Scratch {
    fn new(len: usize) -> Self {
        Self {
            p: vec![0.0; len],
            dp: vec![0.0; len],
            ddp: vec![0.0; len],
        }
    }

    /// `Lⱼ(x)`, `L′ⱼ`, `L″ⱼ` by `(j + 1)Lⱼ₊₁ = (2j + 1)xLⱼ − jLⱼ₋₁` differentiated.
    fn legendre(&mut self, x: f64) {
        let len = self.p.len();
        self.p[0] = 1.0;
        self.dp[0] = 0.0;
        self.ddp[0] = 0.0;
        if len > 1 {
            self.p[1] = x;
            self.dp[1] = 1.0;
            self.ddp[1] = 0.0;
        }
        for j in 1..len.saturating_sub(1) {
            let jf = j as f64;
            let a = 2.0 * jf + 1.0;
            self.p[j + 1] = (a * x * self.p[j] - jf * self.p[j - 1]) / (jf + 1.0);
            self.dp[j + 1] = (a * (self.p[j] + x * self.dp[j]) - jf * self.dp[j - 1]) / (jf + 1.0);
            self.ddp[j + 1] =
                (a * (2.0 * self.dp[j] + x * self.ddp[j]) - jf * self.ddp[j - 1]) / (jf + 1.0);
        }
    }
}

/// Root mean square (about zero).
pub(crate) use platen_signal::metrics::rms;

/// Largest magnitude.
pub(crate) fn peak(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_end_polynomial_matches_values_slopes_and_a_polynomial_exactly() {
        // u = a degree-6 polynomial in s: a degree-6 fit removes all of it.
        let n = 2001;
        let span = 20.0;
        let f = |s: f64| 0.1 + 0.3 * s - 2.0 * s * s + 1.5 * s.powi(4) - 0.7 * s.powi(6);
        let df = |s: f64| (0.3 - 4.0 * s + 6.0 * s.powi(3) - 4.2 * s.powi(5)) / span;
        let u: Vec<f64> = (0..n).map(|i| f(i as f64 / (n - 1) as f64)).collect();
        let v: Vec<f64> = (0..n).map(|i| df(i as f64 / (n - 1) as f64)).collect();
        let p = EndPolynomial::fit(&u, &v, span, 6);
        for i in (0..n).step_by(97) {
            let s = i as f64 / (n - 1) as f64;
            let (pv, pd, pdd) = p.all(s);
            assert!((pv - f(s)).abs() < 1e-10, "{s}: {pv} vs {}", f(s));
            assert!((pd - df(s)).abs() < 1e-10);
            let ddf = (-4.0 + 18.0 * s * s - 21.0 * s.powi(4)) / (span * span);
            assert!((pdd - ddf).abs() < 1e-10);
        }
        // A cubic only matches the ends.
        let c = EndPolynomial::fit(&u, &v, span, 3);
        assert!((c.all(0.0).0 - f(0.0)).abs() < 1e-14);
        assert!((c.all(1.0).0 - f(1.0)).abs() < 1e-14);
        assert!((c.all(1.0).1 - df(1.0)).abs() < 1e-14);
    }
}
