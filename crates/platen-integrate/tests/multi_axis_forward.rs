//! The multi-axis platen forward from recorded actuator forces, through the one mode machine,
//! against the independent SciPy free flight of `tools/reference/multi_axis_cases.py`
//! (DOP853 at rtol 1e-11, atol 1e-13, each sample interval on the linear interpolant of the
//! printed forces; `tests/data/reference/multi_axis.json`, key `forward`).

use nalgebra::{Matrix3, Unit, Vector3};
use platen_integrate::{
    forward_table, table_kinetic_energy_j, table_potential_energy_j, ActuatorForces,
    Dopri5Settings, Method, Rk4,
};
use platen_model::multi_axis::{
    Actuator, Coords, DofSet, Mount, MultiAxisTable, Pad, RigidPlaten, Strut, TableParts,
};
use serde_json::Value;

fn data(name: &str) -> String {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/reference/");
    std::fs::read_to_string(format!("{dir}{name}")).expect("the reference file")
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn v3(v: &Value) -> Vector3<f64> {
    Vector3::new(num(&v[0]), num(&v[1]), num(&v[2]))
}

/// The reference's table (contract keys, read here), its pads' friction as `mu` (the
/// reference's free flight is frictionless).
fn table(t: &Value, mu: Option<f64>) -> MultiAxisTable {
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
            mount: match a.get("pad") {
                Some(pad) => Mount::Pad(Pad {
                    axis: Unit::new_normalize(v3(&pad["axis"])),
                    contact_m: v3(&pad["contact_m"]),
                    friction_coefficient: mu.unwrap_or(num(&pad["friction_coefficient"])),
                }),
                None => Mount::Swivel {
                    platen_m: v3(&a["platen_m"]),
                },
            },
            cap_side_area_m2: num(&a["cap_side_area_m2"]),
            rod_side_area_m2: num(&a["rod_side_area_m2"]),
            chamber_volume_m3: num(&a["chamber_volume_m3"]),
            stroke_m: num(&a["stroke_m"]),
        })
        .collect();
    let struts = t["hold_down_struts"]
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
        .collect();
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

/// The reference's force record, one column per actuator in the table's order.
fn forces(t: &MultiAxisTable) -> ActuatorForces {
    let text = data("multi_axis_forces.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let col = |name: &str| {
        let k = header.iter().position(|h| *h == name).unwrap();
        rows.iter().map(|r| r[k]).collect::<Vec<f64>>()
    };
    let f = t
        .actuators()
        .iter()
        .map(|a| col(&format!("{}_force_n", a.name)))
        .collect();
    ActuatorForces::new(col("t_s"), f).unwrap()
}

/// The largest differences in position (m) and angle (rad) from the reference, over its
/// output samples, and the run's energy residual over its work.
fn compare(method: Method) -> (f64, f64, f64) {
    let r: Value = serde_json::from_str(&data("multi_axis.json")).unwrap();
    let t = table(&r["table"], Some(0.0));
    let f = forces(&t);
    let run = forward_table(&t, None, &f, method, Coords::zeros(), Coords::zeros()).unwrap();
    let every = r["forward"]["output_every"].as_u64().unwrap() as usize;
    let names = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"];
    let (mut dm, mut drad) = (0.0f64, 0.0f64);
    for (k, s) in r["forward"]["samples"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let i = k * every;
        assert_eq!(run.column("t_s").unwrap()[i], num(&s["t_s"]));
        for (d, name) in names.iter().enumerate() {
            let diff = (run.column(name).unwrap()[i] - num(&s["pose"][d])).abs();
            if d < 3 {
                dm = dm.max(diff);
            } else {
                drad = drad.max(diff);
            }
        }
    }
    // Energy: the actuators' work is the kinetic energy plus gravity's and the struts'.
    let last = run.len() - 1;
    let at = |prefix: &[&str], i: usize| Coords::from_fn(|d, _| run.column(prefix[d]).unwrap()[i]);
    let rates = [
        "x_m_s",
        "y_m_s",
        "z_m_s",
        "roll_rad_s",
        "pitch_rad_s",
        "yaw_rad_s",
    ];
    let energy = |i: usize| {
        let (q, qd) = (at(&names, i), at(&rates, i));
        table_kinetic_energy_j(&t, &q, &qd) + table_potential_energy_j(&t, &q)
    };
    let work = run.column("actuator_work_j").unwrap()[last];
    let residual = (work - (energy(last) - energy(0))).abs() / work.abs().max(1.0);
    (dm, drad, residual)
}

/// RK4 at four steps per sample (h = 1/4096 s): 1e-7 m and 1e-7 rad over 5 s, the issue's
/// bound; RK4's error at this step on motions of 1–3 Hz is far below it. The work equals the
/// energy to 1e-6 of itself (RK4's quadrature of the power against its own states).
#[test]
fn rk4_follows_the_independent_free_flight() {
    let (dm, drad, energy) = compare(Method::Rk4(Rk4::with_steps_per_sample(4).unwrap()));
    eprintln!("RK4 h = 1/4096 s: {dm:e} m, {drad:e} rad, energy residual {energy:e}");
    assert!(dm < 1e-7 && drad < 1e-7, "{dm} m, {drad} rad");
    assert!(energy < 1e-6, "{energy}");
}

/// Dopri5 at rtol 1e-10, atol 1e-12 through the same machine: the same bound.
#[test]
fn dopri5_follows_the_independent_free_flight() {
    let (dm, drad, energy) = compare(Method::Dopri5(Dopri5Settings::new(1e-10, 1e-12).unwrap()));
    eprintln!("Dopri5 rtol 1e-10: {dm:e} m, {drad:e} rad, energy residual {energy:e}");
    assert!(dm < 1e-7 && drad < 1e-7, "{dm} m, {drad} rad");
    assert!(energy < 1e-6, "{energy}");
}
