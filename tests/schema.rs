//! `platen schema` prints a valid JSON Schema, every shipped scenario validates against it, and
//! it rejects what the loader rejects structurally (unknown keys, wrong types).

use std::path::{Path, PathBuf};
use std::process::Command;

fn schema() -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .arg("schema")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

fn compile(schema: serde_json::Value) -> (boon::Schemas, boon::SchemaIndex) {
    let mut schemas = boon::Schemas::new();
    let mut compiler = boon::Compiler::new();
    compiler
        .add_resource("platen-scenario.json", schema)
        .unwrap();
    let index = compiler
        .compile("platen-scenario.json", &mut schemas)
        .unwrap();
    (schemas, index)
}

fn all_scenarios(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            all_scenarios(&p, out);
        } else if p.extension().is_some_and(|x| x == "json")
            // `platen identify`'s manifest of the paper's programme, not a scenario.
            && p.file_name().is_some_and(|n| n != "manifest.json")
        {
            out.push(p);
        }
    }
}

#[test]
fn every_shipped_scenario_validates_against_the_schema() {
    let (schemas, index) = compile(schema());
    let mut files = Vec::new();
    all_scenarios(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios"),
        &mut files,
    );
    assert!(files.len() > 80, "{} scenarios", files.len());
    for f in files {
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&f).unwrap()).unwrap();
        if let Err(e) = schemas.validate(&doc, index) {
            panic!("{}: {e}", f.display());
        }
    }
}

#[test]
fn the_schema_rejects_unknown_keys_and_wrong_types() {
    let (schemas, index) = compile(schema());
    for bad in [
        r#"{"model": {"preset": "lhpost-2008", "colour": 1}, "excitation": {"force_csv": "f.csv"}}"#,
        r#"{"model": {"preset": 7}, "excitation": {"force_csv": "f.csv"}}"#,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv"}, "integrator": {"method": "dop853"}}"#,
        r#"{"excitation": {"force_csv": "f.csv"}}"#,
        r#"{"table": {"held_dofs": ["x"], "colour": 1}, "excitation": {"motion_csv": "m.csv"}}"#,
    ] {
        let doc: serde_json::Value = serde_json::from_str(bad).unwrap();
        assert!(schemas.validate(&doc, index).is_err(), "accepted {bad}");
    }
    // A multi-axis table stands in for the model.
    let shipped = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/multi-axis/tower-inverse.json"),
    )
    .unwrap();
    let doc: serde_json::Value = serde_json::from_str(&shipped).unwrap();
    assert!(schemas.validate(&doc, index).is_ok());
}

/// The keys added for issue 16 are in the schema, and unknown keys inside them stay errors.
#[test]
fn the_schema_has_limits_column_offsets_and_the_inverse_dead_band() {
    let (schemas, index) = compile(schema());
    for good in [
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"sine_motion": {"amplitude_m": 0.1, "frequency_hz": 1}},
            "duration_s": 2, "limits": {"stroke_m": 0.15, "velocity_m_s": 0.5, "acceleration_m_s2": 20, "force_n": 1e6}}"#,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "m.csv",
            "columns": {"u_m": {"name": "disp", "unit": "mm", "offset": 0.3, "zero_at_start": true},
                        "a_m_s2": {"name": "acc", "unit": "g", "remove_mean": true}}}}"#,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "m.csv", "rest_velocity_m_s": 0.002}}"#,
    ] {
        let doc: serde_json::Value = serde_json::from_str(good).unwrap();
        assert!(schemas.validate(&doc, index).is_ok(), "rejected {good}");
    }
    for bad in [
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv"}, "limits": {"stroke": 1}}"#,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv"}, "limits": {"stroke_m": "far"}}"#,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv",
            "columns": {"force_n": {"offset_mpa": 1}}}}"#,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv",
            "columns": {"force_n": {"remove_mean": "yes"}}}}"#,
    ] {
        let doc: serde_json::Value = serde_json::from_str(bad).unwrap();
        assert!(schemas.validate(&doc, index).is_err(), "accepted {bad}");
    }
}

#[test]
fn schema_out_writes_the_same_schema_to_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scenario.schema.json");
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(["schema", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success());
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
    assert_eq!(written, schema());
}
