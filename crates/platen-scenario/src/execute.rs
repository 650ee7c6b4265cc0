//! The executor: [`Scenario::run`] runs a validated scenario into any [`SampleSink`].

use std::path::Path;

use platen_integrate::{
    inverse, ForwardIntegrator, IntegrateError, Peaks, RunStats, Sample, SampleSink, Trajectory,
};
use platen_io::csv::CsvWriter;
use platen_io::IoError;
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
        self.model.run(&self.run, sink).map_err(ScenarioError::Run)
    }
}

impl Model {
    /// Runs `run` on this model (a sweep's case: another model or a scaled excitation),
    /// delivering every output sample to `sink`.
    ///
    /// # Errors
    /// The integrator's error when a forward run fails numerically, with its time.
    pub fn run<S: SampleSink>(
        &self,
        run: &Run,
        sink: &mut S,
    ) -> std::result::Result<RunOutput, IntegrateError> {
        match self {
            Model::Identified(m) => run_model(m, run, sink),
            Model::Full(m) => run_model(&**m, run, sink),
        }
    }
}

/// Runs `run` on `model`, delivering every sample to `sink` and to a [`Peaks`].
fn run_model<M: PlatenModel, S: SampleSink>(
    model: &M,
    run: &Run,
    sink: &mut S,
) -> std::result::Result<RunOutput, IntegrateError> {
    let mut sink = (sink, Peaks::default());
    let stats = match run {
        Run::Forward {
            record,
            integrator,
            initial,
            samples,
        } => Some(integrator.forward(model, record, *initial, *samples, &mut sink)?),
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

/// A [`SampleSink`] that streams the contract's columns ([`Trajectory::COLUMN_NAMES`]) to a
/// CSV file as the run produces them, atomically ([`CsvWriter`]): a one-hour 1024 Hz run
/// holds no trajectory in memory, and a failed run leaves no partial file.
#[derive(Debug)]
pub struct CsvSink {
    writer: CsvWriter<'static>,
    error: Option<IoError>,
}

impl CsvSink {
    /// Creates the output's temporary file and writes the header, so that an unwritable
    /// destination fails before the run.
    ///
    /// # Errors
    /// [`ScenarioError::Io`] if the temporary file cannot be created or written.
    pub fn create(path: &Path) -> Result<Self> {
        Ok(Self {
            writer: CsvWriter::create(path, &Trajectory::COLUMN_NAMES)?,
            error: None,
        })
    }

    /// Renames the complete file over the destination.
    ///
    /// # Errors
    /// The first error met while writing (a non-finite value, with its line and column, or
    /// a failed write), or one of committing the file; nothing is left behind.
    pub fn finish(self) -> Result<()> {
        if let Some(error) = self.error {
            return Err(error.into());
        }
        Ok(self.writer.finish()?)
    }
}

impl SampleSink for CsvSink {
    #[inline]
    fn accept(&mut self, s: &Sample) {
        if self.error.is_some() {
            return;
        }
        let row = [
            s.t_s,
            s.u_m,
            s.v_m_s,
            s.a_m_s2,
            s.terms.actuator_n,
            s.terms.inertial_n,
            s.terms.elastic_n,
            s.terms.dissipative_n,
        ];
        if let Err(error) = self.writer.write_row(&row) {
            self.error = Some(error);
        }
    }
}
