//! The one mode machine of the plants whose state goes beyond the platen's own: the platen
//! carrying a specimen ([`crate::forward_rk4_specimen`]) and the closed loop
//! ([`crate::forward_closed_loop`]). A [`Plant`] says what its state is and how it moves; the
//! [`Machine`] advances it through the friction modes with RK4 or Dormand–Prince 5(4).
//!
//! # What the machine does
//!
//! Inside one span of time without an outside cut (a grid step of a force record, a piece of
//! a controller period) the machine advances in the current mode until the span ends or the
//! mode's event function (the speed in slip; `F_s − |N|` in stick; the creep band in creep)
//! reaches zero:
//! * the rest of the span is tried and halved until a piece is *safe* (the event function is
//!   positive at its end, at the stages, and on the cubic Hermite interpolant of its start
//!   and end) or ends across the event;
//! * the event is located by Illinois root finding on the integrator's own map
//!   ([`locate_zero_velocity`]) and its reset applied ([`Machine::event`]): slip → rest
//!   ([`arrive_at_rest`]), breakaway (moved [`just_past`] rounding), creep → stop, reversal or
//!   slip;
//! * a platen leaving rest with a creep speed below the stiff speed creeps
//!   ([`crate::creep`]).
//!
//! # Where time is kept
//!
//! A plant's time is its [`Clock`]'s, kept apart from its right-hand side and its events: the
//! fraction of a grid step for a force record, seconds from the start of the advance for the
//! closed loop ([`crate::clock`]). The machine passes lengths and positions in the clock's
//! units and asks the clock ([`Clock::seconds`], [`Clock::land`], ...) where a located event
//! lands, so that each driver's arithmetic of time is its own and its runs keep their bits.
//!
//! # The integrators
//!
//! A piece is one RK4 step, graded near rest ([`Grading`]), or an adaptive Dormand–Prince
//! 5(4) that meets `rtol`/`atol` over it, scaled per state ([`Plant::error_scale`]). Dopri5
//! that cannot meet its tolerance (the step budget [`pieces::MAX_STEPS`] spent or the step shrunk
//! to nothing) stops the run with [`AdaptiveFailure`] ([`Machine::take_failure`]).

use std::convert::Infallible;

use platen_model::{PlatenModel, Specimen};

use crate::clock::{Clock, SecondsClock};
use crate::creep::{below_stiff_speed, creep_speed_m_s, stiff_speed_m_s};
use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, dip_to_zero, just_past, locate_zero_velocity, mode_at_rest, Direction,
    EventKind, Mode, MAX_EVENTS_PER_STEP,
};
use crate::output::{Sample, SpecimenSample};
use crate::run::{sample_at, Kin, RunStats};
use crate::stop::{AdaptiveFailure, Failure};

mod pieces;

pub(crate) use pieces::direction;
use pieces::Grading;

/// Positions in every plant's state: the platen's displacement, m,
pub(crate) const U: usize = 0;
/// its velocity, m/s,
pub(crate) const V: usize = 1;
/// the actuator's work `∫F_A·v dt`, J,
pub(crate) const W: usize = 2;
/// the platen's dissipation, J,
pub(crate) const DI: usize = 3;
/// and the storey dampers' dissipation, J. The plant's own states follow.
pub(crate) const SD: usize = 4;

/// The state of a plant, `L` numbers.
pub(crate) type Y<const L: usize> = [f64; L];

/// The stages of one RK4 step of `h6·6` seconds from position `s`, for
/// [`Plant::rk4_quadrature`]: the start state `y`, the stage states `y2`, `y3`, `y4` and the
/// inputs in the middle and at the end.
pub(crate) struct Rk4Stages<'a, const L: usize, I> {
    /// Where the step starts, in the clock's units.
    pub(crate) s: f64,
    /// The step over six, s.
    pub(crate) h6: f64,
    /// The input in the middle of the step.
    pub(crate) i_mid: I,
    /// The input at the end of the step.
    pub(crate) i_end: I,
    /// The state at the start.
    pub(crate) y: &'a Y<L>,
    /// The second stage's state.
    pub(crate) y2: &'a Y<L>,
    /// The third stage's state.
    pub(crate) y3: &'a Y<L>,
    /// The fourth stage's state.
    pub(crate) y4: &'a Y<L>,
}

/// The integrator of the pieces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum PieceMethod {
    /// One RK4 step per piece (graded near rest).
    Rk4,
    /// Adaptive Dormand–Prince 5(4) over each piece.
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance in the plant's units ([`Plant::error_scale`]).
        atol: f64,
    },
}

/// A plant: the state of what the platen drives or is driven by, its right-hand side in each
/// friction mode, the net force that decides stick and breakaway, and its clock.
///
/// Positions `at` are in the units of the plant's [`Clock`] inside the current span; `tau` is where
/// the current advance started and `rest` the length left to the end of the span.
pub(crate) trait Plant<const L: usize> {
    /// The platen model.
    type Model: PlatenModel;
    /// What the right-hand side needs from outside the state at a position (a record's
    /// actuator force; nothing in closed loop, whose force is part of the state).
    type Input: Copy;

    /// The platen model.
    fn model(&self) -> &Self::Model;
    /// The outside input at position `at`.
    fn input(&self, at: f64) -> Self::Input;
    /// The rates of the state in `mode` (creep at stiff speed `w_stiff`) into `dy`; returns
    /// the platen's acceleration.
    fn rates(&self, mode: Mode, w_stiff: f64, input: Self::Input, y: &Y<L>, dy: &mut Y<L>) -> f64;
    /// [`Plant::rates`] in slip in direction `direction::<POSITIVE>()`, compiled per direction.
    fn slip_rates<const POSITIVE: bool>(&self, input: Self::Input, y: &Y<L>, dy: &mut Y<L>) -> f64;
    /// The force the friction law sees, `F_A − B` (the actuator force less the base shear).
    fn effective_force(&self, input: Self::Input, y: &Y<L>) -> f64;
    /// The net force `N = F_A − F_E(u) − B` that decides stick and breakaway.
    fn net(&self, input: Self::Input, y: &Y<L>) -> f64;
    /// The rate `Ṅ` of the net force in stick (`u` fixed) from the rates `k`.
    fn net_rate(&self, k: &Y<L>) -> f64;
    /// Sets what the state holds that the integrator does not move (the creep velocity
    /// slaved to the force) at the end of a piece. Nothing by default.
    fn settle(&self, _mode: Mode, _w_stiff: f64, _input: Self::Input, _y: &mut Y<L>) {}
    /// Sets what entering `mode` at state `y` under `input` means to the plant beyond the
    /// machine's own reset (the direction a planar slide leaves rest in). Nothing by default.
    #[inline(always)]
    fn entering(&mut self, _mode: Mode, _input: Self::Input, _y: &mut Y<L>) {}
    /// At a located end of slip (state `y` there, under `input`), the plant's own reset when
    /// the machine's (`v = 0`, then stick, a reversal or creep as the net force at rest
    /// decides) is not what happens: the mode to go on in and the event, with `y` set for it.
    /// `None` by default: the machine's reset.
    #[inline(always)]
    fn arrive(&mut self, _input: Self::Input, _y: &mut Y<L>) -> Option<(Mode, Option<EventKind>)> {
        None
    }
    /// A state the plant cannot take (an actuator at its end stop), found at time `t_s`.
    fn check(&self, _y: &Y<L>, _t_s: f64) -> Result<()> {
        Ok(())
    }
    /// Whether the plant has branches of its own (a yielding storey's elastic and plastic
    /// branches), whose events [`Plant::branch_margin`] and [`Plant::branch_event`] locate and
    /// apply. `false` by default: the check is compiled out.
    const HAS_BRANCHES: bool = false;
    /// The smallest margin of the plant's branches at `y`: positive while every branch holds,
    /// crossing zero at the first branch event. `+∞` by default.
    #[inline(always)]
    fn branch_margin(&self, _y: &Y<L>) -> f64 {
        f64::INFINITY
    }
    /// At a located branch event (state `y`, just past it, at time `t_s`): changes the branches
    /// whose margin has fallen below zero (and the state that goes with them); returns whether
    /// anything changed.
    fn branch_event(&mut self, _y: &mut Y<L>, _t_s: f64) -> bool {
        false
    }
    /// Whether a state accepted at an event gets its rates at once (and goes through
    /// [`Plant::admit`]) or only when the next mode is entered.
    const RATES_ON_COMMIT: bool;
    /// Accepts `y` as the state at time `t_s`: returns whether it changed it (a pressure held
    /// at the cavitation floor), so that its rates are taken again.
    fn admit(&mut self, _y: &mut Y<L>, _t_s: f64) -> bool {
        false
    }
    /// Whether the integrated state `y` is finite (all of it by default; a plant may leave
    /// out quadratures that only report, such as the bare platen's energy integrals).
    #[inline(always)]
    fn is_finite(&self, y: &Y<L>) -> bool {
        y.iter().all(|x| x.is_finite())
    }
    /// Whether stick and creep have rates of their own (the state beyond the platen moves
    /// while it rests, as a specimen or the oil columns do). The bare platen's have none: it
    /// rests exactly, with its own closed forms for stick and creep (see [`crate::bare`]), and
    /// entering those modes takes no evaluation.
    const RATES_AT_REST: bool = true;
    /// Whether the counters count a fast RK4 step that is tried and not committed (the bare
    /// platen's do: its runs report those evaluations).
    const COUNTS_TRIED_STEPS: bool = false;
    /// Whether a platen leaving rest at position `tau` (state `y`, stiff speed `w_stiff`) in
    /// `dir` creeps: its creep speed under the net force is below the stiff speed. By
    /// default at `tau`; a plant whose force is linear over the span may ask at both ends.
    fn creeps_from_rest(&self, dir: Direction, tau: f64, y: &Y<L>, w_stiff: f64) -> bool {
        let f_eff = self.effective_force(self.input(tau), y);
        creep_speed_m_s(self.model(), dir, y[U], f_eff, w_stiff).is_some()
    }
    /// State `i` at the end of an RK4 step with the stages `st`, when the plant sums it its
    /// own way (the bare platen's work `F·v` grouped at the shared middle force); `None`
    /// for the classical combination of the rates.
    #[inline(always)]
    fn rk4_quadrature(&self, _i: usize, _st: &Rk4Stages<'_, L, Self::Input>) -> Option<f64> {
        None
    }
    /// The stiffest local rate of the state `y` that the fixed step does not already
    /// resolve, in 1/(the plant's unit of length): an RK4 advance is cut into equal pieces
    /// with `len·rate ≤ 1` (RK4's amplification of a decaying mode `e^(−hλ)` is then within
    /// 2 % of the exact 0.37 at `hλ = 1`; it is stable to 2.79). 0 by default: the plant's
    /// step resolves every mode it has.
    #[inline(always)]
    fn stiff_rate(&self, _y: &Y<L>) -> f64 {
        0.0
    }
    /// The error scale of state `i` going from `y0` to `y1` for the adaptive step
    /// (`atol·unit + rtol·|y|`; infinite for a quadrature that is not controlled).
    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64;

    /// Where the plant's time is kept ([`Clock`]): a force record's grid or seconds.
    type Clock: Clock;
    /// The plant's clock.
    fn clock(&self) -> &Self::Clock;
    /// The plant's clock, to move (the closed loops' driver moves it between its cuts).
    fn clock_mut(&mut self) -> &mut Self::Clock;
}

/// The machine: a plant's state in its friction mode, with the counters of the run.
pub(crate) struct Machine<P, const L: usize> {
    /// The plant.
    pub(crate) plant: P,
    /// The state.
    pub(crate) y: Y<L>,
    /// The rates at the state in the current mode.
    pub(crate) k: Y<L>,
    /// The platen's acceleration at the state (0 in stick and creep).
    pub(crate) a: f64,
    /// The friction mode.
    pub(crate) mode: Mode,
    /// The stiff speed of the current creep phase, m/s.
    pub(crate) w_stiff: f64,
    /// The grid's step, s: the stiff speed's scale and the adaptive step's ceiling.
    h: f64,
    /// The integrator of the pieces.
    method: PieceMethod,
    /// The last adaptive step, s.
    h_dopri: f64,
    /// Where and why Dopri5 gave up inside the current advance.
    gave_up: Option<(f64, AdaptiveFailure)>,
    /// The solver's counters.
    pub(crate) stats: RunStats,
    /// Whether the last advance was cut short for a stiff mode ([`Plant::stiff_rate`]): its
    /// end is not an event, and the drivers do not count it against
    /// [`MAX_EVENTS_PER_STEP`] when it moved time.
    pub(crate) stiff_cut: bool,
    /// The events with their times, when a stepping run asks for them
    /// ([`Machine::log_events`]); `None` (no allocation) otherwise.
    events: Option<Vec<(f64, EventKind)>>,
}

impl<P: Plant<L>, const L: usize> Machine<P, L> {
    /// A machine at state `y` (mode still to be entered: [`Machine::enter`]).
    pub(crate) fn new(plant: P, y: Y<L>, h: f64, method: PieceMethod) -> Self {
        Machine {
            plant,
            y,
            k: [0.0; L],
            a: 0.0,
            mode: Mode::Stick,
            w_stiff: 0.0,
            h,
            method,
            h_dopri: h,
            gave_up: None,
            stats: RunStats::default(),
            stiff_cut: false,
            events: None,
        }
    }

    /// Whether the pieces are RK4 (whose slip steps away from rest may take
    /// [`Machine::slip_fast`]).
    pub(crate) fn is_rk4(&self) -> bool {
        self.method == PieceMethod::Rk4
    }

    /// Keeps every event with its time from now on, for [`Machine::drain_events`].
    pub(crate) fn log_events(&mut self) {
        self.events.get_or_insert_with(Vec::new);
    }

    /// The events logged since the last call, oldest first, appended to `out`.
    pub(crate) fn drain_events(&mut self, out: &mut std::collections::VecDeque<(f64, EventKind)>) {
        if let Some(events) = &mut self.events {
            out.extend(events.drain(..));
        }
    }

    /// Counts the event `kind` at position `at` (and logs it with its time).
    pub(crate) fn note(&mut self, kind: EventKind, at: f64) {
        self.stats.record(kind);
        if let Some(events) = &mut self.events {
            events.push((self.plant.clock().time_s(at), kind));
        }
    }

    /// The output sample at the current state: index `j` at `t_s`, actuator force `f`, and
    /// the specimen `spec`'s storeys (displacements from position `z` of the state, velocities
    /// after them) with base shear `bs`; `spec`'s flag says that it is a general specimen
    /// (its matrices), not storeys. The platen's own terms see `F_A − B`, so the remainder
    /// `F_D` excludes the base shear.
    #[inline(always)]
    pub(crate) fn sample(
        &self,
        j: usize,
        t_s: f64,
        f: f64,
        bs: f64,
        spec: Option<(&Specimen, bool)>,
        z: usize,
    ) -> Sample {
        let y = &self.y;
        let kin = Kin {
            u: y[U],
            v: y[V],
            work: y[W],
            dissipated: y[DI],
        };
        let model = self.plant.model();
        let stuck = self.mode == Mode::Stick;
        let mut sample = sample_at(model, j, t_s, f - bs, kin, self.a, stuck);
        sample.terms.actuator_n = f;
        if let Some((specimen, general)) = spec {
            let storeys = specimen.len();
            let mut spec = SpecimenSample::new(storeys, bs);
            if !general {
                // `Specimen::absolute_acceleration_m_s2` and `drift_m` of storeys, written
                // out: this runs at every output sample.
                let mut below = 0.0;
                for i in 0..storeys {
                    spec.u_m[i] = y[z + i];
                    spec.a_m_s2[i] = self.a + self.k[z + storeys + i];
                    spec.drift_m[i] = y[z + i] - below;
                    below = y[z + i];
                }
            } else {
                let zs = &y[z..z + storeys];
                for i in 0..storeys {
                    spec.u_m[i] = y[z + i];
                    spec.a_m_s2[i] =
                        specimen.absolute_acceleration_m_s2(i, self.a, self.k[z + storeys + i]);
                    spec.drift_m[i] = specimen.drift_m(i, zs);
                }
            }
            sample.specimen = Some(spec);
        }
        sample
    }

    /// Where and why the adaptive integrator gave up, once.
    pub(crate) fn take_failure(&mut self) -> Option<(f64, AdaptiveFailure)> {
        self.gave_up.take()
    }

    /// The signed creep velocity at `y` under `input`.
    fn creep_velocity(&self, dir: Direction, input: P::Input, y: &Y<L>) -> f64 {
        let f_eff = self.plant.effective_force(input, y);
        let w = creep_speed_m_s(self.plant.model(), dir, y[U], f_eff, self.w_stiff)
            .unwrap_or(self.w_stiff);
        dir.sign() * w
    }

    /// Switches to `mode` at the current state under `input`: its rates (and the stiff speed
    /// and velocity of a creep phase).
    pub(crate) fn enter(&mut self, mode: Mode, input: P::Input) {
        self.mode = mode;
        self.plant.entering(mode, input, &mut self.y);
        if !P::RATES_AT_REST && !matches!(mode, Mode::Slip(_)) {
            // At rest with no rates of its own: nothing moves but what the plant's closed
            // forms move.
            if let Mode::Creep(_) = mode {
                self.w_stiff = stiff_speed_m_s(self.plant.model(), self.y[U], self.h);
            }
            (self.k, self.a) = ([0.0; L], 0.0);
            return;
        }
        if let Mode::Creep(dir) = mode {
            self.w_stiff = stiff_speed_m_s(self.plant.model(), self.y[U], self.h);
            let y = self.y;
            self.y[V] = self.creep_velocity(dir, input, &y);
        }
        let (y, mut k) = (self.y, [0.0; L]);
        self.a = self.plant.rates(mode, self.w_stiff, input, &y, &mut k);
        self.k = k;
        self.stats.rhs_evaluations += 1;
    }

    /// Accepts `y` at time `t_s` as the plant does ([`Plant::RATES_ON_COMMIT`]).
    fn commit(&mut self, y: Y<L>, input: P::Input, t_s: f64) {
        if P::RATES_ON_COMMIT {
            let mut k = [0.0; L];
            let a = self.plant.rates(self.mode, self.w_stiff, input, &y, &mut k);
            self.stats.rhs_evaluations += 1;
            self.commit_with(y, k, a, input, t_s);
        } else {
            self.y = y;
        }
    }

    /// Accepts `y` with its rates `k` and acceleration `a` at time `t_s` (taken again if the
    /// plant changes the state).
    fn commit_with(&mut self, mut y: Y<L>, mut k: Y<L>, mut a: f64, input: P::Input, t_s: f64) {
        if self.plant.admit(&mut y, t_s) {
            a = self.plant.rates(self.mode, self.w_stiff, input, &y, &mut k);
            self.stats.rhs_evaluations += 1;
        }
        (self.y, self.k, self.a) = (y, k, a);
    }

    // ---- events --------------------------------------------------------------------------

    /// The current mode's event function at `y` under `input`: positive until the mode ends.
    #[inline(always)]
    fn event_g(&self, input: P::Input, y: &Y<L>) -> f64 {
        let model = self.plant.model();
        match self.mode {
            Mode::Slip(dir) => dir.sign() * y[V],
            Mode::Stick => model.static_threshold_n(y[U]) - self.plant.net(input, y).abs(),
            Mode::Creep(dir) => {
                let sn = dir.sign() * self.plant.net(input, y);
                (sn - model.static_threshold_n(y[U])).min(self.exit_level(dir, y[U]) - sn)
            }
        }
    }

    /// The drive `s·N` at which creep hands over to slip (the creep speed reaches `w_*`).
    fn exit_level(&self, dir: Direction, u: f64) -> f64 {
        let (s, m) = (dir.sign(), self.plant.model());
        m.static_threshold_n(u)
            + m.dissipative_excess_n(u, self.w_stiff)
            + s * m.velocity_inertial_force_n(u, s * self.w_stiff)
    }

    /// Whether the event function may dip to zero inside a piece of length `len` from the
    /// current state (input `i0`) to `y1` (input `i1`, rates `k1`, platen acceleration `a1`):
    /// the cubic Hermite interpolant of the speed (slip) or of `F_s ∓ N` (stick) touches zero.
    #[allow(clippy::too_many_arguments)]
    fn dips(&self, len: f64, i0: P::Input, y1: &Y<L>, i1: P::Input, k1: &Y<L>, a1: f64) -> bool {
        let span = self.plant.clock().seconds(len);
        match self.mode {
            Mode::Slip(dir) => {
                let d = dir.sign();
                dip_to_zero(d * self.y[V], d * y1[V], d * self.a * span, d * a1 * span).is_some()
            }
            Mode::Stick => {
                let fs = self.plant.model().static_threshold_n(self.y[U]);
                let (n0, n1) = (self.plant.net(i0, &self.y), self.plant.net(i1, y1));
                let (d0, d1) = (
                    self.plant.net_rate(&self.k) * span,
                    self.plant.net_rate(k1) * span,
                );
                dip_to_zero(fs - n0, fs - n1, -d0, -d1).is_some()
                    || dip_to_zero(fs + n0, fs + n1, d0, d1).is_some()
            }
            Mode::Creep(_) => false,
        }
    }

    /// The error of a state found non-finite at position `at`.
    fn non_finite(&self, at: f64) -> IntegrateError {
        let cause = Failure::NonFiniteState {
            u_m: self.y[U],
            v_m_s: self.y[V],
        };
        IntegrateError::failed(self.plant.clock().time_s(at), cause)
    }

    /// Advances over a whole span of length 1 (a grid step) through every mode and event:
    /// [`Machine::advance`] until the span ends. Stops the run where Dopri5 gave up
    /// ([`IntegrateError::AdaptiveFailed`]) or where more than [`MAX_EVENTS_PER_STEP`] events
    /// happen in one span ([`IntegrateError::EventLoopStalled`], a guard against a defect).
    pub(crate) fn advance_span(&mut self) -> Result<()> {
        let mut tau = 0.0;
        let mut events = 0u32;
        loop {
            let before = tau;
            tau = self.advance(tau, 1.0 - tau)?;
            if let Some((t_s, reason)) = self.take_failure() {
                return Err(IntegrateError::failed(t_s, Failure::AdaptiveFailed(reason)));
            }
            if tau >= 1.0 {
                return Ok(());
            }
            if !(self.stiff_cut && tau > before) {
                events += 1;
            }
            if events > MAX_EVENTS_PER_STEP {
                let stalled = Failure::EventLoopStalled { events };
                return Err(IntegrateError::failed(
                    self.plant.clock().time_s(tau),
                    stalled,
                ));
            }
        }
    }

    /// Advances over `span` seconds through every mode and event, for a plant whose positions
    /// count from its own clock in seconds (the closed loops, whose controller cuts time into
    /// segments): each piece moves the clock by its length. The same guards as
    /// [`Machine::advance_span`]: where Dopri5 gave up, and more than
    /// [`MAX_EVENTS_PER_STEP`] events (stiff pieces not counted).
    pub(crate) fn advance_clocked(&mut self, span: f64) -> Result<()>
    where
        P: Plant<L, Clock = SecondsClock>,
    {
        let mut tau = 0.0;
        let mut events = 0u32;
        while tau < span {
            let at = self.advance(0.0, span - tau)?;
            if let Some((t_s, reason)) = self.take_failure() {
                return Err(IntegrateError::failed(t_s, Failure::AdaptiveFailed(reason)));
            }
            tau += at;
            self.plant.clock_mut().t += at;
            if !(self.stiff_cut && at > 0.0) {
                events += 1;
            }
            if events > MAX_EVENTS_PER_STEP {
                let stalled = Failure::EventLoopStalled { events };
                return Err(IntegrateError::failed(self.plant.clock().t, stalled));
            }
        }
        Ok(())
    }

    /// Advances in the current mode from position `tau` over at most `rest`, to the end or to
    /// the mode's next event (its reset applied). Returns where the advance stopped, in the
    /// units of the plant's driver ([`Clock::reach`], [`Clock::land`]).
    pub(crate) fn advance(&mut self, tau: f64, rest: f64) -> Result<f64> {
        let i0 = self.plant.input(tau);
        let slip = matches!(self.mode, Mode::Slip(_));
        let from_rest = slip && self.y[V] == 0.0;
        if let (Mode::Slip(dir), true) = (self.mode, from_rest) {
            // Leaving rest below the stiff speed: creep.
            let w_stiff = stiff_speed_m_s(self.plant.model(), self.y[U], self.h);
            if self.plant.creeps_from_rest(dir, tau, &self.y, w_stiff) {
                self.enter(Mode::Creep(dir), i0);
                return Ok(self.plant.clock().reach(tau, 0.0));
            }
        }
        let (try_grading, event_grading) = match (slip, from_rest) {
            (true, true) => (Grading::Start, Grading::Both),
            (true, false) => (Grading::Single, Grading::End),
            _ => (Grading::Single, Grading::Single),
        };
        let mut len = self.first_length(rest);
        for _ in 0..=MAX_HALVINGS {
            let (y1, stage_min) = self.piece(tau, len, try_grading);
            if let Some(at) = self.stiff_slip(tau, rest, &y1) {
                return Ok(at);
            }
            if !self.plant.is_finite(&y1) {
                return Err(self.non_finite(tau));
            }
            self.plant
                .check(&y1, self.plant.clock().time_s(tau + len))?;
            let i1 = self.plant.input(tau + len);
            let g1 = self.event_g(i1, &y1);
            if g1 > 0.0 && stage_min > 0.0 {
                let mut k1 = [0.0; L];
                let a1 = self.plant.rates(self.mode, self.w_stiff, i1, &y1, &mut k1);
                self.stats.rhs_evaluations += 1;
                if !self.dips(len, i0, &y1, i1, &k1, a1) {
                    if !a1.is_finite() {
                        return Err(self.non_finite(tau + len));
                    }
                    if P::HAS_BRANCHES {
                        if let Some(at) = self.branch_event_in(tau, len, &y1, try_grading) {
                            return Ok(at);
                        }
                    }
                    if self.mode == Mode::Stick {
                        self.stats.stick_time_s += self.plant.clock().seconds(len);
                    }
                    let t_s = self.plant.clock().time_s(tau + len);
                    self.commit_with(y1, k1, a1, i1, t_s);
                    return Ok(self.plant.clock().reach(tau, len));
                }
            } else if g1 <= 0.0 {
                let (y2, g2) = if event_grading == try_grading {
                    (y1, g1)
                } else {
                    let (y2, _) = self.piece(tau, len, event_grading);
                    (y2, self.event_g(i1, &y2))
                };
                if g2 <= 0.0 {
                    let x = self.locate(tau, len, i0, (y2, g2), event_grading);
                    let (x, y_event) = x.unwrap_or((0.0, self.y));
                    if P::HAS_BRANCHES && x > 0.0 {
                        // A branch event before the mode's: that one first.
                        if let Some(at) = self.branch_event_in(tau, x, &y_event, event_grading) {
                            return Ok(at);
                        }
                    }
                    return Ok(self.event(tau, x, rest, y_event));
                }
            }
            len *= 0.5;
        }
        // A piece of 2⁻⁶⁰ of the span still not safe: the event is here.
        let y = self.y;
        Ok(self.event(tau, 0.0, rest, y))
    }

    /// A branch event of the plant (a storey's yield or unloading) inside the piece of length
    /// `len` from `tau` that ends at `y1`, if the plant's margin there has fallen below zero:
    /// located by Illinois root finding on the map of `grading`'s pieces (as the mode's events
    /// are), the state taken just past it, the branch changed there and the rates taken again.
    /// Returns where time landed, in the driver's units; `None` without an event, or for a
    /// graze at the piece's start that changes no branch (the piece then stands).
    fn branch_event_in(&mut self, tau: f64, len: f64, y1: &Y<L>, grading: Grading) -> Option<f64> {
        let g1 = self.plant.branch_margin(y1);
        if g1 >= 0.0 || g1.is_nan() {
            return None;
        }
        let g0 = self.plant.branch_margin(&self.y);
        let (x, mut y) = if g0 <= 0.0 {
            (0.0, self.y)
        } else {
            let tolerance = 4.0 * f64::EPSILON * len.max(self.plant.clock().tolerance_floor());
            let found = locate_zero_velocity(len, g0, (*y1, g1), tolerance, |x| {
                self.stats.root_iterations += 1;
                let (y, _) = self.piece(tau, x, grading);
                Ok::<_, Infallible>((y, self.plant.branch_margin(&y)))
            });
            // With the margin positive at the start, the root finder always brackets it.
            let Ok(Some(found)) = found else {
                return None;
            };
            found
        };
        let t_s = self.plant.clock().time_s(tau + x);
        if !self.plant.branch_event(&mut y, t_s) && x == 0.0 {
            return None;
        }
        if self.mode == Mode::Stick {
            self.stats.stick_time_s += self.plant.clock().seconds(x);
        }
        let input = self.plant.input(tau + x);
        self.plant.settle(self.mode, self.w_stiff, input, &mut y);
        let mut k = [0.0; L];
        let a = self.plant.rates(self.mode, self.w_stiff, input, &y, &mut k);
        self.stats.rhs_evaluations += 1;
        self.commit_with(y, k, a, input, t_s);
        Some(self.plant.clock().reach(tau, x))
    }

    /// The first piece's length over the rest `rest` of a span: all of it, or for RK4 an
    /// equal share of it where a mode the fixed step does not resolve (an orifice near its
    /// laminar drop at full opening) asks for pieces each within RK4's accuracy of it
    /// ([`Machine::stiff_cut`] then set).
    fn first_length(&mut self, rest: f64) -> f64 {
        let mut len = rest;
        self.stiff_cut = false;
        if self.is_rk4() {
            let pieces = (rest * self.plant.stiff_rate(&self.y))
                .ceil()
                .min(MAX_STIFF_PIECES);
            if pieces > 1.0 {
                len = rest / pieces;
                self.stiff_cut = true;
            }
        }
        len
    }

    /// The current mode's event inside a piece of length `len` from `tau` (input `i0` there),
    /// found at its end (`y2`, event function `g2 ≤ 0`): located by Illinois root finding on
    /// the map of `grading`'s pieces, with its position and state there.
    fn locate(
        &mut self,
        tau: f64,
        len: f64,
        i0: P::Input,
        (y2, g2): (Y<L>, f64),
        grading: Grading,
    ) -> Option<(f64, Y<L>)> {
        let g0 = self.event_g(i0, &self.y);
        let tolerance = 4.0 * f64::EPSILON * len.max(self.plant.clock().tolerance_floor());
        let Ok(found) = locate_zero_velocity(len, g0, (y2, g2), tolerance, |x| {
            self.stats.root_iterations += 1;
            let (y, _) = self.piece(tau, x, grading);
            let g = self.event_g(self.plant.input(tau + x), &y);
            Ok::<_, Infallible>((y, g))
        });
        found
    }

    /// Where Dopri5 gave up slipping below the stiff speed (a platen started, or
    /// decelerating, at a few nm/s): there the velocity relaxes within `τ = M/D′ ≪ h` (to rest,
    /// or to a creep speed below the stiff speed), which the adaptive step had to resolve to
    /// its tolerance with steps shrinking as the speed fell, until its step budget ran out.
    /// The point reached is taken as the slip's arrival at rest (the event of a located
    /// `v = 0`: a stop, a reversal, or creep on where the net force still drives the platen),
    /// and the failure is withdrawn; the inertia neglected moves the platen by about `τ·|v|`,
    /// below the creep phase's own bound `h·w_*`. Returns where time landed, in the driver's
    /// units; `None` (the failure stands) anywhere else. It fires only where the run failed
    /// before, so no run that succeeded changes.
    fn stiff_slip(&mut self, tau: f64, rest: f64, y: &Y<L>) -> Option<f64> {
        let (Some((t_s, _)), Mode::Slip(_)) = (self.gave_up, self.mode) else {
            return None;
        };
        if !below_stiff_speed(self.plant.model(), y[U], y[V].abs(), self.h) {
            return None;
        }
        self.gave_up = None;
        let x = self
            .plant
            .clock()
            .units(t_s - self.plant.clock().time_s(tau));
        let mut y_event = *y;
        y_event[V] = 0.0;
        Some(self.event(tau, x, rest, y_event))
    }

    /// The reset at the current mode's event, located `x` past `tau` (`rest` to the span's
    /// end) with state `y_event` there. Returns where time landed, in the driver's units.
    fn event(&mut self, tau: f64, x: f64, rest: f64, y_event: Y<L>) -> f64 {
        let mut at = self.plant.clock().land(tau, x, rest);
        match self.mode {
            Mode::Slip(from) => {
                let mut y = y_event;
                let input = self.plant.input(at);
                if let Some((mode, kind)) = self.plant.arrive(input, &mut y) {
                    self.commit(y, input, self.plant.clock().time_s(at));
                    self.enter(mode, input);
                    if let Some(kind) = kind {
                        self.note(kind, at);
                    }
                    return at;
                }
                y[V] = 0.0;
                self.commit(y, input, self.plant.clock().time_s(at));
                let f_eff = self.plant.effective_force(input, &self.y);
                let (mode, kind) = arrive_at_rest(self.plant.model(), self.y[U], f_eff, from);
                self.enter(mode, input);
                if let Some(kind) = kind {
                    self.note(kind, at);
                }
                at
            }
            Mode::Stick => self.breakaway(tau, x, rest, y_event),
            Mode::Creep(dir) => {
                let start = (self.y, self.k);
                let mut input = self.plant.input(at);
                self.commit(y_event, input, self.plant.clock().time_s(at));
                let sn = dir.sign() * self.plant.net(input, &self.y);
                let fs = self.plant.model().static_threshold_n(self.y[U]);
                if sn - fs <= self.exit_level(dir, self.y[U]) - sn {
                    // The drive fell to the threshold: a stop (or, past rounding, creep on or
                    // a reversal, as the net force at rest decides).
                    self.y[V] = 0.0;
                    let f_eff = self.plant.effective_force(input, &self.y);
                    let mut mode = mode_at_rest(self.plant.model(), self.y[U], f_eff);
                    if mode == Mode::Slip(dir) && x <= self.plant.clock().min_progress() {
                        // The stop rounded onto the start of the advance, where the net force
                        // at rest is a hair along the motion: creeping on from here would
                        // locate the same stop again without moving time. Step just past it,
                        // to where the net force at rest no longer drives the creep on (see
                        // `crate::creep`, whose passes do the same).
                        at = self.creep_just_past(tau, x, rest, start, dir);
                        input = self.plant.input(at);
                        let f_eff = self.plant.effective_force(input, &self.y);
                        mode = mode_at_rest(self.plant.model(), self.y[U], f_eff);
                    }
                    match mode {
                        Mode::Slip(d) if d == dir => self.enter(Mode::Creep(dir), input),
                        Mode::Stick => {
                            self.note(EventKind::Stop, at);
                            self.enter(Mode::Stick, input);
                        }
                        other => {
                            self.note(EventKind::Reversal, at);
                            self.enter(other, input);
                        }
                    }
                } else {
                    // The creep speed reached the stiff speed: slip on from that velocity.
                    let y = self.y;
                    let v = self.creep_velocity(dir, input, &y);
                    self.y[V] = if v == 0.0 {
                        dir.sign() * f64::MIN_POSITIVE
                    } else {
                        v
                    };
                    self.enter(Mode::Slip(dir), input);
                }
                at
            }
        }
    }

    /// The breakaway located `x` past `tau`: moved [`just_past`] rounding so that
    /// `|N| > F_s` holds where slip starts (or, if rounding kept friction holding to the end
    /// of the span, still stuck there).
    fn breakaway(&mut self, tau: f64, x: f64, rest: f64, y_event: Y<L>) -> f64 {
        let fs = self.plant.model().static_threshold_n(self.y[U]);
        let x_b = just_past(x, rest, |x| {
            let (y, _) = self.piece(tau, x, Grading::Single);
            self.plant.net(self.plant.input(tau + x), &y).abs() > fs
        });
        let y = if x_b == x {
            y_event
        } else {
            self.piece(tau, x_b, Grading::Single).0
        };
        self.stats.stick_time_s += self.plant.clock().seconds(x_b);
        let input = self
            .plant
            .input(self.plant.clock().break_at(tau, x_b, rest, false));
        self.commit(y, input, self.plant.clock().time_s(tau + x_b));
        let net = self.plant.net(input, &self.y);
        if net.abs() <= fs {
            // Rounding kept friction holding to the end of the span: still stuck.
            self.enter(Mode::Stick, input);
            return self.plant.clock().break_at(tau, x_b, rest, true);
        }
        let at = self.plant.clock().break_at(tau, x_b, rest, false);
        self.note(EventKind::Breakaway, at);
        self.enter(Mode::Slip(Direction::of_sign(net)), input);
        at
    }

    /// A creep stop located `x ≤` [`Clock::min_progress`] past `tau` (from the state and
    /// rates `start`) where the net force at rest still drives the creep on in `dir`: creeps
    /// from `start` to the first of `x + 4ε, x + 8ε, …` ([`just_past`]) where it does not, or
    /// to the span's end, and accepts that state at rest (`v = 0`). Returns where, in the
    /// driver's units.
    fn creep_just_past(
        &mut self,
        tau: f64,
        x: f64,
        rest: f64,
        start: (Y<L>, Y<L>),
        dir: Direction,
    ) -> f64 {
        let stopped = (self.y, self.k, self.a);
        (self.y, self.k) = start;
        let x_b = just_past(x, rest, |x| {
            let (y, _) = self.piece(tau, x, Grading::Single);
            let f_eff = self.plant.effective_force(self.plant.input(tau + x), &y);
            mode_at_rest(self.plant.model(), y[U], f_eff) != Mode::Slip(dir)
        });
        if x_b > x {
            let (y, _) = self.piece(tau, x_b, Grading::Single);
            let at = tau + x_b;
            self.commit(y, self.plant.input(at), self.plant.clock().time_s(at));
        } else {
            (self.y, self.k, self.a) = stopped;
        }
        self.y[V] = 0.0;
        self.plant.clock().land(tau, x_b, rest)
    }
}

/// The most pieces one RK4 advance is cut into for a stiff mode ([`Plant::stiff_rate`]): a
/// rate that diverges (a chamber emptying at the end stop, `β/V` with `V → 0`) must not stall
/// time. 2¹⁶ pieces of a 1024 Hz controller's period resolve rates up to 6.7e7 1/s.
pub(crate) const MAX_STIFF_PIECES: f64 = 65_536.0;

/// Halvings of a careful piece before its start is taken as a state at rest (2⁻⁶⁰ of a step:
/// the speed there is below what a piece that short can resolve).
pub(crate) const MAX_HALVINGS: u32 = 60;
