//! `platen simulate --pressure-mpa P` runs the scenario at another hold-down pressure: the
//! same run, byte for byte, as the scenario file edited to say `hold_down_pressure_mpa: P`.

mod common;

use std::path::PathBuf;

use common::platen;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_option_is_the_scenario_at_that_pressure() {
    let dir = tempfile::tempdir().unwrap();
    let sr9 = root().join("scenarios/sr9-like-sine-force.json");
    let text = std::fs::read_to_string(&sr9).unwrap();
    let edited = text.replace(
        "\"hold_down_pressure_mpa\": 13.8",
        "\"hold_down_pressure_mpa\": 6.9",
    );
    assert_ne!(text, edited, "the shipped scenario changed");
    let edited_path = dir.path().join("sr9-6.9.json");
    std::fs::write(&edited_path, edited).unwrap();
    let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    let o = platen(&[
        "simulate",
        sr9.to_str().unwrap(),
        "--pressure-mpa",
        "6.9",
        "--out",
        a.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let with_option: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let o = platen(&[
        "simulate",
        edited_path.to_str().unwrap(),
        "--out",
        b.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success());
    let with_file: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(with_option["peak_u_m"], with_file["peak_u_m"]);
    assert_eq!(with_option["hold_down_pressure_mpa"], 6.9);
    // And it is not the scenario's own 13.8 MPa run (half the strut stiffness 2p₀A/h and
    // less friction move the table's resonance and damping).
    let o = platen(&["simulate", sr9.to_str().unwrap(), "--json"]);
    let own: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(own["hold_down_pressure_mpa"], 13.8);
    assert_ne!(with_option["peak_u_m"], own["peak_u_m"]);
}

#[test]
fn an_impossible_pressure_is_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let sr9 = root().join("scenarios/sr9-like-sine-force.json");
    let out = dir.path().join("x.csv");
    for p in ["13.8e6", "-1", "abc"] {
        let o = platen(&[
            "simulate",
            sr9.to_str().unwrap(),
            "--pressure-mpa",
            p,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "{p}");
        assert!(
            String::from_utf8_lossy(&o.stderr).contains("--pressure-mpa"),
            "{p}"
        );
        assert!(!out.exists());
    }
}
