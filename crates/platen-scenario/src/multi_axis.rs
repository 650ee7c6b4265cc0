//! Scenarios of a multi-axis (six-DOF) table: a scenario file with a `table` (see the
//! contract in `docs/multi-axis.md`). [`TableSpec`] is the key as written; [`TableScenario`]
//! the validated scenario and its run.
//!
//! What runs:
//! * the **inverse** of a prescribed six-DOF motion (`excitation.motion_csv` with `t_s` and
//!   any of `x_m` … `yaw_rad`, absent ones at 0, optional rates `x_m_s` … and accelerations
//!   `x_m_s2` …, derived from the pose where absent; or `excitation.ground_motion` per axis),
//!   with a storeys or general linear specimen;
//! * the **forward** run from recorded actuator forces (`excitation.force_csv`);
//! * the **closed loop** when the table has a `controller`: the same motion excitations are
//!   the DOF controller's command, and every actuator has its servo-valves.
//!
//! `{"preset": "lhpost6"}` lays the given values over the LHPOST6's (see `docs/lhpost6.md`).

use std::path::{Path, PathBuf};

use nalgebra::{DMatrix, Matrix3, Unit, Vector3};
use serde::Serialize;

use platen_integrate::{
    forward_table, forward_table_loop, inverse_table, ActuatorForces, ForceRecord, LoopMethod,
    Method, PoseMotion, TableLoopRun, TableLoopStats, TableRun,
};
use platen_model::multi_axis::{
    Actuator, Bearing, BearingLoad, Coords, Dof, DofSet, LinearSpecimen, Mount, MultiAxisTable,
    Pad, RigidPlaten, Strut, TableParts,
};
use platen_model::ModelError;
use platen_system::{
    open_loop, ActuatorHydraulics, DofController, DofGeometry, SystemError, TableHydraulics,
    TableHydraulicsParts,
};

use crate::ctx::{check_finite, check_positive, value_at, Ctx};
use crate::error::{Result, ScenarioError};
use crate::excitation::MotionGenerator;
use crate::excitation::{motion_run, read_mapped, Derived};
use crate::file::{GroundMotionSpec, ScenarioFile, SpecimenSpec};
use crate::scenario::Run;
use crate::system::{complete_servo_valve_under, controller_gains, loop_method_at, supply_under};
use crate::system_file::Overlay;
pub use crate::table_file::{
    ActuatorSpec, AxisLimitsSpec, BearingSpec, DofGainsSpec, PadSpec, PlatenSpec,
    RotationLimitSpec, StrutSpec, TableControllerSpec, TableSpec, TranslationLimitSpec,
};

/// How far from the reference point a table's points (and a specimen's levers, a pose) may
/// lie in a scenario, m (rad for a rotation): the largest shake tables span about 20 m, so a
/// value beyond is a unit slip (millimetres written as metres) or a typing error, refused at
/// its key.
pub const PLAUSIBLE_GEOMETRY_M: f64 = 100.0;

/// The fastest a scenario's pose may move, m/s (rad/s for a rotation): shake tables reach a
/// few m/s, so a rate beyond is a unit slip (mm/s written as m/s), refused at its key.
pub const PLAUSIBLE_RATE_M_S: f64 = 100.0;
/// The largest acceleration a scenario's pose may have, m/s² (rad/s² for a rotation): about
/// 100 g, ten times any shake table's; beyond is a unit slip (mm/s² written as m/s²).
pub const PLAUSIBLE_ACCELERATION_M_S2: f64 = 1000.0;

/// Default oil bulk modulus, Pa.
pub const DEFAULT_OIL_BULK_MODULUS_PA: f64 = 1.5e9;
/// Default supply pressure, Pa (3 000 psi).
pub const DEFAULT_SUPPLY_PRESSURE_PA: f64 = 20.7e6;
/// Default return pressure, Pa.
pub const DEFAULT_RETURN_PRESSURE_PA: f64 = 0.5e6;

/// The pose columns of a six-DOF motion or run, x … yaw.
pub const POSE_COLUMNS: [&str; 6] = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"];
/// Their rates.
pub const RATE_COLUMNS: [&str; 6] = [
    "x_m_s",
    "y_m_s",
    "z_m_s",
    "roll_rad_s",
    "pitch_rad_s",
    "yaw_rad_s",
];
/// Their second derivatives.
pub const ACCELERATION_COLUMNS: [&str; 6] = [
    "x_m_s2",
    "y_m_s2",
    "z_m_s2",
    "roll_rad_s2",
    "pitch_rad_s2",
    "yaw_rad_s2",
];

/// What a multi-axis scenario runs.
#[derive(Debug, Clone, PartialEq)]
pub enum TableRunSpec {
    /// The actuator forces a prescribed six-DOF motion needs.
    Inverse {
        /// The motion (boxed: six channels of four vectors each).
        motion: Box<PoseMotion>,
    },
    /// The closed loop: the motion is the DOF controller's command.
    Loop {
        /// The command (boxed: six channels of four vectors each).
        command: Box<PoseMotion>,
    },
    /// The motion recorded actuator forces produce.
    Forward {
        /// One force record per actuator, in the table's order.
        forces: ActuatorForces,
        /// The integrator.
        method: Method,
        /// The pose and its rates at the first sample (`initial`; at rest at neutral by
        /// default).
        initial: (Coords, Coords),
    },
}

/// A validated scenario of a multi-axis table.
#[derive(Debug, Clone)]
pub struct TableScenario {
    /// Its name.
    pub name: String,
    /// The table.
    pub table: MultiAxisTable,
    /// The specimen on it, if any.
    pub specimen: Option<LinearSpecimen>,
    /// Supply pressure, Pa (the actuators' force limits).
    pub supply_pressure_pa: f64,
    /// Return pressure, Pa.
    pub return_pressure_pa: f64,
    /// What it runs.
    pub run: TableRunSpec,
    /// The motion's channels platen derived, with how.
    pub derived: Derived,
    /// The closed loop's hydraulics and controller, when the table has a `controller`.
    pub system: Option<TableLoopSystem>,
    /// The table's limits per axis (`table.limits`), validated.
    pub limits: crate::table_file::AxisLimitsSpec,
}

/// Where a scenario's motion comes from as it is built.
enum Given {
    /// Its `excitation`.
    File,
    /// A closed loop's command in place of its excitation (`platen plan`).
    Command(PoseMotion),
    /// A still motion in place of its excitation (`platen model`, which does not run it).
    Still(PoseMotion),
}

/// The closed loop around a multi-axis table.
#[derive(Debug, Clone)]
pub struct TableLoopSystem {
    /// Its actuators' hydraulics and supply.
    pub hydraulics: TableHydraulics,
    /// Its DOF controller.
    pub controller: DofController,
    /// The integrator.
    pub method: LoopMethod,
}

impl TableScenario {
    /// Validates a parsed scenario file that has a `table`.
    ///
    /// # Errors
    /// Every bad value with its JSON path (`table.actuators[2].platen_m`, …) and every error
    /// of the motion record (with file and line); a file without `table` is refused.
    pub fn from_file(path: &Path, file: &ScenarioFile) -> Result<Self> {
        Self::build(path, file, None)
    }

    /// The closed loop of a scenario file that has a `table` with a `controller`, commanded
    /// by `command` instead of the file's excitation (which is ignored, and may be absent):
    /// what `platen plan` drives.
    ///
    /// # Errors
    /// As [`TableScenario::from_file`]; a table without a `controller`.
    pub fn commanded_from_file(
        path: &Path,
        file: &ScenarioFile,
        command: PoseMotion,
    ) -> Result<Self> {
        Self::build(path, file, Some(command))
    }

    /// The scenario as `platen model` describes it: its table, specimen, limits and loop,
    /// with a still motion in place of its excitation, which is not read (a scenario whose
    /// PEER records are absent is described all the same).
    ///
    /// # Errors
    /// As [`TableScenario::from_file`] for everything but the excitation.
    pub fn for_description(path: &Path, file: &ScenarioFile) -> Result<Self> {
        let zero = || vec![0.0; 2];
        let dofs: [platen_signal::Motion; 6] = std::array::from_fn(|_| {
            platen_signal::Motion::new(vec![0.0, 1.0], zero(), zero(), zero())
                .expect("two increasing stamps and finite zeros make a motion")
        });
        let still = PoseMotion::new(dofs).map_err(ScenarioError::TableRun)?;
        Self::build_with(path, file, Given::Still(still))
    }

    /// The same closed loop commanded by `command`.
    ///
    /// # Errors
    /// [`ScenarioError::Io`] (the invalid field `table.controller`) if this scenario is not a
    /// closed loop.
    pub fn commanded(&self, command: PoseMotion) -> Result<Self> {
        if self.system.is_none() {
            let ctx = Ctx {
                path: Path::new(&self.name),
            };
            return Err(ctx.invalid(
                "table.controller",
                "(absent)",
                "a DOF controller: only a closed loop follows a command",
            ));
        }
        Ok(TableScenario {
            run: TableRunSpec::Loop {
                command: Box::new(command),
            },
            derived: Derived::new(),
            ..self.clone()
        })
    }

    /// [`TableScenario::from_file`], or with `command` as the closed loop's command in
    /// place of the file's excitation.
    fn build(path: &Path, file: &ScenarioFile, command: Option<PoseMotion>) -> Result<Self> {
        Self::build_with(path, file, command.map_or(Given::File, Given::Command))
    }

    /// [`TableScenario::build`] with the motion `given`.
    fn build_with(path: &Path, file: &ScenarioFile, given_motion: Given) -> Result<Self> {
        let ctx = Ctx { path };
        let Some(given) = &file.table else {
            return Err(ctx.invalid("table", "(absent)", "a multi-axis table"));
        };
        let spec = resolve_preset(&ctx, given)?;
        let spec = &spec;
        let closed = spec.controller.is_some();
        for (key, given, expected) in [
            ("model", file.model.is_some(), "no such key beside a `table` (the table holds its platen)"),
            ("table_system", file.table_system.is_some(), "no such key beside a `table` (the table holds its hydraulics and `controller`)"),
            ("limits", file.limits.is_some(), "no such key beside a `table`: its limits per axis are `table.limits`"),
            (
                "initial",
                file.initial.is_some() && file.excitation.force_csv.is_none(),
                "no such key here: an initial state belongs to a forward run, from `force_csv` (a closed loop starts at rest at neutral)",
            ),
            (
                "integrator",
                file.integrator.is_some() && file.excitation.force_csv.is_none() && !closed,
                "no such key here: an integrator belongs to a forward run (`force_csv`) or a closed loop (a `table.controller`)",
            ),
        ] {
            if given {
                return Err(ctx.invalid(key, "(given)", expected));
            }
        }
        let table = build_table(&ctx, spec)?;
        let specimen = build_specimen(&ctx, file.specimen.as_ref())?;
        let limits = build_limits(&ctx, spec)?;
        let system = match &spec.controller {
            Some(c) => Some(build_system(
                &ctx,
                file.integrator.as_ref(),
                spec,
                c,
                &table,
                specimen.as_ref(),
            )?),
            None => None,
        };
        let (run, derived) = match given_motion {
            Given::File => build_run(&ctx, file, &table, closed)?,
            Given::Still(still) => (
                if closed {
                    TableRunSpec::Loop {
                        command: Box::new(still),
                    }
                } else {
                    TableRunSpec::Inverse {
                        motion: Box::new(still),
                    }
                },
                Derived::new(),
            ),
            Given::Command(_) if !closed => {
                return Err(ctx.invalid(
                    "table.controller",
                    "(absent)",
                    "a DOF controller: only a closed loop follows a command",
                ))
            }
            Given::Command(command) => (
                TableRunSpec::Loop {
                    command: Box::new(command),
                },
                Derived::new(),
            ),
        };
        if let (Some(sys), TableRunSpec::Loop { command }) = (&system, &run) {
            crate::loop_budget::check_steps(
                &ctx,
                spec,
                &table,
                specimen.as_ref(),
                &crate::loop_budget::LoopCost {
                    hydraulics: &sys.hydraulics,
                    period_s: sys.controller.period_s(),
                    steps_per_period: sys.method.steps_per_period(),
                },
                command,
            )?;
        }
        let pressure = |key: &str, v: Option<f64>, default: f64| match v {
            Some(p) => check_positive(&ctx, &format!("table.{key}"), p),
            None => Ok(default),
        };
        Ok(TableScenario {
            name: crate::rig::scenario_name(path, file.name.as_deref()),
            table,
            specimen,
            supply_pressure_pa: pressure(
                "supply_pressure_pa",
                spec.supply_pressure_pa,
                DEFAULT_SUPPLY_PRESSURE_PA,
            )?,
            return_pressure_pa: pressure(
                "return_pressure_pa",
                spec.return_pressure_pa,
                DEFAULT_RETURN_PRESSURE_PA,
            )?,
            run,
            derived,
            system,
            limits,
        })
    }

    /// Runs it, with the closed loop's own figures when it is one.
    ///
    /// # Errors
    /// As [`TableScenario::run`].
    pub fn run_with_stats(&self) -> Result<(TableRun, Option<TableLoopStats>)> {
        if let (TableRunSpec::Loop { command }, Some(sys)) = (&self.run, &self.system) {
            return forward_table_loop(&TableLoopRun {
                table: &self.table,
                hydraulics: &sys.hydraulics,
                controller: &sys.controller,
                specimen: self.specimen.as_ref(),
                command,
                method: sys.method,
            })
            .map(|(run, stats)| (run, Some(stats)))
            .map_err(|source| {
                // A loop that diverged: say that it is unstable, where, and in which DOF.
                match self
                    .linearisation()
                    .and_then(|lin| loop_verdict_stability(&lin).unstable_words())
                {
                    Some(verdict) => ScenarioError::TableLoopUnstable { verdict, source },
                    None => ScenarioError::TableRun(source),
                }
            });
        }
        self.run().map(|run| (run, None))
    }

    /// Runs it.
    ///
    /// # Errors
    /// [`ScenarioError::TableRun`] when the actuators lose rank at a pose of the motion
    /// (inverse) or the integration fails (forward: a non-finite state, Dopri5 unable to meet
    /// its tolerance).
    pub fn run(&self) -> Result<TableRun> {
        let run = match &self.run {
            TableRunSpec::Inverse { motion } => {
                inverse_table(&self.table, self.specimen.as_ref(), motion)
            }
            TableRunSpec::Forward {
                forces,
                method,
                initial,
            } => forward_table(
                &self.table,
                self.specimen.as_ref(),
                forces,
                *method,
                initial.0,
                initial.1,
            ),
            TableRunSpec::Loop { .. } => return self.run_with_stats().map(|(run, _)| run),
        };
        run.map_err(ScenarioError::TableRun)
    }

    /// What `platen generate excitation` writes for this scenario: its six-DOF motion (the
    /// prescribed motion or a closed loop's command: `t_s`, the pose, its rates and
    /// accelerations, a `motion_csv` that `simulate` takes as it is and a three-component
    /// target for `platen plan`), or its recorded actuator forces (`t_s`, `{name}_force_n`):
    /// the column names, the columns, and the kind (`motion` or `force`).
    pub fn excitation_columns(&self) -> (Vec<String>, Vec<&[f64]>, &'static str) {
        let mut names = vec!["t_s".to_owned()];
        match &self.run {
            TableRunSpec::Inverse { motion } | TableRunSpec::Loop { command: motion } => {
                let dofs = Dof::ALL.map(|d| motion.dof(d));
                let mut columns: Vec<&[f64]> = vec![dofs[0].t_s()];
                for (k, m) in dofs.iter().enumerate() {
                    names.push(POSE_COLUMNS[k].to_owned());
                    columns.push(m.u_m());
                }
                for (k, m) in dofs.iter().enumerate() {
                    names.push(RATE_COLUMNS[k].to_owned());
                    columns.push(m.v_m_s());
                }
                for (k, m) in dofs.iter().enumerate() {
                    names.push(ACCELERATION_COLUMNS[k].to_owned());
                    columns.push(m.a_m_s2());
                }
                (names, columns, "motion")
            }
            TableRunSpec::Forward { forces, .. } => {
                let actuators = self.table.actuators();
                names.extend(actuators.iter().map(|a| format!("{}_force_n", a.name)));
                let mut columns: Vec<&[f64]> = vec![forces.t_s()];
                columns.extend((0..actuators.len()).map(|i| forces.force_n(i)));
                (names, columns, "force")
            }
        }
    }

    /// Each actuator's valves' flow capacity at the supply pressure,
    /// `m·Q_r·√((P_s − P_R)/Δp_r)`, m³/s, in the table's order (`None` without a closed loop).
    pub fn flow_capacities_m3_s(&self) -> Option<Vec<f64>> {
        let sys = self.system.as_ref()?;
        Some(
            sys.hydraulics
                .actuators()
                .iter()
                .map(|a| {
                    let v = a.servo_valve;
                    f64::from(v.count)
                        * v.rated_flow_m3_s
                        * ((self.supply_pressure_pa - self.return_pressure_pa)
                            / v.rated_pressure_drop_pa)
                            .sqrt()
                })
                .collect(),
        )
    }

    /// Each actuator's force limits `(pull ≤ 0, push ≥ 0)`, N, in the table's order.
    pub fn force_limits_n(&self) -> Vec<(f64, f64)> {
        self.table
            .actuators()
            .iter()
            .map(|a| a.force_limits_n(self.supply_pressure_pa, self.return_pressure_pa))
            .collect()
    }
}

/// The error of a model-layer refusal of the table, at its JSON path under `table`.
fn table_error(ctx: &Ctx, spec: &TableSpec, e: ModelError) -> ScenarioError {
    let json = serde_json::to_value(spec).unwrap_or_default();
    match e {
        ModelError::InvalidTable { path, expected } => {
            let value = value_at(&json, &path);
            ctx.invalid(&format!("table.{path}"), value, expected)
        }
        ModelError::UncontrolledDof { .. } => {
            ctx.invalid("table.actuators", "(these actuators)", e.to_string())
        }
        other => ctx.invalid("table", "", other.to_string()),
    }
}

fn vector(p: [f64; 3]) -> Vector3<f64> {
    Vector3::from(p)
}

impl TableSpec {
    /// The validated table of this spec; errors name `origin` as the scenario file.
    ///
    /// # Errors
    /// As [`TableScenario::from_file`] for the `table` key.
    pub fn build(&self, origin: &Path) -> Result<MultiAxisTable> {
        build_table(&Ctx { path: origin }, self)
    }

    /// The validated table of this spec (its preset laid under it) and its closed loop
    /// (`None` without a `controller`), bare, with the default integrator; errors name
    /// `origin` as the scenario file.
    ///
    /// # Errors
    /// As [`TableScenario::from_file`] for the `table` key.
    pub fn build_with_loop(
        &self,
        origin: &Path,
    ) -> Result<(MultiAxisTable, Option<TableLoopSystem>)> {
        let ctx = Ctx { path: origin };
        let spec = resolve_preset(&ctx, self)?;
        let table = build_table(&ctx, &spec)?;
        let system = match &spec.controller {
            Some(c) => Some(build_system(&ctx, None, &spec, c, &table, None)?),
            None => None,
        };
        Ok((table, system))
    }
}

/// Every point of `table` within [`PLAUSIBLE_GEOMETRY_M`] of the reference point.
fn check_geometry(ctx: &Ctx, spec: &TableSpec) -> Result<()> {
    let mut points: Vec<(String, [f64; 3])> = Vec::new();
    if let Some(p) = &spec.platen {
        points.push(("platen.centre_of_mass_m".into(), p.centre_of_mass_m));
    }
    for (i, a) in spec.actuators.iter().enumerate() {
        points.push((format!("actuators[{i}].base_m"), a.base_m));
        if let Some(p) = a.platen_m {
            points.push((format!("actuators[{i}].platen_m"), p));
        }
        if let Some(pad) = &a.pad {
            points.push((format!("actuators[{i}].pad.contact_m"), pad.contact_m));
        }
    }
    for (j, st) in spec.hold_down_struts.iter().enumerate() {
        points.push((format!("hold_down_struts[{j}].base_m"), st.base_m));
        points.push((format!("hold_down_struts[{j}].platen_m"), st.platen_m));
    }
    for (k, b) in spec.bearings.iter().enumerate() {
        points.push((format!("bearings[{k}].platen_m"), b.platen_m));
    }
    for (path, p) in points {
        if p.iter()
            .any(|c| c.is_finite() && c.abs() > PLAUSIBLE_GEOMETRY_M)
        {
            return Err(ctx.invalid(
                &format!("table.{path}"),
                format!("{p:?}"),
                format!(
                    "a point within {PLAUSIBLE_GEOMETRY_M} m of the reference point, m (a table \
                     spans about 20 m: beyond is a unit slip, millimetres written as metres, or a \
                     typing error)"
                ),
            ));
        }
    }
    Ok(())
}

/// `table` into a validated table.
fn build_table(ctx: &Ctx, spec: &TableSpec) -> Result<MultiAxisTable> {
    check_geometry(ctx, spec)?;
    let platen = spec.platen.as_ref().ok_or_else(|| {
        ctx.invalid(
            "table.platen",
            "(absent)",
            "the rigid platen: {\"mass_kg\", \"inertia_kg_m2\", \"centre_of_mass_m\"}",
        )
    })?;
    let platen = RigidPlaten::new(
        platen.mass_kg,
        Matrix3::from_fn(|r, c| platen.inertia_kg_m2[r][c]),
        vector(platen.centre_of_mass_m),
    )
    .map_err(|e| table_error(ctx, spec, e))?;
    let mut actuators = Vec::with_capacity(spec.actuators.len());
    for (i, a) in spec.actuators.iter().enumerate() {
        let at = |k: &str| format!("table.actuators[{i}].{k}");
        let mount = match (&a.platen_m, &a.pad) {
            (Some(p), None) => Mount::Swivel {
                platen_m: vector(*p),
            },
            (None, Some(pad)) => {
                let axis = vector(pad.axis.unwrap_or([0.0, 0.0, 1.0]));
                if !(axis.iter().all(|c| c.is_finite()) && axis.norm() > 0.0) {
                    return Err(ctx.invalid(
                        &at("pad.axis"),
                        format!("{:?}", pad.axis),
                        "a non-zero direction",
                    ));
                }
                Mount::Pad(Pad {
                    axis: Unit::new_normalize(axis),
                    contact_m: vector(pad.contact_m),
                    friction_coefficient: pad.friction_coefficient,
                })
            }
            _ => {
                return Err(ctx.invalid(
                    &format!("table.actuators[{i}]"),
                    "(both or neither)",
                    "either `platen_m` (swivel-mounted) or `pad` (a bearing actuator)",
                ))
            }
        };
        actuators.push(Actuator {
            name: a.name.clone(),
            base_m: vector(a.base_m),
            mount,
            cap_side_area_m2: a.cap_side_area_m2,
            rod_side_area_m2: a.rod_side_area_m2,
            chamber_volume_m3: a.chamber_volume_m3,
            stroke_m: a.stroke_m,
        });
    }
    let struts = spec
        .hold_down_struts
        .iter()
        .map(|s| Strut {
            name: s.name.clone(),
            base_m: vector(s.base_m),
            platen_m: vector(s.platen_m),
            area_m2: s.area_m2,
            pressure_pa: s.pressure_pa,
            gas_volume_m3: s.gas_volume_m3,
            polytropic_exponent: s.polytropic_exponent,
        })
        .collect();
    let mut bearings = Vec::with_capacity(spec.bearings.len());
    for (k, b) in spec.bearings.iter().enumerate() {
        let at = |key: &str| format!("table.bearings[{k}].{key}");
        let load =
            match (&b.actuator, b.normal_force_n) {
                (Some(name), None) => {
                    let i = spec
                        .actuators
                        .iter()
                        .position(|a| &a.name == name)
                        .ok_or_else(|| {
                            ctx.invalid(
                                &at("actuator"),
                                format!("{name:?}"),
                                "the name of one of `table.actuators`",
                            )
                        })?;
                    BearingLoad::Actuator(i)
                }
                (None, Some(n)) => BearingLoad::Constant(n),
                _ => return Err(ctx.invalid(
                    &format!("table.bearings[{k}]"),
                    "(both or neither)",
                    "either `actuator` (the swivel-mounted actuator under it) or `normal_force_n`",
                )),
            };
        bearings.push(Bearing {
            platen_m: vector(b.platen_m),
            friction_coefficient: b.friction_coefficient,
            load,
        });
    }
    let mut held = DofSet::EMPTY;
    for (k, name) in spec.held_dofs.iter().enumerate() {
        let dof = Dof::from_name(name).ok_or_else(|| {
            ctx.invalid(
                &format!("table.held_dofs[{k}]"),
                format!("{name:?}"),
                "one of x, y, z, roll, pitch, yaw",
            )
        })?;
        if held.contains(dof) {
            return Err(ctx.invalid(
                &format!("table.held_dofs[{k}]"),
                format!("{name:?}"),
                "each DOF once",
            ));
        }
        held = held.with(dof);
    }
    MultiAxisTable::new(TableParts {
        platen,
        actuators,
        struts,
        bearings,
        held,
        oil_bulk_modulus_pa: spec
            .oil_bulk_modulus_pa
            .unwrap_or(DEFAULT_OIL_BULK_MODULUS_PA),
    })
    .map_err(|e| table_error(ctx, spec, e))
}

/// `excitation` of a multi-axis scenario: a six-DOF motion (`motion_csv`, or `ground_motion`
/// per axis), the inverse's prescribed motion or the closed loop's command (`closed`); or
/// recorded actuator forces (`force_csv`, a forward run, open loop).
fn build_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    table: &MultiAxisTable,
    closed: bool,
) -> Result<(TableRunSpec, Derived)> {
    let ex = &file.excitation;
    if let Some(rel) = &ex.force_csv {
        if closed {
            return Err(ctx.invalid(
                "excitation.force_csv",
                "(given)",
                "a motion (motion_csv or ground_motion): with a `table.controller` the \
                 excitation is the controller's command, and the actuator forces are the loop's",
            ));
        }
        return forward_run(ctx, file, table, &ctx.resolve(rel)).map(|r| (r, Derived::new()));
    }
    for (key, given) in [
        ("excitation.lowpass_hz", ex.lowpass_hz.is_some()),
        (
            "excitation.rest_velocity_m_s",
            ex.rest_velocity_m_s.is_some(),
        ),
    ] {
        if given {
            return Err(ctx.invalid(key, "(given)", "nothing: not used by a multi-axis motion"));
        }
    }
    let generators = MotionGenerator::per_axis(ex);
    let (motion, derived) = match (&ex.motion_csv, &ex.ground_motion, generators) {
        (Some(rel), None, None) => read_pose_motion(ctx, file, &ctx.resolve(rel))?,
        (None, Some(GroundMotionSpec::PerAxis(axes)), None) => axis_ground_motion(ctx, file, axes)?,
        (None, None, Some((key, axes))) if crate::excitation::named_sources(ex).len() == 1 => {
            axis_generated_motion(ctx, file, key, axes)?
        }
        _ => {
            let given = crate::excitation::named_sources(ex);
            let key = given
                .first()
                .map_or("excitation".to_owned(), |k| format!("excitation.{k}"));
            return Err(ctx.invalid(
                &key,
                "(given)",
                "one of motion_csv (a six-DOF motion), ground_motion per axis \
                 ({\"x\": {\"record\": …}, \"y\": …, \"z\": …}), sine_motion, \
                 triangle_motion or white_noise_motion per axis ({\"x\": {…}, \"z\": {…}}) \
                 or force_csv (`t_s` and `{name}_force_n` per actuator: a forward run)",
            ));
        }
    };
    let motion = Box::new(motion);
    Ok(if closed {
        (TableRunSpec::Loop { command: motion }, derived)
    } else {
        (TableRunSpec::Inverse { motion }, derived)
    })
}

/// A six-DOF motion record: `t_s` and any of the pose columns (absent ones 0), their rates
/// and accelerations derived where absent, cut to `duration_s`.
fn read_pose_motion(ctx: &Ctx, file: &ScenarioFile, path: &Path) -> Result<(PoseMotion, Derived)> {
    let ex = &file.excitation;
    let optional: Vec<&'static str> = POSE_COLUMNS
        .iter()
        .chain(&RATE_COLUMNS)
        .chain(&ACCELERATION_COLUMNS)
        .copied()
        .collect();
    let mut cols = read_mapped(ctx, path, ex, &["t_s"], &optional)?;
    if !POSE_COLUMNS.iter().any(|c| cols.contains_key(c)) {
        return Err(ScenarioError::Io(platen_io::IoError::Record {
            path: path.to_owned(),
            message: "a six-DOF motion needs at least one of the columns x_m, y_m, z_m, \
                      roll_rad, pitch_rad, yaw_rad (absent ones are 0)"
                .into(),
        }));
    }
    // A pose beyond any table's reach is a unit slip (mm written as m), refused where it is
    // read: a run of it would end non-finite, or ride on a stroke limit with nothing said.
    let bounded = POSE_COLUMNS
        .iter()
        .map(|n| (*n, PLAUSIBLE_GEOMETRY_M, ["m", "rad"]))
        .chain(
            RATE_COLUMNS
                .iter()
                .map(|n| (*n, PLAUSIBLE_RATE_M_S, ["m/s", "rad/s"])),
        )
        .chain(
            ACCELERATION_COLUMNS
                .iter()
                .map(|n| (*n, PLAUSIBLE_ACCELERATION_M_S2, ["m/s²", "rad/s²"])),
        );
    for (j, (name, limit, units)) in bounded.enumerate() {
        let Some(column) = cols.get(name) else {
            continue;
        };
        if let Some(i) = column.iter().position(|x| x.abs() > limit) {
            let unit = units[usize::from(j % 6 >= 3)];
            return Err(ScenarioError::Io(platen_io::IoError::Record {
                path: path.to_owned(),
                message: format!(
                    "data row {}, column `{name}`: {:e} {unit}, beyond the ±{limit} {unit} any \
                     table reaches (millimetres or degrees written as {unit}?)",
                    i + 1,
                    column[i]
                ),
            }));
        }
    }
    let t = cols.remove("t_s").unwrap_or_default();
    let mut derived = Derived::new();
    let mut dofs = Vec::with_capacity(6);
    for k in 0..6 {
        let u = cols.remove(POSE_COLUMNS[k]);
        let given = u.is_some();
        let u = u.unwrap_or_else(|| vec![0.0; t.len()]);
        let v = cols.remove(RATE_COLUMNS[k]);
        let a = cols.remove(ACCELERATION_COLUMNS[k]);
        let (run, how) = motion_run(ctx, file, path, t.clone(), u, v, a)?;
        let Run::Inverse { motion } = run else {
            unreachable!("a motion record makes an inverse run")
        };
        if given {
            for (name, note) in how {
                let ours = if name == "v_m_s" {
                    RATE_COLUMNS[k]
                } else {
                    ACCELERATION_COLUMNS[k]
                };
                let note = note
                    .replace("v_m_s", RATE_COLUMNS[k])
                    .replace("a_m_s2", ACCELERATION_COLUMNS[k])
                    .replace("u_m", POSE_COLUMNS[k]);
                derived.insert(ours, note);
            }
        }
        dofs.push(motion);
    }
    let dofs: [platen_signal::Motion; 6] = dofs.try_into().expect("six DOFs");
    let motion = PoseMotion::new(dofs).map_err(|cause| crate::excitation::rejected(path, cause))?;
    Ok((motion, derived))
}

/// `excitation.ground_motion` per axis: each record integrated as the uniaxial
/// `ground_motion` is, the axes on one time grid (the shortest record's, every record at
/// the same `sample_rate_hz`), the rotations and absent axes held at zero.
fn axis_ground_motion(
    ctx: &Ctx,
    file: &ScenarioFile,
    axes: &crate::file::AxisGroundMotion,
) -> Result<(PoseMotion, Derived)> {
    let here = "excitation.ground_motion";
    let mut motions: [Option<platen_signal::Motion>; 3] = [None, None, None];
    let mut rates = [None; 3];
    for (k, (axis, g)) in axes.each().into_iter().enumerate() {
        let Some(g) = g else { continue };
        rates[k] = Some(g.sample_rate_hz);
        let at = format!("{here}.{axis}");
        motions[k] = Some(crate::excitation::ground_motion(
            ctx,
            &at,
            g,
            file.duration_s,
        )?);
    }
    let integral =
        "exact integral of the record's acceleration (straight lines between its samples)";
    let derived = |k: usize| {
        [
            (RATE_COLUMNS[k], integral.to_owned()),
            (POSE_COLUMNS[k], format!("{integral}, twice")),
        ]
    };
    axis_motion(ctx, here, motions, rates, derived)
}

/// A generated motion per axis (`sine_motion`, `triangle_motion` or `white_noise_motion`
/// under `excitation.{key}`): each axis's generator over the scenario's duration, the axes
/// on one time grid (every generator at the same `sample_rate_hz`), the rotations and absent
/// axes held at zero. The generators' velocities and accelerations are exact, not derived.
fn axis_generated_motion(
    ctx: &Ctx,
    file: &ScenarioFile,
    key: &str,
    axes: [Option<MotionGenerator>; 3],
) -> Result<(PoseMotion, Derived)> {
    let here = format!("excitation.{key}");
    let mut motions: [Option<platen_signal::Motion>; 3] = [None, None, None];
    let mut rates = [None; 3];
    for (k, g) in axes.into_iter().enumerate() {
        let Some(g) = g else { continue };
        rates[k] = Some(g.sample_rate_hz());
        let at = format!("{here}.{}", AXES[k]);
        motions[k] = Some(crate::excitation::generate_motion(ctx, file, &at, g)?);
    }
    axis_motion(ctx, &here, motions, rates, |_| [])
}

/// The translational axes' names, in order.
const AXES: [&str; 3] = ["x", "y", "z"];

/// The six-DOF motion of the given translational motions (each sampled at `rates_hz`), on
/// one grid: the shortest motion's, all at one rate; the rotations and absent axes still.
/// `derived(k)` names the channels of axis `k` that were derived, not given.
fn axis_motion<const N: usize>(
    ctx: &Ctx,
    here: &str,
    motions: [Option<platen_signal::Motion>; 3],
    rates_hz: [Option<f64>; 3],
    derived: impl Fn(usize) -> [(&'static str, String); N],
) -> Result<(PoseMotion, Derived)> {
    let mut first: Option<(f64, &str)> = None;
    for (k, rate) in rates_hz.iter().enumerate() {
        let Some(rate) = *rate else { continue };
        match first {
            Some((r, axis)) if r != rate => {
                return Err(ctx.invalid(
                    &format!("{here}.{}.sample_rate_hz", AXES[k]),
                    rate,
                    format!("the same rate as {here}.{axis}.sample_rate_hz ({r} Hz)"),
                ))
            }
            None => first = Some((rate, AXES[k])),
            _ => {}
        }
    }
    let n = motions
        .iter()
        .flatten()
        .map(platen_signal::Motion::len)
        .min()
        .ok_or_else(|| ctx.invalid(here, "{}", "a source for at least one of x, y, z"))?;
    let t: Vec<f64> = motions
        .iter()
        .flatten()
        .next()
        .map(|m| m.t_s()[..n].to_vec())
        .unwrap_or_default();
    let still = || {
        let z = vec![0.0; n];
        platen_signal::Motion::new(t.clone(), z.clone(), z.clone(), z)
    };
    let mut dofs = Vec::with_capacity(6);
    let mut notes = Derived::new();
    for k in 0..6 {
        let m = match motions.get(k).and_then(Option::as_ref) {
            Some(m) => {
                notes.extend(derived(k));
                m.clone().truncated(n)
            }
            None => still(),
        };
        dofs.push(m.map_err(|e| ctx.invalid(here, "", e.to_string()))?);
    }
    let dofs: [platen_signal::Motion; 6] = dofs.try_into().expect("six DOFs");
    let motion = PoseMotion::new(dofs).map_err(|e| ctx.invalid(here, "", e.to_string()))?;
    Ok((motion, notes))
}

/// The LHPOST6 preset as written (`presets/lhpost6.json`, made by
/// `tools/make_lhpost6_preset.py`): `{"table": {…}, "limits": {…}}`.
const LHPOST6: &str = include_str!("../presets/lhpost6.json");

/// The preset file's shape.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PresetFile {
    table: TableSpec,
    limits: Option<crate::table_file::AxisLimitsSpec>,
}

/// The names of the table presets.
pub const TABLE_PRESETS: [&str; 1] = ["lhpost6"];

/// The table of preset `name`, limits included.
///
/// # Errors
/// An unknown name.
pub fn table_preset(name: &str) -> std::result::Result<TableSpec, String> {
    match name {
        "lhpost6" => {
            let file: PresetFile =
                serde_json::from_str(LHPOST6).expect("the shipped LHPOST6 preset parses");
            Ok(TableSpec {
                limits: file.limits.or(file.table.limits.clone()),
                ..file.table
            })
        }
        other => Err(format!(
            "one of {} (not {other:?})",
            TABLE_PRESETS.join(", ")
        )),
    }
}

/// `table` with its preset's values laid under it (values given win, field by field; a list
/// given replaces the preset's).
fn resolve_preset(ctx: &Ctx, spec: &TableSpec) -> Result<TableSpec> {
    let Some(name) = &spec.preset else {
        return Ok(spec.clone());
    };
    let base = table_preset(name)
        .map_err(|expected| ctx.invalid("table.preset", format!("{name:?}"), expected))?;
    Ok(spec.clone().overlay(base))
}

/// `table.limits`, every value given finite and > 0.
fn build_limits(ctx: &Ctx, spec: &TableSpec) -> Result<crate::table_file::AxisLimitsSpec> {
    let limits = spec.limits.clone().unwrap_or_default();
    let names = [
        ["stroke_m", "velocity_m_s", "acceleration_m_s2"],
        ["angle_rad", "rate_rad_s", "acceleration_rad_s2"],
    ];
    for (d, values) in Dof::ALL.iter().zip(limits.each()) {
        let keys = names[usize::from(d.is_rotation())];
        for (key, v) in keys.iter().zip(values) {
            if let Some(v) = v {
                check_positive(ctx, &format!("table.limits.{}.{key}", d.name()), v)?;
            }
        }
    }
    if let Some(m) = limits.overturning_moment_n_m {
        check_positive(ctx, "table.limits.overturning_moment_n_m", m)?;
    }
    Ok(limits)
}

/// The error of a table system's refusal, at its JSON path under `table`.
fn system_error(ctx: &Ctx, e: SystemError) -> ScenarioError {
    match e {
        SystemError::Invalid {
            path,
            value,
            expected,
        } => ctx.invalid(&format!("table.{path}"), value, expected),
        SystemError::OfActuator { index, source } => match *source {
            SystemError::Invalid {
                path,
                value,
                expected,
            } => ctx.invalid(&format!("table.actuators[{index}].{path}"), value, expected),
            other => ctx.invalid(&format!("table.actuators[{index}]"), "", other.to_string()),
        },
        SystemError::OfDof { dof, source } => match *source {
            SystemError::Invalid {
                path,
                value,
                expected,
            } => {
                let key = path.trim_start_matches("controller.");
                ctx.invalid(
                    &format!("table.controller.dof.{dof}.{key}"),
                    value,
                    expected,
                )
            }
            other => ctx.invalid(
                &format!("table.controller.dof.{dof}"),
                "",
                other.to_string(),
            ),
        },
        other => ctx.invalid("table", "", other.to_string()),
    }
}

/// The closed loop of a table with `controller`: every actuator's servo-valves and leakage,
/// the supply, the DOF controller (gains for every free DOF, none for a held one), the
/// static forces the chambers must hold at rest, and the integrator (RK4 resolving the
/// loop's fastest mode by default, or `integrator`).
fn build_system(
    ctx: &Ctx,
    integrator: Option<&crate::file::IntegratorSpec>,
    spec: &TableSpec,
    controller: &crate::table_file::TableControllerSpec,
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
) -> Result<TableLoopSystem> {
    let mut actuators = Vec::with_capacity(spec.actuators.len());
    for (i, a) in spec.actuators.iter().enumerate() {
        let prefix = format!("table.actuators[{i}]");
        let valve = a.servo_valve.clone().ok_or_else(|| {
            ctx.invalid(
                &format!("{prefix}.servo_valve"),
                "(missing)",
                "its servo-valves ({\"count\", \"rated_flow_m3_s\", \"rated_pressure_drop_pa\", \
                 \"natural_frequency_hz\", \"damping_ratio\", \"delay_s\"}): the table has a \
                 `controller`",
            )
        })?;
        actuators.push(ActuatorHydraulics {
            cap_area_m2: a.cap_side_area_m2,
            rod_area_m2: a.rod_side_area_m2,
            chamber_volume_m3: a.chamber_volume_m3,
            leakage_m3_s_per_pa: a.leakage_m3_s_per_pa.unwrap_or(0.0),
            servo_valve: complete_servo_valve_under(ctx, &prefix, valve)?,
        });
    }
    let strokes: Vec<f64> = table.actuators().iter().map(|a| a.stroke_m).collect();
    let supply_pressure_pa = spec
        .supply_pressure_pa
        .unwrap_or(DEFAULT_SUPPLY_PRESSURE_PA);
    let hydraulics = TableHydraulics::new(
        TableHydraulicsParts {
            actuators,
            oil_bulk_modulus_pa: table.parts().oil_bulk_modulus_pa,
            supply_pressure_pa,
            return_pressure_pa: spec
                .return_pressure_pa
                .unwrap_or(DEFAULT_RETURN_PRESSURE_PA),
            supply: supply_under(ctx, "table", spec.accumulator.as_ref())?,
        },
        &strokes,
    )
    .map_err(|e| system_error(ctx, e))?;
    let delay = hydraulics.actuators()[0].servo_valve.delay_s;
    if let Some(i) = hydraulics
        .actuators()
        .iter()
        .position(|a| a.servo_valve.delay_s != delay)
    {
        return Err(ctx.invalid(
            &format!("table.actuators[{i}].servo_valve.delay_s"),
            hydraulics.actuators()[i].servo_valve.delay_s,
            format!("the delay of every other valve ({delay} s): the valves share one delay line"),
        ));
    }
    // The static hold: the chambers must exert it between the return and supply pressures.
    let extra = specimen.map_or_else(
        platen_model::multi_axis::Wrench::zeros,
        LinearSpecimen::weight_wrench,
    );
    TableHydraulics::static_forces_n(table, &extra)
        .and_then(|f| hydraulics.rest_states(&f))
        .map_err(|e| system_error(ctx, e))?;
    let rate = controller.sample_rate_hz.ok_or_else(|| {
        ctx.invalid(
            "table.controller.sample_rate_hz",
            "(missing)",
            "the controller's sample rate, Hz",
        )
    })?;
    check_positive(ctx, "table.controller.sample_rate_hz", rate)?;
    let gains = controller.dof.clone().unwrap_or_default();
    let mut loops = [open_loop(rate); 6];
    for (d, g) in Dof::ALL.iter().zip(gains.each()) {
        let at = format!("table.controller.dof.{}", d.name());
        let free = table.free().contains(*d);
        match (g, free) {
            (Some(g), true) => {
                if let Some(r) = g.sample_rate_hz {
                    return Err(ctx.invalid(
                        &format!("{at}.sample_rate_hz"),
                        r,
                        "nothing: every DOF's loop runs at table.controller.sample_rate_hz",
                    ));
                }
                loops[d.index()] = controller_gains(rate, g);
            }
            (Some(_), false) => {
                return Err(ctx.invalid(
                    &at,
                    "(given)",
                    format!("nothing: {} is held (table.held_dofs)", d.name()),
                ))
            }
            (None, true) => {
                return Err(ctx.invalid(
                    &at,
                    "(missing)",
                    "its gains ({\"displacement_gain_per_m\", …}): every free DOF has a loop",
                ))
            }
            (None, false) => {}
        }
    }
    let balance = controller.force_balance_gain.unwrap_or(0.0);
    let geometry = DofGeometry::of_table(table).map_err(|e| system_error(ctx, e))?;
    let controller =
        DofController::new(rate, loops, balance, geometry).map_err(|e| system_error(ctx, e))?;
    crate::loop_budget::check_orifices(ctx, spec, &hydraulics, controller.period_s())?;
    // The fastest mode the integrator steps: the oil columns' (the table's modes with the
    // valves shut, specimen included), resolved to `h·ω ≤ 0.25`. The spools are not
    // stepped: the loop carries them in closed form between drive changes
    // (`platen_system::SpoolResponse`), and RK4 only integrates the flows they open. That
    // quadrature needs the spool's transient resolved to `h·ω_v ≤ 1`, not 0.25 (measured:
    // 1.6e-7 of the motion at `h·ω_v` = 0.74; `tests/multi_axis_loop.rs`).
    let modes = match specimen {
        Some(s) => table.modes_with(s),
        None => table.modes(),
    };
    let fastest = modes
        .iter()
        .map(|m| std::f64::consts::TAU * m.frequency_hz)
        .fold(0.0, f64::max);
    let spool = hydraulics
        .actuators()
        .iter()
        .map(|a| std::f64::consts::TAU * a.servo_valve.natural_frequency_hz)
        .fold(0.0, f64::max);
    let period = controller.period_s();
    let k = (period * fastest / 0.25)
        .max(period * spool)
        .ceil()
        .clamp(1.0, 1e6) as u32;
    let method = loop_method_at(ctx, integrator, period, fastest, k, || {
        ctx.invalid(
            "table.controller.sample_rate_hz",
            rate,
            format!(
                "a rate at which RK4 resolves the loop's fastest mode ({:.1} Hz) within 1e6 \
                 steps per period, or {{\"method\": \"dopri5\"}}",
                fastest / std::f64::consts::TAU
            ),
        )
    })?;
    Ok(TableLoopSystem {
        hydraulics,
        controller,
        method,
    })
}

/// `excitation.force_csv` of a multi-axis scenario: `t_s` and `{name}_force_n` per actuator,
/// cut to `duration_s`; a forward run with the scenario's `integrator`.
fn forward_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    table: &MultiAxisTable,
    path: &Path,
) -> Result<TableRunSpec> {
    for (key, given) in [
        ("excitation.columns", file.excitation.columns.is_some()),
        (
            "excitation.lowpass_hz",
            file.excitation.lowpass_hz.is_some(),
        ),
    ] {
        if given {
            return Err(ctx.invalid(
                key,
                "(given)",
                "nothing: not used by a multi-axis forward run",
            ));
        }
    }
    let names: Vec<String> = table
        .actuators()
        .iter()
        .map(|a| format!("{}_force_n", a.name))
        .collect();
    let mut required: Vec<&str> = vec!["t_s"];
    required.extend(names.iter().map(String::as_str));
    let mut cols = platen_io::csv::read_table(path, &required, &[])?;
    let mut t = cols.take_column("t_s").unwrap_or_default();
    let mut forces: Vec<Vec<f64>> = names
        .iter()
        .map(|n| cols.take_column(n).unwrap_or_default())
        .collect();
    if let Some(d) = file.duration_s {
        check_positive(ctx, "duration_s", d)?;
        let end = t[0] + d;
        if t[t.len() - 1] < end - 1e-9 * d {
            return Err(ScenarioError::RecordTooShort {
                path: path.to_owned(),
                span_s: t[t.len() - 1] - t[0],
                samples: Some(t.len()),
                duration_s: d,
            });
        }
        let n = t.partition_point(|&x| x <= end + 1e-9 * d);
        t.truncate(n);
        for f in &mut forces {
            f.truncate(n);
        }
    }
    let first = ForceRecord::new(
        t.clone(),
        forces
            .first()
            .cloned()
            .unwrap_or_else(|| vec![0.0; t.len()]),
    )
    .map_err(|cause| crate::excitation::rejected(path, cause))?;
    let method = crate::excitation::forward_method(ctx, file, &first)?;
    let forces =
        ActuatorForces::new(t, forces).map_err(|cause| crate::excitation::rejected(path, cause))?;
    let initial = build_initial(ctx, file, table)?;
    Ok(TableRunSpec::Forward {
        forces,
        method,
        initial,
    })
}

/// `initial` of a forward run: the pose and rates given by name, the rest zero; a held DOF's
/// must be 0, and the uniaxial names are refused.
fn build_initial(
    ctx: &Ctx,
    file: &ScenarioFile,
    table: &MultiAxisTable,
) -> Result<(Coords, Coords)> {
    let mut out = (Coords::zeros(), Coords::zeros());
    let Some(initial) = &file.initial else {
        return Ok(out);
    };
    for (key, given) in [
        ("u_m", initial.u_m.is_some()),
        ("v_m_s", initial.v_m_s.is_some()),
        ("from_record", initial.from_record),
    ] {
        if given {
            return Err(ctx.invalid(
                &format!("initial.{key}"),
                "(given)",
                "the pose and rate names of a multi-axis table (x_m … yaw_rad, x_m_s … \
                 yaw_rad_s)",
            ));
        }
    }
    for (k, (key, value)) in initial.table_values().into_iter().enumerate() {
        let Some(v) = value else { continue };
        let at = format!("initial.{key}");
        let v = check_finite(ctx, &at, v)?;
        let dof = Dof::ALL[k % 6];
        // A pose or rate beyond any table's is a unit slip, refused here rather than run into
        // a non-finite state with the uniaxial solver's labels.
        let (limit, unit) = match (k < 6, k % 6 < 3) {
            (true, true) => (PLAUSIBLE_GEOMETRY_M, "m"),
            (true, false) => (PLAUSIBLE_GEOMETRY_M, "rad"),
            (false, true) => (PLAUSIBLE_RATE_M_S, "m/s"),
            (false, false) => (PLAUSIBLE_RATE_M_S, "rad/s"),
        };
        if v.abs() > limit {
            return Err(ctx.invalid(
                &at,
                v,
                format!(
                    "a value within ±{limit} {unit}, beyond which no table moves (millimetres \
                     or degrees written as {unit}?)"
                ),
            ));
        }
        if table.held().contains(dof) && v != 0.0 {
            return Err(ctx.invalid(
                &at,
                v,
                format!("0: {} is held (table.held_dofs)", dof.name()),
            ));
        }
        if k < 6 {
            out.0[k] = v;
        } else {
            out.1[k - 6] = v;
        }
    }
    Ok(out)
}

/// `specimen` of a multi-axis scenario: storeys (along x) or the four matrices.
fn build_specimen(ctx: &Ctx, given: Option<&SpecimenSpec>) -> Result<Option<LinearSpecimen>> {
    let Some(s) = given else {
        return Ok(None);
    };
    if !s.is_general() {
        // The uniaxial rig's reader: the same checks, each storey's value named by its path.
        let frame = crate::rig::build_specimen(ctx, Some(s))?;
        return Ok(frame.as_ref().map(LinearSpecimen::from_storeys));
    }
    if !s.storeys.is_empty() {
        return Err(ctx.invalid(
            "specimen.storeys",
            "(given)",
            "storeys or the four matrices, not both",
        ));
    }
    let matrix = |key: &str,
                  m: &Option<Vec<Vec<f64>>>,
                  cols: Option<usize>|
     -> Result<DMatrix<f64>> {
        let at = format!("specimen.{key}");
        let m = m
            .as_ref()
            .ok_or_else(|| ctx.invalid(&at, "(absent)", "a matrix: a general linear specimen needs mass_matrix, stiffness_matrix, damping_matrix and influence"))?;
        let n = m.len();
        let width = cols.unwrap_or(n);
        if let Some((r, row)) = m.iter().enumerate().find(|(_, row)| row.len() != width) {
            return Err(ctx.invalid(
                &format!("{at}[{r}]"),
                format!("{} numbers", row.len()),
                format!("{width} numbers"),
            ));
        }
        Ok(DMatrix::from_fn(n, width, |r, c| m[r][c]))
    };
    let mass = matrix("mass_matrix", &s.mass_matrix, None)?;
    let stiffness = matrix("stiffness_matrix", &s.stiffness_matrix, None)?;
    let damping = matrix("damping_matrix", &s.damping_matrix, None)?;
    let influence = matrix("influence", &s.influence, Some(6))?;
    if let Some((r, c)) = (0..influence.nrows())
        .flat_map(|r| (0..6).map(move |c| (r, c)))
        .find(|&(r, c)| influence[(r, c)].abs() > PLAUSIBLE_GEOMETRY_M)
    {
        return Err(ctx.invalid(
            &format!("specimen.influence[{r}][{c}]"),
            influence[(r, c)],
            format!(
                "a share of the platen's motion within ±{PLAUSIBLE_GEOMETRY_M} (a rotation's lever \
                 in m: no specimen stands {PLAUSIBLE_GEOMETRY_M} m from the reference point)"
            ),
        ));
    }
    LinearSpecimen::new(mass, stiffness, damping, influence)
        .map(Some)
        .map_err(|e| match e {
            ModelError::InvalidTable { path, expected } => {
                ctx.invalid(&path, "(as given)", expected)
            }
            other => ctx.invalid("specimen", "", other.to_string()),
        })
}

/// The scenario file at `path` is a multi-axis one (it has a `table`).
pub fn is_multi_axis(file: &ScenarioFile) -> bool {
    file.table.is_some()
}

/// The path a scenario's motion record resolves to (for messages).
pub fn motion_path(path: &Path, file: &ScenarioFile) -> Option<PathBuf> {
    file.excitation
        .motion_csv
        .as_ref()
        .map(|rel| Ctx { path }.resolve(rel))
}

/// The peaks of one DOF of a multi-axis run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisPeaks {
    /// Largest |coordinate|, m or rad.
    pub peak: f64,
    /// Largest |rate|, m/s or rad/s.
    pub peak_rate: f64,
    /// Largest |second derivative|, m/s² or rad/s².
    pub peak_acceleration: f64,
}

/// One actuator's peaks against its limits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ActuatorPeaks {
    /// Its name.
    pub name: String,
    /// Largest |stroke|, m.
    pub peak_stroke_m: f64,
    /// Its stroke limit (± from neutral), m.
    pub stroke_limit_m: f64,
    /// Largest force (push), N.
    pub max_force_n: f64,
    /// Smallest force (most pull), N.
    pub min_force_n: f64,
    /// Its push limit at the supply pressure, N.
    pub push_limit_n: f64,
    /// Its pull limit at the supply pressure (≤ 0), N.
    pub pull_limit_n: f64,
    /// Largest |flow| into chamber `a` (closed loop), m³/s.
    pub peak_flow_m3_s: Option<f64>,
    /// Its valves' flow capacity at the supply pressure, `m·Q_r·√((P_s − P_R)/Δp_r)`
    /// (closed loop), m³/s.
    pub flow_capacity_m3_s: Option<f64>,
    /// Time its drive was saturated (`|d| = 1`, counted at the output samples; closed loop),
    /// s.
    pub saturated_time_s: Option<f64>,
    /// Whether stroke and force stayed within the limits.
    pub respected: bool,
}

/// How one DOF of a closed loop followed its command (at the output samples).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisTracking {
    /// RMS of command − achieved, m or rad.
    pub rms_error: f64,
    /// Largest |command − achieved|, m or rad.
    pub peak_error: f64,
    /// RMS of the error over the RMS of the command (`null` for a still command: the
    /// error is then absolute, `rms_error`, the cross-talk into that DOF).
    pub displacement_nrmse: Option<f64>,
    /// RMS of the acceleration error (command's − achieved), m/s² or rad/s².
    pub rms_acceleration_error: f64,
    /// Largest |acceleration error|, m/s² or rad/s².
    pub peak_acceleration_error: f64,
    /// RMS of the acceleration error over the RMS of the command's acceleration (`null`
    /// for a still command).
    pub acceleration_nrmse: Option<f64>,
}

/// One axis's peaks against its limits (`table.limits`; `null` where none is given).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisLimitCheck {
    /// Its displacement limit (stroke or angle), m or rad.
    pub displacement_limit: Option<f64>,
    /// Its rate limit, m/s or rad/s.
    pub rate_limit: Option<f64>,
    /// Its acceleration limit, m/s² or rad/s².
    pub acceleration_limit: Option<f64>,
    /// Whether the peaks stayed within the limits given.
    pub respected: bool,
}

/// The overturning moment the platen exerted on the specimen against the table's limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OverturningSummary {
    /// Largest `√(M_x² + M_y²)` about the reference point, N·m.
    pub peak_n_m: f64,
    /// The limit (`table.limits.overturning_moment_n_m`), N·m.
    pub limit_n_m: Option<f64>,
    /// Whether it stayed within the limit (true without one).
    pub respected: bool,
}

/// A closed loop's own figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableLoopSummary {
    /// Time with a drive saturated (at the controller's samples), s.
    pub saturated_time_s: f64,
    /// First time a chamber reached the cavitation floor (0 Pa absolute), s.
    pub cavitation_at_s: Option<f64>,
    /// Lowest supply pressure, Pa.
    pub min_supply_pressure_pa: f64,
    /// Largest warping force (the null-space part of the actuator forces), N.
    pub max_warping_force_n: f64,
    /// Hydraulic energy delivered into the chambers, J.
    pub hydraulic_energy_j: f64,
    /// Controller samples.
    pub controller_samples: u64,
    /// RK4 steps per controller period (or Dopri5 pieces).
    pub steps_per_period: u32,
    /// The loop's stability from the eigenvalues of its linearisation at neutral (`null`
    /// when it cannot be linearised: the actuators cannot hold the platen there).
    pub stability: Option<LoopStabilityDescription>,
    /// Per free DOF, its loop's margins, broken at its drive with the others closed.
    pub loop_margins: std::collections::BTreeMap<&'static str, DofLoopDescription>,
}

/// One strut's range of pull.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StrutPeaks {
    /// Its name.
    pub name: String,
    /// Smallest pull, N.
    pub min_force_n: f64,
    /// Largest pull, N.
    pub max_force_n: f64,
}

/// What `platen simulate --json` prints for a multi-axis run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableSummary {
    /// The scenario's name.
    pub name: String,
    /// `"inverse"` or `"forward"`.
    pub kind: &'static str,
    /// Output samples.
    pub samples: usize,
    /// Simulated duration, s.
    pub duration_s: f64,
    /// The motion's channels platen derived, with how.
    pub derived: Derived,
    /// Per DOF (`x` … `yaw`), its peaks.
    pub axes: std::collections::BTreeMap<&'static str, AxisPeaks>,
    /// Per actuator, its peaks against its limits.
    pub actuators: Vec<ActuatorPeaks>,
    /// Per strut, its range of pull.
    pub struts: Vec<StrutPeaks>,
    /// With a specimen: the largest |value| of each base-force and overturning-moment column.
    pub specimen: std::collections::BTreeMap<&'static str, f64>,
    /// Per DOF, how it followed its command (closed loop; `null` otherwise).
    pub tracking: Option<std::collections::BTreeMap<&'static str, AxisTracking>>,
    /// Per DOF, its peaks against `table.limits` (every DOF; limits `null` where not given).
    pub limits: std::collections::BTreeMap<&'static str, AxisLimitCheck>,
    /// The overturning moment against its limit (with a specimen; `null` otherwise).
    pub overturning_moment: Option<OverturningSummary>,
    /// The closed loop's own figures (`null` for an open-loop run).
    #[serde(rename = "loop")]
    pub loop_figures: Option<TableLoopSummary>,
    /// What an engineer should look at: limits exceeded, cavitation, saturation.
    pub warnings: Vec<String>,
    /// Whether every actuator and axis stayed within its limits.
    pub within_limits: bool,
    /// The CSV written, if any.
    pub output: Option<String>,
}

fn abs_max(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m: f64, v| m.max(v.abs()))
}

fn rms(x: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

/// The tracking of a command `u_ref`, `a_ref` by the achieved `u`, `a`.
/// `x` in percent with two decimals, `—` for none (a still command's relative error).
fn percent(x: Option<f64>) -> String {
    x.map_or("—".to_owned(), |x| format!("{:.2} %", 100.0 * x))
}

fn tracking(u_ref: &[f64], u: &[f64], a_ref: &[f64], a: &[f64]) -> AxisTracking {
    let err = |r: &[f64], x: &[f64]| -> Vec<f64> { r.iter().zip(x).map(|(r, x)| r - x).collect() };
    let (e, ea) = (err(u_ref, u), err(a_ref, a));
    let ratio = |num: f64, den: f64| (den > 0.0).then(|| num / den);
    let (rms_e, rms_ea) = (rms(e.iter().copied()), rms(ea.iter().copied()));
    AxisTracking {
        rms_error: rms_e,
        peak_error: abs_max(&e),
        displacement_nrmse: ratio(rms_e, rms(u_ref.iter().copied())),
        rms_acceleration_error: rms_ea,
        peak_acceleration_error: abs_max(&ea),
        acceleration_nrmse: ratio(rms_ea, rms(a_ref.iter().copied())),
    }
}

impl TableScenario {
    /// The summary of `run` (a run of this scenario); `output` the CSV written.
    pub fn summary(&self, run: &TableRun, output: Option<&Path>) -> TableSummary {
        self.summary_with(run, None, output)
    }

    /// [`TableScenario::summary`] with the closed loop's figures `stats`.
    pub fn summary_with(
        &self,
        run: &TableRun,
        stats: Option<&TableLoopStats>,
        output: Option<&Path>,
    ) -> TableSummary {
        let col = |name: &str| run.column(name).unwrap_or(&[]);
        let t = col("t_s");
        let axes = Dof::ALL
            .iter()
            .map(|d| {
                let k = d.index();
                (
                    d.name(),
                    AxisPeaks {
                        peak: abs_max(col(POSE_COLUMNS[k])),
                        peak_rate: abs_max(col(RATE_COLUMNS[k])),
                        peak_acceleration: abs_max(col(ACCELERATION_COLUMNS[k])),
                    },
                )
            })
            .collect();
        let capacities = self.flow_capacities_m3_s();
        let actuators: Vec<ActuatorPeaks> = self
            .table
            .actuators()
            .iter()
            .zip(self.force_limits_n())
            .enumerate()
            .map(|(i, (a, (pull, push)))| {
                let force = col(&format!("{}_force_n", a.name));
                let stroke = abs_max(col(&format!("{}_stroke_m", a.name)));
                let max = force.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let min = force.iter().copied().fold(f64::INFINITY, f64::min);
                let capacity = capacities.as_ref().map(|c| c[i]);
                let flow = run.column(&format!("{}_flow_m3_s", a.name)).map(abs_max);
                let saturated = run.column(&format!("{}_drive", a.name)).map(|d| {
                    let n = d.iter().filter(|x| x.abs() >= 1.0).count();
                    let span = t.last().zip(t.first()).map_or(0.0, |(b, a)| b - a);
                    if d.len() > 1 {
                        span * n as f64 / (d.len() - 1) as f64
                    } else {
                        0.0
                    }
                });
                ActuatorPeaks {
                    name: a.name.clone(),
                    peak_stroke_m: stroke,
                    stroke_limit_m: a.stroke_m,
                    max_force_n: max,
                    min_force_n: min,
                    push_limit_n: push,
                    pull_limit_n: pull,
                    peak_flow_m3_s: flow,
                    flow_capacity_m3_s: capacity,
                    saturated_time_s: saturated,
                    respected: stroke <= a.stroke_m && max <= push && min >= pull,
                }
            })
            .collect();
        let struts = self
            .table
            .struts()
            .iter()
            .map(|s| {
                let f = col(&format!("{}_force_n", s.name));
                StrutPeaks {
                    name: s.name.clone(),
                    min_force_n: f.iter().copied().fold(f64::INFINITY, f64::min),
                    max_force_n: f.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                }
            })
            .collect();
        let specimen = [
            "base_force_x_n",
            "base_force_y_n",
            "base_force_z_n",
            "overturning_moment_x_n_m",
            "overturning_moment_y_n_m",
        ]
        .into_iter()
        .filter_map(|c| run.column(c).map(|v| (c, abs_max(v))))
        .collect();
        let tracking = match &self.run {
            TableRunSpec::Loop { command } => Some(
                self.table
                    .free()
                    .iter()
                    .map(|d| {
                        let k = d.index();
                        let m = command.dof(d);
                        (
                            d.name(),
                            tracking(
                                &m.u_m()[..run.len().min(m.len())],
                                col(POSE_COLUMNS[k]),
                                &m.a_m_s2()[..run.len().min(m.len())],
                                col(ACCELERATION_COLUMNS[k]),
                            ),
                        )
                    })
                    .collect(),
            ),
            _ => None,
        };
        let mut warnings = Vec::new();
        let limits: std::collections::BTreeMap<&'static str, AxisLimitCheck> = Dof::ALL
            .iter()
            .zip(self.limits.each())
            .map(|(d, [u, v, a])| {
                let k = d.index();
                let peaks = [
                    abs_max(col(POSE_COLUMNS[k])),
                    abs_max(col(RATE_COLUMNS[k])),
                    abs_max(col(ACCELERATION_COLUMNS[k])),
                ];
                let mut respected = true;
                for ((limit, peak), what) in
                    [u, v, a]
                        .iter()
                        .zip(peaks)
                        .zip(["displacement", "rate", "acceleration"])
                {
                    if let Some(l) = limit {
                        if peak > *l {
                            respected = false;
                            warnings.push(format!(
                                "{} {what} {peak:.4e} beyond its limit {l:.4e} (table.limits)",
                                d.name()
                            ));
                        }
                    }
                }
                (
                    d.name(),
                    AxisLimitCheck {
                        displacement_limit: u,
                        rate_limit: v,
                        acceleration_limit: a,
                        respected,
                    },
                )
            })
            .collect();
        let overturning_moment = match (
            run.column("overturning_moment_x_n_m"),
            run.column("overturning_moment_y_n_m"),
        ) {
            (Some(mx), Some(my)) => {
                let peak = mx
                    .iter()
                    .zip(my)
                    .map(|(a, b)| a.hypot(*b))
                    .fold(0.0, f64::max);
                let limit = self.limits.overturning_moment_n_m;
                let respected = limit.is_none_or(|l| peak <= l);
                if !respected {
                    warnings.push(format!(
                        "overturning moment {peak:.4e} N·m beyond the table's {:.4e} N·m",
                        limit.unwrap_or_default()
                    ));
                }
                Some(OverturningSummary {
                    peak_n_m: peak,
                    limit_n_m: limit,
                    respected,
                })
            }
            _ => None,
        };
        for a in actuators.iter().filter(|a| !a.respected) {
            warnings.push(format!(
                "actuator {} beyond its stroke or force limits",
                a.name
            ));
        }
        let loop_figures = stats.zip(self.system.as_ref()).map(|(st, sys)| {
            let (stability, loop_margins) = match self.linearisation() {
                Some(lin) => {
                    let (s, m) = loop_verdict(&lin);
                    (Some(s), m)
                }
                None => (None, std::collections::BTreeMap::new()),
            };
            if let Some(words) = stability.as_ref().and_then(|s| s.unstable_words()) {
                // The most serious first.
                warnings.insert(
                    0,
                    format!(
                    "the closed loop is unstable (linearised at neutral, {words}): the run shows what the table would \
                         do, but check the controller's gains (`platen model --scenario` shows \
                         each DOF's margins)"
                    ),
                );
            }
            if let Some(at) = st.cavitation_at_s {
                warnings.push(format!(
                    "cavitation: a chamber reached 0 Pa (absolute) at t = {at:.4} s"
                ));
            }
            if st.saturated_time_s > 0.0 {
                warnings.push(format!(
                    "drives saturated for {:.3} s: the table could not follow its command",
                    st.saturated_time_s
                ));
            }
            TableLoopSummary {
                saturated_time_s: st.saturated_time_s,
                cavitation_at_s: st.cavitation_at_s,
                min_supply_pressure_pa: st.min_supply_pressure_pa,
                max_warping_force_n: st.max_warping_force_n,
                hydraulic_energy_j: st.hydraulic_energy_j,
                controller_samples: st.controller_samples,
                steps_per_period: sys.method.steps_per_period(),
                stability,
                loop_margins,
            }
        });
        let axes_respected = limits.values().all(|l| l.respected);
        let overturning_respected = overturning_moment.as_ref().is_none_or(|o| o.respected);
        TableSummary {
            tracking,
            limits,
            overturning_moment,
            loop_figures,
            warnings,
            name: self.name.clone(),
            kind: match self.run {
                TableRunSpec::Inverse { .. } => "inverse",
                TableRunSpec::Forward { .. } => "forward",
                TableRunSpec::Loop { .. } => "closed_loop",
            },
            samples: run.len(),
            duration_s: t.last().zip(t.first()).map_or(0.0, |(b, a)| b - a),
            derived: self.derived.clone(),
            axes,
            within_limits: actuators.iter().all(|a| a.respected)
                && axes_respected
                && overturning_respected,
            actuators,
            struts,
            specimen,
            output: output.map(|p| p.display().to_string()),
        }
    }
}

/// The text `platen simulate` prints for a multi-axis run (`figures` the files written).
pub fn summary_text(s: &TableSummary, figures: &[PathBuf]) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    let what = match s.kind {
        "forward" => "forward from the actuator forces",
        "closed_loop" => "closed loop: the DOF controller follows a six-DOF command",
        _ => "inverse of a six-DOF motion",
    };
    let _ = writeln!(
        t,
        "{}: {what}, {} samples over {:.3} s",
        s.name, s.samples, s.duration_s
    );
    let _ = writeln!(t, "  axis    peak          rate          acceleration");
    for d in Dof::ALL {
        let a = &s.axes[d.name()];
        let u = d.unit();
        let _ = writeln!(
            t,
            "  {:<6}  {:>10.4} {u:<3} {:>10.4} {u}/s {:>10.4} {u}/s²",
            d.name(),
            a.peak,
            a.peak_rate,
            a.peak_acceleration
        );
    }
    if let Some(tr) = &s.tracking {
        let _ = writeln!(
            t,
            "  tracking  rms error     peak error    nrmse     rms acc. error  peak acc. error  acc. nrmse"
        );
        for d in Dof::ALL {
            let Some(a) = tr.get(d.name()) else { continue };
            let u = d.unit();
            let _ = writeln!(
                t,
                "  {:<8}  {:>9.3e} {u:<3} {:>9.3e} {u:<3} {:>8}  {:>9.3e} {u}/s²  {:>9.3e} {u}/s²  {:>8}",
                d.name(),
                a.rms_error,
                a.peak_error,
                percent(a.displacement_nrmse),
                a.rms_acceleration_error,
                a.peak_acceleration_error,
                percent(a.acceleration_nrmse)
            );
        }
    }
    for d in Dof::ALL {
        let Some(l) = s.limits.get(d.name()) else {
            continue;
        };
        if l.displacement_limit.is_none()
            && l.rate_limit.is_none()
            && l.acceleration_limit.is_none()
        {
            continue;
        }
        let show = |x: Option<f64>| x.map_or("-".to_owned(), |v| format!("{v:.4}"));
        let _ = writeln!(
            t,
            "  limits {}: {} {}, {} {}/s, {} {}/s²{}",
            d.name(),
            show(l.displacement_limit),
            d.unit(),
            show(l.rate_limit),
            d.unit(),
            show(l.acceleration_limit),
            d.unit(),
            if l.respected { "" } else { "  EXCEEDED" }
        );
    }
    let _ = writeln!(
        t,
        "  actuator  stroke (limit) m      force min … max (limits) kN"
    );
    for a in &s.actuators {
        let _ = writeln!(
            t,
            "  {:<8}  {:.4} ({:.4})      {:.1} … {:.1} ({:.1} … {:.1}){}",
            a.name,
            a.peak_stroke_m,
            a.stroke_limit_m,
            a.min_force_n / 1e3,
            a.max_force_n / 1e3,
            a.pull_limit_n / 1e3,
            a.push_limit_n / 1e3,
            if a.respected { "" } else { "  OUT OF LIMITS" }
        );
        if let (Some(q), Some(cap)) = (a.peak_flow_m3_s, a.flow_capacity_m3_s) {
            let _ = writeln!(
                t,
                "            flow {:.4} of {:.4} m³/s ({:.0} %), saturated {:.3} s",
                q,
                cap,
                100.0 * q / cap,
                a.saturated_time_s.unwrap_or(0.0)
            );
        }
    }
    for st in &s.struts {
        let _ = writeln!(
            t,
            "  strut {}: pull {:.1} … {:.1} kN",
            st.name,
            st.min_force_n / 1e3,
            st.max_force_n / 1e3
        );
    }
    for (k, v) in &s.specimen {
        let _ = writeln!(t, "  specimen {k}: peak {v:.1}");
    }
    if let Some(o) = &s.overturning_moment {
        let limit = o
            .limit_n_m
            .map_or(String::new(), |l| format!(" of {:.1} MN·m", l / 1e6));
        let _ = writeln!(
            t,
            "  overturning moment: peak {:.3} MN·m{limit}",
            o.peak_n_m / 1e6
        );
    }
    if let Some(l) = &s.loop_figures {
        let _ = writeln!(
            t,
            "  loop: {} controller samples, {} RK4 steps each; lowest supply {:.2} MPa; \
             largest warping force {:.1} kN; saturated {:.3} s",
            l.controller_samples,
            l.steps_per_period,
            l.min_supply_pressure_pa / 1e6,
            l.max_warping_force_n / 1e3,
            l.saturated_time_s
        );
        let verdict = match &l.stability {
            Some(st) if st.stable => "stable".to_owned(),
            Some(st) => format!("UNSTABLE, {}", st.unstable_words().unwrap_or_default()),
            None => "not linearised".to_owned(),
        };
        let margins: Vec<String> = Dof::ALL
            .iter()
            .filter_map(|d| {
                let m = l.loop_margins.get(d.name())?;
                let gm = m
                    .gain_margin_db
                    .map_or("-".to_owned(), |g| format!("{g:.1} dB"));
                let pm = m
                    .phase_margin_deg
                    .map_or("-".to_owned(), |p| format!("{p:.0}°"));
                Some(format!("{} {gm}, {pm}", d.name()))
            })
            .collect();
        let _ = writeln!(
            t,
            "  loop stability (linearised at neutral): {verdict}; margins {}",
            margins.join("; ")
        );
    }
    for w in &s.warnings {
        let _ = writeln!(t, "  warning: {w}");
    }
    if let Some(o) = &s.output {
        let _ = writeln!(t, "  wrote {o}");
    }
    for f in figures {
        let _ = writeln!(t, "  wrote {}", f.display());
    }
    t
}

/// One mode of `platen model --json` on a multi-axis scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeDescription {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// The platen's part of the shape: x, y, z (m), roll, pitch, yaw (rad), mass-normalised.
    pub shape: [f64; 6],
}

/// What `platen model --json` prints on a multi-axis scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableDescription {
    /// The scenario's name.
    pub name: String,
    /// The platen's modes at neutral on its oil columns and struts, valves shut, specimen
    /// included, lowest first.
    pub modes: Vec<ModeDescription>,
    /// Per free DOF, the capacities the geometry and hydraulics give (bare table):
    /// translations `{stroke_m, acceleration_m_s2, force_n}`, rotations `{angle_rad,
    /// acceleration_rad_s2, moment_n_m}`. Velocities come with the servo-valves of the
    /// multi-axis closed loop.
    pub axes:
        std::collections::BTreeMap<&'static str, std::collections::BTreeMap<&'static str, f64>>,
    /// The platen's mass, kg.
    pub mass_kg: f64,
    /// The held DOFs.
    pub held_dofs: Vec<&'static str>,
    /// The closed loop's small-signal figures (a table with a `controller`; `null`
    /// otherwise).
    #[serde(rename = "loop")]
    pub loop_figures: Option<TableLoopDescription>,
}

/// One DOF's loop, broken at its drive with the others closed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DofLoopDescription {
    /// Gain margin, dB (`null`: no phase crossover below the controller's Nyquist
    /// frequency).
    pub gain_margin_db: Option<f64>,
    /// Its phase crossover, Hz.
    pub phase_crossover_hz: Option<f64>,
    /// Phase margin, degrees.
    pub phase_margin_deg: Option<f64>,
    /// Its gain crossover, Hz.
    pub gain_crossover_hz: Option<f64>,
    /// Whether this loop is stable by the Nyquist criterion (the others closed).
    pub stable: bool,
    /// Largest |pose/command| of the DOF up to the Nyquist frequency, and where.
    pub peak_gain: f64,
    /// Where that peak is, Hz.
    pub peak_gain_hz: f64,
}

/// The largest cross-talk of one DOF's command at a frequency.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossTalkDescription {
    /// The frequency, Hz.
    pub frequency_hz: f64,
    /// |pose/command| of the commanded DOF itself.
    pub diagonal: f64,
    /// The DOF that responds the most to it (`null` with one free DOF).
    pub largest_dof: Option<&'static str>,
    /// |that response/command| (m/m, rad/rad, m/rad or rad/m).
    pub largest: Option<f64>,
}

/// The closed loop's stability from the eigenvalues of its linearisation
/// (`platen_system::TableLinearisation::stability`: delays by Padé approximants).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoopStabilityDescription {
    /// No closed-loop eigenvalue in the right half-plane.
    pub stable: bool,
    /// The largest real part of the closed-loop eigenvalues off the imaginary axis (beyond
    /// 1e-3 1/s either way: the chambers' mean pressures and unclosed integrators sit on
    /// it), 1/s: negative, the slowest decay of a stable loop; positive, the fastest growth
    /// of an unstable one.
    pub largest_real_part_1_s: f64,
    /// The unstable eigenvalues (upper half-plane of each pair), fastest-growing first:
    /// `[growth rate 1/s, frequency Hz]`.
    pub unstable_poles: Vec<[f64; 2]>,
    /// The DOF that moves the most in the fastest-growing mode (`null` when stable).
    pub unstable_dof: Option<&'static str>,
}

/// `platen model` on a table with a controller: the linearised loop about neutral at rest
/// (mean flow gains, see `platen_system::TableLinearisation`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableLoopDescription {
    /// The whole loop's stability, from its eigenvalues: the verdict (each DOF's margins
    /// below are measured with the other loops closed).
    pub stability: LoopStabilityDescription,
    /// Per free DOF, its loop's margins.
    pub dofs: std::collections::BTreeMap<&'static str, DofLoopDescription>,
    /// Per free DOF's command, its largest cross-talk at 1, 2, 5 and 10 Hz.
    pub cross_talk: std::collections::BTreeMap<&'static str, Vec<CrossTalkDescription>>,
    /// Per actuator its force at rest (the static hold), N.
    pub static_forces_n: std::collections::BTreeMap<String, f64>,
}

/// The frequencies at which `platen model` reports the cross-talk, Hz.
pub const CROSS_TALK_HZ: [f64; 4] = [1.0, 2.0, 5.0, 10.0];

impl TableScenario {
    /// Its description: modes and capacities.
    pub fn describe(&self) -> TableDescription {
        let modes = match &self.specimen {
            Some(s) => self.table.modes_with(s),
            None => self.table.modes(),
        };
        let rates = self.rate_capacities();
        let axes = self
            .table
            .capacities(self.supply_pressure_pa, self.return_pressure_pa)
            .into_iter()
            .map(|c| {
                let keys = if c.dof.is_rotation() {
                    ["angle_rad", "acceleration_rad_s2", "moment_n_m"]
                } else {
                    ["stroke_m", "acceleration_m_s2", "force_n"]
                };
                let mut values: std::collections::BTreeMap<&'static str, f64> = keys
                    .into_iter()
                    .zip([c.stroke, c.acceleration, c.force])
                    .collect();
                if let Some(r) = rates.as_ref().and_then(|r| r.get(&c.dof.index())) {
                    let key = if c.dof.is_rotation() {
                        "rate_rad_s"
                    } else {
                        "velocity_m_s"
                    };
                    values.insert(key, *r);
                }
                (c.dof.name(), values)
            })
            .collect();
        TableDescription {
            name: self.name.clone(),
            modes: modes
                .into_iter()
                .map(|m| ModeDescription {
                    frequency_hz: m.frequency_hz,
                    shape: m.shape.into(),
                })
                .collect(),
            axes,
            mass_kg: self.table.platen().mass_kg(),
            held_dofs: self.table.held().iter().map(Dof::name).collect(),
            loop_figures: self.loop_description(),
        }
    }

    /// The forces that hold the platen (and the specimen's weight) at rest at neutral, N per
    /// actuator (`None` when the actuators cannot).
    fn static_forces_n(&self) -> Option<Vec<f64>> {
        let extra = self.specimen.as_ref().map_or_else(
            platen_model::multi_axis::Wrench::zeros,
            LinearSpecimen::weight_wrench,
        );
        TableHydraulics::static_forces_n(&self.table, &extra).ok()
    }

    /// Per free DOF (by index) the largest rate the valves give at full opening with no load,
    /// either way: each actuator's stroke rate `G_ik·v` within its extend or retract velocity
    /// (a single-acting one's at its static pressure). `None` without a closed loop.
    fn rate_capacities(&self) -> Option<std::collections::BTreeMap<usize, f64>> {
        let sys = self.system.as_ref()?;
        let hyd = &sys.hydraulics;
        let geo = sys.controller.geometry();
        let forces = self.static_forces_n()?;
        let rest = hyd.rest_states(&forces).ok()?;
        let limits: Vec<(f64, f64)> = rest
            .iter()
            .enumerate()
            .map(|(i, s)| hyd.velocities_m_s(i, s.p_a_pa))
            .collect();
        Some(
            geo.free()
                .iter()
                .enumerate()
                .map(|(k, d)| {
                    let reach = |sign: f64| {
                        limits
                            .iter()
                            .enumerate()
                            .map(|(i, &(extend, retract))| {
                                let per = sign * geo.matrix()[(i, k)];
                                if per > 0.0 {
                                    extend / per
                                } else if per < 0.0 {
                                    retract / -per
                                } else {
                                    f64::INFINITY
                                }
                            })
                            .fold(f64::INFINITY, f64::min)
                    };
                    (d.index(), reach(1.0).min(reach(-1.0)))
                })
                .collect(),
        )
    }

    /// The closed loop's linearisation (`None` without one, or when it cannot be linearised).
    fn linearisation(&self) -> Option<platen_system::TableLinearisation> {
        let sys = self.system.as_ref()?;
        platen_system::TableLinearisation::new(
            &self.table,
            &sys.hydraulics,
            &sys.controller,
            self.specimen.as_ref(),
        )
        .ok()
    }

    /// The closed loop's linearisation: margins per DOF and cross-talk (`None` without one,
    /// or when it cannot be linearised).
    fn loop_description(&self) -> Option<TableLoopDescription> {
        let lin = self.linearisation()?;
        let (stability, dofs) = loop_verdict(&lin);
        let mut cross_talk: std::collections::BTreeMap<&'static str, Vec<CrossTalkDescription>> =
            std::collections::BTreeMap::new();
        for f in CROSS_TALK_HZ {
            for c in lin.cross_talk(f) {
                cross_talk
                    .entry(c.command.name())
                    .or_default()
                    .push(CrossTalkDescription {
                        frequency_hz: f,
                        diagonal: c.diagonal.norm(),
                        largest_dof: c.largest.map(|(d, _)| d.name()),
                        largest: c.largest.map(|(_, x)| x.norm()),
                    });
            }
        }
        let static_forces_n = self
            .table
            .actuators()
            .iter()
            .zip(lin.actuators())
            .map(|(a, l)| (a.name.clone(), l.static_force_n))
            .collect();
        Some(TableLoopDescription {
            stability,
            dofs,
            cross_talk,
            static_forces_n,
        })
    }
}

/// The linearised loop's stability (its eigenvalues) alone.
fn loop_verdict_stability(lin: &platen_system::TableLinearisation) -> LoopStabilityDescription {
    let st = lin.stability();
    LoopStabilityDescription {
        stable: st.stable,
        largest_real_part_1_s: st.largest_real_part_1_s,
        unstable_poles: st
            .unstable_poles
            .iter()
            .map(|p| [p.re, p.im / std::f64::consts::TAU])
            .collect(),
        unstable_dof: st.unstable_dof.map(Dof::name),
    }
}

/// The linearised loop's stability (its eigenvalues) and each free DOF's margins.
fn loop_verdict(
    lin: &platen_system::TableLinearisation,
) -> (
    LoopStabilityDescription,
    std::collections::BTreeMap<&'static str, DofLoopDescription>,
) {
    let stability = loop_verdict_stability(lin);
    let dofs = lin
        .free()
        .iter()
        .filter_map(|&d| {
            let m = lin.margins(d)?;
            Some((
                d.name(),
                DofLoopDescription {
                    gain_margin_db: m.gain_margin_db,
                    phase_crossover_hz: m.phase_crossover_hz,
                    phase_margin_deg: m.phase_margin_deg,
                    gain_crossover_hz: m.gain_crossover_hz,
                    stable: m.stable,
                    peak_gain: m.peak_gain,
                    peak_gain_hz: m.peak_gain_hz,
                },
            ))
        })
        .collect();
    (stability, dofs)
}

impl LoopStabilityDescription {
    /// The unstable verdict in words (`None` when stable): its fastest-growing pole and the
    /// DOF that moves most in it.
    pub fn unstable_words(&self) -> Option<String> {
        if self.stable {
            return None;
        }
        let pole = self.unstable_poles.first().map_or(
            "its eigenvalues could not be computed (values far out of range)".to_owned(),
            |[re, f]| format!("a pole grows at {re:.3} 1/s at {f:.2} Hz"),
        );
        let dof = self
            .unstable_dof
            .map_or(String::new(), |d| format!(", mostly in {d}"));
        Some(format!("{pole}{dof}"))
    }
}

/// The text `platen model` prints for a multi-axis scenario.
pub fn description_text(d: &TableDescription) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: multi-axis table, platen {:.1} t",
        d.name,
        d.mass_kg / 1e3
    );
    if !d.held_dofs.is_empty() {
        let _ = writeln!(t, "  held: {}", d.held_dofs.join(", "));
    }
    let _ = writeln!(t, "  modes (valves shut, at neutral):");
    for (i, m) in d.modes.iter().enumerate() {
        let s = m.shape;
        let _ = writeln!(
            t,
            "    {:>2}  {:>8.3} Hz  shape x {:+.3e} y {:+.3e} z {:+.3e} roll {:+.3e} pitch {:+.3e} yaw {:+.3e}",
            i + 1,
            m.frequency_hz,
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5]
        );
    }
    let _ = writeln!(t, "  capacities (bare table, about the static hold):");
    for (axis, values) in &d.axes {
        let list: Vec<String> = values.iter().map(|(k, v)| format!("{k} {v:.4e}")).collect();
        let _ = writeln!(t, "    {axis:<6} {}", list.join(", "));
    }
    if let Some(l) = &d.loop_figures {
        let st = &l.stability;
        if st.stable {
            let _ = writeln!(
                t,
                "  closed loop (linearised at neutral): stable, no pole in the right half-plane"
            );
        } else {
            let poles: Vec<String> = st
                .unstable_poles
                .iter()
                .map(|[re, f]| format!("{re:.3} 1/s at {f:.2} Hz"))
                .collect();
            let _ = writeln!(
                t,
                "  closed loop (linearised at neutral): UNSTABLE, growing {}{}",
                poles.join(", "),
                st.unstable_dof
                    .map_or(String::new(), |d| format!(" (mostly {d})"))
            );
        }
        let _ = writeln!(
            t,
            "  each DOF's loop broken at its drive (the others closed):"
        );
        let show =
            |x: Option<f64>, unit: &str| x.map_or("-".to_owned(), |v| format!("{v:.2} {unit}"));
        for d in Dof::ALL {
            let Some(m) = l.dofs.get(d.name()) else {
                continue;
            };
            let _ = writeln!(
                t,
                "    {:<6} gain margin {} at {}, phase margin {} at {}, peak {:.2} at {:.2} Hz{}",
                d.name(),
                show(m.gain_margin_db, "dB"),
                show(m.phase_crossover_hz, "Hz"),
                show(m.phase_margin_deg, "°"),
                show(m.gain_crossover_hz, "Hz"),
                m.peak_gain,
                m.peak_gain_hz,
                if m.stable { "" } else { "  UNSTABLE" }
            );
        }
        let _ = writeln!(
            t,
            "  cross-talk (largest other DOF per command, |response/command|):"
        );
        for d in Dof::ALL {
            let Some(list) = l.cross_talk.get(d.name()) else {
                continue;
            };
            let cells: Vec<String> = list
                .iter()
                .map(|c| match (c.largest_dof, c.largest) {
                    (Some(o), Some(x)) => format!(
                        "{:.0} Hz: {:.3} ({o} {:.2e})",
                        c.frequency_hz, c.diagonal, x
                    ),
                    _ => format!("{:.0} Hz: {:.3}", c.frequency_hz, c.diagonal),
                })
                .collect();
            let _ = writeln!(t, "    {:<6} {}", d.name(), cells.join("; "));
        }
    }
    t
}
