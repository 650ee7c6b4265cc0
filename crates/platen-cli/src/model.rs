//! `platen model`: a preset's parameters and derived quantities.

use anyhow::Result;
use serde_json::{json, Value};

use platen_model::Preset;

use crate::Form;

pub fn run(preset: &str, pressure_mpa: Option<f64>, form: Form, json_out: bool) -> Result<()> {
    let preset = Preset::from_name(preset)?;
    let pressure_pa = match pressure_mpa {
        Some(p) if !(p.is_finite() && p >= 0.0) => {
            anyhow::bail!("--pressure-mpa {p}: expected a pressure >= 0 MPa")
        }
        Some(p) => p * 1e6,
        None => preset.nominal_pressure_pa(),
    };
    let identified = preset.identified(pressure_pa)?.build()?;
    let full = preset.physical(pressure_pa)?.build()?;
    let (p, d) = (full.params(), full.derived());
    // The seven contract keys describe the selected form; the derived quantities of Eq. 5-8
    // and the physical parameters are always shown.
    let (form_name, seven) = match form {
        Form::Identified => {
            let q = identified.params();
            (
                "identified",
                [
                    q.effective_mass_kg,
                    q.stiffness_n_per_m,
                    q.coulomb_force_n,
                    q.viscous_coefficient,
                    q.viscous_exponent,
                    q.low_velocity_force_n,
                    q.low_velocity_decay_s_per_m,
                ],
            )
        }
        Form::Full => (
            "full",
            [
                d.effective_mass_kg,
                d.stiffness_n_per_m,
                d.coulomb_force_n,
                p.viscous_coefficient,
                p.viscous_exponent,
                p.low_velocity_force_n,
                p.low_velocity_decay_s_per_m,
            ],
        ),
    };
    let value = json!({
        "preset": preset.name(),
        "form": form_name,
        "hold_down_pressure_mpa": pressure_pa / 1e6,
        "effective_mass_kg": seven[0],
        "stiffness_n_per_m": seven[1],
        "coulomb_force_n": seven[2],
        "viscous_coefficient": seven[3],
        "viscous_exponent": seven[4],
        "low_velocity_force_n": seven[5],
        "low_velocity_decay_s_per_m": seven[6],
        "cubic_stiffness_n_per_m": d.cubic_stiffness_n_per_m,
        "strut_effective_mass_kg": d.strut_effective_mass_kg,
        "strut_rotational_mass_kg": d.strut_rotational_mass_kg,
        "hold_down_force_n": d.hold_down_force_n,
        "hinge_friction_coefficient": d.hinge_friction_coefficient,
        "hold_down_friction_coefficient": d.hold_down_friction_coefficient,
        "full_effective_mass_kg": d.effective_mass_kg,
        "full_stiffness_n_per_m": d.stiffness_n_per_m,
        "full_coulomb_force_n": d.coulomb_force_n,
        "limits": {
            "stroke_m": preset.limits().stroke_m,
            "velocity_m_s": preset.limits().velocity_m_s,
            "acceleration_m_s2": preset.limits().acceleration_m_s2,
            "force_n": preset.limits().force_n,
        },
        "physical": {
            "platen_mass_kg": p.platen_mass_kg,
            "actuator_moving_mass_kg": p.actuator_moving_mass_kg,
            "strut_piston_mass_kg": p.strut_piston_mass_kg,
            "strut_cylinder_mass_kg": p.strut_cylinder_mass_kg,
            "strut_height_m": p.strut_height_m,
            "strut_piston_length_m": p.strut_piston_length_m,
            "hold_down_pressure_pa": p.hold_down_pressure_pa,
            "strut_area_m2": p.strut_area_m2,
            "gas_heat_capacity_ratio": p.gas_heat_capacity_ratio,
            "supported_weight_n": p.supported_weight_n,
            "bearing_friction_coefficient": p.bearing_friction_coefficient,
            "lateral_friction_coefficient": p.lateral_friction_coefficient,
            "lateral_normal_force_n": p.lateral_normal_force_n,
            "hinge_swivel_friction_coefficient": p.hinge_swivel_friction_coefficient,
            "hinge_radius_m": p.hinge_radius_m,
            "hinge_force_distribution_factor": p.hinge_force_distribution_factor,
            "viscous_coefficient": p.viscous_coefficient,
            "viscous_exponent": p.viscous_exponent,
            "strut_viscous_coefficient": p.strut_viscous_coefficient,
            "strut_viscous_exponent": p.strut_viscous_exponent,
            "low_velocity_force_n": p.low_velocity_force_n,
            "low_velocity_decay_s_per_m": p.low_velocity_decay_s_per_m,
        }
    });
    if json_out {
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else if let Value::Object(m) = &value {
        for (k, v) in m {
            if !v.is_object() {
                println!("{k:>34}  {v}");
            }
        }
        for section in ["limits", "physical"] {
            if let Some(Value::Object(sub)) = m.get(section) {
                println!("  {section}:");
                for (k, v) in sub {
                    println!("{k:>34}  {v}");
                }
            }
        }
    }
    Ok(())
}
