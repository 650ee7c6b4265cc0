//! The facade re-exports the crates; every shipped scenario loads through it.

use std::path::Path;

use platen::scenario::{Run, Scenario};

#[test]
fn every_shipped_scenario_validates_through_the_facade() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut forward = 0;
    let mut inverse = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            let text = std::fs::read_to_string(&path).unwrap();
            if text.contains("ground_motion") && std::env::var_os("PLATEN_RECORDS_DIR").is_none() {
                eprintln!(
                    "SKIPPED {}: set PLATEN_RECORDS_DIR to load it",
                    path.display()
                );
                continue;
            }
            let s = Scenario::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            match s.run {
                Run::Forward { .. } => forward += 1,
                Run::Inverse { .. } => inverse += 1,
            }
        }
    }
    assert!(
        forward >= 1 && inverse >= 1,
        "forward {forward}, inverse {inverse}"
    );
}

/// A motion given by displacement only: velocity and acceleration are derived by
/// second-order differences, which are exact for a quadratic u = ½·a₀t² + v₀t.
#[test]
fn a_displacement_only_motion_derives_exact_velocity_and_acceleration_for_a_quadratic() {
    let t: Vec<f64> = (0..=100).map(|j| j as f64 / 64.0).collect();
    let (a0, v0) = (0.8, -0.3);
    let u: Vec<f64> = t.iter().map(|&t| 0.5 * a0 * t * t + v0 * t).collect();
    let m = platen::integrate::Motion::from_displacement(t.clone(), u).unwrap();
    for (i, &t) in t.iter().enumerate() {
        assert!((m.v_m_s()[i] - (a0 * t + v0)).abs() < 1e-12, "v at {t}");
        assert!((m.a_m_s2()[i] - a0).abs() < 1e-10, "a at {t}");
    }
}
