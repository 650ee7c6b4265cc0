//! The validation context of one scenario file: where relative paths resolve and how an
//! invalid field is reported (file, JSON path, value, what was expected).

use std::path::{Path, PathBuf};

use platen_io::IoError;
use platen_model::ModelError;

use crate::error::{Result, ScenarioError};

/// The scenario file being validated.
pub(crate) struct Ctx<'a> {
    pub(crate) path: &'a Path,
}

impl Ctx<'_> {
    pub(crate) fn invalid(
        &self,
        json_path: &str,
        value: impl ToString,
        expected: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError::Io(IoError::InvalidField {
            path: self.path.to_owned(),
            json_path: json_path.to_owned(),
            value: value.to_string(),
            expected: expected.into(),
        })
    }

    pub(crate) fn resolve(&self, relative: &Path) -> PathBuf {
        match self.path.parent() {
            Some(dir) if relative.is_relative() => dir.join(relative),
            _ => relative.to_owned(),
        }
    }

    pub(crate) fn model_error(&self, section: &str, e: ModelError) -> ScenarioError {
        match e {
            ModelError::InvalidParameter {
                name: "hold_down_pressure_pa",
                value,
                expected,
            } => self.invalid("model.hold_down_pressure_mpa", value / 1e6, expected),
            ModelError::InvalidParameter {
                name,
                value,
                expected,
            } => self.invalid(&format!("{section}.{name}"), value, expected),
            other => self.invalid(section, "", other.to_string()),
        }
    }
}

pub(crate) fn check_positive(ctx: &Ctx, json_path: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ctx.invalid(json_path, value, "a finite number > 0"))
    }
}

pub(crate) fn check_finite(ctx: &Ctx, json_path: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ctx.invalid(json_path, value, "a finite number"))
    }
}
