//! `table_system` in a scenario: bad values are refused when the scenario is loaded (before
//! anything runs) with their JSON path and what was expected; a preset takes overrides value
//! by value; an explicit system is the one built by hand; a closed-loop run is deterministic to
//! the byte; an unstable loop runs and says so.

use std::fs;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use platen_integrate::{LoopMethod, SampleSink, Trajectory};
use platen_scenario::{CsvSink, LoopSettings, PlatenScenario, Run, RunSummary, ScenarioError};
use platen_system::{
    preset, Accumulator, Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts,
};

/// A short closed-loop scenario: the identified LHPOST platen commanded by a 2 cm, 1 Hz sine,
/// with `table_system` as given.
fn scenario_with(table_system: Value) -> Value {
    json!({
        "name": "closed loop",
        "model": {"preset": "lhpost-2008"},
        "table_system": table_system,
        "excitation": {"sine_motion": {"amplitude_m": 0.02, "frequency_hz": 1.0}},
        "duration_s": 0.25
    })
}

/// The scenario with `key` (a top-level key) set to `value` (`null` removes it).
fn with(mut scenario: Value, key: &str, value: Value) -> Value {
    let object = scenario.as_object_mut().unwrap();
    if value.is_null() {
        object.remove(key);
    } else {
        object.insert(key.to_owned(), value);
    }
    scenario
}

/// The preset with `overrides` laid over it (an object merged into `{"preset": …}`).
fn lhpost(overrides: Value) -> Value {
    let mut ts = json!({"preset": "lhpost-2008"});
    for (k, v) in overrides.as_object().unwrap() {
        ts[k] = v.clone();
    }
    ts
}

fn write(dir: &Path, name: &str, scenario: &Value) -> PathBuf {
    let path = dir.join(format!("{name}.json"));
    fs::write(&path, serde_json::to_string_pretty(scenario).unwrap()).unwrap();
    path
}

/// The loop settings of a closed-loop scenario's run.
fn loop_of(s: &PlatenScenario) -> LoopSettings {
    match &s.run {
        Run::ClosedLoop { settings, .. } => *settings,
        other => panic!("not a closed loop: {other:?}"),
    }
}

fn load(scenario: &Value) -> Result<PlatenScenario, ScenarioError> {
    let dir = tempfile::tempdir().unwrap();
    PlatenScenario::load(&write(dir.path(), "scenario", scenario))
}

/// Loads `scenario`, which must be refused naming `json_path` and saying `expected`.
fn refused(scenario: &Value, json_path: &str, expected: &str) -> String {
    let error = match load(scenario) {
        Ok(s) => panic!("accepted ({json_path}): {:?}", s.rig.table_system),
        Err(e) => e,
    };
    let message = error.to_string();
    match &error {
        ScenarioError::Io(io) => assert_eq!(io.field(), Some(json_path), "{message}"),
        other => panic!("not a scenario-field error for {json_path}: {other:?}"),
    }
    assert!(
        message.contains(json_path),
        "{json_path} not in the message: {message}"
    );
    assert!(
        message.contains(expected),
        "{expected:?} not in the message: {message}"
    );
    message
}

/// An explicit double-ended table: one 0.02 m² actuator, one valve, 4096 Hz controller.
fn explicit() -> Value {
    json!({
        "actuator": {"count": 1, "area_m2": 0.02, "chamber_volume_m3": 0.02,
                     "leakage_m3_s_per_pa": 1e-11},
        "servo_valve": {"count": 1, "rated_flow_m3_s": 0.01, "rated_pressure_drop_pa": 7e6,
                        "natural_frequency_hz": 120, "damping_ratio": 0.7, "delay_s": 0.0005},
        "oil_bulk_modulus_pa": 1.2e9,
        "supply_pressure_pa": 21e6,
        "return_pressure_pa": 3e5,
        "controller": {"sample_rate_hz": 4096, "displacement_gain_per_m": 20,
                       "velocity_feedforward_s_per_m": 0.9, "delta_p_gain_per_pa": 2e-8,
                       "delta_p_highpass_hz": 1}
    })
}

/// `explicit()`, built in Rust.
fn explicit_by_hand() -> TableSystem {
    TableSystem::new(
        TableSystemParts {
            actuator: Actuator {
                count: 1,
                cap_area_m2: 0.02,
                rod_area_m2: 0.02,
                cap_volume_m3: 0.02,
                rod_volume_m3: 0.02,
                leakage_m3_s_per_pa: 1e-11,
            },
            servo_valve: ServoValve {
                count: 1,
                rated_flow_m3_s: 0.01,
                rated_pressure_drop_pa: 7e6,
                natural_frequency_hz: 120.0,
                damping_ratio: 0.7,
                delay_s: 0.0005,
            },
            oil_bulk_modulus_pa: 1.2e9,
            supply_pressure_pa: 21e6,
            return_pressure_pa: 3e5,
            supply: Supply::Constant,
            controller: Controller {
                sample_rate_hz: 4096.0,
                displacement_gain_per_m: 20.0,
                integral_gain_per_m_s: 0.0,
                velocity_feedforward_s_per_m: 0.9,
                acceleration_feedforward_s2_per_m: 0.0,
                velocity_feedback_s_per_m: 0.0,
                acceleration_feedback_s2_per_m: 0.0,
                delta_p_gain_per_pa: 2e-8,
                delta_p_highpass_hz: 1.0,
            },
        },
        0.0,
    )
    .unwrap()
}

// ---------------------------------------------------------------------------------------
// Refused before anything runs, with the JSON path and what was expected.
// ---------------------------------------------------------------------------------------

#[test]
fn non_positive_areas_volumes_bulk_modulus_and_supply_are_refused() {
    let cases = [
        (
            json!({"actuator": {"area_m2": 0}}),
            "table_system.actuator.cap_side_area_m2",
        ),
        (
            json!({"actuator": {"area_m2": -0.1}}),
            "table_system.actuator.cap_side_area_m2",
        ),
        (
            json!({"actuator": {"cap_side_area_m2": 0.2, "rod_side_area_m2": 0}}),
            "table_system.actuator.rod_side_area_m2",
        ),
        (
            json!({"actuator": {"chamber_volume_m3": 0}}),
            "table_system.actuator.chamber_volume_m3",
        ),
        (
            json!({"actuator": {"chamber_volume_m3": [0.3, -0.2]}}),
            "table_system.actuator.chamber_volume_m3",
        ),
        (
            json!({"oil_bulk_modulus_pa": 0}),
            "table_system.oil_bulk_modulus_pa",
        ),
        (
            json!({"oil_bulk_modulus_pa": -1e9}),
            "table_system.oil_bulk_modulus_pa",
        ),
        (
            json!({"supply_pressure_pa": 0}),
            "table_system.supply_pressure_pa",
        ),
        (
            json!({"supply_pressure_pa": -2e7}),
            "table_system.supply_pressure_pa",
        ),
    ];
    for (overrides, path) in cases {
        refused(
            &scenario_with(lhpost(overrides)),
            path,
            "a finite number > 0",
        );
    }
}

#[test]
fn a_return_pressure_at_or_above_the_supply_is_refused() {
    for ret in [20.7e6, 25e6] {
        refused(
            &scenario_with(lhpost(json!({"return_pressure_pa": ret}))),
            "table_system.return_pressure_pa",
            "below the supply pressure 20700000 Pa",
        );
    }
    // Explicit system, the supply (1 MPa, low but a supply) under the return (2 MPa). A
    // supply below 0.5 MPa is refused as such first (a unit slip; `tests/unit_mistakes.rs`).
    let mut ts = explicit();
    ts["supply_pressure_pa"] = json!(1e6);
    ts["return_pressure_pa"] = json!(2e6);
    refused(
        &scenario_with(ts),
        "table_system.return_pressure_pa",
        "below the supply pressure",
    );
}

#[test]
fn a_chamber_that_would_empty_within_the_stroke_is_refused() {
    // The preset's cap side: 0.2051 m² × 0.75 m = 0.153825 m³.
    let message = refused(
        &scenario_with(lhpost(
            json!({"actuator": {"chamber_volume_m3": [0.15, 0.1335]}}),
        )),
        "table_system.actuator.chamber_volume_m3",
        "the cap-side chamber would empty at u = −0.75 m",
    );
    assert!(message.contains("0.153825"), "{message}");
    // Rod side: 0.1291 m² × 0.75 m = 0.096825 m³.
    refused(
        &scenario_with(lhpost(
            json!({"actuator": {"chamber_volume_m3": [0.2122, 0.09]}}),
        )),
        "table_system.actuator.chamber_volume_m3",
        "the rod-side chamber would empty at u = +0.75 m",
    );
    // Exactly empty at the stroke's end is refused too (V₀ − A·stroke = 0).
    refused(
        &scenario_with(lhpost(
            json!({"actuator": {"area_m2": 0.2, "chamber_volume_m3": 0.15}}),
        )),
        "table_system.actuator.chamber_volume_m3",
        "would empty",
    );
    // The scenario's own `limits.stroke_m` is the stroke checked: a shorter stroke keeps
    // the same chamber full.
    let short = with(
        scenario_with(lhpost(
            json!({"actuator": {"chamber_volume_m3": [0.15, 0.1335]}}),
        )),
        "limits",
        json!({"stroke_m": 0.5}),
    );
    assert!(load(&short).unwrap().rig.table_system.is_some());
}

#[test]
fn a_valve_at_0_hz_and_a_controller_at_0_hz_are_refused() {
    refused(
        &scenario_with(lhpost(json!({"servo_valve": {"natural_frequency_hz": 0}}))),
        "table_system.servo_valve.natural_frequency_hz",
        "a finite number > 0",
    );
    refused(
        &scenario_with(lhpost(json!({"controller": {"sample_rate_hz": 0}}))),
        "table_system.controller.sample_rate_hz",
        "a finite number > 0",
    );
    // The same with an explicit system and an integrator step (whose check needs the
    // controller's period: the rate is refused first).
    let mut ts = explicit();
    ts["controller"]["sample_rate_hz"] = json!(0);
    let s = with(
        scenario_with(ts),
        "integrator",
        json!({"method": "rk4", "step_s": 0.0001}),
    );
    refused(
        &s,
        "table_system.controller.sample_rate_hz",
        "a finite number > 0",
    );
}

#[test]
fn an_rk4_step_must_divide_the_controller_period_and_resolve_the_fastest_mode() {
    let base = scenario_with(lhpost(json!({})));
    // 1024 Hz controller: period 1/1024 s; 0.0003 s is no whole fraction of it.
    refused(
        &with(
            base.clone(),
            "integrator",
            json!({"method": "rk4", "step_s": 0.0003}),
        ),
        "integrator.step_s",
        "the controller's period 0.0009765625 s divided by a whole number",
    );
    // Longer than the period.
    refused(
        &with(
            base.clone(),
            "integrator",
            json!({"method": "rk4", "step_s": 0.0015}),
        ),
        "integrator.step_s",
        "divided by a whole number",
    );
    // The period itself divides it but does not resolve the 246 Hz spool (h·ω = 1.51).
    let message = refused(
        &with(
            base.clone(),
            "integrator",
            json!({"method": "rk4", "step_s": 0.0009765625}),
        ),
        "integrator.step_s",
        "a step that resolves the loop's fastest mode (246.0 Hz)",
    );
    assert!(message.contains("at most 6.470e-4 s"), "{message}");
    // Half the period resolves it.
    let half = load(&with(
        base.clone(),
        "integrator",
        json!({"method": "rk4", "step_s": 0.00048828125}),
    ))
    .unwrap();
    assert_eq!(
        loop_of(&half).method,
        LoopMethod::Rk4 {
            steps_per_period: 2
        }
    );
    // Default: the least k with h·ω ≤ 0.25: ceil(2π·246/1024/0.25) = 7.
    assert_eq!(
        loop_of(&load(&base).unwrap()).method,
        LoopMethod::Rk4 {
            steps_per_period: 7
        }
    );
    // Dopri5 is allowed, with its tolerances checked.
    let dopri = load(&with(
        base.clone(),
        "integrator",
        json!({"method": "dopri5", "rtol": 1e-7}),
    ))
    .unwrap();
    assert!(matches!(
        loop_of(&dopri).method,
        LoopMethod::Dopri5 { rtol, .. } if rtol == 1e-7
    ));
    refused(
        &with(base, "integrator", json!({"method": "dopri5", "atol": 0})),
        "integrator.atol",
        "a finite tolerance > 0",
    );
}

#[test]
fn a_force_excitation_with_a_table_system_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("t_s,force_n\n");
    for j in 0..=256 {
        csv.push_str(&format!(
            "{},{}\n",
            j as f64 / 1024.0,
            1e4 * (j as f64).sin()
        ));
    }
    fs::write(dir.path().join("force.csv"), csv).unwrap();
    let s = with(
        scenario_with(lhpost(json!({}))),
        "excitation",
        json!({"force_csv": "force.csv"}),
    );
    let s = with(s, "duration_s", Value::Null);
    let error = PlatenScenario::load(&write(dir.path(), "force", &s)).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("excitation.force_csv") && message.contains("a motion excitation"),
        "{message}"
    );
    let s = with(
        scenario_with(lhpost(json!({}))),
        "excitation",
        json!({"sine_force": {"amplitude_n": 1e5, "frequency_hz": 1}}),
    );
    let message = refused(&s, "excitation.sine_force", "a motion excitation");
    assert!(message.contains("displacement command"), "{message}");
}

#[test]
fn an_unknown_key_inside_table_system_is_refused_with_its_path() {
    for (ts, path, key) in [
        (
            json!({"preset": "lhpost-2008", "pressure_pa": 1}),
            "table_system",
            "pressure_pa",
        ),
        (
            json!({"preset": "lhpost-2008", "actuator": {"areas_m2": 0.2}}),
            "table_system.actuator",
            "areas_m2",
        ),
        (
            json!({"preset": "lhpost-2008", "servo_valve": {"natural_frequency": 200}}),
            "table_system.servo_valve",
            "natural_frequency",
        ),
        (
            json!({"preset": "lhpost-2008", "controller": {"kp": 3}}),
            "table_system.controller",
            "kp",
        ),
        (
            json!({"preset": "lhpost-2008", "accumulator": {"volume": 3}}),
            "table_system.accumulator",
            "volume",
        ),
    ] {
        let error = load(&scenario_with(ts)).unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains(path) && message.contains(key) && message.contains("unknown"),
            "{path}.{key}: {message}"
        );
        let ScenarioError::Io(io) = &error else {
            panic!("{error:?}")
        };
        let field = io.field().unwrap_or_default();
        assert!(field.starts_with(path), "{field} for {path}.{key}");
    }
}

#[test]
fn an_unknown_preset_lists_the_valid_names() {
    let message = refused(
        &scenario_with(json!({"preset": "lhpost-2099"})),
        "table_system.preset",
        "lhpost-2008",
    );
    assert!(message.contains("lhpost-2099"), "{message}");
}

#[test]
fn both_area_forms_at_once_are_refused() {
    for actuator in [
        json!({"area_m2": 0.2, "cap_side_area_m2": 0.2}),
        json!({"area_m2": 0.2, "rod_side_area_m2": 0.1}),
        json!({"area_m2": 0.2, "cap_side_area_m2": 0.2, "rod_side_area_m2": 0.1}),
    ] {
        refused(
            &scenario_with(lhpost(json!({ "actuator": actuator }))),
            "table_system.actuator.area_m2",
            "either `area_m2` (double-ended) or `cap_side_area_m2` and `rod_side_area_m2`, not both",
        );
    }
}

#[test]
fn a_value_missing_without_a_preset_is_named() {
    // Each required value of the explicit system, removed in turn.
    for (section, key, path) in [
        (Some("actuator"), "count", "table_system.actuator.count"),
        (
            Some("actuator"),
            "area_m2",
            "table_system.actuator.cap_side_area_m2",
        ),
        (
            Some("actuator"),
            "chamber_volume_m3",
            "table_system.actuator.chamber_volume_m3",
        ),
        (
            Some("servo_valve"),
            "count",
            "table_system.servo_valve.count",
        ),
        (
            Some("servo_valve"),
            "rated_flow_m3_s",
            "table_system.servo_valve.rated_flow_m3_s",
        ),
        (
            Some("servo_valve"),
            "rated_pressure_drop_pa",
            "table_system.servo_valve.rated_pressure_drop_pa",
        ),
        (
            Some("servo_valve"),
            "natural_frequency_hz",
            "table_system.servo_valve.natural_frequency_hz",
        ),
        (
            Some("servo_valve"),
            "damping_ratio",
            "table_system.servo_valve.damping_ratio",
        ),
        (
            None,
            "oil_bulk_modulus_pa",
            "table_system.oil_bulk_modulus_pa",
        ),
        (
            None,
            "supply_pressure_pa",
            "table_system.supply_pressure_pa",
        ),
        (
            None,
            "return_pressure_pa",
            "table_system.return_pressure_pa",
        ),
        (
            Some("controller"),
            "sample_rate_hz",
            "table_system.controller.sample_rate_hz",
        ),
    ] {
        let mut ts = explicit();
        match section {
            Some(s) => ts[s].as_object_mut().unwrap().remove(key),
            None => ts.as_object_mut().unwrap().remove(key),
        }
        .unwrap();
        let message = refused(&scenario_with(ts), path, "(missing)");
        assert!(
            message.contains("a value (or a `preset` to take it from)")
                || message.contains("a count ≥ 1")
                || message.contains("a volume, or [cap, rod]")
                || message.contains("the controller's sample rate"),
            "{message}"
        );
    }
    // A single-ended actuator needs both areas.
    let mut ts = explicit();
    ts["actuator"] = json!({"count": 1, "cap_side_area_m2": 0.02, "chamber_volume_m3": 0.02});
    refused(
        &scenario_with(ts),
        "table_system.actuator.rod_side_area_m2",
        "(missing)",
    );
    // Whole sections missing, and an empty system.
    let mut ts = explicit();
    ts.as_object_mut().unwrap().remove("controller");
    refused(
        &scenario_with(ts),
        "table_system.controller.sample_rate_hz",
        "(missing)",
    );
    refused(
        &scenario_with(json!({})),
        "table_system.actuator.count",
        "(missing)",
    );
    // An accumulator without a preset needs all its values.
    let mut ts = explicit();
    ts["accumulator"] = json!({"precharge_pressure_pa": 1e7, "volume_m3": 1,
                               "polytropic_exponent": 1.4});
    refused(
        &scenario_with(ts),
        "table_system.accumulator.pump_flow_m3_s",
        "(missing)",
    );
}

#[test]
fn initial_from_record_with_a_table_system_is_refused() {
    let s = with(
        scenario_with(lhpost(json!({}))),
        "initial",
        json!({"from_record": true}),
    );
    refused(
        &s,
        "initial.from_record",
        "a closed loop has no force record",
    );
    // A given initial state is taken as it is.
    let s = with(
        scenario_with(lhpost(json!({}))),
        "initial",
        json!({"u_m": 0.01, "v_m_s": 0.0}),
    );
    let cl = loop_of(&load(&s).unwrap());
    assert_eq!(cl.initial_state(0.0).u_m, 0.01);
}

#[test]
fn without_a_table_system_a_motion_run_takes_no_integrator() {
    // Without a table_system a motion run takes neither (the check that the table_system
    // lifts).
    let s = with(
        with(scenario_with(Value::Null), "table_system", Value::Null),
        "integrator",
        json!({"method": "rk4", "step_s": 0.00048828125}),
    );
    refused(&s, "integrator", "no integrator");
}

// ---------------------------------------------------------------------------------------
// What a valid table_system builds.
// ---------------------------------------------------------------------------------------

#[test]
fn preset_overrides_change_only_what_they_name() {
    let s = load(&scenario_with(lhpost(
        json!({"controller": {"displacement_gain_per_m": 5}}),
    )))
    .unwrap();
    let mut expected = preset::lhpost_2008().into_parts();
    assert_ne!(expected.controller.displacement_gain_per_m, 5.0);
    expected.controller.displacement_gain_per_m = 5.0;
    assert_eq!(s.rig.table_system.unwrap().into_parts(), expected);

    // The preset alone is the preset.
    let s = load(&scenario_with(lhpost(json!({})))).unwrap();
    assert_eq!(s.rig.table_system.unwrap(), preset::lhpost_2008());

    // One value deep inside each section.
    let s = load(&scenario_with(lhpost(json!({
        "actuator": {"leakage_m3_s_per_pa": 0},
        "servo_valve": {"delay_s": 0.001},
        "accumulator": {"volume_m3": 4},
        "supply_pressure_pa": 21e6
    }))))
    .unwrap();
    let mut expected = preset::lhpost_2008().into_parts();
    expected.actuator.leakage_m3_s_per_pa = 0.0;
    expected.servo_valve.delay_s = 0.001;
    expected.supply_pressure_pa = 21e6;
    let Supply::Accumulator(bank) = &mut expected.supply else {
        panic!("the preset has an accumulator")
    };
    bank.volume_m3 = 4.0;
    assert_eq!(s.rig.table_system.unwrap().into_parts(), expected);

    // A double-ended area over the single-ended preset sets both sides.
    let s = load(&scenario_with(lhpost(
        json!({"actuator": {"area_m2": 0.15}}),
    )))
    .unwrap();
    let a = *s.rig.table_system.unwrap().actuator();
    assert_eq!((a.cap_area_m2, a.rod_area_m2), (0.15, 0.15));
    assert_eq!(
        (a.cap_volume_m3, a.rod_volume_m3),
        (0.2122, 0.1335),
        "the preset's volumes stay"
    );
}

#[test]
fn a_null_accumulator_is_a_constant_supply() {
    let s = load(&scenario_with(lhpost(json!({"accumulator": null})))).unwrap();
    let system = s.rig.table_system.unwrap();
    assert_eq!(*system.supply(), Supply::Constant);
    let mut expected = preset::lhpost_2008().into_parts();
    expected.supply = Supply::Constant;
    assert_eq!(system.into_parts(), expected);
    // Absent: the preset's bank.
    let s = load(&scenario_with(lhpost(json!({})))).unwrap();
    assert!(matches!(
        s.rig.table_system.unwrap().supply(),
        Supply::Accumulator(_)
    ));
}

#[test]
fn an_explicit_double_ended_system_equals_the_one_built_by_hand() {
    let s = load(&scenario_with(explicit())).unwrap();
    assert_eq!(s.rig.table_system.unwrap(), explicit_by_hand());
    assert_eq!(loop_of(&s).initial, None);
    // Both chamber forms, and single-ended areas, give the same double-ended system.
    let mut ts = explicit();
    ts["actuator"] = json!({"count": 1, "cap_side_area_m2": 0.02, "rod_side_area_m2": 0.02,
                            "chamber_volume_m3": [0.02, 0.02], "leakage_m3_s_per_pa": 1e-11});
    assert_eq!(
        load(&scenario_with(ts)).unwrap().rig.table_system.unwrap(),
        explicit_by_hand()
    );
    // An explicit accumulator.
    let mut ts = explicit();
    ts["accumulator"] = json!({"precharge_pressure_pa": 1e7, "volume_m3": 0.5,
                               "polytropic_exponent": 1.4, "pump_flow_m3_s": 0.002});
    let mut expected = explicit_by_hand().into_parts();
    expected.supply = Supply::Accumulator(Accumulator {
        precharge_pressure_pa: 1e7,
        volume_m3: 0.5,
        polytropic_exponent: 1.4,
        pump_flow_m3_s: 0.002,
    });
    assert_eq!(
        load(&scenario_with(ts))
            .unwrap()
            .rig
            .table_system
            .unwrap()
            .into_parts(),
        expected
    );
    // And the system runs: every sample carries the loop's columns.
    let mut trajectory = Trajectory::default();
    let output = s.run(&mut trajectory).unwrap();
    let system = trajectory.system.as_ref().expect("system columns");
    assert_eq!(system.drive.len(), trajectory.t_s.len());
    assert_eq!(trajectory.t_s.len(), 257);
    assert!(output.system.is_some());
}

// ---------------------------------------------------------------------------------------
// Runs.
// ---------------------------------------------------------------------------------------

/// Runs the scenario at `path` into a CSV with the system's columns; the file's bytes.
fn run_to_csv(path: &Path, out: &Path) -> Vec<u8> {
    let scenario = PlatenScenario::load(path).unwrap();
    let mut sink = CsvSink::create_for(out, scenario.storeys(), true).unwrap();
    scenario.run(&mut sink).unwrap();
    sink.finish().unwrap();
    fs::read(out).unwrap()
}

#[test]
fn a_closed_loop_run_writes_the_same_bytes_twice() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "loop", &scenario_with(lhpost(json!({}))));
    let first = run_to_csv(&path, &dir.path().join("first.csv"));
    let second = run_to_csv(&path, &dir.path().join("second.csv"));
    assert!(first == second, "two runs of one scenario differ");
    let text = String::from_utf8(first).unwrap();
    let header = text.lines().next().unwrap();
    assert_eq!(
        header,
        "t_s,u_m,v_m_s,a_m_s2,force_n,inertial_force_n,elastic_force_n,dissipative_force_n,\
         command_u_m,drive,spool_opening,delta_p_pa,flow_m3_s,supply_pressure_pa,\
         cap_pressure_pa,rod_pressure_pa"
    );
    assert_eq!(text.lines().count(), 1 + 257);
    // Dopri5 too.
    let path = write(
        dir.path(),
        "loop-dopri5",
        &with(
            scenario_with(lhpost(json!({}))),
            "integrator",
            json!({"method": "dopri5"}),
        ),
    );
    let first = run_to_csv(&path, &dir.path().join("first-dopri5.csv"));
    let second = run_to_csv(&path, &dir.path().join("second-dopri5.csv"));
    assert!(first == second, "two Dopri5 runs of one scenario differ");
}

/// Counts samples and checks that every one is finite.
#[derive(Default)]
struct Finite {
    samples: usize,
    non_finite: usize,
}

impl SampleSink for Finite {
    fn accept(&mut self, s: &platen_integrate::Sample) {
        self.samples += 1;
        let sy = s.system.expect("system sample");
        if ![
            s.u_m,
            s.v_m_s,
            s.a_m_s2,
            s.terms.actuator_n,
            sy.drive,
            sy.delta_p_pa,
        ]
        .iter()
        .all(|x| x.is_finite())
        {
            self.non_finite += 1;
        }
    }
}

#[test]
fn an_unstable_loop_runs_and_warns_with_its_margins() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "unstable",
        &scenario_with(lhpost(
            json!({"controller": {"displacement_gain_per_m": 1e4}}),
        )),
    );
    let scenario = PlatenScenario::load(&path).unwrap();
    let (_, margins) = scenario.rig.loop_linearisation().unwrap();
    assert!(!margins.stable, "{margins:?}");
    let mut sink = Finite::default();
    // Never a panic: either the run finishes or it stops with a numerical failure.
    match scenario.run(&mut sink) {
        Ok(output) => {
            assert_eq!(sink.samples, 257);
            assert_eq!(sink.non_finite, 0);
            let summary = RunSummary::new(&path, &scenario, &output, None);
            let warning = summary
                .warnings
                .iter()
                .find(|w| w.contains("unstable"))
                .unwrap_or_else(|| panic!("no instability warning in {:?}", summary.warnings));
            assert!(
                warning.contains("gain margin") && warning.contains("phase margin"),
                "{warning}"
            );
            if let Some(g) = margins.gain_margin_db {
                assert!(warning.contains(&format!("{g:.1} dB")), "{warning}");
            }
            let ts = summary.table_system.as_ref().unwrap();
            assert!(!ts.loop_margins.stable);
            assert!(ts.valve_saturated_time_s > 0.0, "{ts:?}");
            // The summary serialises (as `--json` prints it).
            let v = serde_json::to_value(&summary).unwrap();
            assert_eq!(v["table_system"]["loop_margins"]["stable"], json!(false));
        }
        Err(ScenarioError::Run(cause)) => {
            eprintln!("unstable loop stopped cleanly: {cause}");
        }
        Err(other) => panic!("unexpected error: {other:?}"),
    }
}

#[test]
fn a_stable_loop_has_no_instability_warning_and_reports_its_figures() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "stable", &scenario_with(lhpost(json!({}))));
    let scenario = PlatenScenario::load(&path).unwrap();
    let mut trajectory = Trajectory::default();
    let output = scenario.run(&mut trajectory).unwrap();
    let summary = RunSummary::new(&path, &scenario, &output, None);
    assert!(
        !summary.warnings.iter().any(|w| w.contains("unstable")),
        "{:?}",
        summary.warnings
    );
    let f = summary.oil_column_frequency_hz.unwrap();
    assert!((f - 10.66).abs() < 0.02, "{f}");
    let ts = summary.table_system.as_ref().unwrap();
    assert!(ts.loop_margins.stable);
    assert!(ts.tracking_displacement_rms_m.is_finite());
    assert!(
        ts.tracking_displacement_rms_m < 0.02,
        "{}",
        ts.tracking_displacement_rms_m
    );
    assert_eq!(ts.steps_per_controller_period, 7);
    assert_eq!(summary.direction, "forward");
}

// ---------------------------------------------------------------------------------------
// Regressions of fixes in `system.rs`.
// ---------------------------------------------------------------------------------------

#[test]
fn a_malformed_chamber_volume_says_what_was_expected() {
    for volume in [
        json!([0.3]),
        json!("big"),
        json!([0.3, 0.2, 0.1]),
        json!({"cap": 0.3}),
    ] {
        let s = scenario_with(lhpost(json!({"actuator": {"chamber_volume_m3": volume}})));
        let error = load(&s).unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains("table_system.actuator.chamber_volume_m3")
                && message.contains("[cap, rod]"),
            "{volume}: {message}"
        );
        assert!(!message.contains("untagged"), "{message}");
    }
    // Integers are volumes too.
    let s = scenario_with(lhpost(json!({"actuator": {"chamber_volume_m3": [1, 1]}})));
    let a = *load(&s).unwrap().rig.table_system.unwrap().actuator();
    assert_eq!((a.cap_volume_m3, a.rod_volume_m3), (1.0, 1.0));
}

#[test]
fn a_loop_too_fast_for_rk4_is_refused_instead_of_run_at_a_clamped_step() {
    // A 1 GHz spool is no servo-valve's (rad/s written as Hz, or a typing error): refused as
    // such whatever the integrator, before any step is chosen.
    let fast_valve = scenario_with(lhpost(
        json!({"servo_valve": {"natural_frequency_hz": 1e9}}),
    ));
    refused(
        &fast_valve,
        "table_system.servo_valve.natural_frequency_hz",
        "at most 5000 Hz",
    );
    refused(
        &with(fast_valve, "integrator", json!({"method": "dopri5"})),
        "table_system.servo_valve.natural_frequency_hz",
        "at most 5000 Hz",
    );
    // Oil that stiff (β = 1e24 Pa) is refused as no oil, before the step is chosen.
    refused(
        &scenario_with(lhpost(json!({"oil_bulk_modulus_pa": 1e24}))),
        "table_system.oil_bulk_modulus_pa",
        "is stiffer than any oil",
    );
    // The fastest spool taken (5 kHz) is resolved by RK4 at the controller's rate, with
    // more steps per period than the LHPOST's 246 Hz spool takes.
    let s = scenario_with(lhpost(
        json!({"servo_valve": {"natural_frequency_hz": 5000.0}}),
    ));
    let LoopMethod::Rk4 { steps_per_period } = loop_of(&load(&s).unwrap()).method else {
        panic!("RK4 by default");
    };
    let base = loop_of(&load(&scenario_with(lhpost(json!({})))).unwrap())
        .method
        .steps_per_period();
    assert!(
        steps_per_period > 10 * base,
        "{steps_per_period} against {base}"
    );
}

#[test]
fn an_rk4_step_below_a_millionth_of_the_period_is_refused() {
    // 1/1024 s / 2^40: a whole fraction that would have been cast to u32::MAX steps.
    let step = 0.0009765625 / 2f64.powi(40);
    refused(
        &with(
            scenario_with(lhpost(json!({}))),
            "integrator",
            json!({"method": "rk4", "step_s": step}),
        ),
        "integrator.step_s",
        "at least the controller's period",
    );
}

#[test]
fn a_table_system_spec_written_back_reads_as_the_same_system() {
    for ts in [
        json!({"preset": "lhpost-2008"}),
        json!({"preset": "lhpost-2008", "accumulator": null}),
        json!({"preset": "lhpost-2008", "accumulator": {"volume_m3": 3}}),
        explicit(),
    ] {
        let spec: platen_scenario::TableSystemSpec = serde_json::from_value(ts.clone()).unwrap();
        let written = serde_json::to_value(&spec).unwrap();
        let (first, again) = (
            load(&scenario_with(ts.clone())).unwrap(),
            load(&scenario_with(written.clone())).unwrap(),
        );
        let first = (first.rig.table_system, loop_of(&first));
        let again = (again.rig.table_system, loop_of(&again));
        assert_eq!(first, again, "{ts} written as {written}");
    }
}
