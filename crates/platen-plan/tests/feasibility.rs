//! Feasibility on the LHPOST preset: a target beyond the stroke or the velocity limit is an
//! answer (infeasible, the limit named), the largest scale that fits agrees with a brute-force
//! scan of the simulated closed loop, and the four table limits are those `simulate` reports.

mod common;

use std::f64::consts::TAU;
use std::path::Path;

use platen_integrate::Trajectory;
use platen_plan::feasibility::{feasibility, limit_uses};
use platen_plan::{
    max_scale, BaselineSettings, MaxScaleSettings, PlanSettings, PlatenLoop, Target, TargetMotion,
};
use platen_scenario::RunSummary;

/// The one plan ([`platen_plan::plan`]) of the uniaxial scenario `rig` (read from `path`).
fn plan(
    rig: &platen_scenario::LoadedRig,
    path: &Path,
    target: &Target,
    settings: &PlanSettings,
) -> platen_plan::Result<platen_plan::Plan> {
    let scenario = platen_plan::PlanScenario::platen(path, rig.clone());
    let target = platen_plan::PlanTarget::Platen(target.clone());
    let p = platen_plan::plan(&scenario, &target, settings, &mut |_| {})?;
    Ok(p.into_platen().expect("a uniaxial scenario's plan"))
}

const RATE_HZ: f64 = 1024.0;

/// `u = A·w(t)·sin(2πft)`, `w` a half-cosine ramp up over the first 2 s and down over the
/// last 2 s: a displacement target that starts and ends at rest.
fn sine_target(amplitude_m: f64, frequency_hz: f64, duration_s: f64) -> Target {
    let n = (duration_s * RATE_HZ) as usize + 1;
    let t: Vec<f64> = (0..n).map(|j| j as f64 / RATE_HZ).collect();
    let ramp = |x: f64| 0.5 - 0.5 * (std::f64::consts::PI * x.clamp(0.0, 1.0)).cos();
    let u = t
        .iter()
        .map(|&ti| {
            amplitude_m
                * ramp(ti / 2.0)
                * ramp((duration_s - ti) / 2.0)
                * (TAU * frequency_hz * ti).sin()
        })
        .collect();
    Target::displacement(Path::new("sine"), t, u).unwrap()
}

fn motion(target: &Target) -> TargetMotion {
    TargetMotion::new(target, &BaselineSettings::default(), 0.75, RATE_HZ).unwrap()
}

/// The largest scale on a grid of `step` from `from` to `to` that fits, by running every one.
fn scan(table: &PlatenLoop<'_>, m: &TargetMotion, from: f64, to: f64, step: f64) -> f64 {
    let mut best = 0.0;
    let mut s = from;
    let mut last_fit = true;
    while s <= to + 1e-12 {
        let u: Vec<f64> = m.u_m.iter().map(|x| x * s).collect();
        let a = table.run(&m.t_s, &u, "scan").unwrap();
        let fits = limit_uses(table, &a).iter().all(|l| l.respected());
        // Monotonic on the grid: once a scale fails, no larger one fits.
        assert!(
            fits <= last_fit,
            "scale {s} fits after a smaller one failed"
        );
        last_fit = fits;
        if fits {
            best = s;
        }
        s += step;
    }
    best
}

#[test]
fn a_target_beyond_the_stroke_is_infeasible_on_the_stroke_and_its_max_scale_is_the_scans() {
    // A constant supply: a 0.9 m sine for 12 s also empties the preset's accumulator bank
    // (the supply_pressure_pa limit), which is not what this test is about.
    let scenario = common::scenario(
        r#"{"model": {"preset": "lhpost-2008"}, "excitation": {},
            "table_system": {"preset": "lhpost-2008", "accumulator": null}}"#,
    );
    let table = PlatenLoop::of_loaded(&scenario, Path::new("lhpost")).unwrap();
    let m = motion(&sine_target(0.9, 0.25, 12.0));
    let f = feasibility(&table, &m, Some(&MaxScaleSettings::default())).unwrap();
    assert!(!f.feasible);
    assert_eq!(f.limiting[0].limit, "stroke_m", "{:?}", f.limiting);
    assert_eq!(
        f.limiting.len(),
        1,
        "only the stroke fails: {:?}",
        f.limiting
    );
    assert!(f.uses.iter().all(|u| u.limit != "supply_pressure_pa"));
    let stroke = f.limiting[0];
    assert!(stroke.ratio > 1.15 && stroke.ratio < 1.25, "{stroke:?}");
    assert_eq!(stroke.allowed, 0.75);
    assert!(!f.limits.stroke_m.respected && f.limits.velocity_m_s.respected);
    let found = f.max_scale.unwrap();
    assert_eq!(found.limiting, vec!["stroke_m"]);
    assert!(found.bracket[1] - found.bracket[0] <= 1e-3 * found.bracket[0]);
    assert!(found.runs <= 14, "{found:?}");
    let scanned = scan(&table, &m, 0.78, 0.88, 0.005);
    assert!(
        (found.scale - scanned).abs() <= 0.01 * scanned,
        "bisection {} vs scan {scanned}",
        found.scale
    );
    // The standalone search agrees with the one inside the feasibility.
    let again = max_scale(&table, &m, &MaxScaleSettings::default()).unwrap();
    assert_eq!(again.scale, found.scale);
}

#[test]
fn a_target_beyond_the_velocity_limit_is_infeasible_on_the_velocity() {
    let scenario = common::lhpost("");
    let table = PlatenLoop::of_loaded(&scenario, Path::new("lhpost")).unwrap();
    let m = motion(&sine_target(0.6, 0.6, 8.0));
    let f = feasibility(&table, &m, Some(&MaxScaleSettings::default())).unwrap();
    assert!(!f.feasible);
    assert_eq!(f.limiting[0].limit, "velocity_m_s", "{:?}", f.limiting);
    let v = f.limiting[0];
    assert!(v.ratio > 1.2, "{v:?}");
    let found = f.max_scale.unwrap();
    assert_eq!(found.limiting[0], "velocity_m_s");
    let scanned = scan(&table, &m, 0.72, 0.86, 0.005);
    assert!(
        (found.scale - scanned).abs() <= 0.01 * scanned,
        "bisection {} vs scan {scanned}",
        found.scale
    );
}

#[test]
fn a_long_period_acceleration_target_cannot_be_brought_inside_the_stroke() {
    // 3 m/s² at 0.15 Hz for 20 s: a displacement of metres that no end correction removes.
    let n = (20.0 * 256.0) as usize + 1;
    let t: Vec<f64> = (0..n).map(|j| j as f64 / 256.0).collect();
    let a = t.iter().map(|&ti| 3.0 * (TAU * 0.15 * ti).sin()).collect();
    let target = Target::acceleration(Path::new("long"), t, a).unwrap();
    let m = TargetMotion::new(&target, &BaselineSettings::default(), 0.75, RATE_HZ).unwrap();
    assert!(m.peak_u_m() > 0.75);
    // No degree removes the drift with a small correction without removing the record itself:
    // Auto keeps the least correction.
    assert_eq!(m.end_degree, Some(3));
    let scenario = common::lhpost("");
    let table = PlatenLoop::of_loaded(&scenario, Path::new("lhpost")).unwrap();
    let f = feasibility(&table, &m, None).unwrap();
    assert!(!f.feasible);
    assert_eq!(f.limiting[0].limit, "stroke_m");
    assert!(f.max_scale.is_none());
    // Its command drives the platen to the end of the actuators: an answer, with no drive.
    let end = f.achieved.end_stop.expect("the model's end stop");
    assert!(end.value.abs() > 0.75 && end.t_s > 0.0, "{end:?}");
    assert_eq!(f.limiting[0].peak, end.value);
    let p = plan(
        &scenario,
        Path::new("lhpost"),
        &target,
        &PlanSettings::default(),
    )
    .unwrap();
    assert!(p.drive().is_none());
    let summary = p.summary(None);
    assert_eq!(summary.stop, "not_run");
    assert!(summary.iterations.is_empty() && summary.drive.is_none());
    assert!(
        summary.warnings[0].contains("end of its actuators"),
        "{:?}",
        summary.warnings
    );
}

#[test]
fn a_small_target_fits_with_room_and_its_limits_are_simulates() {
    let json = common::lhpost_json("");
    let scenario = common::scenario(&json);
    let table = PlatenLoop::of_loaded(&scenario, Path::new("lhpost")).unwrap();
    let (t, a) = common::accelerogram(2, 10.0, RATE_HZ, 0.3);
    let target = Target::acceleration(Path::new("eq"), t, a).unwrap();
    let m = TargetMotion::new(&target, &BaselineSettings::default(), 0.75, RATE_HZ).unwrap();
    // The treatment starts and ends at rest at zero.
    let last = m.len() - 1;
    for x in [m.u_m[0], m.v_m_s[0], m.u_m[last], m.v_m_s[last]] {
        assert!(x.abs() < 1e-12, "{x}");
    }
    let f = feasibility(&table, &m, Some(&MaxScaleSettings::default())).unwrap();
    assert!(f.feasible, "{:?}", f.limiting);
    assert!(f.limiting.is_empty());
    let names: Vec<_> = f.uses.iter().map(|u| u.limit).collect();
    assert_eq!(
        names,
        [
            "stroke_m",
            "velocity_m_s",
            "acceleration_m_s2",
            "force_n",
            "valve_flow_m3_s",
            "supply_pressure_pa"
        ]
    );
    let found = f.max_scale.unwrap();
    assert!(found.scale > 1.0 && !found.at_upper_bound, "{found:?}");
    // The same command run as `simulate` runs a motion_csv: the same four limits.
    let replay = common::scenario_with(&json, m.t_s.clone(), m.u_m.clone());
    let mut out = Trajectory::default();
    let output = replay.run(&mut out).unwrap();
    let summary = RunSummary::new(Path::new("replay"), &replay, &output, None);
    assert_eq!(summary.limits, f.limits);
}

#[test]
fn a_tiny_target_fits_at_the_upper_bound() {
    let scenario = common::lhpost("");
    let table = PlatenLoop::of_loaded(&scenario, Path::new("lhpost")).unwrap();
    let m = motion(&sine_target(1e-4, 1.0, 6.0));
    let settings = MaxScaleSettings {
        max_scale: 20.0,
        ..MaxScaleSettings::default()
    };
    let found = max_scale(&table, &m, &settings).unwrap();
    assert!(found.at_upper_bound, "{found:?}");
    assert_eq!(found.scale, 20.0);
}
