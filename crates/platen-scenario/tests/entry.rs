//! The one entry for every table ([`Scenario`]): every shipped scenario goes through it, each
//! to the table its file describes; its in-memory run gives the same columns, in the same
//! order, whichever way they are read; a multi-axis table refuses a hold-down pressure.

use std::path::{Path, PathBuf};

use platen_scenario::multi_axis::TableScenario;
use platen_scenario::{simulate, RunResult, Scenario, ScenarioError, ScenarioRig};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The shipped scenarios that need no PEER record, and whether each has a `table`.
fn shipped_without_records() -> Vec<(PathBuf, bool)> {
    let mut out = Vec::new();
    for dir in [
        "scenarios",
        "scenarios/multi-axis",
        "scenarios/specimen",
        "scenarios/sr9",
    ] {
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "json") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            if text.contains("\"ground_motion\"") || text.contains("elcentro") {
                continue;
            }
            let value: serde_json::Value = serde_json::from_str(&text).unwrap();
            out.push((path, value.get("table").is_some()));
        }
    }
    out.sort();
    out
}

#[test]
fn every_shipped_scenario_loads_as_the_table_its_file_describes() {
    let all = shipped_without_records();
    assert!(all.iter().filter(|(_, table)| *table).count() >= 3);
    assert!(all.iter().filter(|(_, table)| !*table).count() >= 8);
    for (path, table) in all {
        let scenario = Scenario::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            matches!(scenario, Scenario::Table(_)),
            table,
            "{}",
            path.display()
        );
        let rig = ScenarioRig::load(&path).unwrap();
        assert_eq!(
            matches!(rig, ScenarioRig::Table(_)),
            table,
            "{}",
            path.display()
        );
        assert!(!scenario.name().is_empty());
        let excitation = scenario.excitation();
        assert_eq!(excitation.names[0], "t_s");
        assert_eq!(excitation.names.len(), excitation.columns.len());
        assert!(excitation
            .columns
            .iter()
            .all(|c| c.len() == excitation.len()));
        assert!(["force", "motion"].contains(&excitation.kind));
    }
}

/// `simulate` of a multi-axis file is the table's own run, column for column.
#[test]
fn simulate_runs_a_multi_axis_file_as_its_table_does() {
    let path = root().join("scenarios/multi-axis/bare-inverse.json");
    let run = simulate(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let file = platen_scenario::file::parse(&path, &text).unwrap();
    let own = TableScenario::from_file(&path, &file)
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(run.columns().len(), own.columns.len());
    for (name, column) in &own.columns {
        assert_eq!(run.column(name), Some(column.as_slice()), "{name}");
    }
    assert_eq!(run.len(), own.len());
    let summary = serde_json::to_value(run.summary()).unwrap();
    assert_eq!(summary["kind"], "inverse");
    assert_eq!(summary["samples"], own.len());
}

/// The columns taken out of a run (what Python receives) are the ones `column` reads, in
/// `columns` order: a uniaxial run with a specimen and a closed loop, whose columns follow the
/// contract's.
#[test]
fn taken_columns_are_the_columns_read_in_place() {
    for (file, extra) in [
        ("scenarios/specimen/frame-forward.json", "storey1_u_m"),
        (
            "scenarios/table-system/wn10g-closed-loop.json",
            "rod_pressure_pa",
        ),
    ] {
        taken_columns_match(&root().join(file), extra);
    }
}

/// [`taken_columns_are_the_columns_read_in_place`] on the scenario at `path`, whose run has
/// the column `extra` beside the contract's.
fn taken_columns_match(path: &Path, extra: &str) {
    let run = Scenario::load(path).unwrap().run_at(path).unwrap();
    assert!(matches!(run, RunResult::Platen { .. }));
    let names: Vec<String> = run.columns().iter().map(|n| n.to_string()).collect();
    assert!(names.iter().any(|n| n == extra), "{names:?}");
    let expected: Vec<Vec<f64>> = names
        .iter()
        .map(|n| run.column(n).unwrap().to_vec())
        .collect();
    let (columns, summary) = run.into_columns();
    let got: Vec<&String> = columns.iter().map(|(n, _)| n).collect();
    assert_eq!(got, names.iter().collect::<Vec<_>>());
    for ((name, column), want) in columns.iter().zip(&expected) {
        assert_eq!(column, want, "{name}");
    }
    assert_eq!(
        serde_json::to_value(summary).unwrap()["samples"],
        expected[0].len()
    );
}

/// A multi-axis table's struts carry their own pressures: `--pressure-mpa` is refused, naming
/// the file and where those pressures are.
#[test]
fn a_table_refuses_a_hold_down_pressure() {
    let path = root().join("scenarios/multi-axis/bare-inverse.json");
    let err = Scenario::load(&path)
        .unwrap()
        .at_pressure_mpa(&path, 10.0)
        .unwrap_err();
    assert!(matches!(err, ScenarioError::PressureOfTable { .. }));
    let message = err.to_string();
    assert!(message.contains("bare-inverse.json"), "{message}");
    assert!(message.contains("hold_down_struts"), "{message}");
    let uniaxial = root().join("scenarios/sr9-like-sine-force.json");
    let at = Scenario::load(&uniaxial)
        .unwrap()
        .at_pressure_mpa(&uniaxial, 6.9);
    assert!(matches!(at, Ok(Scenario::Platen(_))));
}
