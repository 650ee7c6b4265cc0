//! Why a table system was rejected.

/// A rejected table-system parameter, named by its path inside `table_system`.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SystemError {
    /// A value that is non-finite or outside its physical range.
    #[error("`{path}` = {value} is invalid: expected {expected}")]
    Invalid {
        /// Path of the value inside `table_system` (`actuator.cap_side_area_m2`).
        path: &'static str,
        /// The rejected value.
        value: f64,
        /// What a valid value looks like.
        expected: String,
    },
    /// A rejected value of one actuator of a multi-axis table (its index in the table).
    #[error("actuator {index}: {source}")]
    OfActuator {
        /// The actuator's index.
        index: usize,
        /// What was wrong with it.
        source: Box<SystemError>,
    },
    /// A rejected gain of one DOF's loop of a multi-axis controller.
    #[error("DOF {dof}: {source}")]
    OfDof {
        /// The DOF's name (`x`, `roll`, …).
        dof: &'static str,
        /// What was wrong with its gains.
        source: Box<SystemError>,
    },
    /// Parts of a multi-axis table that do not fit together (a table, its hydraulics and its
    /// controller with different actuators or free DOFs).
    #[error("{what} do not match: {found}, where {expected} was expected")]
    Mismatch {
        /// What differs (`actuators of the hydraulics and the table`, …).
        what: &'static str,
        /// What was found.
        found: String,
        /// What was expected.
        expected: String,
    },
    /// An unknown preset name.
    #[error("unknown table-system preset `{name}`: expected one of {known}")]
    UnknownPreset {
        /// The name that was asked for.
        name: String,
        /// The names that exist.
        known: &'static str,
    },
}

/// Result alias of this crate.
pub type Result<T, E = SystemError> = std::result::Result<T, E>;

pub(crate) fn invalid(path: &'static str, value: f64, expected: impl Into<String>) -> SystemError {
    SystemError::Invalid {
        path,
        value,
        expected: expected.into(),
    }
}

/// `value` finite and `> 0`.
pub(crate) fn positive(path: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(path, value, "a finite number > 0"))
    }
}

/// `value` finite and `≥ 0`.
pub(crate) fn non_negative(path: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(path, value, "a finite number ≥ 0"))
    }
}
