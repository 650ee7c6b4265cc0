//! Creep: slip at speeds so low that the friction law is too stiff for an explicit step.
//!
//! # Why
//!
//! With a law `D(w) = F_μ + C·w^α + a·e^(−b·w)` and `α < 1`, the slope `D′(w) = α·C·w^(α−1)`
//! is unbounded as the speed `w = |v|` goes to zero. A platen whose net force `N = F_A − F_E(u)`
//! barely exceeds the static threshold `F_s = D(0⁺)` leaves rest and settles at the **creep
//! speed** `w_c` that solves `D(w_c) = |N|`, with a relaxation time `τ(w) = M/D′(w)` that can be
//! far shorter than any step (for `|N| − F_s` = 1e-6 N on the paper's model, `τ` ≈ 1e-13 s).
//! An explicit step (RK4, Dopri5) at `h ≫ τ` overshoots `v = 0`, which used to be read as a
//! stop or a reversal: the run chattered, moved the wrong way, or stalled.
//!
//! # Method
//!
//! Where `h/τ` is large, the velocity is slaved to the force: the singular-perturbation limit
//! of `M·ẇ = s·N(t, u) − D(u, w)` (`s` the slip direction) is the quasi-static creep
//!
//! ```text
//!     D(u, w) + s·F_vi(u, s·w) = s·N(t, u),    u̇ = s·w,
//! ```
//!
//! whose error is the neglected inertia, `|w − w_qs| ≈ τ·|ẇ_qs|`. The platen is in creep while
//! `w_qs` is below the **stiff speed** `w_*` at which the law's secant stiffness
//! `(D(u, w) − F_s(u))/w` equals `M(u)/h` (so `h/τ ≥ α` below it and an explicit step of length
//! `h` is stable and accurate above it). The displacement error of a creep phase is then at
//! most about `h·w_*` per entry or exit (2e-11 m at 1024 Hz on the paper's model).
//!
//! A creep phase ends
//!
//! * in a **stop**, where `s·N` falls to `F_s(u)` (then `w_qs = 0` and friction holds: `|N| ≤
//!   F_s` is checked at the state reached, never assumed), or
//! * in **slip**, where `w_qs` reaches `w_*`, with `v = s·w_qs` (the two descriptions agree
//!   there to the bound above), or
//! * in a **reversal**, where the net force at the stop is beyond the threshold against the
//!   motion: without static friction (`F_s = 0`) the stop level is `N = 0` and the platen
//!   creeps through `v = 0` into the other direction. A pass whose end rounds onto its start
//!   is moved [`just_past`] it, so a creep never stalls in place.
//!
//! Both times are solved exactly for the force, which is linear inside the span, at the
//! displacement of the start of the span, then corrected for the (sub-nanometre) creep
//! displacement; the reduced equation `u̇ = s·w_qs(t, u)` (with the actuator work and the
//! dissipated energy) is integrated by RK4 on the same span.

use platen_model::PlatenModel;

use crate::event::{just_past, Direction};
use crate::run::Kin;

/// Sub-steps of the reduced creep equation per span. `w_qs(t)` is smooth inside a span (the
/// span ends at a stop or exit), so RK4 on two sub-steps is far below the creep error bound.
const CREEP_SUBSTEPS: u32 = 2;

/// Bisection steps on `log₂ w` (over about 2·10³ binades: 11 halve the bracket to one binade)
/// and Illinois iterations inside that binade.
const LOG_BISECTIONS: u32 = 12;
const ROOT_ITERATIONS: u32 = 60;

/// A pass of [`creep`] that ends this close to where it started (s) has not moved time in the
/// callers' units (a fraction of a step, or seconds into a sample interval): it is stepped
/// just past instead ([`just_past`], whose first increment is `4ε` s).
const MIN_PROGRESS_S: f64 = 4.0 * f64::EPSILON;

/// The lowest speed considered, m/s: below it the platen does not move in any double-precision
/// sense over any time a record can last (1e-300 m/s × 1e9 s).
const SPEED_FLOOR_M_S: f64 = 1e-300;

/// Whether the speed `w` (≥ 0; 0 is below any) is below the stiff speed of a step of length `h_s` at
/// displacement `u` ([`stiff_speed_m_s`]): one evaluation of the law instead of a search.
pub(crate) fn below_stiff_speed<M: PlatenModel>(model: &M, u: f64, w: f64, h_s: f64) -> bool {
    w <= 0.0 || model.dissipative_excess_n(u, w) / w >= model.mass_kg(u) / h_s
}

/// The stiff speed `w_*`, m/s, of the law at displacement `u` for a step of length `h_s`: the
/// speed at which the secant stiffness `(D(u, w) − F_s(u))/w` equals `M(u)/h_s`. Zero if the law
/// is nowhere that stiff (an exponent `α ≥ 1` with a modest viscous coefficient).
pub(crate) fn stiff_speed_m_s<M: PlatenModel>(model: &M, u: f64, h_s: f64) -> f64 {
    let limit = model.mass_kg(u) / h_s;
    let stiff = |w: f64| model.dissipative_excess_n(u, w) / w >= limit;
    let (mut lo, mut hi) = (SPEED_FLOOR_M_S.log2(), 1.0f64);
    if !stiff(SPEED_FLOOR_M_S) {
        return 0.0;
    }
    if stiff(hi.exp2()) {
        return hi.exp2();
    }
    // Bisection on log₂ w to a few parts in 1e6 of a binade: the boundary need not be exact.
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if stiff(mid.exp2()) {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-6 {
            break;
        }
    }
    lo.exp2()
}

/// The quasi-static creep speed `w_qs ≥ 0`, m/s, in direction `dir` at displacement `u` under
/// actuator force `f`: the root of `φ(w) = D(u, w) + s·F_vi(u, s·w) − s·N` on `[0, w_max]`.
/// Zero if `s·N ≤ F_s(u)` (friction holds); `None` if `φ(w_max) < 0` (the creep speed is above
/// `w_max`: the platen slips).
pub(crate) fn creep_speed_m_s<M: PlatenModel>(
    model: &M,
    dir: Direction,
    u: f64,
    f: f64,
    w_max: f64,
) -> Option<f64> {
    let s = dir.sign();
    let drive = s * (f - model.elastic_force_n(u));
    let threshold = model.static_threshold_n(u);
    if drive <= threshold {
        return Some(0.0);
    }
    // The excess of the drive over the threshold: a difference of two nearby numbers, exact.
    let excess = drive - threshold;
    let phi = |w: f64| {
        model.dissipative_excess_n(u, w) + s * model.velocity_inertial_force_n(u, s * w) - excess
    };
    if w_max.is_nan() || w_max <= 0.0 || phi(w_max) < 0.0 {
        return None;
    }
    // φ(0⁺) < 0 ≤ φ(w_max). Bracket the root within one binade by bisection on log₂ w, then
    // Illinois inside it (φ is smooth and monotone there).
    let (mut e_lo, mut e_hi) = (SPEED_FLOOR_M_S.log2(), w_max.log2());
    if phi(SPEED_FLOOR_M_S) >= 0.0 {
        return Some(0.0);
    }
    for _ in 0..LOG_BISECTIONS {
        if e_hi - e_lo <= 1.0 {
            break;
        }
        let mid = 0.5 * (e_lo + e_hi);
        if phi(mid.exp2()) < 0.0 {
            e_lo = mid;
        } else {
            e_hi = mid;
        }
    }
    let (mut lo, mut hi) = (e_lo.exp2(), e_hi.exp2().min(w_max));
    let (mut g_lo, mut g_hi) = (phi(lo), phi(hi));
    let mut side = 0i8;
    for _ in 0..ROOT_ITERATIONS {
        if g_hi == 0.0 || hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let mut w = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        if !(w > lo && w < hi) {
            w = 0.5 * (lo + hi);
        }
        let g = phi(w);
        if g < 0.0 {
            (lo, g_lo) = (w, g);
            if side == 1 {
                g_hi *= 0.5;
            }
            side = 1;
        } else {
            (hi, g_hi) = (w, g);
            if side == -1 {
                g_lo *= 0.5;
            }
            side = -1;
        }
    }
    Some(hi)
}

/// How a creep span ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CreepEnd {
    /// Still creeping at the end of the span.
    Continues,
    /// `s·N` fell to `F_s`: the platen is at rest with `|N| ≤ F_s(u)` (a stop).
    Stops,
    /// The creep speed reached the stiff speed: slip resumes with the state's velocity.
    Slips,
    /// `s·N` fell below `−F_s`: the platen is at rest (`v = 0`) with the net force beyond the
    /// threshold against the motion, so it leaves rest the other way (a reversal). Without
    /// static friction (`F_s = 0`) this is how creep passes through `v = 0`.
    Reverses,
}

/// The result of [`creep`]: where it ended, in seconds from the start of the span, and the
/// state there (`v` = the signed creep speed, zero at a stop).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CreepRun {
    pub y: Kin,
    pub at_s: f64,
    pub end: CreepEnd,
    /// Evaluations of the reduced right-hand side (for the run's statistics).
    pub evaluations: u64,
}

/// Creeps in direction `dir` from `y` over a span of `span_s` seconds in which the actuator
/// force goes linearly from `f_start` to `f_end`, with stiff speed `w_stiff` (see the module
/// docs), until the end of the span, a stop or the return to slip.
pub(crate) fn creep<M: PlatenModel>(
    model: &M,
    dir: Direction,
    y: Kin,
    f_start: f64,
    f_end: f64,
    span_s: f64,
    w_stiff: f64,
) -> CreepRun {
    let s = dir.sign();
    let force = |x: f64| {
        let w = x / span_s;
        if w >= 1.0 {
            f_end
        } else {
            f_start * (1.0 - w) + f_end * w
        }
    };
    let mut run = CreepRun {
        y,
        at_s: 0.0,
        end: CreepEnd::Continues,
        evaluations: 0,
    };
    // At most a few passes: the first solves the end time at the start's displacement, the
    // next ones correct it for the creep displacement (which only moves a stop later).
    for _ in 0..4 {
        let x_pass = run.at_s;
        let u = run.y.u;
        let (end, x_end) = pass_end(model, dir, u, run.at_s, span_s, w_stiff, &force);
        run.y = advance(
            model, dir, run.y, run.at_s, x_end, &force, w_stiff, &mut run,
        );
        run.at_s = x_end;
        match end {
            CreepEnd::Stops => match at_stop(model, dir, &mut run, x_pass, span_s, &force, w_stiff)
            {
                Pass::Ended => return run,
                Pass::Again => {}
                Pass::SpanDone => break,
            },
            CreepEnd::Slips => {
                let f = force(x_end);
                let w = creep_speed_m_s(model, dir, run.y.u, f, w_stiff).unwrap_or(w_stiff);
                // A velocity that is not zero: the slip that follows does not start from rest.
                run.y.v = s * w.max(f64::MIN_POSITIVE);
                run.end = CreepEnd::Slips;
                return run;
            }
            CreepEnd::Continues | CreepEnd::Reverses => break,
        }
    }
    // Still creeping at `at_s`: the end of the span, or (if rounding kept the stop test from
    // holding in every pass) where the caller resumes the creep.
    let w = creep_speed_m_s(model, dir, run.y.u, force(run.at_s), w_stiff).unwrap_or(w_stiff);
    run.y.v = s * w;
    run.end = CreepEnd::Continues;
    run
}

/// Where a pass of [`creep`] from `at_s` ends, with the displacement `u` held (the drive
/// `s·(F_A − F_E(u))` is then linear in time): at the stop level `F_s`, at the exit level
/// (the creep speed reaching `w_stiff`), or at the end of the span.
fn pass_end<M: PlatenModel>(
    model: &M,
    dir: Direction,
    u: f64,
    at_s: f64,
    span_s: f64,
    w_stiff: f64,
    force: &impl Fn(f64) -> f64,
) -> (CreepEnd, f64) {
    let s = dir.sign();
    let elastic = model.elastic_force_n(u);
    let drive = |x: f64| s * (force(x) - elastic);
    let (d0, d1) = (drive(at_s), drive(span_s));
    let threshold = model.static_threshold_n(u);
    let exit_level = threshold
        + model.dissipative_excess_n(u, w_stiff)
        + s * model.velocity_inertial_force_n(u, s * w_stiff);
    // The drive is linear in time at fixed u: where does it reach the stop or exit level?
    let rest = span_s - at_s;
    let crossing = |level: f64| {
        let x = at_s + rest * ((d0 - level) / (d0 - d1)).clamp(0.0, 1.0);
        x.min(span_s)
    };
    if d0 <= threshold {
        (CreepEnd::Stops, at_s)
    } else if d1 <= threshold {
        (CreepEnd::Stops, crossing(threshold))
    } else if d0 >= exit_level {
        (CreepEnd::Slips, at_s)
    } else if d1 >= exit_level {
        (CreepEnd::Slips, crossing(exit_level))
    } else {
        (CreepEnd::Continues, span_s)
    }
}

/// What the stop a pass of [`creep`] reached leaves.
enum Pass {
    /// At rest: a stop or a reversal (`run` is finished).
    Ended,
    /// Rounding left the drive a hair above the stop level: another pass from here.
    Again,
    /// As `Again`, but the span is over.
    SpanDone,
}

/// The stop a pass of [`creep`] reached at `run.at_s` (the pass started at `x_pass`): at rest
/// if `|N| ≤ F_s` there, a reversal if `N` is beyond the threshold against the motion, else
/// (rounding) another pass, stepped [`just_past`] the start if it did not move time.
fn at_stop<M: PlatenModel>(
    model: &M,
    dir: Direction,
    run: &mut CreepRun,
    x_pass: f64,
    span_s: f64,
    force: &impl Fn(f64) -> f64,
    w_stiff: f64,
) -> Pass {
    let (s, x_end) = (dir.sign(), run.at_s);
    let u_end = run.y.u;
    let net = force(x_end) - model.elastic_force_n(u_end);
    let threshold_end = model.static_threshold_n(u_end);
    if net.abs() <= threshold_end {
        run.y.v = 0.0;
        run.end = CreepEnd::Stops;
        return Pass::Ended;
    }
    if s * net < -threshold_end {
        // The net force is beyond the threshold against the motion: the platen passed
        // through rest (with no static friction, `F_s = 0`, the stop level is `N = 0`, and
        // rounding puts `N` on either side of it).
        run.y.v = 0.0;
        run.end = CreepEnd::Reverses;
        return Pass::Ended;
    }
    // Rounding left |N| above the threshold at the new displacement: solve again from here
    // (the stop can only be later).
    if x_end >= span_s {
        return Pass::SpanDone;
    }
    if x_end - x_pass <= MIN_PROGRESS_S {
        // The crossing rounded onto the start of the pass, where the drive is a hair above
        // the stop level: step just past it, where it is not, so every pass moves time
        // forward by more than the callers' rounding.
        let elastic = model.elastic_force_n(u_end);
        let next = just_past(x_end, span_s, |x| s * (force(x) - elastic) <= threshold_end);
        run.y = advance(model, dir, run.y, run.at_s, next, force, w_stiff, run);
        run.at_s = next;
    }
    Pass::Again
}

/// RK4 on the reduced creep equation (`u̇ = s·w_qs`, with the actuator work and the dissipated
/// energy) from local time `x0` to `x1`.
#[allow(clippy::too_many_arguments)]
fn advance<M: PlatenModel>(
    model: &M,
    dir: Direction,
    y: Kin,
    x0: f64,
    x1: f64,
    force: &impl Fn(f64) -> f64,
    w_stiff: f64,
    run: &mut CreepRun,
) -> Kin {
    if x1 <= x0 {
        return y;
    }
    let s = dir.sign();
    // The rates of the reduced equation: (u̇, Ẇ, Ė_D) at local time x and displacement u.
    let mut rates = |x: f64, u: f64| {
        let f = force(x);
        run.evaluations += 1;
        let w = creep_speed_m_s(model, dir, u, f, w_stiff).unwrap_or(w_stiff);
        let d = model.dissipative_magnitude_n(u, w);
        (s * w, f * s * w, d * w)
    };
    let h = (x1 - x0) / f64::from(CREEP_SUBSTEPS);
    let mut y = y;
    for i in 0..CREEP_SUBSTEPS {
        let x = x0 + f64::from(i) * h;
        let k1 = rates(x, y.u);
        let k2 = rates(x + 0.5 * h, y.u + 0.5 * h * k1.0);
        let k3 = rates(x + 0.5 * h, y.u + 0.5 * h * k2.0);
        let k4 = rates(x + h, y.u + h * k3.0);
        let h6 = h / 6.0;
        y.u += h6 * (k1.0 + 2.0 * (k2.0 + k3.0) + k4.0);
        y.work += h6 * (k1.1 + 2.0 * (k2.1 + k3.1) + k4.1);
        y.dissipated += h6 * (k1.2 + 2.0 * (k2.2 + k3.2) + k4.2);
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_model::{IdentifiedModel, IdentifiedParams};

    /// A model that is not the paper's: α = 0.7, F_s = 26 kN.
    fn model() -> IdentifiedModel {
        IdentifiedParams {
            effective_mass_kg: 95e3,
            stiffness_n_per_m: 2.1e6,
            coulomb_force_n: 18e3,
            viscous_coefficient: 30e3,
            viscous_exponent: 0.7,
            low_velocity_force_n: 8e3,
            low_velocity_decay_s_per_m: 50.0,
        }
        .build()
        .unwrap()
    }

    /// The creep speed solves `C·w^α + a·(e^(−bw) − 1) = N − F_s` (written out here, not
    /// through the model) to 1e-12 relative, and approaches the closed form
    /// `((N − F_s)/C)^(1/α)` where the Stribeck term `a·b·w` is negligible.
    #[test]
    fn the_creep_speed_balances_the_law() {
        let m = model();
        for excess in [f64::EPSILON * 26e3 / 2.0, 1e-9, 1e-6, 1e-3, 1.0, 100.0] {
            let f = 26e3 + excess;
            let excess = f - 26e3;
            let w = creep_speed_m_s(&m, Direction::Positive, 0.0, f, 1.0).unwrap();
            let law = 30e3 * w.powf(0.7) + 8e3 * (-50.0 * w).exp_m1();
            assert!(
                (law / excess - 1.0).abs() <= 1e-12,
                "{excess}: {law} vs {excess}"
            );
            let closed = (excess / 30e3).powf(1.0 / 0.7);
            if 8e3 * 50.0 * closed < 1e-6 * excess {
                assert!((w / closed - 1.0).abs() < 1e-5, "{excess}: {w} vs {closed}");
            }
        }
        assert_eq!(
            creep_speed_m_s(&m, Direction::Positive, 0.0, 26e3, 1.0),
            Some(0.0)
        );
        assert_eq!(
            creep_speed_m_s(&m, Direction::Negative, 0.0, -26e3 - 1.0, 1e-12),
            None
        );
    }

    /// The stiff speed is where h/τ crosses α: at 1024 Hz on this model about 2e-10 m/s
    /// ((α·C·h/M)^(1/(1−α)) = (0.7·30e3/(95e3·1024))^(1/0.3)).
    #[test]
    fn the_stiff_speed_is_where_the_secant_stiffness_is_m_over_h() {
        let m = model();
        let h = 1.0 / 1024.0;
        let w = stiff_speed_m_s(&m, 0.0, h);
        let secant = (30e3 * w.powf(0.7) + 8e3 * (-50.0 * w).exp_m1()) / w;
        assert!((secant * h / 95e3 - 1.0).abs() < 1e-4, "{w}: {secant}");
        let estimate = (30e3 * h / 95e3f64).powf(1.0 / 0.3);
        assert!((w / estimate - 1.0).abs() < 0.05, "{w} vs {estimate}");
    }
}
