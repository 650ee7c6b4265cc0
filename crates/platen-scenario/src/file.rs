//! The scenario file as written: serde types with `deny_unknown_fields`, before validation
//! (see [`crate::scenario`] for the format and [`crate::PlatenScenario`] for the validated type).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use platen_io::columns::ColumnSpec;
use platen_io::json::parse_json;

use crate::error::Result;

/// The scenario file as written (after JSON parsing, before validation), and as a program
/// writes one (serialised, absent values are not written).
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// The JSON Schema this file follows (ignored; lets editors find `platen schema`'s output).
    #[serde(rename = "$schema")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    /// A short name for reports (default: the file stem).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Free text.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The model of the uniaxial platen (required without a `table`; absent with one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelSpec>,
    /// The excitation.
    pub excitation: ExcitationSpec,
    /// The integrator (forward runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<IntegratorSpec>,
    /// The initial state (forward runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialSpec>,
    /// Simulated duration, s (default: the record's span).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    /// The table's limits, laid over the preset's (default: the preset's; the LHPOST's are
    /// ±0.75 m, 1.8 m/s, 4.2 g, 6.8 MN).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<LimitsSpec>,
    /// A specimen on the platen: a shear building, bottom storey first.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub specimen: Option<SpecimenSpec>,
    /// The loop around the platen (controller, valves, actuators, supply): with one, a motion
    /// excitation is the displacement command of a closed-loop forward run
    /// ([`crate::system`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table_system: Option<crate::system_file::TableSystemSpec>,
    /// A multi-axis (six-DOF) table instead of the uniaxial platen of `model`
    /// ([`crate::multi_axis`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table: Option<crate::table_file::TableSpec>,
}

/// `specimen`: a linear shear building fixed on the platen (`storeys`), or, on a multi-axis
/// `table`, a general linear specimen (the four matrices).
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpecimenSpec {
    /// The storeys, bottom first (1 to 12).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub storeys: Vec<StoreySpec>,
    /// Mass matrix, n × n, SI units per DOF (kg or kg·m²), DOFs relative to the platen.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_matrix: Option<Vec<Vec<f64>>>,
    /// Stiffness matrix, n × n (N/m or N·m/rad per DOF).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness_matrix: Option<Vec<Vec<f64>>>,
    /// Damping matrix, n × n (N·s/m or N·m·s/rad per DOF).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_matrix: Option<Vec<Vec<f64>>>,
    /// Influence matrix, n rows of six numbers: each DOF's rigid-body share of the platen's
    /// x, y, z, roll, pitch, yaw.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub influence: Option<Vec<Vec<f64>>>,
}

impl SpecimenSpec {
    /// Whether it is the general linear form (any of the four matrices given).
    pub fn is_general(&self) -> bool {
        self.mass_matrix.is_some()
            || self.stiffness_matrix.is_some()
            || self.damping_matrix.is_some()
            || self.influence.is_some()
    }
}

/// One storey of `specimen.storeys`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StoreySpec {
    /// Floor mass, kg (> 0).
    pub mass_kg: f64,
    /// Storey stiffness, N/m (> 0).
    pub stiffness_n_per_m: f64,
    /// Storey viscous damping, N·s/m (≥ 0).
    pub damping_n_s_per_m: f64,
    /// How the storey yields (absent: linear). The stiffness above is the elastic one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hysteresis: Option<HysteresisSpec>,
    /// Storey height, m (> 0; optional): the summary then gives drift ratios.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_m: Option<f64>,
}

/// A storey's hysteresis (`specimen.storeys[i].hysteresis`): one law, by its name.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum HysteresisSpec {
    /// Bilinear with kinematic hardening, exact about yield and unloading.
    Bilinear(BilinearSpec),
    /// Bouc–Wen, smooth.
    BoucWen(BoucWenSpec),
}

/// `hysteresis.bilinear`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BilinearSpec {
    /// Yield force, N (> 0).
    pub yield_force_n: f64,
    /// Post-yield stiffness over the elastic stiffness, in [0, 1) (default 0: elastic-perfectly
    /// plastic).
    #[serde(default)]
    pub post_yield_stiffness_ratio: f64,
}

/// `hysteresis.bouc_wen`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoucWenSpec {
    /// Yield force, N (> 0).
    pub yield_force_n: f64,
    /// Post-yield stiffness over the elastic stiffness, in [0, 1) (default 0).
    #[serde(default)]
    pub post_yield_stiffness_ratio: f64,
    /// The exponent n, in [1, 64] (default 2; larger is sharper).
    #[serde(default = "default_bouc_wen_exponent")]
    pub exponent: f64,
    /// β/(β + γ), in [0, 1] (default 0.5).
    #[serde(default = "default_beta_share")]
    pub beta_share: f64,
}

fn default_bouc_wen_exponent() -> f64 {
    2.0
}

fn default_beta_share() -> f64 {
    0.5
}

/// `limits`: any of the table's four limits, each a number > 0 in SI units; a limit not given
/// is the preset's.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// Displacement stroke, ±m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stroke_m: Option<f64>,
    /// Peak velocity, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_m_s: Option<f64>,
    /// Peak acceleration, m/s².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceleration_m_s2: Option<f64>,
    /// Horizontal actuator force capacity, N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_n: Option<f64>,
}

/// `model`: a preset, its hold-down pressure, and the form with overrides.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Preset name (`lhpost-2008`).
    pub preset: String,
    /// Hold-down nitrogen pressure, MPa (default: the preset's nominal 13.8 MPa).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hold_down_pressure_mpa: Option<f64>,
    /// Identified-model values laid over the preset's (Eq. 22/23).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identified: Option<IdentifiedOverrides>,
    /// Selects the full Lagrangian model; physical values laid over the preset's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub full: Option<PhysicalOverrides>,
}

/// Overrides of the identified model; the contract's keys.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct IdentifiedOverrides {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effective_mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness_n_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coulomb_force_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub viscous_coefficient: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub viscous_exponent: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub low_velocity_force_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub low_velocity_decay_s_per_m: Option<f64>,
}

/// Overrides of the physical parameters of the full model (see
/// [`platen_model::PhysicalParams`] for meanings and units). The hold-down pressure is set by
/// `model.hold_down_pressure_mpa`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct PhysicalOverrides {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub platen_mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub actuator_moving_mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_piston_mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_cylinder_mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_height_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_piston_length_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_area_m2: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gas_heat_capacity_ratio: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub supported_weight_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_friction_coefficient: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lateral_friction_coefficient: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lateral_normal_force_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hinge_swivel_friction_coefficient: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hinge_radius_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hinge_force_distribution_factor: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub viscous_coefficient: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub viscous_exponent: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_viscous_coefficient: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strut_viscous_exponent: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub low_velocity_force_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub low_velocity_decay_s_per_m: Option<f64>,
}

/// `excitation`: exactly one source.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExcitationSpec {
    /// Recorded actuator force (`t_s`, `force_n`): forward run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_csv: Option<PathBuf>,
    /// Prescribed motion (`t_s`, `u_m`, optional `v_m_s`, `a_m_s2`): inverse run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion_csv: Option<PathBuf>,
    /// Generated sine force: forward run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sine_force: Option<SineForce>,
    /// Generated sine displacement (the paper's S tests): inverse run, or the command of a
    /// closed loop. With a multi-axis `table`, per axis: `{"x": {…}, "z": {…}}`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sine_motion: Option<PerAxisOr<SineMotion>>,
    /// Generated triangle displacement with rounded reversals (the paper's T tests): inverse
    /// run, or a closed loop's command; per axis with a multi-axis `table`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub triangle_motion: Option<PerAxisOr<TriangleMotion>>,
    /// Generated band-limited white-noise motion (the paper's WN tests): inverse run, or a
    /// closed loop's command; per axis with a multi-axis `table` (give each axis its own
    /// `seed` for uncorrelated axes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub white_noise_motion: Option<PerAxisOr<WhiteNoiseMotion>>,
    /// Table motion from a ground-acceleration record (an earthquake test): inverse run, or
    /// the command of a closed loop. With a multi-axis `table`, per axis:
    /// `{"x": {…}, "y": {…}, "z": {…}}` (the components of one station).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_motion: Option<GroundMotionSpec>,
    /// Zero-phase low-pass of a force excitation before it drives the model, Hz (the paper
    /// low-passed the SR9 force at 0.6 Hz). Forward runs only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lowpass_hz: Option<f64>,
    /// The filter of `lowpass_hz` (default `brickwall`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lowpass_filter: Option<LowpassFilter>,
    /// Velocity dead band of an inverse run, m/s (default: none, only `v = 0` is at rest):
    /// where `|v|` is at most this the platen counts as at rest, and the friction is the
    /// static reaction that balances the inertial and elastic forces within `±F_s` instead of
    /// flipping with the sign of a noisy measured velocity
    /// ([`platen_integrate::inverse`]). Motion excitations only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rest_velocity_m_s: Option<f64>,
    /// A lab's own channel names and units for `force_csv` / `motion_csv`
    /// (see [`crate::columns`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<BTreeMap<String, ColumnSpec>>,
}

/// Zero-phase low-pass filters for `lowpass_hz`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum LowpassFilter {
    /// Frequency-domain brick wall: unit gain and zero phase below the cut-off, nothing above.
    /// Exact for a record holding whole periods of a periodic test; on other records the
    /// wrap-around from the last sample to the first leaks near the ends.
    Brickwall,
    /// Windowed-sinc FIR of order 1024 (Hamming), zero phase: gain 1 ± 0.5 % in the pass
    /// band, 0.5 at the cut-off (the transition is about 3.3·fs/1024 wide).
    Fir,
    /// 4th-order Butterworth run forward and backward: gain |H(f)|², 0.5 at the cut-off (so
    /// NOT unit gain near it: 0.81 at 5/6 of the cut-off).
    Butterworth,
}

/// A table motion that reproduces a ground-acceleration record as PEER integrates it: the
/// PEER `.AT2` record (or a CSV) is scaled, taken as straight lines between its samples (which
/// cannot overshoot them), baseline-corrected if asked, and integrated exactly to the table
/// velocity and displacement from rest, sampled at `sample_rate_hz`
/// ([`platen_signal::AccelerogramMotion`]). With the default `baseline` (`none`) the velocity
/// and displacement at the record's own sample times are PEER's `.VT2` and `.DT2`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GroundMotion {
    /// The record's file name: looked up next to the scenario, then in the folder named by
    /// `PLATEN_RECORDS_DIR`.
    pub record: PathBuf,
    /// Scale factor on the acceleration (default 1: "100 %").
    #[serde(default = "default_scale")]
    pub scale: f64,
    /// Sample rate of the table motion, Hz (default 1024).
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
    /// Baseline correction before integrating: `none` (default: a PEER-processed record is
    /// already corrected, and integrating it as it is reproduces its `.VT2`/`.DT2`),
    /// `acceleration` (remove the least-squares polynomial of `baseline_order` from the
    /// acceleration: order 0 removes a bias, for a raw record) or `velocity` (remove it from
    /// the velocity, its derivative from the acceleration and its integral from the
    /// displacement).
    #[serde(
        default = "default_baseline",
        skip_serializing_if = "BaselineKind::is_none",
        serialize_with = "BaselineKind::write"
    )]
    pub baseline: BaselineKind,
    /// Polynomial order of the baseline correction (default 0, at most 8).
    #[serde(default)]
    pub baseline_order: usize,
    /// For a record given as CSV (a `.csv` file): the time and acceleration columns' names and
    /// units, e.g. `{"t_s": {"name": "time"}, "a_m_s2": {"name": "acc (g)", "unit": "g"}}`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<BTreeMap<String, ColumnSpec>>,
}

/// `excitation.ground_motion`: one record (the uniaxial table's axis), or one per axis of a
/// multi-axis table.
pub type GroundMotionSpec = PerAxisOr<GroundMotion>;

/// `excitation.ground_motion` per axis: the components of one station.
pub type AxisGroundMotion = Axes<GroundMotion>;

/// An excitation source given once (the uniaxial table's axis), or once per translational
/// axis of a multi-axis table: `{"x": {…}, "y": {…}, "z": {…}}` (any of them; absent axes are
/// held at zero). Rotations are commanded by a six-DOF `motion_csv`.
#[derive(Debug, Clone, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum PerAxisOr<T> {
    /// One source.
    Single(T),
    /// One source per axis (any of x, y, z).
    PerAxis(Axes<T>),
}

/// One source per translational axis of a multi-axis table.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Axes<T> {
    /// Along x (the table's longitudinal axis).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<T>,
    /// Along y.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y: Option<T>,
    /// Vertical.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<T>,
}

impl<T> Axes<T> {
    /// The sources along x, y, z.
    pub fn each(&self) -> [(&'static str, Option<&T>); 3] {
        [
            ("x", self.x.as_ref()),
            ("y", self.y.as_ref()),
            ("z", self.z.as_ref()),
        ]
    }
}

impl<'de, T: serde::de::DeserializeOwned> Deserialize<'de> for PerAxisOr<T> {
    /// An object with an axis among its keys (`x`, `y`, `z`) is per axis, any other one
    /// source (no source has a field of those names), so that a typo in either is reported
    /// by the shape it was meant for.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error;
        let value = serde_json::Value::deserialize(d)?;
        let per_axis = value
            .as_object()
            .is_some_and(|o| o.keys().any(|k| matches!(k.as_str(), "x" | "y" | "z")));
        if per_axis {
            serde_json::from_value(value)
                .map(PerAxisOr::PerAxis)
                .map_err(|e| {
                    let rotations = ["roll", "pitch", "yaw"]
                        .iter()
                        .any(|r| e.to_string().contains(&format!("`{r}`")));
                    let hint = if rotations {
                        " (rotations are commanded by a six-DOF motion_csv)"
                    } else {
                        ""
                    };
                    D::Error::custom(format!("per axis: {e}{hint}"))
                })
        } else {
            serde_json::from_value(value)
                .map(PerAxisOr::Single)
                .map_err(D::Error::custom)
        }
    }
}

impl<T> PerAxisOr<T> {
    /// The one source, if it is not per axis.
    pub fn single(&self) -> Option<&T> {
        match self {
            PerAxisOr::Single(g) => Some(g),
            PerAxisOr::PerAxis(_) => None,
        }
    }

    /// The sources per axis, if given per axis.
    pub fn per_axis(&self) -> Option<&Axes<T>> {
        match self {
            PerAxisOr::Single(_) => None,
            PerAxisOr::PerAxis(axes) => Some(axes),
        }
    }
}

/// Baseline correction of a ground-motion record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum BaselineKind {
    /// None.
    None,
    /// Remove a polynomial from the acceleration.
    Acceleration,
    /// Remove a polynomial from the velocity.
    Velocity,
}

impl BaselineKind {
    /// Whether this is [`BaselineKind::None`] (the default, not written).
    fn is_none(&self) -> bool {
        *self == BaselineKind::None
    }

    /// Writes the kind by its name in the file.
    fn write<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(match self {
            BaselineKind::None => "none",
            BaselineKind::Acceleration => "acceleration",
            BaselineKind::Velocity => "velocity",
        })
    }
}

fn default_scale() -> f64 {
    1.0
}

fn default_baseline() -> BaselineKind {
    BaselineKind::None
}

/// `F(t) = r(t)·amplitude_n·sin(2π·frequency_hz·t)`, with `r` a linear ramp from 0 to 1 over
/// `ramp_s` (0: none), sampled at `sample_rate_hz` from `t = 0`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SineForce {
    /// Force amplitude, N.
    pub amplitude_n: f64,
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Sample rate, Hz (default 1024, the LHPOST data acquisition rate).
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
    /// Length of the initial amplitude ramp, s (default 0).
    #[serde(default)]
    pub ramp_s: f64,
}

/// `u(t) = amplitude_m·sin(2π·frequency_hz·t)` with its exact velocity and acceleration,
/// sampled at `sample_rate_hz` from `t = 0` (the paper's S tests).
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SineMotion {
    /// Displacement amplitude, m.
    pub amplitude_m: f64,
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Sample rate, Hz (default 1024).
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
}

/// A triangle displacement wave with constant-acceleration rounded reversals
/// ([`crate::generate::triangle_motion`]): peak `amplitude_m`, constant velocity
/// `velocity_m_s`, reversal arcs at `reversal_acceleration_m_s2`; period
/// `4U/V + 2V/A_r`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TriangleMotion {
    /// Peak displacement, m.
    pub amplitude_m: f64,
    /// Constant velocity between reversals, m/s.
    pub velocity_m_s: f64,
    /// Acceleration of the rounded reversals, m/s².
    pub reversal_acceleration_m_s2: f64,
    /// Sample rate, Hz (default 1024).
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
}

/// Band-limited white-noise motion ([`crate::generate::white_noise_motion`]).
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WhiteNoiseMotion {
    /// RMS acceleration, in g (`0.1` for the paper's WN10%g).
    pub rms_acceleration_g: f64,
    /// Band of the flat acceleration spectrum, Hz (default `[0.5, 20]`: up to the table's
    /// 20 Hz bandwidth; the lower edge keeps the displacement within the stroke).
    #[serde(default = "default_band")]
    pub band_hz: [f64; 2],
    /// Seed of the random phases (default 1).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Sample rate, Hz (default 1024).
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
}

fn default_band() -> [f64; 2] {
    [0.5, 20.0]
}

fn default_seed() -> u64 {
    1
}

fn default_rate() -> f64 {
    1024.0
}

/// `integrator`, selected by `method`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum IntegratorSpec {
    /// Fixed-step RK4 with exact stick-slip.
    Rk4(Rk4Spec),
    /// Adaptive Dormand–Prince 5(4) (the mode machine's Dopri5, as every plant's) with exact stick-slip.
    Dopri5(Dopri5Spec),
}

/// `{"method": "dopri5", "rtol": …, "atol": …}`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Dopri5Spec {
    /// Relative tolerance (default 1e-8).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// Absolute tolerance, in the state's units (m, m/s) (default 1e-11).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
}

/// Default relative tolerance of `dopri5`.
pub const DEFAULT_RTOL: f64 = 1e-8;
/// Default absolute tolerance of `dopri5`.
pub const DEFAULT_ATOL: f64 = 1e-11;

/// `{"method": "rk4", "step_s": …}`.
#[derive(Debug, Clone, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Rk4Spec {
    /// Step, s; must divide the record's sample interval (default: the sample interval).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_s: Option<f64>,
}

/// `initial`: the state at the record's first sample, given (`{"u_m": …, "v_m_s": …}`) or
/// taken from the force record's own `u_m` and `v_m_s` columns (`{"from_record": true}`, for
/// a recorded test that did not start at rest, like the paper's SR9). With a `table`: any of
/// the pose and rate names (`{"x_m": …, "y_m_s": …}`), the rest at rest at neutral.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Displacement, m (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub u_m: Option<f64>,
    /// Velocity, m/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v_m_s: Option<f64>,
    /// Take the state from the first row of the force CSV's `u_m` and `v_m_s` columns.
    #[serde(default)]
    pub from_record: bool,
    /// With a `table`: the platen's x, m (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x_m: Option<f64>,
    /// With a `table`: the platen's y, m (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y_m: Option<f64>,
    /// With a `table`: the platen's z, m (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_m: Option<f64>,
    /// With a `table`: the platen's roll, rad (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roll_rad: Option<f64>,
    /// With a `table`: the platen's pitch, rad (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pitch_rad: Option<f64>,
    /// With a `table`: the platen's yaw, rad (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw_rad: Option<f64>,
    /// With a `table`: the platen's x rate, m/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x_m_s: Option<f64>,
    /// With a `table`: the platen's y rate, m/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y_m_s: Option<f64>,
    /// With a `table`: the platen's z rate, m/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_m_s: Option<f64>,
    /// With a `table`: the platen's roll rate, rad/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roll_rad_s: Option<f64>,
    /// With a `table`: the platen's pitch rate, rad/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pitch_rad_s: Option<f64>,
    /// With a `table`: the platen's yaw rate, rad/s (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw_rad_s: Option<f64>,
}

impl InitialSpec {
    /// The multi-axis table's pose and rates, by their names (`x_m` … `yaw_rad`, then
    /// `x_m_s` … `yaw_rad_s`), as given.
    pub fn table_values(&self) -> [(&'static str, Option<f64>); 12] {
        [
            ("x_m", self.x_m),
            ("y_m", self.y_m),
            ("z_m", self.z_m),
            ("roll_rad", self.roll_rad),
            ("pitch_rad", self.pitch_rad),
            ("yaw_rad", self.yaw_rad),
            ("x_m_s", self.x_m_s),
            ("y_m_s", self.y_m_s),
            ("z_m_s", self.z_m_s),
            ("roll_rad_s", self.roll_rad_s),
            ("pitch_rad_s", self.pitch_rad_s),
            ("yaw_rad_s", self.yaw_rad_s),
        ]
    }
}

/// Parses scenario JSON, reporting the JSON path (or line and column) of any error.
///
/// # Errors
/// [`crate::ScenarioError::Io`] ([`platen_io::IoError::JsonSyntax`] for text that is not
/// JSON, [`platen_io::IoError::Json`] for JSON that is not a scenario).
pub fn parse(path: &Path, text: &str) -> Result<ScenarioFile> {
    Ok(parse_json(path, text)?)
}

/// The JSON Schema (draft 2020-12) of the scenario format, generated from the types above.
/// `platen schema` prints it; point an editor's JSON-schema support at the printed file.
pub fn json_schema() -> serde_json::Value {
    let mut schema = serde_json::to_value(schemars::schema_for!(ScenarioFile)).unwrap_or_default();
    if let Some(obj) = schema.as_object_mut() {
        obj.insert("title".into(), "platen scenario".into());
        // The uniaxial platen's `model`, or a multi-axis `table`.
        obj.insert(
            "anyOf".into(),
            serde_json::json!([{"required": ["model"]}, {"required": ["table"]}]),
        );
        obj.insert(
            "description".into(),
            "A platen scenario: model (preset, identified or full form), excitation, integrator, initial \
             state and duration. SI units; the unit is in every key's name."
                .into(),
        );
    }
    schema
}

/// The `(name, value)` pairs an overrides object sets (absent fields are not listed), in
/// alphabetical order of the names.
pub(crate) fn given_values<T: Serialize>(overrides: &T) -> Vec<(String, f64)> {
    match serde_json::to_value(overrides) {
        Ok(serde_json::Value::Object(map)) => map
            .into_iter()
            .filter_map(|(k, v)| v.as_f64().map(|v| (k, v)))
            .collect(),
        _ => Vec::new(),
    }
}
