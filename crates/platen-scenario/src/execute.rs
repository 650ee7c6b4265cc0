//! The executor: [`PlatenScenario::run`] runs a validated scenario into any [`SampleSink`].

use std::path::Path;

use platen_integrate::{
    forward_closed_loop, forward_specimen, inverse, inverse_specimen, ForwardIntegrator,
    IntegrateError, LoopRun, LoopStats, Motion, Peak, Peaks, RunStats, Sample, SampleSink,
    SpecimenColumns, SystemColumns, TableSink, Trajectory,
};
use platen_io::series::SeriesWriter;
use platen_io::IoError;
use platen_model::{PlatenModel, Specimen};

use crate::error::{Result, ScenarioError};
use crate::rig::{LoopSettings, Rig};
use crate::scenario::{Model, PlatenScenario, Run};
use platen_system::TableSystem;

/// What a run leaves besides its samples: the peaks (and span) of every output channel and,
/// for a forward run, the solver's statistics and energy balance.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// Signed peaks of u, v, a and the actuator force, with their times.
    pub peaks: Peaks,
    /// Solver statistics of a forward run; `None` for an inverse run.
    pub stats: Option<RunStats>,
    /// What a closed-loop run reports besides (`None` for the others).
    pub system: Option<LoopOutput>,
}

/// What a closed-loop run reports besides its samples and peaks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopOutput {
    /// The loop's statistics (saturation, cavitation, supply).
    pub stats: LoopStats,
    /// How well the platen followed the command.
    pub tracking: Tracking,
}

/// Tracking of a closed-loop run, accumulated as samples stream past: the achieved
/// displacement and acceleration against the command's, and the valves' peak flow.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tracking {
    samples: usize,
    sum_du2: f64,
    sum_da2: f64,
    /// Sums of the command's own squares (the NRMSEs' denominators).
    sum_u2: f64,
    sum_a2: f64,
    /// Signed peak of `u − u_ref`, m.
    pub displacement_peak: Peak,
    /// Signed peak of `a − a_ref`, m/s².
    pub acceleration_peak: Peak,
    /// Signed peak flow into the cap-side chambers, m³/s.
    pub flow_peak: Peak,
}

impl Tracking {
    /// RMS of `u − u_ref`, m.
    pub fn displacement_rms_m(&self) -> f64 {
        (self.sum_du2 / self.samples.max(1) as f64).sqrt()
    }

    /// RMS of `a − a_ref`, m/s².
    pub fn acceleration_rms_m_s2(&self) -> f64 {
        (self.sum_da2 / self.samples.max(1) as f64).sqrt()
    }

    /// RMS of `u − u_ref` over the RMS of `u_ref` (`None` for a command that stays at 0).
    pub fn displacement_nrmse(&self) -> Option<f64> {
        (self.sum_u2 > 0.0).then(|| (self.sum_du2 / self.sum_u2).sqrt())
    }

    /// RMS of `a − a_ref` over the RMS of `a_ref` (`None` for a command without
    /// acceleration): the relative error drive iteration reports.
    pub fn acceleration_nrmse(&self) -> Option<f64> {
        (self.sum_a2 > 0.0).then(|| (self.sum_da2 / self.sum_a2).sqrt())
    }
}

/// A sink that tracks the platen against `command`.
struct TrackingSink<'a> {
    command: &'a Motion,
    tracking: Tracking,
}

impl SampleSink for TrackingSink<'_> {
    fn accept(&mut self, s: &Sample) {
        let (u_ref, a_ref) = (self.command.u_m()[s.index], self.command.a_m_s2()[s.index]);
        let (du, da) = (s.u_m - u_ref, s.a_m_s2 - a_ref);
        let t = &mut self.tracking;
        t.samples += 1;
        t.sum_du2 += du * du;
        t.sum_da2 += da * da;
        t.sum_u2 += u_ref * u_ref;
        t.sum_a2 += a_ref * a_ref;
        update(&mut t.displacement_peak, du, s.t_s);
        update(&mut t.acceleration_peak, da, s.t_s);
        if let Some(sy) = &s.system {
            update(&mut t.flow_peak, sy.flow_m3_s, s.t_s);
        }
    }
}

fn update(p: &mut Peak, value: f64, t_s: f64) {
    if value.abs() > p.value.abs() {
        *p = Peak { value, t_s };
    }
}

impl PlatenScenario {
    /// Runs the scenario, delivering every output sample to `sink` in time order: forward
    /// runs at the force record's sample times, inverse runs at the motion's, closed loops
    /// at the command's.
    ///
    /// # Errors
    /// [`ScenarioError::Run`] when a forward run fails numerically (the cause names the
    /// time); samples before the failure have been delivered to `sink`.
    pub fn run<S: SampleSink>(&self, sink: &mut S) -> Result<RunOutput> {
        self.rig.run(&self.run, sink)
    }
}

impl Rig {
    /// Runs `run` on this rig (its model, specimen and, for a closed loop, table system),
    /// delivering every output sample to `sink` in time order.
    ///
    /// # Errors
    /// [`ScenarioError::Run`] when a forward run fails numerically (the cause names the
    /// time); [`ScenarioError::NoTableSystem`] for a closed loop on a rig without a table
    /// system.
    pub fn run<S: SampleSink>(&self, run: &Run, sink: &mut S) -> Result<RunOutput> {
        match (run, &self.table_system) {
            (Run::ClosedLoop { command, settings }, Some(system)) => {
                self.model
                    .run_closed_loop(system, settings, command, self.specimen.as_ref(), sink)
            }
            (Run::ClosedLoop { .. }, None) => return Err(ScenarioError::NoTableSystem),
            (run, _) => match &self.specimen {
                None => self.model.run(run, sink),
                Some(specimen) => self.model.run_with_specimen(run, specimen, sink),
            },
        }
        .map_err(ScenarioError::Run)
    }
}

impl Model {
    /// Runs `run` on this model (a sweep's case: another model or a scaled excitation),
    /// delivering every output sample to `sink`. The model has no table system: a
    /// [`Run::ClosedLoop`]'s command runs as the motion it asks for (inverse); the rig runs
    /// the loop ([`Rig::run`]).
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

    /// [`Model::run`] with `specimen` on the platen (forward runs with either integrator).
    ///
    /// # Errors
    /// As [`Model::run`].
    pub fn run_with_specimen<S: SampleSink>(
        &self,
        run: &Run,
        specimen: &Specimen,
        sink: &mut S,
    ) -> std::result::Result<RunOutput, IntegrateError> {
        match self {
            Model::Identified(m) => run_specimen(m, run, specimen, sink),
            Model::Full(m) => run_specimen(&**m, run, specimen, sink),
        }
    }
}

fn run_specimen<M: PlatenModel, S: SampleSink>(
    model: &M,
    run: &Run,
    specimen: &Specimen,
    sink: &mut S,
) -> std::result::Result<RunOutput, IntegrateError> {
    let mut sink = (sink, Peaks::default());
    let stats = match run {
        Run::Forward {
            record,
            integrator,
            initial,
            samples,
        } => Some(forward_specimen(
            model,
            specimen,
            record,
            *integrator,
            *initial,
            *samples,
            &mut sink,
        )?),
        Run::Inverse { motion }
        | Run::ClosedLoop {
            command: motion, ..
        } => {
            inverse_specimen(model, specimen, motion, &mut sink);
            None
        }
    };
    Ok(RunOutput {
        peaks: sink.1,
        stats,
        system: None,
    })
}

impl Model {
    /// Runs the closed loop of `system` on this model with `command` as the displacement
    /// command, integrated as `settings` say (and `specimen` on the platen), delivering every
    /// sample to `sink`.
    ///
    /// # Errors
    /// The integrator's error when the run fails numerically, with its time.
    pub fn run_closed_loop<S: SampleSink>(
        &self,
        system: &TableSystem,
        settings: &LoopSettings,
        command: &Motion,
        specimen: Option<&Specimen>,
        sink: &mut S,
    ) -> std::result::Result<RunOutput, IntegrateError> {
        let tracker = TrackingSink {
            command,
            tracking: Tracking::default(),
        };
        let mut sink = (sink, (Peaks::default(), tracker));
        let run = LoopRun {
            system,
            specimen,
            command,
            method: settings.method,
            initial: settings.initial_state(command.u_m()[0]),
        };
        let stats = match self {
            Model::Identified(m) => forward_closed_loop(m, &run, command.len(), &mut sink)?,
            Model::Full(m) => forward_closed_loop(&**m, &run, command.len(), &mut sink)?,
        };
        let (peaks, tracker) = sink.1;
        Ok(RunOutput {
            peaks,
            stats: Some(stats.run),
            system: Some(LoopOutput {
                stats,
                tracking: tracker.tracking,
            }),
        })
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
        Run::Inverse { motion }
        | Run::ClosedLoop {
            command: motion, ..
        } => {
            inverse(model, motion, &mut sink);
            None
        }
    };
    Ok(RunOutput {
        peaks: sink.1,
        stats,
        system: None,
    })
}

/// A [`SampleSink`] that streams the contract's columns ([`Trajectory::COLUMN_NAMES`]) to a
/// CSV file as the run produces them, atomically ([`SeriesWriter`]): a one-hour 1024 Hz run
/// holds no trajectory in memory, and a failed run leaves no partial file. A destination
/// ending in `.parquet` gets the same columns as a Parquet file (`float64`, one row per
/// sample) instead. Created with [`CsvSink::create_named`], it is the [`TableSink`] of a
/// multi-axis run, streamed the same way.
#[derive(Debug)]
pub struct CsvSink {
    writer: SeriesWriter,
    /// The destination and its header's width.
    path: std::path::PathBuf,
    columns: usize,
    error: Option<IoError>,
    /// The row being written (allocated once).
    row: Vec<f64>,
}

impl CsvSink {
    /// Creates the output's temporary file and writes the header, so that an unwritable
    /// destination fails before the run.
    ///
    /// # Errors
    /// [`ScenarioError::Io`] if the temporary file cannot be created or written.
    pub fn create(path: &Path) -> Result<Self> {
        Self::create_with_storeys(path, 0)
    }

    /// [`CsvSink::create`] for a run with a specimen of `storeys` storeys (0: none): the
    /// contract's columns, then `base_shear_n`, `storey{i}_u_m` and `storey{i}_a_m_s2` for
    /// `i = 1…storeys`.
    ///
    /// # Errors
    /// As [`CsvSink::create`].
    pub fn create_with_storeys(path: &Path, storeys: usize) -> Result<Self> {
        Self::create_for(path, storeys, false)
    }

    /// [`CsvSink::create_with_storeys`] for a closed-loop run too (`system`): then the table
    /// system's columns ([`SystemColumns::NAMES`]) follow.
    ///
    /// # Errors
    /// As [`CsvSink::create`].
    pub fn create_for(path: &Path, storeys: usize, system: bool) -> Result<Self> {
        Self::create_for_specimen(path, storeys, false, system)
    }

    /// [`CsvSink::create_for`] for a specimen that yields (`hysteretic`): after the storeys'
    /// `storey{i}_a_m_s2`, per storey its drift `storey{i}_drift_m`, restoring force
    /// `storey{i}_force_n` (the dashpot excluded), hysteretic force
    /// `storey{i}_hysteretic_force_n` and hysteretic energy `storey{i}_hysteretic_j`.
    ///
    /// # Errors
    /// As [`CsvSink::create`].
    pub fn create_for_specimen(
        path: &Path,
        storeys: usize,
        hysteretic: bool,
        system: bool,
    ) -> Result<Self> {
        let mut names: Vec<String> = Trajectory::COLUMN_NAMES
            .iter()
            .map(|&n| n.to_owned())
            .collect();
        if storeys > 0 {
            names.push("base_shear_n".into());
            names.extend((1..=storeys).map(|i| format!("storey{i}_u_m")));
            names.extend((1..=storeys).map(|i| format!("storey{i}_a_m_s2")));
        }
        if hysteretic {
            for kind in SpecimenColumns::HYSTERETIC_NAMES {
                names.extend(kind[..storeys].iter().map(|&n| n.to_owned()));
            }
        }
        if system {
            names.extend(SystemColumns::NAMES.iter().map(|&n| n.to_owned()));
        }
        Self::create_named(path, &names)
    }

    /// [`CsvSink::create`] for a multi-axis run whose columns are `names`
    /// (`TableScenario::columns`): the rows a [`TableSink`] receives are written as they are.
    ///
    /// # Errors
    /// As [`CsvSink::create`].
    pub fn create_named(path: &Path, names: &[String]) -> Result<Self> {
        Ok(Self {
            writer: SeriesWriter::create(path, names)?,
            path: path.to_owned(),
            columns: names.len(),
            error: None,
            row: Vec::with_capacity(names.len()),
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

/// The rows of a multi-axis run, under the header the sink was created with.
impl TableSink for CsvSink {
    fn start(&mut self, names: &[String], _samples: usize) {
        // The header was written at creation, from the scenario's columns: the run's are the
        // same (a mismatch would be a bug, reported as such; it leaves no file).
        if names.len() != self.columns && self.error.is_none() {
            self.error = Some(IoError::HeaderMismatch {
                path: self.path.clone(),
                names: self.columns,
                columns: names.len(),
            });
        }
    }

    #[inline]
    fn accept(&mut self, row: &[f64]) {
        if self.error.is_some() {
            return;
        }
        if let Err(error) = self.writer.write_row(row) {
            self.error = Some(error);
        }
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
        let result = match (&s.specimen, &s.system) {
            (None, None) => self.writer.write_row(&row),
            (sp, sy) => {
                self.row.clear();
                self.row.extend_from_slice(&row);
                if let Some(sp) = sp {
                    let n = sp.storeys;
                    self.row.push(sp.base_shear_n);
                    self.row.extend_from_slice(&sp.u_m[..n]);
                    self.row.extend_from_slice(&sp.a_m_s2[..n]);
                    if sp.hysteretic {
                        self.row.extend_from_slice(&sp.drift_m[..n]);
                        self.row.extend_from_slice(&sp.force_n[..n]);
                        self.row.extend_from_slice(&sp.hysteretic_force_n[..n]);
                        self.row.extend_from_slice(&sp.hysteretic_j[..n]);
                    }
                }
                if let Some(sy) = sy {
                    self.row.extend_from_slice(&SystemColumns::row(sy));
                }
                self.writer.write_row(&self.row)
            }
        };
        if let Err(error) = result {
            self.error = Some(error);
        }
    }
}
