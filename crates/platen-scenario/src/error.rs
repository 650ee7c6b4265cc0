//! Errors of the `platen-scenario` crate.
//!
//! Every variant carries what a user needs to fix the input: the file (shown with
//! [`Path::display`](std::path::Path::display)), the line (1-based as a text editor shows it; the CSV header is line 1),
//! the column name, the offending value and what was expected. The enum is `#[non_exhaustive]`
//! so that variants can be added without breaking callers.
//!
//! Underlying I/O errors are attached as [`std::error::Error::source`] and are *not* repeated
//! in the `Display` text, so that error-chain printers (`anyhow`'s `{:#}` / `{:?}`) show each
//! cause once.

use std::path::PathBuf;

use platen_integrate::IntegrateError;
use platen_io::IoError;

/// Result type of this crate, defaulting to [`ScenarioError`].
pub type Result<T, E = ScenarioError> = std::result::Result<T, E>;

/// Everything that can go wrong while loading or running a scenario.
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// A file the scenario reads (the scenario itself, a record, a column map) cannot be read
    /// or parsed, a scenario field has a value that cannot be used
    /// ([`IoError::InvalidField`], with its JSON path), or an output cannot be written.
    #[error(transparent)]
    Io(#[from] IoError),

    /// A scenario of a multi-axis table (with a `table`) where the uniaxial platen's scenario
    /// was asked for: it runs through [`crate::multi_axis::TableScenario`].
    #[error("`{}`: this scenario has a multi-axis `table`: `platen simulate` and `platen model` run it; this command takes the uniaxial platen's scenarios only, for now", path.display())]
    MultiAxis {
        /// The scenario file.
        path: PathBuf,
    },

    /// The model at another hold-down pressure (`platen simulate --pressure-mpa`) is invalid.
    #[error("`{}`: the model at --pressure-mpa {pressure_mpa}", path.display())]
    Pressure {
        /// The scenario file.
        path: PathBuf,
        /// The pressure asked for, MPa.
        pressure_mpa: f64,
        /// Why the model is invalid there.
        #[source]
        source: platen_model::ModelError,
    },

    /// A hold-down pressure was asked of a multi-axis table, whose struts carry their own.
    #[error("`{}`: --pressure-mpa sets the uniaxial platen's hold-down pressure; a multi-axis table's struts carry theirs in `table.hold_down_struts[].pressure_pa`", path.display())]
    PressureOfTable {
        /// The scenario file.
        path: PathBuf,
    },

    /// A multi-axis run failed (the actuators lose rank at a pose of the motion).
    #[error("the multi-axis run failed; no output was written")]
    TableRun(#[source] IntegrateError),

    /// A multi-axis closed loop whose linearisation is unstable failed in its run (it
    /// diverged): the verdict says why.
    #[error("the multi-axis closed loop is unstable (linearised at neutral, {verdict}; `platen model --scenario` shows each DOF's margins): its run failed; no output was written")]
    TableLoopUnstable {
        /// The linearised loop's verdict: its growing poles and the DOF that moves most.
        verdict: String,
        /// How the run failed.
        #[source]
        source: IntegrateError,
    },

    /// A record is shorter than the scenario's `duration_s`.
    #[error("`{}`: record spans {span_s} s{} but the scenario's duration_s is {duration_s} s", path.display(), samples.map_or(String::new(), |n| format!(" ({n} samples)")))]
    RecordTooShort {
        /// The record file.
        path: PathBuf,
        /// The record's span, s.
        span_s: f64,
        /// The record's number of samples, where the message states it.
        samples: Option<usize>,
        /// The scenario's duration, s.
        duration_s: f64,
    },

    /// A record cannot drive a run (the integrator's checks reject it).
    #[error("`{}`: {cause}", path.display())]
    RecordRejected {
        /// The record file.
        path: PathBuf,
        /// Why the integrator rejects it.
        cause: IntegrateError,
    },

    /// A `ground_motion` record holds velocity or displacement, not acceleration.
    #[error("`{}`: ground_motion needs an acceleration record (.AT2); this one holds velocity or displacement", path.display())]
    NotAcceleration {
        /// The record file.
        path: PathBuf,
    },

    /// A closed-loop run was given to a rig without a `table_system` (a [`crate::PlatenScenario`]
    /// or [`crate::Rig`] built by hand: a scenario file with a motion and no table system is
    /// an inverse run).
    #[error("a closed-loop run needs a rig with a table_system")]
    NoTableSystem,

    /// A forward run failed numerically (or its record could not serve it); the error names
    /// the time. Nothing was written.
    #[error("forward run failed; no output was written")]
    Run(#[source] IntegrateError),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error and its causes as the CLI (anyhow's `{:#}`) and Python print them.
    fn chain(e: &(dyn std::error::Error + 'static)) -> String {
        let mut parts = vec![e.to_string()];
        let mut cause = e.source();
        while let Some(c) = cause {
            parts.push(c.to_string());
            cause = c.source();
        }
        parts.join(": ")
    }

    /// A failed multi-axis run names its cause once along the chain (its message used to
    /// carry the cause that its source gives again: "… failed: numerical failure …: numerical
    /// failure …"), as the uniaxial run's does.
    #[test]
    fn a_failed_run_names_its_cause_once() {
        let cause = IntegrateError::EventLoopStalled {
            t_s: 37.5,
            events: 4097,
        };
        let cause_text = cause.to_string();
        for e in [
            ScenarioError::TableRun(cause.clone()),
            ScenarioError::Run(cause),
        ] {
            let text = chain(&e);
            assert_eq!(text.matches(&cause_text).count(), 1, "{text}");
        }
    }
}
