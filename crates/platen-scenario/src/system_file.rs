//! The `table_system` object as written in a scenario file (its format: [`crate::system`]).
//! [`crate::file`] reads it and [`crate::system`] builds the loop from it; this module uses
//! neither, so neither imports the other back.

use schemars::JsonSchema;
use serde::{Deserialize, Deserializer, Serialize};

/// `table_system`, as written.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableSystemSpec {
    /// A named system (`lhpost-2008`) that the other values are laid over.
    pub preset: Option<String>,
    /// The actuators.
    pub actuator: Option<ActuatorSpec>,
    /// The servo-valves of each actuator.
    pub servo_valve: Option<ServoValveSpec>,
    /// Effective bulk modulus of the oil, Pa.
    pub oil_bulk_modulus_pa: Option<f64>,
    /// Supply pressure (absolute), Pa.
    pub supply_pressure_pa: Option<f64>,
    /// Return pressure (absolute), Pa.
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
    pub controller: Option<ControllerSpec>,
}

/// A key given as `null` is `Some(None)`, an absent one `None`.
fn present<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Option<Option<T>>, D::Error> {
    Option::<T>::deserialize(d).map(Some)
}

/// `table_system.actuator`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// Number of actuators acting together.
    pub count: Option<u32>,
    /// Piston area of a double-ended actuator, m².
    pub area_m2: Option<f64>,
    /// Cap-side piston area of a single-ended actuator, m².
    pub cap_side_area_m2: Option<f64>,
    /// Rod-side annulus area of a single-ended actuator, m².
    pub rod_side_area_m2: Option<f64>,
    /// Each chamber's volume at mid-stroke, lines included, m³: one number, or `[cap, rod]`.
    pub chamber_volume_m3: Option<ChamberVolumes>,
    /// Cross-port leakage, m³/s per Pa.
    pub leakage_m3_s_per_pa: Option<f64>,
}

/// `chamber_volume_m3`: one volume for both chambers, or `[cap, rod]`.
#[derive(Debug, Clone, Copy, Serialize, JsonSchema)]
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
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ServoValveSpec {
    /// Valves per actuator.
    pub count: Option<u32>,
    /// Rated flow of one valve, m³/s.
    pub rated_flow_m3_s: Option<f64>,
    /// Total pressure drop of the rating, Pa.
    pub rated_pressure_drop_pa: Option<f64>,
    /// Spool natural frequency, Hz.
    pub natural_frequency_hz: Option<f64>,
    /// Spool damping ratio.
    pub damping_ratio: Option<f64>,
    /// Pure delay, s.
    pub delay_s: Option<f64>,
}

/// `table_system.accumulator`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AccumulatorSpec {
    /// Gas precharge pressure, Pa.
    pub precharge_pressure_pa: Option<f64>,
    /// Gas volume of the bank at precharge, m³.
    pub volume_m3: Option<f64>,
    /// Polytropic exponent of the gas.
    pub polytropic_exponent: Option<f64>,
    /// Largest pump flow, m³/s.
    pub pump_flow_m3_s: Option<f64>,
}

/// `table_system.controller` (absent gains are 0).
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ControllerSpec {
    /// Sample rate, Hz.
    pub sample_rate_hz: Option<f64>,
    pub displacement_gain_per_m: Option<f64>,
    pub integral_gain_per_m_s: Option<f64>,
    pub velocity_feedforward_s_per_m: Option<f64>,
    pub acceleration_feedforward_s2_per_m: Option<f64>,
    pub velocity_feedback_s_per_m: Option<f64>,
    pub acceleration_feedback_s2_per_m: Option<f64>,
    pub delta_p_gain_per_pa: Option<f64>,
    pub delta_p_highpass_hz: Option<f64>,
}
