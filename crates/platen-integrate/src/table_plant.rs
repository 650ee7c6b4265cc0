//! The multi-axis platen forward from recorded actuator forces: a plant of the one mode
//! machine ([`crate::machine`]), RK4 or Dopri5.
//!
//! The state is the pose `q` and its rates `q̇` (six each) after the machine's five
//! positions. The right-hand side is Newton–Euler ([`MultiAxisTable::accelerations`]) under
//! the actuators' forces (each linear between its samples, along its line at its point), the
//! struts' pull and gravity; the held DOFs stay at zero.
//!
//! **Friction.** Only a table without friction runs forward here (every pad's and bearing's
//! coefficient 0). Such a table has no slide, so the machine's slide speed (`V`) is held at 1
//! and no `v = 0` event can happen: the machine runs one slip phase and its pieces. The
//! planar stick-slip of the bearings is not built yet; [`forward_table`] refuses a table
//! with friction ([`IntegrateError::TableFriction`]).

use platen_model::multi_axis::{angular_velocity, Coords, Dof, Mount, MultiAxisTable, Wrench};
use platen_model::PlatenModel;

use crate::error::{IntegrateError, Result};
use crate::event::{Direction, Mode};
use crate::grid::{Grid, GridStep};
use crate::machine::{Machine, PieceMethod, Plant, DI, U, V, W, Y};
use crate::method::Method;
use crate::multi_axis::TableRun;

/// Where the pose starts in the state.
const Q: usize = 5;
/// Where its rates start.
const QD: usize = Q + 6;
/// The state's length.
const L: usize = QD + 6;

/// The machine's law for a plant without a slide: never consulted (no stick, no creep, no
/// `v = 0`), here because the machine's plants name one.
struct NoSlide;

impl PlatenModel for NoSlide {
    fn mass_kg(&self, _u_m: f64) -> f64 {
        1.0
    }
    fn elastic_force_n(&self, _u_m: f64) -> f64 {
        0.0
    }
    fn velocity_inertial_force_n(&self, _u_m: f64, _v_m_s: f64) -> f64 {
        0.0
    }
    fn dissipative_magnitude_n(&self, _u_m: f64, _speed_m_s: f64) -> f64 {
        0.0
    }
    fn elastic_energy_j(&self, _u_m: f64) -> f64 {
        0.0
    }
}

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
struct At {
    j: usize,
    w: f64,
}

/// The multi-axis platen under its actuator forces: the [`Plant`] of the mode machine.
struct TablePlant<'a> {
    table: &'a MultiAxisTable,
    forces: &'a ActuatorForces,
    /// The time grid (its force is the first actuator's, unused: the input is every
    /// actuator's, [`TablePlant::forces_at`]).
    grid: Grid<'a>,
    /// The grid step being taken.
    n: GridStep,
}

impl TablePlant<'_> {
    fn forces_at(&self, at: At) -> impl Iterator<Item = f64> + '_ {
        let (j, w) = (at.j, at.w);
        self.forces.forces_n.iter().map(move |f| {
            if w == 0.0 {
                f[j]
            } else {
                f[j] * (1.0 - w) + f[j + 1] * w
            }
        })
    }

    /// The actuators' wrench at pose `q` under the forces at `at`, and their power at rates
    /// `qd` (the wrench on the platen's twist).
    fn actuators(&self, at: At, q: &Coords, qd: &Coords) -> (Wrench, f64) {
        let mut wrench = Wrench::zeros();
        for (i, f) in self.forces_at(at).enumerate() {
            wrench += self.table.actuator_at(i, q).unit_wrench * f;
        }
        let omega = angular_velocity(q, qd);
        let twist = Wrench::new(qd[0], qd[1], qd[2], omega[0], omega[1], omega[2]);
        (wrench, wrench.dot(&twist))
    }

    fn pose(y: &Y<L>) -> (Coords, Coords) {
        (
            Coords::from_fn(|k, _| y[Q + k]),
            Coords::from_fn(|k, _| y[QD + k]),
        )
    }

    fn table_rates(&self, at: At, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        let (q, qd) = Self::pose(y);
        let (wrench, power) = self.actuators(at, &q, &qd);
        let applied = wrench + self.table.struts_wrench(&q);
        let qdd = self
            .table
            .accelerations(&q, &qd, &applied)
            .unwrap_or_else(|| Coords::repeat(f64::NAN));
        dy[U] = 0.0;
        dy[V] = 0.0;
        dy[W] = power;
        dy[DI] = 0.0;
        dy[crate::machine::SD] = 0.0;
        for k in 0..6 {
            dy[Q + k] = qd[k];
            dy[QD + k] = qdd[k];
        }
        0.0
    }
}

impl Plant<L> for TablePlant<'_> {
    type Model = NoSlide;
    type Input = At;

    fn model(&self) -> &NoSlide {
        &NoSlide
    }

    #[inline(always)]
    fn input(&self, at: f64) -> At {
        At {
            j: self.n.j,
            w: (self.n.i + at) * self.grid.inv_k,
        }
    }

    fn rates(&self, _mode: Mode, _w_stiff: f64, input: At, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        self.table_rates(input, y, dy)
    }

    fn slip_rates<const POSITIVE: bool>(&self, input: At, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        self.table_rates(input, y, dy)
    }

    /// No slide: nothing for friction to see.
    fn effective_force(&self, _input: At, _y: &Y<L>) -> f64 {
        f64::INFINITY
    }

    fn net(&self, _input: At, _y: &Y<L>) -> f64 {
        f64::INFINITY
    }

    fn net_rate(&self, _k: &Y<L>) -> f64 {
        0.0
    }

    const RATES_ON_COMMIT: bool = false;

    /// The pose (m, rad) and its rates are controlled; the slide and the work are not.
    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64 {
        if i >= Q {
            atol + rtol * y0.abs().max(y1.abs())
        } else {
            f64::INFINITY
        }
    }

    crate::grid::grid_clock!();
}

/// The forward run of `table` under `forces` from the pose `initial` with rates
/// `initial_rates` (held DOFs must be 0 in both), with fixed-step RK4 or adaptive Dopri5
/// through the one mode machine, delivering every sample of the record as a row of the
/// run's columns: `t_s`; the pose, its rates and accelerations; per actuator
/// `{name}_stroke_m`, `{name}_force_n`; per strut `{name}_force_n`; `actuator_work_j` (the
/// actuators' work on the platen since the start).
///
/// # Errors
/// [`IntegrateError::TableFriction`] for a table with friction; [`IntegrateError::LengthMismatch`]
/// when `forces` has not one record per actuator; [`IntegrateError::InvalidStep`] for a step
/// that does not divide the sample interval; [`IntegrateError::NonFiniteState`] and
/// [`IntegrateError::AdaptiveFailed`] as the other forward runs.
pub fn forward_table(
    table: &MultiAxisTable,
    forces: &ActuatorForces,
    method: Method,
    initial: Coords,
    initial_rates: Coords,
) -> Result<TableRun> {
    if has_friction(table) {
        return Err(IntegrateError::TableFriction);
    }
    if forces.forces_n.len() != table.actuators().len() {
        return Err(IntegrateError::LengthMismatch {
            what: "actuator force records",
            found: forces.forces_n.len(),
            expected: table.actuators().len(),
        });
    }
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
    let mut y = [0.0; L];
    y[V] = 1.0;
    for d in Dof::ALL {
        let i = d.index();
        let held = table.held().contains(d);
        y[Q + i] = if held { 0.0 } else { initial[i] };
        y[QD + i] = if held { 0.0 } else { initial_rates[i] };
    }
    let plant = TablePlant {
        table,
        forces,
        grid: Grid {
            force: forces.forces_n.first().map_or(&[][..], Vec::as_slice),
            inv_k: 1.0 / k as f64,
            h,
            t0: forces.t_s[0],
        },
        n: GridStep { n: 0, j: 0, i: 0.0 },
    };
    let mut m = Machine::new(plant, y, h, pieces);
    m.enter(Mode::Slip(Direction::Positive), At { j: 0, w: 0.0 });
    let mut out = Output::new(table, forces.len());
    out.push(&m, 0);
    let mut n = 0u64;
    for j in 0..forces.len() - 1 {
        for i in 0..k {
            step(&mut m, GridStep { n, j, i: i as f64 })?;
            n += 1;
        }
        out.push(&m, j + 1);
    }
    Ok(out.finish())
}

/// Whether any contact of `table` has friction.
fn has_friction(table: &MultiAxisTable) -> bool {
    table.actuators().iter().any(|a| match &a.mount {
        Mount::Pad(p) => p.friction_coefficient > 0.0,
        Mount::Swivel { .. } => false,
    }) || table
        .parts()
        .bearings
        .iter()
        .any(|b| b.friction_coefficient > 0.0)
}

/// One grid step: RK4's single piece when it is safe, else the machine's advance.
fn step(m: &mut Machine<TablePlant<'_>, L>, n: GridStep) -> Result<()> {
    m.plant.n = n;
    m.stats.steps += 1;
    if m.is_rk4() && m.slip_fast::<true>(0.0) {
        return Ok(());
    }
    m.advance_span()
}

/// The run's columns, filled a sample at a time.
struct Output {
    names: Vec<String>,
    data: Vec<Vec<f64>>,
    row: Vec<f64>,
}

impl Output {
    fn new(table: &MultiAxisTable, samples: usize) -> Self {
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
        names.push("actuator_work_j".into());
        let data = names.iter().map(|_| Vec::with_capacity(samples)).collect();
        Output {
            names,
            data,
            row: Vec::new(),
        }
    }

    fn push(&mut self, m: &Machine<TablePlant<'_>, L>, j: usize) {
        let p = &m.plant;
        let (q, qd) = TablePlant::pose(&m.y);
        self.row.clear();
        self.row.push(p.forces.t_s[j]);
        self.row.extend(q.iter().chain(qd.iter()));
        self.row.extend((0..6).map(|k| m.k[QD + k]));
        for i in 0..p.table.actuators().len() {
            self.row.push(p.table.actuator_at(i, &q).stroke_m);
            self.row.push(p.forces.forces_n[i][j]);
        }
        for s in 0..p.table.struts().len() {
            self.row.push(p.table.strut_at(s, &q).force_n);
        }
        self.row.push(m.y[W]);
        for (c, &x) in self.data.iter_mut().zip(&self.row) {
            c.push(x);
        }
    }

    fn finish(self) -> TableRun {
        TableRun {
            columns: self.names.into_iter().zip(self.data).collect(),
        }
    }
}

/// The platen's kinetic energy at pose `q` with rates `qd`, J (for energy balances).
pub fn table_kinetic_energy_j(table: &MultiAxisTable, q: &Coords, qd: &Coords) -> f64 {
    let omega = angular_velocity(q, qd);
    let twist = Wrench::new(qd[0], qd[1], qd[2], omega[0], omega[1], omega[2]);
    0.5 * twist.dot(&(table.spatial_mass_matrix(q) * twist))
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
