//! The multi-axis platen's inverse: a prescribed six-DOF motion, the actuator forces it needs
//! and each term they balance, as named columns.
//!
//! Conventions are [`platen_model::multi_axis`]'s. Every wrench term is what the actuators
//! must *supply* for it, as the uniaxial `F_A = F_I + F_E + F_D` reads: the actuators' wrench
//! is `inertial + elastic + dissipative + weight + base + constraint`, where `elastic` is
//! minus the struts' wrench, `dissipative` minus the bearings' friction, `weight` minus
//! gravity's and `base` the force the platen exerts on the specimen (its base force and
//! overturning moment); `constraint` is what the held DOFs take.

use nalgebra::DVector;
use platen_model::multi_axis::{
    Coords, Dof, InverseSample, LinearSpecimen, MultiAxisTable, Wrench,
};
use platen_signal::Motion;

use crate::error::{IntegrateError, Result};
use crate::inverse::INVERSE_SPECIMEN_SUBSTEPS;
use crate::output::TableSink;

/// A prescribed six-DOF motion: one [`Motion`] per DOF (pose coordinate, its rate and second
/// derivative) on one time grid.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseMotion {
    dofs: [Motion; 6],
}

impl PoseMotion {
    /// The motion of the six DOFs (x, y, z, roll, pitch, yaw: m and rad).
    ///
    /// # Errors
    /// [`IntegrateError::LengthMismatch`] or [`IntegrateError::TimeNotIncreasing`] when the
    /// six do not share their time stamps.
    pub fn new(dofs: [Motion; 6]) -> Result<Self> {
        let t = dofs[0].t_s();
        for (d, m) in Dof::ALL.iter().zip(&dofs).skip(1) {
            if m.len() != t.len() {
                return Err(IntegrateError::LengthMismatch {
                    what: d.name(),
                    found: m.len(),
                    expected: t.len(),
                });
            }
            if let Some(i) = (0..t.len()).find(|&i| m.t_s()[i] != t[i]) {
                return Err(IntegrateError::TimeNotIncreasing {
                    index: i,
                    previous_s: t[i],
                    value_s: m.t_s()[i],
                });
            }
        }
        Ok(PoseMotion { dofs })
    }

    /// The motion of one DOF.
    pub fn dof(&self, dof: Dof) -> &Motion {
        &self.dofs[dof.index()]
    }

    /// The time stamps, s.
    pub fn t_s(&self) -> &[f64] {
        self.dofs[0].t_s()
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.dofs[0].len()
    }

    /// Whether it has no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The pose, its rates and second derivatives at sample `i`.
    pub fn at(&self, i: usize) -> (Coords, Coords, Coords) {
        let pick = |f: fn(&Motion) -> &[f64]| Coords::from_fn(|k, _| f(&self.dofs[k])[i]);
        (pick(Motion::u_m), pick(Motion::v_m_s), pick(Motion::a_m_s2))
    }
}

/// A run of the multi-axis platen as named columns, every one as long as the time column.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TableRun {
    /// The columns in their order, each a name (with its unit) and its values.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl TableRun {
    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |(_, v)| v.len())
    }

    /// Whether it has no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The names of a six-vector's columns: `{prefix}{dof}{suffix}` with the DOF's unit.
fn pose_names(rate: &str) -> [String; 6] {
    Dof::ALL.map(|d| format!("{}_{}{rate}", d.name(), d.unit()))
}

/// The names of a wrench term's columns, `{term}_force_{x,y,z}_n`, `{term}_moment_{x,y,z}_n_m`.
fn wrench_names(term: &str) -> [String; 6] {
    ["x", "y", "z"]
        .map(|a| format!("{term}_force_{a}_n"))
        .into_iter()
        .chain(["x", "y", "z"].map(|a| format!("{term}_moment_{a}_n_m")))
        .collect::<Vec<_>>()
        .try_into()
        .expect("six names")
}

/// The inverse of the multi-axis platen: at every sample of `motion`, the actuator forces
/// ([`MultiAxisTable::inverse`]) with every term, the actuators' strokes, the struts' pulls
/// and, with a `specimen`, its base force and overturning moments. The specimen is driven by
/// the platen's acceleration `(ẗ, ω̇)` less gravity's `(0, 0, −g)` (so that it weighs on the
/// platen), linear between samples, with [`INVERSE_SPECIMEN_SUBSTEPS`] RK4 sub-steps per
/// interval (as the uniaxial [`inverse_specimen`](crate::inverse_specimen)); it starts at
/// rest in its static deflection under its weight (undeflected if its stiffness is
/// singular). A specimen with no vertical share (storeys along x) does not weigh.
///
/// Columns: `t_s`; the pose `x_m` … `yaw_rad`, rates `x_m_s` … `yaw_rad_s`, accelerations
/// `x_m_s2` … `yaw_rad_s2`; per actuator `{name}_stroke_m`, `{name}_force_n`; per strut
/// `{name}_force_n`; with a specimen `base_force_{x,y,z}_n`, `overturning_moment_{x,y}_n_m`;
/// then the terms `{inertial,elastic,dissipative,weight,constraint}_force_{x,y,z}_n` and
/// `…_moment_{x,y,z}_n_m` (about the reference point, table axes; see the module docs).
///
/// # Errors
/// [`IntegrateError::Unresolvable`] at the first sample where the actuators cannot hold the
/// free DOFs (their geometry loses rank at that pose).
pub fn inverse_table(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    motion: &PoseMotion,
) -> Result<TableRun> {
    let mut out = TableRun::default();
    inverse_table_into(table, specimen, motion, &mut out)?;
    Ok(out)
}

/// [`inverse_table`], delivering its rows to `sink` (the columns' names first,
/// [`inverse_table_columns`]) as they are computed.
///
/// # Errors
/// As [`inverse_table`] (the rows before the failing sample delivered).
pub fn inverse_table_into<K: TableSink>(
    table: &MultiAxisTable,
    specimen: Option<&LinearSpecimen>,
    motion: &PoseMotion,
    sink: &mut K,
) -> Result<()> {
    let n = motion.len();
    sink.start(&inverse_table_columns(table, specimen.is_some()), n);
    let mut spec = specimen.map(|s| SpecimenState {
        z: s.equilibrium_under(&-GRAVITY)
            .unwrap_or_else(|| DVector::zeros(s.len())),
        zd: DVector::zeros(s.len()),
    });
    let mut row = Vec::new();
    let t = motion.t_s();
    for i in 0..n {
        let (q, qd, qdd) = motion.at(i);
        if let (Some(s), Some(st)) = (specimen, spec.as_mut()) {
            if i > 0 {
                let a0 = platen_acceleration(&motion.at(i - 1)) - GRAVITY;
                let a1 = platen_acceleration(&(q, qd, qdd)) - GRAVITY;
                st.advance(s, t[i] - t[i - 1], &a0, &a1);
            }
        }
        let on_platen = match (specimen, &spec) {
            (Some(s), Some(st)) => s.wrench_on_platen(&st.z, &st.zd),
            _ => Wrench::zeros(),
        };
        let sample = table
            .inverse(&q, &qd, &qdd, &on_platen)
            .ok_or(IntegrateError::Unresolvable { t_s: t[i] })?;
        row.clear();
        row.push(t[i]);
        row.extend(q.iter().chain(qd.iter()).chain(qdd.iter()));
        let base = specimen.is_some().then(|| -on_platen);
        push_inverse_forces(&mut row, table, &q, &sample, base.as_ref());
        sink.accept(&row);
    }
    Ok(())
}

/// The columns of [`inverse_table`]'s run (see there), `with_specimen` or not: what
/// [`TableSink::start`] receives, known before the run so that its output can be created
/// first.
pub fn inverse_table_columns(table: &MultiAxisTable, with_specimen: bool) -> Vec<String> {
    let mut names = vec!["t_s".to_string()];
    names.extend(pose_names(""));
    names.extend(pose_names("_s"));
    names.extend(pose_names("_s2"));
    for a in table.actuators() {
        names.push(format!("{}_stroke_m", a.name));
        names.push(format!("{}_force_n", a.name));
    }
    for s in table.struts() {
        names.push(format!("{}_force_n", s.name));
    }
    if with_specimen {
        names.extend(
            [
                "base_force_x_n",
                "base_force_y_n",
                "base_force_z_n",
                "overturning_moment_x_n_m",
                "overturning_moment_y_n_m",
            ]
            .map(String::from),
        );
    }
    for term in ["inertial", "elastic", "dissipative", "weight", "constraint"] {
        names.extend(wrench_names(term));
    }
    names
}

/// Appends to `row` the columns after the motion at pose `q`: per actuator its stroke and
/// its force from `sample`, per strut its force, the specimen's `base` wrench (force and
/// overturning moments) when there is one, then the terms of the decomposition.
fn push_inverse_forces(
    row: &mut Vec<f64>,
    table: &MultiAxisTable,
    q: &Coords,
    sample: &InverseSample,
    base: Option<&Wrench>,
) {
    for (k, f) in sample.actuator_forces_n.iter().enumerate() {
        row.push(table.actuator_at(k, q).stroke_m);
        row.push(*f);
    }
    for j in 0..table.struts().len() {
        row.push(table.strut_at(j, q).force_n);
    }
    if let Some(base) = base {
        row.extend([base[0], base[1], base[2], base[3], base[4]]);
    }
    for w in [
        sample.inertial,
        -sample.struts,
        -sample.friction,
        -sample.gravity,
        sample.constraint,
    ] {
        row.extend(w.iter());
    }
}

/// Gravity as a spatial acceleration, m/s².
pub(crate) const GRAVITY: Wrench = Wrench::new(
    0.0,
    0.0,
    -platen_model::STANDARD_GRAVITY_M_S2,
    0.0,
    0.0,
    0.0,
);

/// The platen's acceleration `(ẗ, ω̇)` from its pose, rates and second derivatives.
pub(crate) fn platen_acceleration((q, qd, qdd): &(Coords, Coords, Coords)) -> Wrench {
    let e = platen_model::multi_axis::angular_rate_map(q);
    let alpha = e * qdd.fixed_rows::<3>(3) + platen_model::multi_axis::angular_rate_bias(q, qd);
    Wrench::new(qdd[0], qdd[1], qdd[2], alpha[0], alpha[1], alpha[2])
}

/// The specimen's DOFs relative to the platen and their rates.
struct SpecimenState {
    z: DVector<f64>,
    zd: DVector<f64>,
}

impl SpecimenState {
    /// RK4 over an interval of `dt` s with the platen's acceleration linear from `a0` to `a1`.
    fn advance(&mut self, s: &LinearSpecimen, dt: f64, a0: &Wrench, a1: &Wrench) {
        let steps = INVERSE_SPECIMEN_SUBSTEPS;
        let h = dt / f64::from(steps);
        let acc = |x: f64| a0 + (a1 - a0) * (x / f64::from(steps));
        for k in 0..steps {
            let x = f64::from(k);
            let (z, zd) = (&self.z, &self.zd);
            let k1 = s.accelerations(z, zd, &acc(x));
            let (z2, zd2) = (z + zd * (0.5 * h), zd + &k1 * (0.5 * h));
            let k2 = s.accelerations(&z2, &zd2, &acc(x + 0.5));
            let (z3, zd3) = (z + &zd2 * (0.5 * h), zd + &k2 * (0.5 * h));
            let k3 = s.accelerations(&z3, &zd3, &acc(x + 0.5));
            let (z4, zd4) = (z + &zd3 * h, zd + &k3 * h);
            let k4 = s.accelerations(&z4, &zd4, &acc(x + 1.0));
            let z_new = z + (zd + (&zd2 + &zd3) * 2.0 + &zd4) * (h / 6.0);
            let zd_new = zd + (&k1 + (&k2 + &k3) * 2.0 + &k4) * (h / 6.0);
            (self.z, self.zd) = (z_new, zd_new);
        }
    }
}

/// The in-memory collector: the columns of the run, every one as long as the time column.
impl TableSink for TableRun {
    fn start(&mut self, names: &[String], samples: usize) {
        self.columns = names
            .iter()
            .map(|n| (n.clone(), Vec::with_capacity(samples)))
            .collect();
    }

    fn accept(&mut self, row: &[f64]) {
        for ((_, c), &x) in self.columns.iter_mut().zip(row) {
            c.push(x);
        }
    }
}
