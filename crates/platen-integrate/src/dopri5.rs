//! Adaptive forward runs of the bare platen with Dormand–Prince 5(4), exact about stick-slip.
//!
//! # Method
//!
//! The bare platen's plant ([`crate::bare`]) on the one mode machine ([`crate::machine`]),
//! with adaptive Dormand–Prince 5(4) pieces instead of RK4 ones:
//!
//! * every sample interval of the force record is a span of its own (the force is linear
//!   inside it and its derivative jumps at samples), so the step-size controller never has to
//!   reject steps at a kink; the step size carries over from one span to the next and never
//!   exceeds the interval;
//! * in **slip**, a piece of the rest of the span is integrated adaptively to `rtol`/`atol` on
//!   `(u, v)` and accepted when the speed stays positive at every stage, at its end and on its
//!   cubic Hermite interpolant; otherwise it is halved until it is safe or ends across
//!   `v = 0`, where the crossing is located by a bracketing root finder (Illinois) on the
//!   length of the adaptive integration, and the reset at rest applied;
//! * in **stick** the breakaway time is solved in closed form (the force is linear within the
//!   span), and in **creep** the quasi-static creep of [`crate::creep`] runs with the stiff
//!   speed of a step of one sample interval: the bare platen's exact rest, as with RK4.
//!
//! The actuator work and the dissipated energy ride along as quadratures (not controlled),
//! which gives the energy balance of the run. Dopri5 that cannot meet its tolerance stops the
//! run with [`IntegrateError::AdaptiveFailed`], as for every plant of the machine.

use platen_model::PlatenModel;

use crate::bare::Stepper;
use crate::error::{IntegrateError, Result};
use crate::grid::{drive, Grid};
use crate::machine::PieceMethod;
use crate::output::SampleSink;
use crate::record::ForceRecord;
use crate::run::{check_run, RunStats, State};

/// Settings of the adaptive integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dopri5Settings {
    rtol: f64,
    atol: f64,
}

impl Dopri5Settings {
    /// Relative and absolute tolerances of the step-size controller (per component of the
    /// state `(u [m], v [m/s], …)`).
    ///
    /// # Errors
    /// [`IntegrateError::InvalidTolerance`] unless both are finite and `> 0` (and `rtol < 1`).
    pub fn new(rtol: f64, atol: f64) -> Result<Self> {
        if !(rtol.is_finite() && rtol > 0.0 && rtol < 1.0) {
            return Err(IntegrateError::InvalidTolerance {
                name: "rtol",
                value: rtol,
            });
        }
        if !(atol.is_finite() && atol > 0.0) {
            return Err(IntegrateError::InvalidTolerance {
                name: "atol",
                value: atol,
            });
        }
        Ok(Self { rtol, atol })
    }

    /// Relative tolerance.
    pub fn rtol(self) -> f64 {
        self.rtol
    }

    /// Absolute tolerance.
    pub fn atol(self) -> f64 {
        self.atol
    }
}

/// Runs the model forward under `record` from `initial` with Dopri5 and exact stick-slip,
/// delivering `samples` output samples (the record's first `samples` sample times) to `sink`.
///
/// # Errors
/// As [`crate::forward_rk4`], plus [`IntegrateError::AdaptiveFailed`] when Dopri5 gives up
/// (step-size underflow, too many steps), with the time.
pub fn forward_dopri5<M: PlatenModel, S: SampleSink>(
    model: &M,
    record: &ForceRecord,
    settings: Dopri5Settings,
    initial: State,
    samples: usize,
    sink: &mut S,
) -> Result<RunStats> {
    check_run(record, initial, samples)?;
    let method = PieceMethod::Dopri5 {
        rtol: settings.rtol,
        atol: settings.atol,
    };
    let mut stepper = Stepper::with_method(model, Grid::new(record, 1), initial, method);
    drive(&mut stepper, record.t_s(), 1, samples, sink)
}
