//! Scenarios of a multi-axis (six-DOF) table: a scenario file with a `table` (see the
//! contract in `docs/multi-axis.md`). [`TableSpec`] is the key as written; [`TableScenario`]
//! the validated scenario and its run.
//!
//! What runs today: the **inverse** of a prescribed six-DOF motion (`excitation.motion_csv`
//! with `t_s` and any of `x_m` … `yaw_rad`, absent ones at 0, optional rates `x_m_s` … and
//! accelerations `x_m_s2` …, derived from the pose where absent), with a storeys or general
//! linear specimen. Forward runs from actuator forces, the closed loop and the `lhpost6`
//! preset are refused with their key named.

use std::path::{Path, PathBuf};

use nalgebra::{DMatrix, Matrix3, Unit, Vector3};
use serde::Serialize;

use platen_integrate::{
    forward_table, inverse_table, ActuatorForces, ForceRecord, Method, PoseMotion, TableRun,
};
use platen_model::multi_axis::{
    Actuator, Bearing, BearingLoad, Coords, Dof, DofSet, LinearSpecimen, Mount, MultiAxisTable,
    Pad, RigidPlaten, Strut, TableParts,
};
use platen_model::ModelError;

use crate::ctx::{check_finite, check_positive, Ctx};
use crate::error::{Result, ScenarioError};
use crate::excitation::{motion_run, read_mapped, Derived};
use crate::file::{ScenarioFile, SpecimenSpec};
use crate::scenario::Run;
pub use crate::table_file::{ActuatorSpec, BearingSpec, PadSpec, PlatenSpec, StrutSpec, TableSpec};

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
}

impl TableScenario {
    /// Validates a parsed scenario file that has a `table`.
    ///
    /// # Errors
    /// Every bad value with its JSON path (`table.actuators[2].platen_m`, …) and every error
    /// of the motion record (with file and line); a file without `table` is refused.
    pub fn from_file(path: &Path, file: &ScenarioFile) -> Result<Self> {
        let ctx = Ctx { path };
        let Some(spec) = &file.table else {
            return Err(ctx.invalid("table", "(absent)", "a multi-axis table"));
        };
        for (key, given) in [
            ("model", file.model.is_some()),
            ("table_system", file.table_system.is_some()),
            ("limits", file.limits.is_some()),
            (
                "initial",
                file.initial.is_some() && file.excitation.force_csv.is_none(),
            ),
            (
                "integrator",
                file.integrator.is_some() && file.excitation.force_csv.is_none(),
            ),
        ] {
            if given {
                return Err(ctx.invalid(
                    key,
                    "(given)",
                    "no such key beside a `table` (the table holds its platen and its hydraulics; \
                     an integrator and an initial state belong to a forward run, from \
                     `force_csv`; per-axis limits are not built yet)",
                ));
            }
        }
        let table = build_table(&ctx, spec)?;
        let (run, derived) = build_run(&ctx, file, &table)?;
        let specimen = build_specimen(&ctx, file.specimen.as_ref())?;
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
        })
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
        };
        run.map_err(ScenarioError::TableRun)
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

/// The value at `json_path` (`a.b[2].c`) of `value`, as compact JSON (for messages).
fn value_at(value: &serde_json::Value, json_path: &str) -> String {
    let pointer: String = json_path
        .split('.')
        .flat_map(|part| {
            let mut pieces = part.split('[');
            let key = pieces.next().unwrap_or_default().to_owned();
            std::iter::once(key).chain(pieces.map(|p| p.trim_end_matches(']').to_owned()))
        })
        .map(|p| format!("/{p}"))
        .collect();
    value
        .pointer(&pointer)
        .map_or_else(|| "(absent)".to_owned(), ToString::to_string)
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
}

/// `table` into a validated table.
fn build_table(ctx: &Ctx, spec: &TableSpec) -> Result<MultiAxisTable> {
    if let Some(name) = &spec.preset {
        return Err(ctx.invalid(
            "table.preset",
            format!("{name:?}"),
            "an explicit table: the lhpost6 preset comes with the multi-axis closed loop",
        ));
    }
    for (key, given) in [
        ("table.controller", spec.controller.is_some()),
        ("table.accumulator", spec.accumulator.is_some()),
    ] {
        if given {
            return Err(ctx.invalid(
                key,
                "(given)",
                "nothing yet: the multi-axis closed loop (controller, valves, supply) is not built \
                 yet; remove the key to run the table's mechanics",
            ));
        }
    }
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
        for (key, given) in [
            ("servo_valve", a.servo_valve.is_some()),
            ("leakage_m3_s_per_pa", a.leakage_m3_s_per_pa.is_some()),
        ] {
            if given {
                return Err(ctx.invalid(
                    &at(key),
                    "(given)",
                    "nothing yet: an actuator's valve and leakage belong to the multi-axis closed \
                     loop, not built yet",
                ));
            }
        }
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

/// `excitation` of a multi-axis scenario: `motion_csv` only, for now.
fn build_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    table: &MultiAxisTable,
) -> Result<(TableRunSpec, Derived)> {
    let ex = &file.excitation;
    if let Some(rel) = &ex.force_csv {
        return forward_run(ctx, file, table, &ctx.resolve(rel)).map(|r| (r, Derived::new()));
    }
    let Some(rel) = &ex.motion_csv else {
        let given = crate::excitation::named_sources(ex);
        let key = given
            .first()
            .map_or("excitation".to_owned(), |k| format!("excitation.{k}"));
        return Err(ctx.invalid(
            &key,
            "(given)",
            "motion_csv (the inverse of a six-DOF motion) or force_csv (`t_s` and \
             `{name}_force_n` per actuator: a forward run)",
        ));
    };
    for (key, given) in [
        ("excitation.lowpass_hz", ex.lowpass_hz.is_some()),
        (
            "excitation.rest_velocity_m_s",
            ex.rest_velocity_m_s.is_some(),
        ),
    ] {
        if given {
            return Err(ctx.invalid(key, "(given)", "nothing: not used by a multi-axis inverse"));
        }
    }
    let path = ctx.resolve(rel);
    let optional: Vec<&'static str> = POSE_COLUMNS
        .iter()
        .chain(&RATE_COLUMNS)
        .chain(&ACCELERATION_COLUMNS)
        .copied()
        .collect();
    let mut cols = read_mapped(ctx, &path, ex, &["t_s"], &optional)?;
    if !POSE_COLUMNS.iter().any(|c| cols.contains_key(c)) {
        return Err(ScenarioError::Io(platen_io::IoError::Record {
            path: path.clone(),
            message: "a six-DOF motion needs at least one of the columns x_m, y_m, z_m, \
                      roll_rad, pitch_rad, yaw_rad (absent ones are 0)"
                .into(),
        }));
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
        let (run, how) = motion_run(ctx, file, &path, t.clone(), u, v, a)?;
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
    let motion =
        PoseMotion::new(dofs).map_err(|cause| crate::excitation::rejected(&path, cause))?;
    Ok((
        TableRunSpec::Inverse {
            motion: Box::new(motion),
        },
        derived,
    ))
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
    /// Whether stroke and force stayed within the limits.
    pub respected: bool,
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
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub specimen: std::collections::BTreeMap<&'static str, f64>,
    /// Whether every actuator stayed within its limits.
    pub within_limits: bool,
    /// The CSV written, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub output: Option<String>,
}

fn abs_max(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m: f64, v| m.max(v.abs()))
}

impl TableScenario {
    /// The summary of `run` (a run of this scenario); `output` the CSV written.
    pub fn summary(&self, run: &TableRun, output: Option<&Path>) -> TableSummary {
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
        let actuators: Vec<ActuatorPeaks> = self
            .table
            .actuators()
            .iter()
            .zip(self.force_limits_n())
            .map(|(a, (pull, push))| {
                let force = col(&format!("{}_force_n", a.name));
                let stroke = abs_max(col(&format!("{}_stroke_m", a.name)));
                let max = force.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let min = force.iter().copied().fold(f64::INFINITY, f64::min);
                ActuatorPeaks {
                    name: a.name.clone(),
                    peak_stroke_m: stroke,
                    stroke_limit_m: a.stroke_m,
                    max_force_n: max,
                    min_force_n: min,
                    push_limit_n: push,
                    pull_limit_n: pull,
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
        TableSummary {
            name: self.name.clone(),
            kind: match self.run {
                TableRunSpec::Inverse { .. } => "inverse",
                TableRunSpec::Forward { .. } => "forward",
            },
            samples: run.len(),
            duration_s: t.last().zip(t.first()).map_or(0.0, |(b, a)| b - a),
            derived: self.derived.clone(),
            axes,
            within_limits: actuators.iter().all(|a| a.respected),
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
    let what = if s.kind == "forward" {
        "forward from the actuator forces"
    } else {
        "inverse of a six-DOF motion"
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
}

impl TableScenario {
    /// Its description: modes and capacities.
    pub fn describe(&self) -> TableDescription {
        let modes = match &self.specimen {
            Some(s) => self.table.modes_with(s),
            None => self.table.modes(),
        };
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
                let values = keys
                    .into_iter()
                    .zip([c.stroke, c.acceleration, c.force])
                    .collect();
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
        }
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
    t
}
