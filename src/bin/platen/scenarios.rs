//! `platen scenarios`: the shipped scenarios ([`platen_scenario::catalog`]), with what each
//! runs and its name.

use std::path::PathBuf;

use platen_scenario::catalog::{shipped, RunKind};

/// The arguments of `platen scenarios`.
#[derive(clap::Args)]
pub struct ScenariosArgs {
    /// The folder to list (default: ./scenarios, else the one platen was built from).
    dir: Option<PathBuf>,
    /// Print the list as JSON: [{path, name, kind, needs_record, specimen}, …].
    #[arg(long)]
    pub json: bool,
}

/// Runs `platen scenarios`.
pub fn run(args: &ScenariosArgs) -> anyhow::Result<()> {
    let dir = match args.dir.clone() {
        Some(d) => d,
        None => {
            let here = PathBuf::from("scenarios");
            let built = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios");
            if here.is_dir() {
                here
            } else if built.is_dir() {
                built
            } else {
                anyhow::bail!(
                    "no scenarios folder here (./scenarios) nor where platen was built ({}): give one, `platen scenarios DIR`, or run from a clone of the repository",
                    built.display()
                )
            }
        }
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "`{}` is not a folder: expected a folder of scenario files",
            dir.display()
        );
    }
    let list = shipped(&dir)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    outln!("Scenarios in {}:", dir.display());
    let w = list
        .iter()
        .map(|s| s.path.chars().count())
        .max()
        .unwrap_or(0);
    for s in &list {
        let kind = match s.kind {
            RunKind::Forward => "forward",
            RunKind::Inverse => "inverse",
            RunKind::ClosedLoop => "closed loop",
            RunKind::Group => "folder",
        };
        let mut notes = Vec::new();
        if s.specimen {
            notes.push("specimen");
        }
        if s.needs_record {
            notes.push("needs a record from PLATEN_RECORDS_DIR");
        }
        let notes = if notes.is_empty() {
            String::new()
        } else {
            format!(" ({})", notes.join(", "))
        };
        outln!("  {:<w$}  {:<11}  {}{notes}", s.path, kind, s.name);
    }
    outln!(
        "Run one: platen simulate {}/<path> --out out/run.csv",
        dir.display()
    );
    Ok(())
}
