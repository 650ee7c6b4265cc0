//! Errors across the boundary: every library error becomes one Python exception,
//! `platen._platen.Failure(kind, message)`, that the `platen` package re-raises as its public
//! class for `kind` (`platen.ScenarioError`, a `ValueError`, for bad input, …). The message
//! is the CLI's: the error and its causes joined by `": "` (what `platen` prints after
//! `error: `). A panic is caught and reported as kind `internal`, never unwound into Python.

use std::error::Error;
use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::exceptions::PyException;
use pyo3::prelude::*;

use platen_compare::CompareError;
use platen_integrate::IntegrateError;
use platen_io::IoError;
use platen_scenario::ScenarioError;

pyo3::create_exception!(
    _platen,
    Failure,
    PyException,
    "A failure inside platen: args are (kind, message); the `platen` package re-raises it as its public exception class for `kind`."
);

/// What went wrong, as the CLI's exit codes tell it apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An input that cannot be used: a scenario, record, array or parameter (exit code 3).
    Input,
    /// A run that failed numerically (exit code 4).
    Numerical,
    /// An output that could not be written (exit code 5).
    Output,
    /// Test records from which nothing can be identified (exit code 3).
    Identification,
    /// A bug: a panic inside platen.
    Internal,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Input => "input",
            Kind::Numerical => "numerical",
            Kind::Output => "output",
            Kind::Identification => "identification",
            Kind::Internal => "internal",
        }
    }
}

/// A failure on its way to Python: its kind and the CLI's message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fail {
    /// What went wrong.
    pub kind: Kind,
    /// The message, as the CLI prints it after `error: `.
    pub message: String,
}

impl Fail {
    /// A failure of `kind` with `message`.
    pub fn new(kind: Kind, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
        }
    }

    /// An input failure with `message`.
    pub fn input(message: impl Into<String>) -> Self {
        Self::new(Kind::Input, message)
    }

    /// `e` and its causes as the CLI reports them.
    pub fn of(kind: Kind, e: &(dyn Error + 'static)) -> Self {
        Self::new(kind, chain(e))
    }
}

impl From<Fail> for PyErr {
    fn from(f: Fail) -> PyErr {
        Failure::new_err((f.kind.name(), f.message))
    }
}

/// The error and its causes joined by `": "`, as `anyhow`'s `{:#}` prints them in the CLI.
pub fn chain(e: &(dyn Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

fn integrate_kind(e: &IntegrateError) -> Kind {
    if e.stop_reason().is_some() {
        Kind::Numerical
    } else {
        Kind::Input
    }
}

fn io_kind(e: &IoError) -> Kind {
    if e.is_output_failure() {
        Kind::Output
    } else {
        Kind::Input
    }
}

impl From<ScenarioError> for Fail {
    fn from(e: ScenarioError) -> Self {
        let kind = match &e {
            ScenarioError::Run(ie) => integrate_kind(ie),
            ScenarioError::Io(io) => io_kind(io),
            _ => Kind::Input,
        };
        Fail::of(kind, &e)
    }
}

impl From<IoError> for Fail {
    fn from(e: IoError) -> Self {
        Fail::of(io_kind(&e), &e)
    }
}

impl From<CompareError> for Fail {
    fn from(e: CompareError) -> Self {
        match e {
            CompareError::Scenario(se) => se.into(),
            CompareError::Io(io) => io.into(),
            other => Fail::of(Kind::Input, &other),
        }
    }
}

impl From<platen_model::ModelError> for Fail {
    fn from(e: platen_model::ModelError) -> Self {
        Fail::of(Kind::Input, &e)
    }
}

/// Runs `work` with the GIL released, turning a panic into an [`Kind::Internal`] failure.
pub fn detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T, Fail> + Send,
) -> Result<T, Fail> {
    py.detach(|| match catch_unwind(AssertUnwindSafe(work)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "(no message)".to_owned());
            Err(Fail::new(
                Kind::Internal,
                format!("internal error in platen (please report it): {what}"),
            ))
        }
    })
}
