//! The `table` key of a scenario file as written (serde types with `deny_unknown_fields`);
//! [`crate::multi_axis`] validates it.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

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
    /// Leakage, m³/s per Pa (the closed loop's, not yet run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leakage_m3_s_per_pa: Option<f64>,
    /// Its servo-valve, as `table_system`'s (the closed loop's, not yet run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub servo_valve: Option<serde_json::Value>,
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
    /// A preset to lay these values over (`lhpost6`: not yet shipped).
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
    /// The supply's accumulator (the closed loop's, not yet run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accumulator: Option<serde_json::Value>,
    /// The DOF controller (the closed loop's, not yet run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller: Option<serde_json::Value>,
}
