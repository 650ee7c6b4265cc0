//! The facade re-exports the crates; every shipped scenario loads through it.

use std::path::{Path, PathBuf};

use platen::scenario::{PlatenScenario, Run};

/// The shipped scenarios at the top of `scenarios/`: those that need a PEER record (a
/// `ground_motion`) and the others.
fn shipped_scenarios() -> (Vec<PathBuf>, Vec<PathBuf>) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    paths.into_iter().partition(|p| {
        std::fs::read_to_string(p)
            .unwrap()
            .contains("ground_motion")
    })
}

#[test]
fn every_shipped_scenario_without_a_record_validates_through_the_facade() {
    let (mut forward, mut inverse, mut closed_loop) = (0, 0, 0);
    for path in shipped_scenarios().1 {
        let s = PlatenScenario::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        match s.run {
            Run::Forward { .. } => forward += 1,
            Run::Inverse { .. } => inverse += 1,
            Run::ClosedLoop { .. } => closed_loop += 1,
        }
        // A rig with a table system runs its motion as the loop's command.
        assert_eq!(
            s.rig.table_system.is_some(),
            matches!(s.run, Run::ClosedLoop { .. }),
            "{}",
            path.display()
        );
    }
    assert!(
        forward >= 1 && inverse >= 1,
        "forward {forward}, inverse {inverse}, closed loop {closed_loop}"
    );
}

#[test]
#[cfg_attr(
    not(platen_records),
    ignore = "needs PLATEN_RECORDS_DIR: a folder of PEER NGA records"
)]
fn every_shipped_record_scenario_validates_through_the_facade() {
    let records = shipped_scenarios().0;
    assert!(records.len() >= 2, "{records:?}");
    for path in records {
        let s = PlatenScenario::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(matches!(s.run, Run::Inverse { .. }), "{}", path.display());
    }
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
