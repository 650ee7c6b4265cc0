//! The LHPOST6 preset and how a scenario's `table.preset` lays its values over it.

use super::*;

/// The LHPOST6 preset as written (`presets/lhpost6.json`, made by
/// `tools/make_lhpost6_preset.py`): `{"table": {…}, "limits": {…}}`.
pub(super) const LHPOST6: &str = include_str!("../../presets/lhpost6.json");

/// The preset file's shape.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PresetFile {
    table: TableSpec,
    limits: Option<crate::table_file::AxisLimitsSpec>,
}

/// The names of the table presets.
pub const TABLE_PRESETS: [&str; 1] = ["lhpost6"];

/// The table of preset `name`, limits included.
///
/// # Errors
/// An unknown name.
pub fn table_preset(name: &str) -> std::result::Result<TableSpec, String> {
    match name {
        "lhpost6" => {
            let file: PresetFile =
                serde_json::from_str(LHPOST6).expect("the shipped LHPOST6 preset parses");
            Ok(TableSpec {
                limits: file.limits.or(file.table.limits.clone()),
                ..file.table
            })
        }
        other => Err(format!(
            "one of {} (not {other:?})",
            TABLE_PRESETS.join(", ")
        )),
    }
}

/// `table` with its preset's values laid under it (values given win, field by field; a list
/// given replaces the preset's).
pub(super) fn resolve_preset(ctx: &Ctx, spec: &TableSpec) -> Result<TableSpec> {
    let Some(name) = &spec.preset else {
        return Ok(spec.clone());
    };
    let base = table_preset(name)
        .map_err(|expected| ctx.invalid("table.preset", format!("{name:?}"), expected))?;
    Ok(spec.clone().overlay(base))
}
