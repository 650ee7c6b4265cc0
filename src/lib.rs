#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub use platen_app as app;
pub use platen_compare as compare;
pub use platen_ident as ident;
pub use platen_integrate as integrate;
pub use platen_io as io;
pub use platen_model as model;
pub use platen_plan as plan;
pub use platen_report as report;
pub use platen_scenario as scenario;
pub use platen_signal as signal;
pub use platen_system as system;

mod error;
pub mod prelude;

pub use error::{Error, Result};
/// Loads and runs a scenario file, keeping every column in memory.
pub use platen_scenario::simulate;
/// A finished run in memory, of either table: columns by name and the summary ([`simulate`]).
pub use platen_scenario::RunResult;
/// The old name of [`RunResult`], which read as [`scenario::Run`] (what a scenario runs).
#[deprecated(note = "use platen::RunResult: platen::scenario::Run is what a scenario runs")]
pub type Run = platen_scenario::RunResult;
/// A validated scenario of any table: [`Scenario::load`] then [`Scenario::run`]; the uniaxial
/// platen's ([`PlatenScenario`]) streams into any sink.
pub use platen_scenario::{PlatenScenario, Scenario};

/// The pages under `docs/`, so that `cargo test --doc` compiles and runs their Rust examples
/// as it does the README's (this crate's documentation).
#[cfg(doctest)]
pub mod docs {
    #[doc = include_str!("../docs/library.md")]
    pub struct Library;
    #[doc = include_str!("../docs/cli.md")]
    pub struct Cli;
    #[doc = include_str!("../docs/compare.md")]
    pub struct Compare;
    #[doc = include_str!("../docs/identification.md")]
    pub struct Identification;
    #[doc = include_str!("../docs/records-and-signals.md")]
    pub struct RecordsAndSignals;
    #[doc = include_str!("../docs/model.md")]
    pub struct Model;
    #[doc = include_str!("../docs/accuracy.md")]
    pub struct Accuracy;
    #[doc = include_str!("../docs/performance.md")]
    pub struct Performance;
    #[doc = include_str!("../docs/python.md")]
    pub struct Python;
}
