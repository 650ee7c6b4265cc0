//! The bare platen as a plant of the mode machine ([`crate::machine`]): its state is the
//! platen's `(u, v)` and the two energy integrals, its input the actuator force of a record.
//!
//! Slip, the location of `v = 0` and the reset there are the machine's. Rest is the plant's
//! own and exact, because nothing but the platen moves and the force is linear inside a grid
//! step:
//! * **stick**: `u` is fixed and the net force `N = F_A − F_E(u)` is linear in time, so the
//!   breakaway, where `|N|` reaches `F_s(u)`, is solved in closed form ([`breakaway`]) and
//!   moved [`just_past`] rounding;
//! * **creep**: the quasi-static creep of [`crate::creep`], in closed form over the rest of
//!   the step, with the stiff speed of the grid step;
//! * a platen leaves rest into creep when its creep speed stays below the stiff speed at both
//!   ends of the rest of the step.
//!
//! The work `∫F_A·v dt` of an RK4 step is summed as `F_mid·(v₂ + v₃)` at the shared middle
//! force ([`Plant::rk4_quadrature`]), and a fast step that is tried and not committed counts
//! its evaluations ([`Plant::COUNTS_TRIED_STEPS`]), as this engine always has: its runs keep
//! their bits and their counters.

use platen_model::PlatenModel;

use crate::clock::{Clock, GridClock};
use crate::creep::{creep, CreepEnd};
use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, breakaway, just_past, Direction, EventKind, Mode, MAX_EVENTS_PER_STEP,
};
use crate::grid::{Grid, GridStep, GridStepper};
use crate::machine::{direction, Machine, PieceMethod, Plant, Rk4Stages, DI, U, V, W};
use crate::output::Sample;
use crate::run::{EnergyBalance, Kin, RunStats, State};
use crate::stop::{Failure, StopReason};

/// The state: `u`, `v`, the actuator's work and the platen's dissipation.
const L: usize = 4;
type Y = [f64; L];

/// The bare platen under a force record, on the record's integer time grid; positions are
/// fractions of the current grid step `n`.
pub(crate) struct BarePlant<'a, M> {
    model: &'a M,
    /// The record's grid and the step being taken.
    pub(crate) clock: GridClock<'a>,
}

impl<'a, M: PlatenModel> Plant<L> for BarePlant<'a, M> {
    type Model = M;
    /// The actuator force, N.
    type Input = f64;

    #[inline(always)]
    fn model(&self) -> &M {
        self.model
    }

    /// Slip's rates; nothing at rest ([`Plant::RATES_AT_REST`] is false: rest is exact).
    #[inline(always)]
    fn rates(&self, mode: Mode, _w_stiff: f64, f: f64, y: &Y, dy: &mut Y) -> f64 {
        match mode {
            Mode::Slip(Direction::Positive) => self.slip_rates::<true>(f, y, dy),
            Mode::Slip(Direction::Negative) => self.slip_rates::<false>(f, y, dy),
            Mode::Stick | Mode::Creep(_) => {
                *dy = [0.0; L];
                0.0
            }
        }
    }

    #[inline(always)]
    fn slip_rates<const POSITIVE: bool>(&self, f: f64, y: &Y, dy: &mut Y) -> f64 {
        let r = self
            .model
            .slip_rates(f, y[U], y[V], direction::<POSITIVE>());
        *dy = [y[V], r.a_m_s2, f * y[V], r.dissipated_power_w];
        r.a_m_s2
    }

    #[inline(always)]
    fn effective_force(&self, f: f64, _y: &Y) -> f64 {
        f
    }

    /// `N = F_A − F_E(u)`.
    #[inline(always)]
    fn net(&self, f: f64, y: &Y) -> f64 {
        f - self.model.elastic_force_n(y[U])
    }

    /// `Ṅ = Ḟ_A` with `u` fixed (the machine never asks: stick is exact).
    fn net_rate(&self, _k: &Y) -> f64 {
        0.0
    }

    const RATES_ON_COMMIT: bool = false;
    const RATES_AT_REST: bool = false;
    const COUNTS_TRIED_STEPS: bool = true;

    /// Both ends of the rest of the step: the force is linear in between, and so is the
    /// creep speed's drive.
    fn creeps_from_rest(&self, dir: Direction, tau: f64, y: &Y, w_stiff: f64) -> bool {
        [self.input(tau), self.input(1.0)]
            .iter()
            .all(|&f| crate::creep::creep_speed_m_s(self.model, dir, y[U], f, w_stiff).is_some())
    }

    /// The work at the shared middle force, `F₀v + 2F_mid(v₂ + v₃) + F₁v₄`.
    #[inline(always)]
    fn rk4_quadrature(&self, i: usize, st: &Rk4Stages<'_, L, f64>) -> Option<f64> {
        (i == W).then(|| {
            let f_start = self.input(st.s);
            st.y[W]
                + st.h6
                    * (f_start * st.y[V]
                        + 2.0 * st.i_mid * (st.y2[V] + st.y3[V])
                        + st.i_end * st.y4[V])
        })
    }

    /// The motion only: the energy integrals report, a run goes on while `u` and `v` are
    /// finite.
    #[inline(always)]
    fn is_finite(&self, y: &Y) -> bool {
        y[U].is_finite() && y[V].is_finite()
    }

    /// Metres and m/s; the energy integrals are quadratures and not controlled.
    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64 {
        match i {
            W | DI => f64::INFINITY,
            _ => atol + rtol * y0.abs().max(y1.abs()),
        }
    }

    #[inline(always)]
    fn input(&self, at: f64) -> f64 {
        self.clock.force(at)
    }

    crate::clock::clock_field!(GridClock<'a>);
}

/// A forward run of the bare platen (also one lane of [`crate::ensemble`]): the mode machine
/// over the force record's grid, with the plant's exact rest.
pub(crate) struct Stepper<'a, M> {
    pub(crate) machine: Machine<BarePlant<'a, M>, L>,
}

impl<'a, M: PlatenModel> Stepper<'a, M> {
    /// An RK4 run of `model` on `grid` from `initial`.
    pub(crate) fn new(model: &'a M, grid: Grid<'a>, initial: State) -> Self {
        Self::with_method(model, grid, initial, PieceMethod::Rk4)
    }

    /// A run of `model` on `grid` from `initial` whose pieces are `method`'s.
    pub(crate) fn with_method(
        model: &'a M,
        grid: Grid<'a>,
        initial: State,
        method: PieceMethod,
    ) -> Self {
        let y = Kin::start(initial);
        let h = grid.h;
        let f0 = grid.force[0];
        let plant = BarePlant {
            model,
            clock: GridClock::new(grid),
        };
        let mut machine = Machine::new(plant, [y.u, y.v, y.work, y.dissipated], h, method);
        machine.enter(Mode::initial(model, y.u, y.v, f0), f0);
        machine.stats.energy = EnergyBalance::start(model, y.u, y.v);
        Stepper { machine }
    }

    /// The platen's state.
    #[inline(always)]
    pub(crate) fn kin(&self) -> Kin {
        let y = &self.machine.y;
        Kin {
            u: y[U],
            v: y[V],
            work: y[W],
            dissipated: y[DI],
        }
    }

    /// Commits a slip step taken outside (an ensemble lane): the state `y` with acceleration
    /// `a` and dissipated power `p` at the end of the step, under force `f`.
    #[inline(always)]
    pub(crate) fn commit_slip(&mut self, y: Kin, a: f64, p: f64, f: f64) {
        let m = &mut self.machine;
        m.y = [y.u, y.v, y.work, y.dissipated];
        m.k = [y.v, a, f * y.v, p];
        m.a = a;
    }

    /// The stick part of a step, from fraction `tau`: either friction holds the platen to
    /// the end of the step, or it breaks away ([`breakaway`], in closed form) and the mode
    /// becomes slip, from a point where `|N|` is above the threshold. Returns where.
    fn stick(&mut self, tau: f64) -> f64 {
        let m = &mut self.machine;
        let (p, u) = (&m.plant, m.y[U]);
        let h = p.clock.grid.h;
        let (f_start, f_end) = (p.input(tau), p.input(1.0));
        let Some(b) = breakaway(p.model, u, f_start, f_end) else {
            m.stats.stick_time_s += (1.0 - tau) * h;
            return 1.0;
        };
        let (elastic, threshold) = (p.model.elastic_force_n(u), p.model.static_threshold_n(u));
        let sign = b.direction.sign();
        let tau_b = just_past(tau + b.fraction * (1.0 - tau), 1.0, |t| {
            sign * (p.input(t) - elastic) > threshold
        });
        m.stats.stick_time_s += (tau_b - tau) * h;
        let f = m.plant.input(tau_b);
        m.note(EventKind::Breakaway, tau_b);
        m.enter(Mode::Slip(b.direction), f);
        tau_b
    }

    /// The creep part of a step in direction `dir`, from fraction `tau`: the quasi-static
    /// creep of [`crate::creep`] to the end of the step, a stop, or the return to slip.
    /// Returns where.
    fn creep(&mut self, tau: f64, dir: Direction) -> Result<f64> {
        let m = &mut self.machine;
        let h = m.plant.clock.grid.h;
        let span_s = (1.0 - tau) * h;
        let (f_start, f_end) = (m.plant.input(tau), m.plant.input(1.0));
        let y0 = self.kin();
        let m = &mut self.machine;
        let run = creep(m.plant.model, dir, y0, f_start, f_end, span_s, m.w_stiff);
        m.stats.rhs_evaluations += run.evaluations;
        m.y = [run.y.u, run.y.v, run.y.work, run.y.dissipated];
        let at = if run.at_s >= span_s {
            1.0
        } else {
            (tau + run.at_s / h).min(1.0)
        };
        if !(run.y.u.is_finite() && run.y.v.is_finite()) {
            return Err(self.non_finite(at));
        }
        let m = &mut self.machine;
        Ok(match run.end {
            CreepEnd::Continues => at,
            CreepEnd::Stops => {
                m.note(EventKind::Stop, at);
                m.enter(Mode::Stick, 0.0);
                at
            }
            CreepEnd::Slips => {
                let f = m.plant.input(at);
                m.enter(Mode::Slip(dir), f);
                at
            }
            CreepEnd::Reverses => {
                // Leave rest the other way from where the net force, as this step's grid
                // evaluates it, is beyond the threshold that way (creep's own time rounds).
                let (u, sign) = (m.y[U], dir.opposite().sign());
                let p = &m.plant;
                let (elastic, threshold) =
                    (p.model.elastic_force_n(u), p.model.static_threshold_n(u));
                let at = just_past(at, 1.0, |t| sign * (p.input(t) - elastic) > threshold);
                let f = m.plant.input(at);
                let (mode, kind) = arrive_at_rest(m.plant.model, u, f, dir);
                m.enter(mode, f);
                if let Some(kind) = kind {
                    m.note(kind, at);
                }
                at
            }
        })
    }

    /// The error of a state found non-finite at fraction `at` of the step.
    fn non_finite(&self, at: f64) -> IntegrateError {
        let y = &self.machine.y;
        let cause = Failure::NonFiniteState {
            u_m: y[U],
            v_m_s: y[V],
        };
        IntegrateError::failed(self.machine.plant.clock.time_s(at), cause)
    }

    /// Slip from fraction `tau`: one RK4 step to the end of the grid step when it is safe
    /// ([`Machine::slip_fast`], the platen moving), else the machine's advance.
    #[inline(always)]
    fn slip<const POSITIVE: bool>(&mut self, tau: f64) -> Result<f64> {
        let m = &mut self.machine;
        if m.is_rk4() && m.y[V] != 0.0 && m.slip_fast::<POSITIVE>(tau) {
            return Ok(1.0);
        }
        let at = m.advance(tau, 1.0 - tau)?;
        match m.take_failure() {
            Some((t_s, reason)) => {
                Err(IntegrateError::failed(t_s, Failure::AdaptiveFailed(reason)))
            }
            None => Ok(at),
        }
    }
}

impl<M: PlatenModel> GridStepper for Stepper<'_, M> {
    /// Advances from grid point `n` to `n + 1`, handling every event inside the step.
    #[inline]
    fn step(&mut self, n: GridStep) -> Result<()> {
        self.machine.plant.clock.n = n;
        self.machine.stats.steps += 1;
        let mut tau = 0.0;
        let mut events = 0u32;
        loop {
            let at = match self.machine.mode {
                Mode::Slip(Direction::Positive) => self.slip::<true>(tau)?,
                Mode::Slip(Direction::Negative) => self.slip::<false>(tau)?,
                Mode::Stick => self.stick(tau),
                Mode::Creep(dir) => self.creep(tau, dir)?,
            };
            tau = at;
            if tau >= 1.0 {
                return Ok(());
            }
            events += 1;
            if events > MAX_EVENTS_PER_STEP {
                let stalled = Failure::EventLoopStalled { events };
                return Err(IntegrateError::failed(
                    self.machine.plant.clock.time_s(tau),
                    stalled,
                ));
            }
        }
    }

    /// The output sample at sample `j` of the record (grid point `j·k`, τ = 0).
    fn sample(&self, j: usize, t_s: f64) -> Sample {
        let m = &self.machine;
        m.sample(j, t_s, m.plant.clock.grid.force[j], 0.0, None, 0)
    }

    /// Closes the energy balance at the current state, the run having finished at `t_s`.
    fn finish(&mut self, t_s: f64) -> RunStats {
        let y = self.kin();
        let m = &mut self.machine;
        let rk4 = m.is_rk4();
        let stats = &mut m.stats;
        stats
            .energy
            .close(m.plant.model, y.u, y.v, y.work, y.dissipated);
        if rk4 {
            stats.accepted_steps = stats.steps;
        } else {
            stats.steps = stats.accepted_steps + stats.rejected_steps;
        }
        stats.stop = StopReason::Finished { t_s };
        *stats
    }
}
