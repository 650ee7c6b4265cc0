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
//! The bare platen is a plant of the one mode machine ([`crate::machine`], with its exact rest
//! in [`crate::bare`]); this module keeps the grid, the driver over it and the grading of the
//! pieces near rest that every plant's RK4 shares.
//!
//! No allocation happens per step; a run allocates only what its [`SampleSink`] stores.

use platen_model::PlatenModel;

use crate::bare::Stepper;
use crate::error::{IntegrateError, Result};
use crate::output::{Sample, SampleSink};
use crate::record::ForceRecord;
use crate::run::{check_run, RunStats, State};

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

/// The input and the time hooks of a [`crate::machine::Plant`] that runs on a force record's
/// grid (fields `grid: Grid` and `n: GridStep`): positions are fractions of grid step `n`, the
/// input is the record's force there, an event a hair short of the step's end lands on it.
macro_rules! grid_time {
    () => {
        #[inline(always)]
        fn input(&self, at: f64) -> f64 {
            self.grid.force(self.n, at)
        }
        #[inline(always)]
        fn seconds(&self, len: f64) -> f64 {
            len * self.grid.h
        }
        fn units(&self, seconds: f64) -> f64 {
            seconds / self.grid.h
        }
        fn time_s(&self, at: f64) -> f64 {
            self.grid.time_s(self.n, at)
        }
        fn tolerance_floor(&self) -> f64 {
            0.0
        }
        /// A creep stop located this close (fraction of a step) to where the advance
        /// started has not moved time (see [`crate::machine::Plant::min_progress`]).
        fn min_progress(&self) -> f64 {
            4.0 * f64::EPSILON
        }
        fn land(&self, tau: f64, x: f64, _rest: f64) -> f64 {
            let at = tau + x;
            if 1.0 - at < 1e-12 {
                1.0
            } else {
                at
            }
        }
        fn reach(&self, tau: f64, len: f64) -> f64 {
            tau + len
        }
        fn break_at(&self, tau: f64, x: f64, _rest: f64, _held: bool) -> f64 {
            (tau + x).min(1.0)
        }
    };
}
pub(crate) use grid_time;

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
