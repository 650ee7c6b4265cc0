//! Fifty-odd malformed inputs, one or more per class: every one ends with a non-zero exit, a
//! message naming where the problem is (file, line or JSON path), no panic or backtrace, and no
//! output file left behind.

use std::path::Path;
use std::process::Command;

/// A valid force record and motion record, 1024 Hz, 1 s.
fn good_force() -> String {
    let mut s = String::from("t_s,force_n\n");
    for j in 0..=1024 {
        s.push_str(&format!(
            "{},{}\n",
            j as f64 / 1024.0,
            1e4 * (j as f64 / 100.0).sin()
        ));
    }
    s
}

fn good_motion() -> String {
    let mut s = String::from("t_s,u_m\n");
    for j in 0..=1024 {
        s.push_str(&format!(
            "{},{}\n",
            j as f64 / 1024.0,
            0.01 * (j as f64 / 100.0).sin()
        ));
    }
    s
}

const AT2_HEAD: &str =
    "PEER NGA STRONG MOTION DATABASE RECORD\nTest, 1/1/2000, Station, 90\nACCELERATION TIME SERIES IN UNITS OF G\n";

struct Case {
    what: &'static str,
    scenario: String,
    files: Vec<(&'static str, String)>,
    /// Text the error message must contain (the location).
    needle: &'static str,
}

fn force_scenario(extra: &str) -> String {
    format!(
        r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"force_csv": "f.csv"}}{extra}}}"#
    )
}

fn motion_scenario(excitation: &str) -> String {
    format!(r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {excitation}}}"#)
}

fn cases() -> Vec<Case> {
    let mut v = Vec::new();
    let mut add = |what: &'static str,
                   scenario: String,
                   files: Vec<(&'static str, String)>,
                   needle: &'static str| {
        v.push(Case {
            what,
            scenario,
            files,
            needle,
        })
    };
    let f = || vec![("f.csv", good_force())];
    // Malformed JSON.
    add(
        "truncated JSON",
        r#"{"model": {"preset": "lhpost-2008""#.into(),
        f(),
        "line 1",
    );
    add(
        "trailing comma",
        force_scenario(",").replace("}}}", "}},}"),
        f(),
        "line 1",
    );
    add("not an object", "[1, 2, 3]".into(), f(), "line 1");
    add("empty file", String::new(), f(), "line 1");
    add("binary garbage", "\u{0}\u{1}\u{2}".into(), f(), "line 1");
    // Unknown keys.
    add(
        "unknown top key",
        force_scenario(r#", "extra": 1"#),
        f(),
        "extra",
    );
    add(
        "unknown model key",
        r#"{"model": {"preset": "lhpost-2008", "mass": 1}, "excitation": {"force_csv": "f.csv"}}"#
            .into(),
        f(),
        "model",
    );
    add("unknown identified key", r#"{"model": {"preset": "lhpost-2008", "identified": {"mass_kg": 1}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified");
    add("unknown full key", r#"{"model": {"preset": "lhpost-2008", "full": {"platen_kg": 1}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.full");
    add(
        "unknown excitation key",
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv", "gain": 2}}"#
            .into(),
        f(),
        "excitation",
    );
    add(
        "unknown integrator key",
        force_scenario(r#", "integrator": {"method": "rk4", "h": 0.001}"#),
        f(),
        "integrator",
    );
    add(
        "unknown initial key",
        force_scenario(r#", "initial": {"x_m": 0}"#),
        f(),
        "initial",
    );
    add(
        "unknown sine key",
        motion_scenario(r#"{"sine_motion": {"amplitude_m": 0.1, "frequency_hz": 1, "phase": 0}}"#),
        vec![],
        "excitation.sine_motion",
    );
    // Wrong types.
    add(
        "preset not a string",
        r#"{"model": {"preset": 2008}, "excitation": {"force_csv": "f.csv"}}"#.into(),
        f(),
        "model.preset",
    );
    add("mass as string", r#"{"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": "heavy"}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified.effective_mass_kg");
    add(
        "duration as array",
        force_scenario(r#", "duration_s": [1]"#),
        f(),
        "duration_s",
    );
    add(
        "step as bool",
        force_scenario(r#", "integrator": {"method": "rk4", "step_s": true}"#),
        f(),
        "integrator",
    );
    add(
        "missing model",
        r#"{"excitation": {"force_csv": "f.csv"}}"#.into(),
        f(),
        "model",
    );
    add(
        "missing excitation",
        r#"{"model": {"preset": "lhpost-2008"}}"#.into(),
        f(),
        "excitation",
    );
    // Impossible parameters.
    add("negative mass", r#"{"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": -1}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified.effective_mass_kg");
    add("zero mass", r#"{"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": 0}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified.effective_mass_kg");
    add("negative stiffness", r#"{"model": {"preset": "lhpost-2008", "identified": {"stiffness_n_per_m": -5}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified.stiffness_n_per_m");
    add("alpha above 1", r#"{"model": {"preset": "lhpost-2008", "identified": {"viscous_exponent": 1.5}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified.viscous_exponent");
    add("negative friction", r#"{"model": {"preset": "lhpost-2008", "identified": {"coulomb_force_n": -1}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.identified.coulomb_force_n");
    add("zero strut height", r#"{"model": {"preset": "lhpost-2008", "full": {"strut_height_m": 0}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.full.strut_height_m");
    add("gamma below 1", r#"{"model": {"preset": "lhpost-2008", "full": {"gas_heat_capacity_ratio": 0.5}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.full.gas_heat_capacity_ratio");
    add("negative pressure", r#"{"model": {"preset": "lhpost-2008", "hold_down_pressure_mpa": -2}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model.hold_down_pressure_mpa");
    add(
        "unknown preset",
        r#"{"model": {"preset": "lhpost-2099"}, "excitation": {"force_csv": "f.csv"}}"#.into(),
        f(),
        "model.preset",
    );
    add("both forms", r#"{"model": {"preset": "lhpost-2008", "identified": {}, "full": {}}, "excitation": {"force_csv": "f.csv"}}"#.into(), f(), "model");
    add(
        "zero step",
        force_scenario(r#", "integrator": {"method": "rk4", "step_s": 0}"#),
        f(),
        "integrator.step_s",
    );
    add(
        "negative step",
        force_scenario(r#", "integrator": {"method": "rk4", "step_s": -0.001}"#),
        f(),
        "integrator.step_s",
    );
    add(
        "step not dividing",
        force_scenario(r#", "integrator": {"method": "rk4", "step_s": 0.0007}"#),
        f(),
        "integrator.step_s",
    );
    add(
        "zero rtol",
        force_scenario(r#", "integrator": {"method": "dopri5", "rtol": 0}"#),
        f(),
        "integrator.rtol",
    );
    add(
        "negative atol",
        force_scenario(r#", "integrator": {"method": "dopri5", "atol": -1}"#),
        f(),
        "integrator.atol",
    );
    add(
        "dop853 not offered",
        force_scenario(r#", "integrator": {"method": "dop853"}"#),
        f(),
        "integrator",
    );
    add(
        "zero duration",
        force_scenario(r#", "duration_s": 0"#),
        f(),
        "duration_s",
    );
    add(
        "duration longer than record",
        force_scenario(r#", "duration_s": 5"#),
        f(),
        "f.csv",
    );
    add("lowpass above Nyquist", r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "f.csv", "lowpass_hz": 600}}"#.into(), f(), "excitation.lowpass_hz");
    add(
        "lowpass on a motion",
        motion_scenario(
            r#"{"sine_motion": {"amplitude_m": 0.1, "frequency_hz": 1}, "lowpass_hz": 2}"#,
        ),
        vec![],
        "excitation.lowpass_hz",
    );
    add(
        "two excitations",
        motion_scenario(r#"{"force_csv": "f.csv", "motion_csv": "m.csv"}"#),
        f(),
        "excitation",
    );
    add("integrator on inverse", r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "m.csv"}, "integrator": {"method": "rk4"}}"#.into(), vec![("m.csv", good_motion())], "integrator");
    add("negative frequency", r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"sine_motion": {"amplitude_m": 0.1, "frequency_hz": -1}}, "duration_s": 1}"#.into(), vec![], "excitation.sine_motion.frequency_hz");
    add("triangle arc too big", r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"triangle_motion": {"amplitude_m": 0.01, "velocity_m_s": 1, "reversal_acceleration_m_s2": 1}}, "duration_s": 1}"#.into(), vec![], "excitation.triangle_motion.reversal_acceleration_m_s2");
    add("bad unit", r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "m.csv", "columns": {"u_m": {"unit": "parsec"}}}}"#.into(), vec![("m.csv", good_motion())], "excitation.columns.u_m.unit");
    // Paths.
    add(
        "missing record file",
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "nope.csv"}}"#.into(),
        vec![],
        "nope.csv",
    );
    add(
        "record is a directory",
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "."}}"#.into(),
        vec![],
        "reading",
    );
    add(
        "missing ground-motion record",
        motion_scenario(r#"{"ground_motion": {"record": "NOPE.AT2"}}"#),
        vec![],
        "NOPE.AT2",
    );
    // CSV contents.
    add(
        "missing column",
        force_scenario(""),
        vec![("f.csv", "t_s,force\n0,0\n1,1\n".into())],
        "force_n",
    );
    add(
        "duplicated column",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n,force_n\n0,0,0\n1,1,1\n".into())],
        "force_n",
    );
    add(
        "non-numeric cell",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,0\n1,one\n".into())],
        "line 3",
    );
    add(
        "NaN cell",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,0\n1,NaN\n".into())],
        "line 3",
    );
    add(
        "infinite cell",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,0\n1,inf\n".into())],
        "line 3",
    );
    add(
        "empty record",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n".into())],
        "f.csv",
    );
    add(
        "header only, no newline",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n".into())],
        "f.csv",
    );
    add(
        "single sample",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,1\n".into())],
        "f.csv",
    );
    add(
        "unsorted time",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,0\n2,1\n1,2\n3,3\n".into())],
        "line 4",
    );
    add(
        "duplicate time",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,0\n1,1\n1,2\n".into())],
        "line 4",
    );
    add(
        "ragged row",
        force_scenario(""),
        vec![("f.csv", "t_s,force_n\n0,0\n1\n".into())],
        "line 3",
    );
    add(
        "non-uniform sampling",
        force_scenario(""),
        vec![(
            "f.csv",
            "t_s,force_n\n0,0\n1,1\n2,2\n3.5,3\n4.5,4\n5.5,5\n".into(),
        )],
        "line 5",
    );
    add(
        "empty motion",
        motion_scenario(r#"{"motion_csv": "m.csv"}"#),
        vec![("m.csv", "t_s,u_m\n".into())],
        "m.csv",
    );
    add(
        "motion NaN",
        motion_scenario(r#"{"motion_csv": "m.csv"}"#),
        vec![("m.csv", "t_s,u_m\n0,0\n1,nan\n2,0\n".into())],
        "line 3",
    );
    // PEER records.
    add(
        "AT2 count mismatch",
        motion_scenario(r#"{"ground_motion": {"record": "r.AT2"}}"#),
        vec![(
            "r.AT2",
            format!("{AT2_HEAD}NPTS= 3, DT= .01 SEC\n .1E+00 .2E+00\n"),
        )],
        "line 4",
    );
    add(
        "AT2 bad value",
        motion_scenario(r#"{"ground_motion": {"record": "r.AT2"}}"#),
        vec![(
            "r.AT2",
            format!("{AT2_HEAD}NPTS= 2, DT= .01 SEC\n .1E+00 x\n"),
        )],
        "line 5",
    );
    add(
        "AT2 bad header",
        motion_scenario(r#"{"ground_motion": {"record": "r.AT2"}}"#),
        vec![("r.AT2", "hello\n".into())],
        "line 1",
    );
    add(
        "AT2 zero DT",
        motion_scenario(r#"{"ground_motion": {"record": "r.AT2"}}"#),
        vec![(
            "r.AT2",
            format!("{AT2_HEAD}NPTS= 2, DT= 0 SEC\n .1E+00 .2E+00\n"),
        )],
        "line 4",
    );
    v
}

#[test]
fn every_malformed_input_fails_cleanly_with_its_location_and_writes_nothing() {
    let cases = cases();
    assert!(cases.len() >= 50, "{} cases", cases.len());
    for c in cases {
        let dir = tempfile::tempdir().unwrap();
        let sc = dir.path().join("bad.json");
        std::fs::write(&sc, &c.scenario).unwrap();
        for (name, body) in &c.files {
            std::fs::write(dir.path().join(name), body).unwrap();
        }
        let out = dir.path().join("out.csv");
        let o = Command::new(env!("CARGO_BIN_EXE_platen"))
            .args([
                "simulate",
                sc.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .env_remove("PLATEN_RECORDS_DIR")
            .env("RUST_BACKTRACE", "1")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(
            o.status.code(),
            Some(3),
            "{}: exit {:?}: {err}",
            c.what,
            o.status.code()
        );
        assert!(
            err.contains(c.needle),
            "{}: message lacks {:?}: {err}",
            c.what,
            c.needle
        );
        assert!(
            !err.contains("panicked") && !err.contains("stack backtrace"),
            "{}: {err}",
            c.what
        );
        assert!(err.starts_with("error: "), "{}: {err}", c.what);
        assert!(!Path::new(&out).exists(), "{}: output written", c.what);
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(
            leftovers.is_empty(),
            "{}: temporary files left: {leftovers:?}",
            c.what
        );
    }
}

/// Runs `simulate` on `scenario` (with a good force record beside it) and returns the exit
/// code and stderr; `extra` arguments follow.
fn simulate_bad(scenario: &str, extra: &[&str]) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("bad.json");
    std::fs::write(&sc, scenario).unwrap();
    std::fs::write(dir.path().join("f.csv"), good_force()).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_platen"))
        .args(["simulate", "bad.json"])
        .args(extra)
        .current_dir(dir.path())
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The messages read as sentences: the innermost field of a type error, a file that ends
/// early said so with its line, the field and value said once, an output folder that is a
/// file named as such.
#[test]
fn error_messages_name_the_field_once_and_say_what_is_wrong() {
    for (what, scenario, extra, want, not) in [
        (
            "a string step",
            force_scenario(",\n \"integrator\": {\"method\": \"rk4\",\n  \"step_s\": \"fast\"}"),
            &[][..],
            &[
                "`bad.json`: integrator.step_s (line 3",
                "\"fast\", expected a number",
            ][..],
            &["integrator (line"][..],
        ),
        (
            "a string frequency in a generated motion",
            motion_scenario(r#"{"sine_motion": {"amplitude_m": 0.1, "frequency_hz": "1 Hz"}}"#),
            &[],
            &["excitation.sine_motion.frequency_hz (line 1"],
            &[],
        ),
        (
            "a list where a number belongs",
            force_scenario(r#", "initial": {"u_m": [0]}"#),
            &[],
            &["initial.u_m (line 1", "sequence, expected a number"],
            &[],
        ),
        (
            "a file cut off",
            "{\n  \"model\": {\"preset\": \"lhpost-2008\"},\n".to_owned(),
            &[],
            &["`bad.json`: line 3: the file ends before the JSON is complete"],
            &["?", "EOF"],
        ),
        (
            "an empty file",
            String::new(),
            &[],
            &["`bad.json`: line 1: the file is empty"],
            &["EOF"],
        ),
        (
            "a step that does not divide the interval",
            force_scenario(r#", "integrator": {"method": "rk4", "step_s": 0.0007}"#),
            &[],
            &["integrator.step_s = 0.0007: expected a step that divides the sample interval"],
            &["expected step_s"],
        ),
        (
            "a zero step",
            force_scenario(r#", "integrator": {"method": "rk4", "step_s": 0}"#),
            &[],
            &["integrator.step_s = 0: expected a finite step > 0 s"],
            &["is invalid: expected"],
        ),
        (
            "a huge step",
            force_scenario(r#", "integrator": {"method": "rk4", "step_s": 1e300}"#),
            &[],
            &["integrator.step_s = 1e300: expected"],
            &["000000000000"],
        ),
    ] {
        let (code, err) = simulate_bad(&scenario, extra);
        assert_eq!(code, Some(3), "{what}: {err}");
        for w in want {
            assert!(err.contains(w), "{what}: no {w:?} in {err}");
        }
        for n in not {
            assert!(!err.contains(n), "{what}: {n:?} in {err}");
        }
        assert!(err.matches("expected").count() <= 1, "{what}: {err}");
    }
    // The output's folder is a file (a missing one is created, as --plot's): exit 5, and
    // the message says so.
    let (code, err) = simulate_bad(&force_scenario(""), &["--out", "f.csv/out.csv"]);
    assert_eq!(code, Some(5), "{err}");
    assert!(
        err.contains("the output folder `f.csv` is a file, not a folder"),
        "{err}"
    );
    assert!(!err.contains("temporary"), "{err}");
}

/// With `--json` an error is one JSON object on stderr (kind, exit code, message, file, field,
/// line), with the same exit code as without; usage errors too.
#[test]
fn with_json_errors_are_json_objects_on_stderr() {
    /// What, scenario, extra arguments, exit code, error kind, field named.
    type JsonCase<'a> = (
        &'a str,
        String,
        &'a [&'a str],
        i32,
        &'a str,
        Option<&'a str>,
    );
    let cases: [JsonCase; 4] = [
        (
            "a wrong type",
            force_scenario(r#", "integrator": {"method": "rk4", "step_s": "fast"}"#),
            &[],
            3,
            "input",
            Some("integrator.step_s"),
        ),
        (
            "an impossible value",
            force_scenario(r#", "integrator": {"method": "rk4", "step_s": 0}"#),
            &[],
            3,
            "input",
            Some("integrator.step_s"),
        ),
        (
            "an output folder that is a file",
            force_scenario(""),
            &["--out", "f.csv/out.csv"],
            5,
            "output",
            None,
        ),
        (
            "an unknown flag",
            force_scenario(""),
            &["--colour"],
            2,
            "usage",
            None,
        ),
    ];
    for (what, scenario, extra, code, kind, field) in cases {
        let (plain_code, _) = simulate_bad(&scenario, extra);
        let mut args = extra.to_vec();
        args.push("--json");
        let (json_code, err) = simulate_bad(&scenario, &args);
        assert_eq!(plain_code, Some(code), "{what}");
        assert_eq!(json_code, Some(code), "{what}: {err}");
        let v: serde_json::Value = serde_json::from_str(err.trim())
            .unwrap_or_else(|e| panic!("{what}: stderr is not JSON ({e}): {err}"));
        let e = &v["error"];
        assert_eq!(e["kind"], kind, "{what}: {v}");
        assert_eq!(e["exit_code"], code, "{what}: {v}");
        assert!(
            e["message"].as_str().is_some_and(|m| !m.is_empty()),
            "{what}: {v}"
        );
        if let Some(field) = field {
            assert!(
                e["field"].as_str().unwrap().starts_with(field),
                "{what}: {v}"
            );
            assert!(
                e["file"].as_str().unwrap().ends_with("bad.json"),
                "{what}: {v}"
            );
        }
        if kind == "output" {
            assert!(
                e["file"].as_str().unwrap().ends_with("out.csv"),
                "{what}: {v}"
            );
        }
    }
}
