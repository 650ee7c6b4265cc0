//! Scenario files, time-series CSV readers and writers for `platen`.

pub mod csv_io;
pub mod error;

pub use error::{Result, ScenarioError};
