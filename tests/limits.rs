//! A scenario states its own table's limits (`limits`, laid over the preset's), and a model
//! whose values are overridden is named as such.

use std::process::Output;

use serde_json::Value;

mod common;
use common::platen;

fn stdout(o: &Output) -> String {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The paper's S9 sine (0.2 m, 0.6 Hz: peak velocity 2π·0.6·0.2 = 0.754 m/s, acceleration
/// (2π·0.6)²·0.2 = 2.84 m/s²) on a smaller table: stroke ±0.15 m and 0.5 m/s, its own; the
/// acceleration and force limits are the preset's (4.2 g, 6.8 MN).
const SMALL_TABLE: &str = r#"{
    "model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": 20000, "coulomb_force_n": 3000}},
    "excitation": {"sine_motion": {"amplitude_m": 0.2, "frequency_hz": 0.6}},
    "duration_s": 5,
    "limits": {"stroke_m": 0.15, "velocity_m_s": 0.5}
}"#;

#[test]
fn a_scenarios_own_limits_are_reported_as_exceeded_and_the_rest_are_the_presets() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("small.json");
    std::fs::write(&path, SMALL_TABLE).unwrap();
    let summary: Value = serde_json::from_str(&stdout(&platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--json",
    ])))
    .unwrap();
    let limits = &summary["limits"];
    assert_eq!(limits["stroke_m"]["limit"], 0.15);
    assert_eq!(limits["stroke_m"]["respected"], false);
    assert!((limits["stroke_m"]["peak"].as_f64().unwrap().abs() - 0.2).abs() < 1e-6);
    assert_eq!(limits["velocity_m_s"]["limit"], 0.5);
    assert_eq!(limits["velocity_m_s"]["respected"], false);
    let v = limits["velocity_m_s"]["peak"].as_f64().unwrap().abs();
    assert!(
        (v - 2.0 * std::f64::consts::PI * 0.6 * 0.2).abs() < 1e-4,
        "{v}"
    );
    // Not given: the preset's.
    assert_eq!(limits["force_n"]["limit"], 6.8e6);
    assert_eq!(limits["force_n"]["respected"], true);
    assert!((limits["acceleration_m_s2"]["limit"].as_f64().unwrap() - 4.2 * 9.80665).abs() < 1e-9);
    let exceeded: Vec<&str> = summary["limit_exceedances"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["quantity"].as_str().unwrap())
        .collect();
    assert_eq!(exceeded, ["stroke", "velocity"]);
    // The model is named as overridden, with the values.
    assert_eq!(summary["model_overrides"]["effective_mass_kg"], 20000.0);
    assert_eq!(summary["model_overrides"]["coulomb_force_n"], 3000.0);

    let text = stdout(&platen(&["simulate", path.to_str().unwrap()]));
    assert!(
        text.contains("lhpost-2008 at 13.80 MPa, overridden: coulomb_force_n = 3000, effective_mass_kg = 20000"),
        "{text}"
    );
    assert!(
        text.contains("EXCEEDS stroke limit") && text.contains("EXCEEDS velocity limit"),
        "{text}"
    );
}

#[test]
fn a_scenario_without_overrides_or_limits_reports_the_presets() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plain.json");
    std::fs::write(
        &path,
        r#"{"model": {"preset": "lhpost-2008"},
            "excitation": {"sine_motion": {"amplitude_m": 0.2, "frequency_hz": 0.6}}, "duration_s": 5}"#,
    )
    .unwrap();
    let summary: Value = serde_json::from_str(&stdout(&platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--json",
    ])))
    .unwrap();
    assert_eq!(
        summary["model_overrides"],
        serde_json::json!({}),
        "{summary}"
    );
    assert_eq!(summary["limits"]["stroke_m"]["limit"], 0.75);
    let text = stdout(&platen(&["simulate", path.to_str().unwrap()]));
    assert!(text.contains("lhpost-2008 at 13.80 MPa\n"), "{text}");
    assert!(
        text.contains("within the table's limits (stroke ±0.75 m, 1.8 m/s, 4.2 g, 6.8 MN)"),
        "{text}"
    );
}

#[test]
fn bad_limits_are_input_errors_naming_their_json_path() {
    let dir = tempfile::tempdir().unwrap();
    for (limits, needle) in [
        (r#"{"stroke_m": 0}"#, "limits.stroke_m"),
        (r#"{"force_n": -1}"#, "limits.force_n"),
        (r#"{"stroke": 0.5}"#, "stroke"),
        (r#"{"velocity_m_s": "fast"}"#, "limits.velocity_m_s"),
    ] {
        let path = dir.path().join("bad.json");
        std::fs::write(
            &path,
            format!(
                r#"{{"model": {{"preset": "lhpost-2008"}},
                    "excitation": {{"sine_motion": {{"amplitude_m": 0.2, "frequency_hz": 0.6}}}},
                    "duration_s": 5, "limits": {limits}}}"#
            ),
        )
        .unwrap();
        let o = platen(&["simulate", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(3), "{limits}: {err}");
        assert!(
            err.contains(needle) && err.contains("bad.json"),
            "{limits}: {err}"
        );
    }
}
