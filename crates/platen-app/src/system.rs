//! The inputs of a table-system identification (`platen identify --system`): the closed-loop
//! records read through a column map ([`read_system_records`]) and the table's base geometry
//! (`--base`, [`read_base_system`]), for [`platen_ident::system::identify_system`].

use std::path::{Path, PathBuf};

use platen_ident::system::SystemRecord;
use platen_io::columns::ColumnMap;
use platen_scenario::Scenario;
use platen_system::TableSystem;

use crate::error::InputError;

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
    let s = Scenario::from_file(path, file).map_err(not_system)?;
    let Some(cl) = s.closed_loop else {
        return Err(InputError::NoTableSystem {
            path: path.to_owned(),
        });
    };
    Ok((cl.system, stroke))
}
