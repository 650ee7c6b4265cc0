//! `platen.identify`: `platen identify FILE… --json` on recorded test files: periodic tests
//! by the paper's hysteresis-loop method, any other record by the any-record method.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;

use platen_ident::TestRecord;
use platen_io::columns::ColumnMap;
use platen_scenario::sampling::uniform_step_s;

use crate::error::{chain, detached, Fail, Kind};
use crate::{column_map, json_text};

/// Reads one recorded test: `t_s`, `u_m`, `a_m_s2`, `force_n` and, when present, `v_m_s`,
/// through `columns`, uniformly sampled; named by its path as the CLI names it.
fn read_record(
    path: &Path,
    columns: &ColumnMap,
    pressure_mpa: Option<f64>,
) -> Result<TestRecord, Fail> {
    let mut table = columns.read_table(path, &["t_s", "u_m", "a_m_s2", "force_n"], &["v_m_s"])?;
    let mut take = |c: &str| table.take_column(c);
    let (t, u, a, f, v) = (
        take("t_s"),
        take("u_m"),
        take("a_m_s2"),
        take("force_n"),
        take("v_m_s"),
    );
    let (Some(t), Some(u), Some(a), Some(f)) = (t, u, a, f) else {
        return Err(Fail::new(
            Kind::Internal,
            "internal error: a required column was not read",
        ));
    };
    let dt = uniform_step_s(path, &t)?;
    let located =
        |e: platen_ident::IdentError| Fail::input(format!("`{}`: {}", path.display(), chain(&e)));
    let mut record =
        TestRecord::from_rate(path.display().to_string(), 1.0 / dt, u, a, f).map_err(located)?;
    if let Some(v) = v {
        record = record.with_velocity(v).map_err(located)?;
    }
    if let Some(p) = pressure_mpa {
        record = record.with_pressure_pa(p * 1e6).map_err(located)?;
    }
    Ok(record)
}

/// Identifies the platen from the recorded test `files` (one hold-down pressure, or none,
/// per file): the object of `platen identify --json`.
#[pyfunction]
#[pyo3(signature = (files, pressures_mpa, columns_path, columns_text, viscous_exponent, low_velocity_term))]
pub fn identify(
    py: Python<'_>,
    files: Vec<PathBuf>,
    pressures_mpa: Vec<Option<f64>>,
    columns_path: Option<PathBuf>,
    columns_text: Option<String>,
    viscous_exponent: Option<f64>,
    low_velocity_term: bool,
) -> PyResult<String> {
    Ok(detached(py, move || {
        if files.is_empty() {
            return Err(Fail::input("files: no test files: give recorded CSV files"));
        }
        if pressures_mpa.len() != files.len() {
            return Err(Fail::new(
                Kind::Internal,
                "internal error: one pressure per file expected",
            ));
        }
        if let Some(e) = pressures_mpa
            .iter()
            .flatten()
            .find_map(|&p| platen_scenario::units::check_pressure_mpa(p).err())
        {
            return Err(Fail::input(format!("pressure_mpa = {e}")));
        }
        if let Some(a) = viscous_exponent.filter(|a| !(a.is_finite() && (0.0..=1.0).contains(a))) {
            return Err(Fail::input(format!(
                "viscous_exponent = {a}: expected an exponent in [0, 1]"
            )));
        }
        let columns = column_map(columns_path.as_deref(), columns_text.as_deref())?;
        let records = files
            .iter()
            .zip(&pressures_mpa)
            .map(|(path, p)| read_record(path, &columns, *p))
            .collect::<Result<Vec<_>, Fail>>()?;
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
        // As `platen identify FILE… --json`: each file by its data, every file accounted for.
        let request = platen_ident::MethodRequest::Auto;
        let declared = vec![false; records.len()];
        let id =
            platen_ident::identify_any(&records, &declared, request, &settings, &record_settings)
                .map_err(failed)?;
        let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
        json_text(&id.output(&records, &names, request))
    })?)
}
