//! The paper's identification from a fresh clone: `platen identify --manifest
//! scenarios/paper-tests/manifest.json` makes the recorded-like data of the 72 shipped
//! scenarios (S1–S12, T1–T12 at 13.8, 6.9 and 0 MPa) in memory and identifies them.
//!
//! The truth is the paper's: Eq. 22 (Mₑ = 144 t, Kₑ = 1.266 MN/m at 13.8 MPa, Cₑ = 44.58
//! kN/(m/s)^0.5, α = 0.5), Table I's per-test stiffnesses, Eq. 21's F_μ = 26.00 kN and
//! μₑ = 0.44 %. Tolerances are those of the library's test of the same programme
//! (`crates/platen-ident/tests/paper.rs`), which states why each is what it is.

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

mod common;
use common::{platen, stderr};

fn paper_tests() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper-tests")
}

fn json_of(o: &Output) -> Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn the_shipped_manifest_reproduces_the_papers_identification() {
    let manifest = paper_tests().join("manifest.json");
    let v = json_of(&platen(&[
        "identify",
        "--manifest",
        manifest.to_str().unwrap(),
        "--json",
    ]));
    let get = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k}: {}", v[k]));
    let sines = v["sine_tests"].as_array().unwrap();
    let triangles = v["triangle_tests"].as_array().unwrap();
    assert_eq!((sines.len(), triangles.len()), (36, 36));
    assert_eq!(v["pressures"].as_array().unwrap().len(), 3);
    assert_eq!(v["reference_pressure_mpa"].as_f64(), Some(13.8));

    // Eq. 22: mass and stiffness within 1 %, F_μ and Cₑ within 2 %, α within 0.01.
    assert!((get("effective_mass_kg") / 144e3 - 1.0).abs() < 0.01);
    assert!((get("stiffness_n_per_m") / 1.266e6 - 1.0).abs() < 0.01);
    let f_mu = 0.0044 * 5783e3;
    assert!(
        (get("coulomb_force_n") / f_mu - 1.0).abs() < 0.02,
        "{}",
        get("coulomb_force_n")
    );
    assert!((get("viscous_coefficient") / 44.58e3 - 1.0).abs() < 0.02);
    assert!((get("viscous_exponent") - 0.5).abs() < 0.01);
    // Fig. 8: μₑ = 0.44 % within 10 %.
    let mu = v["friction_coefficient"]["value"].as_f64().unwrap();
    assert!((mu / 0.0044 - 1.0).abs() < 0.10, "μₑ = {mu}");
    // Eq. 21 as the paper fitted it: 26.00 kN and 44.58 kN/(m/s)^0.5 within 10 %.
    let eq21 = |k: &str| v["paper_eq21"][k]["value"].as_f64().unwrap();
    assert!((eq21("coulomb_force_n") / 26.0e3 - 1.0).abs() < 0.10);
    assert!((eq21("viscous_coefficient") / 44.58e3 - 1.0).abs() < 0.10);
    // Table II: S4–S12 within 2 % of 144 t and used; S1–S3 (tiny accelerations) left out.
    for t in sines {
        let name = t["name"].as_str().unwrap();
        let low = ["S1@", "S2@", "S3@"].iter().any(|p| name.starts_with(p));
        assert_eq!(t["used"].as_bool(), Some(!low), "{name}");
        if !low {
            let m = t["effective_mass_kg"].as_f64().unwrap();
            assert!((m / 144e3 - 1.0).abs() < 0.02, "{name}: Mₑ = {m}");
        }
    }
    // Table I: every triangle test at 13.8 MPa within 1.24–1.27 MN/m, and each test's
    // pressure is its scenario's.
    for t in triangles {
        let name = t["name"].as_str().unwrap();
        let p = t["pressure_mpa"].as_f64().unwrap();
        assert_eq!(
            Some(p),
            name.split('@')
                .nth(1)
                .and_then(|s| s.trim_end_matches("MPa").parse().ok()),
            "{name}"
        );
        if p == 13.8 {
            let k = t["stiffness_n_per_m"].as_f64().unwrap();
            assert!((1.24e6..=1.27e6).contains(&k), "{name}: Kₑ = {k}");
        }
    }
}

/// A `scenario` entry gives what `platen generate recorded --seed N` and a `file` entry give:
/// the same JSON, number for number (only the `file` each test came from differs).
#[test]
fn a_scenario_entry_is_the_csv_that_generate_recorded_writes() {
    let dir = tempfile::tempdir().unwrap();
    let tests = [
        ("13.8MPa", "S9", 9),
        ("13.8MPa", "T4", 16),
        ("6.9MPa", "S6", 30),
    ];
    let mut from_scenarios = Vec::new();
    let mut from_files = Vec::new();
    for (folder, name, seed) in tests {
        let scenario = paper_tests().join(folder).join(format!("{name}.json"));
        let csv = dir.path().join(format!("{name}-{folder}.csv"));
        let o = platen(&[
            "generate",
            "recorded",
            scenario.to_str().unwrap(),
            "--seed",
            &seed.to_string(),
            "--out",
            csv.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let pressure_mpa: f64 = folder.trim_end_matches("MPa").parse().unwrap();
        let mut entry = serde_json::json!({ "scenario": scenario, "seed": seed, "name": name });
        if name == "S9" {
            // The scenario's own pressure may be restated.
            entry["pressure_mpa"] = serde_json::json!(pressure_mpa);
        }
        from_scenarios.push(entry);
        from_files.push(serde_json::json!({
            "file": csv, "name": name, "pressure_mpa": pressure_mpa,
        }));
    }
    let identify = |entries: Vec<Value>, stem: &str| {
        let m = dir.path().join(format!("{stem}.json"));
        std::fs::write(&m, serde_json::json!({ "tests": entries }).to_string()).unwrap();
        let mut v = json_of(&platen(&[
            "identify",
            "--manifest",
            m.to_str().unwrap(),
            "--json",
        ]));
        for list in ["sine_tests", "triangle_tests", "records"] {
            for t in v[list].as_array_mut().unwrap() {
                t.as_object_mut()
                    .unwrap()
                    .remove("file")
                    .expect("a file key");
            }
        }
        v
    };
    let a = identify(from_scenarios, "scenarios");
    let b = identify(from_files, "files");
    assert_eq!(a, b);
}

/// Each wrong manifest entry is refused before anything runs, naming the entry.
#[test]
fn bad_scenario_entries_are_refused_naming_the_entry() {
    let dir = tempfile::tempdir().unwrap();
    let s9 = paper_tests().join("13.8MPa/S9.json");
    let s9 = s9.to_str().unwrap();
    let force = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/sr9-like-sine-force.json");
    let cases = [
        (
            format!(r#"{{"tests": [{{"scenario": "{s9}", "file": "x.csv"}}]}}"#),
            "tests[0]`: expected `file` or `scenario`, not both",
        ),
        (
            r#"{"tests": [{"name": "S9"}]}"#.to_owned(),
            "tests[0]`: expected `file` (a recorded CSV) or `scenario`",
        ),
        (
            r#"{"tests": [{"file": "x.csv", "seed": 3}]}"#.to_owned(),
            "tests[0]`: `seed` applies to a `scenario` entry",
        ),
        (
            format!(r#"{{"tests": [{{"scenario": "{s9}", "columns": {{}}}}]}}"#),
            "tests[0]`: `columns` and `floors` apply to a recorded `file`",
        ),
        (
            format!(r#"{{"tests": [{{"scenario": "{s9}", "pressure_mpa": 6.9}}]}}"#),
            "hold-down pressure 6.9 MPa given for it, but the scenario runs at 13.8 MPa",
        ),
        (
            format!(
                r#"{{"tests": [{{"scenario": "{}"}}]}}"#,
                force.to_str().unwrap()
            ),
            "recorded-like data needs a motion scenario",
        ),
        (
            format!(
                r#"{{"floors": [{{"column": "a1", "mass_kg": 1000}}], "tests": [{{"scenario": "{s9}"}}]}}"#
            ),
            "`floors` apply to recorded files",
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let m = dir.path().join(format!("bad-{k}.json"));
        std::fs::write(&m, text).unwrap();
        let o = platen(&["identify", "--manifest", m.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(3), "{text}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{text}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{text}");
    }
}
