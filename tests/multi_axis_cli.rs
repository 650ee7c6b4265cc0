//! `platen simulate` and `platen model` on the shipped multi-axis scenarios: the contract's
//! columns and keys, the figures, and errors that name their place.

use std::path::PathBuf;

mod common;
use common::{platen, stderr};

fn scenario(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/multi-axis")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn simulate_writes_the_contracts_columns_summary_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tower.csv");
    let plots = dir.path().join("plots");
    let o = platen(&[
        "simulate",
        &scenario("tower-inverse.json"),
        "--out",
        out.to_str().unwrap(),
        "--plot",
        plots.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(summary["samples"], 4001);
    assert_eq!(summary["within_limits"], true);
    assert_eq!(summary["actuators"].as_array().unwrap().len(), 10);
    assert_eq!(summary["figures"].as_array().unwrap().len(), 8);
    let text = std::fs::read_to_string(&out).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let mut expect = vec!["t_s"];
    let pose = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"];
    let names: Vec<String> = ["", "_s", "_s2"]
        .iter()
        .flat_map(|s| pose.iter().map(move |p| format!("{p}{s}")))
        .collect();
    expect.extend(names.iter().map(String::as_str));
    assert_eq!(header[..19], expect[..]);
    for name in [
        "h1_stroke_m",
        "h1_force_n",
        "v6_force_n",
        "s4_force_n",
        "base_force_z_n",
        "overturning_moment_y_n_m",
    ] {
        assert!(header.contains(&name), "{name} in {header:?}");
    }
    assert_eq!(text.lines().count(), 4002);
    // The same bytes again.
    let again = dir.path().join("again.csv");
    let o = platen(&[
        "simulate",
        &scenario("tower-inverse.json"),
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn model_describes_the_modes_and_the_axes() {
    let o = platen(&[
        "model",
        "--scenario",
        &scenario("bare-inverse.json"),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let modes = d["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 6);
    assert!(modes
        .iter()
        .all(|m| m["frequency_hz"].as_f64().unwrap() > 0.0
            && m["shape"].as_array().unwrap().len() == 6));
    for axis in ["x", "y", "z"] {
        for key in ["stroke_m", "force_n", "acceleration_m_s2"] {
            assert!(d["axes"][axis][key].as_f64().unwrap() > 0.0, "{axis}.{key}");
        }
    }
    for axis in ["roll", "pitch", "yaw"] {
        for key in ["angle_rad", "moment_n_m"] {
            assert!(d["axes"][axis][key].as_f64().unwrap() > 0.0, "{axis}.{key}");
        }
    }
}

/// An error names the file and JSON path, exits non-zero and writes nothing.
#[test]
fn a_bad_table_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scenario("bare-inverse.json")).unwrap())
            .unwrap();
    doc["table"]["actuators"][3]["platen_m"] = serde_json::json!([1.0, 2.0]);
    doc["excitation"]["motion_csv"] = serde_json::json!(scenario("three-component-motion.csv"));
    let path = dir.path().join("bad.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    let out = dir.path().join("out.csv");
    let o = platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("bad.json") && err.contains("table.actuators[3].platen_m"),
        "{err}"
    );
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // A uniaxial-only verb says so.
    let o = platen(&[
        "compare",
        &scenario("bare-inverse.json"),
        &scenario("three-component-motion.csv"),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("multi-axis"), "{}", stderr(&o));
}

/// The forward scenario (friction, the tower): the pose, the actuators' strokes and forces,
/// the work, the friction's dissipation and stick flag, the specimen's forces and energy.
#[test]
fn the_forward_scenario_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("forward.csv");
    let o = platen(&[
        "simulate",
        &scenario("forward.json"),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(summary["kind"], "forward");
    assert_eq!(summary["samples"], 2001);
    let text = std::fs::read_to_string(&out).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    for name in [
        "x_m",
        "yaw_rad_s2",
        "h4_stroke_m",
        "v1_force_n",
        "s2_force_n",
        "actuator_work_j",
        "dissipated_j",
        "stuck",
        "base_force_x_n",
        "overturning_moment_y_n_m",
        "specimen1_z",
        "specimen_damping_j",
    ] {
        assert!(header.contains(&name), "{name} in {header:?}");
    }
}
