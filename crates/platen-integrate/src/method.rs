//! One entry point for forward runs, whatever the integrator: [`ForwardIntegrator`] and the
//! [`Method`] a scenario selects.

use platen_model::PlatenModel;

use crate::dopri5::{forward_dopri5, Dopri5Settings};
use crate::error::Result;
use crate::output::SampleSink;
use crate::record::ForceRecord;
use crate::rk4::{forward_rk4, Rk4};
use crate::run::{RunStats, State};

/// A forward integrator with exact stick-slip: a recorded force → the motion it produces.
///
/// Every implementation delivers `samples` output samples, at the record's first `samples`
/// sample times, to `sink`, and returns the run's statistics.
pub trait ForwardIntegrator {
    /// The integrator's name as the scenario format spells it (`"rk4"`, `"dopri5"`).
    fn name(&self) -> &'static str;

    /// Runs `model` forward under `record` from `initial`.
    ///
    /// # Errors
    /// As [`forward_rk4`] and [`forward_dopri5`]: a record too short for `samples`, a
    /// non-finite initial state, or a numerical failure with its time.
    fn forward<M: PlatenModel, S: SampleSink>(
        &self,
        model: &M,
        record: &ForceRecord,
        initial: State,
        samples: usize,
        sink: &mut S,
    ) -> Result<RunStats>;
}

/// The integrator of a forward run, as a scenario selects it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Fixed-step RK4 ([`forward_rk4`]).
    Rk4(Rk4),
    /// Adaptive Dormand–Prince 5(4) ([`forward_dopri5`]).
    Dopri5(Dopri5Settings),
}

impl ForwardIntegrator for Method {
    fn name(&self) -> &'static str {
        match self {
            Method::Rk4(_) => "rk4",
            Method::Dopri5(_) => "dopri5",
        }
    }

    fn forward<M: PlatenModel, S: SampleSink>(
        &self,
        model: &M,
        record: &ForceRecord,
        initial: State,
        samples: usize,
        sink: &mut S,
    ) -> Result<RunStats> {
        match self {
            Method::Rk4(rk4) => forward_rk4(model, record, *rk4, initial, samples, sink),
            Method::Dopri5(settings) => {
                forward_dopri5(model, record, *settings, initial, samples, sink)
            }
        }
    }
}
