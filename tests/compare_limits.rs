//! `platen compare` checks the recording itself against the table's limits
//! (`recorded_limits`, one warning per limit exceeded), and `--window` takes a bound within
//! half a recorded sample interval outside the compared span as the span's end.
//!
//! The expected peaks, times and durations are computed here, directly from the CSV text
//! each test writes, not by the code under test.

use std::fs;
use std::path::{Path, PathBuf};

use serde_json::Value;

mod common;
use common::{platen, stderr};

/// The shipped SR9 check: 20 s at 512 Hz, forward, on the LHPOST (stroke 0.75 m, 1.8 m/s,
/// 4.2 g, 6.8 MN).
fn sr9(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/sr9")
        .join(file)
}

/// The SR9 record's sample interval, s (512 Hz).
const SR9_STEP_S: f64 = 1.0 / 512.0;

/// The shipped SR9 record as (header, rows of numbers).
fn sr9_record() -> (Vec<String>, Vec<Vec<f64>>) {
    let text = fs::read_to_string(sr9("sr9-recorded.csv")).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// Writes `columns` of `rows` (picked from `header`) to `path`, each value through `f(name,
/// value)`, in Rust's shortest round-trip notation, and returns the columns as written
/// (parsed back from the text written).
fn write_record(
    path: &Path,
    header: &[String],
    rows: &[Vec<f64>],
    columns: &[&str],
    f: impl Fn(&str, f64) -> f64,
) -> Vec<Vec<f64>> {
    let index: Vec<usize> = columns
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    let mut text = columns.join(",") + "\n";
    for row in rows {
        let cells: Vec<String> = columns
            .iter()
            .zip(&index)
            .map(|(c, &i)| format!("{}", f(c, row[i])))
            .collect();
        text += &cells.join(",");
        text += "\n";
    }
    fs::write(path, &text).unwrap();
    let mut out = vec![Vec::new(); columns.len()];
    for line in text.lines().skip(1) {
        for (col, cell) in out.iter_mut().zip(line.split(',')) {
            col.push(cell.parse().unwrap());
        }
    }
    out
}

/// (signed peak, its time, first time beyond `limit`, samples beyond `limit`) of `x` at `t`,
/// worked out plainly.
fn expected(t: &[f64], x: &[f64], limit: f64) -> (f64, f64, Option<f64>, usize) {
    let mut i_peak = 0;
    for i in 0..x.len() {
        if x[i].abs() > x[i_peak].abs() {
            i_peak = i;
        }
    }
    let beyond: Vec<usize> = (0..x.len()).filter(|&i| x[i].abs() > limit).collect();
    (
        x[i_peak],
        t[i_peak],
        beyond.first().map(|&i| t[i]),
        beyond.len(),
    )
}

/// `json` is the number `expected`, to within 2 ulp: the platen binary prints every f64 in
/// its shortest round-trip form, but serde_json's default parser (without the
/// `float_roundtrip` feature) can land one ulp off when the test reads it back.
fn same(json: &Value, expected: f64) -> bool {
    json.as_f64()
        .is_some_and(|x| (x - expected).abs() <= 2.0 * f64::EPSILON * expected.abs())
}

fn compare(args: &[&str]) -> std::process::Output {
    let mut all = vec!["compare"];
    all.extend_from_slice(args);
    platen(&all)
}

fn ok_json(o: &std::process::Output) -> Value {
    assert!(o.status.success(), "platen failed: {}", stderr(o));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

/// The SR9 record with its displacement scaled by 2.2 (peak 0.38 m → 0.836 m): beyond the
/// LHPOST's 0.75 m stroke, and reported so with the peak, its time, the first sample beyond
/// and the time beyond as computed here from the CSV written; the other columns stay within
/// their limits.
#[test]
fn a_recording_beyond_the_stroke_is_reported_with_its_peak_first_time_and_duration() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scaled.csv");
    let (header, rows) = sr9_record();
    let cols = write_record(
        &rec,
        &header,
        &rows,
        &["t_s", "u_m", "v_m_s", "a_m_s2", "force_n"],
        |c, v| if c == "u_m" { 2.2 * v } else { v },
    );
    let (t, u) = (&cols[0], &cols[1]);
    let stroke_m = 0.75;
    let (peak, peak_t, first, beyond) = expected(t, u, stroke_m);
    let first = first.expect("the scaled record goes beyond the stroke");
    assert!(peak.abs() > 0.8, "the test's own premise: {peak}");

    let scenario = sr9("sr9-forward.json");
    let o = compare(&[
        scenario.to_str().unwrap(),
        "--recorded",
        rec.to_str().unwrap(),
        "--json",
    ]);
    let report = ok_json(&o);
    let limits = &report["recorded_limits"];
    let stroke = &limits["stroke_m"];
    assert_eq!(stroke["column"], "u_m");
    assert!(same(&stroke["limit"], stroke_m));
    // The peak is one of the values written: equal but for the JSON read-back (`same`).
    assert!(same(&stroke["peak"], peak));
    assert!(same(&stroke["peak_t_s"], peak_t));
    assert_eq!(stroke["respected"], false);
    assert!(same(&stroke["first_exceeded_s"], first));
    // Samples beyond × the interval; 1e-9 s covers the interval being estimated from stamps
    // that are exact multiples of 1/512 s.
    let time = stroke["time_exceeded_s"].as_f64().unwrap();
    assert!(
        (time - beyond as f64 * SR9_STEP_S).abs() < 1e-9,
        "{time} s against {beyond} samples"
    );
    assert!(beyond > 10, "a sustained excursion: {beyond} samples");

    // The other columns stay within the LHPOST's limits, each reported with its own peak.
    for (key, column, limit) in [
        ("velocity_m_s", 2, 1.8),
        ("acceleration_m_s2", 3, 4.2 * 9.80665),
        ("force_n", 4, 6.8e6),
    ] {
        let (peak, peak_t, first, _) = expected(t, &cols[column], limit);
        let check = &limits[key];
        assert!(same(&check["limit"], limit), "{key}");
        assert!(same(&check["peak"], peak), "{key}");
        assert!(same(&check["peak_t_s"], peak_t), "{key}");
        assert_eq!(check["respected"], true, "{key}");
        assert_eq!(first, None, "{key}: the test's own premise");
        assert!(check["first_exceeded_s"].is_null(), "{key}");
        assert_eq!(check["time_exceeded_s"].as_f64(), Some(0.0), "{key}");
    }

    // One warning, in the summary and on stderr, naming the column, the peak and the limit.
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = warnings[0].as_str().unwrap();
    for part in [
        "the recording's u_m reaches",
        &format!("{peak:+} m at {peak_t:.3} s"),
        "the table's stroke of 0.75 m",
        &format!("first beyond it at {first:.3} s"),
    ] {
        assert!(w.contains(part), "`{part}` not in: {w}");
    }
    assert!(
        stderr(&o).contains(&format!("warning: {w}")),
        "{}",
        stderr(&o)
    );

    // The text summary and the HTML report say it too.
    let report_path = dir.path().join("report.html");
    let o = compare(&[
        scenario.to_str().unwrap(),
        "--recorded",
        rec.to_str().unwrap(),
        "--report",
        report_path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains(&format!("  warning: {w}")), "{text}");
    assert!(
        text.contains(&format!("BEYOND from {first:.3} s")),
        "{text}"
    );
    let html = fs::read_to_string(&report_path).unwrap();
    assert!(html.contains("<h2>The recording against the table"));
    assert!(
        html.contains("warning: the recording"),
        "the warning in the page"
    );
}

/// The shipped record, less its acceleration and force columns: only the stroke and the
/// velocity are checked (a record without force says nothing about force), both respected,
/// no warning; a scenario whose `limits` lower the stroke to 0.3 m makes the same record go
/// beyond it.
#[test]
fn a_recording_within_its_limits_reports_only_its_own_columns_all_respected() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("motion-only.csv");
    let (header, rows) = sr9_record();
    let cols = write_record(&rec, &header, &rows, &["t_s", "u_m", "v_m_s"], |_, v| v);
    let o = compare(&[
        sr9("sr9-forward.json").to_str().unwrap(),
        "--recorded",
        rec.to_str().unwrap(),
        "--json",
    ]);
    let report = ok_json(&o);
    let limits = report["recorded_limits"].as_object().unwrap();
    let keys: Vec<&str> = limits.keys().map(String::as_str).collect();
    assert_eq!(keys, ["stroke_m", "velocity_m_s"]);
    for (key, column, limit) in [("stroke_m", 1, 0.75), ("velocity_m_s", 2, 1.8)] {
        let (peak, _, first, _) = expected(&cols[0], &cols[column], limit);
        assert_eq!(first, None, "{key}: the test's own premise");
        assert!(same(&limits[key]["peak"], peak), "{key}");
        assert_eq!(limits[key]["respected"], true, "{key}");
    }
    assert_eq!(report["warnings"], serde_json::json!([]));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));

    // The same record against a scenario whose `limits` lower the stroke to 0.3 m.
    let mut scenario: Value =
        serde_json::from_str(&fs::read_to_string(sr9("sr9-forward.json")).unwrap()).unwrap();
    scenario["limits"] = serde_json::json!({ "stroke_m": 0.3 });
    scenario["excitation"]["force_csv"] = sr9("sr9-recorded.csv").display().to_string().into();
    let lowered = dir.path().join("lowered.json");
    fs::write(&lowered, scenario.to_string()).unwrap();
    let o = compare(&[
        lowered.to_str().unwrap(),
        "--recorded",
        rec.to_str().unwrap(),
        "--json",
    ]);
    let report = ok_json(&o);
    let stroke = &report["recorded_limits"]["stroke_m"];
    let (peak, _, first, beyond) = expected(&cols[0], &cols[1], 0.3);
    assert!(same(&stroke["limit"], 0.3));
    assert!(same(&stroke["peak"], peak));
    assert_eq!(stroke["respected"], false);
    assert!(same(&stroke["first_exceeded_s"], first.unwrap()));
    let time = stroke["time_exceeded_s"].as_f64().unwrap();
    assert!((time - beyond as f64 * SR9_STEP_S).abs() < 1e-9, "{time}");
    assert_eq!(report["recorded_limits"]["velocity_m_s"]["respected"], true);
    assert_eq!(report["warnings"].as_array().unwrap().len(), 1);
}

/// A window bound 0.4 of a sample interval outside the compared span (0 s to 20 s) is taken
/// as the span's end, with a note; 0.6 of one is refused, naming the span.
#[test]
fn a_window_bound_within_half_a_sample_of_the_span_is_clamped_and_one_further_out_refused() {
    let (scenario, recorded) = (sr9("sr9-forward.json"), sr9("sr9-recorded.csv"));
    let run = |window: &str| {
        compare(&[
            scenario.to_str().unwrap(),
            "--recorded",
            recorded.to_str().unwrap(),
            &format!("--window={window}"),
            "--json",
        ])
    };
    let start = -0.4 * SR9_STEP_S;
    let report = ok_json(&run(&format!("{start},4")));
    assert_eq!(report["window_s"], serde_json::json!([0.0, 4.0]));
    assert_eq!(report["u_m"]["span_s"], serde_json::json!([0.0, 4.0]));
    assert_eq!(report["u_m"]["samples"], 4 * 512 + 1);
    let notes = report["notes"].to_string();
    assert!(notes.contains("the metrics window is 0,4 s"), "{notes}");

    let end = 20.0 + 0.4 * SR9_STEP_S;
    let report = ok_json(&run(&format!("16,{end}")));
    assert_eq!(report["window_s"], serde_json::json!([16.0, 20.0]));
    assert_eq!(report["u_m"]["samples"], 4 * 512 + 1);

    for window in [
        format!("{},4", -0.6 * SR9_STEP_S),
        format!("16,{}", 20.0 + 0.6 * SR9_STEP_S),
    ] {
        let o = run(&window);
        assert_eq!(o.status.code(), Some(3), "{window}: {}", stderr(&o));
        let message = stderr(&o);
        for part in [
            format!("--window {} s is not inside", window),
            "the compared span 0 s to 20 s".into(),
            "half its sample interval, 0.0009765625 s".into(),
        ] {
            assert!(message.contains(&part), "`{part}` not in: {message}");
        }
        assert!(o.stdout.is_empty());
    }
}
