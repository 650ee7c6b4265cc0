//! One entry for every scenario, whatever its table.
//!
//! [`Scenario::load`] reads a scenario file and validates it as what it describes: the
//! uniaxial platen of the paper ([`PlatenScenario`], a file without `table`) or a multi-axis
//! table ([`TableScenario`], a file with `table`). This is the only place that tells the two
//! apart; every front end (the CLI's `simulate` and `generate`, Python's `platen.simulate`,
//! [`simulate`]) goes through it.
//!
//! ```no_run
//! use platen_scenario::Scenario;
//!
//! // A multi-axis scenario, through the same door as a uniaxial one.
//! let scenario = Scenario::load("scenarios/multi-axis/forward.json".as_ref())?;
//! let run = scenario.run()?;
//! println!("{}: {} samples, x peaks at {:.4} m", scenario.name(), run.len(),
//!     run.column("x_m").unwrap().iter().fold(0.0f64, |m, v| m.max(v.abs())));
//! # Ok::<(), platen_scenario::ScenarioError>(())
//! ```

use std::path::Path;

use serde::Serialize;

use platen_integrate::{SpecimenColumns, SystemColumns, TableRun, Trajectory};
use platen_io::json::parse_json_file;

use crate::error::{Result, ScenarioError};
use crate::file::ScenarioFile;
use crate::multi_axis::{TableScenario, TableSummary};
use crate::rig::LoadedRig;
use crate::scenario::{PlatenScenario, Run};
use crate::summary::RunSummary;

/// A validated scenario of any table.
#[derive(Debug, Clone)]
// One is held per run, never in a collection: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum Scenario {
    /// The uniaxial platen of the paper (a file without `table`).
    Platen(PlatenScenario),
    /// A multi-axis table (a file with `table`).
    Table(TableScenario),
}

/// The summary of a run of any scenario: what `platen simulate --json` prints. Serialised
/// as the inner summary itself (the keys of the uniaxial [`RunSummary`] or of the
/// multi-axis [`TableSummary`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Summary {
    /// A uniaxial platen's run.
    Platen(Box<RunSummary>),
    /// A multi-axis table's run.
    Table(Box<TableSummary>),
}

impl Summary {
    /// What the run wants its user to know (an unstable loop, cavitation, saturated valves).
    pub fn warnings(&self) -> &[String] {
        match self {
            Summary::Platen(s) => &s.warnings,
            Summary::Table(s) => &s.warnings,
        }
    }
}

/// What a scenario file describes apart from its run, whose excitation is not read (a
/// scenario whose records are absent is described all the same): `platen model --scenario`.
#[derive(Debug, Clone)]
// One is held per run, never in a collection: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum ScenarioRig {
    /// The uniaxial platen's rig: model, limits, table system, specimen.
    Platen(LoadedRig),
    /// A multi-axis table, its table, specimen, limits and loop, with a still motion in place
    /// of its excitation ([`TableScenario::for_description`]).
    Table(TableScenario),
}

impl ScenarioRig {
    /// Reads the scenario file at `path` for what it describes.
    ///
    /// # Errors
    /// As [`LoadedRig::load`] and [`TableScenario::for_description`].
    pub fn load(path: &Path) -> Result<Self> {
        let file: ScenarioFile = parse_json_file(path)?;
        if file.table.is_some() {
            let table = TableScenario::for_description(path, &file)?;
            Ok(ScenarioRig::Table(table))
        } else {
            Ok(ScenarioRig::Platen(LoadedRig::load(path)?))
        }
    }
}

/// What a scenario's excitation is, as `platen generate excitation` writes it: column
/// names, columns, and its kind (`force` or `motion`).
#[derive(Debug, Clone, PartialEq)]
pub struct Excitation<'a> {
    /// Column names, `t_s` first.
    pub names: Vec<String>,
    /// The columns, in the order of `names`.
    pub columns: Vec<&'a [f64]>,
    /// `force` (a forward run's) or `motion` (an inverse run's, or a closed loop's command).
    pub kind: &'static str,
}

impl Excitation<'_> {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |c| c.len())
    }

    /// Whether it has no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Scenario {
    /// Reads, parses and validates the scenario at `path`, uniaxial or multi-axis, and loads
    /// every record it names. Nothing is simulated.
    ///
    /// # Errors
    /// Any [`ScenarioError`]: unreadable file, malformed JSON or unknown key (with its JSON
    /// path), invalid values (with their JSON path and what was expected), and every error of
    /// the records it references (with file and line).
    pub fn load(path: &Path) -> Result<Self> {
        Self::from_file(path, parse_json_file(path)?)
    }

    /// Validates a parsed scenario file; relative paths are resolved against `path`'s folder.
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn from_file(path: &Path, file: ScenarioFile) -> Result<Self> {
        if file.table.is_some() {
            Ok(Scenario::Table(TableScenario::from_file(path, &file)?))
        } else {
            Ok(Scenario::Platen(PlatenScenario::from_file(path, file)?))
        }
    }

    /// The scenario's name.
    pub fn name(&self) -> &str {
        match self {
            Scenario::Platen(s) => &s.name,
            Scenario::Table(s) => &s.name,
        }
    }

    /// Number of output samples its run gives.
    pub fn samples(&self) -> usize {
        match self {
            Scenario::Platen(s) => s.run.samples(),
            Scenario::Table(s) => s.output_t_s().len(),
        }
    }

    /// The scenario at another hold-down pressure, MPa (`platen simulate --pressure-mpa`): the
    /// uniaxial platen's model rebuilt from its preset ([`PlatenScenario::at_pressure`]).
    ///
    /// # Errors
    /// [`ScenarioError::PressureOfTable`] for a multi-axis table, whose struts carry their own
    /// pressures; the model's errors at that pressure.
    pub fn at_pressure_mpa(self, path: &Path, pressure_mpa: f64) -> Result<Self> {
        match self {
            Scenario::Platen(s) => s
                .at_pressure(pressure_mpa * 1e6)
                .map(Scenario::Platen)
                .map_err(|source| ScenarioError::Pressure {
                    path: path.to_owned(),
                    pressure_mpa,
                    source,
                }),
            Scenario::Table(_) => Err(ScenarioError::PressureOfTable {
                path: path.to_owned(),
            }),
        }
    }

    /// Runs it keeping every output column in memory, and summarises it (`path`: the file,
    /// as the summary names it).
    ///
    /// # Errors
    /// Every error of the run ([`PlatenScenario::run`], [`TableScenario::run_with_stats`]).
    pub fn run_at(&self, path: &Path) -> Result<RunResult> {
        match self {
            Scenario::Platen(s) => {
                let mut trajectory = Trajectory::with_capacity(s.run.samples());
                let output = s.run(&mut trajectory)?;
                let summary = RunSummary::new(path, s, &output, None);
                Ok(RunResult::Platen {
                    trajectory,
                    summary: Box::new(summary),
                })
            }
            Scenario::Table(s) => {
                let (run, stats) = s.run_with_stats()?;
                let summary = s.summary_with(&run, stats.as_ref(), None);
                Ok(RunResult::Table {
                    run,
                    summary: Box::new(summary),
                })
            }
        }
    }

    /// [`Scenario::run_at`], the summary naming the scenario by its name.
    ///
    /// # Errors
    /// As [`Scenario::run_at`].
    pub fn run(&self) -> Result<RunResult> {
        self.run_at(Path::new(self.name()))
    }

    /// Its excitation as `platen generate excitation` writes it: a force record (`t_s`,
    /// `force_n`; a multi-axis table's `{name}_force_n` per actuator) or a motion (`t_s`,
    /// `u_m`, `v_m_s`, `a_m_s2`; a table's six-DOF pose, rates and accelerations), a closed
    /// loop's being its command.
    pub fn excitation(&self) -> Excitation<'_> {
        match self {
            Scenario::Platen(s) => match &s.run {
                Run::Forward {
                    record, samples, ..
                } => Excitation {
                    names: vec!["t_s".into(), "force_n".into()],
                    columns: vec![&record.t_s()[..*samples], &record.force_n()[..*samples]],
                    kind: "force",
                },
                Run::Inverse { motion }
                | Run::ClosedLoop {
                    command: motion, ..
                } => Excitation {
                    names: ["t_s", "u_m", "v_m_s", "a_m_s2"].map(String::from).to_vec(),
                    columns: vec![motion.t_s(), motion.u_m(), motion.v_m_s(), motion.a_m_s2()],
                    kind: "motion",
                },
            },
            Scenario::Table(s) => {
                let (names, columns, kind) = s.excitation_columns();
                Excitation {
                    names,
                    columns,
                    kind,
                }
            }
        }
    }
}

/// A finished run held in memory: every output column and the summary ([`Scenario::run`],
/// [`simulate`]).
#[derive(Debug, Clone, PartialEq)]
// One is held per run, never in a collection: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum RunResult {
    /// A uniaxial platen's run.
    Platen {
        /// The time series: one value per output sample in each of the contract's columns.
        trajectory: Trajectory,
        /// The summary, as `platen simulate --json` prints it.
        summary: Box<RunSummary>,
    },
    /// A multi-axis table's run.
    Table {
        /// Its named columns.
        run: TableRun,
        /// The summary, as `platen simulate --json` prints it.
        summary: Box<TableSummary>,
    },
}

impl RunResult {
    /// The names of the output columns, in CSV order: for the uniaxial platen `t_s`, `u_m`,
    /// `v_m_s`, `a_m_s2`, `force_n`, `inertial_force_n`, `elastic_force_n`,
    /// `dissipative_force_n` (a specimen adds `base_shear_n`, `storey{i}_u_m`…,
    /// `storey{i}_a_m_s2`…; a closed loop its system's columns); for a table those of
    /// `docs/multi-axis.md`.
    pub fn columns(&self) -> Vec<&str> {
        match self {
            RunResult::Platen { trajectory, .. } => {
                let mut names = Trajectory::COLUMN_NAMES.to_vec();
                if let Some(sp) = &trajectory.specimen {
                    names.extend(sp.columns().into_iter().map(|(name, _)| name));
                }
                if trajectory.system.is_some() {
                    names.extend(platen_integrate::SystemColumns::NAMES);
                }
                names
            }
            RunResult::Table { run, .. } => run.columns.iter().map(|(n, _)| n.as_str()).collect(),
        }
    }

    /// The output column `name` (SI units), or `None` for a name that is not a column.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        match self {
            RunResult::Platen { trajectory, .. } => {
                match Trajectory::COLUMN_NAMES.iter().position(|c| *c == name) {
                    Some(j) => Some(trajectory.columns()[j]),
                    None => (trajectory.specimen.as_ref())
                        .and_then(|sp| sp.column(name))
                        .or_else(|| trajectory.system.as_ref()?.column(name)),
                }
            }
            RunResult::Table { run, .. } => run.column(name),
        }
    }

    /// Number of output samples.
    pub fn len(&self) -> usize {
        self.column("t_s").map_or(0, <[f64]>::len)
    }

    /// Whether the run has no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Its columns, by name in CSV order, taken out without a copy, and its summary.
    pub fn into_columns(self) -> (Vec<(String, Vec<f64>)>, Summary) {
        match self {
            RunResult::Platen {
                mut trajectory,
                summary,
            } => {
                let specimen = trajectory.specimen.take();
                let system = trajectory.system.take();
                let named = |names: &[&str], columns: Vec<Vec<f64>>| -> Vec<(String, Vec<f64>)> {
                    names.iter().map(|n| (*n).to_owned()).zip(columns).collect()
                };
                let mut columns =
                    named(&Trajectory::COLUMN_NAMES, trajectory.into_columns().into());
                if let Some(sp) = specimen {
                    let n = sp.storeys();
                    columns.push((SpecimenColumns::BASE_SHEAR_NAME.to_owned(), sp.base_shear_n));
                    columns.extend(named(&SpecimenColumns::STOREY_U_NAMES[..n], sp.u_m));
                    columns.extend(named(&SpecimenColumns::STOREY_A_NAMES[..n], sp.a_m_s2));
                    for (names, cols) in SpecimenColumns::HYSTERETIC_NAMES.iter().zip(sp.hysteretic)
                    {
                        let k = cols.len();
                        columns.extend(named(&names[..k], cols));
                    }
                }
                if let Some(sy) = system {
                    columns.extend(named(&SystemColumns::NAMES, sy.into_columns().into()));
                }
                (columns, Summary::Platen(summary))
            }
            RunResult::Table { run, summary } => (run.columns, Summary::Table(summary)),
        }
    }

    /// The summary.
    pub fn summary(&self) -> Summary {
        match self {
            RunResult::Platen { summary, .. } => Summary::Platen(summary.clone()),
            RunResult::Table { summary, .. } => Summary::Table(summary.clone()),
        }
    }
}

/// Loads the scenario at `path` (uniaxial or multi-axis), runs it keeping the whole time
/// series in memory, and summarises it: `platen simulate` as one library call.
///
/// # Errors
/// Every error of [`Scenario::load`] and [`Scenario::run_at`].
pub fn simulate(path: impl AsRef<Path>) -> Result<RunResult> {
    let path = path.as_ref();
    Scenario::load(path)?.run_at(path)
}
