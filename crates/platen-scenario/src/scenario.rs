//! The scenario file: a rig (which model, limits, table system and specimen: [`Rig`]) and a
//! run (which excitation, integrator and initial state: [`Run`]).
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
//! * `specimen` (optional): `{"storeys": [{"mass_kg", "stiffness_n_per_m",
//!   "damping_n_s_per_m"}, …]}`, bottom storey first: a shear building on the platen
//!   ([`platen_model::Specimen`]).
//! * `table_system` (optional, [`crate::system`]): the loop around the platen; a motion
//!   excitation is then the displacement command of a closed loop ([`Run::ClosedLoop`]).
//! * `limits` (optional): any of `stroke_m`, `velocity_m_s`, `acceleration_m_s2`, `force_n`,
//!   laid over the preset's table limits; the summary checks the run's peaks against them.
//!
//! Unknown keys are errors, reported with their JSON path.

use std::path::Path;

use platen_integrate::IntegrateError;
use platen_model::{ModelError, Specimen};

use crate::ctx::Ctx;
use crate::error::Result;
use crate::excitation::build_run;
use crate::rig::{scenario_name, LoopSettings, Rig, RigKeys, RigStart};
use platen_io::json::parse_json_file;

pub use crate::excitation::{Derived, Run};
pub use crate::file::*;
pub use crate::model::{Model, ModelKey, ModelOverrides};

/// A validated scenario, ready to run: a rig ([`Rig`]: what the table is) and a run
/// ([`Run`]: what it does).
#[derive(Debug, Clone, PartialEq)]
pub struct PlatenScenario {
    /// The scenario's name.
    pub name: String,
    /// The table: model, limits, table system and specimen.
    pub rig: Rig,
    /// What to run.
    pub run: Run,
    /// The excitation's channels that platen derived (not given by the file or generator), by
    /// name, with how: what the summary reports under `derived`.
    pub derived: Derived,
}

impl PlatenScenario {
    /// Number of storeys of the specimen (0 without one).
    pub fn storeys(&self) -> usize {
        self.rig.storeys()
    }

    /// The same scenario with its excitation multiplied by `k` (see [`Run::scaled`]).
    ///
    /// # Errors
    /// As [`Run::scaled`].
    pub fn scaled(&self, k: f64) -> std::result::Result<PlatenScenario, IntegrateError> {
        Ok(PlatenScenario {
            name: self.name.clone(),
            rig: self.rig.clone(),
            run: self.run.scaled(k)?.into_owned(),
            derived: self.derived.clone(),
        })
    }

    /// The scenario at another hold-down pressure: its model rebuilt from its preset at
    /// `pressure_pa` with the scenario's own overrides (what `platen simulate --pressure-mpa`
    /// runs; see [`Rig::at_pressure`]).
    ///
    /// # Errors
    /// As [`ModelOverrides::build`].
    pub fn at_pressure(
        mut self,
        pressure_pa: f64,
    ) -> std::result::Result<PlatenScenario, ModelError> {
        self.rig = self.rig.at_pressure(pressure_pa)?;
        Ok(self)
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
    /// As [`PlatenScenario::load`].
    pub fn from_file(path: &Path, file: ScenarioFile) -> Result<Self> {
        Self::validate(path, &file, build_run)
    }

    /// Validates `file`'s rig and settings, with `run` building what it runs (from the
    /// file's excitation, or from records given in memory: [`PlatenScenario::from_arrays`]). With
    /// a table system, a motion is the command of a closed loop ([`Run::ClosedLoop`]).
    pub(crate) fn validate(
        path: &Path,
        file: &ScenarioFile,
        run: impl FnOnce(&Ctx, &ScenarioFile) -> Result<(Run, Derived)>,
    ) -> Result<Self> {
        let ctx = Ctx { path };
        let keys = RigKeys::of(&ctx, file)?;
        let start = RigStart::validate(&ctx, &keys)?;
        let (run, derived) = run(&ctx, file)?;
        if let (Some(rel), Run::Inverse { motion }) = (&file.excitation.motion_csv, &run) {
            crate::units::check_displacement_record(
                &ctx.resolve(rel),
                motion.t_s(),
                motion.u_m(),
                start.limits.stroke_m,
            )?;
        }
        if file.table_system.is_some() {
            refuse_force(&ctx, file, &run)?;
        }
        let rig = start.finish(&ctx, &keys)?;
        let run = match (&rig.table_system, run) {
            (Some(system), Run::Inverse { motion }) => Run::ClosedLoop {
                settings: LoopSettings::validate(
                    &ctx,
                    file.integrator.as_ref(),
                    file.initial.as_ref(),
                    &rig,
                    system,
                )?,
                command: motion,
            },
            (_, run) => run,
        };
        if rig.specimen.as_ref().is_some_and(Specimen::is_hysteretic)
            && matches!(run, Run::ClosedLoop { .. })
        {
            let i = file
                .specimen
                .as_ref()
                .and_then(|s| s.storeys.iter().position(|st| st.hysteresis.is_some()))
                .unwrap_or(0);
            return Err(ctx.invalid(
                &format!("specimen.storeys[{i}].hysteresis"),
                "(given)",
                "no table_system: a yielding storey runs on forward and inverse runs so \
                 far (the closed loop takes linear storeys)",
            ));
        }
        Ok(Self {
            name: scenario_name(path, file.name.as_deref()),
            rig,
            run,
            derived,
        })
    }
}

/// The error of a scenario with a `table_system` whose excitation is a force: the motion is
/// the displacement command and the loop makes the force.
fn refuse_force(ctx: &Ctx, file: &ScenarioFile, run: &Run) -> Result<()> {
    if let Run::Forward { .. } = run {
        let key = if file.excitation.force_csv.is_some() {
            "excitation.force_csv"
        } else if file.excitation.sine_force.is_some() {
            "excitation.sine_force"
        } else {
            "excitation"
        };
        return Err(ctx.invalid(
            key,
            "a force",
            "a motion excitation (motion_csv, ground_motion, sine_motion, …): with a \
             `table_system` the motion is the displacement command and the loop makes the force",
        ));
    }
    Ok(())
}
