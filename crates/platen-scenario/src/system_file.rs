//! The `table_system` object as written in a scenario file (its format: [`crate::system`]).
//! [`crate::file`] reads it and [`crate::system`] builds the loop from it; this module uses
//! neither, so neither imports the other back.
//!
//! One type reads and writes it: a [`TableSystem`] is written back as a spec with every
//! value given ([`TableSystemSpec::from`]; what `platen model --system` and
//! `identify --system` print), and a spec is laid over its preset's by one generic overlay
//! ([`Overlay`]): a value given wins, the preset's fills the rest.

use schemars::JsonSchema;
use serde::{Deserialize, Deserializer, Serialize};

use platen_system::{Supply, TableSystem};

/// `table_system`, as written.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableSystemSpec {
    /// A named system (`lhpost-2008`) that the other values are laid over.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// The actuators.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub actuator: Option<ActuatorSpec>,
    /// The servo-valves of each actuator.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub servo_valve: Option<ServoValveSpec>,
    /// Effective bulk modulus of the oil, Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oil_bulk_modulus_pa: Option<f64>,
    /// Supply pressure (absolute), Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub supply_pressure_pa: Option<f64>,
    /// Return pressure (absolute), Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub return_pressure_pa: Option<f64>,
    /// An accumulator bank fed by pumps; `null` for a constant supply. (Absent is not
    /// `null`: it keeps the preset's bank, so it is not written as `null` either.)
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    #[schemars(with = "Option<AccumulatorSpec>")]
    pub accumulator: Option<Option<AccumulatorSpec>>,
    /// The controller.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerSpec>,
}

/// A key given as `null` is `Some(None)`, an absent one `None`.
fn present<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Option<Option<T>>, D::Error> {
    Option::<T>::deserialize(d).map(Some)
}

/// `table_system.actuator`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// Number of actuators acting together.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    /// Piston area of a double-ended actuator, m².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub area_m2: Option<f64>,
    /// Cap-side piston area of a single-ended actuator, m².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cap_side_area_m2: Option<f64>,
    /// Rod-side annulus area of a single-ended actuator, m².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rod_side_area_m2: Option<f64>,
    /// Each chamber's volume at mid-stroke, lines included, m³: one number, or `[cap, rod]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chamber_volume_m3: Option<ChamberVolumes>,
    /// Cross-port leakage, m³/s per Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leakage_m3_s_per_pa: Option<f64>,
}

/// `chamber_volume_m3`: one volume for both chambers, or `[cap, rod]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum ChamberVolumes {
    /// Both chambers alike.
    Both(f64),
    /// `[cap, rod]`.
    Each([f64; 2]),
}

/// By hand rather than `untagged`, so that a wrong value says what was expected (serde's
/// untagged enums only say that no variant matched).
impl<'de> Deserialize<'de> for ChamberVolumes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Volumes;
        impl<'de> serde::de::Visitor<'de> for Volumes {
            type Value = ChamberVolumes;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a volume in m³ for both chambers, or [cap, rod]")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(ChamberVolumes::Both(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(ChamberVolumes::Both(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(ChamberVolumes::Both(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Self::Value, A::Error> {
                use serde::de::Error;
                let mut each = [0.0; 2];
                for (i, slot) in each.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(i, &"[cap, rod]: two volumes"))?;
                }
                if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                    return Err(A::Error::invalid_length(3, &"[cap, rod]: two volumes"));
                }
                Ok(ChamberVolumes::Each(each))
            }
        }
        d.deserialize_any(Volumes)
    }
}

/// `table_system.servo_valve`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ServoValveSpec {
    /// Valves per actuator.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    /// Rated flow of one valve, m³/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rated_flow_m3_s: Option<f64>,
    /// Total pressure drop of the rating, Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rated_pressure_drop_pa: Option<f64>,
    /// Spool natural frequency, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub natural_frequency_hz: Option<f64>,
    /// Spool damping ratio.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
    /// Pure delay, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay_s: Option<f64>,
}

/// `table_system.accumulator`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AccumulatorSpec {
    /// Gas precharge pressure, Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub precharge_pressure_pa: Option<f64>,
    /// Gas volume of the bank at precharge, m³.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_m3: Option<f64>,
    /// Polytropic exponent of the gas.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polytropic_exponent: Option<f64>,
    /// Largest pump flow, m³/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pump_flow_m3_s: Option<f64>,
}

/// `table_system.controller` (absent gains are 0).
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ControllerSpec {
    /// Sample rate, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_rate_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displacement_gain_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integral_gain_per_m_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_feedforward_s_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceleration_feedforward_s2_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_feedback_s_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceleration_feedback_s2_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_p_gain_per_pa: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_p_highpass_hz: Option<f64>,
}

/// Values laid over a base's: a value given here wins, the base's fills what is absent;
/// objects are laid over field by field.
pub(crate) trait Overlay {
    /// `self` laid over `base`.
    fn overlay(self, base: Self) -> Self;
}

/// Values that replace the base's whole.
macro_rules! replaces {
    ($($t:ty),*) => {$(
        impl Overlay for $t {
            fn overlay(self, _base: Self) -> Self {
                self
            }
        }
    )*};
}
replaces!(f64, u32, String, ChamberVolumes);

impl<T: Overlay> Overlay for Option<T> {
    fn overlay(self, base: Self) -> Self {
        match (self, base) {
            (Some(given), Some(base)) => Some(given.overlay(base)),
            (given, base) => given.or(base),
        }
    }
}

/// Objects laid over field by field.
macro_rules! field_by_field {
    ($($t:ident { $($f:ident),* })*) => {$(
        impl Overlay for $t {
            fn overlay(self, base: Self) -> Self {
                $t { $($f: self.$f.overlay(base.$f)),* }
            }
        }
    )*};
}
field_by_field! {
    ServoValveSpec { count, rated_flow_m3_s, rated_pressure_drop_pa, natural_frequency_hz,
                     damping_ratio, delay_s }
    AccumulatorSpec { precharge_pressure_pa, volume_m3, polytropic_exponent, pump_flow_m3_s }
    ControllerSpec { sample_rate_hz, displacement_gain_per_m, integral_gain_per_m_s,
                     velocity_feedforward_s_per_m, acceleration_feedforward_s2_per_m,
                     velocity_feedback_s_per_m, acceleration_feedback_s2_per_m,
                     delta_p_gain_per_pa, delta_p_highpass_hz }
}

impl Overlay for ActuatorSpec {
    /// Field by field, but a double-ended `area_m2` given replaces the base's two areas (and
    /// a side's area given, the base's `area_m2`).
    fn overlay(self, base: Self) -> Self {
        let base = if self.area_m2.is_some() {
            ActuatorSpec {
                cap_side_area_m2: None,
                rod_side_area_m2: None,
                ..base
            }
        } else if self.cap_side_area_m2.is_some() || self.rod_side_area_m2.is_some() {
            ActuatorSpec {
                area_m2: None,
                ..base
            }
        } else {
            base
        };
        ActuatorSpec {
            count: self.count.overlay(base.count),
            area_m2: self.area_m2.overlay(base.area_m2),
            cap_side_area_m2: self.cap_side_area_m2.overlay(base.cap_side_area_m2),
            rod_side_area_m2: self.rod_side_area_m2.overlay(base.rod_side_area_m2),
            chamber_volume_m3: self.chamber_volume_m3.overlay(base.chamber_volume_m3),
            leakage_m3_s_per_pa: self.leakage_m3_s_per_pa.overlay(base.leakage_m3_s_per_pa),
        }
    }
}

impl Overlay for TableSystemSpec {
    /// Field by field, but an `accumulator` given as `null` (a constant supply) replaces the
    /// base's bank.
    fn overlay(self, base: Self) -> Self {
        TableSystemSpec {
            preset: self.preset.overlay(base.preset),
            actuator: self.actuator.overlay(base.actuator),
            servo_valve: self.servo_valve.overlay(base.servo_valve),
            oil_bulk_modulus_pa: self.oil_bulk_modulus_pa.overlay(base.oil_bulk_modulus_pa),
            supply_pressure_pa: self.supply_pressure_pa.overlay(base.supply_pressure_pa),
            return_pressure_pa: self.return_pressure_pa.overlay(base.return_pressure_pa),
            accumulator: match (self.accumulator, base.accumulator) {
                (Some(Some(given)), Some(Some(bank))) => Some(Some(given.overlay(bank))),
                (None, base) => base,
                (given, _) => given,
            },
            controller: self.controller.overlay(base.controller),
        }
    }
}

impl From<&TableSystem> for TableSystemSpec {
    /// The system as the scenario format writes it, every value given (single-ended areas,
    /// `[cap, rod]` volumes, `"accumulator": null` for a constant supply), no preset.
    fn from(sys: &TableSystem) -> Self {
        let (a, v, c) = (sys.actuator(), sys.servo_valve(), sys.controller());
        TableSystemSpec {
            preset: None,
            actuator: Some(ActuatorSpec {
                count: Some(a.count),
                area_m2: None,
                cap_side_area_m2: Some(a.cap_area_m2),
                rod_side_area_m2: Some(a.rod_area_m2),
                chamber_volume_m3: Some(ChamberVolumes::Each([a.cap_volume_m3, a.rod_volume_m3])),
                leakage_m3_s_per_pa: Some(a.leakage_m3_s_per_pa),
            }),
            servo_valve: Some(ServoValveSpec {
                count: Some(v.count),
                rated_flow_m3_s: Some(v.rated_flow_m3_s),
                rated_pressure_drop_pa: Some(v.rated_pressure_drop_pa),
                natural_frequency_hz: Some(v.natural_frequency_hz),
                damping_ratio: Some(v.damping_ratio),
                delay_s: Some(v.delay_s),
            }),
            oil_bulk_modulus_pa: Some(sys.oil_bulk_modulus_pa()),
            supply_pressure_pa: Some(sys.supply_pressure_pa()),
            return_pressure_pa: Some(sys.return_pressure_pa()),
            accumulator: Some(match sys.supply() {
                Supply::Constant => None,
                Supply::Accumulator(acc) => Some(AccumulatorSpec {
                    precharge_pressure_pa: Some(acc.precharge_pressure_pa),
                    volume_m3: Some(acc.volume_m3),
                    polytropic_exponent: Some(acc.polytropic_exponent),
                    pump_flow_m3_s: Some(acc.pump_flow_m3_s),
                }),
            }),
            controller: Some(ControllerSpec {
                sample_rate_hz: Some(c.sample_rate_hz),
                displacement_gain_per_m: Some(c.displacement_gain_per_m),
                integral_gain_per_m_s: Some(c.integral_gain_per_m_s),
                velocity_feedforward_s_per_m: Some(c.velocity_feedforward_s_per_m),
                acceleration_feedforward_s2_per_m: Some(c.acceleration_feedforward_s2_per_m),
                velocity_feedback_s_per_m: Some(c.velocity_feedback_s_per_m),
                acceleration_feedback_s2_per_m: Some(c.acceleration_feedback_s2_per_m),
                delta_p_gain_per_pa: Some(c.delta_p_gain_per_pa),
                delta_p_highpass_hz: Some(c.delta_p_highpass_hz),
            }),
        }
    }
}
