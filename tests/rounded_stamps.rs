//! A lab's 204.8 Hz record whose time stamps are printed to 1e-5 s, 300 s long, through every
//! verb that reads a record: `simulate` (a force file with an RK4 step of Δt/2, and a motion
//! file), `compare` and `identify`. Each must accept it and give what the same record with
//! exact stamps gives: the one sampling-grid check fits the interval over the whole record
//! (`platen_integrate::sampling_grid`).

use std::path::Path;
use std::process::Output;

use serde_json::Value;

mod common;
use common::platen;

fn ok(o: Output) -> Output {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

const RATE_HZ: f64 = 204.8;
const SECONDS: f64 = 300.0;

fn samples() -> usize {
    (SECONDS * RATE_HZ) as usize + 1
}

/// Sample `i`'s stamp: exact (`i/204.8`, shortest round-trip) or printed to 5 decimals.
fn stamp(i: usize, rounded: bool) -> String {
    let t = i as f64 / RATE_HZ;
    if rounded {
        format!("{t:.5}")
    } else {
        format!("{t}")
    }
}

/// Rewrites the first column of a CSV with 5-decimal stamps.
fn round_stamps(from: &Path, to: &Path) {
    let text = std::fs::read_to_string(from).unwrap();
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        if k == 0 {
            out.push_str(line);
        } else {
            let (t, rest) = line.split_once(',').unwrap();
            let t: f64 = t.parse().unwrap();
            out.push_str(&format!("{t:.5},{rest}"));
        }
        out.push('\n');
    }
    std::fs::write(to, out).unwrap();
}

fn column(path: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let j = lines
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == name)
        .unwrap();
    lines
        .map(|l| l.split(',').nth(j).unwrap().parse().unwrap())
        .collect()
}

fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A 150 kN, 0.5 Hz sine force (ramped over 2 s) and the forward scenario that runs it at
/// Δt/2, for exact and rounded stamps.
fn write_force(dir: &Path, rounded: bool) -> String {
    let name = if rounded {
        "force-rounded"
    } else {
        "force-exact"
    };
    let mut csv = String::from("t_s,force_n\n");
    for i in 0..samples() {
        let t = i as f64 / RATE_HZ;
        let f = 150e3 * (t / 2.0).min(1.0) * (std::f64::consts::PI * t).sin();
        csv.push_str(&format!("{},{f}\n", stamp(i, rounded)));
    }
    std::fs::write(dir.join(format!("{name}.csv")), csv).unwrap();
    let scenario = format!(
        r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"force_csv": "{name}.csv"}},
            "integrator": {{"method": "rk4", "step_s": {}}}}}"#,
        0.5 / RATE_HZ
    );
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, scenario).unwrap();
    path.display().to_string()
}

#[test]
fn a_force_file_with_rounded_stamps_runs_at_half_the_fitted_interval_like_exact_stamps() {
    let dir = tempfile::tempdir().unwrap();
    let mut u = Vec::new();
    for rounded in [false, true] {
        let scenario = write_force(dir.path(), rounded);
        let out = dir.path().join(format!("out-{rounded}.csv"));
        let o = ok(platen(&[
            "simulate",
            &scenario,
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]));
        let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(summary["samples"], samples());
        // Two steps per sample interval.
        assert!(summary["solver"]["steps"].as_u64().unwrap() >= 2 * (samples() as u64 - 1));
        u.push(column(&out, "u_m"));
    }
    // The fitted interval of the rounded stamps is 1/204.8 s to 2.5e-15 s (NumPy), so the
    // run differs from the exact one only by that step change accumulated over 300 s:
    // 1e-9 m bounds it with room (peak displacement ≈ 0.3 m).
    let difference = max_abs_difference(&u[0], &u[1]);
    assert!(difference < 1e-9, "max |Δu| = {difference} m");
}

#[test]
fn a_motion_file_with_rounded_stamps_is_differentiated_on_the_fitted_grid() {
    let dir = tempfile::tempdir().unwrap();
    let mut derived = Vec::new();
    for rounded in [false, true] {
        let name = format!("motion-{rounded}");
        let mut csv = String::from("t_s,u_m\n");
        for i in 0..samples() {
            let t = i as f64 / RATE_HZ;
            let u = 0.2 * (2.0 * std::f64::consts::PI * 0.6 * t).sin();
            csv.push_str(&format!("{},{u}\n", stamp(i, rounded)));
        }
        std::fs::write(dir.path().join(format!("{name}.csv")), csv).unwrap();
        let scenario = dir.path().join(format!("{name}.json"));
        std::fs::write(
            &scenario,
            format!(
                r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"motion_csv": "{name}.csv"}}}}"#
            ),
        )
        .unwrap();
        let out = dir.path().join(format!("{name}-out.csv"));
        ok(platen(&[
            "simulate",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]));
        derived.push((column(&out, "v_m_s"), column(&out, "a_m_s2")));
    }
    // Differentiated on the stamps themselves, a rounding of 5e-6 s in a 4.9 ms interval
    // would move the acceleration by metres per second squared (a ≈ 2.8 m/s² here); on the
    // fitted grid (2.5e-15 s off the exact one per interval) they are the exact-stamp ones
    // to the rounding of the times to doubles: a time moved by one ulp at 300 s (5.7e-14 s)
    // moves a second difference of u = 0.2 m by about 0.2·5.7e-14/Δt³ ≈ 1e-7 m/s², a first
    // difference by 0.2·5.7e-14/Δt² ≈ 5e-10 m/s. Measured: 6.9e-11 m/s and 1.8e-9 m/s².
    let dv = max_abs_difference(&derived[0].0, &derived[1].0);
    let da = max_abs_difference(&derived[0].1, &derived[1].1);
    assert!(
        dv < 5e-10 && da < 1e-7,
        "max |Δv| = {dv} m/s, max |Δa| = {da} m/s²"
    );
}

#[test]
fn compare_accepts_a_recording_with_rounded_stamps() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = write_force(dir.path(), false);
    let simulated = dir.path().join("sim.csv");
    ok(platen(&[
        "simulate",
        &scenario,
        "--out",
        simulated.to_str().unwrap(),
    ]));
    let recorded = dir.path().join("recorded.csv");
    round_stamps(&simulated, &recorded);
    let o = ok(platen(&[
        "compare",
        &scenario,
        "--recorded",
        recorded.to_str().unwrap(),
        "--json",
    ]));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    // The simulation interpolated onto stamps that are up to 5e-6 s off its own samples: the
    // displacement differs by at most v·5e-6 s (≈ 5e-6 m of ≈ 0.3 m), NRMSE well under 1e-4.
    let nrmse = summary["u_m"]["nrmse"].as_f64().unwrap();
    assert!(nrmse < 1e-4, "u NRMSE {nrmse}");
}

#[test]
fn identify_takes_a_recorded_test_with_rounded_stamps_as_it_takes_exact_ones() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("s9.json");
    std::fs::write(
        &scenario,
        format!(
            r#"{{"model": {{"preset": "lhpost-2008"}}, "excitation": {{"sine_motion":
                {{"amplitude_m": 0.2, "frequency_hz": 0.6, "sample_rate_hz": {RATE_HZ}}}}},
                "duration_s": {SECONDS}}}"#
        ),
    )
    .unwrap();
    let exact = dir.path().join("exact.csv");
    ok(platen(&[
        "generate",
        "recorded",
        scenario.to_str().unwrap(),
        "--seed",
        "1",
        "--out",
        exact.to_str().unwrap(),
    ]));
    let rounded = dir.path().join("rounded.csv");
    round_stamps(&exact, &rounded);
    let identified: Vec<Value> = [&exact, &rounded]
        .iter()
        .map(|f| {
            let o = ok(platen(&["identify", f.to_str().unwrap(), "--json"]));
            serde_json::from_slice(&o.stdout).unwrap()
        })
        .collect();
    // Same data on grids 2.5e-15 s apart in interval: every identified number agrees to 1e-6.
    let mut compared = 0;
    for (key, value) in identified[0].as_object().unwrap() {
        if let (Some(a), Some(b)) = (value.as_f64(), identified[1][key].as_f64()) {
            assert!(
                (a - b).abs() <= 1e-6 * a.abs().max(1.0),
                "{key}: {a} (exact stamps) against {b} (rounded)"
            );
            compared += 1;
        }
    }
    assert!(compared >= 3, "{}", identified[0]);
}
