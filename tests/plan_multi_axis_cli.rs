//! `platen plan` on a multi-axis scenario (the `lhpost6` preset): a three-component target
//! is planned (its JSON keys per axis and per iteration, the six-DOF drive, the figures), the
//! drive replays through `simulate` to the run the plan reports, and what it cannot take is
//! refused with the file or the option named, nothing written.

use std::fs;
use std::path::{Path, PathBuf};

use serde_json::Value;

mod common;
use common::{platen, stderr};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    fs::write(&path, text).unwrap();
    path
}

/// 0.5 s at 128 Hz: a 3 Hz sine on x under half-cosine ramps of 0.15 s, y and z held.
fn target(dir: &Path) -> PathBuf {
    let mut text = String::from("t_s,x_m_s2\n");
    for j in 0..=64 {
        let t = f64::from(j) / 128.0;
        let ramp = |x: f64| 0.5 - 0.5 * (std::f64::consts::PI * (x / 0.15).clamp(0.0, 1.0)).cos();
        let a = 1.5 * ramp(t) * ramp(0.5 - t) * (std::f64::consts::TAU * 3.0 * t).sin();
        text += &format!("{t},{a:e}\n");
    }
    write(dir, "target.csv", &text)
}

#[test]
fn a_three_component_plan_writes_its_drive_summary_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = write(dir.path(), "l6.json", r#"{"table": {"preset": "lhpost6"}}"#);
    let target = target(dir.path());
    let drive = dir.path().join("drive.csv");
    let figures = dir.path().join("figures");
    let o = platen(&[
        "plan",
        scenario.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
        "--iterations",
        "1",
        "--no-max-scale",
        "--plot",
        figures.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["feasible"], Value::Bool(true));
    assert!(s["binds_first"].is_null() && s["stall_reason"].is_null() && s["max_scale"].is_null());
    let it = s["iterations"].as_array().unwrap();
    assert_eq!(it.len(), 2);
    for axis in ["x", "y", "z"] {
        assert!(
            it[0]["axes"][axis]["rms_acceleration_error_m_s2"].is_number(),
            "{axis}"
        );
    }
    assert!(it[0]["axes"]["x"]["acceleration_nrmse"].is_number());
    assert!(
        it[0]["axes"]["y"]["acceleration_nrmse"].is_null(),
        "y is held at zero"
    );
    assert!(s["margins"]
        .as_array()
        .unwrap()
        .iter()
        .any(|m| m["limit"] == "v1.uplift"));
    assert_eq!(s["figures"].as_array().unwrap().len(), 8);
    for name in [
        "table-plan-acceleration",
        "table-plan-spectra",
        "table-plan-convergence",
        "table-plan-margins",
    ] {
        assert!(figures.join(format!("{name}.svg")).exists(), "{name}");
    }
    let text = fs::read_to_string(&drive).unwrap();
    assert!(text.starts_with("t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad\n"));
    assert_eq!(text.lines().count(), 66);
    // The drive replayed through `simulate` is the run the plan reports for its best
    // iteration: each axis's signed peak acceleration is the plan's.
    let replay = write(
        dir.path(),
        "replay.json",
        &serde_json::json!({"table": {"preset": "lhpost6"},
            "excitation": {"motion_csv": drive}})
        .to_string(),
    );
    let run = dir.path().join("run.csv");
    let o = platen(&[
        "simulate",
        replay.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = fs::read_to_string(&run).unwrap();
    let mut lines = r.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let best = s["best_iteration"].as_u64().unwrap() as usize;
    for axis in ["x", "y", "z"] {
        let col = header
            .iter()
            .position(|c| *c == format!("{axis}_m_s2"))
            .unwrap();
        let peak = rows
            .iter()
            .map(|r| r[col])
            .fold(0.0_f64, |m, v| if v.abs() > m.abs() { v } else { m });
        let reported = it[best]["axes"][axis]["peak_a_m_s2"].as_f64().unwrap();
        // To the last bit but one: serde_json's default parser may miss the nearest double
        // by an ulp (the library test replays to the bit).
        assert!(
            (peak - reported).abs() <= 2.0 * f64::EPSILON * reported.abs(),
            "{axis}: {peak} against {reported}"
        );
    }
}

#[test]
fn what_a_three_component_plan_cannot_take_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = write(dir.path(), "l6.json", r#"{"table": {"preset": "lhpost6"}}"#);
    let target = target(dir.path());
    let no_axis = write(dir.path(), "no-axis.csv", "t_s,roll_rad_s2\n0,0\n0.1,0\n");
    let drive = dir.path().join("drive.csv");
    let base = [
        "plan",
        scenario.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
    ];
    for (extra, expect) in [
        (vec!["--target", no_axis.to_str().unwrap()], "no-axis.csv"),
        (
            vec!["--target", target.to_str().unwrap(), "--frf", "measured"],
            "--frf measured",
        ),
        (
            vec!["--target", target.to_str().unwrap(), "--report", "r.html"],
            "--report",
        ),
    ] {
        let mut args: Vec<&str> = base.to_vec();
        args.extend(extra);
        let o = platen(&args);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(expect), "{expect}: {}", stderr(&o));
        assert!(!drive.exists(), "nothing written");
    }
}

#[test]
fn a_fast_three_component_target_is_resampled_and_each_axis_accepted_against_its_spectrum() {
    // issue 38: a three-component target sampled faster than the controller was refused
    // where a uniaxial one is resampled; and its acceptance check took no required spectrum.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scenario = write(d, "l6.json", r#"{"table": {"preset": "lhpost6"}}"#);
    // 0.5 s at 4096 Hz (the LHPOST6's controller runs at 2048 Hz): the 3 Hz sine of
    // `target` on x, half of it at 5 Hz on z.
    let mut text = String::from("t_s,x_m_s2,z_m_s2\n");
    for j in 0..=2048 {
        let t = f64::from(j) / 4096.0;
        let ramp = |x: f64| 0.5 - 0.5 * (std::f64::consts::PI * (x / 0.15).clamp(0.0, 1.0)).cos();
        let env = ramp(t) * ramp(0.5 - t);
        let x = 1.5 * env * (std::f64::consts::TAU * 3.0 * t).sin();
        let z = 0.75 * env * (std::f64::consts::TAU * 5.0 * t).sin();
        text += &format!("{t},{x:e},{z:e}\n");
    }
    let target = write(d, "fast.csv", &text);
    // An RRS for x only, far below anything achieved: every one of its periods is outside.
    let rrs = write(
        d,
        "rrs.csv",
        "period_s,x_psa_g\n0.1,1e-6\n0.2,1e-6\n0.5,1e-6\n1,1e-6\n",
    );
    let drive = d.join("drive.csv");
    let o = platen(&[
        "plan",
        scenario.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "--rrs",
        rrs.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
        "--iterations",
        "0",
        "--no-max-scale",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["target"]["sample_rate_hz"], 4096.0);
    assert_eq!(s["target"]["drive_sample_rate_hz"], 2048.0);
    let warnings = s["warnings"].to_string();
    assert!(warnings.contains("resampled to 2048 Hz"), "{warnings}");
    // The drive at the controller's rate: 0.5 s at 2048 Hz.
    let text = fs::read_to_string(&drive).unwrap();
    assert_eq!(text.lines().count(), 1 + 1025);
    let acceptance = s["drive"]["spectrum_acceptance"].as_object().unwrap();
    let axes: Vec<&str> = acceptance.keys().map(String::as_str).collect();
    assert_eq!(axes, ["x", "z"], "the axes given, y held");
    let x = &acceptance["x"];
    assert_eq!(x["rrs"], rrs.to_str().unwrap());
    assert_eq!(x["count"], 4);
    assert_eq!(x["within"], false);
    let periods: Vec<f64> = x["outside"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["period_s"].as_f64().unwrap())
        .collect();
    assert_eq!(periods, [0.1, 0.2, 0.5, 1.0]);
    assert!(acceptance["z"]["rrs"].is_null());
    assert_eq!(acceptance["z"]["count"], 50);
    assert!(
        warnings.contains("achieved x response spectrum"),
        "{warnings}"
    );
    // In text, one line per axis.
    let o = platen(&[
        "plan",
        scenario.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "--rrs",
        rrs.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
        "--iterations",
        "0",
        "--no-max-scale",
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("x response spectrum") && out.contains("z response spectrum"),
        "{out}"
    );
    // An RRS without any axis's column is refused naming the file, nothing run.
    let none = write(d, "none.csv", "period_s,psa_g\n0.5,0.2\n");
    fs::remove_file(&drive).unwrap();
    let o = platen(&[
        "plan",
        scenario.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "--rrs",
        none.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(3));
    assert!(
        stderr(&o).contains("none.csv") && stderr(&o).contains("x_psa_m_s2"),
        "{}",
        stderr(&o)
    );
    assert!(!drive.exists());
}

#[test]
fn three_component_drives_iterated_at_half_level_are_scaled_up_and_run_at_full_level() {
    // issue 38: `--iterate-at` on a multi-axis table: the drives are iterated at half the
    // target, doubled, and run once at full level; that run is the drives' (`drive.achieved`),
    // and the drives written replay through `simulate` to it.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scenario = write(d, "l6.json", r#"{"table": {"preset": "lhpost6"}}"#);
    let target = target(d);
    let drive = d.join("drive.csv");
    let o = platen(&[
        "plan",
        scenario.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
        "--iterations",
        "1",
        "--no-max-scale",
        "--iterate-at",
        "0.5",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["iterate_at"], 0.5);
    let x = |r: &Value, key: &str| r["axes"]["x"][key].as_f64().unwrap();
    // The iteration's first run commands half the target (exactly: a power of two).
    assert_eq!(
        x(&s["iterations"][0], "peak_drive_u_m"),
        0.5 * s["target"]["axes"]["x"]["peak_u_m"].as_f64().unwrap()
    );
    let best = s["best_iteration"].as_u64().unwrap() as usize;
    let low = &s["drive"]["at_iteration_level"];
    assert_eq!(*low, s["iterations"][best]);
    let achieved = &s["drive"]["achieved"];
    // Doubled exactly in the JSON; serde_json's default float parser (no `float_roundtrip`)
    // may read a printed number one unit in the last place off, so compare to 1e-15.
    let (full, twice_low) = (
        x(achieved, "peak_drive_u_m"),
        2.0 * x(low, "peak_drive_u_m"),
    );
    assert!(
        (full - twice_low).abs() <= 1e-15 * twice_low,
        "{full} against {twice_low}"
    );
    eprintln!(
        "overall acceleration NRMSE at 50 %: {}; scaled up: {}",
        low["acceleration_nrmse"], achieved["acceleration_nrmse"]
    );
    // The drives written, replayed: the full-level run reported.
    let replay = write(
        d,
        "replay.json",
        &serde_json::json!({"table": {"preset": "lhpost6"},
            "excitation": {"motion_csv": drive}})
        .to_string(),
    );
    let run = d.join("run.csv");
    let o = platen(&[
        "simulate",
        replay.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = platen::io::csv::read_table(&run, &["x_m_s2"], &[]).unwrap();
    let peak = table
        .column("x_m_s2")
        .unwrap()
        .iter()
        .fold(0.0_f64, |m, v| if v.abs() > m.abs() { *v } else { m });
    let reported = x(achieved, "peak_a_m_s2");
    // To the last bit but one (serde_json's parser, as above).
    assert!(
        (peak - reported).abs() <= 2.0 * f64::EPSILON * reported.abs(),
        "{peak} against {reported}"
    );
}

/// issue 55 (item 6): a target the LHPOST6 cannot reach (3 m of x, four times its 0.75 m
/// stroke) drives the x actuators past the end of their chambers, and the plan exited 3 with
/// a numerical failure ("state became non-finite", or "the platen reached the end of its
/// actuators"). It is an answer: not feasible, an actuator's `stroke_m` (the stroke the
/// commands ask, four times its limit) binds, not iterated (`stop` `not_run`), no drive
/// written, exit 0, as the uniaxial plan answers a target its platen cannot reach.
#[test]
fn a_target_past_the_lhpost6_stroke_is_infeasible_not_a_numerical_failure() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = write(dir.path(), "l6.json", r#"{"table": {"preset": "lhpost6"}}"#);
    // 4 s at 128 Hz: a half-cosine pulse of x up to 3 m and back.
    let mut text = String::from("t_s,x_m\n");
    for j in 0..=512 {
        let t = f64::from(j) / 128.0;
        let u = 3.0 * (0.5 - 0.5 * (std::f64::consts::TAU * t / 4.0).cos());
        text += &format!("{t},{u:e}\n");
    }
    let target = write(dir.path(), "three-metres.csv", &text);
    let drive = dir.path().join("drive.csv");
    let args = [
        "plan",
        scenario.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
        "--no-max-scale",
    ];
    let o = platen(&[&args[..], &["--json"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["feasible"], Value::Bool(false));
    assert_eq!(s["stop"], "not_run");
    assert!(s["iterations"].as_array().unwrap().is_empty());
    assert!(s["best_iteration"].is_null() && s["drive"].is_null() && s["frf"].is_null());
    let worst = &s["limiting"][0];
    assert!(
        worst["limit"].as_str().unwrap().ends_with(".stroke_m"),
        "{worst}"
    );
    let ratio = worst["ratio"].as_f64().unwrap();
    assert!(ratio > 3.0 && ratio < 5.0, "3 m asked of 0.75 m: {worst}");
    assert!(s["binds_first"]["limit"]
        .as_str()
        .unwrap()
        .ends_with(".stroke_m"));
    assert!(
        stderr(&o).contains("more stroke than the actuators have")
            && stderr(&o).contains("no drives"),
        "{}",
        stderr(&o)
    );
    assert!(!drive.exists(), "no drive written");
    // In words too, with the same exit code.
    let o = platen(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("feasible: no"), "{text}");
    assert!(
        text.contains("binds first: ") && text.contains(".stroke_m"),
        "{text}"
    );
    assert!(text.contains("drive iteration: not run"), "{text}");
    assert!(!drive.exists(), "no drive written");
}
