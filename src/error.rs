//! One error type for a program that uses several of platen's crates: every crate's error
//! converts into [`Error`] with `?`, and its message is the crate's own.

/// Any of platen's errors, by the crate that raised it (the message is that crate's).
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Loading or validating a scenario.
    #[error(transparent)]
    Scenario(#[from] platen_scenario::ScenarioError),
    /// Reading or writing files (CSV, JSON, Parquet).
    #[error(transparent)]
    Io(#[from] platen_io::IoError),
    /// The platen model's parameters.
    #[error(transparent)]
    Model(#[from] platen_model::ModelError),
    /// The table system's parameters.
    #[error(transparent)]
    System(#[from] platen_system::SystemError),
    /// Signals: records, filters, derivatives.
    #[error(transparent)]
    Signal(#[from] platen_signal::SignalError),
    /// A run of an integrator.
    #[error(transparent)]
    Integrate(#[from] platen_integrate::IntegrateError),
    /// Identification.
    #[error(transparent)]
    Ident(#[from] platen_ident::IdentError),
    /// Reading records for identification.
    #[error(transparent)]
    Input(#[from] platen_app::InputError),
    /// Comparing a run with a recording.
    #[error(transparent)]
    Compare(#[from] platen_compare::CompareError),
    /// Planning a test.
    #[error(transparent)]
    Plan(#[from] platen_plan::PlanError),
    /// Reports and figures.
    #[error(transparent)]
    Report(#[from] platen_report::ReportError),
}

/// A result with platen's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
