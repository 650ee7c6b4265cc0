//! `platen schema`: the JSON Schema of the scenario format.

use std::path::Path;

use anyhow::Result;
use platen_io::write_bytes_atomic;

/// Prints the schema, or writes it to `out`.
pub fn run(out: Option<&Path>) -> Result<()> {
    let text = serde_json::to_string_pretty(&platen_scenario::scenario::json_schema())? + "\n";
    match out {
        Some(path) => write_bytes_atomic(path, text.as_bytes())?,
        None => out!("{text}"),
    }
    Ok(())
}
