//! The validated scenario of a multi-axis table and its run.

use super::*;

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
pub(super) enum Given {
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
        refuse_uniaxial_keys(&ctx, file, closed)?;
        let table = build_table(&ctx, spec)?;
        let specimen = crate::specimen::table_specimen(&ctx, file.specimen.as_ref())?;
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
        let (run, derived) = given_run(&ctx, file, &table, closed, given_motion)?;
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

    /// The columns of its run in their order (its output file's header), known before the
    /// run: the forward run's, the closed loop's or the inverse's (see
    /// [`platen_integrate::table_columns`], [`platen_integrate::table_loop_columns`],
    /// [`platen_integrate::inverse_table_columns`]).
    pub fn columns(&self) -> Vec<String> {
        let specimen = self.specimen.as_ref();
        match &self.run {
            TableRunSpec::Inverse { .. } => inverse_table_columns(&self.table, specimen.is_some()),
            TableRunSpec::Loop { .. } => table_loop_columns(&self.table, specimen),
            TableRunSpec::Forward { .. } => table_columns(&self.table, specimen),
        }
    }

    /// The time stamps of its run's rows, s: one row at each sample of its motion, command
    /// or forces.
    pub fn output_t_s(&self) -> &[f64] {
        match &self.run {
            TableRunSpec::Inverse { motion } | TableRunSpec::Loop { command: motion } => {
                motion.t_s()
            }
            TableRunSpec::Forward { forces, .. } => forces.t_s(),
        }
    }

    /// Runs it, delivering its rows to `sink` as they are computed (the columns' names first,
    /// [`TableScenario::columns`]); returns the closed loop's own figures when it is one.
    ///
    /// # Errors
    /// As [`TableScenario::run`] (the rows before a failure delivered); a closed loop that
    /// diverged is [`ScenarioError::TableLoopUnstable`] when its linearisation is unstable.
    pub fn run_into<K: TableSink>(&self, sink: &mut K) -> Result<Option<TableLoopStats>> {
        let specimen = self.specimen.as_ref();
        let run = match &self.run {
            TableRunSpec::Inverse { motion } => {
                inverse_table_into(&self.table, specimen, motion, sink)
            }
            TableRunSpec::Forward {
                forces,
                method,
                initial,
            } => forward_table_into(&self.table, specimen, forces, *method, *initial, sink),
            TableRunSpec::Loop { command } => return self.run_loop_into(command, sink).map(Some),
        };
        run.map(|()| None).map_err(ScenarioError::TableRun)
    }

    /// [`TableScenario::run_into`] of its closed loop driven by `command`.
    fn run_loop_into<K: TableSink>(
        &self,
        command: &PoseMotion,
        sink: &mut K,
    ) -> Result<TableLoopStats> {
        let Some(sys) = &self.system else {
            // Every scenario read from a file has its loop; one assembled by hand may not.
            return Err(ScenarioError::TableRun(IntegrateError::LengthMismatch {
                what: "closed-loop systems (a `Loop` run needs the scenario's `system`)",
                found: 0,
                expected: 1,
            }));
        };
        let run = TableLoopRun {
            table: &self.table,
            hydraulics: &sys.hydraulics,
            controller: &sys.controller,
            specimen: self.specimen.as_ref(),
            command,
            method: sys.method,
        };
        forward_table_loop_into(&run, sink).map_err(|source| {
            // A loop that diverged: say that it is unstable, where, and in which DOF.
            match self
                .linearisation()
                .and_then(|lin| loop_verdict_stability(&lin).unstable_words())
            {
                Some(verdict) => ScenarioError::TableLoopUnstable { verdict, source },
                None => ScenarioError::TableRun(source),
            }
        })
    }

    /// Runs it in memory, with the closed loop's own figures when it is one.
    ///
    /// # Errors
    /// As [`TableScenario::run_into`].
    pub fn run_with_stats(&self) -> Result<(TableRun, Option<TableLoopStats>)> {
        let mut run = TableRun::default();
        let stats = self.run_into(&mut run)?;
        Ok((run, stats))
    }

    /// Runs it in memory.
    ///
    /// # Errors
    /// [`ScenarioError::TableRun`] when the actuators lose rank at a pose of the motion
    /// (inverse) or the integration fails (forward: a non-finite state, Dopri5 unable to meet
    /// its tolerance); [`ScenarioError::TableLoopUnstable`] for a closed loop that diverged
    /// with an unstable linearisation.
    pub fn run(&self) -> Result<TableRun> {
        self.run_with_stats().map(|(run, _)| run)
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

/// The path a scenario's motion record resolves to (for messages).
pub fn motion_path(path: &Path, file: &ScenarioFile) -> Option<PathBuf> {
    file.excitation
        .motion_csv
        .as_ref()
        .map(|rel| Ctx { path }.resolve(rel))
}

/// The keys a scenario with a `table` must not have: the uniaxial platen's (`model`,
/// `table_system`, `limits`), and `initial` or `integrator` where nothing uses them.
fn refuse_uniaxial_keys(ctx: &Ctx, file: &ScenarioFile, closed: bool) -> Result<()> {
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
    Ok(())
}

/// What the scenario runs, from the motion `given`: its file's excitation, a command in its
/// place (a closed loop only), or a still motion (its description).
fn given_run(
    ctx: &Ctx,
    file: &ScenarioFile,
    table: &MultiAxisTable,
    closed: bool,
    given: Given,
) -> Result<(TableRunSpec, Derived)> {
    Ok(match given {
        Given::File => build_run(ctx, file, table, closed)?,
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
    })
}
