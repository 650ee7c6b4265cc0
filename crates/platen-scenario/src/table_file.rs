//! The `table` key of a scenario file as written (serde types with `deny_unknown_fields`);
//! [`crate::multi_axis`] validates it.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::system_file::{AccumulatorSpec, ControllerSpec, Overlay, ServoValveSpec};

/// `table.platen`: the rigid platen.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlatenSpec {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Inertia tensor about the centre of mass, platen axes, kg·m² (3 × 3, symmetric).
    pub inertia_kg_m2: [[f64; 3]; 3],
    /// Centre of mass from the reference point, platen frame, m.
    pub centre_of_mass_m: [f64; 3],
}

/// `table.actuators[i].pad`: a bearing actuator's pad.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PadSpec {
    /// The actuator's axis, table axes (default `[0, 0, 1]`; normalised).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    /// Where the axis meets the platen's underside at neutral, table axes, m.
    pub contact_m: [f64; 3],
    /// Coulomb friction coefficient of the platen sliding over the pad.
    pub friction_coefficient: f64,
}

/// `table.actuators[i]`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// Its name (output columns `{name}_stroke_m`, `{name}_force_n`).
    pub name: String,
    /// Base point on the reaction mass, table axes, m.
    pub base_m: [f64; 3],
    /// Platen point of a swivel-mounted actuator, platen frame, m (or `pad`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub platen_m: Option<[f64; 3]>,
    /// The pad of a bearing actuator (or `platen_m`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pad: Option<PadSpec>,
    /// Cap-side piston area, m².
    pub cap_side_area_m2: f64,
    /// Rod-side piston area, m² (0: single-acting).
    pub rod_side_area_m2: f64,
    /// Oil volume of each chamber at neutral, lines included, m³.
    pub chamber_volume_m3: f64,
    /// Reach from neutral either way, m.
    pub stroke_m: f64,
    /// Leakage, m³/s per Pa: across the piston, or to return for a single-acting actuator
    /// (default 0; the closed loop's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leakage_m3_s_per_pa: Option<f64>,
    /// Its servo-valves, as `table_system.servo_valve` (the closed loop's: every actuator
    /// needs them when the table has a `controller`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub servo_valve: Option<ServoValveSpec>,
}

/// `table.hold_down_struts[j]`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StrutSpec {
    /// Its name (output column `{name}_force_n`).
    pub name: String,
    /// Base point, table axes, m.
    pub base_m: [f64; 3],
    /// Platen point, platen frame, m.
    pub platen_m: [f64; 3],
    /// Piston area, m².
    pub area_m2: f64,
    /// Gas pressure at neutral, Pa.
    pub pressure_pa: f64,
    /// Gas volume at neutral, m³.
    pub gas_volume_m3: f64,
    /// Polytropic exponent (1 to 2; 1.4 adiabatic nitrogen).
    pub polytropic_exponent: f64,
}

/// `table.bearings[k]`: a contact that is not a bearing actuator's pad.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    /// The contact point, platen frame, m.
    pub platen_m: [f64; 3],
    /// Coulomb friction coefficient.
    pub friction_coefficient: f64,
    /// The swivel-mounted vertical actuator under it (or `normal_force_n`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub actuator: Option<String>,
    /// Its constant normal force, N (a passive bearing; or `actuator`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal_force_n: Option<f64>,
}

/// `table`: a multi-axis table.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    /// A preset to lay these values over (`lhpost6`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// The rigid platen.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub platen: Option<PlatenSpec>,
    /// The actuators.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub actuators: Vec<ActuatorSpec>,
    /// The nitrogen hold-down struts.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hold_down_struts: Vec<StrutSpec>,
    /// Bearings that are not actuator pads.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bearings: Vec<BearingSpec>,
    /// DOFs held at zero by ideal constraints (`x`, `y`, `z`, `roll`, `pitch`, `yaw`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_dofs: Vec<String>,
    /// Oil bulk modulus, Pa (default 1.5 GPa).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oil_bulk_modulus_pa: Option<f64>,
    /// Supply pressure, Pa (default 20.7 MPa): the actuators' force limits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub supply_pressure_pa: Option<f64>,
    /// Return pressure, Pa (default 0.5 MPa).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub return_pressure_pa: Option<f64>,
    /// The supply's accumulator bank, as `table_system.accumulator` (absent: a constant
    /// supply pressure).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accumulator: Option<AccumulatorSpec>,
    /// The DOF controller: with it a motion excitation is the command of a closed loop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller: Option<TableControllerSpec>,
    /// The table's limits per axis, reported against in the summaries.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<AxisLimitsSpec>,
}

/// `table.controller`: DOF control with force balance.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableControllerSpec {
    /// Sample rate of every DOF's loop, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_rate_hz: Option<f64>,
    /// Per DOF its gains (the keys of `table_system.controller` but its rate; for a rotation
    /// the same keys are per rad). A free DOF without gains is refused.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dof: Option<DofGainsSpec>,
    /// Force-balance gain: drive per N of the actuator forces' null-space part (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_balance_gain: Option<f64>,
}

/// `table.controller.dof`: gains per DOF.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct DofGainsSpec {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<ControllerSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y: Option<ControllerSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<ControllerSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roll: Option<ControllerSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pitch: Option<ControllerSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw: Option<ControllerSpec>,
}

impl DofGainsSpec {
    /// The gains of each DOF, x … yaw.
    pub fn each(&self) -> [Option<&ControllerSpec>; 6] {
        [
            self.x.as_ref(),
            self.y.as_ref(),
            self.z.as_ref(),
            self.roll.as_ref(),
            self.pitch.as_ref(),
            self.yaw.as_ref(),
        ]
    }
}

/// The limits of one translation.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TranslationLimitSpec {
    /// Stroke, ± m from neutral.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stroke_m: Option<f64>,
    /// Peak velocity, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_m_s: Option<f64>,
    /// Peak acceleration, m/s².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceleration_m_s2: Option<f64>,
}

/// The limits of one rotation.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RotationLimitSpec {
    /// Angle, ± rad from neutral.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle_rad: Option<f64>,
    /// Peak rate, rad/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_rad_s: Option<f64>,
    /// Peak angular acceleration, rad/s².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceleration_rad_s2: Option<f64>,
}

/// `table.limits`: per axis, and the overturning moment.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct AxisLimitsSpec {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<TranslationLimitSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y: Option<TranslationLimitSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<TranslationLimitSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roll: Option<RotationLimitSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pitch: Option<RotationLimitSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw: Option<RotationLimitSpec>,
    /// The largest overturning moment (about a horizontal axis through the reference point)
    /// the table takes from a specimen, N·m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overturning_moment_n_m: Option<f64>,
}

impl AxisLimitsSpec {
    /// Per DOF (x … yaw) its limits `[displacement, rate, acceleration]` (m or rad, …),
    /// `None` where not given.
    pub fn each(&self) -> [[Option<f64>; 3]; 6] {
        let t = |l: &Option<TranslationLimitSpec>| {
            l.as_ref().map_or([None; 3], |l| {
                [l.stroke_m, l.velocity_m_s, l.acceleration_m_s2]
            })
        };
        let r = |l: &Option<RotationLimitSpec>| {
            l.as_ref().map_or([None; 3], |l| {
                [l.angle_rad, l.rate_rad_s, l.acceleration_rad_s2]
            })
        };
        [
            t(&self.x),
            t(&self.y),
            t(&self.z),
            r(&self.roll),
            r(&self.pitch),
            r(&self.yaw),
        ]
    }
}

/// Given values win; a given list replaces the preset's whole (actuators are not merged by
/// name: a table's geometry is one thing); objects are laid over field by field.
impl Overlay for TableSpec {
    fn overlay(self, base: Self) -> Self {
        fn list<T>(given: Vec<T>, base: Vec<T>) -> Vec<T> {
            if given.is_empty() {
                base
            } else {
                given
            }
        }
        TableSpec {
            preset: None,
            platen: self.platen.or(base.platen),
            actuators: list(self.actuators, base.actuators),
            hold_down_struts: list(self.hold_down_struts, base.hold_down_struts),
            bearings: list(self.bearings, base.bearings),
            held_dofs: list(self.held_dofs, base.held_dofs),
            oil_bulk_modulus_pa: self.oil_bulk_modulus_pa.or(base.oil_bulk_modulus_pa),
            supply_pressure_pa: self.supply_pressure_pa.or(base.supply_pressure_pa),
            return_pressure_pa: self.return_pressure_pa.or(base.return_pressure_pa),
            accumulator: self.accumulator.overlay(base.accumulator),
            controller: self.controller.overlay(base.controller),
            limits: self.limits.overlay(base.limits),
        }
    }
}

impl Overlay for TableControllerSpec {
    fn overlay(self, base: Self) -> Self {
        TableControllerSpec {
            sample_rate_hz: self.sample_rate_hz.or(base.sample_rate_hz),
            dof: self.dof.overlay(base.dof),
            force_balance_gain: self.force_balance_gain.or(base.force_balance_gain),
        }
    }
}

impl Overlay for DofGainsSpec {
    fn overlay(self, base: Self) -> Self {
        DofGainsSpec {
            x: self.x.overlay(base.x),
            y: self.y.overlay(base.y),
            z: self.z.overlay(base.z),
            roll: self.roll.overlay(base.roll),
            pitch: self.pitch.overlay(base.pitch),
            yaw: self.yaw.overlay(base.yaw),
        }
    }
}

impl Overlay for TranslationLimitSpec {
    fn overlay(self, base: Self) -> Self {
        TranslationLimitSpec {
            stroke_m: self.stroke_m.or(base.stroke_m),
            velocity_m_s: self.velocity_m_s.or(base.velocity_m_s),
            acceleration_m_s2: self.acceleration_m_s2.or(base.acceleration_m_s2),
        }
    }
}

impl Overlay for RotationLimitSpec {
    fn overlay(self, base: Self) -> Self {
        RotationLimitSpec {
            angle_rad: self.angle_rad.or(base.angle_rad),
            rate_rad_s: self.rate_rad_s.or(base.rate_rad_s),
            acceleration_rad_s2: self.acceleration_rad_s2.or(base.acceleration_rad_s2),
        }
    }
}

impl Overlay for AxisLimitsSpec {
    fn overlay(self, base: Self) -> Self {
        AxisLimitsSpec {
            x: self.x.overlay(base.x),
            y: self.y.overlay(base.y),
            z: self.z.overlay(base.z),
            roll: self.roll.overlay(base.roll),
            pitch: self.pitch.overlay(base.pitch),
            yaw: self.yaw.overlay(base.yaw),
            overturning_moment_n_m: self.overturning_moment_n_m.or(base.overturning_moment_n_m),
        }
    }
}
