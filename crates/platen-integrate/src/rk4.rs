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
//! in [`crate::bare`]); this module keeps the RK4 settings and the entry point, the grid and
//! its driver are [`crate::grid`]'s, the grading of the pieces near rest the machine's.
//!
//! No allocation happens per step; a run allocates only what its [`SampleSink`] stores.

use platen_model::PlatenModel;

use crate::bare::Stepper;
use crate::error::{IntegrateError, Result};
use crate::grid::{drive, Grid};
use crate::output::SampleSink;
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
