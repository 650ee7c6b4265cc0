//! A preset's parameters and derived quantities: what `platen model --json` prints and
//! Python's `platen.model()` returns.

use serde_json::{json, Map, Value};

use platen_model::{IdentifiedKey, ModelError, PhysicalKey, Preset};

/// The description of `preset` at the hold-down pressure `pressure_pa`: the contract's seven
/// identified keys of the selected form (the identified model's, or for `full` the
/// identified-model equivalent of the full model), `preset`, `form`,
/// `hold_down_pressure_mpa`, the derived quantities of Eq. 5–8 (`full_effective_mass_kg`,
/// `cubic_stiffness_n_per_m`, …), the table `limits` and the `physical` parameters. A JSON
/// object whose keys are in alphabetical order.
///
/// ```
/// use platen_model::Preset;
/// let d = platen_scenario::describe_model(Preset::Lhpost2008, 13.8e6, false)?;
/// assert_eq!(d["effective_mass_kg"], 144e3);
/// assert_eq!(d["form"], "identified");
/// # Ok::<(), platen_model::ModelError>(())
/// ```
///
/// # Errors
/// [`ModelError::InvalidParameter`] for a pressure the preset rejects (negative, not
/// finite).
pub fn describe_model(preset: Preset, pressure_pa: f64, full: bool) -> Result<Value, ModelError> {
    let identified = preset.identified(pressure_pa)?.build()?;
    let physical = preset.physical(pressure_pa)?;
    let full_model = physical.build()?;
    let d = full_model.derived();
    // The seven contract keys describe the selected form.
    let (form_name, seven) = if full {
        ("full", full_model.identified_equivalent())
    } else {
        ("identified", *identified.params())
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's Eq. 22/23 values at 13.8 MPa, and the full form's equivalent from Eq. 5–8.
    #[test]
    fn the_description_holds_the_papers_identified_values_and_the_full_forms_equivalent() {
        let d = describe_model(Preset::Lhpost2008, 13.8e6, false).unwrap();
        assert_eq!(d["effective_mass_kg"], 144e3);
        assert_eq!(d["stiffness_n_per_m"], 1.266e6);
        assert_eq!(d["viscous_exponent"], 0.5);
        assert_eq!(d["hold_down_pressure_mpa"], 13.8);
        // F_hd = 2·p₀·A = 2 × 13.8 MPa × 0.15 m².
        let f_hd = d["hold_down_force_n"].as_f64().unwrap();
        assert!((f_hd - 4.14e6).abs() < 1e-6, "{f_hd}");
        let full = describe_model(Preset::Lhpost2008, 13.8e6, true).unwrap();
        assert_eq!(full["form"], "full");
        assert_eq!(full["effective_mass_kg"], d["full_effective_mass_kg"]);
        assert_eq!(full["stiffness_n_per_m"], d["full_stiffness_n_per_m"]);
    }

    #[test]
    fn a_negative_pressure_is_rejected() {
        let e = describe_model(Preset::Lhpost2008, -1e6, false).unwrap_err();
        assert!(e.to_string().contains("hold_down_pressure_pa"), "{e}");
    }
}
