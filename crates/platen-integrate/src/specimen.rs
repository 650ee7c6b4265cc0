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
//! No allocation happens per step: the storey state lives in fixed-size arrays of
//! [`Specimen::MAX_STOREYS`].

use std::convert::Infallible;

use platen_model::{PlatenModel, Specimen};

use crate::creep::{creep_speed_m_s, stiff_speed_m_s};
use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, dip_to_zero, just_past, locate_zero_velocity, mode_at_rest, Direction,
    EventKind, Mode, StepStop, MAX_EVENTS_PER_STEP,
};
use crate::output::{Sample, SampleSink, SpecimenSample};
use crate::record::ForceRecord;
use crate::rk4::{direction, drive, Grading, Grid, GridStep, GridStepper, Rk4, MAX_HALVINGS};
use crate::run::{check_run, sample_at, EnergyBalance, Kin, RunStats, State};
use crate::stop::{Failure, StopReason};

const NS: usize = Specimen::MAX_STOREYS;
/// A creep stop located this close (fraction of a step) to where the advance started has not
/// moved time: if the net force at rest still drives the creep on, it is stepped just past
/// ([`just_past`], whose first increment is `4ε`) instead of creeping on in place.
const MIN_PROGRESS: f64 = 4.0 * f64::EPSILON;
/// Positions in the state vector: displacement, velocity, actuator work, platen dissipation,
/// storey dissipation, then the `n` storey displacements from `Z` and the `n` storey
/// velocities from `Z + n` (the stepper's `zd`): the live state is the prefix `5 + 2n` of the
/// fixed-size array, and the RK4 loops run over that prefix only.
const U: usize = 0;
const V: usize = 1;
const W: usize = 2;
const DI: usize = 3;
const SD: usize = 4;
const Z: usize = 5;

/// The state of a specimen of `(L − 5)/2` storeys: the stepper is compiled for each length
/// (a 3-storey specimen steps arrays of 11, not of the largest specimen's 29).
type Y<const L: usize> = [f64; L];

/// Runs the model with `specimen` on the platen forward under `record` from `initial` (the
/// specimen at rest relative to the platen), with fixed-step RK4 and exact stick-slip,
/// delivering `samples` output samples (with their [`SpecimenSample`]) to `sink`.
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
    check_run(record, initial, samples)?;
    macro_rules! by_storeys {
        ($($n:literal => $len:literal),*) => {
            match specimen.len() {
                $($n => run::<M, S, $len>(model, specimen, record, rk4, initial, samples, sink),)*
                other => unreachable!("a validated specimen has 1 to {NS} storeys, not {other}"),
            }
        };
    }
    by_storeys!(1 => 7, 2 => 9, 3 => 11, 4 => 13, 5 => 15, 6 => 17, 7 => 19, 8 => 21,
                9 => 23, 10 => 25, 11 => 27, 12 => 29)
}

/// [`forward_rk4_specimen`] with the state length `L = 5 + 2n` fixed at compile time.
fn run<M: PlatenModel, S: SampleSink, const L: usize>(
    model: &M,
    specimen: &Specimen,
    record: &ForceRecord,
    rk4: Rk4,
    initial: State,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    let k = u64::from(rk4.steps_per_sample());
    let mut stepper = Stepper::<M, L>::new(model, specimen, Grid::new(record, k), initial);
    drive(&mut stepper, record.t_s(), k, samples, sink)
}

impl<M: PlatenModel, const L: usize> GridStepper for Stepper<'_, M, L> {
    #[inline(always)]
    fn step(&mut self, n: GridStep) -> Result<()> {
        Stepper::step(self, n)
    }
    #[inline(always)]
    fn sample(&self, j: usize, t_s: f64) -> Sample {
        Stepper::sample(self, j, t_s)
    }
    #[inline(always)]
    fn finish(&mut self, t_s: f64) -> RunStats {
        Stepper::finish(self, t_s)
    }
}

/// The storeys' masses, stiffnesses and dampings (bottom first) in fixed-size arrays; the
/// first `n` are the specimen's.
struct StoreyConstants {
    m: [f64; NS],
    k: [f64; NS],
    c: [f64; NS],
}

impl StoreyConstants {
    fn of(spec: &Specimen) -> Self {
        let mut st = Self {
            m: [0.0; NS],
            k: [0.0; NS],
            c: [0.0; NS],
        };
        for (i, s) in spec.storeys().iter().enumerate() {
            (st.m[i], st.k[i], st.c[i]) = (s.mass_kg, s.stiffness_n_per_m, s.damping_n_s_per_m);
        }
        st
    }
}

/// The part of the storeys' rates that does not depend on the platen's acceleration `a`
/// ([`Stepper::storey_part`]).
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

struct Stepper<'a, M, const L: usize> {
    model: &'a M,
    spec: &'a Specimen,
    /// The storeys' constants in fixed-size arrays (the first `N` are live), so that the
    /// storey loops run over compile-time bounds without indexing the specimen's `Vec`.
    storeys: StoreyConstants,
    grid: Grid<'a>,
    y: Y<L>,
    mode: Mode,
    /// Rates at the current state in the current mode.
    k: Y<L>,
    /// Platen acceleration at the current state (0 in stick and creep).
    a: f64,
    w_stiff: f64,
    /// The actuator force's rate in the current grid interval, N/s (the force is linear
    /// between samples).
    f_rate: f64,
    stats: RunStats,
}

impl<'a, M: PlatenModel, const L: usize> Stepper<'a, M, L> {
    /// The number of storeys.
    const N: usize = (L - Z) / 2;
    /// Where the storey velocities start.
    const ZD: usize = Z + Self::N;

    fn new(model: &'a M, spec: &'a Specimen, grid: Grid<'a>, initial: State) -> Self {
        let mut y = [0.0; L];
        y[U] = initial.u_m;
        y[V] = initial.v_m_s;
        let mut s = Self {
            model,
            spec,
            storeys: StoreyConstants::of(spec),
            grid,
            y,
            mode: Mode::Stick,
            k: [0.0; L],
            a: 0.0,
            w_stiff: 0.0,
            f_rate: 0.0,
            stats: RunStats::default(),
        };
        s.f_rate = s.force_rate(0);
        let f0 = s.grid.force[0];
        let mode = Mode::initial(model, y[U], y[V], f0 - s.base_shear(&y));
        s.enter(mode, f0);
        s.stats.energy = EnergyBalance::start(model, y[U], y[V]);
        s.stats.energy.specimen_start_j = s.specimen_energy(&y);
        s.stats.energy.specimen_end_j = s.stats.energy.specimen_start_j;
        s
    }

    /// The actuator force's rate between samples `j` and `j + 1`, N/s (0 past the record).
    fn force_rate(&self, j: usize) -> f64 {
        let g = &self.grid;
        match (g.force.get(j), g.force.get(j + 1)) {
            (Some(f0), Some(f1)) => (f1 - f0) * g.inv_k / g.h,
            _ => 0.0,
        }
    }

    #[inline(always)]
    fn base_shear(&self, y: &Y<L>) -> f64 {
        self.spec.base_shear_n(y[Z], y[Self::ZD])
    }

    fn specimen_energy(&self, y: &Y<L>) -> f64 {
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
    #[inline(always)]
    fn storey_part(&self, y: &Y<L>) -> StoreyPart {
        storey_part(&self.storeys, y)
    }

    /// Writes the storeys' rates into `dy` from their linear part under platen acceleration
    /// `a`.
    #[inline(always)]
    fn storey_rates(part: &StoreyPart, a: f64, y: &Y<L>, dy: &mut Y<L>) {
        for i in 0..Self::N {
            dy[Z + i] = y[Self::ZD + i];
            dy[Self::ZD + i] = part.q[i] - a;
        }
        dy[SD] = part.power;
    }

    /// The rates of the full state in slip with direction `direction::<POSITIVE>()` under
    /// actuator force `f`, into `dy`; returns the platen acceleration. The slip case of
    /// [`Stepper::rates`], compiled per direction so that `±v` and `±D` fold (exact for ±1).
    #[inline(always)]
    fn slip_rates<const POSITIVE: bool>(&self, f: f64, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        let part = self.storey_part(y);
        let bs = -part.shear0;
        let r = self
            .model
            .slip_rates(f - bs, y[U], y[V], direction::<POSITIVE>());
        dy[U] = y[V];
        dy[V] = r.a_m_s2;
        dy[W] = f * y[V];
        dy[DI] = r.dissipated_power_w;
        Self::storey_rates(&part, r.a_m_s2, y, dy);
        r.a_m_s2
    }

    /// The rates of the full state in `mode` under actuator force `f`, into `dy`; returns the
    /// platen acceleration.
    #[inline(always)]
    fn rates(&self, mode: Mode, f: f64, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        match mode {
            Mode::Slip(Direction::Positive) => return self.slip_rates::<true>(f, y, dy),
            Mode::Slip(Direction::Negative) => return self.slip_rates::<false>(f, y, dy),
            _ => {}
        }
        let part = self.storey_part(y);
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
                let w = creep_speed_m_s(self.model, dir, y[U], f - bs, self.w_stiff)
                    .unwrap_or(self.w_stiff);
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
        Self::storey_rates(&part, a, y, dy);
        a
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
        let mut zdd0 = [0.0; NS];
        self.spec
            .storey_accelerations(0.0, &y[Z..Z + n], &y[zd..zd + n], &mut zdd0[..n]);
        let st = self.spec.storeys()[0];
        let b_rate0 = -(st.stiffness_n_per_m * y[zd] + st.damping_n_s_per_m * zdd0[0]);
        let w_rate = (s * (self.f_rate - b_rate0) - e_u * s * w) / (e_w + st.damping_n_s_per_m);
        if w_rate.is_finite() {
            s * w_rate
        } else {
            0.0
        }
    }

    /// One RK4 step of length `len` (fraction of `h`) from fraction `s` of step `n`, from `y`
    /// with rates `k1` there: the state at the end and the smallest stage speed `dir·v` (slip).
    #[inline(always)]
    fn rk4(&mut self, n: GridStep, s: f64, len: f64, y: &Y<L>, k1: &Y<L>) -> (Y<L>, f64) {
        let mode = self.mode;
        let h = len * self.grid.h;
        let (f_mid, f_end) = (
            self.grid.force(n, s + 0.5 * len),
            self.grid.force(n, s + len),
        );
        let combine = |base: &Y<L>, k: &Y<L>, c: f64| {
            let mut out = *base;
            for i in 0..L {
                out[i] += c * k[i];
            }
            out
        };
        let (mut k2, mut k3, mut k4) = ([0.0; L], [0.0; L], [0.0; L]);
        let y2 = combine(y, k1, 0.5 * h);
        self.rates(mode, f_mid, &y2, &mut k2);
        let y3 = combine(y, &k2, 0.5 * h);
        self.rates(mode, f_mid, &y3, &mut k3);
        let y4 = combine(y, &k3, h);
        self.rates(mode, f_end, &y4, &mut k4);
        self.stats.rhs_evaluations += 3;
        let h6 = h / 6.0;
        let mut y1 = *y;
        for i in 0..L {
            y1[i] += h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let stage_min = match mode {
            Mode::Slip(dir) => {
                let d = dir.sign();
                (d * y2[V]).min(d * y3[V]).min(d * y4[V])
            }
            _ => f64::INFINITY,
        };
        if let Mode::Creep(dir) = mode {
            y1[V] = self.creep_velocity(dir, &y1, f_end);
        }
        (y1, stage_min)
    }

    /// The signed creep velocity at state `y` under force `f`.
    fn creep_velocity(&self, dir: Direction, y: &Y<L>, f: f64) -> f64 {
        let w = creep_speed_m_s(self.model, dir, y[U], f - self.base_shear(y), self.w_stiff)
            .unwrap_or(self.w_stiff);
        dir.sign() * w
    }

    /// The current mode's state over a length `x` (fraction of `h`) from fraction `tau` of step
    /// `n`, split by `grading`; with the smallest stage speed.
    fn piece(&mut self, n: GridStep, tau: f64, x: f64, grading: Grading) -> (Y<L>, f64) {
        let (mut y, mut k) = (self.y, self.k);
        let mut stage_min = f64::INFINITY;
        let mut s = tau;
        for (i, &p) in grading.pieces().iter().enumerate() {
            let len = p * x;
            if i > 0 {
                let f = self.grid.force(n, s);
                self.rates(self.mode, f, &y, &mut k);
                self.stats.rhs_evaluations += 1;
            }
            let (y1, m) = self.rk4(n, s, len, &y, &k);
            y = y1;
            stage_min = stage_min.min(m);
            s += len;
        }
        (y, stage_min)
    }

    /// The net force `N = F_A − F_E(u) − B` at state `y` under force `f`.
    #[inline(always)]
    fn net(&self, y: &Y<L>, f: f64) -> f64 {
        f - self.model.elastic_force_n(y[U]) - self.base_shear(y)
    }

    /// The current mode's event function: positive until the mode ends.
    #[inline(always)]
    fn event_g(&self, y: &Y<L>, f: f64) -> f64 {
        match self.mode {
            Mode::Slip(dir) => dir.sign() * y[V],
            Mode::Stick => self.model.static_threshold_n(y[U]) - self.net(y, f).abs(),
            Mode::Creep(dir) => {
                let sn = dir.sign() * self.net(y, f);
                (sn - self.model.static_threshold_n(y[U])).min(self.exit_level(dir, y[U]) - sn)
            }
        }
    }

    /// The drive `s·N` at which creep hands over to slip (the creep speed reaches `w_*`).
    fn exit_level(&self, dir: Direction, u: f64) -> f64 {
        let s = dir.sign();
        self.model.static_threshold_n(u)
            + self.model.dissipative_excess_n(u, self.w_stiff)
            + s * self.model.velocity_inertial_force_n(u, s * self.w_stiff)
    }

    /// Whether the event function may dip to zero inside a piece of length `len` (fraction
    /// of `h`) from the current state (force `f0`) to `y1` (force `f1`, rates
    /// `k1`, platen acceleration `a1`): the cubic Hermite interpolant of the speed (slip) or
    /// of `F_s ∓ N` (stick) touches zero.
    #[allow(clippy::too_many_arguments)]
    fn dips(&self, len: f64, f0: f64, y1: &Y<L>, f1: f64, k1: &Y<L>, a1: f64) -> bool {
        let span = len * self.grid.h;
        match self.mode {
            Mode::Slip(dir) => {
                let d = dir.sign();
                dip_to_zero(d * self.y[V], d * y1[V], d * self.a * span, d * a1 * span).is_some()
            }
            Mode::Stick => {
                // Ṅ = Ḟ_A − Ḃ = Ḟ_A + k₁ż₁ + c₁z̈₁ (u fixed), times the piece's length.
                let slope = self.f_rate;
                let st = self.spec.storeys()[0];
                let n_rate = |k: &Y<L>| {
                    (slope + st.stiffness_n_per_m * k[Z] + st.damping_n_s_per_m * k[Self::ZD])
                        * span
                };
                let fs = self.model.static_threshold_n(self.y[U]);
                let (n0, n1) = (self.net(&self.y, f0), self.net(y1, f1));
                let (d0, d1) = (n_rate(&self.k), n_rate(k1));
                dip_to_zero(fs - n0, fs - n1, -d0, -d1).is_some()
                    || dip_to_zero(fs + n0, fs + n1, d0, d1).is_some()
            }
            Mode::Creep(_) => false,
        }
    }

    /// Switches to `mode` at the current state under force `f`: its rates (and the stiff
    /// speed of a creep phase).
    fn enter(&mut self, mode: Mode, f: f64) {
        self.mode = mode;
        if let Mode::Creep(dir) = mode {
            self.w_stiff = stiff_speed_m_s(self.model, self.y[U], self.grid.h);
            let y = self.y;
            self.y[V] = self.creep_velocity(dir, &y, f);
        }
        let (y, mut k) = (self.y, [0.0; L]);
        self.a = self.rates(mode, f, &y, &mut k);
        self.k = k;
        self.stats.rhs_evaluations += 1;
    }

    /// Advances from grid point `n` to `n + 1`, handling every event inside the step.
    ///
    /// A step in slip away from rest first tries [`Stepper::slip_fast`] (compiled per
    /// direction); anything it does not commit, and every other mode, goes through the
    /// generic [`Stepper::advance`].
    #[inline(always)]
    fn step(&mut self, n: GridStep) -> Result<()> {
        self.stats.steps += 1;
        let committed = match self.mode {
            Mode::Slip(Direction::Positive) if self.y[V] != 0.0 => self.slip_fast::<true>(n),
            Mode::Slip(Direction::Negative) if self.y[V] != 0.0 => self.slip_fast::<false>(n),
            _ => false,
        };
        if committed {
            return Ok(());
        }
        self.step_with_events(n)
    }

    /// One RK4 step over the whole grid step `n` in slip with direction
    /// `direction::<POSITIVE>()` (the platen moving, `v ≠ 0`), committed when it is safe:
    /// exactly the first try of [`Stepper::advance`] (`τ = 0`, a single piece of length 1),
    /// the same operations in the same order, so what it commits is bit for bit what
    /// [`Stepper::advance`] would. Returns whether it committed; if not, nothing has changed
    /// (statistics included) and the step is taken again by [`Stepper::step_with_events`].
    #[inline(always)]
    fn slip_fast<const POSITIVE: bool>(&mut self, n: GridStep) -> bool {
        let dir = direction::<POSITIVE>();
        // The piece is the whole step: `len = 1 − 0`, `len·h = h`.
        let h = self.grid.h;
        let (f_mid, f_end) = (self.grid.force(n, 0.5), self.grid.force(n, 1.0));
        let (y, k1) = (&self.y, &self.k);
        let hh = 0.5 * h;
        let (mut k2, mut k3, mut k4) = ([0.0; L], [0.0; L], [0.0; L]);
        let mut y2 = *y;
        for i in 0..L {
            y2[i] += hh * k1[i];
        }
        self.slip_rates::<POSITIVE>(f_mid, &y2, &mut k2);
        let mut y3 = *y;
        for i in 0..L {
            y3[i] += hh * k2[i];
        }
        self.slip_rates::<POSITIVE>(f_mid, &y3, &mut k3);
        let mut y4 = *y;
        for i in 0..L {
            y4[i] += h * k3[i];
        }
        self.slip_rates::<POSITIVE>(f_end, &y4, &mut k4);
        let h6 = h / 6.0;
        let mut y1 = *y;
        for i in 0..L {
            y1[i] += h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let stage_min = (dir * y2[V]).min(dir * y3[V]).min(dir * y4[V]);
        if !(dir * y1[V] > 0.0 && stage_min > 0.0 && y1.iter().all(|x| x.is_finite())) {
            return false;
        }
        let mut k_end = [0.0; L];
        let a1 = self.slip_rates::<POSITIVE>(f_end, &y1, &mut k_end);
        let (d0, d1) = (dir * self.a * h, dir * a1 * h);
        if dip_to_zero(dir * self.y[V], dir * y1[V], d0, d1).is_some() || !a1.is_finite() {
            return false;
        }
        self.stats.rhs_evaluations += 4;
        (self.y, self.k, self.a) = (y1, k_end, a1);
        true
    }

    /// [`Stepper::step`] through the generic [`Stepper::advance`]: every mode and event.
    fn step_with_events(&mut self, n: GridStep) -> Result<()> {
        self.f_rate = self.force_rate(n.j);
        let mut tau = 0.0;
        let mut events = 0u32;
        loop {
            match self.advance(n, tau)? {
                StepStop::Step => return Ok(()),
                StepStop::Event { at, .. } | StepStop::Moved { at } => tau = at,
            }
            events += 1;
            if tau >= 1.0 {
                return Ok(());
            }
            if events > MAX_EVENTS_PER_STEP {
                let stalled = Failure::EventLoopStalled { events };
                return Err(IntegrateError::failed(self.grid.time_s(n, tau), stalled));
            }
        }
    }

    /// Advances in the current mode from fraction `tau` of step `n` to the end of the step or
    /// the mode's next event: the rest of the step is tried and halved until a piece is safe
    /// (committed) or ends across the event, which is then located on the RK4 map.
    fn advance(&mut self, n: GridStep, tau: f64) -> Result<StepStop> {
        let f0 = self.grid.force(n, tau);
        let slip = matches!(self.mode, Mode::Slip(_));
        let from_rest = slip && self.y[V] == 0.0;
        if let (Mode::Slip(dir), true) = (self.mode, from_rest) {
            // Leaving rest below the stiff speed: creep (see the module docs).
            let w_stiff = stiff_speed_m_s(self.model, self.y[U], self.grid.h);
            let f_eff = f0 - self.base_shear(&self.y);
            if creep_speed_m_s(self.model, dir, self.y[U], f_eff, w_stiff).is_some() {
                self.enter(Mode::Creep(dir), f0);
                return Ok(StepStop::Moved { at: tau });
            }
        }
        let (try_grading, event_grading) = match (slip, from_rest) {
            (true, true) => (Grading::Start, Grading::Both),
            (true, false) => (Grading::Single, Grading::End),
            _ => (Grading::Single, Grading::Single),
        };
        let mut len = 1.0 - tau;
        for _ in 0..=MAX_HALVINGS {
            let (y1, stage_min) = self.piece(n, tau, len, try_grading);
            if !y1.iter().all(|x| x.is_finite()) {
                return Err(self.non_finite(n, tau));
            }
            let f1 = self.grid.force(n, tau + len);
            let g1 = self.event_g(&y1, f1);
            if g1 > 0.0 && stage_min > 0.0 {
                let mut k1 = [0.0; L];
                let a1 = self.rates(self.mode, f1, &y1, &mut k1);
                self.stats.rhs_evaluations += 1;
                if !self.dips(len, f0, &y1, f1, &k1, a1) {
                    if !a1.is_finite() {
                        return Err(self.non_finite(n, tau + len));
                    }
                    if self.mode == Mode::Stick {
                        self.stats.stick_time_s += len * self.grid.h;
                    }
                    (self.y, self.k, self.a) = (y1, k1, a1);
                    let at = tau + len;
                    return Ok(if at >= 1.0 {
                        StepStop::Step
                    } else {
                        StepStop::Moved { at }
                    });
                }
            } else if g1 <= 0.0 {
                let (y2, g2) = if event_grading == try_grading {
                    (y1, g1)
                } else {
                    let (y2, _) = self.piece(n, tau, len, event_grading);
                    (y2, self.event_g(&y2, f1))
                };
                if g2 <= 0.0 {
                    let g0 = self.event_g(&self.y, f0);
                    let tolerance = 4.0 * f64::EPSILON * len;
                    let Ok(found) = locate_zero_velocity(len, g0, (y2, g2), tolerance, |x| {
                        self.stats.root_iterations += 1;
                        let (y, _) = self.piece(n, tau, x, event_grading);
                        let g = self.event_g(&y, self.grid.force(n, tau + x));
                        Ok::<_, Infallible>((y, g))
                    });
                    let (x, y_event) = found.unwrap_or((0.0, self.y));
                    return Ok(self.event(n, tau, x, y_event));
                }
            }
            len *= 0.5;
        }
        // A piece of 2⁻⁶⁰ of the step still not safe: the event is here.
        let y = self.y;
        Ok(self.event(n, tau, 0.0, y))
    }

    /// The reset at the current mode's event, located at `x` (fraction of `h`) past fraction
    /// `tau` of step `n` with state `y_event` there.
    fn event(&mut self, n: GridStep, tau: f64, x: f64, y_event: Y<L>) -> StepStop {
        let mut at = tau + x;
        if 1.0 - at < 1e-12 {
            at = 1.0;
        }
        match self.mode {
            Mode::Slip(from) => {
                self.y = y_event;
                self.y[V] = 0.0;
                let f = self.grid.force(n, at);
                let f_eff = f - self.base_shear(&self.y);
                let (mode, kind) = arrive_at_rest(self.model, self.y[U], f_eff, from);
                self.enter(mode, f);
                match kind {
                    Some(kind) => {
                        self.stats.record(kind);
                        StepStop::Event { at, kind }
                    }
                    None => StepStop::Moved { at },
                }
            }
            Mode::Stick => {
                // Move past rounding so that |N| > F_s holds where slip starts.
                let u = self.y[U];
                let fs = self.model.static_threshold_n(u);
                let end = 1.0 - tau;
                let x_b = just_past(x, end, |x| {
                    let (y, _) = self.piece_at_rest(n, tau, x);
                    self.net(&y, self.grid.force(n, tau + x)).abs() > fs
                });
                let y = if x_b == x {
                    y_event
                } else {
                    self.piece_at_rest(n, tau, x_b).0
                };
                let at = (tau + x_b).min(1.0);
                self.stats.stick_time_s += x_b * self.grid.h;
                self.y = y;
                let f = self.grid.force(n, at);
                let net = self.net(&y, f);
                if net.abs() <= fs {
                    // Rounding kept friction holding to the end of the step: still stuck.
                    self.enter(Mode::Stick, f);
                    return StepStop::Moved { at };
                }
                self.stats.record(EventKind::Breakaway);
                self.enter(Mode::Slip(Direction::of_sign(net)), f);
                StepStop::Event {
                    at,
                    kind: EventKind::Breakaway,
                }
            }
            Mode::Creep(dir) => {
                let start = self.y;
                self.y = y_event;
                let mut f = self.grid.force(n, at);
                let sn = dir.sign() * self.net(&self.y, f);
                let fs = self.model.static_threshold_n(self.y[U]);
                if sn - fs <= self.exit_level(dir, self.y[U]) - sn {
                    // The drive fell to the threshold: a stop (or, past rounding, creep on or
                    // a reversal, as the net force at rest decides).
                    self.y[V] = 0.0;
                    let f_eff = f - self.base_shear(&self.y);
                    let mut mode = mode_at_rest(self.model, self.y[U], f_eff);
                    if mode == Mode::Slip(dir) && x <= MIN_PROGRESS {
                        // The stop rounded onto the start of the advance, where the net force
                        // at rest is a hair along the motion: creeping on from here would
                        // locate the same stop again without moving time. Step just past it,
                        // to where the net force at rest no longer drives the creep on (see
                        // `crate::creep`, whose passes do the same).
                        (at, f) = self.creep_just_past(n, tau, x, start, dir);
                        mode = mode_at_rest(self.model, self.y[U], f - self.base_shear(&self.y));
                    }
                    match mode {
                        Mode::Slip(d) if d == dir => {
                            self.enter(Mode::Creep(dir), f);
                            StepStop::Moved { at }
                        }
                        Mode::Stick => {
                            self.stats.record(EventKind::Stop);
                            self.enter(Mode::Stick, f);
                            StepStop::Event {
                                at,
                                kind: EventKind::Stop,
                            }
                        }
                        other => {
                            self.stats.record(EventKind::Reversal);
                            self.enter(other, f);
                            StepStop::Event {
                                at,
                                kind: EventKind::Reversal,
                            }
                        }
                    }
                } else {
                    // The creep speed reached the stiff speed: slip on from that velocity.
                    let v = self.creep_velocity(dir, &self.y.clone(), f);
                    self.y[V] = if v == 0.0 {
                        dir.sign() * f64::MIN_POSITIVE
                    } else {
                        v
                    };
                    self.enter(Mode::Slip(dir), f);
                    StepStop::Moved { at }
                }
            }
        }
    }

    /// A creep stop located `x ≤` [`MIN_PROGRESS`] past fraction `tau` of step `n` (from the
    /// state `start`) where the net force at rest still drives the creep on in `dir`: creeps
    /// from `start` to the first of `x + 4ε, x + 8ε, …` ([`just_past`]) where it does not,
    /// or to the end of the step, and makes that the state (at rest, `v = 0`). Returns where
    /// (fraction of the step) and the force there.
    fn creep_just_past(
        &mut self,
        n: GridStep,
        tau: f64,
        x: f64,
        start: Y<L>,
        dir: Direction,
    ) -> (f64, f64) {
        let stopped = self.y;
        self.y = start;
        let x_b = just_past(x, 1.0 - tau, |x| {
            let (y, _) = self.piece(n, tau, x, Grading::Single);
            let f = self.grid.force(n, tau + x);
            mode_at_rest(self.model, y[U], f - self.base_shear(&y)) != Mode::Slip(dir)
        });
        self.y = if x_b > x {
            self.piece(n, tau, x_b, Grading::Single).0
        } else {
            stopped
        };
        self.y[V] = 0.0;
        let mut at = tau + x_b;
        if 1.0 - at < 1e-12 {
            at = 1.0;
        }
        (at, self.grid.force(n, at))
    }

    /// The stuck state over a length `x` from fraction `tau` of step `n` (one RK4 step).
    fn piece_at_rest(&mut self, n: GridStep, tau: f64, x: f64) -> (Y<L>, f64) {
        self.piece(n, tau, x, Grading::Single)
    }

    /// The error of a state found non-finite at fraction `tau` of step `n`.
    fn non_finite(&self, n: GridStep, tau: f64) -> IntegrateError {
        let cause = Failure::NonFiniteState {
            u_m: self.y[U],
            v_m_s: self.y[V],
        };
        IntegrateError::failed(self.grid.time_s(n, tau), cause)
    }

    fn kin(&self) -> Kin {
        Kin {
            u: self.y[U],
            v: self.y[V],
            work: self.y[W],
            dissipated: self.y[DI],
        }
    }

    /// The output sample at sample `j` of the record (grid point `j·k`).
    fn sample(&self, j: usize, t_s: f64) -> Sample {
        let f = self.grid.force[j];
        let bs = self.base_shear(&self.y);
        // The platen's own terms see F_A − B; the remainder F_D then excludes the base shear.
        let mut sample = sample_at(
            self.model,
            j,
            t_s,
            f - bs,
            self.kin(),
            self.a,
            self.mode == Mode::Stick,
        );
        sample.terms.actuator_n = f;
        let mut spec = SpecimenSample {
            base_shear_n: bs,
            storeys: Self::N,
            u_m: [0.0; NS],
            a_m_s2: [0.0; NS],
            drift_m: [0.0; NS],
        };
        let mut below = 0.0;
        for i in 0..Self::N {
            spec.u_m[i] = self.y[Z + i];
            spec.a_m_s2[i] = self.a + self.k[Self::ZD + i];
            spec.drift_m[i] = self.y[Z + i] - below;
            below = self.y[Z + i];
        }
        sample.specimen = Some(spec);
        sample
    }

    /// Closes the energy balance at the current state, the run having finished at `t_s`.
    fn finish(&mut self, t_s: f64) -> RunStats {
        let y = self.y;
        self.stats.energy.close(self.model, y[U], y[V], y[W], y[DI]);
        self.stats.energy.specimen_end_j = self.specimen_energy(&y);
        self.stats.energy.specimen_dissipated_j = y[SD];
        self.stats.accepted_steps = self.stats.steps;
        self.stats.stop = StopReason::Finished { t_s };
        self.stats
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
            let bs = spec.base_shear_n(y[Z], y[Z + 3]);
            assert_eq!(bs.to_bits(), (-part.shear0).to_bits(), "case {case}");
        }
    }
}
