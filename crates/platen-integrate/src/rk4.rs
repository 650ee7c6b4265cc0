//! Fixed-step classical Runge–Kutta (RK4) with exact stick-slip events.
//!
//! # Method
//!
//! Time runs on an integer counter: `t = t₀ + (n + τ)·h` with `h = Δt/k` (`Δt` the force
//! record's sample interval, `k ≥ 1` steps per sample) and `τ ∈ [0, 1]` the fraction of the
//! current step already done. The force is linear between samples, so it is linear inside
//! every step and is evaluated from the two samples that bracket it, never from a float time.
//!
//! The platen is in one of three modes (the events between them, and how they are located
//! and decided, are those of [`crate::event`], shared with Dopri5):
//!
//! * **slip±**: the smooth right-hand side with the friction direction fixed is stepped with
//!   RK4. If the step ends with the velocity on the other side of zero, the crossing is
//!   located by root-finding (Illinois) on the *length* of the RK4 step taken from the step's
//!   start, so the state at the event is an RK4 step that ends at `v = 0`. There `v` is set to
//!   exactly zero and the net force `N = F_A − F_E(u)` decides: stick if `|N| ≤ F_s(u)`,
//!   otherwise slip in the direction of `N`.
//! * **stick**: `u` is fixed and `v = a = 0`. Because `F_A` is linear within a step, the
//!   breakaway time, at which `|N|` reaches `F_s(u)`, is solved exactly; the rest of the
//!   step is then stepped in slip.
//!
//! No allocation happens per step; a run allocates only what its [`SampleSink`] stores.

use std::convert::Infallible;

use platen_model::{PlatenModel, SlipRates};

use crate::error::{IntegrateError, Result};
use crate::event::{
    arrive_at_rest, breakaway, locate_zero_velocity, Direction, EventKind, Mode, StepStop,
    MAX_EVENTS_PER_STEP,
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
struct GridStep {
    n: u64,
    j: usize,
    /// `i` as a number (exact: `i < k ≤ 1e9`).
    i: f64,
}

/// The force record seen from the integer time grid.
struct Grid<'a> {
    force: &'a [f64],
    inv_k: f64,
    h: f64,
    t0: f64,
}

impl Grid<'_> {
    /// Force at fraction `tau ∈ [0, 1]` of grid step `n`: linear between the two samples
    /// that bracket the step, exact at both samples.
    #[inline(always)]
    fn force(&self, n: GridStep, tau: f64) -> f64 {
        let j = n.j;
        let w = (n.i + tau) * self.inv_k;
        if w == 0.0 {
            self.force[j]
        } else {
            self.force[j] * (1.0 - w) + self.force[j + 1] * w
        }
    }

    #[inline]
    fn time_s(&self, n: GridStep, tau: f64) -> f64 {
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
const fn direction<const POSITIVE: bool>() -> f64 {
    if POSITIVE {
        1.0
    } else {
        -1.0
    }
}

/// One classical RK4 step of length `h` in slip with direction `direction::<POSITIVE>()`
/// from `y`, given the rates at the start `r0` (so the caller can reuse them) and the forces
/// at the start, middle and end of the step.
#[inline(always)]
fn rk4_slip<M: PlatenModel, const POSITIVE: bool>(
    m: &M,
    y: Kin,
    r0: SlipRates,
    h: f64,
    f_start: f64,
    f_mid: f64,
    f_end: f64,
) -> Kin {
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
    Kin {
        u: u + h6 * (v + 2.0 * (v2 + v3) + v4),
        v: v + h6 * (r0.a_m_s2 + 2.0 * (r2.a_m_s2 + r3.a_m_s2) + r4.a_m_s2),
        work: y.work + h6 * (f_start * v + 2.0 * f_mid * (v2 + v3) + f_end * v4),
        dissipated: y.dissipated
            + h6 * (r0.dissipated_power_w
                + 2.0 * (r2.dissipated_power_w + r3.dissipated_power_w)
                + r4.dissipated_power_w),
    }
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
    let grid = Grid {
        force: record.force_n(),
        inv_k: 1.0 / k as f64,
        h: record.dt_s() / k as f64,
        t0: record.t_s()[0],
    };
    let mut stepper = Stepper::new(model, grid, initial);
    let times = record.t_s();
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

/// How a slip interval that touches `v = 0` is split into RK4 sub-steps.
///
/// Near `v = 0` the `|v|^α` law (α < 1) makes the right-hand side singular like `√(t − t*)`,
/// which cuts a single RK4 step's accuracy to `O(h^1.5)` (about 1e-7 m/s per event at
/// h = 1/1024 s on the paper's model). Geometric sub-steps that halve towards the singular
/// end make the step that holds it `2⁵` times shorter, which removes that error to the
/// 1e-10 m level, at the cost of a few extra stages per event only.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Grading {
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
    fn pieces(self) -> &'static [f64] {
        match self {
            Grading::Start => &GRADED_START,
            Grading::End => &GRADED_END,
            Grading::Both => &GRADED_BOTH,
        }
    }
}

/// The mutable state of a forward RK4 run.
struct Stepper<'a, M> {
    model: &'a M,
    grid: Grid<'a>,
    y: Kin,
    mode: Mode,
    /// Rates at the current state in the current mode (zero in stick).
    rates: SlipRates,
    stats: RunStats,
}

const AT_REST: SlipRates = SlipRates {
    a_m_s2: 0.0,
    dissipated_power_w: 0.0,
};

impl<'a, M: PlatenModel> Stepper<'a, M> {
    fn new(model: &'a M, grid: Grid<'a>, initial: State) -> Self {
        let mut s = Self {
            model,
            grid,
            y: Kin::start(initial),
            mode: Mode::Stick,
            rates: AT_REST,
            stats: RunStats::default(),
        };
        let f0 = s.grid.force[0];
        s.mode = Mode::initial(model, s.y.u, s.y.v, f0);
        s.refresh_rates(f0);
        s.stats.energy = EnergyBalance::start(model, s.y.u, s.y.v);
        s
    }

    #[inline(always)]
    fn refresh_rates(&mut self, f: f64) {
        self.rates = match self.mode {
            Mode::Stick => AT_REST,
            Mode::Slip(dir) => {
                self.stats.rhs_evaluations += 1;
                self.model.slip_rates(f, self.y.u, self.y.v, dir.sign())
            }
        };
    }

    /// The output sample at sample `j` of the record (grid point `j·k`, τ = 0).
    fn sample(&self, j: usize, t_s: f64) -> Sample {
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
    fn step(&mut self, n: GridStep) -> Result<()> {
        self.stats.steps += 1;
        let mut tau = 0.0;
        let mut events = 0u32;
        loop {
            let stop = match self.mode {
                Mode::Slip(Direction::Positive) => self.slip::<true>(n, tau)?,
                Mode::Slip(Direction::Negative) => self.slip::<false>(n, tau)?,
                Mode::Stick => self.stick(n, tau),
            };
            match stop {
                StepStop::Step => return Ok(()),
                StepStop::Event { at, .. } => tau = at,
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
    /// mode becomes slip.
    #[inline]
    fn stick(&mut self, n: GridStep, tau: f64) -> StepStop {
        let h = self.grid.h;
        let (f_start, f_end) = (self.grid.force(n, tau), self.grid.force(n, 1.0));
        let Some(b) = breakaway(self.model, self.y.u, f_start, f_end) else {
            self.stats.stick_time_s += (1.0 - tau) * h;
            return StepStop::Step;
        };
        let tau_b = tau + b.fraction * (1.0 - tau);
        self.stats.stick_time_s += (tau_b - tau) * h;
        self.stats.record(EventKind::Breakaway);
        self.mode = Mode::Slip(b.direction);
        let f = self.grid.force(n, tau_b);
        self.refresh_rates(f);
        StepStop::Event {
            at: tau_b,
            kind: EventKind::Breakaway,
        }
    }

    /// The slip part of [`Stepper::step`] in direction `direction::<POSITIVE>()`, from
    /// fraction `tau` of step `n`: either completes the step ([`StepStop::Step`]) or stops at
    /// the located `v = 0` event with the reset applied ([`StepStop::Event`] at the new `τ`).
    #[inline(always)]
    fn slip<const POSITIVE: bool>(&mut self, n: GridStep, tau: f64) -> Result<StepStop> {
        let dir = direction::<POSITIVE>();
        let h = self.grid.h;
        let rem = 1.0 - tau;
        // Leaving v = 0 (after a breakaway or reversal) the √|v| law is singular:
        // grade the sub-steps towards the start.
        let from_rest = self.y.v == 0.0;
        let y1 = if from_rest {
            self.advance::<POSITIVE>(n, tau, rem, Grading::Start)
        } else {
            let f_start = self.grid.force(n, tau);
            let f_mid = self.grid.force(n, tau + 0.5 * rem);
            let f_end = self.grid.force(n, 1.0);
            self.stats.rhs_evaluations += 3;
            rk4_slip::<M, POSITIVE>(
                self.model,
                self.y,
                self.rates,
                rem * h,
                f_start,
                f_mid,
                f_end,
            )
        };
        if !(y1.u.is_finite() && y1.v.is_finite()) {
            return Err(self.non_finite(n, tau));
        }
        if dir * y1.v > 0.0 {
            self.commit::<POSITIVE>(n, y1)?;
            return Ok(StepStop::Step);
        }
        // v reaches zero inside the step. Arriving at v = 0 is singular too:
        // redo the remainder graded towards the end, then locate the crossing on
        // that graded map.
        let grading = if from_rest {
            Grading::Both
        } else {
            Grading::End
        };
        let y2 = self.advance::<POSITIVE>(n, tau, rem, grading);
        if dir * y2.v > 0.0 {
            self.commit::<POSITIVE>(n, y2)?;
            return Ok(StepStop::Step);
        }
        let Some((x, y_event)) = self.locate::<POSITIVE>(n, tau, rem, y2, grading) else {
            // Started at v = 0 and no step length moves the platen in `dir`:
            // friction holds it.
            self.y.v = 0.0;
            self.mode = Mode::Stick;
            self.stats.record(EventKind::Stop);
            self.rates = AT_REST;
            return Ok(StepStop::Event {
                at: tau,
                kind: EventKind::Stop,
            });
        };
        let mut at = tau + x;
        if 1.0 - at < 1e-12 {
            at = 1.0;
        }
        self.y = Kin { v: 0.0, ..y_event };
        let f = self.grid.force(n, at);
        let kind;
        (self.mode, kind) = arrive_at_rest(self.model, self.y.u, f);
        self.stats.record(kind);
        self.refresh_rates(f);
        Ok(StepStop::Event { at, kind })
    }

    /// Accepts the state at the end of step `n`.
    #[inline(always)]
    fn commit<const POSITIVE: bool>(&mut self, n: GridStep, y: Kin) -> Result<()> {
        self.y = y;
        // The mode is slip in this direction: refresh_rates with the direction known.
        let f = self.grid.force(n, 1.0);
        self.stats.rhs_evaluations += 1;
        self.rates = self
            .model
            .slip_rates(f, self.y.u, self.y.v, direction::<POSITIVE>());
        if !self.rates.a_m_s2.is_finite() {
            return Err(self.non_finite(n, 1.0));
        }
        Ok(())
    }

    /// RK4 in slip from the current state at fraction `tau` of step `n` over a length `x·h`,
    /// split into the sub-steps of `grading`.
    fn advance<const POSITIVE: bool>(
        &mut self,
        n: GridStep,
        tau: f64,
        x: f64,
        grading: Grading,
    ) -> Kin {
        let dir = direction::<POSITIVE>();
        let (mut y, mut r) = (self.y, self.rates);
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
            y = rk4_slip::<M, POSITIVE>(self.model, y, r, len * self.grid.h, f_start, f_mid, f_end);
            self.stats.rhs_evaluations += 3;
            s += len;
        }
        y
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
    /// velocity from the current state reaches zero, given that the full remainder ends at
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
            let y = self.advance::<POSITIVE>(n, tau, x, grading);
            Ok::<_, Infallible>((y, dir * y.v))
        });
        found
    }

    /// Closes the energy balance at the current state, the run having finished at `t_s`.
    fn finish(&mut self, t_s: f64) -> RunStats {
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
