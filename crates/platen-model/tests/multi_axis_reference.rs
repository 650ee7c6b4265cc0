//! The multi-axis platen against the independent NumPy/SciPy reference of
//! `tools/reference/multi_axis_cases.py` (`tests/data/reference/multi_axis.json`): its own
//! kinematics, Newton–Euler from `vee(Ṙ·Rᵀ)`, and `scipy.linalg.eigh` for the modes.

use nalgebra::{Matrix3, Unit, Vector3};
use platen_model::multi_axis::{
    Actuator, Coords, DofSet, Mount, MultiAxisTable, Pad, RigidPlaten, Strut, TableParts, Wrench,
};
use serde_json::Value;

fn reference() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/reference/multi_axis.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("the reference file")).unwrap()
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn v3(v: &Value) -> Vector3<f64> {
    Vector3::new(num(&v[0]), num(&v[1]), num(&v[2]))
}

fn coords(v: &Value) -> Coords {
    Coords::from_fn(|k, _| num(&v[k]))
}

/// The reference's table, read here with the contract's keys (independently of the scenario
/// reader); `struts` and `friction` keep or drop those parts.
fn table(t: &Value, struts: bool, friction: bool) -> MultiAxisTable {
    let p = &t["platen"];
    let platen = RigidPlaten::new(
        num(&p["mass_kg"]),
        Matrix3::from_fn(|r, c| num(&p["inertia_kg_m2"][r][c])),
        v3(&p["centre_of_mass_m"]),
    )
    .unwrap();
    let actuators = t["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| Actuator {
            name: a["name"].as_str().unwrap().into(),
            base_m: v3(&a["base_m"]),
            mount: if a.get("pad").is_some() {
                let pad = &a["pad"];
                Mount::Pad(Pad {
                    axis: Unit::new_normalize(v3(&pad["axis"])),
                    contact_m: v3(&pad["contact_m"]),
                    friction_coefficient: if friction {
                        num(&pad["friction_coefficient"])
                    } else {
                        0.0
                    },
                })
            } else {
                Mount::Swivel {
                    platen_m: v3(&a["platen_m"]),
                }
            },
            cap_side_area_m2: num(&a["cap_side_area_m2"]),
            rod_side_area_m2: num(&a["rod_side_area_m2"]),
            chamber_volume_m3: num(&a["chamber_volume_m3"]),
            stroke_m: num(&a["stroke_m"]),
        })
        .collect();
    let struts = if struts {
        t["hold_down_struts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| Strut {
                name: s["name"].as_str().unwrap().into(),
                base_m: v3(&s["base_m"]),
                platen_m: v3(&s["platen_m"]),
                area_m2: num(&s["area_m2"]),
                pressure_pa: num(&s["pressure_pa"]),
                gas_volume_m3: num(&s["gas_volume_m3"]),
                polytropic_exponent: num(&s["polytropic_exponent"]),
            })
            .collect()
    } else {
        Vec::new()
    };
    MultiAxisTable::new(TableParts {
        platen,
        actuators,
        struts,
        bearings: Vec::new(),
        held: DofSet::EMPTY,
        oil_bulk_modulus_pa: num(&t["oil_bulk_modulus_pa"]),
    })
    .unwrap()
}

/// Strokes, unit vectors and points of application at 50 random poses (rotations up to
/// 0.2 rad) to 1e-9 m, and the struts' lengths and pulls (1e-9 m, 1e-9 relative): exact
/// kinematics on both sides, so only rounding separates them.
#[test]
fn kinematics_equal_the_independent_computation_at_random_poses() {
    let r = reference();
    let t = table(&r["table"], true, true);
    let mut worst = 0.0f64;
    for case in r["kinematics"].as_array().unwrap() {
        let q = coords(&case["pose"]);
        for (i, a) in t.actuators().iter().enumerate() {
            let pose = t.actuator_at(i, &q);
            let stroke = num(&case["strokes_m"][&a.name]);
            worst = worst.max((pose.stroke_m - stroke).abs());
            assert!(
                (pose.stroke_m - stroke).abs() < 1e-9,
                "{} at {q}: {} against {stroke}",
                a.name,
                pose.stroke_m
            );
            assert!((pose.unit - v3(&case["unit_vectors"][&a.name])).norm() < 1e-12);
            assert!((pose.point_m - v3(&case["points_m"][&a.name])).norm() < 1e-9);
        }
        for (j, s) in t.struts().iter().enumerate() {
            let pose = t.strut_at(j, &q);
            assert!((pose.length_m - num(&case["strut_lengths_m"][&s.name])).abs() < 1e-9);
            let pull = num(&case["strut_forces_n"][&s.name]);
            assert!(
                (pose.force_n / pull - 1.0).abs() < 1e-9,
                "{}: {} against {pull}",
                s.name,
                pose.force_n
            );
        }
    }
    eprintln!("largest stroke difference {worst:e} m");
}

fn wrench(sample: &Value) -> Wrench {
    let (f, m) = (v3(&sample["force_n"]), v3(&sample["moment_n_m"]));
    Wrench::new(f[0], f[1], f[2], m[0], m[1], m[2])
}

/// Newton–Euler with the gyroscopic term and gravity, off-centre centre of mass, all six DOFs
/// moving: the required wrench equals the reference's to 1e-8 of its size; and the inverse's
/// actuator forces (no friction, no struts) exert that wrench to the same.
#[test]
fn the_inverse_exerts_the_newton_euler_wrench() {
    let r = reference();
    let t = table(&r["table"], false, false);
    let mut worst = 0.0f64;
    for s in r["newton_euler"]["samples"].as_array().unwrap() {
        let (q, qd, qdd) = (
            coords(&s["pose"]),
            coords(&s["rates"]),
            coords(&s["accelerations"]),
        );
        let expect = wrench(s);
        let omega = platen_model::multi_axis::angular_velocity(&q, &qd);
        assert!((omega - v3(&s["omega_rad_s"])).norm() < 1e-12);
        let got = t.required_wrench(&q, &qd, &qdd);
        let rel = (got - expect).norm() / expect.norm();
        assert!(rel < 1e-8, "t = {}: {got} against {expect}", num(&s["t_s"]));
        let inv = t.inverse(&q, &qd, &qdd, &Wrench::zeros()).unwrap();
        let exerted: Wrench = inv
            .actuator_forces_n
            .iter()
            .enumerate()
            .map(|(i, f)| t.actuator_at(i, &q).unit_wrench * *f)
            .sum();
        let rel = (exerted - expect).norm() / expect.norm();
        worst = worst.max(rel);
        assert!(
            rel < 1e-8,
            "t = {}: {exerted} against {expect}",
            num(&s["t_s"])
        );
    }
    eprintln!("largest relative wrench difference {worst:e}");
}

/// The modes at neutral equal `scipy.linalg.eigh(K, M)` of the axial springs within 0.5 %
/// (the bound; they agree to rounding), shapes included, for the asymmetric table
/// and the symmetric one.
#[test]
fn the_modes_equal_the_generalised_eigenproblem() {
    let r = reference();
    for (key, modes) in [("table", "modes"), ("table_symmetric", "modes_symmetric")] {
        let t = table(&r[key], true, true);
        let got = t.modes();
        let expect = &r[modes];
        for (i, m) in got.iter().enumerate() {
            let f = num(&expect["frequencies_hz"][i]);
            assert!(
                (m.frequency_hz / f - 1.0).abs() < 1e-9,
                "{key} mode {i}: {} Hz against {f} Hz",
                m.frequency_hz
            );
            let shape = coords(&expect["shapes"][i]);
            assert!(
                (m.shape - shape).norm() < 1e-6 * shape.norm(),
                "{key} mode {i}: {} against {shape}",
                m.shape
            );
        }
    }
}

/// The paper's strut pair, exact: the reference's horizontal forces to 1e-9 relative.
#[test]
fn the_paper_struts_pull_as_the_reference_says() {
    let r = reference();
    let s = &r["strut_paper"];
    let h = num(&s["h_m"]);
    let strut = |name: &str, y: f64| Strut {
        name: name.into(),
        base_m: Vector3::new(0.0, y, -h),
        platen_m: Vector3::new(0.0, y, 0.0),
        area_m2: num(&s["area_m2"]),
        pressure_pa: num(&s["pressure_pa"]),
        gas_volume_m3: num(&s["gas_volume_m3"]),
        polytropic_exponent: num(&s["polytropic_exponent"]),
    };
    let r0 = reference();
    let mut parts = table(&r0["table"], false, false).parts().clone();
    parts.struts = vec![strut("a", -1.0), strut("b", 1.0)];
    let t = MultiAxisTable::new(parts).unwrap();
    for (u, f) in s["u_m"]
        .as_array()
        .unwrap()
        .iter()
        .zip(s["force_n"].as_array().unwrap())
    {
        let q = Coords::new(num(u), 0.0, 0.0, 0.0, 0.0, 0.0);
        let pull_back = -t.struts_wrench(&q)[0];
        let f = num(f);
        assert!(
            (pull_back - f).abs() <= 1e-9 * f.abs().max(1.0),
            "u = {u}: {pull_back} against {f}"
        );
    }
}
