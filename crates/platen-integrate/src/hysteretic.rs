//! A shear building whose storeys yield ([`platen_model::hysteresis`]), stepped on a
//! prescribed base motion by RK4 with exact yield and unloading events.
//!
//! # State
//!
//! Per storey (bottom first) the displacement `zᵢ` relative to the platen, its rate `żᵢ`, the
//! hysteretic state variable `hᵢ` (bilinear: the plastic drift, m; Bouc–Wen: the hysteretic
//! force, N; 0 on a linear storey) and the energy dissipated in hysteresis `E_hᵢ`, J, plus
//! the bilinear storeys' branches. The storey shear is `Vᵢ = Fᵢ(δᵢ, hᵢ) + cᵢ·δ̇ᵢ`, and
//! `mᵢ·(a + z̈ᵢ) = −Vᵢ + Vᵢ₊₁` as for linear storeys.
//!
//! # Events
//!
//! Between events every bilinear storey is linear on its branch, so RK4 converges at its
//! order. After each piece the storeys' event margins
//! ([`HystereticStorey::event_margin`]) are checked; where one has fallen below zero, the
//! earliest crossing is located by Illinois root finding on the length of the RK4 map from
//! the piece's start, the state is taken just past it, the storey changes branch there
//! ([`HystereticStorey::after_event`]) and the rest of the piece is stepped on. Bouc–Wen's
//! force is integrated with the rest of the state; its law has a kink where the drift rate
//! crosses zero (its `sgn(δ̇·q)`), located the same way so that RK4 keeps its order there.

use std::convert::Infallible;

use platen_model::{Branch, HystereticStorey, Specimen};

use crate::event::locate_zero_velocity;

const NS: usize = Specimen::MAX_STOREYS;

/// The most events a single sub-step may hold before the rest of it is taken without looking
/// further: far more than a drift can turn or yield in a tenth of a millisecond.
const MAX_EVENTS_PER_STEP: usize = 64;

/// The most pieces a sub-step is cut into for a stiff Bouc–Wen storey.
const MAX_STIFF_PIECES: f64 = 4096.0;

/// The share of `q_y` beyond which a Bouc–Wen storey's excursion is counted as a yield (the law
/// has no yield point; at 90 % the tangent stiffness has fallen to a small share of the
/// elastic one for the exponents in use).
pub(crate) const BOUC_WEN_YIELD_SHARE: f64 = 0.9;

/// A shear building with hysteretic storeys: its constants and its state.
#[derive(Debug, Clone)]
pub(crate) struct HystereticBuilding {
    n: usize,
    m: [f64; NS],
    k: [f64; NS],
    c: [f64; NS],
    /// The storeys that yield.
    hyst: [Option<HystereticStorey>; NS],
    /// The state `[z, ż, h, E_h]`, each block of `NS`.
    pub(crate) y: State,
    /// The hysteretic storeys' branches (`Elastic` for the linear ones).
    pub(crate) branch: [Branch; NS],
    /// The energy dissipated by the storey dampers, J.
    pub(crate) damper_j: f64,
    /// Yield excursions, per storey: a bilinear storey's yield events; a Bouc–Wen storey's
    /// passages of `|q|` beyond [`BOUC_WEN_YIELD_SHARE`] of `q_y`, once per direction of drift.
    pub(crate) yield_events: [usize; NS],
    /// Whether a Bouc–Wen storey's excursion in its current direction has been counted.
    counted: [bool; NS],
    /// The events met since they were last drained, if they are being logged.
    log: Option<Vec<StoreyEvent>>,
}

/// A bilinear storey's event: it began to yield, or unloaded back onto its elastic branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StoreyEvent {
    /// When, s.
    pub t_s: f64,
    /// The storey, from 0 (bottom first).
    pub storey: usize,
    /// Yield (`true`: the drift reached the elastic range's edge while loading) or unloading
    /// (`false`: the drift rate turned back while yielding).
    pub yielded: bool,
}

/// The building's state: `z`, `ż`, `h` and `E_h` per storey.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct State {
    pub(crate) z: [f64; NS],
    pub(crate) zd: [f64; NS],
    pub(crate) h: [f64; NS],
    pub(crate) e: [f64; NS],
}

impl State {
    const ZERO: Self = Self {
        z: [0.0; NS],
        zd: [0.0; NS],
        h: [0.0; NS],
        e: [0.0; NS],
    };
}

/// The rates of a [`State`], and the storey dampers' power.
struct Rates {
    zdd: [f64; NS],
    hd: [f64; NS],
    ed: [f64; NS],
    damper_w: f64,
}

impl HystereticBuilding {
    /// The building of `specimen` (a shear building; its linear storeys are linear here too),
    /// at rest relative to the platen.
    pub(crate) fn new(specimen: &Specimen) -> Self {
        let n = specimen.len();
        let mut b = Self {
            n,
            m: [0.0; NS],
            k: [0.0; NS],
            c: [0.0; NS],
            hyst: [None; NS],
            y: State::ZERO,
            branch: [Branch::Elastic; NS],
            damper_j: 0.0,
            yield_events: [0; NS],
            counted: [false; NS],
            log: None,
        };
        for (i, s) in specimen.storeys().iter().enumerate() {
            (b.m[i], b.k[i], b.c[i]) = (s.mass_kg, s.stiffness_n_per_m, s.damping_n_s_per_m);
            b.hyst[i] = specimen.hysteretic_storey(i);
            if let Some(h) = &b.hyst[i] {
                b.branch[i] = h.initial_branch();
            }
        }
        b
    }

    /// Keeps a log of the events from now on ([`HystereticBuilding::take_events`]).
    pub(crate) fn log_events(&mut self) {
        self.log = Some(Vec::new());
    }

    /// The events logged so far, in time order, emptying the log.
    pub(crate) fn take_events(&mut self) -> Vec<StoreyEvent> {
        self.log.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// The number of storeys.
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    /// Storey `i`'s restoring force (dashpot excluded), N, at state `y`.
    pub(crate) fn force_n(&self, i: usize, y: &State) -> f64 {
        let d = self.drift(i, &y.z);
        match &self.hyst[i] {
            Some(h) => h.force_n(d, y.h[i], self.branch[i]),
            None => self.k[i] * d,
        }
    }

    /// Storey `i`'s hysteretic force `q`, N (0 for a linear storey).
    pub(crate) fn hysteretic_force_n(&self, i: usize, y: &State) -> f64 {
        match &self.hyst[i] {
            Some(h) => h.hysteretic_force_n(self.drift(i, &y.z), y.h[i], self.branch[i]),
            None => 0.0,
        }
    }

    #[inline(always)]
    fn drift(&self, i: usize, z: &[f64; NS]) -> f64 {
        if i == 0 {
            z[0] - 0.0
        } else {
            z[i] - z[i - 1]
        }
    }

    /// The base shear `B = −V₁`, N, at state `y`.
    pub(crate) fn base_shear_n(&self, y: &State) -> f64 {
        -(self.force_n(0, y) + self.c[0] * y.zd[0])
    }

    /// The rates at base acceleration `a`: the same storey-shear recursion as
    /// [`Specimen::storey_accelerations`], with each storey's restoring force.
    #[inline(always)]
    fn rates(&self, a: f64, y: &State) -> Rates {
        let n = self.n;
        let mut r = Rates {
            zdd: [0.0; NS],
            hd: [0.0; NS],
            ed: [0.0; NS],
            damper_w: 0.0,
        };
        let (mut z_prev, mut zd_prev, mut shear_prev) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let (d, dd) = (y.z[i] - z_prev, y.zd[i] - zd_prev);
            let spring = match &self.hyst[i] {
                Some(h) => {
                    (r.hd[i], r.ed[i]) = h.rates(dd, y.h[i], self.branch[i]);
                    h.force_n(d, y.h[i], self.branch[i])
                }
                None => self.k[i] * d,
            };
            let shear = spring + self.c[i] * dd;
            r.damper_w += self.c[i] * dd * dd;
            if i > 0 {
                r.zdd[i - 1] = (shear - shear_prev) / self.m[i - 1] - a;
            }
            (z_prev, zd_prev, shear_prev) = (y.z[i], y.zd[i], shear);
        }
        r.zdd[n - 1] = -shear_prev / self.m[n - 1] - a;
        r
    }

    /// The storeys' accelerations relative to the platen at base acceleration `a` and state
    /// `y`, m/s².
    pub(crate) fn relative_accelerations(&self, a: f64, y: &State) -> [f64; NS] {
        self.rates(a, y).zdd
    }

    /// The RK4 map of length `len·h` from `y` (the damper energy's increment beside it), the
    /// base acceleration `acc(s)` at the sub-step fraction `s` from `s0`.
    ///
    /// For `len = 1` it is the same arithmetic as the linear storeys' RK4 of the inverse run,
    /// so a building that never yields steps bit for bit as a linear one.
    #[inline(always)]
    fn map(&self, y: &State, h: f64, s0: f64, len: f64, acc: &impl Fn(f64) -> f64) -> (State, f64) {
        let n = self.n;
        let h = h * len;
        let stage = |y: &State, k: &Rates, dt: f64, v: &[f64; NS]| {
            let mut s = *y;
            for (j, vj) in v[..n].iter().enumerate() {
                s.z[j] = y.z[j] + dt * vj;
                s.zd[j] = y.zd[j] + dt * k.zdd[j];
                s.h[j] = y.h[j] + dt * k.hd[j];
                s.e[j] = y.e[j] + dt * k.ed[j];
            }
            s
        };
        let k1 = self.rates(acc(s0), y);
        let y2 = stage(y, &k1, 0.5 * h, &y.zd);
        let k2 = self.rates(acc(s0 + 0.5 * len), &y2);
        let y3 = stage(y, &k2, 0.5 * h, &y2.zd);
        let k3 = self.rates(acc(s0 + 0.5 * len), &y3);
        let y4 = stage(y, &k3, h, &y3.zd);
        let k4 = self.rates(acc(s0 + len), &y4);
        let mut out = *y;
        for j in 0..n {
            out.z[j] += h / 6.0 * (y.zd[j] + 2.0 * (y2.zd[j] + y3.zd[j]) + y4.zd[j]);
            out.zd[j] += h / 6.0 * (k1.zdd[j] + 2.0 * (k2.zdd[j] + k3.zdd[j]) + k4.zdd[j]);
            out.h[j] += h / 6.0 * (k1.hd[j] + 2.0 * (k2.hd[j] + k3.hd[j]) + k4.hd[j]);
            out.e[j] += h / 6.0 * (k1.ed[j] + 2.0 * (k2.ed[j] + k3.ed[j]) + k4.ed[j]);
        }
        let damper = h / 6.0 * (k1.damper_w + 2.0 * (k2.damper_w + k3.damper_w) + k4.damper_w);
        (out, damper)
    }

    /// Storey `i`'s event margin at state `y` (`+∞` for a storey without events).
    #[inline(always)]
    fn margin(&self, i: usize, y: &State) -> f64 {
        match &self.hyst[i] {
            Some(h) => {
                let dd = self.drift(i, &y.zd);
                h.event_margin(self.drift(i, &y.z), dd, y.h[i], self.branch[i])
            }
            None => f64::INFINITY,
        }
    }

    /// Takes one sub-step of length `h` from the sub-step fraction `s0` (counted from `t0_s`),
    /// the base acceleration `acc(s)`, with every yield and unloading event inside it located
    /// and the branch changed there.
    ///
    /// A Bouc–Wen storey whose own rate the sub-step does not resolve (a fast drift over a
    /// small yield drift: `|∂q̇/∂q| ≤ n·|δ̇|/δ_y·|q/q_y|ⁿ⁻¹`) has the sub-step cut into equal
    /// pieces each within it (`h·rate ≤ 1`, as the forward run's stiff pieces).
    pub(crate) fn step(&mut self, t0_s: f64, h: f64, s0: f64, acc: &impl Fn(f64) -> f64) {
        let pieces = (h * self.stiff_rate()).ceil().clamp(1.0, MAX_STIFF_PIECES);
        if pieces == 1.0 {
            self.step_events(t0_s, h, s0, 1.0, acc);
        } else {
            for p in 0..pieces as u32 {
                let s = s0 + f64::from(p) / pieces;
                self.step_events(t0_s, h, s, 1.0 / pieces, acc);
            }
        }
        for i in 0..self.n {
            if let Some(hy) = &self.hyst[i] {
                // Loading (the drift moving the way of q) past the share of the yield level.
                let loading = matches!(self.branch[i], Branch::Moving(d) if d * self.y.h[i] > 0.0);
                if !hy.is_bilinear()
                    && loading
                    && !self.counted[i]
                    && self.y.h[i].abs() >= BOUC_WEN_YIELD_SHARE * hy.qy
                {
                    self.counted[i] = true;
                    self.yield_events[i] += 1;
                }
            }
        }
    }

    /// The stiffest Bouc–Wen storey's own rate at the current state, 1/s (0 without one).
    fn stiff_rate(&self) -> f64 {
        let mut rate: f64 = 0.0;
        for i in 0..self.n {
            if let Some(h) = &self.hyst[i] {
                rate = rate.max(h.own_rate_1_s(self.drift(i, &self.y.zd), self.y.h[i]));
            }
        }
        rate
    }

    /// [`HystereticBuilding::step`] over `len` sub-steps from `s0`, but for the counting of
    /// Bouc–Wen excursions.
    fn step_events(&mut self, t0_s: f64, h: f64, s0: f64, len: f64, acc: &impl Fn(f64) -> f64) {
        let (mut s, mut left) = (s0, len);
        // Storeys found on their boundary at a piece's start whose event did not change their
        // branch (a graze): not looked at again in this sub-step.
        let mut grazed = [false; NS];
        for _ in 0..MAX_EVENTS_PER_STEP {
            let (end, damper) = self.map(&self.y, h, s, left, acc);
            // The earliest crossing, as a length in sub-steps from `s`.
            let mut first: Option<(f64, usize)> = None;
            for (i, &grazed) in grazed[..self.n].iter().enumerate() {
                if grazed || self.margin(i, &end) >= 0.0 {
                    continue;
                }
                let at = self.crossing(i, h, s, left, acc);
                if first.is_none_or(|(t, _)| at < t) {
                    first = Some((at, i));
                }
            }
            let Some((at, i)) = first else {
                (self.y, self.damper_j) = (end, self.damper_j + damper);
                return;
            };
            let (y, damper) = self.map(&self.y, h, s, at, acc);
            (self.y, self.damper_j) = (y, self.damper_j + damper);
            let hyst = self.hyst[i].expect("only hysteretic storeys have events");
            let (d, dd) = (self.drift(i, &self.y.z), self.drift(i, &self.y.zd));
            let before = self.branch[i];
            let (branch, plastic) = hyst.after_event(d, dd, self.y.h[i], before);
            if branch == before {
                grazed[i] = true;
            } else if !hyst.is_bilinear() {
                self.counted[i] = false;
            } else {
                let yielded = branch != Branch::Elastic;
                self.yield_events[i] += usize::from(yielded);
                if let Some(log) = &mut self.log {
                    log.push(StoreyEvent {
                        t_s: t0_s + (s + at) * h,
                        storey: i,
                        yielded,
                    });
                }
            }
            (self.branch[i], self.y.h[i]) = (branch, plastic);
            s += at;
            left -= at;
            if left <= 0.0 {
                return;
            }
        }
        let (end, damper) = self.map(&self.y, h, s, left, acc);
        (self.y, self.damper_j) = (end, self.damper_j + damper);
    }

    /// Where storey `i`'s margin first reaches zero along the RK4 map from the current state,
    /// as a length in `[0, left]` (in sub-steps): the Illinois root finder of the platen's
    /// events ([`crate::event::locate_zero_velocity`]), bracketed until the bracket is a few
    /// ulps wide, the end just past the crossing returned; 0 when the storey starts on its
    /// boundary (just after the opposite event).
    fn crossing(&self, i: usize, h: f64, s0: f64, left: f64, acc: &impl Fn(f64) -> f64) -> f64 {
        let g = |len: f64| self.margin(i, &self.map(&self.y, h, s0, len, acc).0);
        let g0 = self.margin(i, &self.y);
        if g0 <= 0.0 {
            return 0.0;
        }
        let tolerance = 4.0 * f64::EPSILON * left.max(1.0);
        let found = locate_zero_velocity(left, g0, ((), g(left)), tolerance, |x| {
            Ok::<_, Infallible>(((), g(x)))
        });
        let Ok(found) = found;
        found.map_or(0.0, |(x, ())| x)
    }
}
