//! The error object a verb run with `--json` prints on stderr, one line, instead of the
//! `error: …` text:
//!
//! ```json
//! {"error": {"kind": "input", "exit_code": 3,
//!            "message": "`s.json`: integrator.step_s (line 3 column 21): invalid type: …",
//!            "file": "s.json", "field": "integrator.step_s (line 3 column 21)", "line": null}}
//! ```
//!
//! - `kind`: `usage` (exit 2: the command line), `input` (3: a file, scenario or parameter
//!   that cannot be used), `numerical` (4: the integration failed), `output` (5: an output
//!   could not be written);
//! - `exit_code`: the process's exit code (the same with or without `--json`);
//! - `message`: the text the plain form prints after `error: `;
//! - `file`: the file the error is about, where one is known, else null;
//! - `field`: the JSON path of a scenario field (with the line and column of a type error) or
//!   the name of a CSV column, else null (a JSON syntax error has no field);
//! - `line`: the 1-based line of a CSV file or of a JSON syntax error, else null.

use std::fmt;

use serde::Serialize;

use platen_compare::CompareError;
use platen_io::IoError;
use platen_report::ReportError;
use platen_scenario::ScenarioError;

/// The object printed: `{"error": {…}}`.
#[derive(Serialize)]
pub(crate) struct ErrorObject {
    error: ErrorDetail,
}

/// The error's fields, declared in the order they print (sorted, as every `--json` object).
#[derive(Serialize)]
struct ErrorDetail {
    exit_code: u8,
    field: Option<String>,
    file: Option<String>,
    kind: &'static str,
    line: Option<u64>,
    message: String,
}

impl fmt::Display for ErrorObject {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = serde_json::to_string(self).map_err(|_| fmt::Error)?;
        f.write_str(&text)
    }
}

/// The `kind` of an exit code.
fn kind(code: u8) -> &'static str {
    match code {
        2 => "usage",
        4 => "numerical",
        5 => "output",
        _ => "input",
    }
}

/// The error object of a usage error (the command line itself), exit code 2.
pub(crate) fn usage(message: &str) -> ErrorObject {
    ErrorObject {
        error: ErrorDetail {
            exit_code: 2,
            field: None,
            file: None,
            kind: kind(2),
            line: None,
            message: message.to_owned(),
        },
    }
}

/// The error object of `e`, which exits with `code`.
pub(crate) fn object(e: &anyhow::Error, code: u8) -> ErrorObject {
    let (file, field, line) = match io_error(e) {
        Some(io) => (
            Some(io.file().display().to_string()),
            io.field().map(str::to_owned),
            io.line(),
        ),
        None => (scenario_file(e), None, None),
    };
    ErrorObject {
        error: ErrorDetail {
            exit_code: code,
            field,
            file,
            kind: kind(code),
            line,
            message: format!("{e:#}"),
        },
    }
}

/// The file I/O error in `e`'s chain, looking through the transparent wrappers that hide it
/// from `chain()` (as [`crate::exit_code`] does).
fn io_error(e: &anyhow::Error) -> Option<&IoError> {
    e.chain().find_map(|cause| {
        let scenario = match cause.downcast_ref::<CompareError>() {
            Some(CompareError::Scenario(se)) => Some(se),
            Some(CompareError::Io(io)) => return Some(io),
            _ => cause.downcast_ref::<ScenarioError>(),
        };
        if let Some(ScenarioError::Io(io)) = scenario {
            return Some(io);
        }
        if let Some(ReportError::Write(io)) = cause.downcast_ref::<ReportError>() {
            return Some(io);
        }
        cause.downcast_ref::<IoError>()
    })
}

/// The record file a scenario error names.
fn scenario_file(e: &anyhow::Error) -> Option<String> {
    e.chain().find_map(|cause| {
        let se = match cause.downcast_ref::<CompareError>() {
            Some(CompareError::Scenario(se)) => se,
            _ => cause.downcast_ref::<ScenarioError>()?,
        };
        match se {
            ScenarioError::RecordTooShort { path, .. }
            | ScenarioError::RecordRejected { path, .. }
            | ScenarioError::NotAcceleration { path } => Some(path.display().to_string()),
            _ => None,
        }
    })
}
