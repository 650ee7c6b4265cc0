//! The names of the full model's physical parameters (scenario `full` overrides, `--set
//! full.NAME=…`): one table for every reader and writer.

use std::fmt;
use std::str::FromStr;

use crate::error::ModelError;
use crate::PhysicalParams;

/// A field of [`PhysicalParams`] and its name.
type Slot = (&'static str, fn(&mut PhysicalParams) -> &mut f64);

/// Every overridable physical parameter (the hold-down pressure has its own setting), in
/// the order of [`PhysicalParams`]' documentation.
const SLOTS: [Slot; 21] = [
    ("platen_mass_kg", |p| &mut p.platen_mass_kg),
    ("actuator_moving_mass_kg", |p| {
        &mut p.actuator_moving_mass_kg
    }),
    ("strut_piston_mass_kg", |p| &mut p.strut_piston_mass_kg),
    ("strut_cylinder_mass_kg", |p| &mut p.strut_cylinder_mass_kg),
    ("strut_height_m", |p| &mut p.strut_height_m),
    ("strut_piston_length_m", |p| &mut p.strut_piston_length_m),
    ("strut_area_m2", |p| &mut p.strut_area_m2),
    ("gas_heat_capacity_ratio", |p| {
        &mut p.gas_heat_capacity_ratio
    }),
    ("supported_weight_n", |p| &mut p.supported_weight_n),
    ("bearing_friction_coefficient", |p| {
        &mut p.bearing_friction_coefficient
    }),
    ("lateral_friction_coefficient", |p| {
        &mut p.lateral_friction_coefficient
    }),
    ("lateral_normal_force_n", |p| &mut p.lateral_normal_force_n),
    ("hinge_swivel_friction_coefficient", |p| {
        &mut p.hinge_swivel_friction_coefficient
    }),
    ("hinge_radius_m", |p| &mut p.hinge_radius_m),
    ("hinge_force_distribution_factor", |p| {
        &mut p.hinge_force_distribution_factor
    }),
    ("viscous_coefficient", |p| &mut p.viscous_coefficient),
    ("viscous_exponent", |p| &mut p.viscous_exponent),
    ("strut_viscous_coefficient", |p| {
        &mut p.strut_viscous_coefficient
    }),
    ("strut_viscous_exponent", |p| &mut p.strut_viscous_exponent),
    ("low_velocity_force_n", |p| &mut p.low_velocity_force_n),
    ("low_velocity_decay_s_per_m", |p| {
        &mut p.low_velocity_decay_s_per_m
    }),
];

/// One overridable physical parameter of the full model, by its contract name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PhysicalKey(usize);

impl PhysicalKey {
    /// Every key, in the order of [`PhysicalParams`].
    pub fn all() -> impl Iterator<Item = PhysicalKey> {
        (0..SLOTS.len()).map(PhysicalKey)
    }

    /// The name (`"platen_mass_kg"`, …).
    pub fn name(self) -> &'static str {
        SLOTS[self.0].0
    }

    /// Looks a key up by its name.
    ///
    /// # Errors
    /// [`ModelError::UnknownParameter`]: "unknown full parameter; expected one of …".
    pub fn from_name(name: &str) -> Result<Self, ModelError> {
        SLOTS
            .iter()
            .position(|(n, _)| *n == name)
            .map(PhysicalKey)
            .ok_or_else(|| ModelError::UnknownParameter {
                form: "full",
                name: name.to_owned(),
                known: SLOTS.map(|(n, _)| n).join(", "),
            })
    }
}

impl fmt::Display for PhysicalKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PhysicalKey {
    type Err = ModelError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s)
    }
}

impl PhysicalParams {
    /// The value of parameter `key`.
    pub fn get(&self, key: PhysicalKey) -> f64 {
        let mut copy = *self;
        *(SLOTS[key.0].1)(&mut copy)
    }

    /// Sets parameter `key` to `value` (not validated: [`PhysicalParams::build`] does that).
    pub fn set(&mut self, key: PhysicalKey, value: f64) {
        *(SLOTS[key.0].1)(self) = value;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_round_trips_and_addresses_its_own_field() {
        let mut p = crate::preset::lhpost_2008_physical(13.8e6);
        for (i, key) in PhysicalKey::all().enumerate() {
            assert_eq!(key.name().parse::<PhysicalKey>().unwrap(), key);
            p.set(key, 1000.0 + i as f64);
        }
        for (i, key) in PhysicalKey::all().enumerate() {
            assert_eq!(p.get(key), 1000.0 + i as f64, "{key}");
        }
        assert_eq!(p.platen_mass_kg, 1000.0);
        assert_eq!(p.low_velocity_decay_s_per_m, 1020.0);
        assert_eq!(p.hold_down_pressure_pa, 13.8e6, "the pressure is not a key");
    }

    #[test]
    fn an_unknown_name_lists_every_key() {
        let err = PhysicalKey::from_name("mass").unwrap_err().to_string();
        assert!(err.starts_with("unknown full parameter; expected one of platen_mass_kg, "));
        assert!(
            err.ends_with("low_velocity_force_n, low_velocity_decay_s_per_m"),
            "{err}"
        );
    }
}
