//! `platen model --system PRESET` and `platen model --scenario FILE`: the table system's
//! closed forms (oil column, capacities), its linearised loop (margins) and the Bode plots of
//! `--plot`.

use std::f64::consts::PI;
use std::fs;
use std::path::Path;
use std::process::Output;

use serde_json::Value;

mod common;
use common::{check_png, platen, stderr, svg_content};

/// The published and derived numbers of the `lhpost-2008` table system (see
/// `platen_system::preset`): two actuators, cap and rod areas, chamber volumes at
/// mid-stroke, the oil's bulk modulus, and the identified effective mass Mₑ = 144 t.
const N: f64 = 2.0;
const A_A_M2: f64 = 0.2051;
const A_B_M2: f64 = 0.1291;
const V_A_M3: f64 = 0.2122;
const V_B_M3: f64 = 0.1335;
const BETA_PA: f64 = 1e9;
const M_KG: f64 = 144_000.0;

/// The oil-column frequency `(1/2π)·√(n·β·(A_a²/V_a + A_b²/V_b)/M)` of a moving mass `m_kg`
/// at mid-stroke, Hz.
fn oil_column_hz(m_kg: f64) -> f64 {
    (N * BETA_PA * (A_A_M2 * A_A_M2 / V_A_M3 + A_B_M2 * A_B_M2 / V_B_M3) / m_kg).sqrt() / (2.0 * PI)
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", stderr(o));
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn ok_json(o: &Output) -> Value {
    serde_json::from_str(&ok(o)).unwrap()
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number `{key}` in {v:#}"))
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// A closed-loop scenario with a two-storey specimen of 30 + 25 t (the frame of
/// `scenarios/specimen`), written to `dir`. Its excitation names a record that does not
/// exist: `platen model` does not read it.
fn specimen_scenario(dir: &Path, table_system: bool) -> String {
    let system = if table_system {
        r#""table_system": {"preset": "lhpost-2008"},"#
    } else {
        ""
    };
    let text = format!(
        r#"{{
  "name": "frame on the table",
  "model": {{"preset": "lhpost-2008"}},
  {system}
  "excitation": {{"motion_csv": "no-such-record.csv"}},
  "specimen": {{"storeys": [
    {{"mass_kg": 30000.0, "stiffness_n_per_m": 27083177.88, "damping_n_s_per_m": 86208.43}},
    {{"mass_kg": 25000.0, "stiffness_n_per_m": 19345127.06, "damping_n_s_per_m": 61577.45}}
  ]}}
}}"#
    );
    let path = dir.join(if table_system {
        "frame-closed-loop.json"
    } else {
        "frame.json"
    });
    fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// The text names the LHPOST's oil column at the paper's 10.66 Hz, after the model's own
/// description, which is printed as `platen model` prints it.
#[test]
fn system_text_names_the_oil_column_at_10_66_hz() {
    let plain = ok(&platen(&["model"]));
    let text = ok(&platen(&["model", "--system", "lhpost-2008"]));
    assert!(text.starts_with(&plain), "{text}");
    let line = text
        .lines()
        .find(|l| l.contains("oil column at mid-stroke, bare table"))
        .unwrap_or_else(|| panic!("no oil-column line in\n{text}"));
    assert!(line.trim_end().ends_with("10.66   Hz"), "{line}");
    for what in [
        "valve-limited velocity, extending",
        "force capacity, pushing",
        "flow gain, cap-side land",
        "gain margin",
        "phase margin",
        "RK4 steps per controller period",
    ] {
        assert!(text.contains(what), "no `{what}` in\n{text}");
    }
}

/// The JSON's oil-column frequency is the closed form of the preset's published numbers
/// (n = 2, β = 1 GPa, A_a = 0.2051 m², A_b = 0.1291 m², V_a = 0.2122 m³, V_b = 0.1335 m³,
/// M = Mₑ = 144 t) to 1e-9, which is the paper's 10.66 Hz; the capacities are their closed
/// forms too.
#[test]
fn json_oil_column_is_the_closed_form_of_the_published_numbers() {
    let d = ok_json(&platen(&["model", "--system", "lhpost-2008", "--json"]));
    let ts = &d["table_system"];
    let expected = oil_column_hz(M_KG);
    let f = num(ts, "oil_column_frequency_hz");
    assert!(
        relative(f, expected) < 1e-9,
        "{f} Hz, closed form {expected} Hz"
    );
    assert!((f - 10.66).abs() < 0.005, "{f}");
    assert_eq!(num(ts, "model_mass_kg"), M_KG);
    assert!(ts["oil_column_frequency_with_specimen_hz"].is_null());
    // The stroke's ends stiffen the column: one chamber is shorter.
    for key in [
        "oil_column_frequency_retracted_hz",
        "oil_column_frequency_extended_hz",
    ] {
        assert!(num(ts, key) > f, "{key}");
    }
    // Stall forces n·(A_a·P_s − A_b·P_R) and n·(A_b·P_s − A_a·P_R): 8.4 and 5.2 MN for the
    // pair, the published 4.2 and 2.6 MN per actuator.
    let (ps, pr) = (20.7e6, 0.35e6);
    let push = num(ts, "force_capacity_push_n");
    let pull = num(ts, "force_capacity_pull_n");
    assert!(
        relative(push, N * (A_A_M2 * ps - A_B_M2 * pr)) < 1e-12,
        "{push}"
    );
    assert!(
        relative(pull, N * (A_B_M2 * ps - A_A_M2 * pr)) < 1e-12,
        "{pull}"
    );
    // At least the published 1.8 m/s either way at full opening, with no load.
    assert!(num(ts, "valve_limited_velocity_extend_m_s") > 1.8);
    assert!(num(ts, "valve_limited_velocity_retract_m_s") > 1.8);
    assert!(num(ts, "valve_flow_capacity_m3_s") > 0.0);
    // The linearisation: compliances V/β, the model's mass.
    let lin = &ts["linearisation"];
    assert!(relative(num(lin, "compliance_a_m3_per_pa"), V_A_M3 / BETA_PA) < 1e-12);
    assert!(relative(num(lin, "compliance_b_m3_per_pa"), V_B_M3 / BETA_PA) < 1e-12);
    assert!(num(lin, "flow_gain_a_m3_s") > 0.0 && num(lin, "flow_gain_b_m3_s") > 0.0);
    assert_eq!(num(lin, "mass_kg"), M_KG);
    // The parameters are the scenario format's `table_system` keys.
    let p = &ts["parameters"];
    assert_eq!(num(&p["actuator"], "cap_side_area_m2"), A_A_M2);
    assert_eq!(num(p, "oil_bulk_modulus_pa"), BETA_PA);
}

/// The loop's margins are all there, finite and positive for the preset's stable loop, with
/// the closed loop's peak and bandwidth; the default step divides the controller's period.
#[test]
fn margins_and_the_default_step_are_present() {
    let d = ok_json(&platen(&["model", "--system", "lhpost-2008", "--json"]));
    let ts = &d["table_system"];
    let m = &ts["loop_margins"];
    assert_eq!(m["stable"], Value::Bool(true), "{m:#}");
    for key in [
        "gain_margin_db",
        "phase_crossover_hz",
        "phase_margin_deg",
        "gain_crossover_hz",
        "peak_gain",
        "peak_gain_hz",
    ] {
        let v = num(m, key);
        assert!(v.is_finite() && v > 0.0, "{key} = {v}");
    }
    assert!(num(m, "phase_crossover_hz") < 512.0);
    assert!(num(ts, "closed_loop_bandwidth_hz") > 1.0);
    assert!(num(ts, "closed_loop_min_gain") <= 1.0);
    let k = num(ts, "steps_per_controller_period");
    assert!(k >= 1.0 && k.fract() == 0.0, "{k}");
    let rate = num(ts, "controller_sample_rate_hz");
    assert!(relative(num(ts, "step_s") * k * rate, 1.0) < 1e-12);
}

/// A specimen of m = 55 t on the table, taken from a scenario, lowers the oil column by
/// √(M/(M + m)) (a rigid payload), the bare frequency staying the model's; the scenario's
/// excitation is not read. A scenario without a `table_system` takes one from --system.
#[test]
fn a_specimen_lowers_the_oil_column_by_the_mass_ratio() {
    let dir = tempfile::tempdir().unwrap();
    let m_kg = 55_000.0;
    for (path, extra) in [
        (specimen_scenario(dir.path(), true), None),
        (
            specimen_scenario(dir.path(), false),
            Some(["--system", "lhpost-2008"]),
        ),
    ] {
        let mut args = vec!["model", "--scenario", &path, "--json"];
        args.extend(extra.iter().flatten());
        let d = ok_json(&platen(&args));
        let ts = &d["table_system"];
        let bare = num(ts, "oil_column_frequency_hz");
        let loaded = num(ts, "oil_column_frequency_with_specimen_hz");
        assert!(relative(bare, oil_column_hz(M_KG)) < 1e-9, "{bare}");
        let ratio = (M_KG / (M_KG + m_kg)).sqrt();
        assert!(loaded < bare);
        assert!(
            relative(loaded, bare * ratio) < 1e-9,
            "{loaded} vs {bare}·{ratio}"
        );
        assert_eq!(num(ts, "specimen_mass_kg"), m_kg);
        assert_eq!(num(&ts["linearisation"], "mass_kg"), M_KG + m_kg);
        assert_eq!(num(&d["specimen"], "total_mass_kg"), m_kg);
        assert_eq!(d["scenario"].as_str(), Some(path.as_str()));
    }
    let text = ok(&platen(&[
        "model",
        "--scenario",
        &specimen_scenario(dir.path(), true),
    ]));
    assert!(
        text.contains("oil column at mid-stroke, with the specimen"),
        "{text}"
    );
    assert!(text.contains("specimen: 2 storeys, 55.0 t"), "{text}");
}

/// `--plot DIR` writes the two Bode figures as SVG and PNG, listed under `figures`: the
/// closed loop and the loop gain, magnitude and phase on a logarithmic frequency axis from
/// 0.1 Hz to 200 Hz (below the 512 Hz Nyquist frequency of the 1024 Hz controller).
#[test]
fn plot_writes_the_bode_figures() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("bode");
    let d = ok_json(&platen(&[
        "model",
        "--system",
        "lhpost-2008",
        "--json",
        "--plot",
        plots.to_str().unwrap(),
    ]));
    let listed: Vec<&str> = d["figures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(listed.len(), 4, "{listed:?}");
    for name in ["bode-closed-loop", "bode-loop-gain"] {
        let svg = plots.join(format!("{name}.svg"));
        for ext in ["svg", "png"] {
            let path = plots.join(format!("{name}.{ext}"));
            assert!(listed.contains(&path.to_str().unwrap()), "{listed:?}");
        }
        let c = svg_content(&svg);
        check_png(&svg, &c);
        assert!(c.text.contains("frequency f (Hz)"), "{}", c.text);
        for tick in ["0.1", "1", "10", "100", "200"] {
            assert!(c.text.lines().any(|l| l == tick), "no tick {tick}");
        }
        assert!(!c.text.lines().any(|l| l == "500"), "beyond 200 Hz");
        assert!(c.text.contains("oil column 10.66 Hz"), "{}", c.text);
    }
    let gain = svg_content(&plots.join("bode-loop-gain.svg"));
    assert!(gain.text.contains("phase margin"), "{}", gain.text);
    assert!(gain.text.contains("gain margin"), "{}", gain.text);
    let closed = svg_content(&plots.join("bode-closed-loop.svg"));
    assert!(closed.text.contains("|U/R|"), "{}", closed.text);

    // The text form lists what it wrote.
    let text = ok(&platen(&[
        "model",
        "--system",
        "lhpost-2008",
        "--plot",
        plots.to_str().unwrap(),
    ]));
    assert!(text.contains("wrote 4 figure files"), "{text}");
}

/// An unknown table-system preset is an input error naming it and the valid presets, before
/// anything is printed or written.
#[test]
fn an_unknown_system_preset_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("bode");
    let o = platen(&[
        "model",
        "--system",
        "lhpost-2009",
        "--plot",
        plots.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("lhpost-2009") && e.contains("lhpost-2008"),
        "{e}"
    );
    assert!(o.stdout.is_empty());
    assert!(!plots.exists());
}

/// Without a table system there is nothing to plot; a scenario and the preset options
/// conflict; plain `platen model` has no `table_system`.
#[test]
fn plot_needs_a_table_system_and_the_scenario_excludes_the_preset_options() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("bode");
    for args in [
        vec!["model", "--plot", plots.to_str().unwrap()],
        vec![
            "model",
            "--scenario",
            &specimen_scenario(dir.path(), false),
            "--plot",
            plots.to_str().unwrap(),
        ],
    ] {
        let o = platen(&args);
        assert_eq!(o.status.code(), Some(3), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--system"), "{}", stderr(&o));
        assert!(!plots.exists());
    }
    let path = specimen_scenario(dir.path(), true);
    let o = platen(&["model", "--scenario", &path, "--pressure-mpa", "6.9"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let d = ok_json(&platen(&["model", "--json"]));
    assert!(d["table_system"].is_null());
}
