//! Errors of the `platen-plan` crate.
//!
//! An infeasible target is **not** an error: it is an answer ([`crate::Feasibility`]). Errors
//! are inputs that cannot be planned (a target too short, not finite, not uniformly sampled;
//! a scenario without a `table_system`), settings out of
//! range, and closed-loop runs that fail numerically.

use std::path::PathBuf;

use platen_integrate::IntegrateError;
use platen_io::IoError;
use platen_scenario::ScenarioError;
use platen_signal::SignalError;

/// Result type of this crate, defaulting to [`PlanError`].
pub type Result<T, E = PlanError> = std::result::Result<T, E>;

/// Why a plan could not be made.
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The scenario cannot be loaded or validated (its file, JSON path and value).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),

    /// A file cannot be read or written: the target CSV (with its line and column), the drive.
    #[error(transparent)]
    Io(#[from] IoError),

    /// A target given in memory is unusable: `index` is the 0-based sample.
    #[error("target `{origin}`: {message}")]
    Target {
        /// Where the target comes from (a file, or the caller that gave the arrays).
        origin: String,
        /// What is wrong, with the sample's index.
        message: String,
    },

    /// The scenario has no `table_system`: there is no loop to plan a drive for.
    #[error(
        "`{}`: no `table_system`: planning needs the loop around the platen (add \
         \"table_system\": {{\"preset\": \"lhpost-2008\"}} or an explicit system)",
        scenario.display()
    )]
    NoTableSystem {
        /// The scenario.
        scenario: PathBuf,
    },

    /// A planning setting is out of range.
    #[error("setting `{name}` = {value} is invalid: expected {expected}")]
    Setting {
        /// The setting's name (SI unit in the name).
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// What a valid value looks like.
        expected: &'static str,
    },

    /// The white-noise measurement of the loop's response cannot be made (its band, RMS or
    /// duration).
    #[error("the white-noise measurement of the loop's response: {0}")]
    Measurement(String),

    /// A signal-processing plan was refused (a band or rate the tools cannot use).
    #[error(transparent)]
    Signal(#[from] SignalError),

    /// A closed-loop run failed numerically (or its command was refused); the cause names
    /// the time.
    #[error("the closed-loop run of {what} failed")]
    Run {
        /// Which run (`the target`, `iteration 3`, `the white-noise measurement`).
        what: String,
        /// Why.
        #[source]
        source: IntegrateError,
    },
}

impl PlanError {
    /// The error as a file error when it is one, so that callers that report errors by file,
    /// line and field (the CLI's exit codes and JSON error object) see it as such: a file that
    /// cannot be read or written and a scenario without a `table_system` (a missing field,
    /// [`IoError::InvalidField`]). Any other error is returned as it is.
    pub fn into_io(self) -> std::result::Result<IoError, Self> {
        match self {
            PlanError::Io(io) => Ok(io),
            PlanError::NoTableSystem { scenario } => Ok(IoError::InvalidField {
                path: scenario,
                json_path: "table_system".to_owned(),
                value: "(missing)".to_owned(),
                expected: "the loop around the platen, {\"preset\": \"lhpost-2008\"} or an \
                           explicit system: planning runs the closed loop"
                    .to_owned(),
            }),
            other => Err(other),
        }
    }
}

/// `value` if it is finite and `ok`, else the setting's error.
pub(crate) fn check_setting(
    name: &'static str,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<f64> {
    if value.is_finite() && ok {
        Ok(value)
    } else {
        Err(PlanError::Setting {
            name,
            value,
            expected,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use platen_io::IoError;

    use super::PlanError;

    /// A scenario without a loop is a missing field;
    /// other errors stay plan errors.
    #[test]
    fn file_errors_become_io_errors_and_the_others_stay() {
        let bare = PlanError::NoTableSystem {
            scenario: PathBuf::from("s.json"),
        };
        assert!(matches!(
            bare.into_io(),
            Ok(IoError::InvalidField { json_path, .. }) if json_path == "table_system"
        ));
        let setting = PlanError::Setting {
            name: "gain",
            value: 3.0,
            expected: "(0, 2)",
        };
        assert!(matches!(
            setting.into_io(),
            Err(PlanError::Setting { name: "gain", .. })
        ));
    }
}
