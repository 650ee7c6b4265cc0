//! The multi-axis loop test table of `tools/reference/loop_table.json` (the table of
//! `scenarios/multi-axis/tower-inverse.json` without its specimen, with servo-valves and a DOF
//! controller), built in Rust from that file, with frictionless pads and a constant supply:
//! the table the NumPy reference `tools/reference/multi_axis_loop.py` linearises.

use nalgebra::{Matrix3, Unit, Vector3};
use platen_model::multi_axis::{
    Actuator, Dof, DofSet, Mount, MultiAxisTable, Pad, RigidPlaten, Strut, TableParts,
};
use platen_system::{
    open_loop, ActuatorHydraulics, Controller, DofController, DofGeometry, ServoValve, Supply,
    TableHydraulics, TableHydraulicsParts,
};
use serde_json::Value;

/// The table, its hydraulics and its controller.
pub struct LoopTable {
    pub table: MultiAxisTable,
    pub hydraulics: TableHydraulics,
    pub controller: DofController,
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("loop_table.json: `{key}` is not a number"))
}

fn point(v: &Value, key: &str) -> Vector3<f64> {
    let a = v[key]
        .as_array()
        .unwrap_or_else(|| panic!("loop_table.json: `{key}` is not an array"));
    Vector3::new(
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    )
}

/// The table of `tools/reference/loop_table.json`, pads frictionless.
pub fn loop_table() -> LoopTable {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/reference/loop_table.json"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let root: Value = serde_json::from_str(&text).unwrap();
    let t = &root["table"];
    let p = &t["platen"];
    let rows: Vec<Vector3<f64>> = (0..3)
        .map(|r| {
            let row = &p["inertia_kg_m2"][r];
            Vector3::new(
                row[0].as_f64().unwrap(),
                row[1].as_f64().unwrap(),
                row[2].as_f64().unwrap(),
            )
        })
        .collect();
    let inertia = Matrix3::from_rows(&[
        rows[0].transpose(),
        rows[1].transpose(),
        rows[2].transpose(),
    ]);
    let platen =
        RigidPlaten::new(num(p, "mass_kg"), inertia, point(p, "centre_of_mass_m")).unwrap();
    let mut actuators = Vec::new();
    let mut hydraulics = Vec::new();
    for a in t["actuators"].as_array().unwrap() {
        let mount = if a.get("platen_m").is_some() {
            Mount::Swivel {
                platen_m: point(a, "platen_m"),
            }
        } else {
            let pad = &a["pad"];
            Mount::Pad(Pad {
                axis: Unit::new_normalize(point(pad, "axis")),
                contact_m: point(pad, "contact_m"),
                friction_coefficient: 0.0,
            })
        };
        actuators.push(Actuator {
            name: a["name"].as_str().unwrap().into(),
            base_m: point(a, "base_m"),
            mount,
            cap_side_area_m2: num(a, "cap_side_area_m2"),
            rod_side_area_m2: num(a, "rod_side_area_m2"),
            chamber_volume_m3: num(a, "chamber_volume_m3"),
            stroke_m: num(a, "stroke_m"),
        });
        let v = &a["servo_valve"];
        hydraulics.push(ActuatorHydraulics {
            cap_area_m2: num(a, "cap_side_area_m2"),
            rod_area_m2: num(a, "rod_side_area_m2"),
            chamber_volume_m3: num(a, "chamber_volume_m3"),
            leakage_m3_s_per_pa: num(a, "leakage_m3_s_per_pa"),
            servo_valve: ServoValve {
                count: v["count"].as_u64().unwrap() as u32,
                rated_flow_m3_s: num(v, "rated_flow_m3_s"),
                rated_pressure_drop_pa: num(v, "rated_pressure_drop_pa"),
                natural_frequency_hz: num(v, "natural_frequency_hz"),
                damping_ratio: num(v, "damping_ratio"),
                delay_s: num(v, "delay_s"),
            },
        });
    }
    let struts = t["hold_down_struts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| Strut {
            name: s["name"].as_str().unwrap().into(),
            base_m: point(s, "base_m"),
            platen_m: point(s, "platen_m"),
            area_m2: num(s, "area_m2"),
            pressure_pa: num(s, "pressure_pa"),
            gas_volume_m3: num(s, "gas_volume_m3"),
            polytropic_exponent: num(s, "polytropic_exponent"),
        })
        .collect();
    let held: Vec<Dof> = t["held_dofs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| Dof::from_name(d.as_str().unwrap()).unwrap())
        .collect();
    let beta = num(t, "oil_bulk_modulus_pa");
    let strokes: Vec<f64> = actuators.iter().map(|a| a.stroke_m).collect();
    let table = MultiAxisTable::new(TableParts {
        platen,
        actuators,
        struts,
        bearings: Vec::new(),
        held: DofSet::of(&held),
        oil_bulk_modulus_pa: beta,
    })
    .unwrap();
    let hydraulics = TableHydraulics::new(
        TableHydraulicsParts {
            actuators: hydraulics,
            oil_bulk_modulus_pa: beta,
            supply_pressure_pa: num(t, "supply_pressure_pa"),
            return_pressure_pa: num(t, "return_pressure_pa"),
            supply: Supply::Constant,
        },
        &strokes,
    )
    .unwrap();
    let c = &t["controller"];
    let rate = num(c, "sample_rate_hz");
    let mut loops = [open_loop(rate); 6];
    for d in table.free().iter() {
        let g = &c["dof"][d.name()];
        let gain = |key: &str| g[key].as_f64().unwrap_or(0.0);
        loops[d.index()] = Controller {
            sample_rate_hz: rate,
            displacement_gain_per_m: gain("displacement_gain_per_m"),
            integral_gain_per_m_s: gain("integral_gain_per_m_s"),
            velocity_feedforward_s_per_m: gain("velocity_feedforward_s_per_m"),
            acceleration_feedforward_s2_per_m: gain("acceleration_feedforward_s2_per_m"),
            velocity_feedback_s_per_m: gain("velocity_feedback_s_per_m"),
            acceleration_feedback_s2_per_m: gain("acceleration_feedback_s2_per_m"),
            delta_p_gain_per_pa: gain("delta_p_gain_per_pa"),
            delta_p_highpass_hz: gain("delta_p_highpass_hz"),
        };
    }
    let controller = DofController::new(
        rate,
        loops,
        c["force_balance_gain"].as_f64().unwrap_or(0.0),
        DofGeometry::of_table(&table).unwrap(),
    )
    .unwrap();
    LoopTable {
        table,
        hydraulics,
        controller,
    }
}
