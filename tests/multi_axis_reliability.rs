//! The multi-axis table's bad inputs, one test each (issue 55): no panic, no hang, every bad
//! value named at its JSON path, and the closed loop's stability told by its eigenvalues and
//! checked against what the nonlinear run does.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

mod common;
use common::{platen, stderr};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The three-component motion shipped with the multi-axis scenarios (20 s at 200 Hz).
fn motion() -> String {
    root()
        .join("scenarios/multi-axis/three-component-motion.csv")
        .display()
        .to_string()
}

/// The LHPOST6 preset written out in full (so that one actuator's value can be changed),
/// in closed loop under the shipped three-component motion.
fn lhpost6() -> Value {
    let preset: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("crates/platen-scenario/presets/lhpost6.json"))
            .unwrap(),
    )
    .unwrap();
    let mut table = preset["table"].clone();
    table["limits"] = preset["limits"].clone();
    json!({"name": "lhpost6 in full", "table": table, "excitation": {"motion_csv": motion()}})
}

/// A mid-size table of a lab's own: a 4 × 4 m, 20 t platen on four horizontal and four
/// swivel-mounted vertical actuators (in compression: an inverted pendulum until the loops
/// close), 630 l/min valves at 80 Hz, a 2048 Hz controller with gains `k_p` /m, `K_vf` 0.55
/// s/m and a `Δp` feedback of `k_dp` /Pa (high-passed at 0.5 Hz); under a 10 mm, 1 Hz sine
/// along x for 5 s.
fn mid_table(dir: &Path, k_p: f64, k_dp: f64) -> Value {
    let valve = json!({"count": 1, "rated_flow_m3_s": 0.0105, "rated_pressure_drop_pa": 7e6,
        "natural_frequency_hz": 80.0, "damping_ratio": 0.7, "delay_s": 0.0005});
    let actuator = |name: &str, base: [f64; 3], at: [f64; 3], stroke: f64| {
        json!({"name": name, "base_m": base, "platen_m": at, "cap_side_area_m2": 0.01,
            "rod_side_area_m2": 0.006, "chamber_volume_m3": 0.003, "stroke_m": stroke,
            "servo_valve": valve, "leakage_m3_s_per_pa": 1e-12})
    };
    let mut actuators = vec![
        actuator("h1", [4.0, 1.0, -0.2], [2.0, 1.0, -0.2], 0.25),
        actuator("h2", [-4.0, -1.0, -0.2], [-2.0, -1.0, -0.2], 0.25),
        actuator("h3", [1.0, 4.0, -0.2], [1.0, 2.0, -0.2], 0.25),
        actuator("h4", [-1.0, -4.0, -0.2], [-1.0, -2.0, -0.2], 0.25),
    ];
    for (i, (x, y)) in [(1.5, 1.5), (-1.5, 1.5), (-1.5, -1.5), (1.5, -1.5)]
        .into_iter()
        .enumerate()
    {
        actuators.push(actuator(
            &format!("v{}", i + 1),
            [x, y, -2.5],
            [x, y, -0.4],
            0.1,
        ));
    }
    let mut gains = json!({"displacement_gain_per_m": k_p, "velocity_feedforward_s_per_m": 0.55});
    if k_dp > 0.0 {
        gains["delta_p_gain_per_pa"] = json!(k_dp);
        gains["delta_p_highpass_hz"] = json!(0.5);
    }
    let dof: serde_json::Map<String, Value> = ["x", "y", "z", "roll", "pitch", "yaw"]
        .iter()
        .map(|d| ((*d).to_owned(), gains.clone()))
        .collect();
    let csv = dir.join("sine-x.csv");
    let mut text = String::from("t_s,x_m\n");
    for j in 0..=5 * 2048 {
        let t = j as f64 / 2048.0;
        let x = 0.01
            * (std::f64::consts::TAU * t).sin()
            * (std::f64::consts::PI * t / 5.0).sin().powi(2);
        text.push_str(&format!("{t},{x}\n"));
    }
    std::fs::write(&csv, text).unwrap();
    json!({
        "name": "mid-size swivel table",
        "table": {
            "platen": {"mass_kg": 20000.0,
                "inertia_kg_m2": [[26933.0, 0.0, 0.0], [0.0, 26933.0, 0.0], [0.0, 0.0, 53333.0]],
                "centre_of_mass_m": [0.0, 0.0, -0.2]},
            "actuators": actuators,
            "oil_bulk_modulus_pa": 1.5e9,
            "supply_pressure_pa": 20.7e6,
            "return_pressure_pa": 0.3e6,
            "controller": {"sample_rate_hz": 2048.0, "dof": dof}
        },
        "excitation": {"motion_csv": csv.display().to_string()}
    })
}

/// Writes `doc` (or `text`) into `dir` and runs `platen VERB file ARGS…`, failing the test on a
/// panic or a run past `limit`. Returns (exit code, stdout, stderr).
fn run(dir: &Path, verb: &str, doc: &Value, args: &[&str]) -> (Option<i32>, String, String) {
    run_text(dir, verb, &doc.to_string(), args)
}

fn run_text(dir: &Path, verb: &str, text: &str, args: &[&str]) -> (Option<i32>, String, String) {
    let path = dir.join("case.json");
    std::fs::write(&path, text).unwrap();
    let mut all = vec![verb];
    if verb == "model" {
        all.push("--scenario");
    }
    all.push(path.to_str().unwrap());
    all.extend_from_slice(args);
    let start = Instant::now();
    let o = platen(&all);
    let elapsed = start.elapsed();
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{verb}: panic: {err}");
    assert_ne!(o.status.code(), Some(101), "{verb}: {err}");
    // A refusal comes before any work: well within a second even in a debug build.
    if !o.status.success() {
        assert!(
            elapsed < Duration::from_secs(20),
            "{verb} took {elapsed:?} to refuse"
        );
    }
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        err,
    )
}

/// `doc` changed by `edit` is refused by `simulate` (exit 3, nothing written) with a message
/// naming `path` and containing each of `words`.
fn refused(dir: &Path, doc: &Value, path: &str, words: &[&str]) {
    let mut all = vec![path];
    all.extend_from_slice(words);
    fails(dir, doc, Some(3), &all);
}

/// `doc` fails in `simulate` (with exit code `code`, or any non-zero one for `None`), nothing
/// written, with a message containing each of `words`.
fn fails(dir: &Path, doc: &Value, code: Option<i32>, words: &[&str]) {
    let out = dir.join("out.csv");
    let (got, _, err) = run(dir, "simulate", doc, &["--out", out.to_str().unwrap()]);
    match code {
        Some(c) => assert_eq!(got, Some(c), "{err}"),
        None => assert_ne!(got, Some(0), "{err}"),
    }
    for w in words {
        assert!(err.contains(w), "expected `{w}` in: {err}");
    }
    assert!(!out.exists(), "{err}");
}

#[test]
fn every_dof_held_is_refused_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = lhpost6();
    doc["table"]["held_dofs"] = json!(["x", "y", "z", "roll", "pitch", "yaw"]);
    refused(dir.path(), &doc, "table.held_dofs", &["at most five"]);
    let (code, _, err) = run(dir.path(), "model", &doc, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("table.held_dofs"), "{err}");
}

#[test]
fn reserved_and_unfit_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = lhpost6();
    doc["table"]["actuators"][0]["name"] = json!("warping");
    refused(
        dir.path(),
        &doc,
        "table.actuators[0].name",
        &["warping_force_n"],
    );
    let mut doc = lhpost6();
    doc["table"]["actuators"][1]["name"] = json!("h,2");
    refused(dir.path(), &doc, "table.actuators[1].name", &["CSV column"]);
}

#[test]
fn geometry_beyond_any_table_is_refused_at_its_key() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = lhpost6();
    doc["table"]["platen"]["centre_of_mass_m"] = json!([1e300, 0.0, 0.0]);
    refused(
        dir.path(),
        &doc,
        "table.platen.centre_of_mass_m",
        &["within 100 m"],
    );
    let mut doc = lhpost6();
    doc["table"]["hold_down_struts"][0]["base_m"] = json!([1e300, 0.0, -4.5]);
    refused(
        dir.path(),
        &doc,
        "table.hold_down_struts[0].base_m",
        &["within 100 m"],
    );
    // A four-element point is named at its key, not as a syntax error.
    let mut doc = lhpost6();
    doc["table"]["platen"]["centre_of_mass_m"] = json!([0.0, 0.0, 0.0, 0.0]);
    refused(
        dir.path(),
        &doc,
        "table.platen.centre_of_mass_m",
        &["more elements"],
    );
}

/// The values that made a run seem to hang are refused before it starts, each at its key.
#[test]
fn values_that_would_hang_the_loop_are_refused_at_their_key() {
    let dir = tempfile::tempdir().unwrap();
    let valves = |key: &str, value: f64| {
        let mut doc = lhpost6();
        for a in doc["table"]["actuators"].as_array_mut().unwrap() {
            a["servo_valve"][key] = json!(value);
        }
        doc
    };
    // 630 l/min written as m³/s.
    refused(
        dir.path(),
        &valves("rated_flow_m3_s", 630.0),
        "table.actuators[0].servo_valve.rated_flow_m3_s",
        &["l/min"],
    );
    refused(
        dir.path(),
        &valves("rated_pressure_drop_pa", 1e-300),
        "table.actuators[0].servo_valve.rated_pressure_drop_pa",
        &["rated drop in Pa"],
    );
    refused(
        dir.path(),
        &valves("natural_frequency_hz", 1e9),
        "table.actuators[0].servo_valve.natural_frequency_hz",
        &["at most 5000 Hz"],
    );
    // A spool within that bound, but the run's steps beyond the budget: 2 000 s of the
    // LHPOST6 with its spools at 4 kHz.
    let mut doc = valves("natural_frequency_hz", 4000.0);
    doc["excitation"] = json!({"sine_motion": {"x": {"amplitude_m": 0.001,
        "frequency_hz": 1.0, "sample_rate_hz": 200.0}}});
    doc["duration_s"] = json!(2000.0);
    refused(
        dir.path(),
        &doc,
        "table.actuators[0].servo_valve.natural_frequency_hz",
        &["spool", "integration steps"],
    );
    let specimen = |k: f64, lever: f64| {
        let mut doc = lhpost6();
        doc["specimen"] = json!({"mass_matrix": [[1000.0]], "stiffness_matrix": [[k]],
            "damping_matrix": [[0.0]], "influence": [[1.0, 0.0, 0.0, 0.0, lever, 0.0]]});
        doc
    };
    refused(
        dir.path(),
        &specimen(1e17, 0.0),
        "specimen.stiffness_matrix",
        &["stiffest mode"],
    );
    refused(
        dir.path(),
        &specimen(1e6, 60_000.0),
        "specimen.influence",
        &["100"],
    );
}

/// A specimen larger than the runs carry is refused by `model` and `simulate` alike, at once.
#[test]
fn a_large_specimen_is_refused_by_model_too() {
    let dir = tempfile::tempdir().unwrap();
    let n = 150;
    let eye = |v: f64| -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| (0..n).map(|j| if i == j { v } else { 0.0 }).collect())
            .collect()
    };
    let mut doc = lhpost6();
    doc["specimen"] = json!({"mass_matrix": eye(1000.0), "stiffness_matrix": eye(1e6),
        "damping_matrix": eye(0.0), "influence": vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]; n]});
    let (code, _, err) = run(dir.path(), "model", &doc, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("specimen.mass_matrix") && err.contains("at most 12"),
        "{err}"
    );
    refused(dir.path(), &doc, "specimen.mass_matrix", &["at most 12"]);
}

#[test]
fn messages_name_the_value_not_its_consequence() {
    let dir = tempfile::tempdir().unwrap();
    // A duration shorter than the record's first interval.
    let mut doc = lhpost6();
    doc["duration_s"] = json!(1e-9);
    refused(dir.path(), &doc, "duration_s", &["interval"]);
    // A control byte inside a CSV number is shown escaped.
    let csv = std::fs::read_to_string(motion()).unwrap();
    let bad: String = csv
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 5 {
                format!("{}\u{7}{}\n", &l[..3], &l[3..])
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let path = dir.path().join("bell.csv");
    std::fs::write(&path, bad).unwrap();
    let mut doc = lhpost6();
    doc["excitation"]["motion_csv"] = json!(path.display().to_string());
    let (code, _, err) = run(dir.path(), "simulate", &doc, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("\\u{7}") && !err.contains('\u{7}'), "{err}");
    // A bare NaN in the scenario is a syntax error for `plan` as for `simulate`.
    let text = lhpost6().to_string().replacen("0.0005", "NaN", 1);
    let target = dir.path().join("target.csv");
    std::fs::write(&target, "t_s,x_m\n0,0\n0.5,0.01\n1,0\n").unwrap();
    let out = dir.path().join("drive.csv");
    let (code, _, err) = run_text(
        dir.path(),
        "plan",
        &text,
        &[
            "--target",
            target.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("JSON syntax error at line"), "{err}");
    assert!(!out.exists());
}

/// `platen model --scenario` describes a scenario without reading its excitation: the
/// Northridge scenario without the PEER records.
#[test]
fn model_does_not_need_the_records() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_platen"))
        .args([
            "model",
            "--scenario",
            root()
                .join("scenarios/multi-axis/lhpost6-northridge.json")
                .to_str()
                .unwrap(),
            "--json",
        ])
        .env_remove("PLATEN_RECORDS_DIR")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let d: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(d["loop"]["stability"]["stable"], true, "{d}");
}

/// The stability verdict against the nonlinear run (independent of the linearisation): the
/// swivel-vertical table tuned with a `Δp` feedback is stable with margin (14 dB, 64°) and
/// tracks its command; without the `Δp` feedback its oil columns ring up and the run does not
/// track. The per-DOF Nyquist verdicts count the open loop's unstable poles (the verticals'
/// inverted pendulum), so they agree with the eigenvalues: no DOF of the stable table is
/// called unstable.
#[test]
fn the_stability_verdict_agrees_with_the_nonlinear_run() {
    let dir = tempfile::tempdir().unwrap();
    for (k_dp, stable) in [(5e-9, true), (0.0, false)] {
        let doc = mid_table(dir.path(), 4.0, k_dp);
        let (code, out, err) = run(dir.path(), "model", &doc, &["--json"]);
        assert_eq!(code, Some(0), "{err}");
        let d: Value = serde_json::from_str(&out).unwrap();
        let l = &d["loop"];
        assert_eq!(l["stability"]["stable"], stable, "{l}");
        for dof in ["x", "y", "z", "roll", "pitch", "yaw"] {
            assert_eq!(l["dofs"][dof]["stable"], stable, "{dof}: {l}");
        }
        if stable {
            let gm = l["dofs"]["x"]["gain_margin_db"].as_f64().unwrap();
            let pm = l["dofs"]["x"]["phase_margin_deg"].as_f64().unwrap();
            assert!(gm > 10.0 && pm > 45.0, "{gm} dB, {pm}°");
        } else {
            assert!(l["stability"]["unstable_dof"].is_string(), "{l}");
        }
        let (code, out, err) = run(dir.path(), "simulate", &doc, &["--json"]);
        assert_eq!(code, Some(0), "{err}");
        let s: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(s["loop"]["stability"]["stable"], stable, "{s}");
        assert_eq!(s["loop"]["loop_margins"]["x"]["stable"], stable, "{s}");
        let nrmse = s["tracking"]["x"]["acceleration_nrmse"].as_f64().unwrap();
        let warned = s["warnings"][0]
            .as_str()
            .is_some_and(|w| w.starts_with("the closed loop is unstable"));
        if stable {
            // Measured 19.7 %: the sine's acceleration followed, the valves' lag aside.
            assert!(nrmse < 0.3, "stable table's x acceleration NRMSE {nrmse}");
            assert!(!warned, "{s}");
        } else {
            // Measured 285 %: the oil columns' ring-up swamps the command.
            assert!(nrmse > 1.0, "unstable table's x acceleration NRMSE {nrmse}");
            assert!(warned, "{s}");
        }
    }
}

/// A pose or rate beyond any table's, in a forward run's `initial` or a `motion_csv` column, is
/// refused at its key or column (it ran into a non-finite state labelled `u`, `v`).
#[test]
fn poses_and_rates_beyond_any_table_are_refused_where_they_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("scenarios/multi-axis/forward.json")).unwrap(),
    )
    .unwrap();
    let forces = root().join("scenarios/multi-axis/forward-forces.csv");
    doc["excitation"]["force_csv"] = json!(forces.display().to_string());
    doc["initial"] = json!({"y_m": 1000.0});
    refused(dir.path(), &doc, "initial.y_m", &["within ±100 m"]);
    doc["initial"] = json!({"yaw_rad_s": -1e6});
    refused(
        dir.path(),
        &doc,
        "initial.yaw_rad_s",
        &["within ±100 rad/s"],
    );
    // A motion whose velocity column is in mm/s: the column and row named.
    let text = std::fs::read_to_string(motion()).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let at = header.split(',').position(|c| c == "y_m_s").unwrap();
    let mut csv = format!("{header}\n");
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
        cells[at] = format!("{}", 1000.0 * cells[at].parse::<f64>().unwrap() + 1.0e3);
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    let path = dir.path().join("mm-per-s.csv");
    std::fs::write(&path, csv).unwrap();
    let mut doc = lhpost6();
    doc["excitation"]["motion_csv"] = json!(path.display().to_string());
    refused(
        dir.path(),
        &doc,
        "mm-per-s.csv",
        &["column `y_m_s`", "beyond the ±100 m/s"],
    );
}

/// z held on a table whose verticals are single-acting: they carry no weight, which such an
/// actuator cannot hold at rest; said so, not "needs 0 Pa".
#[test]
fn z_held_on_single_acting_verticals_is_explained() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = lhpost6();
    doc["table"]["held_dofs"] = json!(["z"]);
    refused(
        dir.path(),
        &doc,
        "table.actuators[4].cap_side_area_m2",
        &["single-acting", "cannot pull", "with z held"],
    );
}

/// A strut whose gas runs out under the motion is reported as that, with its key, not as a
/// non-finite state or a bad number in the output file.
#[test]
fn a_strut_out_of_gas_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = lhpost6();
    // 0.2 mm of travel before the gas is gone (30 cm³ on 0.15 m²).
    doc["table"]["hold_down_struts"][0]["gas_volume_m3"] = json!(3e-5);
    fails(
        dir.path(),
        &doc,
        None,
        &[
            "table.hold_down_struts[0]",
            "ran out of gas",
            "gas_volume_m3 / area_m2",
        ],
    );
}

/// The shipped open-loop forward scenario (actuator forces, pads with friction, the tower)
/// copied into `dir` with its force record, laid over by `edit`.
fn forward_in(dir: &Path, scale_forces: f64) -> Value {
    let csv =
        std::fs::read_to_string(root().join("scenarios/multi-axis/forward-forces.csv")).unwrap();
    let mut lines = csv.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for line in lines {
        let mut cells = line.split(',');
        let t = cells.next().unwrap();
        out.push_str(t);
        for c in cells {
            let f: f64 = c.parse().unwrap();
            out.push_str(&format!(",{:e}", f * scale_forces));
        }
        out.push('\n');
    }
    std::fs::write(dir.join("forward-forces.csv"), out).unwrap();
    let text = std::fs::read_to_string(root().join("scenarios/multi-axis/forward.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A forward run on a strut with almost no gas (0.3 cm³: a gas spring of about 1.5e12 N/m
/// on the platen, faster than the step can follow) stops with the table's six coordinates
/// and the key to look at, exit 4 and nothing written; it used to run on and fail writing a
/// non-finite force into the output file ("`out.csv`, line 116, column `a1_force_n`").
#[test]
fn a_strut_with_almost_no_gas_stops_a_forward_run_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = forward_in(dir.path(), 1.0);
    doc["table"]["hold_down_struts"][0]["gas_volume_m3"] = json!(3e-7);
    fails(
        dir.path(),
        &doc,
        Some(4),
        &[
            "the table's state became non-finite",
            "roll = ",
            "gas_volume_m3",
        ],
    );
}

/// A forward run whose state blows up (forces of 1e290 N) says so with the table's six
/// coordinates and the keys to look at, not the uniaxial platen's `u` and `v`; exit 4 (a
/// numerical failure), nothing written.
#[test]
fn a_table_state_that_blows_up_is_reported_with_six_dof_labels() {
    let dir = tempfile::tempdir().unwrap();
    let doc = forward_in(dir.path(), 1e284);
    fails(
        dir.path(),
        &doc,
        Some(4),
        &[
            "the table's state became non-finite",
            "x = ",
            "yaw = ",
            "rated_flow_m3_s",
        ],
    );
    let (_, _, err) = run(dir.path(), "simulate", &doc, &[]);
    assert!(!err.contains("(u = "), "{err}");
}
