//! `platen_plan::plan`'s `on_run`, the progress hook `platen plan`'s bar is driven by: it
//! reports each run of the drive iteration once, in order, and plans exactly what a plan
//! without it does.

use std::f64::consts::TAU;
use std::path::Path;

use platen::plan::{plan, PlanScenario, PlanSettings, PlanTarget, Target};

#[test]
fn on_run_reports_every_drive_run_in_order_and_plans_what_plan_does() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("scenarios/table-system/wn10g-closed-loop.json");
    let scenario = PlanScenario::load(&path).unwrap();
    // A 1 Hz, 5 cm sine over 8 s with half-cosine ramps at both ends.
    let t: Vec<f64> = (0..=8 * 1024).map(|j| j as f64 / 1024.0).collect();
    let ramp = |x: f64| 0.5 - 0.5 * (std::f64::consts::PI * x.clamp(0.0, 1.0)).cos();
    let u = t
        .iter()
        .map(|&ti| 0.05 * ramp(ti / 2.0) * ramp((8.0 - ti) / 2.0) * (TAU * ti).sin())
        .collect();
    let target = PlanTarget::Platen(Target::displacement(Path::new("sine"), t, u).unwrap());
    let mut settings = PlanSettings {
        max_scale: None,
        ..Default::default()
    };
    settings.iteration.max_iterations = 3;
    settings.iteration.target_nrmse = 0.0;
    let mut runs = Vec::new();
    let observed = plan(&scenario, &target, &settings, &mut |k| runs.push(k)).unwrap();
    let plain = plan(&scenario, &target, &settings, &mut |_| {}).unwrap();
    let (a, b) = (
        observed.summary(&settings, None),
        plain.summary(&settings, None),
    );
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
    let platen::plan::PlannedSummary::Platen(a) = a else {
        panic!("a uniaxial scenario's plan")
    };
    let iterations = a.iterations.len();
    assert!(iterations >= 1, "{iterations}");
    assert_eq!(runs, (0..runs.len()).collect::<Vec<_>>());
    assert!(runs.len() >= iterations && runs.len() <= 4, "{runs:?}");
}
