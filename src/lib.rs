#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub use platen_compare as compare;
pub use platen_ident as ident;
pub use platen_integrate as integrate;
pub use platen_io as io;
pub use platen_model as model;
pub use platen_report as report;
pub use platen_scenario as scenario;
pub use platen_signal as signal;

/// Loads and runs a scenario file, keeping every column in memory.
pub use platen_scenario::simulate;
/// A finished run in memory: columns by name and the summary ([`simulate`]).
pub use platen_scenario::RunResult as Run;
/// The validated scenario: [`Scenario::load`] then [`Scenario::run`] into any sink.
pub use platen_scenario::Scenario;
