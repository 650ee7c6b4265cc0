//! The scenario file: which model, which excitation, which integrator.
//!
//! ```json
//! {
//!   "name": "SR9-like sine force",
//!   "model": { "preset": "lhpost-2008", "hold_down_pressure_mpa": 13.8 },
//!   "excitation": { "sine_force": { "amplitude_n": 6e5, "frequency_hz": 0.5 } },
//!   "integrator": { "method": "rk4", "step_s": 0.0009765625 },
//!   "initial": { "u_m": 0.0, "v_m_s": 0.0 },
//!   "duration_s": 20.0
//! }
//! ```
//!
//! * `model.preset` names the table (`lhpost-2008`). By default the **identified** model of
//!   Eq. 22/23 runs; an `identified` object lays its values (the contract's seven keys) over
//!   the preset's. A `full` object selects the **full Lagrangian** model of Eq. 1–8 and lays
//!   its physical parameters (names as in [`platen_model::PhysicalParams`]) over the preset's;
//!   `"full": {}` runs the preset's physical parameters. `hold_down_pressure_mpa` (default
//!   13.8) sets the nitrogen pressure of either form.
//! * `excitation` holds exactly one of `force_csv` (columns `t_s`, `force_n`, uniformly
//!   sampled, linear between samples: a forward run), `motion_csv` (`t_s`, `u_m`, optional
//!   `v_m_s`, `a_m_s2`: an inverse run), or a generated `sine_force` (forward),
//!   `sine_motion`, `triangle_motion` or `white_noise_motion` (inverse).
//!   Paths are relative to the scenario file.
//! * `integrator` (forward runs only; default RK4 at the record's sample interval):
//!   `{"method": "rk4", "step_s": Δt/k}` or `{"method": "dopri5", "rtol": 1e-8, "atol": 1e-11}`.
//! * `initial` (forward runs only; default at rest at 0).
//! * `duration_s` defaults to the record's span; required for generated excitations.
//!
//! Unknown keys are errors, reported with their JSON path.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::Deserialize;

use platen_integrate::{Dopri5Settings, ForceRecord, Method, Motion, Rk4, State};
use platen_model::{
    FullModel, IdentifiedModel, IdentifiedParams, ModelError, PhysicalParams, Preset, TableLimits,
    STANDARD_GRAVITY_M_S2,
};

use crate::error::{Result, ScenarioError};
use crate::generate::{self, GenerateError};
use crate::sampling::uniform_step_s;
use platen_io::columns::{ColumnMap, ColumnSpec};
use platen_io::json::{parse_json, parse_json_file};
use platen_io::IoError;

/// The scenario file as written (after JSON parsing, before validation).
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// The JSON Schema this file follows (ignored; lets editors find `platen schema`'s output).
    #[serde(rename = "$schema")]
    pub schema: Option<String>,
    /// A short name for reports (default: the file stem).
    pub name: Option<String>,
    /// Free text.
    pub description: Option<String>,
    /// The model.
    pub model: ModelSpec,
    /// The excitation.
    pub excitation: ExcitationSpec,
    /// The integrator (forward runs).
    pub integrator: Option<IntegratorSpec>,
    /// The initial state (forward runs).
    pub initial: Option<InitialSpec>,
    /// Simulated duration, s (default: the record's span).
    pub duration_s: Option<f64>,
}

/// `model`: a preset, its hold-down pressure, and the form with overrides.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Preset name (`lhpost-2008`).
    pub preset: String,
    /// Hold-down nitrogen pressure, MPa (default: the preset's nominal 13.8 MPa).
    pub hold_down_pressure_mpa: Option<f64>,
    /// Identified-model values laid over the preset's (Eq. 22/23).
    pub identified: Option<IdentifiedOverrides>,
    /// Selects the full Lagrangian model; physical values laid over the preset's.
    pub full: Option<PhysicalOverrides>,
}

/// Overrides of the identified model; the contract's keys.
#[derive(Debug, Clone, Default, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct IdentifiedOverrides {
    pub effective_mass_kg: Option<f64>,
    pub stiffness_n_per_m: Option<f64>,
    pub coulomb_force_n: Option<f64>,
    pub viscous_coefficient: Option<f64>,
    pub viscous_exponent: Option<f64>,
    pub low_velocity_force_n: Option<f64>,
    pub low_velocity_decay_s_per_m: Option<f64>,
}

/// Overrides of the physical parameters of the full model (see
/// [`platen_model::PhysicalParams`] for meanings and units). The hold-down pressure is set by
/// `model.hold_down_pressure_mpa`.
#[derive(Debug, Clone, Default, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct PhysicalOverrides {
    pub platen_mass_kg: Option<f64>,
    pub actuator_moving_mass_kg: Option<f64>,
    pub strut_piston_mass_kg: Option<f64>,
    pub strut_cylinder_mass_kg: Option<f64>,
    pub strut_height_m: Option<f64>,
    pub strut_piston_length_m: Option<f64>,
    pub strut_area_m2: Option<f64>,
    pub gas_heat_capacity_ratio: Option<f64>,
    pub supported_weight_n: Option<f64>,
    pub bearing_friction_coefficient: Option<f64>,
    pub lateral_friction_coefficient: Option<f64>,
    pub lateral_normal_force_n: Option<f64>,
    pub hinge_swivel_friction_coefficient: Option<f64>,
    pub hinge_radius_m: Option<f64>,
    pub hinge_force_distribution_factor: Option<f64>,
    pub viscous_coefficient: Option<f64>,
    pub viscous_exponent: Option<f64>,
    pub strut_viscous_coefficient: Option<f64>,
    pub strut_viscous_exponent: Option<f64>,
    pub low_velocity_force_n: Option<f64>,
    pub low_velocity_decay_s_per_m: Option<f64>,
}

/// `excitation`: exactly one source.
#[derive(Debug, Clone, Default, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExcitationSpec {
    /// Recorded actuator force (`t_s`, `force_n`): forward run.
    pub force_csv: Option<PathBuf>,
    /// Prescribed motion (`t_s`, `u_m`, optional `v_m_s`, `a_m_s2`): inverse run.
    pub motion_csv: Option<PathBuf>,
    /// Generated sine force: forward run.
    pub sine_force: Option<SineForce>,
    /// Generated sine displacement (the paper's S tests): inverse run.
    pub sine_motion: Option<SineMotion>,
    /// Generated triangle displacement with rounded reversals (the paper's T tests): inverse run.
    pub triangle_motion: Option<TriangleMotion>,
    /// Generated band-limited white-noise motion (the paper's WN tests): inverse run.
    pub white_noise_motion: Option<WhiteNoiseMotion>,
    /// Table motion from a ground-acceleration record (an earthquake test): inverse run.
    pub ground_motion: Option<GroundMotion>,
    /// Zero-phase low-pass of a force excitation before it drives the model, Hz (the paper
    /// low-passed the SR9 force at 0.6 Hz). Forward runs only.
    pub lowpass_hz: Option<f64>,
    /// The filter of `lowpass_hz` (default `brickwall`).
    pub lowpass_filter: Option<LowpassFilter>,
    /// A lab's own channel names and units for `force_csv` / `motion_csv`
    /// (see [`platen_io::columns`]).
    pub columns: Option<BTreeMap<String, ColumnSpec>>,
}

/// Zero-phase low-pass filters for `lowpass_hz`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
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

/// A table motion that reproduces a ground-acceleration record: the PEER `.AT2` record is
/// scaled, resampled (not-a-knot cubic spline; anti-aliased when downsampling),
/// baseline-corrected and integrated (trapezoidal) to table velocity and displacement, from
/// rest at 0.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
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
    /// Baseline correction before integrating: `none`, `acceleration` (remove the
    /// least-squares polynomial of `baseline_order` from the acceleration) or `velocity` (from
    /// the velocity). Default `acceleration` of order 0: the mean acceleration is removed, so
    /// the table ends at rest.
    #[serde(default = "default_baseline")]
    pub baseline: BaselineKind,
    /// Polynomial order of the baseline correction (default 0, at most 8).
    #[serde(default)]
    pub baseline_order: usize,
    /// For a record given as CSV (a `.csv` file): the time and acceleration columns' names and
    /// units, e.g. `{"t_s": {"name": "time"}, "a_m_s2": {"name": "acc (g)", "unit": "g"}}`.
    pub columns: Option<BTreeMap<String, ColumnSpec>>,
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

fn default_scale() -> f64 {
    1.0
}

fn default_baseline() -> BaselineKind {
    BaselineKind::Acceleration
}

/// `F(t) = r(t)·amplitude_n·sin(2π·frequency_hz·t)`, with `r` a linear ramp from 0 to 1 over
/// `ramp_s` (0: none), sampled at `sample_rate_hz` from `t = 0`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum IntegratorSpec {
    /// Fixed-step RK4 with exact stick-slip.
    Rk4(Rk4Spec),
    /// Adaptive Dormand–Prince 5(4) (ode_solvers' Dopri5) with exact stick-slip.
    Dopri5(Dopri5Spec),
}

/// `{"method": "dopri5", "rtol": …, "atol": …}`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Dopri5Spec {
    /// Relative tolerance (default 1e-8).
    pub rtol: Option<f64>,
    /// Absolute tolerance, in the state's units (m, m/s) (default 1e-11).
    pub atol: Option<f64>,
}

/// Default relative tolerance of `dopri5`.
pub const DEFAULT_RTOL: f64 = 1e-8;
/// Default absolute tolerance of `dopri5`.
pub const DEFAULT_ATOL: f64 = 1e-11;

/// `{"method": "rk4", "step_s": …}`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Rk4Spec {
    /// Step, s; must divide the record's sample interval (default: the sample interval).
    pub step_s: Option<f64>,
}

/// `initial`: the state at the record's first sample, given (`{"u_m": …, "v_m_s": …}`) or
/// taken from the force record's own `u_m` and `v_m_s` columns (`{"from_record": true}`, for
/// a recorded test that did not start at rest, like the paper's SR9).
#[derive(Debug, Clone, Default, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Displacement, m (default 0).
    pub u_m: Option<f64>,
    /// Velocity, m/s (default 0).
    pub v_m_s: Option<f64>,
    /// Take the state from the first row of the force CSV's `u_m` and `v_m_s` columns.
    #[serde(default)]
    pub from_record: bool,
}

/// A validated model in one of its two forms.
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    /// The identified model (Eq. 22/23).
    Identified(IdentifiedModel),
    /// The full Lagrangian model (Eq. 1–8).
    Full(Box<FullModel>),
}

impl Model {
    /// `"identified"` or `"full"`.
    pub fn form(&self) -> &'static str {
        match self {
            Model::Identified(_) => "identified",
            Model::Full(_) => "full",
        }
    }
}

/// What a scenario runs.
#[derive(Debug, Clone, PartialEq)]
pub enum Run {
    /// Force-driven: the force record drives the model forward.
    Forward {
        /// The actuator force.
        record: ForceRecord,
        /// Integrator settings.
        integrator: Method,
        /// State at the first sample.
        initial: State,
        /// Output samples (the first `samples` of the record).
        samples: usize,
    },
    /// Motion-driven: the force the motion needs.
    Inverse {
        /// The prescribed motion (already cut to the duration).
        motion: Motion,
    },
}

impl Run {
    /// The times of the first and last output sample, s: known before the run, so that
    /// inputs that must cover them (a recorded test to compare with) are checked first.
    pub fn time_span_s(&self) -> (f64, f64) {
        let (t, n) = match self {
            Run::Forward {
                record, samples, ..
            } => (record.t_s(), *samples),
            Run::Inverse { motion } => (motion.t_s(), motion.len()),
        };
        match n.checked_sub(1).and_then(|last| t.get(last)) {
            Some(&end) => (t[0], end),
            None => (f64::NAN, f64::NAN),
        }
    }
}

/// A validated scenario, ready to run.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The scenario's name.
    pub name: String,
    /// The preset it is based on.
    pub preset: Preset,
    /// The hold-down pressure, Pa.
    pub hold_down_pressure_pa: f64,
    /// The model.
    pub model: Model,
    /// The table's limits.
    pub limits: TableLimits,
    /// What to run.
    pub run: Run,
}

impl Scenario {
    /// Reads, parses and validates the scenario at `path`, and loads every record it names.
    /// Nothing is simulated.
    ///
    /// # Errors
    /// Any [`ScenarioError`]: unreadable file, malformed JSON or unknown key (with its JSON
    /// path), invalid values (with their JSON path and what was expected), and every error of
    /// the records it references (with file and line).
    pub fn load(path: &Path) -> Result<Self> {
        Self::from_file(path, parse_json_file(path)?)
    }

    /// Validates a parsed scenario; relative paths are resolved against `path`'s folder.
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn from_file(path: &Path, file: ScenarioFile) -> Result<Self> {
        let ctx = Ctx { path };
        let preset = Preset::from_name(&file.model.preset).map_err(|e| {
            ctx.invalid(
                "model.preset",
                format!("{:?}", file.model.preset),
                e.to_string(),
            )
        })?;
        let pressure_pa = match file.model.hold_down_pressure_mpa {
            Some(p) if !(p.is_finite() && p >= 0.0) => {
                return Err(ctx.invalid("model.hold_down_pressure_mpa", p, "a pressure >= 0 MPa"))
            }
            Some(p) => p * 1e6,
            None => preset.nominal_pressure_pa(),
        };
        let model = build_model(&ctx, preset, pressure_pa, &file.model)?;
        let run = build_run(&ctx, &file)?;
        let name = file.name.clone().unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
        Ok(Self {
            name,
            preset,
            hold_down_pressure_pa: pressure_pa,
            model,
            limits: preset.limits(),
            run,
        })
    }
}

/// Parses scenario JSON, reporting the JSON path (or line and column) of any error.
///
/// # Errors
/// [`ScenarioError::Io`] ([`platen_io::IoError::Json`]).
pub fn parse(path: &Path, text: &str) -> Result<ScenarioFile> {
    Ok(parse_json(path, text)?)
}

struct Ctx<'a> {
    path: &'a Path,
}

impl Ctx<'_> {
    fn invalid(
        &self,
        json_path: &str,
        value: impl ToString,
        expected: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError::InvalidField {
            path: self.path.to_owned(),
            json_path: json_path.to_owned(),
            value: value.to_string(),
            expected: expected.into(),
        }
    }

    fn resolve(&self, relative: &Path) -> PathBuf {
        match self.path.parent() {
            Some(dir) if relative.is_relative() => dir.join(relative),
            _ => relative.to_owned(),
        }
    }

    fn model_error(&self, section: &str, e: ModelError) -> ScenarioError {
        match e {
            ModelError::InvalidParameter {
                name: "hold_down_pressure_pa",
                value,
                expected,
            } => self.invalid("model.hold_down_pressure_mpa", value / 1e6, expected),
            ModelError::InvalidParameter {
                name,
                value,
                expected,
            } => self.invalid(&format!("{section}.{name}"), value, expected),
            other => self.invalid(section, "", other.to_string()),
        }
    }
}

macro_rules! lay_over {
    ($target:expr, $over:expr, [$($field:ident),* $(,)?]) => {
        $( if let Some(v) = $over.$field { $target.$field = v; } )*
    };
}

fn build_model(ctx: &Ctx, preset: Preset, pressure_pa: f64, spec: &ModelSpec) -> Result<Model> {
    match (&spec.identified, &spec.full) {
        (Some(_), Some(_)) => Err(ctx.invalid(
            "model",
            "{identified, full}",
            "either an `identified` object (identified model) or a `full` object (full Lagrangian model), not both",
        )),
        (_, Some(over)) => {
            let mut p: PhysicalParams = preset.physical(pressure_pa).map_err(|e| ctx.model_error("model.full", e))?;
            lay_over!(p, over, [
                platen_mass_kg, actuator_moving_mass_kg, strut_piston_mass_kg, strut_cylinder_mass_kg,
                strut_height_m, strut_piston_length_m, strut_area_m2, gas_heat_capacity_ratio,
                supported_weight_n, bearing_friction_coefficient, lateral_friction_coefficient,
                lateral_normal_force_n, hinge_swivel_friction_coefficient, hinge_radius_m,
                hinge_force_distribution_factor, viscous_coefficient, viscous_exponent,
                strut_viscous_coefficient, strut_viscous_exponent, low_velocity_force_n,
                low_velocity_decay_s_per_m,
            ]);
            p.build().map(|m| Model::Full(Box::new(m))).map_err(|e| ctx.model_error("model.full", e))
        }
        (over, None) => {
            let mut p: IdentifiedParams =
                preset.identified(pressure_pa).map_err(|e| ctx.model_error("model.identified", e))?;
            if let Some(over) = over {
                lay_over!(p, over, [
                    effective_mass_kg, stiffness_n_per_m, coulomb_force_n, viscous_coefficient,
                    viscous_exponent, low_velocity_force_n, low_velocity_decay_s_per_m,
                ]);
            }
            p.build().map(Model::Identified).map_err(|e| ctx.model_error("model.identified", e))
        }
    }
}

fn check_positive(ctx: &Ctx, json_path: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ctx.invalid(json_path, value, "a finite number > 0"))
    }
}

/// Number of samples of a record of `len` samples at interval `dt` that `duration_s` covers.
fn samples_for(
    ctx: &Ctx,
    record_path: &Path,
    duration_s: Option<f64>,
    dt: f64,
    len: usize,
) -> Result<usize> {
    let Some(d) = duration_s else { return Ok(len) };
    check_positive(ctx, "duration_s", d)?;
    // Tolerate rounding of the duration to about a millionth of a sample.
    let n = (d / dt + 1e-6).floor() as usize + 1;
    if n > len {
        return Err(ScenarioError::Record {
            path: record_path.to_owned(),
            message: format!(
                "record spans {} s ({len} samples) but the scenario's duration_s is {d} s",
                (len - 1) as f64 * dt
            ),
        });
    }
    Ok(n)
}

fn build_run(ctx: &Ctx, file: &ScenarioFile) -> Result<Run> {
    let ex = &file.excitation;
    let given: Vec<&str> = [
        ("force_csv", ex.force_csv.is_some()),
        ("motion_csv", ex.motion_csv.is_some()),
        ("sine_force", ex.sine_force.is_some()),
        ("sine_motion", ex.sine_motion.is_some()),
        ("triangle_motion", ex.triangle_motion.is_some()),
        ("white_noise_motion", ex.white_noise_motion.is_some()),
        ("ground_motion", ex.ground_motion.is_some()),
    ]
    .iter()
    .filter(|(_, present)| *present)
    .map(|(name, _)| *name)
    .collect();
    if given.len() != 1 {
        return Err(ctx.invalid(
            "excitation",
            format!("{{{}}}", given.join(", ")),
            "exactly one of force_csv, motion_csv, sine_force, sine_motion, triangle_motion, white_noise_motion, ground_motion",
        ));
    }
    let kind = given[0];
    let forward = ex.force_csv.is_some() || ex.sine_force.is_some();
    if !forward && (ex.lowpass_hz.is_some() || ex.lowpass_filter.is_some()) {
        return Err(ctx.invalid(
            "excitation.lowpass_hz",
            ex.lowpass_hz
                .map_or("(filter only)".to_owned(), |f| f.to_string()),
            "no low-pass on a motion: it applies to force excitations (force_csv, sine_force)",
        ));
    }
    if !forward {
        if file.integrator.is_some() {
            return Err(ctx.invalid(
                "integrator",
                "{…}",
                "no integrator: a motion-driven (inverse) run integrates nothing",
            ));
        }
        if file.initial.is_some() {
            return Err(ctx.invalid(
                "initial",
                "{…}",
                "no initial state: a motion-driven (inverse) run starts from its motion",
            ));
        }
    }
    // Generated excitations have no length of their own.
    let duration = || -> Result<f64> {
        file.duration_s.ok_or_else(|| {
            ctx.invalid(
                "duration_s",
                "(missing)",
                format!("a duration in s: excitation.{kind} has no length of its own"),
            )
        })
    };
    let generated = |e: GenerateError| match e {
        GenerateError::Invalid {
            name: "duration_s",
            value,
            expected,
        } => ctx.invalid("duration_s", value, expected),
        GenerateError::Invalid {
            name,
            value,
            expected,
        } => ctx.invalid(&format!("excitation.{kind}.{name}"), value, expected),
    };
    if let Some(rel) = &ex.force_csv {
        let path = ctx.resolve(rel);
        let mut cols = read_mapped(ctx, &path, ex, &["t_s", "force_n"], &["u_m", "v_m_s"])?;
        let t = cols.remove("t_s").unwrap_or_default();
        let f = cols.remove("force_n").unwrap_or_default();
        let recorded_state = match (cols.get("u_m"), cols.get("v_m_s")) {
            (Some(u), Some(v)) => Some((u[0], v[0])),
            _ => None,
        };
        let dt = uniform_step_s(&path, &t)?;
        let samples = samples_for(ctx, &path, file.duration_s, dt, t.len())?;
        let record = ForceRecord::new(t, f).map_err(|e| ScenarioError::Record {
            path: path.clone(),
            message: e.to_string(),
        })?;
        let record = lowpass(ctx, ex, record, samples)?;
        return forward_run(ctx, file, record, samples, recorded_state);
    }
    if let Some(g) = &ex.sine_force {
        let record = generate::sine_force(
            g.amplitude_n,
            g.frequency_hz,
            g.ramp_s,
            g.sample_rate_hz,
            duration()?,
        )
        .map_err(generated)?;
        let samples = record.len();
        let record = lowpass(ctx, ex, record, samples)?;
        return forward_run(ctx, file, record, samples, None);
    }
    let motion = if let Some(rel) = &ex.motion_csv {
        let path = ctx.resolve(rel);
        let mut cols = read_mapped(ctx, &path, ex, &["t_s", "u_m"], &["v_m_s", "a_m_s2"])?;
        let t = cols.remove("t_s").unwrap_or_default();
        let u = cols.remove("u_m").unwrap_or_default();
        let v = cols.remove("v_m_s");
        let a = cols.remove("a_m_s2");
        let samples = match file.duration_s {
            None => t.len(),
            Some(d) => {
                check_positive(ctx, "duration_s", d)?;
                let end = t[0] + d;
                if t[t.len() - 1] < end - 1e-9 * d.abs() {
                    return Err(ScenarioError::Record {
                        path,
                        message: format!(
                            "record spans {} s but the scenario's duration_s is {d} s",
                            t[t.len() - 1] - t[0]
                        ),
                    });
                }
                t.partition_point(|&x| x <= end + 1e-9 * d.abs())
            }
        };
        let cut = |c: Vec<f64>| c[..samples].to_vec();
        match (v, a) {
            (Some(v), Some(a)) => Motion::new(cut(t), cut(u), cut(v), cut(a)),
            (Some(v), None) => Motion::from_displacement_velocity(cut(t), cut(u), cut(v)),
            (None, Some(_)) | (None, None) => Motion::from_displacement(cut(t), cut(u)),
        }
        .map_err(|e| ScenarioError::Record {
            path,
            message: e.to_string(),
        })?
    } else if let Some(g) = &ex.sine_motion {
        generate::sine_motion(g.amplitude_m, g.frequency_hz, g.sample_rate_hz, duration()?)
            .map_err(generated)?
    } else if let Some(g) = &ex.triangle_motion {
        generate::triangle_motion(
            g.amplitude_m,
            g.velocity_m_s,
            g.reversal_acceleration_m_s2,
            g.sample_rate_hz,
            duration()?,
        )
        .map_err(generated)?
    } else if let Some(g) = &ex.ground_motion {
        ground_motion(ctx, g, file.duration_s)?
    } else {
        let g = ex
            .white_noise_motion
            .as_ref()
            .expect("exactly one excitation is present");
        let rms = check_positive(
            ctx,
            "excitation.white_noise_motion.rms_acceleration_g",
            g.rms_acceleration_g,
        )?;
        generate::white_noise_motion(
            rms * STANDARD_GRAVITY_M_S2,
            (g.band_hz[0], g.band_hz[1]),
            g.seed,
            g.sample_rate_hz,
            duration()?,
        )
        .map_err(generated)?
    };
    Ok(Run::Inverse { motion })
}

/// Reads platen's columns `required` and `optional` from `path` through the excitation's
/// `columns` mapping (file headers and units), in SI units. The time column must increase
/// strictly; a violation names its line.
fn read_mapped(
    ctx: &Ctx,
    path: &Path,
    ex: &ExcitationSpec,
    required: &[&'static str],
    optional: &[&'static str],
) -> Result<BTreeMap<&'static str, Vec<f64>>> {
    let map = match &ex.columns {
        Some(spec) => ColumnMap::new(spec, "excitation.columns")
            .map_err(|(json_path, value, expected)| ctx.invalid(&json_path, value, expected))?,
        None => ColumnMap::default(),
    };
    let mut table = map.read_table(path, required, optional)?;
    let mut out = BTreeMap::new();
    for &ours in required.iter().chain(optional) {
        if let Some(col) = table.take_column(ours) {
            out.insert(ours, col);
        }
    }
    if let Some(t) = out.get("t_s") {
        if let Some(i) = (1..t.len()).find(|&i| t[i] <= t[i - 1]) {
            return Err(IoError::TimeNotIncreasing {
                path: path.to_owned(),
                line: i as u64 + 2,
                previous_s: t[i - 1],
                value_s: t[i],
            }
            .into());
        }
    }
    Ok(out)
}

/// Applies `excitation.lowpass_hz` to the first `samples` samples of a force record (the part
/// that runs), with the chosen zero-phase filter.
fn lowpass(
    ctx: &Ctx,
    ex: &ExcitationSpec,
    record: ForceRecord,
    samples: usize,
) -> Result<ForceRecord> {
    let Some(cutoff) = ex.lowpass_hz else {
        if ex.lowpass_filter.is_some() {
            return Err(ctx.invalid(
                "excitation.lowpass_filter",
                "(set)",
                "a lowpass_hz for the filter to use",
            ));
        }
        return Ok(record);
    };
    let rate = 1.0 / record.dt_s();
    if !(cutoff.is_finite() && cutoff > 0.0 && cutoff < 0.5 * rate) {
        return Err(ctx.invalid(
            "excitation.lowpass_hz",
            cutoff,
            format!(
                "a cut-off between 0 and the record's Nyquist frequency {} Hz",
                0.5 * rate
            ),
        ));
    }
    let input = &record.force_n()[..samples];
    let signal =
        |e: platen_signal::SignalError| ctx.invalid("excitation.lowpass_hz", cutoff, e.to_string());
    use platen_signal::ZeroPhaseFilter;
    let filtered = match ex.lowpass_filter.unwrap_or(LowpassFilter::Brickwall) {
        LowpassFilter::Brickwall => platen_signal::SpectralLowpass::new(samples, cutoff, rate)
            .map_err(signal)?
            .apply(input)
            .map_err(signal)?,
        LowpassFilter::Fir => {
            platen_signal::FirLowpass::new(1024, cutoff, rate, platen_signal::Window::Hamming)
                .map_err(signal)?
                .apply(input)
                .map_err(signal)?
        }
        LowpassFilter::Butterworth => platen_signal::ButterworthLowpass::new(4, cutoff, rate)
            .map_err(signal)?
            .apply(input)
            .map_err(signal)?,
    };
    ForceRecord::new(record.t_s()[..samples].to_vec(), filtered)
        .map_err(|e| ctx.invalid("excitation.lowpass_hz", cutoff, e.to_string()))
}

/// The table motion of an `excitation.ground_motion`.
fn ground_motion(ctx: &Ctx, g: &GroundMotion, duration_s: Option<f64>) -> Result<Motion> {
    let here = "excitation.ground_motion";
    let scale = check_finite(ctx, &format!("{here}.scale"), g.scale)?;
    let rate = check_positive(ctx, &format!("{here}.sample_rate_hz"), g.sample_rate_hz)?;
    let path = platen_io::peer::find_record(ctx.path.parent(), &g.record)?;
    let is_csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let (acc, dt_s) = if is_csv {
        let ex = ExcitationSpec {
            columns: g.columns.clone(),
            ..ExcitationSpec::default()
        };
        let mut cols = read_mapped(ctx, &path, &ex, &["t_s", "a_m_s2"], &[])?;
        let t = cols.remove("t_s").unwrap_or_default();
        let dt = uniform_step_s(&path, &t)?;
        (cols.remove("a_m_s2").unwrap_or_default(), dt)
    } else {
        if g.columns.is_some() {
            return Err(ctx.invalid(
                &format!("{here}.columns"),
                "(set)",
                "columns only for a record given as .csv",
            ));
        }
        let rec = platen_io::peer::read_peer(&path)?;
        if rec.quantity != platen_io::peer::Quantity::Acceleration {
            return Err(ScenarioError::Record {
                path,
                message: "ground_motion needs an acceleration record (.AT2); this one holds velocity or displacement"
                    .into(),
            });
        }
        (rec.values, rec.dt_s)
    };
    let signal = |name: &str, e: platen_signal::SignalError| {
        ctx.invalid(&format!("{here}.{name}"), "", e.to_string())
    };
    let a: Vec<f64> = acc.iter().map(|x| x * scale).collect();
    let resampler =
        platen_signal::Resampler::new(1.0 / dt_s, rate, platen_signal::Interpolation::default())
            .map_err(|e| signal("sample_rate_hz", e))?;
    if resampler.output_len(a.len()) > generate::MAX_GENERATED_SAMPLES {
        return Err(ctx.invalid(
            &format!("{here}.sample_rate_hz"),
            rate,
            format!(
                "a rate giving at most {} samples for this record",
                generate::MAX_GENERATED_SAMPLES
            ),
        ));
    }
    let mut a = resampler
        .apply(&a)
        .map_err(|e| signal("sample_rate_hz", e))?;
    if let Some(d) = duration_s {
        check_positive(ctx, "duration_s", d)?;
        let n = (d * rate + 1e-6).floor() as usize + 1;
        if n > a.len() {
            return Err(ScenarioError::Record {
                path,
                message: format!(
                    "record spans {} s but the scenario's duration_s is {d} s",
                    (a.len() - 1) as f64 / rate
                ),
            });
        }
        a.truncate(n);
    }
    let baseline = match g.baseline {
        BaselineKind::None => platen_signal::Baseline::None,
        BaselineKind::Acceleration => platen_signal::Baseline::Acceleration {
            order: g.baseline_order,
        },
        BaselineKind::Velocity => platen_signal::Baseline::Velocity {
            order: g.baseline_order,
        },
    };
    let integrator = platen_signal::MotionIntegrator::new(rate, baseline)
        .map_err(|e| signal("baseline_order", e))?;
    if matches!(g.baseline, BaselineKind::Acceleration) {
        platen_signal::remove_polynomial(&mut a, g.baseline_order);
    }
    let m = integrator.integrate(&a, platen_signal::InitialMotion::default());
    let t = (0..a.len()).map(|j| j as f64 / rate).collect();
    Motion::new(t, m.u_m, m.v_m_s, a).map_err(|e| ScenarioError::Record {
        path,
        message: e.to_string(),
    })
}

fn check_finite(ctx: &Ctx, json_path: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ctx.invalid(json_path, value, "a finite number"))
    }
}

fn forward_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    record: ForceRecord,
    samples: usize,
    recorded_state: Option<(f64, f64)>,
) -> Result<Run> {
    let integrator = match &file.integrator {
        None => Method::Rk4(Rk4::with_steps_per_sample(1).expect("k = 1 is valid")),
        Some(IntegratorSpec::Rk4(Rk4Spec { step_s })) => {
            let step = step_s.unwrap_or(record.dt_s());
            Method::Rk4(
                Rk4::from_step(step, record.dt_s())
                    .map_err(|e| ctx.invalid("integrator.step_s", step, e.to_string()))?,
            )
        }
        Some(IntegratorSpec::Dopri5(spec)) => {
            let rtol = spec.rtol.unwrap_or(DEFAULT_RTOL);
            let atol = spec.atol.unwrap_or(DEFAULT_ATOL);
            let settings = Dopri5Settings::new(rtol, atol).map_err(|e| match e {
                platen_integrate::IntegrateError::InvalidTolerance { name, value } => ctx.invalid(
                    &format!("integrator.{name}"),
                    value,
                    "a finite number > 0 (rtol < 1)",
                ),
                other => ctx.invalid("integrator", "", other.to_string()),
            })?;
            Method::Dopri5(settings)
        }
    };
    let initial = file.initial.clone().unwrap_or_default();
    let (u0, v0) = if initial.from_record {
        if initial.u_m.is_some() || initial.v_m_s.is_some() {
            return Err(ctx.invalid(
                "initial",
                "{from_record, u_m/v_m_s}",
                "either from_record or u_m/v_m_s, not both",
            ));
        }
        match recorded_state {
            Some(state) => state,
            None => {
                return Err(ctx.invalid(
                    "initial.from_record",
                    "true",
                    "a force_csv with u_m and v_m_s columns to take the initial state from",
                ))
            }
        }
    } else {
        (initial.u_m.unwrap_or(0.0), initial.v_m_s.unwrap_or(0.0))
    };
    let u_m = check_finite(ctx, "initial.u_m", u0)?;
    let v_m_s = check_finite(ctx, "initial.v_m_s", v0)?;
    Ok(Run::Forward {
        record,
        integrator,
        initial: State { u_m, v_m_s },
        samples,
    })
}

/// The JSON Schema (draft 2020-12) of the scenario format, generated from the types above.
/// `platen schema` prints it; point an editor's JSON-schema support at the printed file.
pub fn json_schema() -> serde_json::Value {
    let mut schema = serde_json::to_value(schemars::schema_for!(ScenarioFile)).unwrap_or_default();
    if let Some(obj) = schema.as_object_mut() {
        obj.insert("title".into(), "platen scenario".into());
        obj.insert(
            "description".into(),
            "A platen scenario: model (preset, identified or full form), excitation, integrator, initial \
             state and duration. SI units; the unit is in every key's name."
                .into(),
        );
    }
    schema
}
