//! Scenarios of the multi-axis table: the shipped ones run, bad input is refused with its
//! path before any work, and the inverse agrees with the uniaxial one and with statics.

use std::path::{Path, PathBuf};

use platen_scenario::file::{parse, ScenarioFile};
use platen_scenario::multi_axis::TableScenario;
use serde_json::{json, Value};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn shipped(name: &str) -> (PathBuf, ScenarioFile) {
    let path = root().join("scenarios/multi-axis").join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let file = parse(&path, &text).unwrap();
    (path, file)
}

/// A scenario of `table` (and `specimen`) over the motion `csv` (written beside it).
fn scenario(dir: &Path, mut value: Value, csv: &str) -> Result<TableScenario, String> {
    std::fs::write(dir.join("motion.csv"), csv).unwrap();
    value["excitation"] = json!({"motion_csv": "motion.csv"});
    let path = dir.join("s.json");
    let text = value.to_string();
    std::fs::write(&path, &text).unwrap();
    let file = parse(&path, &text).map_err(|e| e.to_string())?;
    TableScenario::from_file(&path, &file).map_err(|e| e.to_string())
}

fn tower_table() -> Value {
    let (_, file) = shipped("tower-inverse.json");
    serde_json::to_value(file.table.unwrap()).unwrap()
}

/// Ten samples at 100 Hz of `columns` (name, value per sample).
/// A column of a motion: its name and its value at a time.
type Column<'a> = (&'a str, fn(f64) -> f64);

/// An edit of a table and the text its error must contain.
type Case = (Box<dyn Fn(&mut Value)>, &'static str);

fn csv(columns: &[Column<'_>]) -> String {
    let mut s = String::from("t_s");
    for (n, _) in columns {
        s += &format!(",{n}");
    }
    s += "\n";
    for i in 0..10 {
        let t = f64::from(i) * 0.01;
        s += &format!("{t}");
        for (_, f) in columns {
            s += &format!(",{}", f(t));
        }
        s += "\n";
    }
    s
}

#[test]
fn the_shipped_scenarios_run_within_their_limits() {
    for name in ["tower-inverse.json", "bare-inverse.json"] {
        let (path, file) = shipped(name);
        let s = TableScenario::from_file(&path, &file).unwrap();
        let run = s.run().unwrap();
        assert_eq!(run.len(), 4001);
        let summary = s.summary(&run, None);
        assert!(summary.within_limits, "{name}: {:?}", summary.actuators);
        assert_eq!(summary.specimen.is_empty(), name == "bare-inverse.json");
    }
}

/// At rest, the tower's weight and its eccentricity: the platen holds it up with m·g and
/// the moment (m·g·e_y, −m·g·e_x) about the reference point (the shipped tower: 2 × 60 t at
/// (0.9, −0.6) m), to 1e-9 relative (its static deflection is solved, not integrated).
#[test]
fn a_tower_at_rest_weighs_with_its_eccentricity() {
    let dir = tempfile::tempdir().unwrap();
    let (_, file) = shipped("tower-inverse.json");
    let value = json!({"table": tower_table(), "specimen": serde_json::to_value(file.specimen.unwrap()).unwrap()});
    let s = scenario(dir.path(), value, &csv(&[("x_m", |_| 0.0)])).unwrap();
    let run = s.run().unwrap();
    let w = 120e3 * platen_model::STANDARD_GRAVITY_M_S2;
    let last = |c: &str| *run.column(c).unwrap().last().unwrap();
    assert!((last("base_force_z_n") / w - 1.0).abs() < 1e-9);
    assert!((last("overturning_moment_x_n_m") / (w * -0.6) - 1.0).abs() < 1e-9);
    assert!((last("overturning_moment_y_n_m") / (-w * 0.9) - 1.0).abs() < 1e-9);
    assert!(last("base_force_x_n").abs() < 1e-6 * w);
}

/// Bad tables and motions: each refused with its JSON path or column, before any run.
#[test]
fn bad_input_is_refused_with_its_path() {
    let dir = tempfile::tempdir().unwrap();
    let good = csv(&[("x_m", |t| 0.01 * t)]);
    let cases: Vec<Case> = vec![
        (
            Box::new(|t| t["actuators"][2]["platen_m"] = json!([1.0, 2.0])),
            "actuators[2].platen_m",
        ),
        (
            Box::new(|t| t["actuators"][0]["platen_m"] = t["actuators"][0]["base_m"].clone()),
            "table.actuators[0].platen_m",
        ),
        (
            Box::new(|t| t["platen"]["inertia_kg_m2"][0][1] = json!(5e5)),
            "table.platen.inertia_kg_m2",
        ),
        (
            Box::new(|t| t["platen"]["mass_kg"] = json!(-1.0)),
            "table.platen.mass_kg",
        ),
        (
            Box::new(|t| t["held_dofs"] = json!(["x", "surge"])),
            "table.held_dofs[1]",
        ),
        (Box::new(|t| t["actuators"][0]["bogus"] = json!(1)), "bogus"),
        (
            Box::new(|t| {
                let a = t["actuators"].as_array_mut().unwrap();
                a.drain(0..4);
            }),
            "moves the platen in `x`",
        ),
        (
            Box::new(|t| t["actuators"][5]["pad"]["axis"] = json!([1.0, 0.0, 0.0])),
            "table.actuators[5].pad.axis",
        ),
        (
            Box::new(|t| t["controller"] = json!({})),
            "table.actuators[0].servo_valve",
        ),
    ];
    for (edit, expect) in cases {
        let mut table = tower_table();
        edit(&mut table);
        let err = scenario(dir.path(), json!({"table": table}), &good).unwrap_err();
        assert!(err.contains(expect), "expected `{expect}` in: {err}");
    }
    // The motion: no pose column, a non-finite value, time going back.
    let table = tower_table();
    let err = scenario(dir.path(), json!({"table": table}), &csv(&[("u_m", |t| t)])).unwrap_err();
    assert!(err.contains("x_m, y_m"), "{err}");
    let err = scenario(
        dir.path(),
        json!({"table": table}),
        "t_s,x_m\n0,0\n0.01,nan\n0.02,0\n",
    )
    .unwrap_err();
    assert!(err.contains("line 3") || err.contains("x_m"), "{err}");
    let err = scenario(
        dir.path(),
        json!({"table": table}),
        "t_s,x_m\n0,0\n0.02,0\n0.01,0\n",
    )
    .unwrap_err();
    assert!(err.contains("line 4"), "{err}");
    // A uniaxial model beside a table.
    let err = scenario(
        dir.path(),
        json!({"table": table, "model": {"preset": "lhpost-2008"}}),
        &good,
    )
    .unwrap_err();
    assert!(err.contains("model"), "{err}");
    // Specimen matrices of the wrong size.
    let specimen = json!({"mass_matrix": [[1.0]], "stiffness_matrix": [[1.0, 0.0]], "damping_matrix": [[0.0]], "influence": [[1.0, 0, 0, 0, 0, 0]]});
    let err = scenario(
        dir.path(),
        json!({"table": table, "specimen": specimen}),
        &good,
    )
    .unwrap_err();
    assert!(err.contains("specimen.stiffness_matrix[0]"), "{err}");
}

/// Storeys on a table held but in x, moving along x: the base shear equals the uniaxial
/// inverse's (`inverse_specimen`, the same RK4 on the same storeys) to 1e-9 relative.
#[test]
fn storeys_on_a_table_held_but_in_x_shear_as_on_the_uniaxial_platen() {
    let dir = tempfile::tempdir().unwrap();
    let mut table = tower_table();
    table["held_dofs"] = json!(["y", "z", "roll", "pitch", "yaw"]);
    let storeys = json!({"storeys": [
        {"mass_kg": 20e3, "stiffness_n_per_m": 4e7, "damping_n_s_per_m": 5e4},
        {"mass_kg": 15e3, "stiffness_n_per_m": 3e7, "damping_n_s_per_m": 4e4}]});
    let text = {
        let mut s = String::from("t_s,x_m,x_m_s,x_m_s2\n");
        for i in 0..2048 {
            let t = f64::from(i) / 1024.0;
            let w = std::f64::consts::TAU * 1.3;
            s += &format!(
                "{t},{},{},{}\n",
                0.1 * (w * t).sin(),
                0.1 * w * (w * t).cos(),
                -0.1 * w * w * (w * t).sin()
            );
        }
        s
    };
    let s = scenario(
        dir.path(),
        json!({"table": table, "specimen": storeys}),
        &text,
    )
    .unwrap();
    let run = s.run().unwrap();
    let base = run.column("base_force_x_n").unwrap();
    let frame = platen_model::Specimen::new(vec![
        platen_model::Storey {
            mass_kg: 20e3,
            stiffness_n_per_m: 4e7,
            damping_n_s_per_m: 5e4,
        },
        platen_model::Storey {
            mass_kg: 15e3,
            stiffness_n_per_m: 3e7,
            damping_n_s_per_m: 4e4,
        },
    ])
    .unwrap();
    let t: Vec<f64> = run.column("t_s").unwrap().to_vec();
    let motion = platen_integrate::Motion::new(
        t,
        run.column("x_m").unwrap().to_vec(),
        run.column("x_m_s").unwrap().to_vec(),
        run.column("x_m_s2").unwrap().to_vec(),
    )
    .unwrap();
    let model = platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    let mut out = platen_integrate::Trajectory::default();
    platen_integrate::inverse_specimen(&model, &frame, &motion, &mut out);
    let uni = &out.specimen.as_ref().unwrap().base_shear_n;
    let peak = uni.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for (a, b) in base.iter().zip(uni) {
        assert!((a - b).abs() <= 1e-9 * peak, "{a} against {b}");
    }
}

fn numeric_leaves(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Number(_) => out.push(at),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| numeric_leaves(x, format!("{at}/{i}"), out)),
        Value::Object(o) => o
            .iter()
            .for_each(|(k, x)| numeric_leaves(x, format!("{at}/{k}"), out)),
        _ => {}
    }
}

/// Every number of the tower's table and specimen set to 0, −1, 1e300, −1e-300 or null:
/// refused with a message or run, never a panic; and a refusal names the key it is about.
#[test]
fn no_value_of_a_table_panics() {
    let dir = tempfile::tempdir().unwrap();
    let (_, file) = shipped("tower-inverse.json");
    let base = json!({"table": tower_table(), "specimen": serde_json::to_value(file.specimen.unwrap()).unwrap()});
    let mut leaves = Vec::new();
    numeric_leaves(&base, String::new(), &mut leaves);
    assert!(leaves.len() > 150, "{}", leaves.len());
    let motion = csv(&[("x_m", |t| 0.01 * t), ("roll_rad", |t| 0.001 * t)]);
    let mut runs = 0;
    for leaf in &leaves {
        for v in [
            json!(0.0),
            json!(-1.0),
            json!(1e300),
            json!(-1e-300),
            Value::Null,
        ] {
            let mut doc = base.clone();
            *doc.pointer_mut(leaf).unwrap() = v.clone();
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                scenario(dir.path(), doc, &motion)
                    .and_then(|s| s.run().map(|_| ()).map_err(|e| chain(&e)))
            }));
            let Ok(result) = outcome else {
                panic!("{leaf} = {v}: panicked");
            };
            if let Err(e) = result {
                let key = leaf
                    .rsplit('/')
                    .find(|p| p.parse::<usize>().is_err())
                    .unwrap();
                assert!(
                    e.contains(key) || e.contains("moves the platen") || e.contains("rank"),
                    "{leaf} = {v}: {e}"
                );
            }
            runs += 1;
        }
    }
    assert!(runs > 750);
}

/// Forward and inverse are each other's inverse: the actuator forces the inverse finds for
/// a six-DOF motion (all DOFs at once, 1024 Hz, 2 s) drive the frictionless table forward
/// (RK4, 4 steps per sample) back along that motion. What separates them is the forward
/// run's force, linear between samples where the inverse's is exact at them (and open-loop
/// drift of that difference over 2 s); measured 2.3e-7 m and 9.3e-8 rad here, bound 1e-6
/// (m and rad).
#[test]
fn the_forward_run_retraces_the_motion_its_inverse_forces_came_from() {
    let mut table = tower_table();
    for a in table["actuators"].as_array_mut().unwrap() {
        if let Some(pad) = a.get_mut("pad") {
            pad["friction_coefficient"] = json!(0.0);
        }
    }
    let (dm, drad) = round_trip(json!({ "table": table }));
    eprintln!("round trip: {dm:e} m, {drad:e} rad");
    assert!(dm < 1e-6 && drad < 1e-6, "{dm} m, {drad} rad");
}

/// The same round trip with the pads' friction and the eccentric tower, all DOFs but yaw
/// moving: the inverse's friction (per pad, along each sample's sliding direction) and the
/// forward's planar stick-slip (it starts stuck, at rest) and its specimen agree. What
/// separates them is the friction's jump at each reversal, exact in the inverse at the
/// samples and linear between them in the forward: a velocity error of about μ·g·Δt per
/// reversal (4e-5 m/s at 0.44 %, 1 ms) that drifts open loop. Measured 2.3e-5 m and 6.8e-6
/// rad; bound 1e-4 (m and rad), the order of μ·g·Δt over the 2 s. (With yaw the two laws
/// differ: the forward's limit-surface ellipsoid is not the inverse's per-pad Coulomb for a
/// platen that slides and turns at once; see docs/multi-axis.md.)
#[test]
fn the_round_trip_holds_with_friction_and_a_tower() {
    let (_, file) = shipped("tower-inverse.json");
    let specimen = serde_json::to_value(file.specimen.unwrap()).unwrap();
    let base = json!({ "table": tower_table(), "specimen": specimen });
    let (dm, drad) = round_trip_of(base, [0.05, 0.04, 0.005, 0.004, 0.003, 0.0]);
    eprintln!("round trip with friction and the tower: {dm:e} m, {drad:e} rad");
    assert!(dm < 1e-4 && drad < 1e-4, "{dm} m, {drad} rad");
}

/// The largest pose differences (m, rad) between a six-DOF motion and the forward run of
/// the scenario `base` (a table, perhaps a specimen) under the forces its inverse finds.
fn round_trip(base: Value) -> (f64, f64) {
    round_trip_of(base, [0.05, 0.04, 0.005, 0.004, 0.003, 0.006])
}

/// [`round_trip`] of the motion with these amplitudes (x … yaw).
fn round_trip_of(base: Value, amplitude: [f64; 6]) -> (f64, f64) {
    let dir = tempfile::tempdir().unwrap();
    let freq = [0.7, 0.9, 1.3, 1.1, 1.7, 0.5];
    let mut text = String::from("t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad,x_m_s,y_m_s,z_m_s,roll_rad_s,pitch_rad_s,yaw_rad_s,x_m_s2,y_m_s2,z_m_s2,roll_rad_s2,pitch_rad_s2,yaw_rad_s2\n");
    for i in 0..2049 {
        let t = f64::from(i) / 1024.0;
        let mut row = vec![t];
        // (1 − cos) so that every DOF starts at rest at neutral.
        for k in 0..6 {
            let w = std::f64::consts::TAU * freq[k];
            row.push(amplitude[k] * (1.0 - (w * t).cos()));
        }
        for k in 0..6 {
            let w = std::f64::consts::TAU * freq[k];
            row.push(amplitude[k] * w * (w * t).sin());
        }
        for k in 0..6 {
            let w = std::f64::consts::TAU * freq[k];
            row.push(amplitude[k] * w * w * (w * t).cos());
        }
        text += &row
            .iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(",");
        text += "\n";
    }
    let inverse = scenario(dir.path(), base.clone(), &text).unwrap();
    let motion = inverse.run().unwrap();
    // The inverse's output carries t_s and {name}_force_n: the forward's force_csv as it is.
    let forces = dir.path().join("forces.csv");
    let header: Vec<&str> = motion.columns.iter().map(|(n, _)| n.as_str()).collect();
    let columns: Vec<&[f64]> = motion.columns.iter().map(|(_, c)| c.as_slice()).collect();
    platen_io::csv::write_csv_atomic(&forces, &header, &columns).unwrap();
    let path = dir.path().join("forward.json");
    let mut doc = base;
    doc["excitation"] = json!({"force_csv": "forces.csv"});
    doc["integrator"] = json!({"method": "rk4", "step_s": 1.0 / 4096.0});
    std::fs::write(&path, doc.to_string()).unwrap();
    let file = parse(&path, &doc.to_string()).unwrap();
    let forward = TableScenario::from_file(&path, &file)
        .unwrap()
        .run()
        .unwrap();
    let (mut dm, mut drad) = (0.0f64, 0.0f64);
    for (k, name) in ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"]
        .iter()
        .enumerate()
    {
        let (a, b) = (forward.column(name).unwrap(), motion.column(name).unwrap());
        let d = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        if k < 3 {
            dm = dm.max(d);
        } else {
            drad = drad.max(d);
        }
    }
    (dm, drad)
}

/// A forward run names a missing force column before any work.
#[test]
fn a_forward_run_names_what_it_cannot_take() {
    let dir = tempfile::tempdir().unwrap();
    let table = tower_table();
    std::fs::write(dir.path().join("f.csv"), "t_s,h1_force_n\n0,0\n0.01,0\n").unwrap();
    let path = dir.path().join("s.json");
    let doc = json!({"table": table, "excitation": {"force_csv": "f.csv"}});
    let file = parse(&path, &doc.to_string()).unwrap();
    let err = TableScenario::from_file(&path, &file)
        .unwrap_err()
        .to_string();
    assert!(err.contains("h2_force_n"), "{err}");
}

/// `initial` with a table: the pose and rates by name at the first sample; a held DOF's, the
/// uniaxial names, or the pose names without a table are refused with their path.
#[test]
fn a_forward_run_starts_where_initial_says() {
    let dir = tempfile::tempdir().unwrap();
    let (path, file) = shipped("forward.json");
    let mut doc = serde_json::to_value(&file).unwrap();
    doc["excitation"]["force_csv"] = json!(path
        .parent()
        .unwrap()
        .join("forward-forces.csv")
        .to_str()
        .unwrap());
    doc["duration_s"] = json!(0.1);
    let run_with = |initial: Value| {
        let mut d = doc.clone();
        d["initial"] = initial;
        let p = dir.path().join("s.json");
        let file = parse(&p, &d.to_string()).map_err(|e| e.to_string())?;
        TableScenario::from_file(&p, &file)
            .and_then(|s| s.run())
            .map_err(|e| e.to_string())
    };
    let run = run_with(json!({"x_m": 0.01, "y_m_s": 0.02, "yaw_rad": 0.001})).unwrap();
    assert_eq!(run.column("x_m").unwrap()[0], 0.01);
    assert_eq!(run.column("y_m_s").unwrap()[0], 0.02);
    assert_eq!(run.column("yaw_rad").unwrap()[0], 0.001);
    assert_eq!(run.column("z_m").unwrap()[0], 0.0);
    let err = run_with(json!({"u_m": 0.01})).unwrap_err();
    assert!(err.contains("initial.u_m"), "{err}");
    let err = run_with(json!({"roll_rad_s": f64::MAX, "x_m": "a"})).unwrap_err();
    assert!(err.contains("initial.x_m"), "{err}");
    let mut held = doc.clone();
    held["table"]["held_dofs"] = json!(["yaw"]);
    held["initial"] = json!({"yaw_rad": 0.001});
    let p = dir.path().join("held.json");
    let file = parse(&p, &held.to_string()).unwrap();
    let err = TableScenario::from_file(&p, &file).unwrap_err().to_string();
    assert!(
        err.contains("initial.yaw_rad") && err.contains("held"),
        "{err}"
    );
}

/// A table's pose names in the `initial` of a uniaxial scenario are refused with their path.
#[test]
fn the_pose_names_need_a_table() {
    let path = root().join("scenarios/paper-forward-force.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut doc: Value = serde_json::from_str(&text).unwrap();
    doc["initial"] = json!({"x_m_s": 0.1});
    let file = parse(&path, &doc.to_string()).unwrap();
    let err = platen_scenario::PlatenScenario::from_file(&path, file)
        .unwrap_err()
        .to_string();
    assert!(err.contains("initial.x_m_s"), "{err}");
}

/// The tower table with servo-valves on every actuator and a DOF controller with gains on
/// every DOF.
fn loop_table() -> Value {
    let mut t = tower_table();
    for a in t["actuators"].as_array_mut().unwrap() {
        a["servo_valve"] = json!({"count": 2, "rated_flow_m3_s": 0.1667,
            "rated_pressure_drop_pa": 7e6, "natural_frequency_hz": 246.0,
            "damping_ratio": 0.5, "delay_s": 0.0005});
    }
    let gains = json!({"displacement_gain_per_m": 16.0, "velocity_feedforward_s_per_m": 0.2,
        "delta_p_gain_per_pa": 2e-8, "delta_p_highpass_hz": 0.1});
    t["controller"] = json!({"sample_rate_hz": 2048.0, "force_balance_gain": 1e-8,
        "dof": {"x": gains, "y": gains, "z": gains, "roll": gains, "pitch": gains, "yaw": gains}});
    t
}

/// The closed loop's keys: each bad one refused with its JSON path, before any run.
#[test]
fn a_bad_closed_loop_is_refused_with_its_path() {
    let dir = tempfile::tempdir().unwrap();
    let good = csv(&[("x_m", |t| 0.01 * t)]);
    assert!(scenario(dir.path(), json!({"table": loop_table()}), &good).is_ok());
    let cases: Vec<Case> = vec![
        (
            Box::new(|t| t["actuators"][3]["servo_valve"]["count"] = json!(0)),
            "table.actuators[3].servo_valve.count",
        ),
        (
            Box::new(|t| {
                t["actuators"][6]["servo_valve"]
                    .as_object_mut()
                    .unwrap()
                    .remove("rated_flow_m3_s");
            }),
            "table.actuators[6].servo_valve.rated_flow_m3_s",
        ),
        (
            Box::new(|t| t["actuators"][2]["servo_valve"]["delay_s"] = json!(0.001)),
            "table.actuators[2].servo_valve.delay_s",
        ),
        (
            Box::new(|t| t["actuators"][1]["leakage_m3_s_per_pa"] = json!(-1.0)),
            "table.actuators[1].leakage_m3_s_per_pa",
        ),
        (
            Box::new(|t| {
                t["controller"]["dof"]
                    .as_object_mut()
                    .unwrap()
                    .remove("pitch");
            }),
            "table.controller.dof.pitch",
        ),
        (
            Box::new(|t| t["controller"]["dof"]["y"]["displacement_gain_per_m"] = json!(-3.0)),
            "table.controller.dof.y.displacement_gain_per_m",
        ),
        (
            Box::new(|t| t["controller"]["dof"]["x"]["sample_rate_hz"] = json!(1024.0)),
            "table.controller.dof.x.sample_rate_hz",
        ),
        (
            Box::new(|t| t["controller"]["dof"]["surge"] = json!({})),
            "surge",
        ),
        (
            Box::new(|t| t["held_dofs"] = json!(["yaw"])),
            "table.controller.dof.yaw",
        ),
        (
            Box::new(|t| t["controller"]["force_balance_gain"] = json!(-1.0)),
            "table.controller.force_balance_gain",
        ),
        (
            Box::new(|t| {
                t["controller"]
                    .as_object_mut()
                    .unwrap()
                    .remove("sample_rate_hz");
            }),
            "table.controller.sample_rate_hz",
        ),
        (
            Box::new(|t| t["limits"] = json!({"x": {"stroke_m": -0.1}})),
            "table.limits.x.stroke_m",
        ),
        (
            Box::new(|t| t["accumulator"] = json!({"volume_m3": 1.0})),
            "table.accumulator.precharge_pressure_pa",
        ),
        (
            Box::new(|t| t["supply_pressure_pa"] = json!(1e6)),
            "table.actuators[4].cap_side_area_m2",
        ),
        (Box::new(|t| t["preset"] = json!("lhpost9")), "table.preset"),
    ];
    for (edit, expect) in cases {
        let mut table = loop_table();
        edit(&mut table);
        let err = scenario(dir.path(), json!({"table": table}), &good).unwrap_err();
        assert!(err.contains(expect), "expected `{expect}` in: {err}");
    }
}

/// The LHPOST6 preset loads, and values given are laid over it.
#[test]
fn the_lhpost6_preset_loads_and_takes_values_over_it() {
    let dir = tempfile::tempdir().unwrap();
    let good = csv(&[("x_m", |t| 0.01 * t)]);
    let s = scenario(
        dir.path(),
        json!({"table": {"preset": "lhpost6", "supply_pressure_pa": 21e6}}),
        &good,
    )
    .unwrap();
    assert_eq!(s.table.actuators().len(), 10);
    assert_eq!(s.supply_pressure_pa, 21e6);
    assert_eq!(s.limits.x.as_ref().and_then(|x| x.stroke_m), Some(0.89));
}

/// The LHPOST6 preset meets the published per-axis figures it was derived from within 5 %
/// (`docs/lhpost6.md`; the sources: x ±0.89 m, 3.0 m/s, 3.7 g; y ±0.38 m, 2.5 m/s, 1.85 g;
/// z ±0.127 m, 0.5 m/s, 3.4 g, bare table), read from what `platen model` reports.
#[test]
fn the_lhpost6_preset_meets_its_published_figures() {
    let dir = tempfile::tempdir().unwrap();
    let good = csv(&[("x_m", |t| 0.01 * t)]);
    let s = scenario(dir.path(), json!({"table": {"preset": "lhpost6"}}), &good).unwrap();
    let d = s.describe();
    let g = platen_model::STANDARD_GRAVITY_M_S2;
    let published = [
        ("x", [0.89, 3.0, 3.7 * g]),
        ("y", [0.38, 2.5, 1.85 * g]),
        ("z", [0.127, 0.5, 3.4 * g]),
    ];
    for (axis, [stroke, velocity, acceleration]) in published {
        let a = &d.axes[axis];
        for (key, want) in [
            ("stroke_m", stroke),
            ("velocity_m_s", velocity),
            ("acceleration_m_s2", acceleration),
        ] {
            let got = a[key];
            eprintln!(
                "{axis} {key}: {got} (published {want}, ratio {:.4})",
                got / want
            );
            // Tolerance: the 5 %, what a derived geometry is asked to reproduce.
            assert!(
                (got / want - 1.0).abs() < 0.05,
                "{axis} {key}: {got} against {want}"
            );
        }
    }
    // Its closed loop is stable in every DOF (the linearisation's margins).
    let l = d.loop_figures.expect("the preset has a controller");
    for (dof, m) in &l.dofs {
        assert!(m.stable, "{dof} unstable");
    }
}

/// The scenario `doc` (a table and an excitation), written to `dir` and loaded.
fn scenario_of(dir: &Path, doc: &Value) -> Result<TableScenario, String> {
    let path = dir.join("s.json");
    let text = doc.to_string();
    std::fs::write(&path, &text).unwrap();
    let file = parse(&path, &text).map_err(|e| e.to_string())?;
    TableScenario::from_file(&path, &file).map_err(|e| e.to_string())
}

/// Generated motions per axis: each axis is its generator's closed form (here a sine,
/// `A·sin(2πft)` with its exact rate and acceleration), the absent axes and the rotations
/// are still, and the inverse forces are those of the same motion given as a six-DOF
/// `motion_csv` written here from the closed form (to 1e-9 relative: both are the
/// inverse of one motion; only the CSV's printed digits, 17 significant, separate them).
#[test]
fn generated_motions_per_axis_are_their_closed_forms_on_their_axes() {
    let dir = tempfile::tempdir().unwrap();
    let (ax, fx, az, fz, rate) = (0.05, 1.0, 0.004, 2.5, 200.0);
    let doc = json!({"table": tower_table(), "duration_s": 2.0, "excitation": {"sine_motion": {
        "x": {"amplitude_m": ax, "frequency_hz": fx, "sample_rate_hz": rate},
        "z": {"amplitude_m": az, "frequency_hz": fz, "sample_rate_hz": rate}}}});
    let run = scenario_of(dir.path(), &doc).unwrap().run().unwrap();
    let t = run.column("t_s").unwrap().to_vec();
    assert_eq!(t.len(), 401, "2 s at 200 Hz, both ends");
    let tau = std::f64::consts::TAU;
    for (name, a, f, order) in [
        ("x_m", ax, fx, 0),
        ("x_m_s", ax, fx, 1),
        ("x_m_s2", ax, fx, 2),
        ("z_m", az, fz, 0),
        ("z_m_s2", az, fz, 2),
    ] {
        let w = tau * f;
        for (i, (&ti, &got)) in t.iter().zip(run.column(name).unwrap()).enumerate() {
            let want = match order {
                0 => a * (w * ti).sin(),
                1 => a * w * (w * ti).cos(),
                _ => -a * w * w * (w * ti).sin(),
            };
            let scale = a * w.powi(order);
            assert!(
                (got - want).abs() <= 1e-12 * scale,
                "{name}[{i}] = {got}, closed form {want}"
            );
        }
    }
    for still in ["y_m", "roll_rad", "pitch_rad", "yaw_rad", "y_m_s2"] {
        assert!(
            run.column(still).unwrap().iter().all(|&v| v == 0.0),
            "{still}"
        );
    }
    // The same motion as a six-DOF CSV, from the closed form.
    let mut text = String::from("t_s,x_m,x_m_s,x_m_s2,z_m,z_m_s,z_m_s2\n");
    for &ti in &t {
        let (wx, wz) = (tau * fx, tau * fz);
        let row = [
            ti,
            ax * (wx * ti).sin(),
            ax * wx * (wx * ti).cos(),
            -ax * wx * wx * (wx * ti).sin(),
            az * (wz * ti).sin(),
            az * wz * (wz * ti).cos(),
            -az * wz * wz * (wz * ti).sin(),
        ];
        text += &row
            .iter()
            .map(|v| format!("{v:.16e}"))
            .collect::<Vec<_>>()
            .join(",");
        text += "\n";
    }
    let from_csv = scenario(dir.path(), json!({"table": tower_table()}), &text)
        .unwrap()
        .run()
        .unwrap();
    let mut compared = 0;
    for (name, col) in &run.columns {
        if !name.ends_with("_force_n") {
            continue;
        }
        let other = from_csv.column(name).unwrap();
        let peak = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in col.iter().zip(other) {
            assert!((a - b).abs() <= 1e-9 * peak, "{name}: {a} against {b}");
        }
        compared += 1;
    }
    assert!(compared >= 6, "{compared} force columns");
}

/// Per-axis generators in closed loop: white noise on x and y with their own seeds is the
/// loop's command, each axis the uniaxial generator's motion of the same values (the
/// `command_x_m` column equals a uniaxial inverse run's `u_m` of that generator, to the bit),
/// z and the rotations still.
#[test]
fn generated_motions_per_axis_command_the_closed_loop() {
    let dir = tempfile::tempdir().unwrap();
    let noise = |seed: u64| {
        json!({"rms_acceleration_g": 0.05, "band_hz": [1.0, 20.0], "seed": seed,
            "sample_rate_hz": 1024.0})
    };
    let doc = json!({"table": loop_table(), "duration_s": 2.0,
        "excitation": {"white_noise_motion": {"x": noise(3), "y": noise(4)}}});
    let run = scenario_of(dir.path(), &doc).unwrap().run().unwrap();
    let (cx, cy) = (
        run.column("command_x_m").unwrap(),
        run.column("command_y_m").unwrap(),
    );
    assert!(run.column("command_z_m").unwrap().iter().all(|&v| v == 0.0));
    // The uniaxial generator of seed 3 and seed 4, as a uniaxial inverse run writes them.
    for (seed, command) in [(3, cx), (4, cy)] {
        let path = dir.path().join("u.json");
        let uni = json!({"model": {"preset": "lhpost-2008"}, "duration_s": 2.0,
            "excitation": {"white_noise_motion": noise(seed)}});
        let text = uni.to_string();
        let file = parse(&path, &text).unwrap();
        let run = platen_scenario::PlatenScenario::from_file(&path, file)
            .unwrap()
            .run;
        let platen_scenario::Run::Inverse { motion: u } = run else {
            panic!("a generated motion is an inverse run")
        };
        assert_eq!(u.u_m().len(), command.len());
        assert!(
            u.u_m().iter().zip(command).all(|(a, b)| a == b),
            "seed {seed}"
        );
    }
    assert!(
        cx.iter().zip(cy).any(|(a, b)| a != b),
        "each axis its own seed"
    );
}

/// Per-axis generators refused with their path: a rate that differs between axes, a bad
/// value on one axis, a rotation (a six-DOF motion_csv commands those), two generators at
/// once, one generator not given per axis on a table, and per-axis on the uniaxial table.
#[test]
fn bad_generated_motions_per_axis_are_refused_with_their_path() {
    let dir = tempfile::tempdir().unwrap();
    let sine = |a: f64, f: f64, rate: f64| json!({"amplitude_m": a, "frequency_hz": f, "sample_rate_hz": rate});
    let cases = [
        (
            json!({"sine_motion": {"x": sine(0.01, 1.0, 1024.0), "y": sine(0.01, 1.0, 512.0)}}),
            "excitation.sine_motion.y.sample_rate_hz",
        ),
        (
            json!({"sine_motion": {"x": sine(0.01, 1.0, 1024.0), "z": sine(0.01, -1.0, 1024.0)}}),
            "excitation.sine_motion.z.frequency_hz",
        ),
        (
            json!({"white_noise_motion": {"y": {"rms_acceleration_g": -0.1}}}),
            "excitation.white_noise_motion.y.rms_acceleration_g",
        ),
        (
            json!({"sine_motion": {"x": sine(0.01, 1.0, 1024.0), "roll": sine(0.01, 1.0, 1024.0)}}),
            "six-DOF motion_csv",
        ),
        (
            json!({"sine_motion": {"x": sine(0.01, 1.0, 1024.0)},
                "white_noise_motion": {"y": {"rms_acceleration_g": 0.1}}}),
            "excitation.sine_motion",
        ),
        (json!({"sine_motion": sine(0.01, 1.0, 1024.0)}), "per axis"),
        (
            json!({"triangle_motion": {"x": {"amplitude_m": 0.01, "velocity_m_s": 1.0,
                "reversal_acceleration_m_s2": 1.0}}}),
            "excitation.triangle_motion.x.reversal_acceleration_m_s2",
        ),
    ];
    for (excitation, expect) in cases {
        let doc = json!({"table": loop_table(), "duration_s": 1.0, "excitation": excitation});
        let err = scenario_of(dir.path(), &doc).unwrap_err();
        assert!(err.contains(expect), "expected `{expect}` in: {err}");
    }
    // Per axis on the uniaxial table.
    let path = dir.path().join("u.json");
    let uni = json!({"model": {"preset": "lhpost-2008"}, "duration_s": 1.0,
        "excitation": {"sine_motion": {"x": sine(0.01, 1.0, 1024.0)}}});
    let text = uni.to_string();
    let file = parse(&path, &text).unwrap();
    let err = platen_scenario::PlatenScenario::from_file(&path, file)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("excitation.sine_motion") && err.contains("multi-axis"),
        "{err}"
    );
}

/// The error and its causes joined by ": ", as the CLI and Python print them.
fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text += ": ";
        text += &c.to_string();
        cause = c.source();
    }
    text
}
