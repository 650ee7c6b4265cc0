//! Fixed-step RK4 for a platen carrying a specimen (a shear building, [`Specimen`]), with
//! exact stick-slip.
//!
//! # Equations
//!
//! The state is the platen's `(u, v)`, the storeys' relative `(zᵢ, żᵢ)` and three energy
//! integrals (actuator work, platen dissipation, storey-damper dissipation). With the base
//! shear `B = −(k₁z₁ + c₁ż₁)` (the force the platen exerts on the specimen) the platen obeys
//! `M(u)·a = F_A − F_E − F_D − B`: the friction laws see the *effective* force `F_A − B`, so the
//! event logic of [`crate::event`] and the creep of [`crate::creep`] apply with that force.
//!
//! # Modes
//!
//! * **slip±**: RK4 on the full state. As in the bare platen's RK4, a piece of the step is
//!   accepted when the platen's speed stays positive at its stages, its end and on its Hermite
//!   interpolant; otherwise the piece is halved until it is safe or ends across `v = 0`, where
//!   the crossing is located by Illinois root finding on the length of the (graded) RK4 map.
//! * **stick**: the platen is at rest and the specimen keeps vibrating on it (RK4 with `a = 0`).
//!   The net force `N = F_A − F_E(u) − B` is no longer linear in time, so the breakaway is
//!   located like a crossing: a piece is accepted when `F_s ∓ N` stays positive at its end and
//!   on its Hermite interpolant (the derivative `Ṅ = Ḟ_A + k₁ż₁ + c₁z̈₁` is exact), otherwise it
//!   is halved, and where `|N|` reaches `F_s` the time is found by root finding on the RK4 map
//!   of the specimen, then moved [`just_past`] it so that slip starts with `|N| > F_s`.
//! * **creep±**: the quasi-static creep of [`crate::creep`] with the effective force: the
//!   platen velocity is slaved to `N`, the specimen is stepped as on a fixed base (the base
//!   acceleration in creep is the rate of a velocity below the stiff speed, negligible), and
//!   the end of creep (a stop where `s·N` falls to `F_s`, slip where the creep speed reaches the
//!   stiff speed) is located by root finding on the RK4 map. At a stop the net force at rest
//!   decides: stick, a reversal (beyond the threshold against the motion: without static
//!   friction, `F_s = 0`, creep passes through `v = 0` so), or creep on; a stop that rounds
//!   onto the start of its advance with the net force still a hair along the motion is
//!   stepped [`just_past`] it, so the event loop always moves time forward.
//!
//! A platen leaves rest into creep if its creep speed under the net force there is below the
//! stiff speed (which it is at an exact breakaway), and creep hands over to slip where it
//! reaches that speed. The specimen starts at rest relative to the platen.
//!
//! # Storeys that yield
//!
//! A specimen with hysteretic storeys ([`platen_model::hysteresis`]) carries, per storey, its
//! hysteretic state (bilinear: the plastic drift; Bouc–Wen: the hysteretic force) and the
//! energy its plastic part dissipates, after the storey velocities. The storeys' branches
//! (bilinear elastic or yielding; Bouc–Wen's direction of drift) are the plant's own
//! ([`crate::machine`]'s branch events): a piece whose end finds a storey past its branch's
//! margin is cut back to the located event, the branch changes there, and the step goes on. A
//! Bouc–Wen storey under a fast drift over a small yield drift is stiff; the fixed step is then
//! cut into pieces that resolve it.
//!
//! No allocation happens per step: the storey state lives in fixed-size arrays of
//! [`Specimen::MAX_STOREYS`].

use std::collections::VecDeque;

use platen_model::{Branch, HystereticStorey, PlatenModel, Specimen};

use crate::clock::{Clock as _, GridClock};
use crate::creep::creep_speed_m_s;
use crate::error::Result;
use crate::event::{Direction, EventKind, Mode};
use crate::grid::{drive, Grid, GridStep, GridStepper};
use crate::hysteretic::BOUC_WEN_YIELD_SHARE;
use crate::machine::{direction, Machine, PieceMethod, Plant, DI, SD, U, V, W};
use crate::method::Method;
use crate::output::{Sample, SampleSink};
use crate::record::ForceRecord;
use crate::rk4::Rk4;
use crate::run::{check_run, EnergyBalance, RunStats, State};
use crate::steppable::{Samples, Steppable};
use crate::stop::StopReason;

const NS: usize = Specimen::MAX_STOREYS;
/// Positions in the state vector: displacement, velocity, actuator work, platen dissipation,
/// storey dissipation, then the `n` storey displacements from `Z` and the `n` storey
/// velocities from `Z + n` (the stepper's `zd`): the live state is the prefix `5 + 2n` of the
/// fixed-size array, and the RK4 loops run over that prefix only.
const Z: usize = 5;

/// The state of a specimen of `(L − 5)/2` storeys: the stepper is compiled for each length
/// (a 3-storey specimen steps arrays of 11, not of the largest specimen's 29).
type Y<const L: usize> = [f64; L];

/// Runs the model with `specimen` on the platen forward under `record` from `initial` (the
/// specimen at rest relative to the platen), with fixed-step RK4 and exact stick-slip,
/// delivering `samples` output samples (with their [`crate::SpecimenSample`]) to `sink`.
///
/// # Errors
/// As [`crate::forward_rk4`].
pub fn forward_rk4_specimen<M: PlatenModel, S: SampleSink>(
    model: &M,
    specimen: &Specimen,
    record: &ForceRecord,
    rk4: Rk4,
    initial: State,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    forward_specimen(
        model,
        specimen,
        record,
        Method::Rk4(rk4),
        initial,
        samples,
        sink,
    )
}

/// Runs the model with `specimen` on the platen forward under `record`, as
/// [`forward_rk4_specimen`], with the integrator `method`: fixed-step RK4, or the adaptive
/// Dormand–Prince 5(4) over each sample interval (`rtol` on every displacement and velocity,
/// `atol` in metres and m/s), with the same events.
///
/// # Errors
/// As [`crate::forward_rk4`]; with Dopri5 also [`crate::IntegrateError::AdaptiveFailed`] when it
/// cannot meet its tolerance (step budget spent or step underflow), with the time.
pub fn forward_specimen<M: PlatenModel, S: SampleSink>(
    model: &M,
    specimen: &Specimen,
    record: &ForceRecord,
    method: Method,
    initial: State,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    check_run(record, initial, samples)?;
    let (k, pieces, grid) = pieces_of(record, method);
    with_stepper!(model, specimen, grid, initial, pieces, |stepper| {
        drive(&mut stepper, record.t_s(), k, samples, sink)
    })
}

/// Binds `$stepper` to the stepper of `$specimen`'s storeys (its state length `5 + 2n` fixed
/// at compile time: a 3-storey specimen steps arrays of 11, not of the largest specimen's
/// 29) and evaluates `$body` with it.
macro_rules! with_stepper {
    ($model:expr, $specimen:expr, $grid:expr, $initial:expr, $pieces:expr, |$stepper:ident| $body:expr) => {
        if $specimen.is_hysteretic() {
            // Storeys that yield: each storey adds its hysteretic state and energy.
            with_stepper!(@hysteretic $model, $specimen, $grid, $initial, $pieces, $stepper, $body;
                1 => 9, 2 => 13, 3 => 17, 4 => 21, 5 => 25, 6 => 29, 7 => 33, 8 => 37,
                9 => 41, 10 => 45, 11 => 49, 12 => 53)
        } else {
            with_stepper!(@len $model, $specimen, $grid, $initial, $pieces, $stepper, $body;
                1 => 7, 2 => 9, 3 => 11, 4 => 13, 5 => 15, 6 => 17, 7 => 19, 8 => 21,
                9 => 23, 10 => 25, 11 => 27, 12 => 29)
        }
    };
    (@hysteretic $model:expr, $specimen:expr, $grid:expr, $initial:expr, $pieces:expr, $stepper:ident, $body:expr;
        $($n:literal => $len:literal),*) => {
        match $specimen.len() {
            $($n => {
                #[allow(unused_mut)]
                let mut $stepper =
                    Stepper::<_, $len, false, true>::new($model, $specimen, $grid, $initial, $pieces);
                $body
            })*
            other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
        }
    };
    (@len $model:expr, $specimen:expr, $grid:expr, $initial:expr, $pieces:expr, $stepper:ident, $body:expr;
        $($n:literal => $len:literal),*) => {
        match $specimen.len() {
            // The storeys' arithmetic or a general specimen's, chosen at compile time.
            $($n if $specimen.is_shear_building() => {
                #[allow(unused_mut)]
                let mut $stepper =
                    Stepper::<_, $len, false, false>::new($model, $specimen, $grid, $initial, $pieces);
                $body
            })*
            $($n => {
                #[allow(unused_mut)]
                let mut $stepper =
                    Stepper::<_, $len, true, false>::new($model, $specimen, $grid, $initial, $pieces);
                $body
            })*
            other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
        }
    };
}
use with_stepper;

/// The steps per sample interval, the machine's pieces and the grid of a run with `method`
/// (Dopri5 takes a sample interval a piece).
fn pieces_of(record: &ForceRecord, method: Method) -> (u64, PieceMethod, Grid<'_>) {
    let (k, pieces) = match method {
        Method::Rk4(rk4) => (u64::from(rk4.steps_per_sample()), PieceMethod::Rk4),
        Method::Dopri5(settings) => (
            1,
            PieceMethod::Dopri5 {
                rtol: settings.rtol(),
                atol: settings.atol(),
            },
        ),
    };
    (k, pieces, Grid::new(record, k))
}

/// The specimen run as a [`Steppable`] run.
pub(crate) fn boxed_specimen<'a, M: PlatenModel>(
    model: &'a M,
    specimen: &'a Specimen,
    record: &'a ForceRecord,
    method: Method,
    initial: State,
) -> Result<Box<dyn Steppable + 'a>> {
    check_run(record, initial, record.len())?;
    let (k, pieces, grid) = pieces_of(record, method);
    Ok(with_stepper!(
        model,
        specimen,
        grid,
        initial,
        pieces,
        |stepper| {
            stepper.machine.log_events();
            Box::new(Steps {
                stepper,
                times: record.t_s(),
                k,
                j: None,
            })
        }
    ))
}

/// A specimen run advanced a sample interval at a time.
struct Steps<'a, M, const L: usize, const G: bool, const H: bool> {
    stepper: Stepper<'a, M, L, G, H>,
    times: &'a [f64],
    /// Steps per sample interval.
    k: u64,
    /// The last sample delivered.
    j: Option<usize>,
}

impl<M: PlatenModel, const L: usize, const G: bool, const H: bool> Steppable
    for Steps<'_, M, L, G, H>
{
    fn advance(&mut self, out: &mut Samples) -> Result<bool> {
        let last = self.times.len() - 1;
        let j = match self.j {
            None => 0,
            Some(j) if j < last => {
                for i in 0..self.k {
                    let n = j as u64 * self.k + i;
                    self.stepper.step(GridStep { n, j, i: i as f64 })?;
                }
                j + 1
            }
            Some(_) => return Ok(false),
        };
        out.accept(&self.stepper.sample(j, self.times[j]));
        self.j = Some(j);
        Ok(j < last)
    }

    fn drain_events(&mut self, out: &mut VecDeque<(f64, EventKind)>) {
        self.stepper.machine.drain_events(out);
    }

    fn finish(&mut self) -> RunStats {
        let t_s = self.times[self.j.unwrap_or(0)];
        self.stepper.finish(t_s)
    }
}

/// The storeys' masses, stiffnesses and dampings (bottom first) in fixed-size arrays; the
/// first `n` are the specimen's.
struct StoreyConstants {
    m: [f64; NS],
    k: [f64; NS],
    c: [f64; NS],
    /// Each DOF's share `ιᵢ` of the platen's acceleration (1 for storeys).
    iota: [f64; NS],
}

impl StoreyConstants {
    fn of(spec: &Specimen) -> Self {
        let mut st = Self {
            m: [0.0; NS],
            k: [0.0; NS],
            c: [0.0; NS],
            iota: [0.0; NS],
        };
        for (i, s) in spec.storeys().iter().enumerate() {
            (st.m[i], st.k[i], st.c[i]) = (s.mass_kg, s.stiffness_n_per_m, s.damping_n_s_per_m);
        }
        for (i, iota) in st.iota[..spec.len()].iter_mut().enumerate() {
            *iota = spec.influence(i);
        }
        st
    }
}

/// The part of the storeys' rates that does not depend on the platen's acceleration `a`
/// ([`SpecimenPlant::storey_part`]).
struct StoreyPart {
    /// The storey accelerations at `a = 0`: `z̈ᵢ = qᵢ − a`.
    q: [f64; NS],
    /// The power dissipated by the storey dampers, W.
    power: f64,
    /// The bottom storey's shear `k₁z₁ + c₁ż₁ = −B`, N.
    shear0: f64,
}

/// [`Stepper::storey_part`] for a state of length `L` (`(L − 5)/2` storeys).
#[inline(always)]
fn storey_part<const L: usize>(st: &StoreyConstants, y: &Y<L>) -> StoreyPart {
    let (n, zd0) = ((L - Z) / 2, Z + (L - Z) / 2);
    let mut part = StoreyPart {
        q: [0.0; NS],
        power: 0.0,
        shear0: 0.0,
    };
    let (mut z_prev, mut zd_prev, mut shear_prev) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (z, zd) = (y[Z + i], y[zd0 + i]);
        let (d, dd) = (z - z_prev, zd - zd_prev);
        let shear = st.k[i] * d + st.c[i] * dd;
        part.power += st.c[i] * dd * dd;
        if i == 0 {
            part.shear0 = shear;
        } else {
            part.q[i - 1] = (shear - shear_prev) / st.m[i - 1];
        }
        (z_prev, zd_prev, shear_prev) = (z, zd, shear);
    }
    part.q[n - 1] = -shear_prev / st.m[n - 1];
    part
}

/// The platen with a specimen on it, under a force record: the [`Plant`] of the mode machine.
///
/// `G`: a general linear specimen (its matrices), whose arithmetic is the specimen's; storeys
/// otherwise, whose arithmetic is written out here for the hot loops. A compile-time choice:
/// a test of it at every evaluation of the rates cost the storeys' run 18 % of its speed.
struct SpecimenPlant<'a, M, const L: usize, const G: bool, const H: bool> {
    model: &'a M,
    spec: &'a Specimen,
    /// The storeys' constants in fixed-size arrays (the first `N` are live), so that the
    /// storey loops run over compile-time bounds without indexing the specimen's `Vec`.
    storeys: StoreyConstants,
    /// The record's grid and the step being taken: positions are fractions `τ ∈ [0, 1]` of
    /// it.
    clock: GridClock<'a>,
    /// The actuator force's rate in the current grid interval, N/s (the force is linear
    /// between samples).
    f_rate: f64,
    /// `H`: the storeys' hysteresis (`None` for a linear storey) and branches, and each
    /// storey's yield excursions so far.
    hyst: [Option<HystereticStorey>; NS],
    branch: [Branch; NS],
    yield_excursions: [usize; NS],
    /// `H`: whether a Bouc–Wen storey's excursion in its current direction is counted.
    counted: [bool; NS],
}

impl<'a, M: PlatenModel, const L: usize, const G: bool, const H: bool>
    SpecimenPlant<'a, M, L, G, H>
{
    /// The number of storeys.
    const N: usize = (L - Z) / if H { 4 } else { 2 };
    /// Where the storey velocities start.
    const ZD: usize = Z + Self::N;
    /// `H`: where the storeys' hysteretic states start ([`crate::hysteretic`]).
    const HS: usize = Z + 2 * Self::N;
    /// `H`: where the storeys' hysteretic energies start.
    const ES: usize = Z + 3 * Self::N;

    /// `H`: storey `i`'s drift and drift rate at `y`.
    #[inline(always)]
    fn drifts(&self, i: usize, y: &Y<L>) -> (f64, f64) {
        let (z, zd) = (y[Z + i], y[Self::ZD + i]);
        if i == 0 {
            (z - 0.0, zd - 0.0)
        } else {
            (z - y[Z + i - 1], zd - y[Self::ZD + i - 1])
        }
    }

    /// `H`: storey `i`'s restoring force at `y`, N (dashpot excluded).
    #[inline(always)]
    fn storey_force(&self, i: usize, y: &Y<L>) -> f64 {
        let (d, _) = self.drifts(i, y);
        match &self.hyst[i] {
            Some(h) => h.force_n(d, y[Self::HS + i], self.branch[i]),
            None => self.storeys.k[i] * d,
        }
    }

    /// `H`: the storeys' part of the rates that does not depend on the platen's acceleration,
    /// as [`Self::storey_part`], each storey's restoring force its hysteretic one; the
    /// hysteretic states' and energies' rates written into `dy`.
    #[inline(always)]
    fn hysteretic_part(&self, y: &Y<L>, dy: &mut Y<L>) -> StoreyPart {
        let st = &self.storeys;
        let mut part = StoreyPart {
            q: [0.0; NS],
            power: 0.0,
            shear0: 0.0,
        };
        let mut shear_prev = 0.0;
        for i in 0..Self::N {
            let (d, dd) = self.drifts(i, y);
            let spring = match &self.hyst[i] {
                Some(h) => {
                    let (hd, ed) = h.rates(dd, y[Self::HS + i], self.branch[i]);
                    (dy[Self::HS + i], dy[Self::ES + i]) = (hd, ed);
                    h.force_n(d, y[Self::HS + i], self.branch[i])
                }
                None => {
                    (dy[Self::HS + i], dy[Self::ES + i]) = (0.0, 0.0);
                    st.k[i] * d
                }
            };
            let shear = spring + st.c[i] * dd;
            part.power += st.c[i] * dd * dd;
            if i == 0 {
                part.shear0 = shear;
            } else {
                part.q[i - 1] = (shear - shear_prev) / st.m[i - 1];
            }
            shear_prev = shear;
        }
        part.q[Self::N - 1] = -shear_prev / st.m[Self::N - 1];
        part
    }

    /// The actuator force's rate between samples `j` and `j + 1`, N/s (0 past the record).
    fn force_rate(&self, j: usize) -> f64 {
        let g = &self.clock.grid;
        match (g.force.get(j), g.force.get(j + 1)) {
            (Some(f0), Some(f1)) => (f1 - f0) * g.inv_k / g.h,
            _ => 0.0,
        }
    }

    #[inline(always)]
    fn base_shear(&self, y: &Y<L>) -> f64 {
        let st = &self.storeys;
        if H {
            return -(self.storey_force(0, y) + st.c[0] * y[Self::ZD]);
        }
        if G {
            self.spec
                .base_shear_n(&y[Z..Z + Self::N], &y[Self::ZD..Self::ZD + Self::N])
        } else {
            // `Specimen::base_shear_n` of storeys, from the constants at hand.
            -(st.k[0] * y[Z] + st.c[0] * y[Self::ZD])
        }
    }

    fn specimen_energy(&self, y: &Y<L>) -> f64 {
        if H {
            // Kinetic, and each storey's recoverable energy (a yielding storey's
            // `½·a·k·δ² + q²/(2(1 − a)k)`).
            let mut e = 0.0;
            for i in 0..Self::N {
                let w = y[V] + y[Self::ZD + i];
                let (d, _) = self.drifts(i, y);
                let stored = match &self.hyst[i] {
                    Some(h) => {
                        let q = h.hysteretic_force_n(d, y[Self::HS + i], self.branch[i]);
                        h.stored_energy_j(d, q)
                    }
                    None => 0.5 * self.storeys.k[i] * d * d,
                };
                e += 0.5 * self.storeys.m[i] * w * w + stored;
            }
            return e;
        }
        let (n, zd) = (Self::N, Self::ZD);
        self.spec.energy_j(y[V], &y[Z..Z + n], &y[zd..zd + n])
    }

    /// The storeys' part of the rates that does not depend on the platen's acceleration `a`
    /// (the storey accelerations are `qᵢ − a`), computed once per stage before the platen's.
    ///
    /// The same operations, in the same order, as [`Specimen::storey_accelerations`] (whose
    /// `(shearᵢ₊₁ − shearᵢ)/mᵢ − a` is `qᵢ − a` here, and whose bottom storey's shear
    /// `k₁(z₁ − 0) + c₁(ż₁ − 0)` is `−B` bit for bit), so the results are identical; the
    /// unit test `storey_part_is_the_model_s` checks it.
    ///
    /// A general linear specimen takes [`Specimen::storey_accelerations`] at `a = 0`.
    #[inline(always)]
    fn storey_part(&self, y: &Y<L>) -> StoreyPart {
        if !G {
            return storey_part(&self.storeys, y);
        }
        let (n, zd) = (Self::N, Self::ZD);
        let (z, zd) = (&y[Z..Z + n], &y[zd..zd + n]);
        let mut part = StoreyPart {
            q: [0.0; NS],
            power: 0.0,
            shear0: -self.spec.base_shear_n(z, zd),
        };
        part.power = self.spec.storey_accelerations(0.0, z, zd, &mut part.q[..n]);
        part
    }

    /// Writes the storeys' rates into `dy` from their linear part under platen acceleration
    /// `a` (`z̈ᵢ = qᵢ − ιᵢ·a`).
    #[inline(always)]
    fn storey_rates(&self, part: &StoreyPart, a: f64, y: &Y<L>, dy: &mut Y<L>) {
        let st = &self.storeys;
        for i in 0..Self::N {
            dy[Z + i] = y[Self::ZD + i];
            dy[Self::ZD + i] = if G {
                part.q[i] - st.iota[i] * a
            } else {
                part.q[i] - a
            };
        }
        dy[SD] = part.power;
    }

    /// The platen's acceleration `a = s·ẇ` in creep at speed `w` (`0 < w < w_*`): the rate of
    /// the creep speed, which the specimen feels as base acceleration.
    ///
    /// The creep speed solves `E(u, w) = s·(F_A − B)` with
    /// `E = F_s(u) + D_excess(u, w) + s·F_vi(u, s·w) + s·F_E(u)`. With `u̇ = s·w` and
    /// `Ḃ = Ḃ₀ + c₁·a` (`Ḃ₀` the base-shear rate at zero base acceleration: the base shear
    /// `−(k₁z₁ + c₁ż₁)` feels `a` through `z̈₁ = z̈₁⁰ − a`), differentiating gives
    /// `ẇ = (s·(Ḟ_A − Ḃ₀) − E_u·s·w) / (E_w + c₁)`. The partial derivatives are central
    /// differences (relative steps 1e-4 in `w`, 1e-6 in `u`; `a` is itself small, O(h), so their error is far below
    /// the integration error). Feeding this `a` to the storeys keeps the specimen's energy
    /// balance exact in creep: without it the storeys' absolute kinetic energy changes by
    /// `Σmᵢ(v + żᵢ)·Δv` with no work behind it, an error of order `h²`.
    fn creep_acceleration(&self, dir: Direction, y: &Y<L>, w: f64) -> f64 {
        let (s, u) = (dir.sign(), y[U]);
        let m = self.model;
        // The speed-dependent part apart: next to F_s and F_E it is below their rounding.
        let e_speed =
            |w: f64| m.dissipative_excess_n(u, w) + s * m.velocity_inertial_force_n(u, s * w);
        let e_static = |u: f64| {
            m.static_threshold_n(u)
                + m.dissipative_excess_n(u, w)
                + s * m.velocity_inertial_force_n(u, s * w)
                + s * m.elastic_force_n(u)
        };
        let dw = 1e-4 * w;
        let e_w = (e_speed(w + dw) - e_speed(w - dw)) / (2.0 * dw);
        if !(e_w.is_finite() && e_w > 0.0) {
            return 0.0;
        }
        let du = 1e-6 * u.abs().max(1e-3);
        let e_u = (e_static(u + du) - e_static(u - du)) / (2.0 * du);
        let (n, zd) = (Self::N, Self::ZD);
        let (b_rate0, c_base) = if H {
            let mut dy = [0.0; L];
            let part = self.hysteretic_part(y, &mut dy);
            let force_rate = match &self.hyst[0] {
                Some(h) => h.force_rate_n_s(y[zd], dy[Self::HS], self.branch[0]),
                None => self.storeys.k[0] * y[zd],
            };
            let c0 = self.storeys.c[0];
            (-(force_rate + c0 * part.q[0]), c0)
        } else {
            let mut zdd0 = [0.0; NS];
            self.spec
                .storey_accelerations(0.0, &y[Z..Z + n], &y[zd..zd + n], &mut zdd0[..n]);
            (
                self.spec.base_shear_rate_n_s(&y[zd..zd + n], &zdd0[..n]),
                self.spec.base_damping_n_s_per_m(),
            )
        };
        let w_rate = (s * (self.f_rate - b_rate0) - e_u * s * w) / (e_w + c_base);
        if w_rate.is_finite() {
            s * w_rate
        } else {
            0.0
        }
    }

    /// The signed creep velocity at state `y` under force `f` (stiff speed `w_stiff`).
    fn creep_velocity(&self, dir: Direction, w_stiff: f64, y: &Y<L>, f: f64) -> f64 {
        let w = creep_speed_m_s(self.model, dir, y[U], f - self.base_shear(y), w_stiff)
            .unwrap_or(w_stiff);
        dir.sign() * w
    }
}

impl<'a, M: PlatenModel, const L: usize, const G: bool, const H: bool> Plant<L>
    for SpecimenPlant<'a, M, L, G, H>
{
    type Model = M;
    /// The actuator force, N.
    type Input = f64;

    #[inline(always)]
    fn model(&self) -> &M {
        self.model
    }

    #[inline(always)]
    fn rates(&self, mode: Mode, w_stiff: f64, f: f64, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        match mode {
            Mode::Slip(Direction::Positive) => return self.slip_rates::<true>(f, y, dy),
            Mode::Slip(Direction::Negative) => return self.slip_rates::<false>(f, y, dy),
            _ => {}
        }
        let part = if H {
            self.hysteretic_part(y, dy)
        } else {
            self.storey_part(y)
        };
        let bs = -part.shear0;
        let a = match mode {
            Mode::Slip(_) => unreachable!("slip returned above"),
            Mode::Stick => {
                dy[U] = 0.0;
                dy[V] = 0.0;
                dy[W] = 0.0;
                dy[DI] = 0.0;
                0.0
            }
            Mode::Creep(dir) => {
                let s = dir.sign();
                let w = creep_speed_m_s(self.model, dir, y[U], f - bs, w_stiff).unwrap_or(w_stiff);
                dy[U] = s * w;
                dy[V] = 0.0;
                dy[W] = f * s * w;
                dy[DI] = self.model.dissipative_magnitude_n(y[U], w) * w;
                if w > 0.0 {
                    self.creep_acceleration(dir, y, w)
                } else {
                    0.0
                }
            }
        };
        self.storey_rates(&part, a, y, dy);
        a
    }

    /// The slip case of [`Plant::rates`], compiled per direction so that `±v` and `±D` fold
    /// (exact for ±1).
    #[inline(always)]
    fn slip_rates<const POSITIVE: bool>(&self, f: f64, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        let part = if H {
            self.hysteretic_part(y, dy)
        } else {
            self.storey_part(y)
        };
        let bs = -part.shear0;
        let r = self
            .model
            .slip_rates(f - bs, y[U], y[V], direction::<POSITIVE>());
        dy[U] = y[V];
        dy[V] = r.a_m_s2;
        dy[W] = f * y[V];
        dy[DI] = r.dissipated_power_w;
        self.storey_rates(&part, r.a_m_s2, y, dy);
        r.a_m_s2
    }

    #[inline(always)]
    fn effective_force(&self, f: f64, y: &Y<L>) -> f64 {
        f - self.base_shear(y)
    }

    /// `N = F_A − F_E(u) − B`.
    #[inline(always)]
    fn net(&self, f: f64, y: &Y<L>) -> f64 {
        f - self.model.elastic_force_n(y[U]) - self.base_shear(y)
    }

    /// `Ṅ = Ḟ_A − Ḃ = Ḟ_A + k₁ż₁ + c₁z̈₁` (`u` fixed).
    fn net_rate(&self, k: &Y<L>) -> f64 {
        let (n, zd, st) = (Self::N, Self::ZD, &self.storeys);
        if H {
            // Ḟ_A − Ḃ = Ḟ_A + Ḟ₁ + c₁·z̈₁, the bottom storey's force rate on its branch.
            let force_rate = match &self.hyst[0] {
                Some(h) => h.force_rate_n_s(k[Z], k[Self::HS], self.branch[0]),
                None => st.k[0] * k[Z],
            };
            return self.f_rate + force_rate + st.c[0] * k[zd];
        }
        if G {
            self.spec
                .less_base_shear_rate(self.f_rate, &k[Z..Z + n], &k[zd..zd + n])
        } else {
            self.f_rate + st.k[0] * k[Z] + st.c[0] * k[zd]
        }
    }

    /// In creep the velocity is slaved to the net force at the end of each piece.
    #[inline(always)]
    fn settle(&self, mode: Mode, w_stiff: f64, f: f64, y: &mut Y<L>) {
        if let Mode::Creep(dir) = mode {
            y[V] = self.creep_velocity(dir, w_stiff, y, f);
        }
    }

    const RATES_ON_COMMIT: bool = false;

    /// Metres for the motion and the storeys, m/s for the velocities; the energy integrals
    /// are quadratures and not controlled.
    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64 {
        let relative = rtol * y0.abs().max(y1.abs());
        match i {
            W | DI | SD => f64::INFINITY,
            // A yielding storey's energy is a quadrature; its Bouc–Wen force is in N (the
            // tolerance in metres times the storey's plastic stiffness), its plastic drift in m.
            _ if H && i >= Self::ES => f64::INFINITY,
            _ if H && i >= Self::HS => match &self.hyst[i - Self::HS] {
                Some(h) if !h.is_bilinear() => atol * h.pk + relative,
                _ => atol + relative,
            },
            _ => atol + relative,
        }
    }

    const HAS_BRANCHES: bool = H;

    /// A Bouc–Wen storey's own rate: `|∂q̇/∂q| ≤ n·|δ̇|/δ_y·|q/q_y|ⁿ⁻¹`, which a fast drift over
    /// a small yield drift makes far stiffer than the grid step (a 4 mm yield drift at 2 m/s
    /// and n = 3: 1 500/s): the RK4 advance is cut into pieces that resolve it.
    fn stiff_rate(&self, y: &Y<L>) -> f64 {
        if !H {
            return 0.0;
        }
        let mut rate: f64 = 0.0;
        for i in 0..Self::N {
            if let Some(h) = &self.hyst[i] {
                rate = rate.max(h.own_rate_1_s(self.drifts(i, y).1, y[Self::HS + i]));
            }
        }
        rate * self.clock.seconds(1.0)
    }

    /// The smallest event margin of the yielding storeys ([`HystereticStorey::event_margin`]).
    #[inline(always)]
    fn branch_margin(&self, y: &Y<L>) -> f64 {
        let mut margin = f64::INFINITY;
        for i in 0..Self::N {
            if let Some(h) = &self.hyst[i] {
                let (d, dd) = self.drifts(i, y);
                margin = margin.min(h.event_margin(d, dd, y[Self::HS + i], self.branch[i]));
            }
        }
        margin
    }

    /// Changes the branch of every yielding storey whose margin has fallen to zero or below
    /// ([`HystereticStorey::after_event`]), counting a bilinear storey's yield.
    fn branch_event(&mut self, y: &mut Y<L>, _t_s: f64) -> bool {
        let mut changed = false;
        for i in 0..Self::N {
            let Some(h) = self.hyst[i] else { continue };
            let (d, dd) = self.drifts(i, y);
            let hs = Self::HS + i;
            // At or past its margin (the root finder may land on the zero itself).
            if h.event_margin(d, dd, y[hs], self.branch[i]) > 0.0 {
                continue;
            }
            let (branch, state) = h.after_event(d, dd, y[hs], self.branch[i]);
            if branch == self.branch[i] {
                continue;
            }
            if h.is_bilinear() {
                self.yield_excursions[i] += usize::from(branch != Branch::Elastic);
            } else {
                self.counted[i] = false;
            }
            (self.branch[i], y[hs]) = (branch, state);
            changed = true;
        }
        changed
    }

    /// Counts a Bouc–Wen storey's excursion where its hysteretic force passes
    /// [`BOUC_WEN_YIELD_SHARE`] of `q_y` while loading (as [`crate::hysteretic`] does).
    fn admit(&mut self, y: &mut Y<L>, _t_s: f64) -> bool {
        if H {
            for i in 0..Self::N {
                let Some(h) = &self.hyst[i] else { continue };
                let q = y[Self::HS + i];
                let loading = matches!(self.branch[i], Branch::Moving(d) if d * q > 0.0);
                if !h.is_bilinear()
                    && loading
                    && !self.counted[i]
                    && q.abs() >= BOUC_WEN_YIELD_SHARE * h.qy
                {
                    self.counted[i] = true;
                    self.yield_excursions[i] += 1;
                }
            }
        }
        false
    }

    #[inline(always)]
    fn input(&self, at: f64) -> f64 {
        self.clock.force(at)
    }

    crate::clock::clock_field!(GridClock<'a>);
}

/// A forward run with a specimen: the mode machine over the force record's grid.
struct Stepper<'a, M, const L: usize, const G: bool, const H: bool> {
    machine: Machine<SpecimenPlant<'a, M, L, G, H>, L>,
}

impl<'a, M: PlatenModel, const L: usize, const G: bool, const H: bool> Stepper<'a, M, L, G, H> {
    fn new(
        model: &'a M,
        spec: &'a Specimen,
        grid: Grid<'a>,
        initial: State,
        method: PieceMethod,
    ) -> Self {
        let mut y = [0.0; L];
        y[U] = initial.u_m;
        y[V] = initial.v_m_s;
        let h = grid.h;
        let mut plant = SpecimenPlant {
            model,
            spec,
            storeys: StoreyConstants::of(spec),
            clock: GridClock::new(grid),
            f_rate: 0.0,
            hyst: [None; NS],
            branch: [Branch::Elastic; NS],
            yield_excursions: [0; NS],
            counted: [false; NS],
        };
        if H {
            for i in 0..spec.len() {
                plant.hyst[i] = spec.hysteretic_storey(i);
                if let Some(h) = &plant.hyst[i] {
                    plant.branch[i] = h.initial_branch();
                }
            }
        }
        plant.f_rate = plant.force_rate(0);
        let f0 = plant.clock.grid.force[0];
        let mode = Mode::initial(model, y[U], y[V], f0 - plant.base_shear(&y));
        let specimen_start_j = plant.specimen_energy(&y);
        let mut machine = Machine::new(plant, y, h, method);
        machine.enter(mode, f0);
        let energy = &mut machine.stats.energy;
        *energy = EnergyBalance::start(model, y[U], y[V]);
        energy.specimen_start_j = specimen_start_j;
        energy.specimen_end_j = specimen_start_j;
        Stepper { machine }
    }

    /// [`Stepper::step`] through the machine's advance: every mode and event.
    fn step_with_events(&mut self, n: GridStep) -> Result<()> {
        let m = &mut self.machine;
        m.plant.f_rate = m.plant.force_rate(n.j);
        m.advance_span()
    }
}

impl<M: PlatenModel, const L: usize, const G: bool, const H: bool> GridStepper
    for Stepper<'_, M, L, G, H>
{
    /// Advances from grid point `n` to `n + 1`, handling every event inside the step.
    ///
    /// A step of RK4 in slip away from rest first tries [`Machine::slip_fast`] (compiled per
    /// direction); anything it does not commit, and every other mode, goes through the
    /// machine's [`Machine::advance`].
    #[inline(always)]
    fn step(&mut self, n: GridStep) -> Result<()> {
        let m = &mut self.machine;
        m.plant.clock.n = n;
        m.stats.steps += 1;
        // A yielding specimen's steps go through the machine's advance, which looks for its
        // branch events.
        let rk4 = m.is_rk4() && !H;
        let committed = match m.mode {
            Mode::Slip(Direction::Positive) if rk4 && m.y[V] != 0.0 => m.slip_fast::<true>(0.0),
            Mode::Slip(Direction::Negative) if rk4 && m.y[V] != 0.0 => m.slip_fast::<false>(0.0),
            _ => false,
        };
        if committed {
            return Ok(());
        }
        self.step_with_events(n)
    }

    /// The output sample at sample `j` of the record (grid point `j·k`).
    #[inline(always)]
    fn sample(&self, j: usize, t_s: f64) -> Sample {
        let (m, p) = (&self.machine, &self.machine.plant);
        let mut sample = m.sample(
            j,
            t_s,
            p.clock.grid.force[j],
            p.base_shear(&m.y),
            Some((p.spec, G)),
            Z,
        );
        if H {
            if let Some(spec) = &mut sample.specimen {
                let y = &m.y;
                spec.hysteretic = true;
                for i in 0..SpecimenPlant::<M, L, G, H>::N {
                    let (d, _) = p.drifts(i, y);
                    let hs = y[SpecimenPlant::<M, L, G, H>::HS + i];
                    spec.force_n[i] = p.storey_force(i, y);
                    spec.hysteretic_force_n[i] =
                        p.hyst[i].map_or(0.0, |h| h.hysteretic_force_n(d, hs, p.branch[i]));
                    spec.hysteretic_j[i] = y[SpecimenPlant::<M, L, G, H>::ES + i];
                }
                spec.yield_excursions = p.yield_excursions;
            }
        }
        sample
    }

    /// Closes the energy balance at the current state, the run having finished at `t_s`.
    fn finish(&mut self, t_s: f64) -> RunStats {
        let m = &mut self.machine;
        let y = m.y;
        let specimen_end_j = m.plant.specimen_energy(&y);
        let rk4 = m.is_rk4();
        let stats = &mut m.stats;
        stats.energy.close(m.plant.model, y[U], y[V], y[W], y[DI]);
        stats.energy.specimen_end_j = specimen_end_j;
        stats.energy.specimen_dissipated_j = y[SD];
        if H {
            // The work of the storeys' plastic parts, dissipated like the dampers'.
            let (n, es) = (
                SpecimenPlant::<M, L, G, H>::N,
                SpecimenPlant::<M, L, G, H>::ES,
            );
            stats.energy.specimen_dissipated_j += y[es..es + n].iter().sum::<f64>();
        }
        if rk4 {
            stats.accepted_steps = stats.steps;
        }
        stats.stop = StopReason::Finished { t_s };
        *stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_model::Storey;

    /// The stepper's split of the storey rates (linear part first, then `− a`) gives the
    /// model's storey accelerations, damper power and base shear bit for bit.
    #[test]
    fn storey_part_is_the_model_s() {
        let storey = |m: f64, k: f64, c: f64| Storey {
            mass_kg: m,
            stiffness_n_per_m: k,
            damping_n_s_per_m: c,
        };
        let spec = Specimen::new(vec![
            storey(30e3, 27.08e6, 86.2e3),
            storey(25e3, 19.35e6, 61.6e3),
            storey(21e3, 13.1e6, 0.0),
        ])
        .unwrap();
        let st = StoreyConstants::of(&spec);
        // A deterministic spread of states, signs and magnitudes (-0.0 included).
        let mut x = 0.123_456_789_f64;
        let mut next = || {
            x = (x * 3.987_654_321 + 0.314_159).fract();
            (x - 0.5) * 10f64.powi((x * 12.0) as i32 - 8)
        };
        for case in 0..2000 {
            let mut y = [0.0; 11];
            for v in &mut y {
                *v = next();
            }
            if case == 0 {
                y[Z] = -0.0;
                y[Z + 3] = -0.0;
            }
            let a = next();
            let part = storey_part(&st, &y);
            let mut zdd = [0.0; 3];
            let power = spec.storey_accelerations(a, &y[Z..Z + 3], &y[Z + 3..Z + 6], &mut zdd);
            assert_eq!(power.to_bits(), part.power.to_bits(), "case {case}");
            for (i, (zdd, q)) in zdd.iter().zip(part.q).enumerate() {
                assert_eq!(zdd.to_bits(), (q - a).to_bits(), "case {case} storey {i}");
            }
            let bs = spec.base_shear_n(&y[Z..Z + 3], &y[Z + 3..Z + 6]);
            assert_eq!(bs.to_bits(), (-part.shear0).to_bits(), "case {case}");
        }
    }
}
