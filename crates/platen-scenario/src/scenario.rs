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

use std::path::Path;

use platen_integrate::IntegrateError;
use platen_model::{
    FullModel, IdentifiedModel, IdentifiedParams, PhysicalParams, Preset, TableLimits,
};

use crate::ctx::Ctx;
use crate::error::Result;
use crate::excitation::build_run;
use platen_io::json::parse_json_file;

pub use crate::excitation::Run;
pub use crate::file::*;

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
    /// The same scenario with its excitation multiplied by `k` (see [`Run::scaled`]).
    ///
    /// # Errors
    /// As [`Run::scaled`].
    pub fn scaled(&self, k: f64) -> std::result::Result<Scenario, IntegrateError> {
        Ok(Scenario {
            name: self.name.clone(),
            preset: self.preset,
            hold_down_pressure_pa: self.hold_down_pressure_pa,
            model: self.model.clone(),
            limits: self.limits,
            run: self.run.scaled(k)?,
        })
    }

    /// Reads, parses and validates the scenario at `path`, and loads every record it names.
    /// Nothing is simulated.
    ///
    /// # Errors
    /// Any [`crate::ScenarioError`]: unreadable file, malformed JSON or unknown key (with its JSON
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
