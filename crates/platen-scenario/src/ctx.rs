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
        // A number far from 1 as `1e300`, not three hundred digits.
        let mut value = value.to_string();
        if value.len() > 17 {
            if let Ok(v) = value.parse::<f64>() {
                value = format!("{v:e}");
            }
        }
        // A lower layer's sentence ("step_s = 0 is invalid: expected a finite number > 0")
        // keeps only what it expects: the field and value are said once, here.
        let mut expected = expected.into();
        if let Some(at) = expected.rfind(": expected ") {
            expected.drain(..at + ": expected ".len());
        }
        ScenarioError::Io(IoError::InvalidField {
            path: self.path.to_owned(),
            json_path: json_path.to_owned(),
            value,
            expected,
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

/// The value at `json_path` (`a.b[2].c`) of `value`, as compact JSON (for messages).
pub(crate) fn value_at(value: &serde_json::Value, json_path: &str) -> String {
    let pointer: String = json_path
        .split('.')
        .flat_map(|part| {
            let mut pieces = part.split('[');
            let key = pieces.next().unwrap_or_default().to_owned();
            std::iter::once(key).chain(pieces.map(|p| p.trim_end_matches(']').to_owned()))
        })
        .map(|p| format!("/{p}"))
        .collect();
    value
        .pointer(&pointer)
        .map_or_else(|| "(absent)".to_owned(), ToString::to_string)
}
