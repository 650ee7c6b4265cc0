//! `platen identify --system` on a small table's records as a lab exports them (independent
//! numpy stand-ins, `tests/data/small_table`: Δp only, the drive in volts, mm, bar and g,
//! noise, skew, content above 30 Hz the command does not drive, a two-storey frame, no
//! drawings). The printed scenario is the table: every value identified, given or assumed
//! with its provenance, none from a preset, no `duration_s`, only values `simulate` takes;
//! it runs as printed on another record's command. Records that cannot show the loop are
//! answered with the reason.

use std::fs;
use std::path::{Path, PathBuf};

use serde_json::Value;

mod common;
use common::{platen, stderr};

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/small_table")
        .join(name)
        .display()
        .to_string()
}

fn identify() -> Value {
    let o = platen(&[
        "identify",
        "--system",
        &data("wn.csv"),
        &data("sweep.csv"),
        &data("eq1.csv"),
        &data("eq2.csv"),
        &data("eq3.csv"),
        "--columns",
        &data("columns.json"),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Every leaf's JSON path under `value` (`a.b[0].c`).
fn leaves(value: &Value, path: &str, out: &mut Vec<String>) {
    match value {
        Value::Object(m) => {
            for (k, v) in m {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                leaves(v, &p, out);
            }
        }
        Value::Array(a) if a.iter().all(Value::is_number) => {
            for i in 0..a.len() {
                out.push(format!("{path}[{i}]"));
            }
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                leaves(v, &format!("{path}[{i}]"), out);
            }
        }
        _ => out.push(path.to_owned()),
    }
}

/// One column of a CSV by its header.
fn column(path: &Path, name: &str) -> Vec<f64> {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| h.trim() == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().trim().parse().unwrap())
        .collect()
}

#[test]
fn the_printed_scenario_is_the_table_and_runs_on_another_records_command() {
    let out = identify();
    let scenario = &out["scenario"];
    assert!(scenario.is_object(), "{out:#}");
    // No duration copied from a record; no preset behind the table system.
    assert!(scenario.get("duration_s").is_none());
    assert!(scenario["table_system"].get("preset").is_none());
    // Every value of the model, the table system, the specimen and the limits has a
    // provenance (a preset value leaking in would have none).
    let provenance: Vec<&str> = out["scenario_provenance"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["path"].as_str().unwrap())
        .collect();
    let mut paths = Vec::new();
    for part in ["table_system", "specimen", "limits"] {
        leaves(&scenario[part], part, &mut paths);
    }
    leaves(
        &scenario["model"]["identified"],
        "model.identified",
        &mut paths,
    );
    for p in &paths {
        assert!(provenance.contains(&p.as_str()), "{p} has no provenance");
    }
    let sources: Vec<&str> = out["scenario_provenance"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["source"].as_str().unwrap())
        .collect();
    assert!(sources
        .iter()
        .all(|s| ["identified", "given", "assumed"].contains(s)));
    // The area: assumed, and said so.
    let area = out["scenario_provenance"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["path"] == "table_system.actuator.cap_side_area_m2")
        .unwrap();
    assert_eq!(area["source"], "assumed");
    // Every gain a scenario takes (≥ 0).
    for (k, v) in scenario["table_system"]["controller"].as_object().unwrap() {
        assert!(v.as_f64().unwrap() >= 0.0, "{k} = {v}");
    }

    // As printed, on the other held-out record's command (eq4.csv): only its motion_csv
    // changes. It runs, and its displacement follows the record's within 1 % (NRMSE).
    let dir = tempfile::tempdir().unwrap();
    let mut s = scenario.clone();
    s["excitation"]["motion_csv"] = Value::String(data("eq4.csv"));
    let path: PathBuf = dir.path().join("identified.json");
    fs::write(&path, serde_json::to_string_pretty(&s).unwrap()).unwrap();
    let csv = dir.path().join("run.csv");
    let o = platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sim = column(&csv, "u_m");
    let rec: Vec<f64> = column(Path::new(&data("eq4.csv")), "Actuator displacement (mm)")
        .iter()
        .map(|x| x * 1e-3)
        .collect();
    assert_eq!(sim.len(), rec.len());
    let rms = |x: &mut dyn Iterator<Item = f64>| {
        let v: Vec<f64> = x.collect();
        (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt()
    };
    let nrmse = rms(&mut sim.iter().zip(&rec).map(|(a, b)| a - b)) / rms(&mut rec.iter().copied());
    eprintln!("simulate on eq4's command: displacement NRMSE {nrmse:.5}");
    assert!(nrmse < 0.01, "{nrmse}");
}

#[test]
fn records_that_cannot_show_the_loop_get_the_reason_not_a_scenario() {
    let dir = tempfile::tempdir().unwrap();
    // The lab's map without the drive (the file has none).
    let text = fs::read_to_string(data("columns.json")).unwrap();
    let mut map: Value = serde_json::from_str(&text).unwrap();
    map.as_object_mut().unwrap().remove("drive");
    let map_path = dir.path().join("columns.json");
    fs::write(&map_path, map.to_string()).unwrap();
    for (file, columns, words) in [
        (
            "no-drive.csv",
            map_path.display().to_string(),
            "no drive recorded",
        ),
        (
            "constant-command.csv",
            data("columns.json"),
            "does not move the table",
        ),
    ] {
        let o = platen(&[
            "identify",
            "--system",
            &data(file),
            "--columns",
            &columns,
            "--json",
        ]);
        assert!(!o.status.success());
        assert!(
            o.stdout.is_empty() || !String::from_utf8_lossy(&o.stdout).contains("\"scenario\"")
        );
        let e = stderr(&o);
        assert!(e.contains(words), "{file}: {e}");
    }
}
