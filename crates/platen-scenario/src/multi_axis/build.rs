//! From the file's `table`, `specimen` and `initial` to the model: geometry checks, the
//! table, its limits, its hydraulics and controller.

use super::*;

/// The error of a model-layer refusal of the table, at its JSON path under `table`.
pub(super) fn table_error(ctx: &Ctx, spec: &TableSpec, e: ModelError) -> ScenarioError {
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

pub(super) fn vector(p: [f64; 3]) -> Vector3<f64> {
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
pub(super) fn check_geometry(ctx: &Ctx, spec: &TableSpec) -> Result<()> {
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
pub(super) fn build_table(ctx: &Ctx, spec: &TableSpec) -> Result<MultiAxisTable> {
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
    let actuators = (spec.actuators.iter().enumerate())
        .map(|(i, a)| build_actuator(ctx, i, a))
        .collect::<Result<Vec<_>>>()?;
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
    let bearings = (spec.bearings.iter().enumerate())
        .map(|(k, b)| build_bearing(ctx, spec, k, b))
        .collect::<Result<Vec<_>>>()?;
    MultiAxisTable::new(TableParts {
        platen,
        actuators,
        struts,
        bearings,
        held: held_dofs(ctx, spec)?,
        oil_bulk_modulus_pa: spec
            .oil_bulk_modulus_pa
            .unwrap_or(DEFAULT_OIL_BULK_MODULUS_PA),
    })
    .map_err(|e| table_error(ctx, spec, e))
}

/// `table.actuators[i]`: swivel-mounted (`platen_m`) or on a pad (`pad`).
fn build_actuator(ctx: &Ctx, i: usize, a: &ActuatorSpec) -> Result<Actuator> {
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
    Ok(Actuator {
        name: a.name.clone(),
        base_m: vector(a.base_m),
        mount,
        cap_side_area_m2: a.cap_side_area_m2,
        rod_side_area_m2: a.rod_side_area_m2,
        chamber_volume_m3: a.chamber_volume_m3,
        stroke_m: a.stroke_m,
    })
}

/// `table.bearings[k]`: loaded by the actuator under it (`actuator`) or a constant
/// `normal_force_n`.
fn build_bearing(ctx: &Ctx, spec: &TableSpec, k: usize, b: &BearingSpec) -> Result<Bearing> {
    let at = |key: &str| format!("table.bearings[{k}].{key}");
    let load = match (&b.actuator, b.normal_force_n) {
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
        _ => {
            return Err(ctx.invalid(
                &format!("table.bearings[{k}]"),
                "(both or neither)",
                "either `actuator` (the swivel-mounted actuator under it) or `normal_force_n`",
            ))
        }
    };
    Ok(Bearing {
        platen_m: vector(b.platen_m),
        friction_coefficient: b.friction_coefficient,
        load,
    })
}

/// `table.held_dofs`: each a DOF's name, once.
fn held_dofs(ctx: &Ctx, spec: &TableSpec) -> Result<DofSet> {
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
    Ok(held)
}

/// `table.limits`, every value given finite and > 0.
pub(super) fn build_limits(
    ctx: &Ctx,
    spec: &TableSpec,
) -> Result<crate::table_file::AxisLimitsSpec> {
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
pub(super) fn system_error(ctx: &Ctx, e: SystemError) -> ScenarioError {
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
pub(super) fn build_system(
    ctx: &Ctx,
    integrator: Option<&crate::file::IntegratorSpec>,
    spec: &TableSpec,
    controller: &crate::table_file::TableControllerSpec,
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
) -> Result<TableLoopSystem> {
    let hydraulics = build_hydraulics(ctx, spec, table, specimen)?;
    let controller = build_controller(ctx, controller, table)?;
    crate::loop_budget::check_orifices(ctx, spec, &hydraulics, controller.period_s())?;
    let method = build_loop_method(ctx, integrator, table, specimen, &hydraulics, &controller)?;
    Ok(TableLoopSystem {
        hydraulics,
        controller,
        method,
    })
}

/// Every actuator's servo-valves and leakage, and the supply; the valves share one delay,
/// and the chambers can hold the table (and `specimen`) at rest between the return and
/// supply pressures.
fn build_hydraulics(
    ctx: &Ctx,
    spec: &TableSpec,
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
) -> Result<TableHydraulics> {
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
    Ok(hydraulics)
}

/// The DOF controller of `table.controller`: gains for every free DOF, none for a held one.
fn build_controller(
    ctx: &Ctx,
    controller: &crate::table_file::TableControllerSpec,
    table: &MultiAxisTable,
) -> Result<DofController> {
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
    DofController::new(rate, loops, balance, geometry).map_err(|e| system_error(ctx, e))
}

/// The loop's integrator: `integrator`, or RK4 resolving the loop's fastest mode.
fn build_loop_method(
    ctx: &Ctx,
    integrator: Option<&crate::file::IntegratorSpec>,
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    hydraulics: &TableHydraulics,
    controller: &DofController,
) -> Result<LoopMethod> {
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
    let rate = controller.sample_rate_hz();
    loop_method_at(ctx, integrator, period, fastest, k, || {
        ctx.invalid(
            "table.controller.sample_rate_hz",
            rate,
            format!(
                "a rate at which RK4 resolves the loop's fastest mode ({:.1} Hz) within 1e6 \
                 steps per period, or {{\"method\": \"dopri5\"}}",
                fastest / std::f64::consts::TAU
            ),
        )
    })
}

/// `initial` of a forward run: the pose and rates given by name, the rest zero; a held DOF's
/// must be 0, and the uniaxial names are refused.
pub(super) fn build_initial(
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
