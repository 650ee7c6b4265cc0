//! The inputs of a table-system identification (`platen identify --system`): the closed-loop
//! records read through a column map, which of them are fitted and which held out, and the
//! table's base geometry (`--base`). [`read_system_inputs`] does all three;
//! [`platen_ident::system::identify_system`] fits what it returns.
//!
//! **Held out.** With one record, it is fitted. With two or more, every record but the last
//! is fitted and the last is held out: the identified loop is judged on it (and on the
//! fitted ones), and its command drives the runnable scenario the identification prints
//! ([`SystemInputs::commanding`]).
//!
//! ```no_run
//! use platen_app::system::{read_system_inputs, SystemRequest};
//!
//! let inputs = read_system_inputs(&SystemRequest {
//!     files: vec!["wn.csv".into(), "eq1.csv".into(), "eq4.csv".into()],
//!     ..SystemRequest::default()
//! })?;
//! assert_eq!(inputs.fit, [true, true, false]);
//! assert_eq!(inputs.commanding, 2);
//! # Ok::<(), platen_app::InputError>(())
//! ```

use std::path::{Path, PathBuf};

use platen_ident::system::SystemRecord;
use platen_io::columns::ColumnMap;
use platen_scenario::PlatenScenario;
use platen_system::TableSystem;

use crate::error::InputError;

/// What a table-system identification reads: closed-loop records, a column map and a base.
#[derive(Debug, Clone, Default)]
pub struct SystemRequest {
    /// The closed-loop records (CSV), in order: with two or more, the last is held out.
    pub files: Vec<PathBuf>,
    /// How the files' channels map to platen's columns (default: platen's own names).
    pub columns: ColumnMap,
    /// The table's geometry from its drawings (`--base`): a scenario with a `table_system`,
    /// or a `table_system` object (default: none, the plant in ratios to the actuator area).
    pub base: Option<PathBuf>,
}

/// The records of a table-system identification, which are fitted, and the base.
#[derive(Debug, Clone)]
pub struct SystemInputs {
    /// The files read, as given (one per record).
    pub files: Vec<PathBuf>,
    /// The records, in the order of the files.
    pub records: Vec<SystemRecord>,
    /// Whether each record is fitted ([`fitted`]); the others are held out and judged.
    pub fit: Vec<bool>,
    /// The record whose command drives the identified scenario: the last (the held-out one
    /// when there are two or more).
    pub commanding: usize,
    /// The base's table system, if a base was given.
    pub base: Option<TableSystem>,
    /// The base's stroke limit, m, if it gives one.
    pub base_stroke_m: Option<f64>,
}

impl SystemInputs {
    /// The file of the [`commanding`](Self::commanding) record, made absolute (as given when
    /// it cannot be): what the identified scenario's `motion_csv` names.
    pub fn commanding_path(&self) -> PathBuf {
        let file = &self.files[self.commanding];
        std::fs::canonicalize(file).unwrap_or_else(|_| file.clone())
    }
}

/// Which of `records` records are fitted: every one when there is one, else all but the
/// last, which is held out.
pub fn fitted(records: usize) -> Vec<bool> {
    (0..records)
        .map(|i| records == 1 || i + 1 < records)
        .collect()
}

/// Reads a table-system identification's inputs: the records ([`read_system_records`]), then
/// the base ([`read_base_system`], validated against the first record), and marks the
/// records to fit ([`fitted`]).
///
/// # Errors
/// [`InputError::NoSystemFiles`] without files, and the errors of [`read_system_records`]
/// and [`read_base_system`].
pub fn read_system_inputs(request: &SystemRequest) -> Result<SystemInputs, InputError> {
    let files = &request.files;
    if files.is_empty() {
        return Err(InputError::NoSystemFiles);
    }
    let records = read_system_records(files, &request.columns)?;
    let (base, base_stroke_m) = match &request.base {
        Some(path) => {
            let (system, stroke) = read_base_system(path, &files[0], &request.columns)?;
            (Some(system), stroke)
        }
        None => (None, None),
    };
    Ok(SystemInputs {
        files: files.clone(),
        fit: fitted(records.len()),
        commanding: records.len() - 1,
        records,
        base,
        base_stroke_m,
    })
}

/// Reads the closed-loop records of a table-system identification
/// ([`platen_ident::system::identify_system`]): `t_s`, `command_u_m` and `u_m`, and where
/// recorded `drive`, `delta_p_pa`, `cap_pressure_pa`, `rod_pressure_pa`, `a_m_s2` and the
/// storeys' `storey{i}_a_m_s2`, through `columns`; each named by its path.
///
/// # Errors
/// [`InputError::SystemColumns`] (with the file's error) for a file that cannot be read or
/// lacks a required column.
pub fn read_system_records(
    files: &[PathBuf],
    columns: &ColumnMap,
) -> Result<Vec<SystemRecord>, InputError> {
    let storey_names: Vec<String> = (1..=platen_model::Specimen::MAX_STOREYS)
        .map(|i| format!("storey{i}_a_m_s2"))
        .collect();
    let mut optional = vec![
        "drive",
        "delta_p_pa",
        "a_m_s2",
        "cap_pressure_pa",
        "rod_pressure_pa",
    ];
    optional.extend(storey_names.iter().map(String::as_str));
    let mut records = Vec::with_capacity(files.len());
    for path in files {
        let mut t = columns
            .read_table(path, &["t_s", "command_u_m", "u_m"], &optional)
            .map_err(|source| InputError::SystemColumns { source })?;
        let storeys = storey_names
            .iter()
            .map_while(|c| t.take_column(c))
            .collect();
        let mut take = |c: &str| t.take_column(c);
        records.push(SystemRecord {
            name: path.display().to_string(),
            t_s: take("t_s").unwrap_or_default(),
            command_u_m: take("command_u_m").unwrap_or_default(),
            u_m: take("u_m").unwrap_or_default(),
            drive: take("drive"),
            delta_p_pa: take("delta_p_pa"),
            a_m_s2: take("a_m_s2"),
            cap_pressure_pa: take("cap_pressure_pa"),
            rod_pressure_pa: take("rod_pressure_pa"),
            storey_a_m_s2: storeys,
        });
    }
    Ok(records)
}

/// Reads the base of a table-system identification (`--base`): a scenario with a
/// `table_system`, or a `table_system` object, validated as a scenario would validate it
/// (commanded by `record`'s `command_u_m` through `columns`), with its stroke limit if it
/// gives one.
///
/// # Errors
/// [`InputError::BaseUnreadable`], [`InputError::BaseNotJson`], [`InputError::BaseNotSystem`]
/// (each with its cause) and [`InputError::NoTableSystem`].
pub fn read_base_system(
    path: &Path,
    record: &Path,
    columns: &ColumnMap,
) -> Result<(TableSystem, Option<f64>), InputError> {
    let text = std::fs::read_to_string(path).map_err(|source| InputError::BaseUnreadable {
        path: path.to_owned(),
        source,
    })?;
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|source| InputError::BaseNotJson {
            path: path.to_owned(),
            source,
        })?;
    let (spec, stroke) = match value.get("table_system") {
        Some(ts) => (
            ts.clone(),
            value.pointer("/limits/stroke_m").and_then(|v| v.as_f64()),
        ),
        None => (value.clone(), None),
    };
    let record = std::fs::canonicalize(record).unwrap_or_else(|_| record.to_path_buf());
    // Validated with a tiny stroke: the base's volumes are replaced by the fitted ones.
    let scenario = serde_json::json!({
        "model": { "preset": "lhpost-2008" },
        "table_system": spec,
        "limits": { "stroke_m": stroke.unwrap_or(1e-3) },
        "excitation": {
            "motion_csv": record.display().to_string(),
            "columns": { "u_m": { "name": columns.header("command_u_m") } }
        },
    });
    let not_system = |source| InputError::BaseNotSystem {
        path: path.into(),
        source,
    };
    let file = platen_scenario::file::parse(path, &scenario.to_string()).map_err(not_system)?;
    let s = PlatenScenario::from_file(path, file).map_err(not_system)?;
    let Some(system) = s.rig.table_system else {
        return Err(InputError::NoTableSystem {
            path: path.to_owned(),
        });
    };
    Ok((system, stroke))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_record_is_fitted_and_of_more_the_last_is_held_out() {
        assert_eq!(fitted(0), Vec::<bool>::new());
        assert_eq!(fitted(1), [true]);
        assert_eq!(fitted(2), [true, false]);
        assert_eq!(fitted(4), [true, true, true, false]);
    }

    #[test]
    fn no_files_is_an_error_before_anything_is_read() {
        let err = read_system_inputs(&SystemRequest::default()).unwrap_err();
        assert!(matches!(err, InputError::NoSystemFiles));
        assert_eq!(
            err.to_string(),
            "identify --system needs at least one recorded CSV file"
        );
    }
}
