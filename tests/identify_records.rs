//! `platen identify` on records that are not periodic tests: routing, the JSON contract (the
//! seven keys at the top level), a specimen's floors from a manifest, and lab files as
//! recorded. The records are the independent NumPy ones of `tests/data/any-record`.

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

mod common;
use common::platen;

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/any-record")
}

/// A copy of a lab file in `dir` with its time stamps printed exactly (`k/204.8` in full),
/// for the checks that do not depend on accepting rounded stamps.
fn exact_stamps(dir: &Path, file: &str) -> PathBuf {
    let text = std::fs::read_to_string(data().join(file)).unwrap();
    let mut lines = text.lines();
    let mut out = String::from(lines.next().unwrap());
    out.push('\n');
    for (k, line) in lines.enumerate() {
        let rest = line.split_once(',').unwrap().1;
        out.push_str(&format!("{:?},{rest}\n", k as f64 / 204.8));
    }
    let path = dir.join(file);
    std::fs::write(&path, out).unwrap();
    path
}

fn json(o: &Output) -> Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

const KEYS: [&str; 7] = [
    "effective_mass_kg",
    "stiffness_n_per_m",
    "coulomb_force_n",
    "viscous_coefficient",
    "viscous_exponent",
    "low_velocity_force_n",
    "low_velocity_decay_s_per_m",
];

#[test]
fn an_earthquake_record_goes_to_the_any_record_method_with_the_seven_keys_at_the_top() {
    let dir = tempfile::tempdir().unwrap();
    let csv = exact_stamps(dir.path(), "eq-lab.csv");
    let columns = data().join("columns.json");
    let v = json(&platen(&[
        "identify",
        csv.to_str().unwrap(),
        "--columns",
        columns.to_str().unwrap(),
        "--no-output-error",
        "--json",
    ]));
    assert_eq!(v["method"], "record");
    for key in KEYS {
        assert!(v[key].as_f64().is_some(), "{key}: {}", v[key]);
        assert_eq!(v["uncertainty"][key]["status"], "estimated", "{key}");
    }
    let m = v["effective_mass_kg"].as_f64().unwrap();
    assert!((m / 118e3 - 1.0).abs() < 0.02, "{m}");
    assert!(v["dissipative_band"].as_array().unwrap().len() > 10);
    assert_eq!(v["records"][0]["velocity"], "crossover");
    let c = &v["equation_error"]["statistics"]["correlations"];
    assert_eq!(c["keys"].as_array().unwrap().len(), 7);
}

#[test]
fn a_manifest_with_floors_removes_the_specimens_base_shear() {
    let dir = tempfile::tempdir().unwrap();
    exact_stamps(dir.path(), "eq-two-storey-lab.csv");
    let manifest = dir.path().join("m.json");
    std::fs::copy(data().join("two-storey-manifest.json"), &manifest).unwrap();
    let v = json(&platen(&[
        "identify",
        "--manifest",
        manifest.to_str().unwrap(),
        "--no-output-error",
        "--json",
    ]));
    let m = v["effective_mass_kg"].as_f64().unwrap();
    let k = v["stiffness_n_per_m"].as_f64().unwrap();
    assert!((m / 118e3 - 1.0).abs() < 0.02, "{m}");
    assert!((k / 0.95e6 - 1.0).abs() < 0.02, "{k}");
    assert_eq!(
        v["records"][0]["floor_masses_kg"],
        serde_json::json!([14000.0, 11000.0])
    );
}

#[test]
fn forcing_the_periodic_method_on_an_earthquake_falls_back_with_its_reason() {
    // Issue 26: an earthquake is never lost to a forced periodic fit; it is identified by
    // the any-record method, and its account says why.
    let dir = tempfile::tempdir().unwrap();
    let csv = exact_stamps(dir.path(), "eq-lab.csv");
    let columns = data().join("columns.json");
    let o = platen(&[
        "identify",
        csv.to_str().unwrap(),
        "--columns",
        columns.to_str().unwrap(),
        "--method",
        "periodic",
        "--no-output-error",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let records = v["records"].as_array().unwrap();
    assert_eq!(records.len(), 1);
    assert_eq!(records[0]["method"], "record");
    assert_eq!(records[0]["used"], true);
    assert!(records[0]["reason"].is_null(), "present, null when used");
    assert!(
        records[0]["routing"]
            .as_str()
            .unwrap()
            .starts_with("not a periodic test: "),
        "{}",
        records[0]
    );
    assert!(v["effective_mass_kg"].as_f64().unwrap() > 0.0);
}

#[test]
fn a_bad_floor_mass_is_an_input_error_naming_the_manifest() {
    let dir = tempfile::tempdir().unwrap();
    exact_stamps(dir.path(), "eq-two-storey-lab.csv");
    let text = std::fs::read_to_string(data().join("two-storey-manifest.json")).unwrap();
    let manifest = dir.path().join("m.json");
    std::fs::write(&manifest, text.replace("14000", "-1")).unwrap();
    let o = platen(&["identify", "--manifest", manifest.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("m.json") && err.contains("mass_kg"), "{err}");
}

/// The lab file exactly as written: stamps rounded to 10⁻⁵ s (intervals 4.88 and 4.89 ms
/// against 4.8828 ms). Needs the fitted-grid sampling check of issue 16 (uniformity judged
/// against a fitted interval, not each interval against the median); today's check rejects
/// the file at line 4.
#[test]
fn a_lab_file_with_rounded_stamps_is_identified_as_recorded() {
    let csv = data().join("eq-lab.csv");
    let columns = data().join("columns.json");
    let v = json(&platen(&[
        "identify",
        csv.to_str().unwrap(),
        "--columns",
        columns.to_str().unwrap(),
        "--no-output-error",
        "--json",
    ]));
    let m = v["effective_mass_kg"].as_f64().unwrap();
    assert!((m / 118e3 - 1.0).abs() < 0.02, "{m}");
}

/// docs/identification.md's day of records: the lab's three records (one mislabelled a sine)
/// and two of the paper's periodic tests, each routed by its data, every one listed with
/// what was done with it.
#[test]
fn a_mixed_day_lists_every_record_with_its_method() {
    let manifest = data().join("mixed-day-manifest.json");
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("day.html");
    let o = platen(&[
        "identify",
        "--manifest",
        manifest.to_str().unwrap(),
        "--no-output-error",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["method"], "mixed");
    let got: Vec<(String, String, bool)> = v["records"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["name"].as_str().unwrap().to_owned(),
                r["method"].as_str().unwrap().to_owned(),
                r["used"].as_bool().unwrap(),
            )
        })
        .collect();
    let want = [
        ("eq-lab", "record"),
        ("wn-lab", "record"),
        ("wn-low-lab", "record"),
        ("S9@13.8MPa", "periodic"),
        ("T4@13.8MPa", "periodic"),
    ];
    assert_eq!(got.len(), want.len());
    for ((name, method, used), (n, m)) in got.iter().zip(want) {
        assert_eq!((name.as_str(), method.as_str(), *used), (n, m, true));
    }
    for r in v["records"].as_array().unwrap() {
        assert!(r["channel_delay_s"].is_object(), "{r}");
        assert!(r["reason"].is_null(), "{r}");
    }
    let warnings = v["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .contains("`wn-lab` was declared periodic but is not")),
        "{warnings:?}"
    );
    // The HTML report's table: one row per file, with the columns of the JSON.
    let html = std::fs::read_to_string(&page).unwrap();
    let table = &html[html.find("<h2>Records</h2>").expect("a Records section")..];
    let table = &table[..table.find("</table>").unwrap()];
    assert!(table.contains(
        "<th>file</th><th>method</th><th>used</th><th>reason</th><th>channel delay</th><th>routing</th>"
    ));
    assert_eq!(table.matches("<tr>").count(), 1 + want.len());
    for (n, _) in want {
        assert!(
            table.contains(&format!("<td><code>{n}</code></td>")) || table.contains(n),
            "{n}"
        );
    }
    assert_eq!(v["periodic"]["sine_tests"].as_array().unwrap().len(), 1);
    assert_eq!(v["periodic"]["triangle_tests"].as_array().unwrap().len(), 1);
}

/// The text report prints the record's rate as a person writes it, not the float the rounded
/// stamps give (204.79999998958843).
#[test]
fn the_report_prints_a_rounded_sample_rate() {
    let o = platen(&[
        "identify",
        data().join("eq-lab.csv").to_str().unwrap(),
        "--columns",
        data().join("columns.json").to_str().unwrap(),
        "--no-output-error",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("6145 samples at 204.8 Hz,"), "{text}");
}

/// issue 38: records of different tables fitted jointly passed without a word. Each record's
/// mass alone (refitted with the other parameters at the joint fit's) is reported, and where
/// the records that determine it (inertia at least half their force, standard error below
/// 2.5 %) put it more than 10 % apart, a warning says so. The any-record files' table has
/// 118 t; the paper's LHPOST, 144 t, under its WN10%g (`scenarios/wn10g-white-noise.json`,
/// written by `platen simulate`): 119.0 t against 143.7 t here, 18 % of the joint 138.5 t.
/// The two files of one table give 117.84 and 117.97 t alone (0.1 % apart); the paper's 24
/// tests at 13.8 MPa (forced to this method), 143.8 to 144.9 t (0.8 %) among the 13 judged
/// (measured with the release build: the 10 % has a margin of 12 on one table, 1.8 across
/// two).
#[test]
fn records_of_two_tables_fitted_jointly_are_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let d = data();
    let lhpost = dir.path().join("wn10g.csv");
    let wn10g = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/wn10g-white-noise.json");
    let o = platen(&[
        "simulate",
        wn10g.to_str().unwrap(),
        "--out",
        lhpost.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let columns: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("columns.json")).unwrap()).unwrap();
    let manifest = |tests: Vec<Value>| {
        let path = dir.path().join("m.json");
        let m = serde_json::json!({"columns": columns, "tests": tests});
        std::fs::write(&path, m.to_string()).unwrap();
        path
    };
    let file = |f: &str| serde_json::json!({"file": d.join(f), "name": f});
    let identify = |m: &Path| {
        json(&platen(&[
            "identify",
            "--manifest",
            m.to_str().unwrap(),
            "--no-output-error",
            "--json",
        ]))
    };
    let disagree = |v: &Value| {
        v["warnings"].as_array().unwrap().iter().any(|w| {
            w.as_str()
                .unwrap()
                .contains("disagree on the platen's mass")
        })
    };
    let one_table = identify(&manifest(vec![file("eq-lab.csv"), file("wn-lab.csv")]));
    assert!(!disagree(&one_table), "{}", one_table["warnings"]);
    for r in one_table["records"].as_array().unwrap() {
        let m = r["mass_alone_kg"].as_f64().unwrap();
        assert!((m / 118e3 - 1.0).abs() < 0.02, "{r}");
        assert!(r["mass_alone_std_error_kg"].as_f64().unwrap() > 0.0);
        assert!(r["mass_alone_inertial_share"].as_f64().unwrap() > 0.5);
    }
    let si = serde_json::json!({"t_s": {"name": "t_s"}, "u_m": {"name": "u_m"},
        "a_m_s2": {"name": "a_m_s2"}, "force_n": {"name": "force_n"}});
    let other = serde_json::json!({"file": lhpost, "name": "wn10g", "columns": si});
    let two_tables = identify(&manifest(vec![
        file("eq-lab.csv"),
        file("wn-lab.csv"),
        other,
    ]));
    assert!(disagree(&two_tables), "{}", two_tables["warnings"]);
    let warning = two_tables["warnings"].to_string();
    assert!(warning.contains("`wn10g` alone 14") && warning.contains("identify them apart"));
}
