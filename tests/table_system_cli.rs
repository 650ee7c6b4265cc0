//! `platen simulate` on a closed-loop scenario (`table_system`): the CSV carries the contract's
//! columns and then the loop's, `--json` the oil-column frequency and the tracking; a bad
//! `table_system` is refused with its JSON path and nothing written.

use std::fs;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

mod common;
use common::{platen, stderr};

/// A short closed-loop scenario: the LHPOST preset's loop commanded by a 2 cm, 1 Hz sine.
fn scenario(table_system: Value) -> Value {
    json!({
        "name": "closed-loop sine",
        "model": {"preset": "lhpost-2008"},
        "table_system": table_system,
        "excitation": {"sine_motion": {"amplitude_m": 0.02, "frequency_hz": 1.0}},
        "duration_s": 0.5
    })
}

fn write(dir: &Path, name: &str, scenario: &Value) -> PathBuf {
    let path = dir.join(name);
    fs::write(&path, serde_json::to_string_pretty(scenario).unwrap()).unwrap();
    path
}

/// The names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn simulate_writes_the_contract_columns_then_the_loops() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "loop.json",
        &scenario(json!({"preset": "lhpost-2008"})),
    );
    let out = dir.path().join("loop.csv");
    let o = platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let text = fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let contract = [
        "t_s",
        "u_m",
        "v_m_s",
        "a_m_s2",
        "force_n",
        "inertial_force_n",
        "elastic_force_n",
        "dissipative_force_n",
    ];
    let system = [
        "command_u_m",
        "drive",
        "spool_opening",
        "delta_p_pa",
        "flow_m3_s",
        "supply_pressure_pa",
    ];
    assert_eq!(header[..8], contract, "{header:?}");
    assert_eq!(header[8..14], system, "{header:?}");
    // Every input sample: 0.5 s at 1024 Hz.
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 513);
    assert!(rows.iter().all(|r| r.len() == header.len()));
    assert!(rows.iter().flatten().all(|x| x.is_finite()));
    // The command is the sine; the drive stays within ±1.
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t, cmd, drive) = (col("t_s"), col("command_u_m"), col("drive"));
    for r in &rows {
        let expected = 0.02 * (std::f64::consts::TAU * r[t]).sin();
        assert!(
            (r[cmd] - expected).abs() < 1e-12,
            "{} vs {expected}",
            r[cmd]
        );
        assert!(r[drive].abs() <= 1.0);
    }

    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let f = summary["oil_column_frequency_hz"].as_f64().unwrap();
    assert!((f - 10.66).abs() < 0.02, "oil column {f} Hz");
    let rms = summary["table_system"]["tracking_displacement_rms_m"]
        .as_f64()
        .unwrap();
    assert!((0.0..0.02).contains(&rms), "{rms}");
    assert_eq!(summary["samples"], json!(513));
    assert_eq!(summary["direction"], json!("forward"));
    assert!(summary["table_system"]["loop_margins"]["stable"]
        .as_bool()
        .unwrap());
    assert_eq!(summary["out"], json!(out.display().to_string()));
    // Only the scenario and its CSV in the folder: no temporary file left.
    assert_eq!(listing(dir.path()), ["loop.csv", "loop.json"]);
}

#[test]
fn a_bad_table_system_exits_non_zero_naming_its_path_and_writes_nothing() {
    for (table_system, path, expected) in [
        (
            json!({"preset": "lhpost-2008", "actuator": {"area_m2": 0}}),
            "table_system.actuator.cap_side_area_m2",
            "a finite number > 0",
        ),
        (
            json!({"preset": "lhpost-2008", "return_pressure_pa": 3e7}),
            "table_system.return_pressure_pa",
            "below the supply pressure",
        ),
        (
            json!({"preset": "lhpost-2008", "actuator": {"chamber_volume_m3": 0.1}}),
            "table_system.actuator.chamber_volume_m3",
            "would empty",
        ),
        (
            json!({"preset": "lhpost-2008", "servo_valve": {"natural_frequency_hz": 0}}),
            "table_system.servo_valve.natural_frequency_hz",
            "a finite number > 0",
        ),
        (
            json!({"preset": "lhpost-2008", "controller": {"gain": 1}}),
            "table_system.controller",
            "gain",
        ),
        (
            json!({"preset": "nees-2099"}),
            "table_system.preset",
            "lhpost-2008",
        ),
        (
            json!({"actuator": {"count": 1}}),
            "table_system.actuator.cap_side_area_m2",
            "(missing)",
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let scenario_path = write(dir.path(), "bad.json", &scenario(table_system));
        let out = dir.path().join("bad.csv");
        let o = platen(&[
            "simulate",
            scenario_path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{path}: {err}");
        assert!(
            err.contains(path) && err.contains(expected),
            "{path} / {expected:?} not in: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(o.stdout.is_empty(), "{path}");
        assert!(!out.exists(), "{path}: an output was written");
        assert_eq!(
            listing(dir.path()),
            ["bad.json"],
            "{path}: files left behind"
        );

        // With --json the error is one object naming the field.
        let o = platen(&[
            "simulate",
            scenario_path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(o.status.code(), Some(3), "{path}");
        let error: Value = serde_json::from_slice(&o.stderr).unwrap();
        let field = error["error"]["field"].as_str().unwrap_or_default();
        assert!(field.starts_with(path), "{path}: {error}");
        assert_eq!(
            listing(dir.path()),
            ["bad.json"],
            "{path}: files left behind"
        );
    }
}

#[test]
fn a_force_excitation_with_a_table_system_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = scenario(json!({"preset": "lhpost-2008"}));
    s["excitation"] = json!({"sine_force": {"amplitude_n": 1e5, "frequency_hz": 1}});
    let path = write(dir.path(), "force.json", &s);
    let out = dir.path().join("force.csv");
    let o = platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains("excitation") && err.contains("motion excitation"),
        "{err}"
    );
    assert_eq!(listing(dir.path()), ["force.json"]);
}

/// The CSV at `path` as its header and columns of numbers.
fn columns(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols = vec![Vec::new(); header.len()];
    for line in lines {
        for (c, v) in cols.iter_mut().zip(line.split(',')) {
            c.push(v.parse::<f64>().unwrap());
        }
    }
    (header, cols)
}

fn column<'a>(csv: &'a (Vec<String>, Vec<Vec<f64>>), name: &str) -> &'a [f64] {
    let i = csv.0.iter().position(|h| h == name).unwrap();
    &csv.1[i]
}

#[test]
fn the_tracking_summary_gives_the_relative_errors_the_readme_quotes() {
    // The relative errors recomputed here from the files the CLI writes: the command
    // (`generate excitation`) and the run (`simulate --out`), sample by sample. The README and
    // docs/table-system.md quote the acceleration's as 53 %.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = root.join("scenarios/table-system/wn10g-closed-loop.json");
    let dir = tempfile::tempdir().unwrap();
    let (cmd, run) = (dir.path().join("command.csv"), dir.path().join("run.csv"));
    let s = scenario.to_str().unwrap();
    let o = platen(&["generate", "excitation", s, "--out", cmd.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = platen(&["simulate", s, "--out", run.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let (cmd, run) = (columns(&cmd), columns(&run));
    let nrmse = |achieved: &[f64], reference: &[f64]| {
        assert_eq!(achieved.len(), reference.len());
        let e2: f64 = achieved
            .iter()
            .zip(reference)
            .map(|(a, r)| (a - r).powi(2))
            .sum();
        let r2: f64 = reference.iter().map(|r| r * r).sum();
        (e2 / r2).sqrt()
    };
    let ts = &summary["table_system"];
    for (key, channel) in [
        ("tracking_displacement_nrmse", "u_m"),
        ("tracking_acceleration_nrmse", "a_m_s2"),
    ] {
        let expected = nrmse(column(&run, channel), column(&cmd, channel));
        let got = ts[key].as_f64().unwrap_or_else(|| panic!("{key} in {ts}"));
        eprintln!("{key}: {got} (recomputed {expected})");
        // Tolerance: the CSV's shortest round-trip decimals give the summary's samples
        // back exactly; what remains is the order of summation.
        assert!((got - expected).abs() < 1e-12 * expected, "{key}");
    }
    let a = ts["tracking_acceleration_nrmse"].as_f64().unwrap();
    assert!((0.525..0.535).contains(&a), "the quoted 53 %: {a}");
    // The keys a multi-axis table gives each DOF carry the same figures for the one DOF x;
    // the flat keys are their aliases.
    let x = &ts["tracking"]["x"];
    for (key, alias) in [
        ("displacement_nrmse", "tracking_displacement_nrmse"),
        ("acceleration_nrmse", "tracking_acceleration_nrmse"),
        ("rms_error", "tracking_displacement_rms_m"),
        ("rms_acceleration_error", "tracking_acceleration_rms_m_s2"),
    ] {
        assert_eq!(x[key], ts[alias], "tracking.x.{key} against {alias}");
    }
    for (key, alias) in [
        ("peak_error", "tracking_displacement_peak_m"),
        ("peak_acceleration_error", "tracking_acceleration_peak_m_s2"),
    ] {
        let (got, signed) = (x[key].as_f64().unwrap(), ts[alias].as_f64().unwrap());
        assert_eq!(
            got,
            signed.abs(),
            "tracking.x.{key}: the magnitude of {alias}"
        );
    }
    assert_eq!(ts["saturated_time_s"], ts["valve_saturated_time_s"]);
    assert_eq!(ts["steps_per_period"], ts["steps_per_controller_period"]);
    let text = platen(&["simulate", s]);
    let out = String::from_utf8_lossy(&text.stdout);
    assert!(out.contains("acceleration error 53.4 % NRMSE"), "{out}");
}

#[test]
fn a_command_that_stays_at_zero_has_null_relative_errors() {
    // No reference to be relative to: null in --json (the key is there), "—" in text.
    let dir = tempfile::tempdir().unwrap();
    let mut still = scenario(json!({"preset": "lhpost-2008"}));
    still["excitation"] = json!({"sine_motion": {"amplitude_m": 0.0, "frequency_hz": 1.0}});
    let path = write(dir.path(), "still.json", &still);
    let o = platen(&["simulate", path.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let ts = summary["table_system"].as_object().unwrap();
    for key in ["tracking_displacement_nrmse", "tracking_acceleration_nrmse"] {
        assert!(
            ts.contains_key(key) && ts[key].is_null(),
            "{key}: {:?}",
            ts.get(key)
        );
    }
    let o = platen(&["simulate", path.to_str().unwrap()]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("displacement error — NRMSE"), "{out}");
}
