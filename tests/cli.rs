//! End-to-end tests of the `platen` binary on the shipped scenarios and on bad input.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{platen, stderr};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scenario(name: &str) -> String {
    workspace()
        .join("scenarios")
        .join(name)
        .display()
        .to_string()
}

/// Reads a CSV written by platen into (header, rows).
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

const CONTRACT_COLUMNS: [&str; 8] = [
    "t_s",
    "u_m",
    "v_m_s",
    "a_m_s2",
    "force_n",
    "inertial_force_n",
    "elastic_force_n",
    "dissipative_force_n",
];

/// The shipped scenarios of the uniaxial platen but the paper's periodic program
/// (scenarios/paper-tests, 72 files, run in tests/paper_program.rs): those that need a PEER
/// record (a `ground_motion`) and the others. The multi-axis ones (scenarios/multi-axis)
/// have their own columns: tests/multi_axis_cli.rs.
fn shipped_scenarios() -> (Vec<PathBuf>, Vec<PathBuf>) {
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(workspace().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir()
            && path
                .file_name()
                .is_some_and(|n| n != "paper-tests" && n != "multi-axis")
        {
            paths.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
        } else {
            paths.push(path);
        }
    }
    paths.retain(|p| p.extension().is_some_and(|e| e == "json"));
    paths.sort();
    paths.into_iter().partition(|p| {
        std::fs::read_to_string(p)
            .unwrap()
            .contains("ground_motion")
    })
}

/// Runs a shipped scenario with `--out` and `--json` and checks what it wrote.
fn check_shipped_scenario_run(path: &Path, dir: &Path) {
    let out = dir.join("out.csv");
    let o = platen(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}: {}", path.display(), stderr(&o));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (header, rows) = read_csv(&out);
    assert_eq!(
        header[..CONTRACT_COLUMNS.len()],
        CONTRACT_COLUMNS,
        "{}",
        path.display()
    );
    // A specimen adds base_shear_n, storey{i}_u_m, storey{i}_a_m_s2 (contract); a closed loop
    // (a table_system) then adds the loop's columns (contract, then the chamber pressures).
    let mut extra: Vec<String> = Vec::new();
    if let Some(storeys) = summary["specimen"]["storeys"].as_array() {
        let n = storeys.len();
        extra.push("base_shear_n".to_string());
        extra.extend((1..=n).map(|i| format!("storey{i}_u_m")));
        extra.extend((1..=n).map(|i| format!("storey{i}_a_m_s2")));
        // A specimen that yields (some storey with a ductility) adds its storeys' hysteresis.
        if storeys.iter().any(|s| !s["ductility"].is_null()) {
            for suffix in [
                "_drift_m",
                "_force_n",
                "_hysteretic_force_n",
                "_hysteretic_j",
            ] {
                extra.extend((1..=n).map(|i| format!("storey{i}{suffix}")));
            }
        }
    }
    if !summary["table_system"].is_null() {
        extra.extend(
            [
                "command_u_m",
                "drive",
                "spool_opening",
                "delta_p_pa",
                "flow_m3_s",
                "supply_pressure_pa",
                "cap_pressure_pa",
                "rod_pressure_pa",
            ]
            .map(String::from),
        );
    }
    assert_eq!(
        header[CONTRACT_COLUMNS.len()..],
        extra,
        "{}",
        path.display()
    );
    assert_eq!(rows.len() as u64, summary["samples"].as_u64().unwrap());
    // Sample times are uniform and start at 0 for every shipped scenario.
    assert_eq!(rows[0][0], 0.0);
    for key in [
        "peak_u_m",
        "peak_v_m_s",
        "peak_a_m_s2",
        "peak_force_n",
        "limit_exceedances",
        "direction",
    ] {
        assert!(
            summary.get(key).is_some(),
            "{}: summary lacks {key}",
            path.display()
        );
    }
    // Every forward run closes its energy balance: the residual is integration error only
    // (measured <= 2e-12 relative for RK4 at the record's rate, <= 2e-14 for Dopri5).
    if summary["direction"] == "forward" {
        let rel = summary["energy"]["relative_residual"].as_f64().unwrap();
        assert!(
            rel.abs() < 1e-9,
            "{}: energy residual {rel}",
            path.display()
        );
    }
}

#[test]
fn every_shipped_scenario_without_a_record_runs_and_writes_every_input_sample_with_the_contract_columns(
) {
    let dir = tempfile::tempdir().unwrap();
    let paths = shipped_scenarios().1;
    assert!(
        paths.len() >= 3,
        "expected at least three shipped scenarios, found {}",
        paths.len()
    );
    for path in paths {
        check_shipped_scenario_run(&path, dir.path());
    }
}

#[test]
#[cfg_attr(
    not(platen_records),
    ignore = "needs PLATEN_RECORDS_DIR: a folder of PEER NGA records"
)]
fn every_shipped_record_scenario_runs_and_writes_every_input_sample_with_the_contract_columns() {
    let dir = tempfile::tempdir().unwrap();
    let paths = shipped_scenarios().0;
    assert!(paths.len() >= 2, "{paths:?}");
    for path in paths {
        check_shipped_scenario_run(&path, dir.path());
    }
}

/// Without the records a scenario that needs one stops cleanly, says where to get them and
/// writes nothing (the child runs without `PLATEN_RECORDS_DIR` whether or not it is set here).
#[test]
fn without_the_records_a_record_scenario_stops_with_exit_3_naming_platen_records_dir() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    for path in shipped_scenarios().0 {
        let o = Command::new(env!("CARGO_BIN_EXE_platen"))
            .args(["simulate", path.to_str().unwrap(), "--out"])
            .arg(&out)
            .env_remove("PLATEN_RECORDS_DIR")
            .output()
            .expect("run platen");
        assert_eq!(o.status.code(), Some(3), "{}", path.display());
        assert!(stderr(&o).contains("PLATEN_RECORDS_DIR"), "{}", stderr(&o));
        assert!(!out.exists(), "{}", path.display());
    }
}

#[test]
fn a_forward_summary_reports_stick_phases_and_solver_statistics() {
    let o = platen(&["simulate", &scenario("paper-forward-force.json"), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["direction"], "forward");
    assert_eq!(s["samples"], 10241);
    assert_eq!(s["breakaways"], 1);
    let stick = s["stick_time_s"].as_f64().unwrap();
    assert!((stick - 0.3633).abs() < 1e-3, "{stick}");
    assert_eq!(s["solver"]["steps"], 10240);
    assert_eq!(s["limit_exceedances"].as_array().unwrap().len(), 0);
}

/// The inverse of the identified model is Eq. 23 (plus Eq. 22's low-velocity term, switched
/// off here): F_A = Mₑü + Kₑu + (Cₑ|u̇|^α + F_μ)·sign(u̇), recomputed from the written u, v, a.
/// Both sides are the same arithmetic on the same numbers, so 1e-9 relative is loose.
#[test]
fn the_inverse_reproduces_eq_23_to_1e_9_relative() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("s.json");
    std::fs::write(
        &sc,
        r#"{"model": {"preset": "lhpost-2008", "identified": {"low_velocity_force_n": 0}},
            "excitation": {"sine_motion": {"amplitude_m": 0.2, "frequency_hz": 0.6}},
            "duration_s": 5}"#,
    )
    .unwrap();
    let out = dir.path().join("f.csv");
    let o = platen(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = read_csv(&out);
    let (m, k, f_mu, c) = (144e3, 1.266e6, 0.0044 * 5783e3, 44.58e3);
    let peak = rows.iter().map(|r| r[4].abs()).fold(0.0, f64::max);
    for r in &rows {
        let (u, v, a, f) = (r[1], r[2], r[3], r[4]);
        let eq23 = m * a + k * u + (c * v.abs().sqrt() + f_mu) * v.signum() * f64::from(v != 0.0);
        assert!(
            (f - eq23).abs() <= 1e-9 * peak,
            "t = {}: {f} vs {eq23}",
            r[0]
        );
    }
}

#[test]
fn the_same_scenario_gives_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    for out in [&a, &b] {
        let o = platen(&[
            "simulate",
            &scenario("full-model-large-stroke.json"),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn model_json_prints_the_identified_keys_and_derived_quantities() {
    let o = platen(&[
        "model",
        "--preset",
        "lhpost-2008",
        "--pressure-mpa",
        "13.8",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in [
        "effective_mass_kg",
        "stiffness_n_per_m",
        "coulomb_force_n",
        "viscous_coefficient",
        "viscous_exponent",
        "low_velocity_force_n",
        "low_velocity_decay_s_per_m",
        "cubic_stiffness_n_per_m",
        "strut_effective_mass_kg",
        "strut_rotational_mass_kg",
        "hold_down_force_n",
        "hinge_friction_coefficient",
    ] {
        assert!(m[key].is_number(), "missing {key}");
    }
    assert_eq!(m["effective_mass_kg"], 144000.0);
    assert!((m["coulomb_force_n"].as_f64().unwrap() - 25445.2).abs() < 0.01);
    let half = platen(&["model", "--pressure-mpa", "6.9", "--json"]);
    let h: serde_json::Value = serde_json::from_slice(&half.stdout).unwrap();
    assert_eq!(
        h["stiffness_n_per_m"].as_f64().unwrap() * 2.0,
        m["stiffness_n_per_m"].as_f64().unwrap()
    );
}

/// Writes `json` as a scenario in a fresh folder, runs simulate with --out, and returns the
/// exit code, stderr and whether an output file appeared.
fn run_bad(json: &str) -> (i32, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("bad.json");
    std::fs::write(&sc, json).unwrap();
    std::fs::write(
        dir.path().join("force.csv"),
        "t_s,force_n\n0,0\n0.5,1\n1,2\n",
    )
    .unwrap();
    let out = dir.path().join("out.csv");
    let o = platen(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    (o.status.code().unwrap_or(-1), stderr(&o), out.exists())
}

#[test]
fn bad_scenarios_fail_with_the_json_path_and_no_output() {
    let cases: &[(&str, &str)] = &[
        (
            r#"{"model": {"preset": "lhpost-2008", "colour": 1}, "excitation": {"force_csv": "force.csv"}}"#,
            "model",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "force.csv"}, "extra": 1}"#,
            "extra",
        ),
        (
            r#"{"model": {"preset": "lhpost-1999"}, "excitation": {"force_csv": "force.csv"}}"#,
            "model.preset",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": -5}}, "excitation": {"force_csv": "force.csv"}}"#,
            "model.identified.effective_mass_kg",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008", "full": {"strut_viscous_exponent": 2}}, "excitation": {"force_csv": "force.csv"}}"#,
            "model.full.strut_viscous_exponent",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "force.csv"}, "integrator": {"method": "rk4", "step_s": 0}}"#,
            "integrator.step_s",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "force.csv"}, "integrator": {"method": "rk4", "step_s": 0.3}}"#,
            "integrator.step_s",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "missing.csv"}}"#,
            "missing.csv",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "force.csv"}, "duration_s": 5}"#,
            "duration_s",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {}}"#,
            "excitation",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "force.csv""#,
            "line 1",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008", "hold_down_pressure_mpa": -1}, "excitation": {"force_csv": "force.csv"}}"#,
            "hold_down_pressure_mpa",
        ),
        (
            r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"sine_force": {"amplitude_n": 1, "frequency_hz": 1}}}"#,
            "duration_s",
        ),
    ];
    for (json, location) in cases {
        let (code, err, wrote) = run_bad(json);
        assert_eq!(code, 3, "{json}: exit {code}, {err}");
        assert!(
            err.contains(location),
            "{json}: message does not name {location}: {err}"
        );
        assert!(
            err.contains("bad.json") || err.contains(".csv"),
            "{json}: message does not name the file: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!wrote, "{json}: output written despite the error");
    }
}

#[test]
fn a_bad_force_record_is_reported_with_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("s.json");
    std::fs::write(
        &sc,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv"}}"#,
    )
    .unwrap();
    for (csv, needle) in [
        ("t_s,force_n\n0,0\n0.5,abc\n1,2\n", "line 3"),
        ("t_s,force_n\n0,0\n0.5,NaN\n1,2\n", "line 3"),
        ("t_s,force_n\n0,0\n0.5,1\n0.4,2\n", "line 4"),
        ("t_s,force\n0,0\n0.5,1\n", "force_n"),
    ] {
        std::fs::write(dir.path().join("f.csv"), csv).unwrap();
        let o = platen(&["simulate", sc.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{csv}: {err}");
        assert!(
            err.contains("f.csv") && err.contains(needle),
            "{csv}: {err}"
        );
    }
    // A dropped sample in a 1024 Hz record: the interval that ends on line 13 is doubled.
    let mut csv = String::from("t_s,force_n\n");
    for j in (0..40).filter(|&j| j != 11) {
        csv.push_str(&format!("{},{}\n", j as f64 / 1024.0, j));
    }
    std::fs::write(dir.path().join("f.csv"), csv).unwrap();
    let o = platen(&["simulate", sc.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("line 13") && err.contains("uniform"), "{err}");
}

#[test]
fn a_failed_run_leaves_the_previous_output_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    std::fs::write(&out, "previous result\n").unwrap();
    let sc = dir.path().join("s.json");
    std::fs::write(
        &sc,
        r#"{"model": {"preset": "nope"}, "excitation": {"force_csv": "f.csv"}}"#,
    )
    .unwrap();
    let o = platen(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(3));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "previous result\n");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "no temporary file left behind"
    );
}

#[test]
fn an_unwritable_output_path_is_an_io_error() {
    // A file where the output's folder should be (a missing folder is created).
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let out = file.join("out.csv");
    let o = platen(&[
        "simulate",
        &scenario("s9-sine-motion.json"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    assert!(stderr(&o).contains("out.csv"));
}

/// An inverse run from a motion CSV with displacement only (a lab's displacement channel):
/// the force follows from the derived velocity and acceleration.
#[test]
fn an_inverse_run_accepts_a_displacement_only_motion_csv() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("t_s,u_m,extra\n");
    for j in 0..=2048 {
        let t = j as f64 / 1024.0;
        csv.push_str(&format!(
            "{t},{},7\n",
            0.1 * (std::f64::consts::PI * t).sin()
        ));
    }
    std::fs::write(dir.path().join("m.csv"), csv).unwrap();
    let sc = dir.path().join("s.json");
    std::fs::write(
        &sc,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "m.csv"}}"#,
    )
    .unwrap();
    let out = dir.path().join("f.csv");
    let o = platen(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = read_csv(&out);
    assert_eq!(rows.len(), 2049);
    // Mid-record, v and a are the derivatives of 0.1·sin(πt) to second order in Δt.
    let r = &rows[700];
    let t = r[0];
    let w = std::f64::consts::PI;
    assert!((r[2] - 0.1 * w * (w * t).cos()).abs() < 1e-6, "{r:?}");
    assert!((r[3] + 0.1 * w * w * (w * t).sin()).abs() < 1e-5, "{r:?}");
}

/// A Dopri5 scenario reports its solver statistics and an energy residual, and agrees with
/// the RK4 run of the same record (both within 1e-8 m of the reference).
#[test]
fn a_dopri5_scenario_reports_statistics_and_energy_and_agrees_with_rk4() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    let o = platen(&[
        "simulate",
        &scenario("paper-forward-force-dopri5.json"),
        "--out",
        a.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["solver"]["method"], "dopri5");
    for key in [
        "steps",
        "accepted_steps",
        "rejected_steps",
        "rhs_evaluations",
        "events_located",
    ] {
        assert!(s["solver"][key].is_u64(), "solver.{key}");
    }
    assert!(s["energy"]["relative_residual"].as_f64().unwrap().abs() < 1e-9);
    let o = platen(&[
        "simulate",
        &scenario("paper-forward-force.json"),
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, ra) = read_csv(&a);
    let (_, rb) = read_csv(&b);
    let du = ra
        .iter()
        .zip(&rb)
        .map(|(x, y)| (x[1] - y[1]).abs())
        .fold(0.0, f64::max);
    assert!(du < 2e-8, "{du}");
}

#[test]
fn bad_dopri5_tolerances_name_their_json_path() {
    for (json, path) in [
        (r#"{"method": "dopri5", "rtol": 0}"#, "integrator.rtol"),
        (
            r#"{"method": "dopri5", "rtol": 1e-6, "atol": -1}"#,
            "integrator.atol",
        ),
        (r#"{"method": "dopri5", "tol": 1e-6}"#, "integrator"),
        (r#"{"method": "dop853"}"#, "integrator"),
    ] {
        let (code, err, wrote) = run_bad(&format!(
            r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"force_csv": "force.csv"}}, "integrator": {json}}}"#
        ));
        assert_eq!(code, 3, "{json}: {err}");
        assert!(err.contains(path), "{json}: {err}");
        assert!(!wrote);
    }
}

/// The paper's earthquake test: Northridge 1994 Tarzana at 100 % from the real record. The
/// table respects all four limits: PGD 0.32 m < 0.75 m, PGV 1.13 m/s < 1.8 m/s,
/// PGA 1.78 g < 4.2 g, and the force 144 t × 17.4 m/s² ≈ 2.5 MN < 6.8 MN. The 1024 Hz samples
/// of the straight lines between the 50 Hz record's samples fall 0.36/1024 s after its
/// 1.7794 g peak sample, where the line has dropped by 291 m/s³ × 0.35 ms = 0.1 m/s²
/// (0.0104 g): the peak acceleration is checked to 0.015 g.
#[test]
#[cfg_attr(
    not(platen_records),
    ignore = "needs PLATEN_RECORDS_DIR: a folder holding RSN1087_NORTHR_TAR090.AT2"
)]
fn the_tarzana_scenario_runs_from_the_real_record_within_the_table_limits() {
    let o = platen(&[
        "simulate",
        &scenario("northridge-tarzana-100.json"),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let g = 9.80665;
    assert!(
        (s["peak_a_m_s2"].as_f64().unwrap() / g - 1.7794).abs() < 0.015,
        "{s}"
    );
    assert!(
        (s["peak_u_m"].as_f64().unwrap().abs() - 0.3241).abs() < 0.01,
        "{s}"
    );
    let f = s["peak_force_n"].as_f64().unwrap();
    assert!((2.3e6..2.8e6).contains(&f.abs()), "{f}");
    assert_eq!(s["limit_exceedances"].as_array().unwrap().len(), 0);
    for key in ["stroke_m", "velocity_m_s", "acceleration_m_s2", "force_n"] {
        assert_eq!(s["limits"][key]["respected"], true, "{key}: {s}");
    }
}

/// A lab's export: its own headers and units (time in ms, displacement in mm, acceleration in
/// g) mapped by `columns`; the run equals the one from the same data in SI columns.
#[test]
fn a_lab_export_with_its_own_channel_names_and_units_is_mapped() {
    let dir = tempfile::tempdir().unwrap();
    let (mut lab, mut si) = (
        String::from("Time,Table disp,Table acc,Other\n"),
        String::from("t_s,u_m,a_m_s2\n"),
    );
    for j in 0..=1024 {
        let t = j as f64 / 256.0;
        let w = std::f64::consts::PI;
        let (u, a) = (0.05 * (w * t).sin(), -0.05 * w * w * (w * t).sin());
        lab.push_str(&format!(
            "{},{},{},1\n",
            t * 1000.0,
            u * 1000.0,
            a / 9.80665
        ));
        si.push_str(&format!("{t},{u},{a}\n"));
    }
    std::fs::write(dir.path().join("lab.csv"), lab).unwrap();
    std::fs::write(dir.path().join("si.csv"), si).unwrap();
    let lab_json = r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "lab.csv", "columns": {
        "t_s": {"name": "Time", "unit": "ms"}, "u_m": {"name": "Table disp", "unit": "mm"},
        "a_m_s2": {"name": "Table acc", "unit": "g"}}}}"#;
    std::fs::write(dir.path().join("lab.json"), lab_json).unwrap();
    std::fs::write(
        dir.path().join("si.json"),
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "si.csv"}}"#,
    )
    .unwrap();
    let run = |name: &str| {
        let out = dir.path().join(format!("{name}.out.csv"));
        let o = platen(&[
            "simulate",
            dir.path().join(format!("{name}.json")).to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        read_csv(&out).1
    };
    let (a, b) = (run("lab"), run("si"));
    assert_eq!(a.len(), b.len());
    // Unit conversions round in the last bits: compare each column to 1e-9 of its own scale.
    // Where the velocity (the crossover estimate from u and a) is zero to rounding, 1e-15 m/s,
    // the √|v| law turns that rounding into Cₑ·√(1e-14 m/s) = 44.58 kN × 1e-7 ≈ 5 mN of force
    // (columns force_n and dissipative_force_n): allowed on top.
    for c in 0..b[0].len() {
        let scale = b.iter().map(|r| r[c].abs()).fold(0.0, f64::max).max(1e-12);
        let sqrt_law = if c == 4 || c == 7 { 5e-3 } else { 0.0 };
        for (x, y) in a.iter().zip(&b) {
            assert!(
                (x[c] - y[c]).abs() <= 1e-9 * scale + sqrt_law,
                "column {c}: {x:?} vs {y:?}"
            );
        }
    }
    // A unit of the wrong kind is an input error naming its JSON path.
    std::fs::write(
        dir.path().join("bad.json"),
        lab_json.replace(r#""unit": "mm""#, r#""unit": "g""#),
    )
    .unwrap();
    let o = platen(&["simulate", dir.path().join("bad.json").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3));
    assert!(
        stderr(&o).contains("excitation.columns.u_m.unit"),
        "{}",
        stderr(&o)
    );
}

/// A reader that closes the pipe early (`platen model | head -1`) stops the verb quietly:
/// exit 0, nothing on stderr, no panic. The reader here closes before the first write.
#[test]
fn a_closed_standard_output_is_not_a_panic() {
    for args in [&["model"][..], &["schema"], &["model", "--json"]] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_platen"))
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {:?} {stderr}", out.status);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
    }
}

#[test]
fn out_creates_its_missing_folder_as_plot_does() {
    // issue 38: `--plot out/figs` made its folder where `--out out/run.csv` refused a missing
    // `out/`. Both create what is missing now, nested folders included.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results").join("today").join("run.csv");
    let plot = dir.path().join("figures").join("today");
    let o = platen(&[
        "simulate",
        &scenario("sr9-like-sine-force.json"),
        "--out",
        out.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (header, rows) = read_csv(&out);
    assert_eq!(header[0], "t_s");
    assert!(rows.len() > 100);
    assert!(plot.read_dir().unwrap().count() > 0);
}
