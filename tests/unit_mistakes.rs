//! Inputs whose magnitude betrays a unit mistake, through the built binary: a force record in
//! kN read as N (runs, with a warning naming the peak and the breakaway force), a pressure in
//! Pa where MPa is asked (refused), a displacement record far beyond the stroke (refused).
//!
//! The breakaway force is computed here from the paper's identified values, not by the code
//! under test: `F_s = F_μ + a = 0.44 % × 5783 kN + 12.04 kN = 37.4852 kN` at 13.8 MPa
//! (Eq. 22/23: the dissipative force at v → 0⁺ is `F_μ + a`).

use std::path::{Path, PathBuf};

mod common;
use common::{platen, stderr};

/// The paper's breakaway force of the LHPOST at 13.8 MPa, N.
const PAPER_BREAKAWAY_N: f64 = 0.0044 * 5783e3 + 12.04e3;

/// Writes `text` to `dir/name` and returns the path as a string.
fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// A force record: `amplitude` × sin(2π·0.5 Hz·t) over 4 s at 100 Hz, under the header `F`.
fn sine_force_csv(amplitude: f64) -> String {
    let mut text = String::from("t_s,F\n");
    for i in 0..=400 {
        let t = i as f64 * 0.01;
        let f = amplitude * (std::f64::consts::PI * t).sin();
        text.push_str(&format!("{t},{f}\n"));
    }
    text
}

/// A number printed as `… {value} kN` right after `prefix` in `text`, in N.
fn kn_after(text: &str, prefix: &str) -> f64 {
    let rest = &text[text
        .find(prefix)
        .unwrap_or_else(|| panic!("{prefix:?} in {text}"))
        + prefix.len()..];
    let number = rest.split(" kN").next().unwrap();
    number.trim().parse::<f64>().unwrap() * 1e3
}

/// The first row of `csv` (header first) whose second column is largest in magnitude:
/// `(line, time text, value)`, read from the text written, not from platen.
fn first_peak(csv: &str) -> (usize, String, f64) {
    let mut best = (0, String::new(), 0.0_f64);
    for (k, line) in csv.lines().enumerate().skip(1) {
        let (t, x) = line.split_once(',').unwrap();
        let x: f64 = x.parse().unwrap();
        if x.abs() > best.2.abs() {
            best = (k + 1, t.to_owned(), x);
        }
    }
    best
}

fn json(o: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&o.stdout)))
}

#[test]
fn a_force_in_kn_read_as_n_warns_with_the_peak_and_the_breakaway_force() {
    let dir = tempfile::tempdir().unwrap();
    // 600 kN of a sine, written in kN, read as N: a 600 N peak.
    let force = sine_force_csv(600.0);
    write(dir.path(), "force.csv", &force);
    let scenario = |unit: &str| {
        format!(
            r#"{{"model": {{"preset": "lhpost-2008"}},
                 "excitation": {{"force_csv": "force.csv",
                                 "columns": {{"force_n": {{"name": "F", "unit": "{unit}"}}}}}}}}"#
        )
    };
    let sc = write(dir.path(), "n.json", &scenario("N"));
    let out = dir.path().join("out.csv");
    let o = platen(&["simulate", &sc, "--json", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("warning: the force never reaches"), "{err}");
    let summary = json(&o);
    let warnings = summary["warnings"].as_array().expect("a warnings list");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = warnings[0].as_str().unwrap();
    assert!(err.contains(w), "stderr lacks the summary's warning: {err}");
    // The breakaway force, printed to 1 N (three decimals of kN): the paper's within 0.5 N
    // of printing, and 1 N of rounding in the preset's 0.44 % × 5783 kN.
    let breakaway = kn_after(w, "the breakaway force ");
    assert!(
        (breakaway - PAPER_BREAKAWAY_N).abs() <= 1.0,
        "breakaway {breakaway} N, paper {PAPER_BREAKAWAY_N} N: {w}"
    );
    // The peak: 600 N (sin(π/2), to the printed 1 N), at the first sample that reaches it.
    let peak = kn_after(w, "its peak |force| is ");
    assert!((peak - 600.0).abs() <= 0.5, "{w}");
    let (_, t_peak, _) = first_peak(&force);
    assert!(
        w.contains(&format!("is 0.600 kN at {t_peak} s,")),
        "{t_peak}: {w}"
    );
    assert!(w.contains("kN where N is expected"), "{w}");
    assert!(w.contains("the run confirms it"), "{w}");
    // The run's own output: the platen never moved (u and v stay exactly 0 in every row).
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (iu, iv) = (
        header.iter().position(|c| *c == "u_m").unwrap(),
        header.iter().position(|c| *c == "v_m_s").unwrap(),
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 401);
    assert!(rows.iter().all(|r| r[iu] == 0.0 && r[iv] == 0.0));
    // Stuck for the whole 4 s (a sum of 400 steps: 1e-9 s of rounding).
    let stuck = summary["stick_time_s"].as_f64().unwrap();
    assert!((stuck - 4.0).abs() < 1e-9, "{stuck}");

    // The same file mapped in kN moves the platen (600 kN ≫ 37.5 kN): no warning.
    let sc = write(dir.path(), "kn.json", &scenario("kN"));
    let o = platen(&["simulate", &sc, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        json(&o)["warnings"],
        serde_json::json!([]),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

#[test]
fn a_force_below_breakaway_at_a_displaced_start_names_both_breakaway_forces() {
    let dir = tempfile::tempdir().unwrap();
    // Starting at u0 = 0.1 m the springs pull with Kₑ·u0 = 126.6 kN (Kₑ = 1.266 MN/m): a
    // constant 126.6 kN holds the platen, and so does anything within F_s = 37.485 kN of it.
    let mut text = String::from("t_s,force_n\n");
    for i in 0..=200 {
        let t = i as f64 * 0.01;
        let f = 126.6e3 + 30e3 * (std::f64::consts::PI * t).sin();
        text.push_str(&format!("{t},{f}\n"));
    }
    write(dir.path(), "force.csv", &text);
    let sc = write(
        dir.path(),
        "s.json",
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "force.csv"},
            "initial": {"u_m": 0.1, "v_m_s": 0.0}}"#,
    );
    let o = platen(&["simulate", &sc, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = json(&o);
    let w = summary["warnings"][0].as_str().unwrap().to_owned();
    let elastic = 1.266e6 * 0.1;
    let low = kn_after(&w, "the breakaway forces ");
    let high = kn_after(&w, &format!("{:.3} kN and ", low / 1e3));
    assert!((low - (elastic - PAPER_BREAKAWAY_N)).abs() <= 1.0, "{w}");
    assert!((high - (elastic + PAPER_BREAKAWAY_N)).abs() <= 1.0, "{w}");
    assert_eq!(summary["peak_v_m_s"], 0.0);
}

#[test]
fn a_pressure_in_pa_where_mpa_is_asked_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let sr9 = root.join("scenarios/sr9-like-sine-force.json");
    let cases = dir.path().join("cases.csv");
    let report = dir.path().join("report.html");
    let record = write(dir.path(), "rec.csv", "t_s,u_m,a_m_s2,force_n\n0,0,0,0\n");
    for args in [
        vec![
            "sweep",
            sr9.to_str().unwrap(),
            "--pressure-mpa",
            "13.8e6",
            "--out",
            cases.to_str().unwrap(),
        ],
        vec![
            "identify",
            &record,
            "--pressure-mpa",
            "13.8e6",
            "--json",
            "--report",
            report.to_str().unwrap(),
        ],
        vec!["model", "--pressure-mpa", "13.8e6", "--json"],
    ] {
        let o = platen(&args);
        assert!(!o.status.success(), "{args:?}");
        let err = stderr(&o);
        assert!(err.contains("--pressure-mpa"), "{err}");
        assert!(err.contains("MPa is expected"), "{err}");
        assert!(err.contains("13.8e6 looks like Pa (13.8 MPa)"), "{err}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
    assert!(!cases.exists() && !report.exists());
    // In a scenario: refused with its JSON path, before anything runs or is written.
    let text = std::fs::read_to_string(&sr9).unwrap().replace(
        "\"hold_down_pressure_mpa\": 13.8",
        "\"hold_down_pressure_mpa\": 13.8e6",
    );
    assert!(
        text.contains("13.8e6"),
        "the shipped scenario changed: {text}"
    );
    let sc = write(dir.path(), "p.json", &text);
    let out = dir.path().join("out.csv");
    let o = platen(&["simulate", &sc, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("model.hold_down_pressure_mpa"), "{err}");
    assert!(err.contains("13.8e6 looks like Pa (13.8 MPa)"), "{err}");
    assert!(!out.exists());
    // In an identification manifest: refused naming the manifest and the entry.
    let manifest = write(
        dir.path(),
        "m.json",
        r#"{"tests": [{"file": "rec.csv", "pressure_mpa": 13.8e6}]}"#,
    );
    let o = platen(&["identify", "--manifest", &manifest, "--json"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("m.json") && err.contains("tests[0].pressure_mpa"),
        "{err}"
    );
    assert!(err.contains("13.8e6 looks like Pa (13.8 MPa)"), "{err}");
    assert!(o.stdout.is_empty());
    // 13.8 itself runs.
    assert!(platen(&[
        "sweep",
        sr9.to_str().unwrap(),
        "--pressure-mpa",
        "13.8",
        "--json"
    ])
    .status
    .success());
}

/// A displacement sine of `amplitude_m` at 0.5 Hz over 2 s at 100 Hz.
fn sine_motion_csv(amplitude_m: f64) -> String {
    let mut text = String::from("t_s,u_m\n");
    for i in 0..=200 {
        let t = i as f64 * 0.01;
        text.push_str(&format!(
            "{t},{}\n",
            amplitude_m * (std::f64::consts::PI * t).sin()
        ));
    }
    text
}

#[test]
fn a_displacement_record_a_hundred_strokes_long_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // The LHPOST's stroke is ±0.75 m: 75 m is 100 strokes (a 75 mm record read as m would be
    // 75 m too).
    let far = sine_motion_csv(75.0);
    write(dir.path(), "far.csv", &far);
    let sc = write(
        dir.path(),
        "far.json",
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "far.csv"}}"#,
    );
    let out = dir.path().join("out.csv");
    let o = platen(&["simulate", &sc, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    // The first sample of the largest |u| (75 m to rounding, near t = 0.5 s or 1.5 s).
    let (line, t_peak, peak) = first_peak(&far);
    assert!((peak.abs() - 75.0).abs() < 1e-9 && (line == 52 || line == 152));
    for part in [
        "far.csv",
        &format!("line {line}, column u_m"),
        &format!("reaches {peak} m at {t_peak} s"),
        "100 times the table's stroke of ±0.75 m",
        "mm read as m",
        r#""u_m": {"unit": "mm"}"#,
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    assert!(!out.exists() && o.stdout.is_empty());
    // Five strokes still run, the limit reported as exceeded (what would the table need).
    write(dir.path(), "near.csv", &sine_motion_csv(3.75));
    let sc = write(
        dir.path(),
        "near.json",
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "near.csv"}}"#,
    );
    let o = platen(&["simulate", &sc, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&o)["limits"]["stroke_m"]["respected"], false);
}

#[test]
fn a_supply_pressure_in_mpa_or_far_beyond_any_table_is_refused_as_such() {
    // issue 38: `supply_pressure_pa: 20.7` (MPa) was blamed on the return pressure, and
    // 2.07e9 ran (at 20 g, "lowest 560 MPa").
    let dir = tempfile::tempdir().unwrap();
    for (value, says) in [
        ("20.7", "20.7 looks like MPa, which is 20.7e6 Pa"),
        ("20700", "looks like kPa"),
        ("2.07e9", "2070 MPa is beyond any servo-hydraulic supply"),
    ] {
        let path = dir.path().join(format!("supply-{value}.json"));
        std::fs::write(
            &path,
            format!(
                r#"{{"model": {{"preset": "lhpost-2008"}},
                    "table_system": {{"preset": "lhpost-2008", "supply_pressure_pa": {value}}},
                    "excitation": {{"sine_motion": {{"amplitude_m": 0.02, "frequency_hz": 1.0}}}},
                    "duration_s": 0.5}}"#
            ),
        )
        .unwrap();
        let o = platen(&["simulate", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(3), "{value}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("table_system.supply_pressure_pa") && e.contains(says),
            "{value}: {e}"
        );
        assert!(!e.contains("return_pressure_pa"), "{value}: {e}");
    }
}

/// An LHPOST scenario whose force record `rec.csv` (beside it) has its time in `Time`, in
/// `unit`, and its force in `F`, N.
fn force_record_scenario(unit: &str) -> String {
    format!(
        r#"{{"model": {{"preset": "lhpost-2008"}},
             "excitation": {{"force_csv": "rec.csv",
                             "columns": {{"t_s": {{"name": "Time", "unit": "{unit}"}},
                                         "force_n": {{"name": "F"}}}}}}}}"#
    )
}

/// A time column declared in ms whose values are seconds (the issue 38 case: 5121 samples
/// over "0.020 s", a 256 kHz record) is refused before any work by every reader that maps
/// columns: `simulate`'s force record and `plan`'s target, with the rate it would read at,
/// the unit declared, and the map that reads it as seconds. The same file mapped in seconds
/// runs.
#[test]
fn a_time_in_seconds_declared_as_ms_is_refused_by_simulate_and_plan() {
    let dir = tempfile::tempdir().unwrap();
    // 20 s at 256 Hz: declared ms, it reads as 5121 samples over 0.02 s (256 kHz).
    let mut text = String::from("Time,F,Acc\n");
    for i in 0..=5120 {
        let t = i as f64 / 256.0;
        let s = (std::f64::consts::PI * t).sin();
        text.push_str(&format!("{t},{},{}\n", 200e3 * s, 0.1 * s));
    }
    write(dir.path(), "rec.csv", &text);
    let scenario = force_record_scenario;
    let ms = write(dir.path(), "ms.json", &scenario("ms"));
    let out = dir.path().join("out.csv");
    let o = platen(&["simulate", &ms, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    for part in [
        "rec.csv",
        "column t_s: 5121 samples over 0.02 s",
        "2.5600e5 Hz",
        "declared as ms",
        r#""t_s": {"unit": "s"}"#,
        "(a rate of 256.0000 Hz)",
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    assert!(!out.exists() && o.stdout.is_empty());
    let s = write(dir.path(), "s.json", &scenario("s"));
    let o = platen(&["simulate", &s]);
    assert!(o.status.success(), "{}", stderr(&o));

    // The same slip in a plan's target (acceleration in g, time declared ms).
    let map = |unit: &str| {
        format!(
            r#"{{"t_s": {{"name": "Time", "unit": "{unit}"}}, "a_m_s2": {{"name": "Acc", "unit": "g"}}}}"#
        )
    };
    write(dir.path(), "ms-map.json", &map("ms"));
    let drive = dir.path().join("drive.csv");
    let o = platen(&[
        "plan",
        "scenarios/table-system/wn10g-closed-loop.json",
        "--target",
        dir.path().join("rec.csv").to_str().unwrap(),
        "--columns",
        dir.path().join("ms-map.json").to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
    ]);
    assert_ne!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    for part in [
        "rec.csv",
        "2.5600e5 Hz",
        "declared as ms",
        r#""t_s": {"unit": "s"}"#,
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    assert!(!drive.exists());
}

/// A displacement target written in mm under `u_m` (a 195 mm peak read as 195 m, 260 times
/// the LHPOST's stroke) is refused by `plan` with the hint `simulate` gives for the same
/// record, not planned.
#[test]
fn a_displacement_target_in_mm_read_as_m_is_refused_by_plan_with_the_mm_hint() {
    let dir = tempfile::tempdir().unwrap();
    // 195 mm of a 0.5 Hz sine at 100 Hz for 8 s, written in mm under u_m.
    let mut text = String::from("t_s,u_m\n");
    for i in 0..=800 {
        let t = i as f64 * 0.01;
        text.push_str(&format!(
            "{t},{}\n",
            195.0 * (std::f64::consts::PI * t).sin()
        ));
    }
    write(dir.path(), "target.csv", &text);
    let drive = dir.path().join("drive.csv");
    let o = platen(&[
        "plan",
        "scenarios/table-system/wn10g-closed-loop.json",
        "--target",
        dir.path().join("target.csv").to_str().unwrap(),
        "--out",
        drive.to_str().unwrap(),
    ]);
    assert_ne!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    for part in [
        "target.csv",
        "column u_m",
        "times the table's stroke of ±0.75 m",
        "mm read as m",
        r#""u_m": {"unit": "mm"}"#,
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    assert!(!drive.exists() && o.stdout.is_empty());
}

/// A bulk modulus or a chamber volume in the wrong unit is refused with what it looks like:
/// 1.5 (GPa) and 1500 (MPa) as Pa, 1e24 beyond any oil; a chamber of 212.2 "m³" (litres).
/// The preset's own values run. (The multi-axis tables' actuators go through the same check,
/// `platen_system::PLAUSIBLE_CHAMBER_M3`.)
#[test]
fn a_bulk_modulus_or_a_chamber_volume_in_another_unit_is_refused_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            r#""oil_bulk_modulus_pa": 1.5"#,
            "table_system.oil_bulk_modulus_pa",
            "1.5 looks like GPa, which is 1.5e9 Pa",
        ),
        (
            r#""oil_bulk_modulus_pa": 1500"#,
            "table_system.oil_bulk_modulus_pa",
            "1500 looks like MPa, which is 1500e6 Pa",
        ),
        (
            r#""oil_bulk_modulus_pa": 1e24"#,
            "table_system.oil_bulk_modulus_pa",
            "stiffer than any oil",
        ),
        (
            r#""actuator": {"chamber_volume_m3": 212.2}"#,
            "table_system.actuator.chamber_volume_m3",
            "212.2 looks like litres, which is 0.2122 m³",
        ),
    ];
    for (i, (value, path, says)) in cases.into_iter().enumerate() {
        let file = dir.path().join(format!("case-{i}.json"));
        std::fs::write(
            &file,
            format!(
                r#"{{"model": {{"preset": "lhpost-2008"}},
                    "table_system": {{"preset": "lhpost-2008", {value}}},
                    "excitation": {{"sine_motion": {{"amplitude_m": 0.02, "frequency_hz": 1.0}}}},
                    "duration_s": 0.5}}"#
            ),
        )
        .unwrap();
        let o = platen(&["simulate", file.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(3), "{value}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(path) && e.contains(says), "{value}: {e}");
    }
    let fine = dir.path().join("fine.json");
    std::fs::write(
        &fine,
        r#"{"model": {"preset": "lhpost-2008"},
            "table_system": {"preset": "lhpost-2008", "oil_bulk_modulus_pa": 1.5e9,
                             "actuator": {"chamber_volume_m3": 0.2122}},
            "excitation": {"sine_motion": {"amplitude_m": 0.02, "frequency_hz": 1.0}},
            "duration_s": 0.5}"#,
    )
    .unwrap();
    let o = platen(&["simulate", fine.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The low side of the same slip: a time column declared in seconds whose values are
/// milliseconds (a 1024 Hz record reads as 1.024 Hz) is refused before any work, naming the
/// rate it would have in ms; the same file mapped in ms runs.
#[test]
fn a_time_in_milliseconds_read_as_seconds_is_refused_with_the_ms_map() {
    let dir = tempfile::tempdir().unwrap();
    // 2 s at 1024 Hz, the time written in ms.
    let mut text = String::from("Time,F\n");
    for i in 0..=2048 {
        let t_ms = i as f64 * 1000.0 / 1024.0;
        let s = (std::f64::consts::TAU * t_ms / 1000.0).sin();
        text.push_str(&format!("{t_ms},{}\n", 200e3 * s));
    }
    write(dir.path(), "rec.csv", &text);
    let scenario = force_record_scenario;
    let s = write(dir.path(), "s.json", &scenario("s"));
    let out = dir.path().join("out.csv");
    let o = platen(&["simulate", &s, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    for part in [
        "rec.csv",
        "column t_s: 2049 samples over 2000 s",
        "a sample rate of 1.0240 Hz",
        r#""t_s": {"unit": "ms"}"#,
        "(a rate of 1024.0000 Hz)",
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    assert!(!out.exists() && o.stdout.is_empty());
    let ms = write(dir.path(), "ms.json", &scenario("ms"));
    let o = platen(&["simulate", &ms]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// An actuator area in cm² written as m² (the LHPOST's 2051 cm² cap side as 2051 m²) is
/// refused with what it looks like, on the uniaxial and the multi-axis table; 0.2051 runs.
#[test]
fn an_area_in_square_centimetres_is_refused_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let uniaxial = |area: &str| {
        format!(
            r#"{{"model": {{"preset": "lhpost-2008"}},
                "table_system": {{"preset": "lhpost-2008",
                                 "actuator": {{"cap_side_area_m2": {area}, "rod_side_area_m2": 0.1291}}}},
                "excitation": {{"sine_motion": {{"amplitude_m": 0.02, "frequency_hz": 1.0}}}},
                "duration_s": 0.5}}"#
        )
    };
    let bad = write(dir.path(), "cm2.json", &uniaxial("2051"));
    let o = platen(&["simulate", &bad]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("cap_side_area_m2") && e.contains("2051 looks like cm², which is 0.2051 m²"),
        "{e}"
    );
    let fine = write(dir.path(), "m2.json", &uniaxial("0.2051"));
    let o = platen(&["simulate", &fine]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The multi-axis table: the LHPOST6's first actuator in cm².
    let preset: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string("crates/platen-scenario/presets/lhpost6.json").unwrap(),
    )
    .unwrap();
    let motion = std::fs::canonicalize("scenarios/multi-axis/three-component-motion.csv").unwrap();
    let mut table = serde_json::json!({"table": preset["table"].clone(),
        "excitation": {"motion_csv": motion}});
    let first = &mut table["table"]["actuators"][0];
    let area = first["cap_side_area_m2"].as_f64().unwrap();
    first["cap_side_area_m2"] = serde_json::json!(area * 1e4);
    let file = write(dir.path(), "six.json", &table.to_string());
    let o = platen(&["simulate", &file]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("cap_side_area_m2") && e.contains("looks like cm²"),
        "{e}"
    );
}
