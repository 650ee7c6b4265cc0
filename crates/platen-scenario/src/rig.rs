//! What the table *is* ([`Rig`]: its model, limits, table system and specimen), apart from
//! what it *does* ([`crate::Run`]), and a rig read from a scenario file without a run
//! ([`Rig::load`], [`LoadedRig`]: what a planner drives with its own commands).
//!
//! ```
//! use std::path::{Path, PathBuf};
//! use platen_scenario::LoadedRig;
//!
//! // A scenario file without an excitation: the rig and how its loop is integrated.
//! let loaded = LoadedRig::parse(
//!     Path::new("rig.json"),
//!     r#"{"model": {"preset": "lhpost-2008"}, "table_system": {"preset": "lhpost-2008"}}"#,
//! )?;
//! assert!(loaded.rig.table_system.is_some() && loaded.loop_settings()?.is_some());
//! assert_eq!(loaded.rig.limits.stroke_m, 0.75);
//! # Ok::<(), platen_scenario::ScenarioError>(())
//! ```

use std::path::{Path, PathBuf};

use serde::de::IgnoredAny;
use serde::Deserialize;

use platen_integrate::{LoopMethod, State};
use platen_io::json::{parse_json, parse_json_file};
use platen_model::{ModelError, Preset, Specimen, TableLimits};
use platen_system::TableSystem;

use crate::ctx::{check_finite, check_positive, Ctx};
use crate::error::{Result, ScenarioError};
use crate::file::{InitialSpec, IntegratorSpec, LimitsSpec, ModelSpec, ScenarioFile, SpecimenSpec};
use crate::model::{build_model, model_overrides, Model, ModelKey, ModelOverrides};
use crate::system::{build_table_system, loop_method};
use crate::system_file::TableSystemSpec;

/// What the table is: its model (a preset at a hold-down pressure, with the scenario's values
/// laid over it), its limits, the loop around the platen (a table system) if any, and the
/// specimen on the platen if any. A [`crate::Run`] says what it does.
#[derive(Debug, Clone, PartialEq)]
pub struct Rig {
    /// The preset the model is based on.
    pub preset: Preset,
    /// The hold-down pressure, Pa.
    pub hold_down_pressure_pa: f64,
    /// The model.
    pub model: Model,
    /// The form and the values laid over the preset: what rebuilds the model at another
    /// pressure or with other parameter values ([`Rig::model_at`]).
    pub overrides: ModelOverrides,
    /// The table's limits (the preset's, with the scenario's `limits` laid over them).
    pub limits: TableLimits,
    /// The loop around the platen (controller, servo-valves, actuators, supply), if any: a
    /// motion given to the rig is then the displacement command of a closed loop.
    pub table_system: Option<TableSystem>,
    /// The specimen on the platen, if any.
    pub specimen: Option<Specimen>,
}

impl Rig {
    /// Number of storeys of the specimen (0 without one).
    pub fn storeys(&self) -> usize {
        self.specimen.as_ref().map_or(0, Specimen::len)
    }

    /// The moving mass at mid-stroke with the specimen as a rigid payload, kg.
    pub fn moving_mass_kg(&self) -> f64 {
        self.model.mass_kg_at(0.0) + self.specimen.as_ref().map_or(0.0, Specimen::total_mass_kg)
    }

    /// The rig at another hold-down pressure: its model rebuilt from its preset at
    /// `pressure_pa` with its own overrides.
    ///
    /// # Errors
    /// As [`ModelOverrides::build`].
    pub fn at_pressure(mut self, pressure_pa: f64) -> std::result::Result<Rig, ModelError> {
        self.model = self.model_at(pressure_pa, &[])?;
        self.hold_down_pressure_pa = pressure_pa;
        Ok(self)
    }

    /// The rig's model rebuilt from its preset at `pressure_pa`, with its own overrides and
    /// then `extra` laid over it (what a sweep varies).
    ///
    /// # Errors
    /// As [`ModelOverrides::build`].
    pub fn model_at(
        &self,
        pressure_pa: f64,
        extra: &[(ModelKey, f64)],
    ) -> std::result::Result<Model, ModelError> {
        self.overrides.build(self.preset, pressure_pa, extra)
    }

    /// The rig of the scenario file at `path`: its model, limits, table system and
    /// specimen. The run's keys (`excitation`, `duration_s`, `integrator`, `initial`) may be
    /// absent; when present they are not validated and no record is read
    /// ([`LoadedRig::load`]).
    ///
    /// # Errors
    /// Any [`crate::ScenarioError`] of the rig's keys, as [`crate::PlatenScenario::load`] reports
    /// it: unreadable file, malformed JSON or unknown key (with its line and JSON path),
    /// invalid values (with their JSON path and what was expected).
    pub fn load(path: &Path) -> Result<Rig> {
        LoadedRig::load(path).map(|loaded| loaded.rig)
    }

    /// The model, limits, specimen and table system of `keys`, in the order a scenario
    /// validates them (the run's keys between the limits and the specimen: [`RigStart`]).
    pub(crate) fn validate(ctx: &Ctx, keys: &RigKeys) -> Result<Rig> {
        RigStart::validate(ctx, keys)?.finish(ctx, keys)
    }
}

/// How a closed loop is integrated and where the platen starts: the scenario's `integrator`
/// and `initial` for a rig with a table system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSettings {
    /// The integrator.
    pub method: LoopMethod,
    /// The platen's state at the command's first sample (`None`: at rest at the command's
    /// first displacement).
    pub initial: Option<State>,
}

impl LoopSettings {
    /// The platen's initial state for `command_u0_m`, the command's first displacement.
    pub fn initial_state(&self, command_u0_m: f64) -> State {
        self.initial.unwrap_or(State {
            u_m: command_u0_m,
            v_m_s: 0.0,
        })
    }

    /// The settings the file's `integrator` and `initial` give the closed loop of `system`
    /// on `rig`, with JSON paths in their errors.
    pub(crate) fn validate(
        ctx: &Ctx,
        integrator: Option<&IntegratorSpec>,
        initial: Option<&InitialSpec>,
        rig: &Rig,
        system: &TableSystem,
    ) -> Result<LoopSettings> {
        let stroke_m = rig.limits.stroke_m;
        let method = loop_method(ctx, integrator, system, rig.moving_mass_kg(), stroke_m)?;
        let initial = match initial {
            None => None,
            Some(init) => {
                if init.from_record {
                    return Err(ctx.invalid(
                        "initial.from_record",
                        true,
                        "`u_m` and `v_m_s`: a closed loop has no force record to take them from",
                    ));
                }
                Some(State {
                    u_m: check_finite(ctx, "initial.u_m", init.u_m.unwrap_or(0.0))?,
                    v_m_s: check_finite(ctx, "initial.v_m_s", init.v_m_s.unwrap_or(0.0))?,
                })
            }
        };
        Ok(LoopSettings { method, initial })
    }
}

/// A rig read from a scenario file without a run ([`LoadedRig::load`]): its name, the rig,
/// and the file's settings for the closed-loop runs it may be given
/// ([`LoadedRig::loop_settings`]): what `platen plan` drives with its own commands and
/// `platen model --scenario` describes.
#[derive(Debug, Clone)]
pub struct LoadedRig {
    /// The scenario's name (default: the file stem).
    pub name: String,
    /// The rig.
    pub rig: Rig,
    /// The `table_system.preset` the file names, if any.
    pub table_system_preset: Option<String>,
    path: PathBuf,
    integrator: Option<IntegratorSpec>,
    initial: Option<InitialSpec>,
}

impl LoadedRig {
    /// Reads the scenario file at `path` for its rig: its model, limits, table system and
    /// specimen. The run's keys (`excitation`, `duration_s`, `integrator`, `initial`) may be
    /// absent; the excitation and duration are not read (nor their records), the integrator
    /// and initial state only by [`LoadedRig::loop_settings`].
    ///
    /// # Errors
    /// Any [`crate::ScenarioError`] of the rig's keys, as [`crate::PlatenScenario::load`] reports
    /// it: unreadable file, malformed JSON or unknown key (with its line and JSON path),
    /// invalid values (with their JSON path and what was expected).
    pub fn load(path: &Path) -> Result<LoadedRig> {
        Self::validate(path, parse_json_file(path)?)
    }

    /// [`LoadedRig::load`] of the scenario JSON `text`, named `path` in messages (relative
    /// paths resolve against its folder).
    ///
    /// # Errors
    /// As [`LoadedRig::load`].
    pub fn parse(path: &Path, text: &str) -> Result<LoadedRig> {
        Self::validate(path, parse_json(path, text)?)
    }

    fn validate(path: &Path, file: RigFile) -> Result<LoadedRig> {
        let rig = Rig::validate(&Ctx { path }, &file.keys())?;
        Ok(LoadedRig {
            name: scenario_name(path, file.name.as_deref()),
            rig,
            table_system_preset: file.table_system.and_then(|t| t.preset),
            path: path.to_owned(),
            integrator: file.integrator,
            initial: file.initial,
        })
    }

    /// The settings the file's `integrator` and `initial` give the rig's closed loop
    /// (`None` without a table system).
    ///
    /// # Errors
    /// An invalid integrator (a step that does not divide the controller's period or cannot
    /// resolve the loop, a bad tolerance) or initial state, with its JSON path.
    pub fn loop_settings(&self) -> Result<Option<LoopSettings>> {
        let Some(system) = &self.rig.table_system else {
            return Ok(None);
        };
        let ctx = Ctx { path: &self.path };
        LoopSettings::validate(
            &ctx,
            self.integrator.as_ref(),
            self.initial.as_ref(),
            &self.rig,
            system,
        )
        .map(Some)
    }
}

/// The scenario's `name`, or the file stem.
pub(crate) fn scenario_name(path: &Path, name: Option<&str>) -> String {
    name.map(str::to_owned).unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    })
}

/// A scenario file read for its rig: [`ScenarioFile`]'s keys, with the run's excitation and
/// duration optional and not read (kept in step with [`ScenarioFile`]: an unknown key is
/// an error in both; named as it is in serde's messages).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "ScenarioFile")]
struct RigFile {
    #[serde(rename = "$schema")]
    #[allow(dead_code)]
    schema: Option<IgnoredAny>,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<IgnoredAny>,
    model: ModelSpec,
    #[allow(dead_code)]
    excitation: Option<IgnoredAny>,
    integrator: Option<IntegratorSpec>,
    initial: Option<InitialSpec>,
    #[allow(dead_code)]
    duration_s: Option<IgnoredAny>,
    limits: Option<LimitsSpec>,
    specimen: Option<SpecimenSpec>,
    table_system: Option<TableSystemSpec>,
}

impl RigFile {
    fn keys(&self) -> RigKeys<'_> {
        RigKeys {
            model: &self.model,
            limits: self.limits.as_ref(),
            specimen: self.specimen.as_ref(),
            table_system: self.table_system.as_ref(),
        }
    }
}

/// The keys of a scenario file that make its rig.
pub(crate) struct RigKeys<'a> {
    pub(crate) model: &'a ModelSpec,
    pub(crate) limits: Option<&'a LimitsSpec>,
    pub(crate) specimen: Option<&'a SpecimenSpec>,
    pub(crate) table_system: Option<&'a TableSystemSpec>,
}

impl<'a> RigKeys<'a> {
    /// The rig's keys of a whole scenario file of the uniaxial platen.
    ///
    /// # Errors
    /// A file without `model` (a multi-axis file, with a `table`, is not a rig of the
    /// uniaxial platen: [`crate::multi_axis::TableScenario`]).
    pub(crate) fn of(ctx: &Ctx, file: &'a ScenarioFile) -> Result<Self> {
        if file.table.is_some() {
            return Err(ScenarioError::MultiAxis {
                path: ctx.path.to_owned(),
            });
        }
        let model = file.model.as_ref().ok_or_else(|| {
            ctx.invalid(
                "model",
                "(absent)",
                "a model, for example {\"preset\": \"lhpost-2008\"} (or a multi-axis `table`)",
            )
        })?;
        Ok(RigKeys {
            model,
            limits: file.limits.as_ref(),
            specimen: file.specimen.as_ref(),
            table_system: file.table_system.as_ref(),
        })
    }
}

/// The first half of a rig's validation (model and limits): a scenario validates its run
/// next, so that a bad excitation is reported before a bad specimen or table system, then
/// [`RigStart::finish`]es the rig.
pub(crate) struct RigStart {
    preset: Preset,
    hold_down_pressure_pa: f64,
    model: Model,
    overrides: ModelOverrides,
    pub(crate) limits: TableLimits,
}

impl RigStart {
    /// The model and limits of `keys`.
    pub(crate) fn validate(ctx: &Ctx, keys: &RigKeys) -> Result<RigStart> {
        let spec = keys.model;
        let preset = Preset::from_name(&spec.preset).map_err(|e| {
            ctx.invalid("model.preset", format!("{:?}", spec.preset), e.to_string())
        })?;
        let pressure_pa = match spec.hold_down_pressure_mpa {
            Some(p) => match crate::units::expected_pressure_mpa(p) {
                Some(expected) => {
                    return Err(ctx.invalid("model.hold_down_pressure_mpa", p, expected))
                }
                None => p * 1e6,
            },
            None => preset.nominal_pressure_pa(),
        };
        let overrides = model_overrides(ctx, spec)?;
        let model = build_model(ctx, preset, pressure_pa, &overrides)?;
        let limits = table_limits(ctx, preset, keys.limits)?;
        Ok(RigStart {
            preset,
            hold_down_pressure_pa: pressure_pa,
            model,
            overrides,
            limits,
        })
    }

    /// The rig: the specimen and the table system of `keys` added.
    pub(crate) fn finish(self, ctx: &Ctx, keys: &RigKeys) -> Result<Rig> {
        let specimen = crate::specimen::platen_specimen(ctx, keys.specimen)?;
        let table_system = keys
            .table_system
            .map(|spec| build_table_system(ctx, spec, self.limits.stroke_m))
            .transpose()?;
        Ok(Rig {
            preset: self.preset,
            hold_down_pressure_pa: self.hold_down_pressure_pa,
            model: self.model,
            overrides: self.overrides,
            limits: self.limits,
            table_system,
            specimen,
        })
    }
}

/// The preset's table limits with the scenario's `limits` laid over them.
fn table_limits(ctx: &Ctx, preset: Preset, given: Option<&LimitsSpec>) -> Result<TableLimits> {
    let mut limits = preset.limits();
    let Some(given) = given else {
        return Ok(limits);
    };
    for (name, value, slot) in [
        ("stroke_m", given.stroke_m, &mut limits.stroke_m),
        ("velocity_m_s", given.velocity_m_s, &mut limits.velocity_m_s),
        (
            "acceleration_m_s2",
            given.acceleration_m_s2,
            &mut limits.acceleration_m_s2,
        ),
        ("force_n", given.force_n, &mut limits.force_n),
    ] {
        if let Some(v) = value {
            *slot = check_positive(ctx, &format!("limits.{name}"), v)?;
        }
    }
    Ok(limits)
}
