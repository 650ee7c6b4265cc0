//! The shipped scenarios: what `platen scenarios` lists. Each scenario file of a folder (its
//! top level and one level of subfolders) with its name and what kind of run it is, read
//! with the scenario format's own parser ([`crate::file::parse`]) but not run: no record is
//! loaded. Files that are not scenarios (an identification manifest, a CSV) are left out; a
//! folder of many scenarios that belong together (the paper's periodic programme) counts as
//! one entry.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{Result, ScenarioError};

/// Subfolders holding this many scenario files or more are listed as one entry (the paper's
/// 72 periodic tests), not file by file.
pub const GROUP_FILES: usize = 12;

/// What a scenario runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunKind {
    /// A force drives the model (`force_csv`, `sine_force`).
    Forward,
    /// A motion is prescribed and the force computed.
    Inverse,
    /// A `table_system` (or a multi-axis table with a controller or a preset): the motion is
    /// the controller's command.
    ClosedLoop,
    /// A folder of scenarios.
    Group,
}

/// One entry of the list.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShippedScenario {
    /// Path relative to the folder listed (`/`-separated).
    pub path: String,
    /// The scenario's `name`, or for a group the number of its scenarios.
    pub name: String,
    /// What it runs.
    pub kind: RunKind,
    /// Whether it needs a record from the records folder (`ground_motion`: a PEER record, or
    /// another such as the El Centro digitisation), which is not shipped.
    pub needs_record: bool,
    /// Whether it carries a specimen.
    pub specimen: bool,
}

/// The scenarios under `dir`, sorted by path.
///
/// # Errors
/// [`ScenarioError::Io`]-kind errors when `dir` cannot be read (named in the message).
pub fn shipped(dir: &Path) -> Result<Vec<ShippedScenario>> {
    let mut out = Vec::new();
    for path in json_files(dir)? {
        if let Some(s) = entry(dir, &path) {
            out.push(s);
        }
    }
    for sub in subfolders(dir)? {
        let entries: Vec<ShippedScenario> = json_files(&sub)?
            .iter()
            .filter_map(|p| entry(dir, p))
            .collect();
        let mut nested = 0;
        for d in subfolders(&sub)? {
            nested += json_files(&d)?
                .iter()
                .filter(|p| entry(dir, p).is_some())
                .count();
        }
        if entries.len() + nested >= GROUP_FILES {
            out.push(ShippedScenario {
                path: format!("{}/", relative(dir, &sub)),
                name: format!("{} scenarios", entries.len() + nested),
                kind: RunKind::Group,
                needs_record: false,
                specimen: false,
            });
            continue;
        }
        out.extend(entries);
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(out)
}

/// The entry of one file, if it is a scenario.
fn entry(dir: &Path, path: &Path) -> Option<ShippedScenario> {
    let text = std::fs::read_to_string(path).ok()?;
    let file = crate::file::parse(path, &text).ok()?;
    let e = &file.excitation;
    let table_loop = file
        .table
        .as_ref()
        .is_some_and(|t| t.controller.is_some() || t.preset.is_some());
    let kind = if file.table_system.is_some() || table_loop {
        RunKind::ClosedLoop
    } else if e.force_csv.is_some() || e.sine_force.is_some() {
        RunKind::Forward
    } else {
        RunKind::Inverse
    };
    Some(ShippedScenario {
        path: relative(dir, path),
        name: file.name.unwrap_or_default(),
        kind,
        needs_record: e.ground_motion.is_some(),
        specimen: file.specimen.is_some(),
    })
}

fn relative(dir: &Path, path: &Path) -> String {
    path.strip_prefix(dir)
        .unwrap_or(path)
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

fn listing(dir: &Path) -> Result<Vec<PathBuf>> {
    let read = std::fs::read_dir(dir).map_err(|source| {
        ScenarioError::Io(platen_io::IoError::Io {
            path: dir.to_path_buf(),
            action: platen_io::IoAction::Reading,
            source,
        })
    })?;
    let mut v: Vec<PathBuf> = read.filter_map(|e| e.ok().map(|e| e.path())).collect();
    v.sort();
    Ok(v)
}

fn json_files(dir: &Path) -> Result<Vec<PathBuf>> {
    Ok(listing(dir)?
        .into_iter()
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "json"))
        .collect())
}

fn subfolders(dir: &Path) -> Result<Vec<PathBuf>> {
    Ok(listing(dir)?.into_iter().filter(|p| p.is_dir()).collect())
}
