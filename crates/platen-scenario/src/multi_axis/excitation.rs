//! The excitation of a multi-axis scenario: a six-DOF motion (file, PEER records per axis,
//! generators per axis) or recorded actuator forces.

use super::*;

/// `excitation` of a multi-axis scenario: a six-DOF motion (`motion_csv`, or `ground_motion`
/// per axis), the inverse's prescribed motion or the closed loop's command (`closed`); or
/// recorded actuator forces (`force_csv`, a forward run, open loop).
pub(super) fn build_run(
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
pub(super) fn read_pose_motion(
    ctx: &Ctx,
    file: &ScenarioFile,
    path: &Path,
) -> Result<(PoseMotion, Derived)> {
    let ex = &file.excitation;
    let optional: Vec<&'static str> = POSE_COLUMNS
        .iter()
        .chain(&RATE_COLUMNS)
        .chain(&ACCELERATION_COLUMNS)
        .copied()
        .collect();
    let mut cols = read_mapped(ctx, path, ex, &["t_s"], &optional)?;
    check_pose_columns(path, &cols)?;
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
            note_derived(k, how, &mut derived);
        }
        dofs.push(motion);
    }
    let dofs: [platen_signal::Motion; 6] = dofs.try_into().expect("six DOFs");
    let motion = PoseMotion::new(dofs).map_err(|cause| crate::excitation::rejected(path, cause))?;
    Ok((motion, derived))
}

/// Refuses a six-DOF motion record's columns `cols` (read from `path`) without a pose
/// column, or with a value beyond any table's reach.
fn check_pose_columns(
    path: &Path,
    cols: &std::collections::BTreeMap<&'static str, Vec<f64>>,
) -> Result<()> {
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
    Ok(())
}

/// Files how DOF `k`'s rate and acceleration were derived (`how`, in the uniaxial columns'
/// names) in `derived`, under the DOF's own columns' names.
fn note_derived(k: usize, how: Derived, derived: &mut Derived) {
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

/// `excitation.ground_motion` per axis: each record integrated as the uniaxial
/// `ground_motion` is, the axes on one time grid (the shortest record's, every record at
/// the same `sample_rate_hz`), the rotations and absent axes held at zero.
pub(super) fn axis_ground_motion(
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
pub(super) fn axis_generated_motion(
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
pub(super) const AXES: [&str; 3] = ["x", "y", "z"];

/// The six-DOF motion of the given translational motions (each sampled at `rates_hz`), on
/// one grid: the shortest motion's, all at one rate; the rotations and absent axes still.
/// `derived(k)` names the channels of axis `k` that were derived, not given.
pub(super) fn axis_motion<const N: usize>(
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

/// `excitation.force_csv` of a multi-axis scenario: `t_s` and `{name}_force_n` per actuator,
/// cut to `duration_s`; a forward run with the scenario's `integrator`.
pub(super) fn forward_run(
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
