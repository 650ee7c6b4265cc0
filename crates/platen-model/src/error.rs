//! Errors raised when model parameters are built.

/// Why a set of model parameters was rejected.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter is non-finite or outside its physical range.
    #[error("parameter `{name}` = {value} is invalid: expected {expected}")]
    InvalidParameter {
        /// Name of the parameter, as in the contract (SI unit in the name).
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// What a valid value looks like.
        expected: &'static str,
    },
    /// A preset name that does not exist.
    #[error("unknown preset `{name}`: expected one of {known}")]
    UnknownPreset {
        /// The name that was asked for.
        name: String,
        /// The preset names that exist, comma separated.
        known: &'static str,
    },
    /// A storey of a specimen with an invalid value.
    #[error("storey {} (from the bottom): {source}", index + 1)]
    InvalidStorey {
        /// Zero-based index of the storey, bottom first.
        index: usize,
        /// What is wrong with it.
        source: Box<ModelError>,
    },
    /// A parameter name that the form does not have.
    #[error("unknown {form} parameter; expected one of {known}")]
    UnknownParameter {
        /// The form of the model (`"identified"` or `"full"`).
        form: &'static str,
        /// The name that was asked for.
        name: String,
        /// The names that exist, comma separated.
        known: String,
    },
    /// A value of a multi-axis table out of its range; `path` is its place in the scenario's
    /// `table` (for example `actuators[2].pad.axis`).
    #[error("table.{path}: expected {expected}")]
    InvalidTable {
        /// Where the value is, as a JSON path under `table`.
        path: String,
        /// What a valid value looks like.
        expected: String,
    },
    /// The actuators of a multi-axis table cannot move a DOF that is not held.
    #[error(
        "table: no combination of the actuators moves the platen in `{dof}`, which is not held \
         (hold it in `held_dofs` or add an actuator that acts on it)"
    )]
    UncontrolledDof {
        /// The DOF (contract name) that dominates the direction nothing pushes.
        dof: &'static str,
    },
}

/// Result alias of this crate.
pub type Result<T, E = ModelError> = std::result::Result<T, E>;

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::InvalidParameter {
            name,
            value,
            expected: "a finite number > 0",
        })
    }
}

/// Checks that `value` is finite and `>= 0`.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ModelError::InvalidParameter {
            name,
            value,
            expected: "a finite number >= 0",
        })
    }
}

/// Checks that `value` is finite (any sign).
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ModelError::InvalidParameter {
            name,
            value,
            expected: "a finite number",
        })
    }
}

/// Checks that an exponent lies in `[0, 1]`.
pub(crate) fn unit_exponent(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(ModelError::InvalidParameter {
            name,
            value,
            expected: "an exponent in [0, 1]",
        })
    }
}
