//! The multi-axis platen under its actuators' forces, from a record ([`crate::forward_table`])
//! or from its hydraulics in closed loop ([`crate::forward_table_loop`]): a plant of the one
//! mode machine ([`crate::machine`]), RK4 or Dopri5.
//!
//! The state is the pose `q` and its rates `q̇` (six each) after the machine's five
//! positions. The right-hand side is Newton–Euler ([`MultiAxisTable::accelerations`]) under
//! the actuators' forces (each linear between its samples, along its line at its point), the
//! struts' pull and gravity; the held DOFs stay at zero.
//!
//! **Friction: exact planar stick-slip.** The bearings' Coulomb friction (`μᵢ·Nᵢ` at each
//! contact, `Nᵢ` the force of the actuator that presses it or a constant) holds and resists
//! the in-plane motion (x, y, yaw) through one limit surface, the ellipsoid of
//! [`MultiAxisTable::stick`]: inside it the platen sticks, sliding it meets the surface's
//! point whose normal is its motion ([`MultiAxisTable::sliding_friction`]), leaving rest it
//! goes along the normal of the point Gauss's principle picks
//! ([`MultiAxisTable::breakaway`]). The machine sees a slide through a *gauge*: a speed `V`
//! along the direction the platen slides in (set at breakaway and again at the start of
//! every grid step; in the metric of the friction centre's velocity and the yaw rate times
//! the friction radius `M_max/F_max`), integrated with the rest of the state. A slide ends
//! where `V` reaches zero, located by the machine's root finder:
//! * if the in-plane motion has stopped there (its speed below 1e-6 of what its
//!   acceleration gives in one grid step), the in-plane rates are set to exactly zero and the
//!   platen sticks while the holding friction stays inside the surface (ratio ≤ 1), or leaves
//!   rest at once (a reversal);
//! * if it has not (the slide turned through a right angle inside one step), the gauge is
//!   aimed along the motion again and the slide goes on.
//!
//! In stick the in-plane coordinates are held exactly (their rates are zero, not small) while
//! z, roll and pitch move; breakaway is the ratio reaching 1, moved just past rounding as in
//! the uniaxial machine. With y and yaw held the gauge is `±v_x` and this is the uniaxial
//! exact stick-slip of a Coulomb law (no creep: the planar law does not depend on the speed).
//! A table without friction has no slide: its gauge is held at 1 and it runs one slip phase.
//!
//! **Specimen.** A general linear specimen's DOFs and rates follow the pose's in the state;
//! it pushes on the platen with its restoring forces and feels the platen's acceleration less
//! gravity's, so the coupling is explicit.

use nalgebra::{DVector, DVectorView};
use nalgebra::{Vector2, Vector3};
use platen_model::multi_axis::{
    planar_rate, Coords, Dof, FrictionCapacity, Kinematics, LinearSpecimen, MultiAxisTable,
    PlanarRate, Wrench,
};
use platen_model::PlatenModel;

use crate::clock::Clock;
use crate::error::IntegrateError;
use crate::event::{Direction, EventKind, Mode};
use crate::machine::{Machine, PieceMethod, Plant, DI, U, V, W, Y};
use crate::multi_axis::{platen_acceleration, GRAVITY};
use crate::stop::Failure;

/// Where the pose starts in the state.
pub(crate) const Q: usize = 5;
/// Where its rates start.
pub(crate) const QD: usize = Q + 6;
/// Where the specimen's DOFs start (their rates follow them).
pub(crate) const Z: usize = QD + 6;
/// The state's length without a specimen.
pub(crate) const BARE: usize = Z;
/// The most DOFs of a specimen a forward run takes (the model's own limit, which
/// [`LinearSpecimen::new`](platen_model::multi_axis::LinearSpecimen::new) enforces).
pub const MAX_TABLE_SPECIMEN_DOFS: usize = platen_model::multi_axis::MAX_SPECIMEN_DOFS;
/// The state's length with a specimen (its unused DOFs stay at zero).
pub(crate) const WITH_SPECIMEN: usize = Z + 2 * MAX_TABLE_SPECIMEN_DOFS;

/// The most actuators a forward run takes (their forces at an instant live on the stack).
pub const MAX_TABLE_ACTUATORS: usize = 64;

/// A slide ends in rest where its in-plane speed is below this share of what its
/// acceleration gives in one grid step (at a true stop the located speed is rounding, some
/// 1e-15 of it; a slide that turned instead keeps a speed of the order of that).
const REST_SHARE: f64 = 1e-6;

/// Holding friction up to this share beyond the limit surface still holds: the rounding of
/// the ratio (found through the platen's mass matrix and the bearings' capacity, some 1e-16
/// of it). A platen at rest with the ratio a hair above 1 (a decaying motion that ends with
/// the holding friction on the surface) has no slide to leave in: the slip it would enter
/// decelerates at once by rounding, arrives at rest again at the same instant, and without
/// this margin the stick-slip events repeat there without end. Physically nothing: 1e-9 of
/// the bearings' capacity.
const RATIO_ROUNDING: f64 = 1e-9;

/// The friction direction near rest is blended with the slide's known direction over the
/// speed the friction takes off in this many grid steps: enough that an RK4 stage that
/// overshoots rest (by less than one step's worth) keeps the direction, and that the stiff
/// turning of the Coulomb direction near rest takes at least that many steps.
const BLEND_STEPS: f64 = 4.0;

/// The machine's law for the table: the friction the machine compares is the ratio of the
/// holding friction to the bearings' limit surface ([`MultiAxisTable::stick`]), so its
/// threshold is 1 and nothing else of the law is consulted (no elastic force, no creep).
pub(crate) struct UnitThreshold;

impl PlatenModel for UnitThreshold {
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
        1.0
    }
    fn elastic_energy_j(&self, _u_m: f64) -> f64 {
        0.0
    }
}

/// The slide's gauge: the speed `V` of the in-plane motion along the direction `unit`, in
/// the metric of the friction centre's velocity and the yaw rate times the friction radius
/// (both frozen when the gauge is set, so that `V` is linear in the state and integrates
/// with it).
#[derive(Debug, Clone, Copy)]
struct Gauge {
    /// The friction centre from the reference point, horizontal, m.
    arm: Vector2<f64>,
    /// The friction radius `M_max/F_max`, m (1 where there is none).
    radius_m: f64,
    /// The slide's direction in that metric (unit).
    unit: Vector3<f64>,
}

impl Gauge {
    /// The gauge of the bearings' `capacity` at the reference point `t`, along `w`.
    fn new(capacity: &FrictionCapacity, t: &Vector3<f64>, w: &PlanarRate) -> Self {
        let arm = (capacity.centre_m - t).xy();
        let radius_m = if capacity.force_n > 0.0 && capacity.moment_n_m > 0.0 {
            capacity.moment_n_m / capacity.force_n
        } else {
            1.0
        };
        let mut g = Gauge {
            arm,
            radius_m,
            unit: Vector3::x(),
        };
        let s = g.scaled(w);
        let n = s.norm();
        if n > 0.0 {
            g.unit = s / n;
        }
        g
    }

    /// The in-plane motion `w` of the reference point as the friction centre's velocity and
    /// the yaw rate times the radius.
    fn scaled(&self, w: &PlanarRate) -> Vector3<f64> {
        Vector3::new(
            w[0] - w[2] * self.arm[1],
            w[1] + w[2] * self.arm[0],
            w[2] * self.radius_m,
        )
    }

    /// The speed along the slide of the in-plane motion `w` (or its rate of an acceleration).
    fn speed(&self, w: &PlanarRate) -> f64 {
        self.unit.dot(&self.scaled(w))
    }
}

/// A specimen's restoring forces at an instant (its first `n`), N or N·m.
type SpecimenForces = [f64; MAX_TABLE_SPECIMEN_DOFS];

/// The actuator forces at an instant, N.
pub(crate) type Forces = [f64; MAX_TABLE_ACTUATORS];

/// The actuators' strokes from neutral (m) and their rates (m/s) at an instant, the first
/// `n` of each: what a source's own states need of the platen's motion
/// ([`Source::NEEDS_STROKES`]), taken from the poses the actuators' wrench is built from.
pub(crate) struct Strokes {
    pub(crate) stroke_m: [f64; MAX_TABLE_ACTUATORS],
    pub(crate) rate_m_s: [f64; MAX_TABLE_ACTUATORS],
}

/// Where a table's actuator forces come from, with the clock of the run that drives it: a
/// record ([`Recorded`]) or the actuators' own hydraulics in closed loop
/// ([`crate::table_loop`]). What the plant's hooks need of it.
pub(crate) trait Source<const L: usize> {
    /// What the forces need from outside the state at a position.
    type Input: Copy;
    /// As [`Plant::RATES_ON_COMMIT`].
    const RATES_ON_COMMIT: bool;
    /// Whether [`Source::rates`] reads the actuators' strokes and their rates (else they are
    /// not computed).
    const NEEDS_STROKES: bool;
    /// The input at position `at`.
    fn input(&self, at: f64) -> Self::Input;
    /// The actuator forces at `input` and state `y`, N.
    fn forces(&self, input: Self::Input, y: &Y<L>) -> Forces;
    /// The rates of the source's own states (none for a record) with the actuators at
    /// `strokes` (filled where [`Source::NEEDS_STROKES`]), into `dy`.
    #[inline(always)]
    fn rates(&self, _input: Self::Input, _y: &Y<L>, _strokes: &Strokes, _dy: &mut Y<L>) {}
    /// As [`Plant::admit`].
    fn admit(&mut self, _y: &mut Y<L>, _t_s: f64) -> bool {
        false
    }
    /// As [`Plant::stiff_rate`], the source's own states' at the actuators' `strokes`
    /// (`None`: a bound over every stroke). 0 by default.
    #[inline(always)]
    fn stiff_rate(&self, _y: &Y<L>, _strokes: Option<&Strokes>) -> f64 {
        0.0
    }
    /// The error scale of the source's own state `i` (`None`: not the source's).
    fn error_scale(&self, _i: usize, _y0: f64, _y1: f64, _rtol: f64, _atol: f64) -> Option<f64> {
        None
    }
    /// Where the run's time is kept: the record's grid, or the loop's seconds.
    type Clock: Clock;
    /// The run's clock.
    fn clock(&self) -> &Self::Clock;
    /// The run's clock, to move.
    fn clock_mut(&mut self) -> &mut Self::Clock;
}

/// The multi-axis platen under its actuator forces: the [`Plant`] of the mode machine.
pub(crate) struct TablePlant<'a, S, const L: usize> {
    pub(crate) table: &'a MultiAxisTable,
    /// Where the actuator forces come from.
    pub(crate) source: S,
    /// The specimen on the platen.
    pub(crate) specimen: Option<&'a LinearSpecimen>,
    /// Whether any contact has friction (else the gauge is held at 1: one slip phase).
    pub(crate) friction: bool,
    /// The slide's gauge.
    gauge: Gauge,
    /// The in-plane motion the slide was last known to go along (at breakaway, at the start
    /// of the grid step): the direction of the friction near rest.
    leaving: PlanarRate,
    /// The friction direction's blend with `leaving` ([`MultiAxisTable::sliding_friction`]):
    /// what the bearings' friction takes off the speed in [`BLEND_STEPS`] grid steps, m/s.
    blend_m_s: f64,
}

impl<S: Source<L>, const L: usize> TablePlant<'_, S, L> {
    fn forces_at(&self, at: S::Input, y: &Y<L>) -> Forces {
        self.source.forces(at, y)
    }

    /// The actuators' wrench with the platen's kinematics `k` under the forces `f`, and
    /// their strokes and rates where the source needs them: each actuator's pose taken once.
    fn actuators(&self, f: &Forces, k: &Kinematics) -> (Wrench, Strokes) {
        let mut wrench = Wrench::zeros();
        let mut strokes = Strokes {
            stroke_m: [0.0; MAX_TABLE_ACTUATORS],
            rate_m_s: [0.0; MAX_TABLE_ACTUATORS],
        };
        let frame = &k.frame;
        for (i, f) in f.iter().take(self.table.actuators().len()).enumerate() {
            let pose = self.table.actuator_in(i, frame);
            wrench += pose.unit_wrench * *f;
            if S::NEEDS_STROKES {
                strokes.stroke_m[i] = pose.stroke_m;
                strokes.rate_m_s[i] =
                    self.table
                        .stroke_rate_in(i, frame, &pose, &k.velocity_m_s, &k.omega_rad_s);
            }
        }
        (wrench, strokes)
    }

    /// The platen's twist (velocity of the reference point, angular velocity).
    fn twist(k: &Kinematics) -> Wrench {
        let (v, omega) = (k.velocity_m_s, k.omega_rad_s);
        Wrench::new(v[0], v[1], v[2], omega[0], omega[1], omega[2])
    }

    /// The rates in slip (or free flight without friction); returns the gauge's rate.
    fn slip_rates(&self, at: S::Input, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        let (q, qd) = pose(y);
        let f = self.forces_at(at, y);
        let kin = self.table.kinematics(&q, &qd);
        let frame = &kin.frame;
        let (wrench, strokes) = self.actuators(&f, &kin);
        let twist = Self::twist(&kin);
        let restoring = self.specimen_restoring(y);
        let mut applied = wrench + self.table.struts_wrench_in(frame) + self.push_of(&restoring);
        let mut lost = 0.0;
        if self.friction {
            let capacity = self.table.friction_capacity_in(frame, &f);
            let friction =
                self.table
                    .sliding_friction(&q, &qd, &capacity, &self.leaving, self.blend_m_s);
            applied += friction;
            lost = -friction.dot(&twist);
        }
        let qdd = self
            .table
            .accelerations_in(&kin, &applied)
            .unwrap_or_else(|| Coords::repeat(f64::NAN));
        dy[U] = 0.0;
        dy[V] = if self.friction {
            self.gauge.speed(&planar_rate(&qdd))
        } else {
            0.0
        };
        dy[W] = wrench.dot(&twist);
        dy[DI] = lost;
        dy[crate::machine::SD] = 0.0;
        for k in 0..6 {
            dy[Q + k] = qd[k];
            dy[QD + k] = qdd[k];
        }
        self.specimen_rates((&q, &qd, &qdd), &restoring, y, dy);
        self.source.rates(at, y, &strokes, dy);
        dy[V]
    }

    /// The specimen's DOFs and rates in `y` (`n` each).
    fn specimen_state<'y>(s: &LinearSpecimen, y: &'y Y<L>) -> (&'y [f64], &'y [f64]) {
        let n = s.len();
        (&y[Z..Z + n], &y[Z + n..Z + 2 * n])
    }

    /// The specimen's restoring forces `C·ż + K·z` at `y`, on the stack (its first `n`;
    /// zero without one): taken once per right-hand side for its push and its rates.
    fn specimen_restoring(&self, y: &Y<L>) -> SpecimenForces {
        let mut r = [0.0; MAX_TABLE_SPECIMEN_DOFS];
        if let Some(s) = self.specimen {
            let (z, zd) = Self::specimen_state(s, y);
            s.restoring_into(z, zd, &mut r);
        }
        r
    }

    /// The specimen's push on the platen of its restoring forces `restoring` (zero without
    /// one).
    fn push_of(&self, restoring: &SpecimenForces) -> Wrench {
        match self.specimen {
            Some(s) => s.wrench_from_restoring(restoring),
            None => Wrench::zeros(),
        }
    }

    /// The specimen's push on the platen at `y` (zero without one).
    pub(crate) fn specimen_push(&self, y: &Y<L>) -> Wrench {
        self.push_of(&self.specimen_restoring(y))
    }

    /// The specimen's rates under the platen moving with `q`, `qd`, `qdd` (it feels the
    /// platen's acceleration less gravity's) with its restoring forces `restoring` at `y`,
    /// and its dampers' power into `SD`.
    fn specimen_rates(
        &self,
        (q, qd, qdd): (&Coords, &Coords, &Coords),
        restoring: &SpecimenForces,
        y: &Y<L>,
        dy: &mut Y<L>,
    ) {
        let Some(s) = self.specimen else {
            return;
        };
        let n = s.len();
        let (_, zd) = Self::specimen_state(s, y);
        let a = platen_acceleration(&(*q, *qd, *qdd)) - GRAVITY;
        let mut zdd = [0.0; MAX_TABLE_SPECIMEN_DOFS];
        s.accelerations_into(restoring, &a, &mut zdd);
        for i in 0..n {
            dy[Z + i] = zd[i];
            dy[Z + n + i] = zdd[i];
        }
        let mut czd = [0.0; MAX_TABLE_SPECIMEN_DOFS];
        s.damping_forces_into(zd, &mut czd);
        // `żᵀ·(C·ż)` by nalgebra's dot, as on owned vectors (the same sums in the same order).
        dy[crate::machine::SD] =
            DVectorView::from_slice(zd, n).dot(&DVectorView::from_slice(&czd[..n], n));
    }

    /// The rates at rest in the plane: the in-plane coordinates held by friction.
    fn stick_rates(&self, at: S::Input, y: &Y<L>, dy: &mut Y<L>) {
        let (q, qd) = pose(y);
        let f = self.forces_at(at, y);
        let kin = self.table.kinematics(&q, &qd);
        let frame = &kin.frame;
        let (wrench, strokes) = self.actuators(&f, &kin);
        let twist = Self::twist(&kin);
        let restoring = self.specimen_restoring(y);
        let applied = wrench + self.table.struts_wrench_in(frame) + self.push_of(&restoring);
        let capacity = self.table.friction_capacity_in(frame, &f);
        let (qdd, holding) = match self.table.stick(&q, &qd, &applied, &capacity) {
            Some(s) => (s.accelerations, s.wrench),
            None => (Coords::repeat(f64::NAN), Wrench::repeat(f64::NAN)),
        };
        dy[U] = 0.0;
        dy[V] = 0.0;
        dy[W] = wrench.dot(&twist);
        dy[DI] = -holding.dot(&twist);
        dy[crate::machine::SD] = 0.0;
        for k in 0..6 {
            dy[Q + k] = qd[k];
            dy[QD + k] = qdd[k];
        }
        self.specimen_rates((&q, &qd, &qdd), &restoring, y, dy);
        self.source.rates(at, y, &strokes, dy);
    }

    /// The holding friction's ratio to the limit surface at `y` under the forces at `at`
    /// (infinite where the equations are singular; 1 within [`RATIO_ROUNDING`] above it).
    fn ratio(&self, at: S::Input, y: &Y<L>) -> f64 {
        let (q, qd) = pose(y);
        let f = self.forces_at(at, y);
        let kin = self.table.kinematics(&q, &qd);
        let applied = self.actuators(&f, &kin).0
            + self.table.struts_wrench_in(&kin.frame)
            + self.specimen_push(y);
        let capacity = self.table.friction_capacity_in(&kin.frame, &f);
        let ratio = self
            .table
            .stick(&q, &qd, &applied, &capacity)
            .map_or(f64::INFINITY, |s| s.ratio);
        if ratio > 1.0 && ratio <= 1.0 + RATIO_ROUNDING {
            1.0
        } else {
            ratio
        }
    }

    /// Leaving rest at `y` under the forces at `at`: the in-plane motion
    /// ([`MultiAxisTable::breakaway`]) and the gauge along it.
    fn leave(&self, at: S::Input, y: &Y<L>) -> (PlanarRate, Gauge) {
        let (q, qd) = pose(y);
        let f = self.forces_at(at, y);
        let kin = self.table.kinematics(&q, &qd);
        let applied = self.actuators(&f, &kin).0
            + self.table.struts_wrench_in(&kin.frame)
            + self.specimen_push(y);
        let capacity = self.table.friction_capacity_in(&kin.frame, &f);
        let t = Vector3::new(q[0], q[1], q[2]);
        let w = self
            .table
            .stick(&q, &qd, &applied, &capacity)
            .map_or(PlanarRate::zeros(), |s| {
                self.table.breakaway(&q, &qd, &applied, &capacity, &s)
            });
        (w, Gauge::new(&capacity, &t, &w))
    }

    /// The gauge along the in-plane motion of `y`, with the bearings' capacity under the
    /// forces at `at`.
    fn gauge_along(&self, at: S::Input, y: &Y<L>) -> Gauge {
        let (q, qd) = pose(y);
        let capacity = self.table.friction_capacity(&q, &self.forces_at(at, y));
        Gauge::new(
            &capacity,
            &Vector3::new(q[0], q[1], q[2]),
            &planar_rate(&qd),
        )
    }

    /// Aims the slide along the in-plane motion `along` with `gauge`, its blend speed from
    /// the bearings' capacity at `y` under the forces at `at`.
    fn aim(&mut self, at: S::Input, y: &Y<L>, gauge: Gauge, along: PlanarRate) {
        let (q, _) = pose(y);
        let capacity = self.table.friction_capacity(&q, &self.forces_at(at, y));
        self.gauge = gauge;
        self.leaving = along;
        self.blend_m_s = BLEND_STEPS * self.source.clock().step_s() * capacity.force_n
            / self.table.platen().mass_kg();
    }
}

/// A strut whose gas volume falls below this fraction of its volume at neutral has used up
/// its gas: its pressure is then `100^n` times the neutral one (7 600 times for `n` = 1.44),
/// beyond any strut's rating, and grows without bound as the volume goes.
pub const SPENT_GAS_FRACTION: f64 = 0.01;

/// A run whose state became non-finite while a strut had less than this fraction of its gas
/// left (at the last finite state) is reported as that strut's gas spent: a strut at a
/// quarter of its gas stiffens seven-fold within the step (n = 1.44) and its pull is what the
/// step could not follow.
pub(crate) const BLOWN_UP_GAS_FRACTION: f64 = 0.25;

/// The first strut of `table` at pose `q` with less than [`SPENT_GAS_FRACTION`] of its gas
/// volume left, if any.
pub(crate) fn spent_strut(table: &MultiAxisTable, q: &Coords) -> Option<usize> {
    spent_strut_below(table, q, SPENT_GAS_FRACTION)
}

/// The first strut of `table` at pose `q` with less than `fraction` of its gas volume left.
fn spent_strut_below(table: &MultiAxisTable, q: &Coords, fraction: f64) -> Option<usize> {
    table.struts().iter().enumerate().position(|(j, s)| {
        let p = table.strut_at(j, q).pressure_pa;
        // V = V₀·(p₀/p)^(1/n); an infinite pressure is a volume gone.
        let left = (s.pressure_pa / p).powf(1.0 / s.polytropic_exponent);
        left.is_nan() || left <= fraction
    })
}

/// The error of a table run whose step from pose `q0` failed with `e`: a state that blew up
/// while a strut was running out of gas is the strut's gas spent (its pull, not the solver,
/// went without bound); any other non-finite state is reported with the table's six
/// coordinates (the pose the step started from), not the uniaxial platen's `u` and `v`.
pub(crate) fn table_step_error(
    e: IntegrateError,
    table: &MultiAxisTable,
    q0: &Coords,
) -> IntegrateError {
    match e {
        IntegrateError::NonFiniteState { t_s, .. } => {
            match spent_strut_below(table, q0, BLOWN_UP_GAS_FRACTION) {
                Some(strut) => IntegrateError::StrutGasSpent { t_s, strut },
                None => IntegrateError::failed(
                    t_s,
                    Failure::TableNonFiniteState {
                        pose: std::array::from_fn(|k| q0[k]),
                    },
                ),
            }
        }
        e => e,
    }
}

/// The pose and its rates in `y`.
pub(crate) fn pose<const L: usize>(y: &Y<L>) -> (Coords, Coords) {
    (
        Coords::from_fn(|k, _| y[Q + k]),
        Coords::from_fn(|k, _| y[QD + k]),
    )
}

/// Sets the in-plane rates of `y` to zero.
fn hold_in_plane<const L: usize>(y: &mut Y<L>) {
    for d in [Dof::X, Dof::Y, Dof::Yaw] {
        y[QD + d.index()] = 0.0;
    }
    y[V] = 0.0;
}

impl<S: Source<L>, const L: usize> Plant<L> for TablePlant<'_, S, L> {
    type Model = UnitThreshold;
    type Input = S::Input;

    fn model(&self) -> &UnitThreshold {
        &UnitThreshold
    }

    #[inline(always)]
    fn input(&self, at: f64) -> S::Input {
        self.source.input(at)
    }

    fn rates(&self, mode: Mode, _w_stiff: f64, input: S::Input, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        if mode == Mode::Stick {
            self.stick_rates(input, y, dy);
            0.0
        } else {
            self.slip_rates(input, y, dy)
        }
    }

    fn slip_rates<const POSITIVE: bool>(&self, input: S::Input, y: &Y<L>, dy: &mut Y<L>) -> f64 {
        TablePlant::slip_rates(self, input, y, dy)
    }

    /// The holding friction's ratio to the limit surface (the machine's threshold is 1).
    fn effective_force(&self, input: S::Input, y: &Y<L>) -> f64 {
        if self.friction {
            self.ratio(input, y)
        } else {
            f64::INFINITY
        }
    }

    fn net(&self, input: S::Input, y: &Y<L>) -> f64 {
        self.effective_force(input, y)
    }

    /// Not known from the state's rates alone (the forces move with time): the stick's
    /// breakaway is found from the ratio at the ends of each piece.
    fn net_rate(&self, _k: &Y<L>) -> f64 {
        0.0
    }

    fn entering(&mut self, mode: Mode, input: S::Input, y: &mut Y<L>) {
        if !self.friction {
            return;
        }
        match mode {
            Mode::Stick => hold_in_plane(y),
            Mode::Slip(_) if y[V] == 0.0 => {
                let (leaving, gauge) = self.leave(input, y);
                self.aim(input, y, gauge, leaving);
            }
            _ => {}
        }
    }

    fn arrive(&mut self, input: S::Input, y: &mut Y<L>) -> Option<(Mode, Option<EventKind>)> {
        let w = planar_rate(&Coords::from_fn(|k, _| y[QD + k]));
        let speed = self.gauge.scaled(&w).norm();
        let mut dy = [0.0; L];
        TablePlant::slip_rates(self, input, y, &mut dy);
        let accel = self
            .gauge
            .scaled(&planar_rate(&Coords::from_fn(|k, _| dy[QD + k])))
            .norm();
        if speed > REST_SHARE * accel * self.source.clock().step_s() {
            // Still sliding, on a path that turned: aim the gauge along it again.
            let gauge = self.gauge_along(input, y);
            self.aim(input, y, gauge, w);
            y[V] = self.gauge.speed(&w);
            return Some((Mode::Slip(Direction::Positive), None));
        }
        hold_in_plane(y);
        if self.ratio(input, y) <= 1.0 {
            // The machine's reset: stick, a stop.
            return None;
        }
        Some((Mode::Slip(Direction::Positive), Some(EventKind::Reversal)))
    }

    fn creeps_from_rest(&self, _dir: Direction, _tau: f64, _y: &Y<L>, _w_stiff: f64) -> bool {
        false
    }

    const RATES_ON_COMMIT: bool = S::RATES_ON_COMMIT;

    fn admit(&mut self, y: &mut Y<L>, t_s: f64) -> bool {
        self.source.admit(y, t_s)
    }

    /// The pose (m, rad), its rates and the specimen's are controlled, and the source's own
    /// states by its scales; the gauge and the work are not.
    /// The source's: its bound over every stroke, and the rate at the actuators' strokes
    /// (the platen's kinematics taken once more) only where that bound is not resolved by
    /// the step.
    fn stiff_rate(&self, y: &Y<L>) -> f64 {
        let bound = self.source.stiff_rate(y, None);
        if bound * self.source.clock().step_s() <= 1.0 {
            return bound;
        }
        let (q, qd) = pose(y);
        let kin = self.table.kinematics(&q, &qd);
        let (_, strokes) = self.actuators(&[0.0; MAX_TABLE_ACTUATORS], &kin);
        self.source.stiff_rate(y, Some(&strokes))
    }

    fn error_scale(&self, i: usize, y0: f64, y1: f64, rtol: f64, atol: f64) -> f64 {
        if let Some(scale) = self.source.error_scale(i, y0, y1, rtol, atol) {
            scale
        } else if i >= Q {
            atol + rtol * y0.abs().max(y1.abs())
        } else {
            f64::INFINITY
        }
    }

    type Clock = S::Clock;
    fn clock(&self) -> &S::Clock {
        self.source.clock()
    }
    fn clock_mut(&mut self) -> &mut S::Clock {
        self.source.clock_mut()
    }
}

/// The state at the start of a run of `table` carrying `specimen` from the pose `initial`
/// with rates `initial_rates` (the held DOFs at zero), the specimen at rest in its static
/// deflection; the rest of the state zero.
pub(crate) fn start_state<const L: usize>(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    initial: Coords,
    initial_rates: Coords,
) -> Y<L> {
    let mut y = [0.0; L];
    y[V] = 1.0;
    for d in Dof::ALL {
        let i = d.index();
        let held = table.held().contains(d);
        y[Q + i] = if held { 0.0 } else { initial[i] };
        y[QD + i] = if held { 0.0 } else { initial_rates[i] };
    }
    if let Some(s) = specimen {
        // At rest in its static deflection under its weight (undeflected if its stiffness
        // is singular), as the inverse starts it.
        let z = s
            .equilibrium_under(&-GRAVITY)
            .unwrap_or_else(|| DVector::zeros(s.len()));
        for (i, zi) in z.iter().enumerate() {
            y[Z + i] = *zi;
        }
    }
    y
}

/// The machine of `table` (carrying `specimen`) driven by `source` from the state `y`, in
/// its first mode: stuck if the platen rests in its plane and the bearings hold it, else
/// sliding along its motion (one slip phase without friction).
pub(crate) fn start_machine<'a, S: Source<L>, const L: usize>(
    table: &'a MultiAxisTable,
    specimen: Option<&'a LinearSpecimen>,
    source: S,
    mut y: Y<L>,
    h: f64,
    pieces: PieceMethod,
) -> Machine<TablePlant<'a, S, L>, L> {
    let friction = table.has_friction();
    let mut plant = TablePlant {
        table,
        source,
        specimen,
        friction,
        gauge: Gauge {
            arm: Vector2::zeros(),
            radius_m: 1.0,
            unit: Vector3::x(),
        },
        leaving: PlanarRate::zeros(),
        blend_m_s: 0.0,
    };
    let start = plant.source.input(0.0);
    let mut mode = Mode::Slip(Direction::Positive);
    if friction {
        let w = planar_rate(&pose(&y).1);
        if w == PlanarRate::zeros() {
            y[V] = 0.0;
            if plant.ratio(start, &y) <= 1.0 {
                mode = Mode::Stick;
            }
        } else {
            let gauge = plant.gauge_along(start, &y);
            plant.aim(start, &y, gauge, w);
            y[V] = plant.gauge.speed(&w);
        }
    }
    let mut m = Machine::new(plant, y, h, pieces);
    m.enter(mode, start);
    m
}

/// At the start of a grid step: a slide with friction has its gauge aimed along its motion.
/// Returns whether the platen slides (or moves free of friction).
pub(crate) fn reaim<S: Source<L>, const L: usize>(
    m: &mut Machine<TablePlant<'_, S, L>, L>,
) -> bool {
    let sliding = m.mode == Mode::Slip(Direction::Positive) && m.y[V] > 0.0;
    if sliding && m.plant.friction {
        let input = m.plant.input(0.0);
        let gauge = m.plant.gauge_along(input, &m.y);
        let w = planar_rate(&pose(&m.y).1);
        let y = m.y;
        m.plant.aim(input, &y, gauge, w);
        m.y[V] = gauge.speed(&w);
        m.k[V] = gauge.speed(&planar_rate(&Coords::from_fn(|k, _| m.k[QD + k])));
        m.a = m.k[V];
    }
    sliding
}
