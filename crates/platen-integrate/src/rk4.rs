//! Fixed-step classical Runge–Kutta (RK4) with exact stick-slip events.
//!
//! # Method
//!
//! Time runs on an integer counter: `t = t₀ + (n + τ)·h` with `h = Δt/k` (`Δt` the force
//! record's sample interval, `k ≥ 1` steps per sample) and `τ ∈ [0, 1]` the fraction of the
//! current step already done. The force is linear between samples, so it is linear inside
//! every step and is evaluated from the two samples that bracket it, never from a float time.
//!
//! The platen is in one of the modes of [`crate::event`] (the events between them, and how
//! they are located and decided, are shared with Dopri5):
//!
//! * **slip±**: the smooth right-hand side with the friction direction fixed is stepped with
//!   RK4. A step is accepted as it is when the speed stays positive at every stage, at its end
//!   and on its cubic Hermite interpolant; otherwise the rest of the step is halved until a
//!   piece is safe (committed) or ends across `v = 0`, where the crossing is located by
//!   root-finding (Illinois) on the *length* of an RK4 step graded towards the singular end,
//!   so the state at the event is an RK4 step that ends at `v = 0`. There `v` is set to
//!   exactly zero and the net force `N = F_A − F_E(u)` decides: stick if `|N| ≤ F_s(u)`,
//!   reversal if it is beyond the threshold against the motion, creep if along it.
//! * **stick**: `u` is fixed and `v = a = 0`. Because `F_A` is linear within a step, the
//!   breakaway time, at which `|N|` reaches `F_s(u)`, is solved exactly; the rest of the
//!   step is then stepped in slip (or creep, if the creep speed stays below the stiff speed).
//! * **creep±**: the quasi-static creep of [`crate::creep`], with the stiff speed of the grid
//!   step `h`.
//!
//! No allocation happens per step; a run allocates only what its [`SampleSink`] stores.

use std::convert::Infallible;

use platen_model::{PlatenModel, SlipRates};

use crate::creep::{creep, creep_speed_m_s, stiff_speed_m_s, CreepEnd};
use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, breakaway, dip_to_zero, just_past, locate_zero_velocity, Direction, EventKind,
    Mode, StepStop, MAX_EVENTS_PER_STEP,
};
use crate::output::{Sample, SampleSink};
use crate::record::ForceRecord;
use crate::run::{check_run, sample_at, EnergyBalance, Kin, RunStats, State};
use crate::stop::{Failure, StopReason};

/// Fixed-step RK4 settings: `k` steps per sample interval of the force record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rk4 {
    steps_per_sample: u32,
}

impl Rk4 {
    /// `k` steps per sample interval (`k ≥ 1`).
    ///
    /// # Errors
    /// [`IntegrateError::InvalidStep`] if `k == 0`.
    pub fn with_steps_per_sample(k: u32) -> Result<Self> {
        if k == 0 {
            return Err(IntegrateError::InvalidStep {
                step_s: f64::INFINITY,
            });
        }
        Ok(Self {
            steps_per_sample: k,
        })
    }

    /// The settings whose step is `step_s` for a record sampled every `sample_interval_s`.
    /// The step must divide the interval into a whole number of steps (to 1e-9 relative).
    ///
    /// # Errors
    /// [`IntegrateError::InvalidStep`] for a non-finite or non-positive step,
    /// [`IntegrateError::StepNotDivisor`] if the interval is not a whole number of steps.
    pub fn from_step(step_s: f64, sample_interval_s: f64) -> Result<Self> {
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(IntegrateError::InvalidStep { step_s });
        }
        let k = (sample_interval_s / step_s).round();
        if !(1.0..=1e9).contains(&k)
            || (k * step_s - sample_interval_s).abs() > 1e-9 * sample_interval_s
        {
            return Err(IntegrateError::StepNotDivisor {
                step_s,
                sample_interval_s,
            });
        }
        Ok(Self {
            steps_per_sample: k as u32,
        })
    }

    /// Steps per sample interval.
    pub fn steps_per_sample(self) -> u32 {
        self.steps_per_sample
    }
}

/// Grid step `n` (from `t₀`), which is sub-step `i` of the sample interval that starts at
/// sample `j` (`n = j·k + i`). Carried together so that the hot loop never divides.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GridStep {
    pub(crate) n: u64,
    pub(crate) j: usize,
    /// `i` as a number (exact: `i < k ≤ 1e9`).
    pub(crate) i: f64,
}

/// The force record seen from the integer time grid.
pub(crate) struct Grid<'a> {
    pub(crate) force: &'a [f64],
    pub(crate) inv_k: f64,
    pub(crate) h: f64,
    pub(crate) t0: f64,
}

impl<'a> Grid<'a> {
    /// The grid of `k` steps per sample interval of `record`.
    pub(crate) fn new(record: &'a ForceRecord, k: u64) -> Self {
        Grid {
            force: record.force_n(),
            inv_k: 1.0 / k as f64,
            h: record.dt_s() / k as f64,
            t0: record.t_s()[0],
        }
    }

    /// Force at fraction `tau ∈ [0, 1]` of grid step `n`: linear between the two samples
    /// that bracket the step, exact at both samples.
    #[inline(always)]
    pub(crate) fn force(&self, n: GridStep, tau: f64) -> f64 {
        let j = n.j;
        let w = (n.i + tau) * self.inv_k;
        if w == 0.0 {
            self.force[j]
        } else {
            self.force[j] * (1.0 - w) + self.force[j + 1] * w
        }
    }

    #[inline]
    pub(crate) fn time_s(&self, n: GridStep, tau: f64) -> f64 {
        self.t0 + (n.n as f64 + tau) * self.h
    }
}

/// The friction direction of slip as a number: `+1.0` for `POSITIVE`, `−1.0` otherwise.
///
/// The slip path is monomorphised over the direction so that, once the model's
/// `slip_rates` is inlined, `direction·v` and `direction·D` fold to `v`/`−v` and `D`/`−D`
/// (exact for ±1, so the results are bit for bit those of a run-time direction) and two
/// multiplications leave the dependency chain of every stage.
#[inline(always)]
pub(crate) const fn direction<const POSITIVE: bool>() -> f64 {
    if POSITIVE {
        1.0
    } else {
        -1.0
    }
}

/// One classical RK4 step of length `h` in slip with direction `direction::<POSITIVE>()`
/// from `y`, given the rates at the start `r0` (so the caller can reuse them) and the forces
/// at the start, middle and end of the step. Also returns the smallest speed `direction·v`
/// of the three later stages (a stage at or below zero means the step may cross `v = 0`).
#[inline(always)]
fn rk4_slip<M: PlatenModel, const POSITIVE: bool>(
    m: &M,
    y: Kin,
    r0: SlipRates,
    h: f64,
    f_start: f64,
    f_mid: f64,
    f_end: f64,
) -> (Kin, f64) {
    let dir = direction::<POSITIVE>();
    let (u, v) = (y.u, y.v);
    let hh = 0.5 * h;
    let v2 = v + hh * r0.a_m_s2;
    let r2 = m.slip_rates(f_mid, u + hh * v, v2, dir);
    let v3 = v + hh * r2.a_m_s2;
    let r3 = m.slip_rates(f_mid, u + hh * v2, v3, dir);
    let v4 = v + h * r3.a_m_s2;
    let r4 = m.slip_rates(f_end, u + h * v3, v4, dir);
    let h6 = h / 6.0;
    let stage_min = (dir * v2).min(dir * v3).min(dir * v4);
    let y1 = Kin {
        u: u + h6 * (v + 2.0 * (v2 + v3) + v4),
        v: v + h6 * (r0.a_m_s2 + 2.0 * (r2.a_m_s2 + r3.a_m_s2) + r4.a_m_s2),
        work: y.work + h6 * (f_start * v + 2.0 * f_mid * (v2 + v3) + f_end * v4),
        dissipated: y.dissipated
            + h6 * (r0.dissipated_power_w
                + 2.0 * (r2.dissipated_power_w + r3.dissipated_power_w)
                + r4.dissipated_power_w),
    };
    (y1, stage_min)
}

/// Runs the model forward under the recorded force `record` from `initial`, with fixed-step
/// RK4 and exact stick-slip, delivering `samples` output samples (the record's first
/// `samples` sample times) to `sink`.
///
/// # Errors
/// [`IntegrateError::RecordTooShort`] if `samples` exceeds the record,
/// [`IntegrateError::InvalidInitialState`] for a non-finite initial state,
/// [`IntegrateError::NonFiniteState`] or [`IntegrateError::EventLoopStalled`] on numerical
/// failure (with the time at which it happened). Samples before a failure have already been
/// delivered to `sink`.
pub fn forward_rk4<M: PlatenModel, S: SampleSink>(
    model: &M,
    record: &ForceRecord,
    rk4: Rk4,
    initial: State,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    check_run(record, initial, samples)?;
    let k = u64::from(rk4.steps_per_sample);
    let mut stepper = Stepper::new(model, Grid::new(record, k), initial);
    drive(&mut stepper, record.t_s(), k, samples, sink)
}

/// A fixed-step integrator on the integer time grid: what [`drive`] runs.
pub(crate) trait GridStepper {
    /// Advances from grid point `n` to `n + 1`, handling every event inside the step.
    fn step(&mut self, n: GridStep) -> Result<()>;
    /// The output sample at sample `j` of the record (grid point `j·k`), at time `t_s`.
    fn sample(&self, j: usize, t_s: f64) -> Sample;
    /// Closes the run's statistics, the run having finished at `t_s`.
    fn finish(&mut self, t_s: f64) -> RunStats;
}

/// Runs `stepper` over the first `samples` sample `times` (`k` steps per interval), delivering
/// every sample to `sink`.
#[inline(always)]
pub(crate) fn drive<T: GridStepper, S: SampleSink>(
    stepper: &mut T,
    times: &[f64],
    k: u64,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    if samples == 0 {
        return Ok(stepper.finish(times[0]));
    }
    sink.accept(&stepper.sample(0, times[0]));
    let mut n = 0u64;
    for j in 0..samples - 1 {
        for i in 0..k {
            stepper.step(GridStep { n, j, i: i as f64 })?;
            n += 1;
        }
        sink.accept(&stepper.sample(j + 1, times[j + 1]));
    }
    Ok(stepper.finish(times[samples - 1]))
}

impl<M: PlatenModel> GridStepper for Stepper<'_, M> {
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

/// How a slip interval is split into RK4 sub-steps.
///
/// Near `v = 0` the `|v|^α` law (α < 1) makes the right-hand side singular like `√(t − t*)`,
/// which cuts a single RK4 step's accuracy to `O(h^1.5)` (about 1e-7 m/s per event at
/// h = 1/1024 s on the paper's model). Geometric sub-steps that halve towards the singular
/// end make the step that holds it `2⁵` times shorter, which removes that error to the
/// 1e-10 m level, at the cost of a few extra stages per event only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Grading {
    /// One plain RK4 step.
    Single,
    /// Singular at the start (leaving rest).
    Start,
    /// Singular at the end (arriving at rest).
    End,
    /// Singular at both ends.
    Both,
}

const GRADED_START: [f64; 6] = [
    1.0 / 32.0,
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    1.0 / 4.0,
    1.0 / 2.0,
];
const GRADED_END: [f64; 6] = [
    1.0 / 2.0,
    1.0 / 4.0,
    1.0 / 8.0,
    1.0 / 16.0,
    1.0 / 32.0,
    1.0 / 32.0,
];
const GRADED_BOTH: [f64; 12] = [
    1.0 / 64.0,
    1.0 / 64.0,
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    1.0 / 4.0,
    1.0 / 4.0,
    1.0 / 8.0,
    1.0 / 16.0,
    1.0 / 32.0,
    1.0 / 64.0,
    1.0 / 64.0,
];

impl Grading {
    pub(crate) fn pieces(self) -> &'static [f64] {
        match self {
            Grading::Single => &[1.0],
            Grading::Start => &GRADED_START,
            Grading::End => &GRADED_END,
            Grading::Both => &GRADED_BOTH,
        }
    }
}

/// Halvings of a careful piece before its start is taken as a state at rest (2⁻⁶⁰ of a step:
/// the speed there is below what a piece that short can resolve).
pub(crate) const MAX_HALVINGS: u32 = 60;

/// The mutable state of a forward RK4 run (also one lane of [`crate::ensemble`]).
pub(crate) struct Stepper<'a, M> {
    model: &'a M,
    pub(crate) grid: Grid<'a>,
    pub(crate) y: Kin,
    pub(crate) mode: Mode,
    /// Rates at the current state in the current mode (zero in stick and creep).
    pub(crate) rates: SlipRates,
    /// The stiff speed of the current creep phase (see [`crate::creep`]), m/s.
    w_stiff: f64,
    pub(crate) stats: RunStats,
}

const AT_REST: SlipRates = SlipRates {
    a_m_s2: 0.0,
    dissipated_power_w: 0.0,
};

impl<'a, M: PlatenModel> Stepper<'a, M> {
    pub(crate) fn new(model: &'a M, grid: Grid<'a>, initial: State) -> Self {
        let mut s = Self {
            model,
            grid,
            y: Kin::start(initial),
            mode: Mode::Stick,
            rates: AT_REST,
            w_stiff: 0.0,
            stats: RunStats::default(),
        };
        let f0 = s.grid.force[0];
        s.enter(Mode::initial(model, s.y.u, s.y.v, f0), f0);
        s.stats.energy = EnergyBalance::start(model, s.y.u, s.y.v);
        s
    }

    /// Switches to `mode` at the current state under force `f`: the rates of slip, or the
    /// stiff speed of a creep phase.
    fn enter(&mut self, mode: Mode, f: f64) {
        self.mode = mode;
        if let Mode::Creep(_) = mode {
            self.w_stiff = stiff_speed_m_s(self.model, self.y.u, self.grid.h);
        }
        self.refresh_rates(f);
    }

    #[inline(always)]
    fn refresh_rates(&mut self, f: f64) {
        self.rates = match self.mode {
            Mode::Stick | Mode::Creep(_) => AT_REST,
            Mode::Slip(dir) => {
                self.stats.rhs_evaluations += 1;
                self.model.slip_rates(f, self.y.u, self.y.v, dir.sign())
            }
        };
    }

    /// The output sample at sample `j` of the record (grid point `j·k`, τ = 0).
    pub(crate) fn sample(&self, j: usize, t_s: f64) -> Sample {
        sample_at(
            self.model,
            j,
            t_s,
            self.grid.force[j],
            self.y,
            self.rates.a_m_s2,
            self.mode == Mode::Stick,
        )
    }

    /// Advances from grid point `n` to `n + 1`, handling every event inside the step.
    #[inline]
    pub(crate) fn step(&mut self, n: GridStep) -> Result<()> {
        self.stats.steps += 1;
        let mut tau = 0.0;
        let mut events = 0u32;
        loop {
            let stop = match self.mode {
                Mode::Slip(Direction::Positive) => self.slip::<true>(n, tau)?,
                Mode::Slip(Direction::Negative) => self.slip::<false>(n, tau)?,
                Mode::Stick => self.stick(n, tau),
                Mode::Creep(dir) => self.creep(n, tau, dir)?,
            };
            match stop {
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

    /// The stick part of [`Stepper::step`], from fraction `tau` of step `n`: either friction
    /// holds the platen to the end of the step, or it breaks away ([`breakaway`]) and the
    /// mode becomes slip, from a point where `|N|` is above the threshold.
    #[inline]
    fn stick(&mut self, n: GridStep, tau: f64) -> StepStop {
        let h = self.grid.h;
        let (f_start, f_end) = (self.grid.force(n, tau), self.grid.force(n, 1.0));
        let Some(b) = breakaway(self.model, self.y.u, f_start, f_end) else {
            self.stats.stick_time_s += (1.0 - tau) * h;
            return StepStop::Step;
        };
        let (elastic, threshold) = (
            self.model.elastic_force_n(self.y.u),
            self.model.static_threshold_n(self.y.u),
        );
        let sign = b.direction.sign();
        let tau_b = just_past(tau + b.fraction * (1.0 - tau), 1.0, |t| {
            sign * (self.grid.force(n, t) - elastic) > threshold
        });
        self.stats.stick_time_s += (tau_b - tau) * h;
        self.stats.record(EventKind::Breakaway);
        let f = self.grid.force(n, tau_b);
        self.enter(Mode::Slip(b.direction), f);
        StepStop::Event {
            at: tau_b,
            kind: EventKind::Breakaway,
        }
    }

    /// The creep part of [`Stepper::step`] in direction `dir`, from fraction `tau` of step
    /// `n`: the quasi-static creep of [`crate::creep`] to the end of the step, a stop, or the
    /// return to slip.
    fn creep(&mut self, n: GridStep, tau: f64, dir: Direction) -> Result<StepStop> {
        let h = self.grid.h;
        let span_s = (1.0 - tau) * h;
        let (f_start, f_end) = (self.grid.force(n, tau), self.grid.force(n, 1.0));
        let run = creep(
            self.model,
            dir,
            self.y,
            f_start,
            f_end,
            span_s,
            self.w_stiff,
        );
        self.stats.rhs_evaluations += run.evaluations;
        self.y = run.y;
        let at = if run.at_s >= span_s {
            1.0
        } else {
            (tau + run.at_s / h).min(1.0)
        };
        if !(self.y.u.is_finite() && self.y.v.is_finite()) {
            return Err(self.non_finite(n, at));
        }
        Ok(match run.end {
            CreepEnd::Continues if at >= 1.0 => StepStop::Step,
            CreepEnd::Continues => StepStop::Moved { at },
            CreepEnd::Stops => {
                self.stats.record(EventKind::Stop);
                self.enter(Mode::Stick, 0.0);
                StepStop::Event {
                    at,
                    kind: EventKind::Stop,
                }
            }
            CreepEnd::Slips => {
                let f = self.grid.force(n, at);
                self.enter(Mode::Slip(dir), f);
                StepStop::Moved { at }
            }
            CreepEnd::Reverses => {
                // Leave rest the other way from where the net force, as this step's grid
                // evaluates it, is beyond the threshold that way (creep's own time rounds).
                let back = dir.opposite();
                let (u, sign) = (self.y.u, back.sign());
                let (elastic, threshold) = (
                    self.model.elastic_force_n(u),
                    self.model.static_threshold_n(u),
                );
                let at = just_past(at, 1.0, |t| {
                    sign * (self.grid.force(n, t) - elastic) > threshold
                });
                let f = self.grid.force(n, at);
                let (mode, kind) = arrive_at_rest(self.model, u, f, dir);
                self.enter(mode, f);
                match kind {
                    Some(kind) => {
                        self.stats.record(kind);
                        StepStop::Event { at, kind }
                    }
                    None => StepStop::Moved { at },
                }
            }
        })
    }

    /// The slip part of [`Stepper::step`] in direction `direction::<POSITIVE>()`, from
    /// fraction `tau` of step `n`.
    ///
    /// The fast path is one RK4 step to the end of the grid step, accepted when the speed
    /// stays positive at every stage and end and its cubic Hermite interpolant does not dip to
    /// zero inside the step ([`dip_to_zero`]). Otherwise [`Stepper::careful`] takes over.
    #[inline(always)]
    fn slip<const POSITIVE: bool>(&mut self, n: GridStep, tau: f64) -> Result<StepStop> {
        if self.y.v != 0.0 {
            let dir = direction::<POSITIVE>();
            let span = (1.0 - tau) * self.grid.h;
            let f_start = self.grid.force(n, tau);
            let f_mid = self.grid.force(n, 0.5 * (1.0 + tau));
            let f_end = self.grid.force(n, 1.0);
            self.stats.rhs_evaluations += 3;
            let (y1, stage_min) = rk4_slip::<M, POSITIVE>(
                self.model, self.y, self.rates, span, f_start, f_mid, f_end,
            );
            if dir * y1.v > 0.0 && stage_min > 0.0 {
                self.stats.rhs_evaluations += 1;
                let r1 = self.model.slip_rates(f_end, y1.u, y1.v, dir);
                let (d0, d1) = (dir * self.rates.a_m_s2 * span, dir * r1.a_m_s2 * span);
                if dip_to_zero(dir * self.y.v, dir * y1.v, d0, d1).is_none() {
                    if !(y1.u.is_finite() && r1.a_m_s2.is_finite()) {
                        return Err(self.non_finite(n, 1.0));
                    }
                    self.y = y1;
                    self.rates = r1;
                    return Ok(StepStop::Step);
                }
            }
            if !(y1.u.is_finite() && y1.v.is_finite()) {
                return Err(self.non_finite(n, tau));
            }
        }
        self.careful::<POSITIVE>(n, tau)
    }

    /// Slip near `v = 0` from fraction `tau` of step `n`: the rest of the step is tried, and
    /// halved until the piece either is safe (speed positive at every stage, at its end and
    /// on its Hermite interpolant: it is committed, [`StepStop::Moved`] or
    /// [`StepStop::Step`]) or ends across `v = 0` (the crossing is located on the graded map
    /// and the reset of [`arrive_at_rest`] applied: [`StepStop::Event`], or
    /// [`StepStop::Moved`] into creep). Every crossing inside the step is found this way, two
    /// reversals in one step included.
    fn careful<const POSITIVE: bool>(&mut self, n: GridStep, tau: f64) -> Result<StepStop> {
        let dir = direction::<POSITIVE>();
        let from = Direction::of_sign(dir);
        let from_rest = self.y.v == 0.0;
        if from_rest
            && self.creeps_from_rest(from, self.grid.force(n, tau), self.grid.force(n, 1.0))
        {
            self.enter(Mode::Creep(from), 0.0);
            return Ok(StepStop::Moved { at: tau });
        }
        let mut len = 1.0 - tau;
        for _ in 0..=MAX_HALVINGS {
            let grading = if from_rest {
                Grading::Start
            } else {
                Grading::Single
            };
            let (y1, stage_min) = self.advance::<POSITIVE>(n, tau, len, grading);
            if !(y1.u.is_finite() && y1.v.is_finite()) {
                return Err(self.non_finite(n, tau));
            }
            if dir * y1.v > 0.0 && stage_min > 0.0 {
                let f1 = self.grid.force(n, tau + len);
                self.stats.rhs_evaluations += 1;
                let r1 = self.model.slip_rates(f1, y1.u, y1.v, dir);
                let span = len * self.grid.h;
                let (d0, d1) = (dir * self.rates.a_m_s2 * span, dir * r1.a_m_s2 * span);
                if dip_to_zero(dir * self.y.v, dir * y1.v, d0, d1).is_none() {
                    if !r1.a_m_s2.is_finite() {
                        return Err(self.non_finite(n, tau + len));
                    }
                    self.y = y1;
                    self.rates = r1;
                    let at = tau + len;
                    return Ok(if at >= 1.0 {
                        StepStop::Step
                    } else {
                        StepStop::Moved { at }
                    });
                }
            } else if dir * y1.v <= 0.0 {
                // The piece ends across v = 0. Arriving at rest is singular: redo it graded
                // towards the end, then locate the crossing on that graded map.
                let grading = if from_rest {
                    Grading::Both
                } else {
                    Grading::End
                };
                let (y2, _) = self.advance::<POSITIVE>(n, tau, len, grading);
                if dir * y2.v <= 0.0 {
                    let (x, y_event) = self
                        .locate::<POSITIVE>(n, tau, len, y2, grading)
                        .unwrap_or((0.0, self.y));
                    let mut at = tau + x;
                    if 1.0 - at < 1e-12 {
                        at = 1.0;
                    }
                    self.y = Kin { v: 0.0, ..y_event };
                    return Ok(self.arrive(n, at, from));
                }
            }
            // Not safe and not (yet) across: the crossing or dip, if any, is in the first
            // part of the piece.
            len *= 0.5;
        }
        // A piece of 2⁻⁶⁰ of the step still not safe: the platen is at rest to within what
        // such a piece resolves.
        self.y.v = 0.0;
        Ok(self.arrive(n, tau, from))
    }

    /// Whether a platen leaving rest in `from` is in the creep regime for the rest of the
    /// step: its creep speed under the force at both ends (`f_start`, `f_end`; the force is
    /// linear in between) is below the stiff speed, so an explicit step would only overshoot
    /// (see [`crate::creep`]).
    fn creeps_from_rest(&mut self, from: Direction, f_start: f64, f_end: f64) -> bool {
        let w_stiff = stiff_speed_m_s(self.model, self.y.u, self.grid.h);
        [f_start, f_end]
            .iter()
            .all(|&f| creep_speed_m_s(self.model, from, self.y.u, f, w_stiff).is_some())
    }

    /// The reset at `v = 0` reached at fraction `at` of step `n` in slip `from`
    /// ([`arrive_at_rest`]): stick, reversal, or creep on.
    fn arrive(&mut self, n: GridStep, at: f64, from: Direction) -> StepStop {
        let f = self.grid.force(n, at);
        let (mode, kind) = arrive_at_rest(self.model, self.y.u, f, from);
        self.enter(mode, f);
        match kind {
            Some(kind) => {
                self.stats.record(kind);
                StepStop::Event { at, kind }
            }
            None => StepStop::Moved { at },
        }
    }

    /// RK4 in slip from the current state at fraction `tau` of step `n` over a length `x·h`,
    /// split into the sub-steps of `grading`; with the smallest stage speed of all sub-steps.
    fn advance<const POSITIVE: bool>(
        &mut self,
        n: GridStep,
        tau: f64,
        x: f64,
        grading: Grading,
    ) -> (Kin, f64) {
        let dir = direction::<POSITIVE>();
        let (mut y, mut r) = (self.y, self.rates);
        let mut stage_min = f64::INFINITY;
        let mut s = tau;
        for (i, &p) in grading.pieces().iter().enumerate() {
            let len = p * x;
            let f_start = self.grid.force(n, s);
            if i > 0 {
                r = self.model.slip_rates(f_start, y.u, y.v, dir);
                self.stats.rhs_evaluations += 1;
            }
            let f_mid = self.grid.force(n, s + 0.5 * len);
            let f_end = self.grid.force(n, s + len);
            let (y1, m) =
                rk4_slip::<M, POSITIVE>(self.model, y, r, len * self.grid.h, f_start, f_mid, f_end);
            y = y1;
            stage_min = stage_min.min(m);
            self.stats.rhs_evaluations += 3;
            s += len;
        }
        (y, stage_min)
    }

    /// The error of a state found non-finite at fraction `tau` of step `n`.
    fn non_finite(&self, n: GridStep, tau: f64) -> IntegrateError {
        let cause = Failure::NonFiniteState {
            u_m: self.y.u,
            v_m_s: self.y.v,
        };
        IntegrateError::failed(self.grid.time_s(n, tau), cause)
    }

    /// Finds the step length `x ∈ (0, rem]` (fraction of `h`) at which the graded RK4
    /// velocity from the current state reaches zero, given that the length `rem` ends at
    /// `y_rem` with `dir·v ≤ 0` ([`locate_zero_velocity`] on the graded RK4 map). Returns `x`
    /// and the state there (velocity not yet zeroed), or `None` if the platen starts at rest
    /// and does not move in `dir` for any step length.
    fn locate<const POSITIVE: bool>(
        &mut self,
        n: GridStep,
        tau: f64,
        rem: f64,
        y_rem: Kin,
        grading: Grading,
    ) -> Option<(f64, Kin)> {
        let dir = direction::<POSITIVE>();
        // g(x) = dir·v(x): positive before the crossing, ≤ 0 after it.
        let g_start = dir * self.y.v;
        let end = (y_rem, dir * y_rem.v);
        let tolerance = 4.0 * f64::EPSILON * rem;
        let Ok(found) = locate_zero_velocity(rem, g_start, end, tolerance, |x| {
            self.stats.root_iterations += 1;
            let (y, _) = self.advance::<POSITIVE>(n, tau, x, grading);
            Ok::<_, Infallible>((y, dir * y.v))
        });
        found
    }

    /// Closes the energy balance at the current state, the run having finished at `t_s`.
    pub(crate) fn finish(&mut self, t_s: f64) -> RunStats {
        self.stats.energy.close(
            self.model,
            self.y.u,
            self.y.v,
            self.y.work,
            self.y.dissipated,
        );
        self.stats.accepted_steps = self.stats.steps;
        self.stats.stop = StopReason::Finished { t_s };
        self.stats
    }
}
