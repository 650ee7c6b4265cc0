//! Scenario files for `platen`: validated, and the executor that runs them, for every table.
//!
//! * [`Scenario::load`]: the one entry. It reads a scenario file and validates it as what it
//!   describes — the uniaxial platen of the paper ([`PlatenScenario`]) or a multi-axis table
//!   ([`multi_axis::TableScenario`], a file with `table`) — and loads its records before
//!   anything is simulated; [`Scenario::run`] runs either in memory ([`RunResult`]),
//!   [`Scenario::excitation`] is what it is driven by, [`ScenarioRig::load`] what it
//!   describes without its run. Every front end goes through these.
//! * [`scenario`]: the scenario JSON format: for the platen a [`Rig`] (what the table is:
//!   model, limits, table system, specimen) and a [`Run`] (what it does: [`Run::Forward`]
//!   from a force, [`Run::Inverse`] from a motion, [`Run::ClosedLoop`] from a command);
//!   [`PlatenScenario::run`] streams its samples into any sink (CLI, sweep, bench, Python);
//! * [`multi_axis`]: the `table` key of a six-DOF table, organised by concern (file format,
//!   building, excitation, the LHPOST6 preset, running, summary, description);
//! * [`Rig::load`], [`LoadedRig::load`]: a scenario file's rig without a run (no excitation
//!   needed), for a planner's own commands;
//! * [`PlatenScenario::from_arrays`]: the same format with the records given in memory
//!   (Python's `platen.forward` and `platen.inverse`).
//!
//! # Conventions
//!
//! SI units inside; the unit is in every column and key name (`t_s`, `u_m`, `v_m_s`,
//! `a_m_s2`, `force_n`, `hold_down_pressure_mpa`). Errors name the file and the line (CSV) or
//! the JSON path (scenario), the value, and what was expected.

#![warn(missing_docs)]

mod arrays;
pub mod catalog;
mod ctx;
pub mod describe;
mod describe_system;
mod entry;
pub mod error;
mod excitation;
mod execute;
pub mod file;
pub mod generate;
pub mod loop_budget;
mod model;
pub mod multi_axis;
pub mod recorded;
mod rig;
pub mod sampling;
pub mod scenario;
mod specimen;
mod summary;
pub mod sweep;
pub mod system;
mod system_file;
mod table_file;
pub mod units;

pub use arrays::Arrays;
pub use describe::describe_model;
pub use entry::{simulate, Excitation, RunResult, Scenario, ScenarioRig, Summary};
pub use error::{Result, ScenarioError};
pub use execute::{CsvSink, LoopOutput, RunOutput, Tracking};
pub use model::{Model, ModelKey, ModelOverrides};
/// Column maps are part of the scenario format (`excitation.columns`).
pub use platen_io::columns;
pub use rig::{LoadedRig, LoopSettings, Rig};
pub use scenario::{PlatenScenario, Run};
pub use summary::{
    AxisTracking, EnergySummary, ExceedanceSummary, ForwardSummary, LimitCheck, LimitsSummary,
    LoopMargins, RunSummary, SolverSummary, SpecimenSummary, StoreySummary,
};
pub use system::TableSystemSpec;
