//! `platen schema`: the JSON Schema of the scenario format.

use std::path::PathBuf;

use anyhow::Result;
use platen_io::write_bytes_atomic;

use crate::usage;

/// The arguments of `platen schema`.
#[derive(clap::Args)]
pub struct SchemaArgs {
    /// Write the schema to this file instead of standard output.
    #[arg(long, value_parser = usage::OutFile("scenario.schema.json"))]
    out: Option<PathBuf>,
}

/// Prints the schema, or writes it to `--out`.
pub fn run(args: &SchemaArgs) -> Result<()> {
    let text = serde_json::to_string_pretty(&platen_scenario::scenario::json_schema())? + "\n";
    match &args.out {
        Some(path) => write_bytes_atomic(path, text.as_bytes())?,
        None => out!("{text}"),
    }
    Ok(())
}
