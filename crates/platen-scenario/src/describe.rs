//! What `platen model` describes, as data: a preset's (or a scenario's) parameters and
//! derived quantities ([`ModelDescription`], [`describe_model`]; what `platen model --json`
//! prints and Python's `platen.model()` returns) and, with a table system, its closed forms
//! and linearised loop ([`SystemAnalysis`], [`SystemDescription`]).
//!
//! Serialised with serde, every object prints its keys in alphabetical order (the order of
//! the contract's JSON): the structs declare their fields in that order.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;
use serde_json::Value;

use platen_model::{IdentifiedKey, IdentifiedParams, ModelError, PhysicalKey, Preset, TableLimits};

use crate::rig::Rig;
use crate::scenario::Model;

pub use crate::describe_system::{
    LinearisationDescription, LoopMarginsDescription, SystemAnalysis, SystemDescription,
};

/// The description of a model: the contract's seven identified keys of the selected form,
/// the derived quantities of Eq. 5–8 (`full_*`, `cubic_stiffness_n_per_m`, …), the
/// `physical` parameters, the table `limits` and, for a scenario, its path, the values it
/// lays over its preset's, its specimen and its table system.
///
/// Fields are declared in alphabetical order, so that it serialises like the JSON object of
/// [`describe_model`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelDescription {
    /// Coulomb friction force `F_μ` of the selected form, N.
    pub coulomb_force_n: f64,
    /// Cubic stiffness `K′ₑ` of the hold-down struts (Eq. 6b), N/m.
    pub cubic_stiffness_n_per_m: f64,
    /// Effective mass `Mₑ` of the selected form, kg.
    pub effective_mass_kg: f64,
    /// `"identified"` or `"full"`.
    pub form: String,
    /// Coulomb friction force of the full model (Eq. 7a), N.
    pub full_coulomb_force_n: f64,
    /// Effective mass of the full model (Eq. 5a), kg.
    pub full_effective_mass_kg: f64,
    /// Stiffness of the full model (Eq. 6a), N/m.
    pub full_stiffness_n_per_m: f64,
    /// Hinge friction coefficient `μ⁽ⁱᵛ⁾ₑ` (Eq. 8).
    pub hinge_friction_coefficient: f64,
    /// Hold-down force `2p₀A`, N.
    pub hold_down_force_n: f64,
    /// Hold-down friction coefficient `μ′ₑ` (Eq. 7b).
    pub hold_down_friction_coefficient: f64,
    /// Hold-down (nitrogen pre-charge) pressure, MPa.
    pub hold_down_pressure_mpa: f64,
    /// The table's operational limits.
    pub limits: LimitsDescription,
    /// Low-velocity friction decay `b` of the selected form, s/m.
    pub low_velocity_decay_s_per_m: f64,
    /// Low-velocity friction force `a` of the selected form, N.
    pub low_velocity_force_n: f64,
    /// The values a scenario lays over its preset's, by key (empty: none, or no scenario).
    pub model_overrides: Option<BTreeMap<String, f64>>,
    /// The physical parameters of the full model, by key (SI, the scenario format's names).
    pub physical: BTreeMap<String, f64>,
    /// The preset's name.
    pub preset: String,
    /// The scenario file described, as given (`null`: a preset).
    pub scenario: Option<String>,
    /// The scenario's specimen, if any.
    pub specimen: Option<SpecimenDescription>,
    /// Stiffness `Kₑ` of the selected form, N/m.
    pub stiffness_n_per_m: f64,
    /// Effective mass of one strut `M̄ₑ` (Eq. 5b), kg.
    pub strut_effective_mass_kg: f64,
    /// Strut rotational mass `M̄′ₑ` (Eq. 5c), kg.
    pub strut_rotational_mass_kg: f64,
    /// The table system's closed forms and linearised loop, if one is described.
    pub table_system: Option<SystemDescription>,
    /// Viscous coefficient `Cₑ` of the selected form, N/(m/s)^α.
    pub viscous_coefficient: f64,
    /// Viscous exponent `α` of the selected form.
    pub viscous_exponent: f64,
}

/// The table's operational limits (`limits`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LimitsDescription {
    /// Acceleration of the bare table, m/s².
    pub acceleration_m_s2: f64,
    /// Actuator force, N.
    pub force_n: f64,
    /// Stroke, either way, m.
    pub stroke_m: f64,
    /// Velocity, m/s.
    pub velocity_m_s: f64,
}

impl From<&TableLimits> for LimitsDescription {
    fn from(l: &TableLimits) -> Self {
        Self {
            acceleration_m_s2: l.acceleration_m_s2,
            force_n: l.force_n,
            stroke_m: l.stroke_m,
            velocity_m_s: l.velocity_m_s,
        }
    }
}

/// A scenario's specimen (`specimen`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpecimenDescription {
    /// Number of storeys.
    pub storeys: usize,
    /// Mass of all storeys, kg.
    pub total_mass_kg: f64,
}

impl ModelDescription {
    /// The description of `preset` at the hold-down pressure `pressure_pa`, its seven
    /// identified keys those of the identified model or, when `full`, the identified-model
    /// equivalent of the full model.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] for a pressure the preset rejects (negative, not
    /// finite).
    pub fn of_preset(
        preset: Preset,
        pressure_pa: f64,
        full: bool,
    ) -> std::result::Result<Self, ModelError> {
        let identified = preset.identified(pressure_pa)?.build()?;
        let physical = preset.physical(pressure_pa)?;
        let full_model = physical.build()?;
        let d = full_model.derived();
        // The seven contract keys describe the selected form.
        let (form, seven) = if full {
            ("full", full_model.identified_equivalent())
        } else {
            ("identified", *identified.params())
        };
        let mut physical_map = BTreeMap::new();
        physical_map.insert(
            "hold_down_pressure_pa".to_owned(),
            physical.hold_down_pressure_pa,
        );
        for key in PhysicalKey::all() {
            physical_map.insert(key.name().to_owned(), physical.get(key));
        }
        let mut description = Self {
            coulomb_force_n: 0.0,
            cubic_stiffness_n_per_m: d.cubic_stiffness_n_per_m,
            effective_mass_kg: 0.0,
            form: form.to_owned(),
            full_coulomb_force_n: d.coulomb_force_n,
            full_effective_mass_kg: d.effective_mass_kg,
            full_stiffness_n_per_m: d.stiffness_n_per_m,
            hinge_friction_coefficient: d.hinge_friction_coefficient,
            hold_down_force_n: d.hold_down_force_n,
            hold_down_friction_coefficient: d.hold_down_friction_coefficient,
            hold_down_pressure_mpa: pressure_pa / 1e6,
            limits: LimitsDescription::from(&preset.limits()),
            low_velocity_decay_s_per_m: 0.0,
            low_velocity_force_n: 0.0,
            model_overrides: None,
            physical: physical_map,
            preset: preset.name().to_owned(),
            scenario: None,
            specimen: None,
            stiffness_n_per_m: 0.0,
            strut_effective_mass_kg: d.strut_effective_mass_kg,
            strut_rotational_mass_kg: d.strut_rotational_mass_kg,
            table_system: None,
            viscous_coefficient: 0.0,
            viscous_exponent: 0.0,
        };
        description.set_identified(&seven);
        Ok(description)
    }

    /// The description of the rig `s` of the scenario read from `path` ([`Rig::load`]): its
    /// preset's at its pressure and form with the rig's own model laid in (its seven
    /// identified keys, for the full form its identified equivalent, physical parameters and
    /// derived quantities), its limits, `scenario` (the path as given), `model_overrides`
    /// and `specimen`. The table system is left to [`SystemAnalysis`].
    ///
    /// # Errors
    /// As [`ModelDescription::of_preset`] (not for a validated rig).
    pub fn of_rig(path: &Path, s: &Rig) -> std::result::Result<Self, ModelError> {
        let mut d = Self::of_preset(s.preset, s.hold_down_pressure_pa, s.model.form() == "full")?;
        let seven = match &s.model {
            Model::Identified(m) => *m.params(),
            Model::Full(m) => m.identified_equivalent(),
        };
        d.set_identified(&seven);
        if let Model::Full(m) = &s.model {
            for key in PhysicalKey::all() {
                d.physical
                    .insert(key.name().to_owned(), m.params().get(key));
            }
            let derived = m.derived();
            d.cubic_stiffness_n_per_m = derived.cubic_stiffness_n_per_m;
            d.strut_effective_mass_kg = derived.strut_effective_mass_kg;
            d.strut_rotational_mass_kg = derived.strut_rotational_mass_kg;
            d.hold_down_force_n = derived.hold_down_force_n;
            d.hinge_friction_coefficient = derived.hinge_friction_coefficient;
            d.hold_down_friction_coefficient = derived.hold_down_friction_coefficient;
            d.full_effective_mass_kg = derived.effective_mass_kg;
            d.full_stiffness_n_per_m = derived.stiffness_n_per_m;
            d.full_coulomb_force_n = derived.coulomb_force_n;
        }
        d.limits = LimitsDescription::from(&s.limits);
        d.scenario = Some(path.display().to_string());
        let overrides: BTreeMap<String, f64> = s
            .overrides
            .values()
            .iter()
            .map(|(key, value)| (key.name().to_owned(), *value))
            .collect();
        if !overrides.is_empty() {
            d.model_overrides = Some(overrides);
        }
        d.specimen = s.specimen.as_ref().map(|sp| SpecimenDescription {
            storeys: sp.len(),
            total_mass_kg: sp.total_mass_kg(),
        });
        Ok(d)
    }

    /// Lays the seven identified keys of `seven` in.
    fn set_identified(&mut self, seven: &IdentifiedParams) {
        self.effective_mass_kg = seven.get(IdentifiedKey::EffectiveMass);
        self.stiffness_n_per_m = seven.get(IdentifiedKey::Stiffness);
        self.coulomb_force_n = seven.get(IdentifiedKey::CoulombForce);
        self.viscous_coefficient = seven.get(IdentifiedKey::ViscousCoefficient);
        self.viscous_exponent = seven.get(IdentifiedKey::ViscousExponent);
        self.low_velocity_force_n = seven.get(IdentifiedKey::LowVelocityForce);
        self.low_velocity_decay_s_per_m = seven.get(IdentifiedKey::LowVelocityDecay);
    }
}

/// The model `preset` at the hold-down pressure `pressure_pa`: its identified model or,
/// when `full`, its full model (the model [`ModelDescription::of_preset`] describes).
///
/// # Errors
/// [`ModelError::InvalidParameter`] for a pressure the preset rejects.
pub fn preset_model(
    preset: Preset,
    pressure_pa: f64,
    full: bool,
) -> std::result::Result<Model, ModelError> {
    Ok(if full {
        Model::Full(Box::new(preset.physical(pressure_pa)?.build()?))
    } else {
        Model::Identified(preset.identified(pressure_pa)?.build()?)
    })
}

/// The description of `preset` at the hold-down pressure `pressure_pa`
/// ([`ModelDescription::of_preset`]) as a JSON object, its keys in alphabetical order.
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
pub fn describe_model(
    preset: Preset,
    pressure_pa: f64,
    full: bool,
) -> std::result::Result<Value, ModelError> {
    let d = ModelDescription::of_preset(preset, pressure_pa, full)?;
    // Numbers and strings under string keys: the conversion cannot fail.
    Ok(serde_json::to_value(d).unwrap_or(Value::Null))
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

    /// The structs declare their fields alphabetically: printed as they are, they give the
    /// bytes of the sorted JSON object (the contract's order).
    #[test]
    fn the_struct_prints_its_keys_in_the_json_objects_order() {
        for full in [false, true] {
            let d = ModelDescription::of_preset(Preset::Lhpost2008, 6.9e6, full).unwrap();
            let direct = serde_json::to_string_pretty(&d).unwrap();
            let sorted = serde_json::to_string_pretty(&serde_json::to_value(&d).unwrap()).unwrap();
            assert_eq!(direct, sorted);
        }
    }

    #[test]
    fn a_scenario_lays_its_values_and_specimen_in() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
        let path = root.join("table-system/wn10g-closed-loop.json");
        let loaded = crate::LoadedRig::load(&path).unwrap();
        assert_eq!(loaded.table_system_preset.as_deref(), Some("lhpost-2008"));
        let d = ModelDescription::of_rig(&path, &loaded.rig).unwrap();
        assert_eq!(
            d.scenario.as_deref(),
            Some(path.display().to_string().as_str())
        );
        assert_eq!(d.form, "identified");
        assert_eq!(d.effective_mass_kg, 144e3);
    }
}
