//! `platen simulate --out run.parquet` (issue 28): the CSV's columns under the same names, one
//! `float64` per sample, read back with the parquet crate's reader and compared bit for bit
//! with the CSV of the same run and with the trajectory kept in memory; a failed write leaves
//! no file.

use std::path::Path;

use platen::integrate::Trajectory;
use platen::io::csv::read_table;
use platen::io::parquet::read_parquet;
use platen::PlatenScenario;

mod common;
use common::{platen, stderr};

fn shipped(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name)
        .display()
        .to_string()
}

/// Runs `scenario` with `--out` to a CSV and to a Parquet file; returns the Parquet's names
/// and columns after checking them against the CSV's, bit for bit.
fn parquet_matches_csv(scenario: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("run.csv");
    let parquet = dir.path().join("run.parquet");
    for out in [&csv, &parquet] {
        let o = platen(&["simulate", scenario, "--out", out.to_str().unwrap()]);
        assert!(o.status.success(), "{scenario}: {}", stderr(&o));
    }
    let (names, columns) = read_parquet(&parquet).unwrap();
    let header = std::fs::read_to_string(&csv).unwrap();
    let csv_names: Vec<&str> = header.lines().next().unwrap().split(',').collect();
    assert_eq!(names, csv_names, "{scenario}");
    let table = read_table(&csv, &csv_names, &[]).unwrap();
    for (name, column) in names.iter().zip(&columns) {
        let from_csv = table.column(name).unwrap();
        assert_eq!(column.len(), from_csv.len(), "{scenario} {name}");
        for (i, (a, b)) in column.iter().zip(from_csv).enumerate() {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "{scenario} {name} row {i}: {a} vs {b}"
            );
        }
    }
    (names, columns)
}

#[test]
fn a_forward_run_in_parquet_is_the_trajectory_bit_for_bit() {
    let scenario = shipped("sr9-like-sine-force.json");
    let (names, columns) = parquet_matches_csv(&scenario);
    assert_eq!(names, Trajectory::COLUMN_NAMES);
    let loaded = PlatenScenario::load(Path::new(&scenario)).unwrap();
    let mut trajectory = Trajectory::default();
    loaded.run(&mut trajectory).unwrap();
    for ((name, column), expected) in names.iter().zip(&columns).zip(trajectory.columns()) {
        assert_eq!(column.len(), expected.len(), "{name}");
        assert!(
            column
                .iter()
                .zip(expected)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{name}"
        );
    }
}

#[test]
fn specimen_inverse_and_closed_loop_runs_have_the_csv_columns() {
    let (names, _) = parquet_matches_csv(&shipped("specimen/frame-forward.json"));
    assert!(names.iter().any(|n| n == "base_shear_n"), "{names:?}");
    parquet_matches_csv(&shipped("s9-sine-motion.json"));
    let (names, _) = parquet_matches_csv(&shipped("table-system/wn10g-closed-loop.json"));
    assert!(names.iter().any(|n| n == "supply_pressure_pa"), "{names:?}");
}

#[test]
fn a_parquet_output_in_a_folder_that_is_a_file_fails_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let out = file.join("run.parquet");
    let o = platen(&[
        "simulate",
        &shipped("sr9-like-sine-force.json"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("run.parquet"), "{}", stderr(&o));
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
