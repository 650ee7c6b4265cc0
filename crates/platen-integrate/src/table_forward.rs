//! The multi-axis platen forward from recorded actuator forces ([`forward_table`]): the
//! table's plant ([`crate::table_plant`]) with a [`Recorded`] source on the record's grid,
//! RK4 or Dopri5; the run's columns ([`Rows`]) delivered to a [`TableSink`]; the platen's
//! energies.

use platen_model::multi_axis::{Coords, Dof, LinearSpecimen, MultiAxisTable, Wrench};

use crate::clock::GridClock;
use crate::error::{IntegrateError, Result};
use crate::event::Mode;
use crate::grid::{Grid, GridStep};
use crate::machine::{Machine, PieceMethod, DI, W, Y};
use crate::method::Method;
use crate::multi_axis::TableRun;
use crate::output::TableSink;
use crate::table_plant::{
    pose, reaim, start_machine, start_state, table_step_error, Forces, Source, TablePlant, BARE,
    MAX_TABLE_ACTUATORS, MAX_TABLE_SPECIMEN_DOFS, QD, WITH_SPECIMEN, Z,
};

/// The actuator forces of a forward run: one record per actuator on one time grid.
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorForces {
    t_s: Vec<f64>,
    forces_n: Vec<Vec<f64>>,
}

impl ActuatorForces {
    /// The records `forces_n[i]` (actuator `i`, N) at times `t_s` (s, uniform, strictly
    /// increasing), linear between samples.
    ///
    /// # Errors
    /// [`IntegrateError::LengthMismatch`], [`IntegrateError::NonFiniteInput`] and the checks
    /// of a force record ([`crate::ForceRecord::new`]) on the time column.
    pub fn new(t_s: Vec<f64>, forces_n: Vec<Vec<f64>>) -> Result<Self> {
        // The time grid's checks: those of a force record.
        let first = forces_n
            .first()
            .cloned()
            .unwrap_or_else(|| vec![0.0; t_s.len()]);
        crate::ForceRecord::new(t_s.clone(), first)?;
        for f in &forces_n {
            if f.len() != t_s.len() {
                return Err(IntegrateError::LengthMismatch {
                    what: "an actuator's force",
                    found: f.len(),
                    expected: t_s.len(),
                });
            }
            if let Some(index) = f.iter().position(|x| !x.is_finite()) {
                return Err(IntegrateError::NonFiniteInput {
                    what: "an actuator's force",
                    index,
                    value: f[index],
                });
            }
        }
        Ok(ActuatorForces { t_s, forces_n })
    }

    /// The sample times, s.
    pub fn t_s(&self) -> &[f64] {
        &self.t_s
    }

    /// Actuator `i`'s force record, N.
    pub fn force_n(&self, i: usize) -> &[f64] {
        &self.forces_n[i]
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether it has no sample.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }
}

/// Where a position lands: sample interval `j`, fraction `w` of it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct At {
    j: usize,
    w: f64,
}

/// Recorded actuator forces on their time grid: the source of a forward run.
pub(crate) struct Recorded<'a> {
    forces: &'a ActuatorForces,
    /// The time grid and the step being taken (the grid's force is the first actuator's,
    /// unused: the input is every actuator's, [`Recorded::forces`]).
    clock: GridClock<'a>,
}

impl<'a, const L: usize> Source<L> for Recorded<'a> {
    type Input = At;
    const RATES_ON_COMMIT: bool = false;
    const NEEDS_STROKES: bool = false;

    #[inline(always)]
    fn input(&self, at: f64) -> At {
        let n = self.clock.n;
        At {
            j: n.j,
            w: (n.i + at) * self.clock.grid.inv_k,
        }
    }

    fn forces(&self, at: At, _y: &Y<L>) -> Forces {
        let (j, w) = (at.j, at.w);
        let mut out = [0.0; MAX_TABLE_ACTUATORS];
        for (o, f) in out.iter_mut().zip(&self.forces.forces_n) {
            *o = if w == 0.0 {
                f[j]
            } else {
                f[j] * (1.0 - w) + f[j + 1] * w
            };
        }
        out
    }

    crate::clock::clock_field!(GridClock<'a>);
}

/// The forward run of `table` under `forces` from the pose `initial` with rates
/// `initial_rates` (held DOFs must be 0 in both), with fixed-step RK4 or adaptive Dopri5
/// through the one mode machine, the bearings' friction with exact planar stick-slip,
/// delivering every sample of the record as a row of the run's columns: `t_s`; the pose,
/// its rates and accelerations; per actuator `{name}_stroke_m`, `{name}_force_n`; per strut
/// `{name}_force_n`; `actuator_work_j` (the actuators' work on the platen since the start);
/// with friction `dissipated_j` (the friction's) and `stuck` (1 while the platen rests in
/// its plane, else 0); with a `specimen` its `base_force_{x,y,z}_n` and
/// `overturning_moment_{x,y}_n_m` (the force the platen exerts on it, about the reference
/// point), each of its DOFs `specimen{i}_z` and rate `specimen{i}_zdot` (in the DOF's own
/// SI unit, m or rad, relative to the platen) and `specimen_damping_j` (its dampers'
/// dissipation). The specimen starts at rest in its static deflection under its weight and
/// feels the platen's acceleration less gravity's, as in [`crate::inverse_table`].
///
/// # Errors
/// [`IntegrateError::LengthMismatch`] when `forces` has not one record per actuator (or the
/// table more than [`MAX_TABLE_ACTUATORS`]); [`IntegrateError::InvalidStep`] for a step
/// that does not divide the sample interval; [`IntegrateError::NonFiniteState`] and
/// [`IntegrateError::AdaptiveFailed`] as the other forward runs.
pub fn forward_table(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    forces: &ActuatorForces,
    method: Method,
    initial: Coords,
    initial_rates: Coords,
) -> Result<TableRun> {
    let mut out = TableRun::default();
    let start = (initial, initial_rates);
    forward_table_into(table, specimen, forces, method, start, &mut out)?;
    Ok(out)
}

/// [`forward_table`] from the pose and rates `(initial, initial_rates)`, delivering its rows
/// to `sink` (the columns' names first, [`TableSink::start`]).
///
/// # Errors
/// As [`forward_table`] (the rows before a failure delivered).
pub fn forward_table_into<K: TableSink>(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    forces: &ActuatorForces,
    method: Method,
    start: (Coords, Coords),
    sink: &mut K,
) -> Result<()> {
    if forces.forces_n.len() != table.actuators().len() {
        return Err(IntegrateError::LengthMismatch {
            what: "actuator force records",
            found: forces.forces_n.len(),
            expected: table.actuators().len(),
        });
    }
    if table.actuators().len() > MAX_TABLE_ACTUATORS {
        return Err(IntegrateError::LengthMismatch {
            what: "actuators of a forward run (at most MAX_TABLE_ACTUATORS)",
            found: table.actuators().len(),
            expected: MAX_TABLE_ACTUATORS,
        });
    }
    match specimen {
        None => run::<BARE, K>(table, None, forces, method, start, sink),
        Some(s) if s.len() <= MAX_TABLE_SPECIMEN_DOFS => {
            run::<WITH_SPECIMEN, K>(table, Some(s), forces, method, start, sink)
        }
        Some(s) => Err(IntegrateError::LengthMismatch {
            what: "specimen DOFs of a forward run (at most MAX_TABLE_SPECIMEN_DOFS)",
            found: s.len(),
            expected: MAX_TABLE_SPECIMEN_DOFS,
        }),
    }
}

/// [`forward_table_into`] with a state of `L` numbers.
fn run<const L: usize, K: TableSink>(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    forces: &ActuatorForces,
    method: Method,
    (initial, initial_rates): (Coords, Coords),
    out: &mut K,
) -> Result<()> {
    let dt = forces.t_s[1] - forces.t_s[0];
    let (k, pieces) = match method {
        Method::Rk4(rk4) => (u64::from(rk4.steps_per_sample()), PieceMethod::Rk4),
        Method::Dopri5(s) => (
            1,
            PieceMethod::Dopri5 {
                rtol: s.rtol(),
                atol: s.atol(),
            },
        ),
    };
    let h = dt / k as f64;
    let source = Recorded {
        forces,
        clock: GridClock::new(Grid {
            force: forces.forces_n.first().map_or(&[][..], Vec::as_slice),
            inv_k: 1.0 / k as f64,
            h,
            t0: forces.t_s[0],
        }),
    };
    let y = start_state::<L>(table, specimen, initial, initial_rates);
    let mut m = start_machine(table, specimen, source, y, h, pieces);
    let mut rows = Rows::new(table, specimen, Vec::new());
    rows.start(out, forces.len());
    rows.push(&m, forces.t_s[0], &recorded_forces(forces, 0), &[], out);
    let mut n = 0u64;
    for j in 0..forces.len() - 1 {
        for i in 0..k {
            step(&mut m, GridStep { n, j, i: i as f64 })?;
            n += 1;
        }
        let f = recorded_forces(forces, j + 1);
        rows.push(&m, forces.t_s[j + 1], &f, &[], out);
    }
    Ok(())
}

/// The recorded forces at sample `j`.
fn recorded_forces(forces: &ActuatorForces, j: usize) -> Vec<f64> {
    forces.forces_n.iter().map(|f| f[j]).collect()
}

/// One grid step: RK4's single piece when it is safe, else the machine's advance. A slide
/// with friction has its gauge aimed along its motion first.
fn step<const L: usize>(
    m: &mut Machine<TablePlant<'_, Recorded<'_>, L>, L>,
    n: GridStep,
) -> Result<()> {
    m.plant.source.clock.n = n;
    m.stats.steps += 1;
    let (q0, _) = pose(&m.y);
    let sliding = reaim(m);
    if sliding && m.is_rk4() && m.slip_fast::<true>(0.0) {
        return Ok(());
    }
    m.advance_span()
        .map_err(|e| table_step_error(e, m.plant.table, &q0))
}

/// The specimen's base force and overturning moments (the force the platen exerts on it,
/// about the reference point), as the inverse names them.
const SPECIMEN_COLUMNS: [&str; 5] = [
    "base_force_x_n",
    "base_force_y_n",
    "base_force_z_n",
    "overturning_moment_x_n_m",
    "overturning_moment_y_n_m",
];

/// The columns of a forward run ([`forward_table_into`]) of `table` carrying `specimen`, in
/// their order (the closed loop's follow them, [`crate::table_loop_columns`]): what
/// [`TableSink::start`] receives, known before the run so that its output can be created
/// first.
pub fn table_columns(table: &MultiAxisTable, specimen: Option<&LinearSpecimen>) -> Vec<String> {
    let mut names = vec!["t_s".to_string()];
    for suffix in ["", "_s", "_s2"] {
        names.extend(Dof::ALL.map(|d| format!("{}_{}{suffix}", d.name(), d.unit())));
    }
    for a in table.actuators() {
        names.push(format!("{}_stroke_m", a.name));
        names.push(format!("{}_force_n", a.name));
    }
    for s in table.struts() {
        names.push(format!("{}_force_n", s.name));
    }
    if specimen.is_some() {
        names.extend(SPECIMEN_COLUMNS.map(String::from));
    }
    names.push("actuator_work_j".into());
    if table.has_friction() {
        names.push("dissipated_j".into());
        names.push("stuck".into());
    }
    if let Some(s) = specimen {
        for i in 1..=s.len() {
            names.push(format!("specimen{i}_z"));
            names.push(format!("specimen{i}_zdot"));
        }
        names.push("specimen_damping_j".into());
    }
    names
}

/// The run's columns: their names, and each row filled a sample at a time for a sink.
pub(crate) struct Rows {
    names: Vec<String>,
    row: Vec<f64>,
}

impl Rows {
    /// The columns of a run of `table` carrying `specimen` ([`table_columns`]), with `extra`
    /// columns last.
    pub(crate) fn new(
        table: &MultiAxisTable,
        specimen: Option<&LinearSpecimen>,
        extra: Vec<String>,
    ) -> Self {
        let mut names = table_columns(table, specimen);
        names.extend(extra);
        Rows {
            names,
            row: Vec::new(),
        }
    }

    /// Hands the columns' names to `sink`, before the first of `samples` rows.
    pub(crate) fn start<K: TableSink>(&self, sink: &mut K, samples: usize) {
        sink.start(&self.names, samples);
    }

    /// Delivers to `sink` the row at time `t_s` with the actuator forces `forces` and the
    /// `extra` columns' values.
    pub(crate) fn push<S: Source<L>, K: TableSink, const L: usize>(
        &mut self,
        m: &Machine<TablePlant<'_, S, L>, L>,
        t_s: f64,
        forces: &[f64],
        extra: &[f64],
        sink: &mut K,
    ) {
        let p = &m.plant;
        let (q, qd) = pose(&m.y);
        self.row.clear();
        self.row.push(t_s);
        self.row.extend(q.iter().chain(qd.iter()));
        self.row.extend((0..6).map(|k| m.k[QD + k]));
        for (i, f) in forces.iter().enumerate().take(p.table.actuators().len()) {
            self.row.push(p.table.actuator_at(i, &q).stroke_m);
            self.row.push(*f);
        }
        for s in 0..p.table.struts().len() {
            self.row.push(p.table.strut_at(s, &q).force_n);
        }
        if p.specimen.is_some() {
            let base = -p.specimen_push(&m.y);
            self.row
                .extend([base[0], base[1], base[2], base[3], base[4]]);
        }
        self.row.push(m.y[W]);
        if p.friction {
            self.row.push(m.y[DI]);
            self.row.push(f64::from(u8::from(m.mode == Mode::Stick)));
        }
        if let Some(s) = p.specimen {
            let n = s.len();
            for i in 0..n {
                self.row.push(m.y[Z + i]);
                self.row.push(m.y[Z + n + i]);
            }
            self.row.push(m.y[crate::machine::SD]);
        }
        self.row.extend_from_slice(extra);
        sink.accept(&self.row);
    }
}

/// The platen's kinetic energy at pose `q` with rates `qd`, J (for energy balances).
pub fn table_kinetic_energy_j(table: &MultiAxisTable, q: &Coords, qd: &Coords) -> f64 {
    let k = table.kinematics(q, qd);
    let omega = k.omega_rad_s;
    let twist = Wrench::new(qd[0], qd[1], qd[2], omega[0], omega[1], omega[2]);
    0.5 * twist.dot(&(table.spatial_mass_matrix_in(&k) * twist))
}

/// The potential energy of gravity and of the struts' gas at pose `q`, J, from neutral: the
/// centre of mass's rise times the weight, and per strut the work done on its gas,
/// `(p·V − p₀·V₀)/(n − 1)` (`p₀·V₀·ln(V₀/V)` for `n = 1`).
pub fn table_potential_energy_j(table: &MultiAxisTable, q: &Coords) -> f64 {
    let p = table.platen();
    let r = platen_model::multi_axis::rotation(q);
    let height = q[2] + (r * p.centre_of_mass_m())[2] - p.centre_of_mass_m()[2];
    let gravity = p.mass_kg() * platen_model::STANDARD_GRAVITY_M_S2 * height;
    let struts: f64 = table
        .struts()
        .iter()
        .enumerate()
        .map(|(j, s)| {
            let pose = table.strut_at(j, q);
            // The gas volume behind the pressure, V = V₀·(p₀/p)^(1/n).
            let volume = s.gas_volume_m3
                * (s.pressure_pa / pose.pressure_pa).powf(1.0 / s.polytropic_exponent);
            let n = s.polytropic_exponent;
            if (n - 1.0).abs() < 1e-12 {
                s.pressure_pa * s.gas_volume_m3 * (s.gas_volume_m3 / volume).ln()
            } else {
                (pose.pressure_pa * volume - s.pressure_pa * s.gas_volume_m3) / (n - 1.0)
            }
        })
        .sum();
    gravity + struts
}
