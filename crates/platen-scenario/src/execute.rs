//! The executor: [`Scenario::run`] runs a validated scenario into any [`SampleSink`].

use platen_integrate::{inverse, ForwardIntegrator, Peaks, RunStats, SampleSink};
use platen_model::PlatenModel;

use crate::error::{Result, ScenarioError};
use crate::scenario::{Model, Run, Scenario};

/// What a run leaves besides its samples: the peaks (and span) of every output channel and,
/// for a forward run, the solver's statistics and energy balance.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// Signed peaks of u, v, a and the actuator force, with their times.
    pub peaks: Peaks,
    /// Solver statistics of a forward run; `None` for an inverse run.
    pub stats: Option<RunStats>,
}

impl Scenario {
    /// Runs the scenario, delivering every output sample to `sink` in time order: forward
    /// runs at the force record's sample times, inverse runs at the motion's.
    ///
    /// # Errors
    /// [`ScenarioError::Run`] when a forward run fails numerically (the cause names the
    /// time); samples before the failure have been delivered to `sink`.
    pub fn run<S: SampleSink>(&self, sink: &mut S) -> Result<RunOutput> {
        match &self.model {
            Model::Identified(m) => run_model(m, &self.run, sink),
            Model::Full(m) => run_model(&**m, &self.run, sink),
        }
    }
}

/// Runs `run` on `model`, delivering every sample to `sink` and to a [`Peaks`].
fn run_model<M: PlatenModel, S: SampleSink>(
    model: &M,
    run: &Run,
    sink: &mut S,
) -> Result<RunOutput> {
    let mut sink = (sink, Peaks::default());
    let stats = match run {
        Run::Forward {
            record,
            integrator,
            initial,
            samples,
        } => Some(
            integrator
                .forward(model, record, *initial, *samples, &mut sink)
                .map_err(ScenarioError::Run)?,
        ),
        Run::Inverse { motion } => {
            inverse(model, motion, &mut sink);
            None
        }
    };
    Ok(RunOutput {
        peaks: sink.1,
        stats,
    })
}
