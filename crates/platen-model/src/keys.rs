//! The names of the model's parameters, as in the contract: one source for every reader,
//! writer and table.

use std::fmt;
use std::str::FromStr;

use crate::error::ModelError;
use crate::IdentifiedParams;

/// One of the seven parameters of the identified model (Eq. 22/23), named as in the contract
/// (scenario overrides, `identify --json`, `model --json`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum IdentifiedKey {
    /// `effective_mass_kg`: `Mₑ`, kg.
    EffectiveMass,
    /// `stiffness_n_per_m`: `Kₑ`, N/m.
    Stiffness,
    /// `coulomb_force_n`: `F_μ`, N.
    CoulombForce,
    /// `viscous_coefficient`: `Cₑ`, N/(m/s)^α.
    ViscousCoefficient,
    /// `viscous_exponent`: `α`.
    ViscousExponent,
    /// `low_velocity_force_n`: `a`, N.
    LowVelocityForce,
    /// `low_velocity_decay_s_per_m`: `b`, s/m.
    LowVelocityDecay,
}

/// The seven identified keys' names, comma separated, in the order of [`IdentifiedKey::ALL`].
pub const IDENTIFIED_KEY_NAMES: &str = "effective_mass_kg, stiffness_n_per_m, coulomb_force_n, \
     viscous_coefficient, viscous_exponent, low_velocity_force_n, low_velocity_decay_s_per_m";

impl IdentifiedKey {
    /// Every key, in the contract's order.
    pub const ALL: [IdentifiedKey; 7] = [
        IdentifiedKey::EffectiveMass,
        IdentifiedKey::Stiffness,
        IdentifiedKey::CoulombForce,
        IdentifiedKey::ViscousCoefficient,
        IdentifiedKey::ViscousExponent,
        IdentifiedKey::LowVelocityForce,
        IdentifiedKey::LowVelocityDecay,
    ];

    /// The contract name (`"effective_mass_kg"`, …).
    pub fn name(self) -> &'static str {
        match self {
            IdentifiedKey::EffectiveMass => "effective_mass_kg",
            IdentifiedKey::Stiffness => "stiffness_n_per_m",
            IdentifiedKey::CoulombForce => "coulomb_force_n",
            IdentifiedKey::ViscousCoefficient => "viscous_coefficient",
            IdentifiedKey::ViscousExponent => "viscous_exponent",
            IdentifiedKey::LowVelocityForce => "low_velocity_force_n",
            IdentifiedKey::LowVelocityDecay => "low_velocity_decay_s_per_m",
        }
    }

    /// The SI unit of the value, for display (`"kg"`, `"N/m"`, `"N"`, `"N/(m/s)^α"`, `""`
    /// for the exponent, `"s/m"`).
    pub fn unit(self) -> &'static str {
        match self {
            IdentifiedKey::EffectiveMass => "kg",
            IdentifiedKey::Stiffness => "N/m",
            IdentifiedKey::CoulombForce | IdentifiedKey::LowVelocityForce => "N",
            IdentifiedKey::ViscousCoefficient => "N/(m/s)^α",
            IdentifiedKey::ViscousExponent => "",
            IdentifiedKey::LowVelocityDecay => "s/m",
        }
    }

    /// Looks a key up by its contract name.
    ///
    /// # Errors
    /// [`ModelError::UnknownParameter`]: "unknown identified parameter; expected one of …"
    /// listing the seven names.
    pub fn from_name(name: &str) -> Result<Self, ModelError> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| ModelError::UnknownParameter {
                form: "identified",
                name: name.to_owned(),
                known: IDENTIFIED_KEY_NAMES.to_owned(),
            })
    }
}

impl fmt::Display for IdentifiedKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IdentifiedKey {
    type Err = ModelError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s)
    }
}

impl IdentifiedParams {
    /// The value of parameter `key`.
    pub fn get(&self, key: IdentifiedKey) -> f64 {
        let mut copy = *self;
        *copy.slot_mut(key)
    }

    /// Sets parameter `key` to `value` (not validated: [`IdentifiedParams::build`] does that).
    pub fn set(&mut self, key: IdentifiedKey, value: f64) {
        *self.slot_mut(key) = value;
    }

    /// Builds parameters from a value per key.
    pub fn from_fn(mut value: impl FnMut(IdentifiedKey) -> f64) -> Self {
        Self {
            effective_mass_kg: value(IdentifiedKey::EffectiveMass),
            stiffness_n_per_m: value(IdentifiedKey::Stiffness),
            coulomb_force_n: value(IdentifiedKey::CoulombForce),
            viscous_coefficient: value(IdentifiedKey::ViscousCoefficient),
            viscous_exponent: value(IdentifiedKey::ViscousExponent),
            low_velocity_force_n: value(IdentifiedKey::LowVelocityForce),
            low_velocity_decay_s_per_m: value(IdentifiedKey::LowVelocityDecay),
        }
    }

    fn slot_mut(&mut self, key: IdentifiedKey) -> &mut f64 {
        match key {
            IdentifiedKey::EffectiveMass => &mut self.effective_mass_kg,
            IdentifiedKey::Stiffness => &mut self.stiffness_n_per_m,
            IdentifiedKey::CoulombForce => &mut self.coulomb_force_n,
            IdentifiedKey::ViscousCoefficient => &mut self.viscous_coefficient,
            IdentifiedKey::ViscousExponent => &mut self.viscous_exponent,
            IdentifiedKey::LowVelocityForce => &mut self.low_velocity_force_n,
            IdentifiedKey::LowVelocityDecay => &mut self.low_velocity_decay_s_per_m,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_round_trips_through_its_name() {
        for key in IdentifiedKey::ALL {
            assert_eq!(key.name().parse::<IdentifiedKey>().unwrap(), key);
        }
        let names: Vec<&str> = IdentifiedKey::ALL.iter().map(|k| k.name()).collect();
        assert_eq!(names.join(", "), IDENTIFIED_KEY_NAMES);
    }

    #[test]
    fn an_unknown_name_lists_the_seven_in_the_wording_sweep_uses() {
        let err = IdentifiedKey::from_name("mass_kg").unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown identified parameter; expected one of effective_mass_kg, \
             stiffness_n_per_m, coulomb_force_n, viscous_coefficient, viscous_exponent, \
             low_velocity_force_n, low_velocity_decay_s_per_m"
        );
    }

    #[test]
    fn get_and_set_address_the_named_field() {
        let mut p = IdentifiedParams::from_fn(|_| 0.0);
        p.set(IdentifiedKey::LowVelocityDecay, 78.5);
        assert_eq!(p.low_velocity_decay_s_per_m, 78.5);
        assert_eq!(p.get(IdentifiedKey::LowVelocityDecay), 78.5);
        assert_eq!(p.get(IdentifiedKey::EffectiveMass), 0.0);
    }
}
