//! Stick-slip events, the one place where their logic lives: both forward integrators (RK4 in
//! `rk4.rs`, Dopri5 in `dopri5.rs`) call it and hold none of their own.
//!
//! # Model
//!
//! At `v = 0` the friction is set-valued, so the platen is in one of four [`Mode`]s: slip+ and
//! slip− (the smooth right-hand side with the friction direction fixed), stick (`u` fixed,
//! `v = a = 0`), and creep± (slip so slow that the law is too stiff for an explicit step: the
//! quasi-static limit of [`crate::creep`]). The stick-slip mode changes only at an event
//! ([`EventKind`]):
//!
//! * **stop** or **reversal**: in slip, the velocity reaches zero. Every crossing inside a
//!   step is found: a step is accepted only if the speed is positive at each of its stages, at
//!   its end, and on its cubic Hermite interpolant ([`dip_to_zero`]), otherwise it is halved
//!   until a piece is safe or ends across zero (so two reversals inside one step are both
//!   located). [`locate_zero_velocity`] then finds the crossing (Illinois root finding on the
//!   length of the integrator's own step from a point before it, so the state there is one the
//!   integrator produced); the integrator sets `v` to exactly zero and applies the reset
//!   [`arrive_at_rest`]: the net force `N = F_A − F_E(u)` decides stick if `|N| ≤ F_s(u)`,
//!   slip the other way if it is beyond the threshold against the motion, and creep on if it
//!   is beyond the threshold along the motion (the exact solution cannot reach rest there; the
//!   step was too long for the stiff law, and this is not counted as an event);
//! * **breakaway**: in stick, [`breakaway`] solves the time at which `|N|` reaches `F_s(u)`
//!   exactly, since `F_A` is linear between the force record's samples; [`just_past`] moves it
//!   past rounding so that slip starts where `|N| > F_s` holds.
//!
//! A platen that leaves rest with a creep speed below the stiff speed for the rest of the step
//! creeps from the start; creep ends in a stop (where `|N|` falls to `F_s`, checked) or in
//! slip (where the creep speed reaches the stiff speed). A stick decision is only ever taken
//! where `|N| ≤ F_s(u)` holds at the state reached.
//!
//! # Interface
//!
//! An integrator advances inside one step (RK4: a grid step, Dopri5: a sample interval) in
//! the current mode until it reports a [`StepStop`]: [`StepStop::Step`] (the end of the step
//! was reached), [`StepStop::Event`] (an event was located and its reset applied) or
//! [`StepStop::Moved`] (part of the step was done without an event), and gives up after
//! [`MAX_EVENTS_PER_STEP`] of those in one step (a guard against a defect: every one of them
//! moves time forward or changes the mode in a way that cannot repeat in place). The
//! integrators measure time inside a step in their own units (RK4: the fraction `τ` of the grid
//! step; Dopri5: seconds from the segment's start); every function here works on the fraction
//! or length it is given and returns one in the same units.

use platen_model::PlatenModel;

/// Largest number of stick-slip events and partial advances tolerated inside one step before
/// the run is declared stalled. Every event and advance moves time forward or changes the mode
/// in a way that cannot repeat without time moving (see [`arrive_at_rest`] and [`just_past`]),
/// so this is a guard against a defect, not a limit a run is expected to reach.
pub(crate) const MAX_EVENTS_PER_STEP: u32 = 4096;

/// Iteration cap of the event root-finder (it converges in about ten).
const MAX_ROOT_ITERATIONS: u32 = 100;

/// A stick-slip event: where the friction mode changes.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// Slip → stick: the platen came to rest and friction held it.
    Stop,
    /// Slip → slip the other way: the velocity crossed zero and the net force exceeded the
    /// friction threshold.
    Reversal,
    /// Stick → slip: the net force reached the friction threshold.
    Breakaway,
}

/// Direction of slip (and of the friction force's opposite).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Direction {
    /// `v > 0`.
    Positive,
    /// `v < 0`.
    Negative,
}

impl Direction {
    /// The direction of the sign of `x` (`−0.0` is negative), as `1.0f64.copysign(x)`.
    #[inline(always)]
    pub(crate) fn of_sign(x: f64) -> Self {
        if x.is_sign_negative() {
            Direction::Negative
        } else {
            Direction::Positive
        }
    }

    /// The other direction.
    #[inline(always)]
    pub(crate) fn opposite(self) -> Self {
        match self {
            Direction::Positive => Direction::Negative,
            Direction::Negative => Direction::Positive,
        }
    }

    /// `+1.0` or `−1.0`.
    #[inline(always)]
    pub(crate) fn sign(self) -> f64 {
        match self {
            Direction::Positive => 1.0,
            Direction::Negative => -1.0,
        }
    }
}

/// The friction mode of the platen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// At rest, held by friction.
    Stick,
    /// Slipping in a direction.
    Slip(Direction),
    /// Creeping in a direction: slip at speeds where the law is too stiff for an explicit
    /// step, with the velocity slaved to the force (see [`crate::creep`]).
    Creep(Direction),
}

impl Mode {
    /// The mode of a run that starts at `(u, v)` under actuator force `f`: slip in the
    /// direction of a non-zero velocity, else [`mode_at_rest`].
    #[inline]
    pub(crate) fn initial<M: PlatenModel>(model: &M, u: f64, v: f64, f: f64) -> Self {
        if v > 0.0 {
            Mode::Slip(Direction::Positive)
        } else if v < 0.0 {
            Mode::Slip(Direction::Negative)
        } else {
            mode_at_rest(model, u, f)
        }
    }
}

/// Mode of a platen at rest at `u` under actuator force `f`: stick inside the friction cone,
/// otherwise slip towards the net force.
#[inline]
pub(crate) fn mode_at_rest<M: PlatenModel>(model: &M, u: f64, f: f64) -> Mode {
    let net = f - model.elastic_force_n(u);
    if net.abs() <= model.static_threshold_n(u) {
        Mode::Stick
    } else {
        Mode::Slip(Direction::of_sign(net))
    }
}

/// The reset at a located `v = 0` reached in slip in direction `from` (the caller sets the
/// velocity to exactly zero): the mode that follows and the event, if one happened.
///
/// * `|N| ≤ F_s(u)`: stick, a [`EventKind::Stop`];
/// * `N` beyond the threshold against `from`: slip the other way, a [`EventKind::Reversal`];
/// * `N` beyond the threshold along `from`: no event. The exact solution cannot reach `v = 0`
///   there (the net force still drives the platen on, so it settles at its creep speed); the
///   step that crossed zero was too long for the stiff law at that speed. The platen creeps on
///   in its direction ([`Mode::Creep`]).
#[inline]
pub(crate) fn arrive_at_rest<M: PlatenModel>(
    model: &M,
    u: f64,
    f: f64,
    from: Direction,
) -> (Mode, Option<EventKind>) {
    match mode_at_rest(model, u, f) {
        Mode::Stick => (Mode::Stick, Some(EventKind::Stop)),
        Mode::Slip(d) if d == from => (Mode::Creep(from), None),
        other => (other, Some(EventKind::Reversal)),
    }
}

/// The first of `at, at + ε, at + 2ε, at + 4ε, …` (capped at `end`) where `holds` is true,
/// `ε` a few ulps of 1. Used to step an event time that rounding left on the wrong side of its
/// condition (a breakaway where `|N|` is not yet above `F_s`) just past it, so the next mode's
/// precondition holds at the state it starts from. `holds(end)` must be true.
#[inline]
pub(crate) fn just_past(at: f64, end: f64, mut holds: impl FnMut(f64) -> bool) -> f64 {
    let mut x = at;
    let mut eps = 4.0 * f64::EPSILON * end.abs().max(1.0);
    for _ in 0..64 {
        if x >= end || holds(x) {
            return x.min(end);
        }
        x = (at + eps).min(end);
        eps *= 2.0;
    }
    end
}

/// Whether the velocity may touch zero inside a step whose speed goes from `w0 ≥ 0` to
/// `w1 > 0` with slopes `d0`, `d1` (the speed's derivative times the step length, i.e. in
/// units of the step fraction `θ`): the cubic Hermite interpolant of the speed on `θ ∈ [0,
/// 1]` has an interior minimum at or below zero. Returns that `θ`, if any.
///
/// The interpolant is accurate to `O(h⁴)` on a smooth step, so a dip below zero that it does
/// not show is smaller than the step's own error. A cheap bound is tried first (the cubic
/// lies above `min(w0, w1) − ¼·max|dᵢ − Δ|`), so a step far from rest costs a few flops.
#[inline]
pub(crate) fn dip_to_zero(w0: f64, w1: f64, d0: f64, d1: f64) -> Option<f64> {
    let delta = w1 - w0;
    let bound = 0.25 * (d0 - delta).abs().max((d1 - delta).abs());
    if w0.min(w1) > bound {
        return None;
    }
    dip_to_zero_exact(w0, w1, d0, d1)
}

#[cold]
fn dip_to_zero_exact(w0: f64, w1: f64, d0: f64, d1: f64) -> Option<f64> {
    // p(θ) = w0 + d0·θ + c2·θ² + c3·θ³
    let delta = w1 - w0;
    let c2 = 3.0 * delta - 2.0 * d0 - d1;
    let c3 = d0 + d1 - 2.0 * delta;
    let p = |t: f64| w0 + t * (d0 + t * (c2 + t * c3));
    // p′(θ) = d0 + 2c2·θ + 3c3·θ²: its roots in (0, 1).
    let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, d0);
    let mut roots = [f64::NAN; 2];
    if qa.abs() <= 1e-12 * (qb.abs() + qc.abs()) {
        if qb != 0.0 {
            roots[0] = -qc / qb;
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let q = -0.5 * (qb + disc.sqrt().copysign(qb));
            roots = [q / qa, if q != 0.0 { qc / q } else { f64::NAN }];
        }
    }
    roots
        .into_iter()
        .filter(|t| *t > 0.0 && *t < 1.0)
        .filter(|&t| p(t) <= 0.0)
        .reduce(f64::min)
}

/// A breakaway inside the rest of a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Breakaway {
    /// Where `|N|` reaches the threshold, as a fraction of the rest of the step, in `[0, 1]`.
    pub fraction: f64,
    /// The direction of the slip that follows (that of the net force).
    pub direction: Direction,
}

/// The stick decision over the rest of a step in which the actuator force goes linearly
/// from `f_start` to `f_end`, for a platen stuck at `u`: `None` if friction holds it to the
/// end of the step (`|N| ≤ F_s(u)` there), otherwise the exact breakaway.
///
/// `|N|` is linear in time and within the threshold at the start (the platen is stuck), so
/// it crosses the threshold once, where `N` reaches `±F_s(u)` with the sign of `N` at the end.
#[inline]
pub(crate) fn breakaway<M: PlatenModel>(
    model: &M,
    u: f64,
    f_start: f64,
    f_end: f64,
) -> Option<Breakaway> {
    let elastic = model.elastic_force_n(u);
    let threshold = model.static_threshold_n(u);
    let net_end = f_end - elastic;
    if net_end.abs() <= threshold {
        return None;
    }
    let net_start = f_start - elastic;
    let target = threshold.copysign(net_end);
    let fraction = ((target - net_start) / (net_end - net_start)).clamp(0.0, 1.0);
    Some(Breakaway {
        fraction,
        direction: Direction::of_sign(net_end),
    })
}

/// Locates where `g = dir·v` reaches zero on the integrator's own map `x ↦ y(x)` (the state
/// after an integration of length `x` from a fixed start), by a bracketing root finder
/// (the Illinois variant of regula falsi: superlinear).
///
/// * `span`: the length at which the crossing is known to have happened, `end = (y, g)` the
///   state and `g ≤ 0` there;
/// * `g_start`: `g` at length 0. If it is not positive (the platen starts at rest, after a
///   breakaway or reversal), lengths `span/2, span/4, …` are tried first until one moves
///   the platen in `dir`;
/// * `tolerance`: the bracket width at which to stop;
/// * `trial(x)`: the state at length `x` and its `g` (it may fail).
///
/// Returns the length at the crossing (the end of the final bracket, where `g ≤ 0`) and the
/// state there, or `None` if the platen starts at rest and no length down to `1e-15·span`
/// moves it in `dir`: friction holds it.
///
/// # Errors
/// The first error of `trial`.
#[inline]
pub(crate) fn locate_zero_velocity<Y: Copy, E>(
    span: f64,
    g_start: f64,
    end: (Y, f64),
    tolerance: f64,
    mut trial: impl FnMut(f64) -> Result<(Y, f64), E>,
) -> Result<Option<(f64, Y)>, E> {
    let (mut hi, (mut y_hi, mut g_hi)) = (span, end);
    let (mut lo, mut g_lo) = (0.0, g_start);
    if g_lo <= 0.0 {
        // Starting at rest: find a length that moves.
        let mut x = 0.5 * span;
        loop {
            let (y, g) = trial(x)?;
            if g > 0.0 {
                (lo, g_lo) = (x, g);
                break;
            }
            (hi, y_hi, g_hi) = (x, y, g);
            x *= 0.5;
            if x < 1e-15 * span {
                return Ok(None);
            }
        }
    }
    let mut side = 0i8;
    for _ in 0..MAX_ROOT_ITERATIONS {
        if g_hi == 0.0 || hi - lo <= tolerance {
            break;
        }
        let mut x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let (y, g) = trial(x)?;
        if g > 0.0 {
            (lo, g_lo) = (x, g);
            if side == 1 {
                g_hi *= 0.5;
            }
            side = 1;
        } else {
            (hi, y_hi, g_hi) = (x, y, g);
            if side == -1 {
                g_lo *= 0.5;
            }
            side = -1;
        }
    }
    Ok(Some((hi, y_hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `v(x) = 1 − x` on `[0, 2]`: the crossing is at 1, found to the tolerance.
    #[test]
    fn the_root_finder_finds_a_linear_crossing() {
        let found =
            locate_zero_velocity(2.0, 1.0, ((), -1.0), 1e-14, |x| Ok::<_, ()>(((), 1.0 - x)))
                .unwrap()
                .unwrap();
        assert!((found.0 - 1.0).abs() < 1e-12, "{}", found.0);
    }

    /// Starting at rest with no length that moves the platen, friction holds it.
    #[test]
    fn the_root_finder_reports_a_platen_that_cannot_move() {
        let found = locate_zero_velocity(1.0, 0.0, ((), -1.0), 1e-14, |x| Ok::<_, ()>(((), -x)));
        assert_eq!(found, Ok(None));
    }

    /// A sign of the net force gives the direction, `−0.0` included.
    #[test]
    fn a_direction_follows_the_sign_bit_like_copysign() {
        for x in [2.0, -3.0, 0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(Direction::of_sign(x).sign(), 1.0f64.copysign(x));
        }
    }
}
