//! A motion file keeps every channel it gives: the recorded acceleration drives the inertial
//! force, a missing velocity is the crossover estimate (u and a) or the derivative of u, a
//! missing acceleration the derivative of v; the summary says what was derived.

use std::f64::consts::PI;
use std::path::Path;

use platen_scenario::{simulate, RunResult};

const RATE_HZ: f64 = 1024.0;

/// Writes `columns` (name, values) as a CSV with `t_s` and a motion scenario reading it.
fn scenario(dir: &Path, name: &str, columns: &[(&str, Vec<f64>)]) -> std::path::PathBuf {
    let n = columns[0].1.len();
    let mut csv = String::from("t_s");
    for (c, _) in columns {
        csv.push(',');
        csv.push_str(c);
    }
    csv.push('\n');
    for i in 0..n {
        csv.push_str(&format!("{}", i as f64 / RATE_HZ));
        for (_, values) in columns {
            csv.push_str(&format!(",{}", values[i]));
        }
        csv.push('\n');
    }
    std::fs::write(dir.join(format!("{name}.csv")), csv).unwrap();
    let path = dir.join(format!("{name}.json"));
    std::fs::write(
        &path,
        format!(
            r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"motion_csv": "{name}.csv"}}}}"#
        ),
    )
    .unwrap();
    path
}

/// The paper's S9 motion (0.2 m, 0.6 Hz) for 20 s, with the table's 10.66 Hz oil-column
/// ringing (0.3 m/s²) in the accelerometer only: a displacement transducer does not see it.
fn s9_like() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let w = 2.0 * PI * 0.6;
    let n = 20 * RATE_HZ as usize + 1;
    let t = |i: usize| i as f64 / RATE_HZ;
    let u = (0..n).map(|i| 0.2 * (w * t(i)).sin()).collect();
    let v = (0..n).map(|i| 0.2 * w * (w * t(i)).cos()).collect();
    let a = (0..n)
        .map(|i| -0.2 * w * w * (w * t(i)).sin() + 0.3 * (2.0 * PI * 10.66 * t(i)).sin())
        .collect();
    (u, v, a)
}

/// The uniaxial summary of a run of the platen.
fn summary(run: &RunResult) -> &platen_scenario::RunSummary {
    match run {
        RunResult::Platen { summary, .. } => summary,
        RunResult::Table { .. } => panic!("a uniaxial scenario ran as a table"),
    }
}

fn column<'a>(run: &'a RunResult, name: &str) -> &'a [f64] {
    run.column(name).unwrap()
}

/// The inertial force is `Mₑ·a` with the file's own acceleration, bit for bit (Mₑ = 144 t on
/// the identified model), ringing included; the velocity is the crossover estimate: the
/// sine's velocity plus, from the accelerometer above the 2 Hz crossover, the ringing's
/// `−0.3/(2π·10.66)·cos(2π·10.66·t)` (weight 1 − 1/(1 + (10.66/2)⁴) = 0.9988), within 0.5 %
/// of the sine's amplitude away from the record's edges (the two paths' gains are within
/// (2πfΔt)²/3 of one and add to one).
#[test]
fn a_motion_with_displacement_and_acceleration_keeps_the_acceleration_and_derives_the_velocity() {
    let dir = tempfile::tempdir().unwrap();
    let (u, v_true, a) = s9_like();
    let path = scenario(dir.path(), "ua", &[("u_m", u), ("a_m_s2", a.clone())]);
    let run = simulate(&path).unwrap();
    assert_eq!(column(&run, "a_m_s2"), &a[..]);
    for (f, ai) in column(&run, "inertial_force_n").iter().zip(&a) {
        assert_eq!(*f, 144e3 * ai);
    }
    let v = column(&run, "v_m_s");
    let inner = 1024..v.len() - 1024;
    let w_ring = 2.0 * PI * 10.66;
    let ringing = |i: usize| -0.3 / w_ring * (w_ring * i as f64 / RATE_HZ).cos();
    let worst = inner
        .map(|i| (v[i] - v_true[i] - ringing(i)).abs())
        .fold(0.0, f64::max);
    let amplitude = 0.2 * 2.0 * PI * 0.6;
    assert!(worst < 0.005 * amplitude, "velocity error {worst} m/s");
    let derived = &summary(&run).derived;
    assert_eq!(derived.len(), 1, "{derived:?}");
    assert!(derived["v_m_s"].contains("crossover"), "{derived:?}");
    let json = serde_json::to_value(summary(&run)).unwrap();
    assert!(json["derived"]["v_m_s"].is_string(), "{json}");
}

/// Without an acceleration, the one of `v` is derived (the ringing is not in `u` or `v`, so
/// it is not in the result): central differences of a sine, gain `sin(ωΔt)/(ωΔt)`, 1e-5.
#[test]
fn a_motion_with_displacement_and_velocity_derives_the_acceleration() {
    let dir = tempfile::tempdir().unwrap();
    let (u, v, _) = s9_like();
    let path = scenario(dir.path(), "uv", &[("u_m", u), ("v_m_s", v.clone())]);
    let run = simulate(&path).unwrap();
    assert_eq!(column(&run, "v_m_s"), &v[..]);
    let w = 2.0 * PI * 0.6;
    let a = column(&run, "a_m_s2");
    for (i, ai) in a.iter().enumerate().skip(1).take(a.len() - 2) {
        let exact = -0.2 * w * w * (w * i as f64 / RATE_HZ).sin();
        assert!((ai - exact).abs() < 1e-5 * 0.2 * w * w, "sample {i}");
    }
    assert_eq!(
        summary(&run).derived.keys().copied().collect::<Vec<_>>(),
        ["a_m_s2"]
    );
}

/// Every channel given: nothing derived, and the summary has no `derived` key.
#[test]
fn a_motion_with_every_channel_derives_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (u, v, a) = s9_like();
    let path = scenario(
        dir.path(),
        "uva",
        &[("u_m", u), ("v_m_s", v), ("a_m_s2", a)],
    );
    let run = simulate(&path).unwrap();
    assert!(summary(&run).derived.is_empty());
    let json = serde_json::to_value(summary(&run)).unwrap();
    assert_eq!(json["derived"], serde_json::json!({}), "{json}");
}

/// `excitation.rest_velocity_m_s` reaches the inverse run (a constant position with a velocity
/// jittering by ±0.5 mm/s: the friction is the static reaction, without sign flips), and a
/// force excitation or a band that is not a positive velocity is refused with its JSON path.
#[test]
fn the_scenarios_dead_band_reaches_the_inverse_run_and_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    let n = 2048;
    let u = vec![0.05; n];
    let v = (0..n)
        .map(|i| if i % 2 == 0 { 5e-4 } else { -5e-4 })
        .collect();
    let a = vec![0.0; n];
    let path = scenario(
        dir.path(),
        "still",
        &[("u_m", u), ("v_m_s", v), ("a_m_s2", a)],
    );
    let flips = |run: &RunResult| {
        column(run, "dissipative_force_n")
            .windows(2)
            .filter(|w| w[0] * w[1] < 0.0)
            .count()
    };
    assert_eq!(flips(&simulate(&path).unwrap()), n - 1);
    let text = std::fs::read_to_string(&path).unwrap().replace(
        r#""motion_csv": "still.csv""#,
        r#""motion_csv": "still.csv", "rest_velocity_m_s": 0.001"#,
    );
    std::fs::write(&path, &text).unwrap();
    let run = simulate(&path).unwrap();
    assert_eq!(flips(&run), 0);
    // Kₑu = 63.3 kN against F_s = 37.485 kN: the actuator holds the difference.
    let f = column(&run, "force_n");
    assert!(
        f.iter()
            .all(|&f| (f - (1.266e6 * 0.05 - 37_485.2)).abs() < 1.0),
        "{}",
        f[0]
    );

    for (bad, needle) in [
        (text.replace("0.001", "0"), "excitation.rest_velocity_m_s"),
        (text.replace("0.001", "-1"), "excitation.rest_velocity_m_s"),
    ] {
        std::fs::write(&path, bad).unwrap();
        let e = simulate(&path).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
    let force = dir.path().join("force.json");
    std::fs::write(
        &force,
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {"sine_force": {"amplitude_n": 1e5, "frequency_hz": 0.5}, "rest_velocity_m_s": 0.001}, "duration_s": 2}"#,
    )
    .unwrap();
    let e = simulate(&force).unwrap_err().to_string();
    assert!(
        e.contains("excitation.rest_velocity_m_s") && e.contains("motion"),
        "{e}"
    );
}
