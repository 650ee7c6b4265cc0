//! `platen.identify`: `platen identify [FILE…] [--manifest M] --json`: periodic tests by the
//! paper's hysteresis-loop method, any other record by the any-record method. The records are
//! read by [`platen_app`], the reading the CLI uses (column maps with `delay_s`,
//! manifests with kinds, pressures, `floors` and scenario entries).

use std::path::PathBuf;

use pyo3::prelude::*;

use platen_app::{read_records, InputError, RecordRequest};

use crate::error::{chain, detached, Fail, Kind};
use crate::{column_map, json_text};

/// A reading error as the CLI reports it (a file's or a scenario's own error keeps its kind).
fn input_fail(e: InputError) -> Fail {
    match e {
        InputError::Io(io) => io.into(),
        InputError::Scenario(se) => se.into(),
        other => Fail::of(Kind::Input, &other),
    }
}

/// Identifies the platen from the recorded test `files` and the manifest's entries
/// (`pressures_mpa`: none, one for all, or one per file): the object of `platen identify
/// --json`.
#[pyfunction]
#[pyo3(signature = (files, pressures_mpa, columns_path, columns_text, viscous_exponent, low_velocity_term, manifest=None))]
#[allow(clippy::too_many_arguments)]
pub fn identify(
    py: Python<'_>,
    files: Vec<PathBuf>,
    pressures_mpa: Vec<Option<f64>>,
    columns_path: Option<PathBuf>,
    columns_text: Option<String>,
    viscous_exponent: Option<f64>,
    low_velocity_term: bool,
    manifest: Option<PathBuf>,
) -> PyResult<String> {
    Ok(detached(py, move || {
        if let Some(a) = viscous_exponent.filter(|a| !(a.is_finite() && (0.0..=1.0).contains(a))) {
            return Err(Fail::input(format!(
                "viscous_exponent = {a}: expected an exponent in [0, 1]"
            )));
        }
        let request = RecordRequest {
            files,
            pressures_mpa,
            manifest,
            columns: column_map(columns_path.as_deref(), columns_text.as_deref())?,
        };
        let inputs = read_records(&request).map_err(input_fail)?;
        let failed = |e: platen_ident::IdentError| {
            Fail::new(
                Kind::Identification,
                format!("identification failed: {}", chain(&e)),
            )
        };
        let settings = platen_ident::Settings {
            viscous_exponent,
            low_velocity_term,
            ..platen_ident::Settings::default()
        }
        .build()
        .map_err(failed)?;
        let record_settings = platen_ident::RecordSettings {
            viscous_exponent,
            low_velocity_term,
            ..platen_ident::RecordSettings::default()
        }
        .build()
        .map_err(failed)?;
        // As `platen identify … --json`: each file by its data (or the manifest's `"kind":
        // "record"`), every file accounted for.
        let request = platen_ident::MethodRequest::Auto;
        let id = platen_ident::identify_any(
            &inputs.records,
            &inputs.declared_record(),
            request,
            &settings,
            &record_settings,
        )
        .map_err(failed)?;
        json_text(&id.output(&inputs.records, &inputs.files(), request))
    })?)
}
