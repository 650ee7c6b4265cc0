//! A comparison as a library user makes one: the SR9 check, and records it must refuse.

use std::fs;
use std::path::{Path, PathBuf};

use platen_compare::{Channel, CompareError, Comparison, Direction, Settings, Window};

fn sr9(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/sr9")
        .join(file)
}

/// The recorded SR9 file cut to the rows with `t0 <= t <= t1`, written to `dir`.
fn cut_record(dir: &Path, t0: f64, t1: f64) -> PathBuf {
    let text = fs::read_to_string(sr9("sr9-recorded.csv")).unwrap();
    let mut lines = text.lines();
    let mut out = vec![lines.next().unwrap().to_owned()];
    for line in lines {
        let t: f64 = line.split(',').next().unwrap().parse().unwrap();
        if (t0..=t1).contains(&t) {
            out.push(line.to_owned());
        }
    }
    let path = dir.join("cut.csv");
    fs::write(&path, out.join("\n") + "\n").unwrap();
    path
}

#[test]
fn sr9_forward_compares_displacement_then_velocity_and_summarises_them_by_name() {
    let c = Comparison::from_files(
        &sr9("sr9-forward.json"),
        &sr9("sr9-recorded.csv"),
        None,
        &Settings::default(),
    )
    .unwrap();
    assert_eq!(c.direction, Direction::Forward);
    let channels: Vec<Channel> = c.channels.iter().map(|ch| ch.channel).collect();
    assert_eq!(channels, [Channel::Displacement, Channel::Velocity]);
    let json = serde_json::to_value(c.summary(&[], None)).unwrap();
    assert_eq!(json["channels"], serde_json::json!(["u_m", "v_m_s"]));
    assert_eq!(json["u_m"]["unit"], "m");
    assert_eq!(json["v_m_s"]["unit"], "m/s");
    assert!(json["report"].is_null());
    // The residual is simulated − recorded.
    let u = &c.channels[0];
    assert_eq!(u.residual()[10], u.simulated[10] - u.recorded[10]);
}

#[test]
fn a_record_that_ends_before_the_scenario_is_refused_naming_both_spans() {
    let dir = tempfile::tempdir().unwrap();
    let cut = cut_record(dir.path(), 0.0, 10.0);
    let e = Comparison::from_files(&sr9("sr9-forward.json"), &cut, None, &Settings::default())
        .unwrap_err();
    assert!(matches!(e, CompareError::RecordTooShort { .. }), "{e:?}");
    let message = e.to_string();
    assert!(
        message
            .contains("does not cover the scenario's time span: the record runs from 0 s to 10 s"),
        "{message}"
    );
}

#[test]
fn a_window_outside_the_compared_span_is_refused() {
    let settings = Settings {
        window: Some(Window {
            start_s: 15.0,
            end_s: 25.0,
        }),
        ..Settings::default()
    };
    let e = Comparison::from_files(
        &sr9("sr9-forward.json"),
        &sr9("sr9-recorded.csv"),
        None,
        &settings,
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("--window 15,25 s is not inside the compared span 0 s to 20 s"),
        "{e}"
    );
}
