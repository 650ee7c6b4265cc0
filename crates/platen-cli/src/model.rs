//! `platen model`: a preset's parameters and derived quantities.

use anyhow::Result;
use serde_json::{json, Map, Value};

use platen_model::{IdentifiedKey, PhysicalKey, Preset};

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
    let value = describe(preset, pressure_pa, form)?;
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

/// The preset's description at `pressure_pa`: the seven contract keys of the selected form,
/// the derived quantities of Eq. 5–8, the table limits and the physical parameters.
fn describe(preset: Preset, pressure_pa: f64, form: Form) -> Result<Value> {
    let identified = preset.identified(pressure_pa)?.build()?;
    let physical = preset.physical(pressure_pa)?;
    let full = physical.build()?;
    let d = full.derived();
    // The seven contract keys describe the selected form.
    let (form_name, seven) = match form {
        Form::Identified => ("identified", *identified.params()),
        Form::Full => ("full", full.identified_equivalent()),
    };
    let mut m = Map::new();
    for key in IdentifiedKey::ALL {
        m.insert(key.name().into(), json!(seven.get(key)));
    }
    let mut physical_map = Map::new();
    physical_map.insert(
        "hold_down_pressure_pa".into(),
        json!(physical.hold_down_pressure_pa),
    );
    for key in PhysicalKey::all() {
        physical_map.insert(key.name().into(), json!(physical.get(key)));
    }
    let limits = preset.limits();
    let rest = json!({
        "preset": preset.name(),
        "form": form_name,
        "hold_down_pressure_mpa": pressure_pa / 1e6,
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
            "stroke_m": limits.stroke_m,
            "velocity_m_s": limits.velocity_m_s,
            "acceleration_m_s2": limits.acceleration_m_s2,
            "force_n": limits.force_n,
        },
        "physical": Value::Object(physical_map),
    });
    if let Value::Object(rest) = rest {
        m.extend(rest);
    }
    Ok(Value::Object(m))
}
