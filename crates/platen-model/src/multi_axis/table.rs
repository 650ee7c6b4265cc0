//! The multi-axis table: its rigid platen, actuators, hold-down struts and bearings, validated
//! once; its kinematics at any pose and its Newton–Euler dynamics.

use nalgebra::{Cholesky, DMatrix, Matrix3, Matrix6, Unit, Vector3, Vector6, SVD};

use super::dof::{
    angular_rate_bias, angular_rate_map, angular_velocity, rotation, translation, Coords, Dof,
    DofSet,
};
use crate::error::{ModelError, Result};
use crate::STANDARD_GRAVITY_M_S2;

/// A point or direction of the table, m, in table axes (base points) or platen axes
/// (platen points, from the reference point).
pub type Point = Vector3<f64>;

/// A wrench about the reference point in table axes: force (N) then moment (N·m).
pub type Wrench = Vector6<f64>;

/// The rigid platen.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidPlaten {
    mass_kg: f64,
    inertia_kg_m2: Matrix3<f64>,
    centre_of_mass_m: Point,
}

/// Relative tolerance of the inertia tensor's symmetry check (printed tensors round).
const SYMMETRY_TOLERANCE: f64 = 1e-9;

fn invalid(path: impl Into<String>, expected: impl Into<String>) -> ModelError {
    ModelError::InvalidTable {
        path: path.into(),
        expected: expected.into(),
    }
}

/// How far from the reference point any point of the table may lie, m: beyond, the statics
/// and linearisations lose their digits (a scenario refuses far less: a table spans about
/// 20 m, and `platen_scenario` takes a point beyond 100 m as the unit slip it is).
pub const MAX_GEOMETRY_M: f64 = 1e6;

fn finite_point(path: &str, p: &Point) -> Result<()> {
    if p.iter().all(|c| c.is_finite() && c.abs() <= MAX_GEOMETRY_M) {
        Ok(())
    } else {
        Err(invalid(
            path,
            format!(
                "three finite coordinates within {MAX_GEOMETRY_M:e} m of the reference point, m"
            ),
        ))
    }
}

/// Names an actuator or strut may not take: its columns would repeat one of the run's own
/// (`warping_force_n`, the closed loop's force-balance column).
pub const RESERVED_NAMES: [&str; 1] = ["warping"];

/// An actuator's or strut's name: not empty, not reserved, and fit for a CSV column name (no
/// comma, quote or control character, no spaces around it).
fn check_name(path: String, name: &str) -> Result<()> {
    if name.trim().is_empty() {
        return Err(invalid(path, "a non-empty name"));
    }
    if name.trim() != name || name.chars().any(|c| c == ',' || c == '"' || c.is_control()) {
        return Err(invalid(
            path,
            format!(
                "a name fit for a CSV column (no comma, quote, control character or surrounding \
                 space; got {name:?})"
            ),
        ));
    }
    if RESERVED_NAMES.contains(&name) {
        return Err(invalid(
            path,
            format!(
                "a name other than {}: `{name}_force_n` is a column of the run itself",
                RESERVED_NAMES.map(|r| format!("`{r}`")).join(", ")
            ),
        ));
    }
    Ok(())
}

fn positive(path: String, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(invalid(
            path,
            format!("a finite number > 0, {unit} (got {value})"),
        ))
    }
}

fn non_negative(path: String, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(invalid(
            path,
            format!("a finite number >= 0, {unit} (got {value})"),
        ))
    }
}

impl RigidPlaten {
    /// A platen of mass `mass_kg` with the inertia tensor `inertia_kg_m2` about its centre of
    /// mass (platen axes) and the centre of mass at `centre_of_mass_m` (platen frame, from the
    /// reference point).
    ///
    /// # Errors
    /// [`ModelError::InvalidTable`] (path `platen.…`) for a mass that is not finite and > 0,
    /// a non-finite centre of mass, or an inertia tensor that is not symmetric positive
    /// definite or breaks the triangle inequality of principal moments (no rigid body has it).
    pub fn new(mass_kg: f64, inertia_kg_m2: Matrix3<f64>, centre_of_mass_m: Point) -> Result<Self> {
        positive("platen.mass_kg".into(), mass_kg, "kg")?;
        finite_point("platen.centre_of_mass_m", &centre_of_mass_m)?;
        let i = inertia_kg_m2;
        let scale = i.abs().max();
        if !i.iter().all(|c| c.is_finite())
            || (i - i.transpose()).abs().max() > SYMMETRY_TOLERANCE * scale
        {
            return Err(invalid(
                "platen.inertia_kg_m2",
                "a symmetric 3×3 tensor of finite numbers, kg·m²",
            ));
        }
        let sym = (i + i.transpose()) * 0.5;
        let eig = sym.symmetric_eigenvalues();
        let (lo, hi) = (eig.min(), eig.max());
        let sum = eig.sum();
        if lo <= 0.0 || hi > sum - hi + SYMMETRY_TOLERANCE * scale {
            return Err(invalid(
                "platen.inertia_kg_m2",
                format!(
                    "a positive definite tensor whose principal moments obey the triangle \
                     inequality, kg·m² (principal moments {:.6e}, {:.6e}, {:.6e})",
                    eig[0], eig[1], eig[2]
                ),
            ));
        }
        Ok(RigidPlaten {
            mass_kg,
            inertia_kg_m2: sym,
            centre_of_mass_m,
        })
    }

    /// The mass, kg.
    pub fn mass_kg(&self) -> f64 {
        self.mass_kg
    }

    /// The inertia tensor about the centre of mass, platen axes, kg·m².
    pub fn inertia_kg_m2(&self) -> &Matrix3<f64> {
        &self.inertia_kg_m2
    }

    /// The centre of mass, platen frame, m.
    pub fn centre_of_mass_m(&self) -> &Point {
        &self.centre_of_mass_m
    }
}

/// How an actuator meets the platen.
#[derive(Debug, Clone, PartialEq)]
pub enum Mount {
    /// Spherical joints at both ends: the force acts along the line from the base point to
    /// this platen point (platen frame).
    Swivel {
        /// The platen end, platen frame, m.
        platen_m: Point,
    },
    /// A bearing actuator: its axis is fixed to the reaction mass and its pad carries the
    /// platen, which slides over it.
    Pad(Pad),
}

/// The pad of a bearing actuator.
#[derive(Debug, Clone, PartialEq)]
pub struct Pad {
    /// The actuator's axis (table axes, unit).
    pub axis: Unit<Vector3<f64>>,
    /// Where the axis meets the platen's underside at neutral (table axes), m. The underside
    /// is the platen-frame plane through this point normal to the platen's z axis.
    pub contact_m: Point,
    /// The Coulomb friction coefficient of the platen sliding over the pad.
    pub friction_coefficient: f64,
}

/// One actuator: its geometry and the hydraulic sizes the mechanics need.
#[derive(Debug, Clone, PartialEq)]
pub struct Actuator {
    /// Its name (output columns `{name}_stroke_m`, `{name}_force_n`).
    pub name: String,
    /// Its base point on the reaction mass, table axes, m.
    pub base_m: Point,
    /// How it meets the platen.
    pub mount: Mount,
    /// Piston area of the cap-side chamber, m².
    pub cap_side_area_m2: f64,
    /// Piston area of the rod-side chamber, m² (0: single-acting).
    pub rod_side_area_m2: f64,
    /// Oil volume of each chamber at neutral, lines included, m³.
    pub chamber_volume_m3: f64,
    /// Reach from neutral either way, m.
    pub stroke_m: f64,
}

impl Actuator {
    /// The oil-column stiffness `β·(A_cap² + A_rod²)/V` with the valves shut at neutral, N/m.
    pub fn oil_column_stiffness_n_per_m(&self, oil_bulk_modulus_pa: f64) -> f64 {
        oil_bulk_modulus_pa * (self.cap_side_area_m2.powi(2) + self.rod_side_area_m2.powi(2))
            / self.chamber_volume_m3
    }
}

/// A nitrogen hold-down strut: a gas spring from a base point to a platen point that pulls the
/// platen down. Its gas is compressed as it extends: `V = V₀ − A·(L − L₀)`,
/// `p = p₀·(V₀/V)^n`, pull `p·A` (the sign of the paper's Eq. 6b, whose `K′ₑ > 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Strut {
    /// Its name (output column `{name}_force_n`).
    pub name: String,
    /// Base point, table axes, m.
    pub base_m: Point,
    /// Platen point, platen frame, m.
    pub platen_m: Point,
    /// Piston area, m².
    pub area_m2: f64,
    /// Gas pressure at neutral, Pa.
    pub pressure_pa: f64,
    /// Gas volume at neutral, m³.
    pub gas_volume_m3: f64,
    /// Polytropic exponent `n` (1: isothermal; 1.4–1.44 for nitrogen, adiabatic).
    pub polytropic_exponent: f64,
}

impl Strut {
    /// The gas pressure at length `length_m` when its neutral length is `neutral_m`, Pa
    /// (infinite once the gas volume is used up).
    pub fn pressure_at_pa(&self, length_m: f64, neutral_m: f64) -> f64 {
        let volume = self.gas_volume_m3 - self.area_m2 * (length_m - neutral_m);
        if volume <= 0.0 {
            return f64::INFINITY;
        }
        self.pressure_pa * (self.gas_volume_m3 / volume).powf(self.polytropic_exponent)
    }

    /// The axial gas stiffness at neutral `n·p₀·A²/V₀`, N/m.
    pub fn axial_stiffness_n_per_m(&self) -> f64 {
        self.polytropic_exponent * self.pressure_pa * self.area_m2.powi(2) / self.gas_volume_m3
    }
}

/// What presses a passive bearing's contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BearingLoad {
    /// The force of a swivel-mounted vertical actuator (its index) under it.
    Actuator(usize),
    /// A constant normal force, N.
    Constant(f64),
}

/// A bearing contact that is not a bearing actuator's pad.
#[derive(Debug, Clone, PartialEq)]
pub struct Bearing {
    /// The contact point, platen frame, m.
    pub platen_m: Point,
    /// Its Coulomb friction coefficient.
    pub friction_coefficient: f64,
    /// What presses it.
    pub load: BearingLoad,
}

/// Everything a [`MultiAxisTable`] is built from.
#[derive(Debug, Clone, PartialEq)]
pub struct TableParts {
    /// The rigid platen.
    pub platen: RigidPlaten,
    /// The actuators.
    pub actuators: Vec<Actuator>,
    /// The hold-down struts.
    pub struts: Vec<Strut>,
    /// Bearings that are not actuator pads.
    pub bearings: Vec<Bearing>,
    /// The DOFs held at zero by ideal constraints.
    pub held: DofSet,
    /// The oil's bulk modulus, Pa.
    pub oil_bulk_modulus_pa: f64,
}

/// A multi-axis table, always valid: the platen is held or moved in every DOF, and every
/// value is in its physical range.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiAxisTable {
    parts: TableParts,
    /// Actuator lengths at neutral (swivel; 0 for pads), m.
    neutral_lengths_m: Vec<f64>,
    /// Strut lengths at neutral, m.
    strut_neutral_m: Vec<f64>,
}

/// An actuator at a pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorPose {
    /// Stroke from neutral, m (swivel: length change; pad: the axis point's travel).
    pub stroke_m: f64,
    /// The direction of its force on the platen (table axes, unit).
    pub unit: Vector3<f64>,
    /// Where its force acts, table axes, m.
    pub point_m: Point,
    /// The wrench about the reference point of a unit force: `[u; (point − t) × u]`.
    pub unit_wrench: Wrench,
}

/// The platen's frame at a pose: its rotation, the reference point's position and the
/// underside's normal ([`MultiAxisTable::frame`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// `R = Rz(yaw)·Ry(pitch)·Rx(roll)`.
    pub rotation: nalgebra::Rotation3<f64>,
    /// The reference point, table axes, m.
    pub translation: Vector3<f64>,
    /// The platen's z axis `R·e_z` (the underside's normal).
    pub normal: Vector3<f64>,
}

/// The platen's motion at a pose with its rates: its frame and what the equations of motion
/// need of the angles, each computed once ([`MultiAxisTable::kinematics`]). One right-hand
/// side of the dynamics needs the rotation, the rate map and the angular velocity in several
/// places; taking them from here gives the same numbers as computing each afresh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// The platen's frame at the pose.
    pub frame: Frame,
    /// `E(q)`, with `ω = E·(roll′, pitch′, yaw′)` ([`angular_rate_map`]).
    pub rate_map: Matrix3<f64>,
    /// The angular velocity `ω` in table axes, rad/s.
    pub omega_rad_s: Vector3<f64>,
    /// The reference point's velocity `ṫ`, m/s.
    pub velocity_m_s: Vector3<f64>,
    /// `Ė·θ̇` ([`angular_rate_bias`]), rad/s².
    pub rate_bias_rad_s2: Vector3<f64>,
    /// The platen's centre of mass from the reference point, table axes, `R·c`, m.
    pub centre_of_mass_m: Point,
    /// The platen's inertia about its centre of mass in table axes, `R·I_c·Rᵀ`, kg·m².
    pub inertia_kg_m2: Matrix3<f64>,
}

/// A hold-down strut at a pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrutPose {
    /// Pin-to-pin length, m.
    pub length_m: f64,
    /// Gas pressure, Pa.
    pub pressure_pa: f64,
    /// Its pull `p·A`, N (≥ 0; acts on the platen towards the base).
    pub force_n: f64,
    /// The wrench it exerts on the platen about the reference point.
    pub wrench: Wrench,
}

pub(crate) fn point_wrench(arm: &Vector3<f64>, force: &Vector3<f64>) -> Wrench {
    let m = arm.cross(force);
    Wrench::new(force[0], force[1], force[2], m[0], m[1], m[2])
}

/// Checks actuator `i` of `parts` (its name unique, its areas, volume and stroke, its
/// mount); its length at neutral, m (0 for a pad).
fn check_actuator(parts: &TableParts, i: usize) -> Result<f64> {
    let a = &parts.actuators[i];
    let at = |key: &str| format!("actuators[{i}].{key}");
    check_name(at("name"), &a.name)?;
    if parts.actuators[..i].iter().any(|b| b.name == a.name) {
        return Err(invalid(
            at("name"),
            format!("a name used once (`{}` repeats)", a.name),
        ));
    }
    finite_point(&at("base_m"), &a.base_m)?;
    positive(at("cap_side_area_m2"), a.cap_side_area_m2, "m²")?;
    non_negative(at("rod_side_area_m2"), a.rod_side_area_m2, "m²")?;
    positive(at("chamber_volume_m3"), a.chamber_volume_m3, "m³")?;
    positive(at("stroke_m"), a.stroke_m, "m")?;
    match &a.mount {
        Mount::Swivel { platen_m } => {
            finite_point(&at("platen_m"), platen_m)?;
            let length = (platen_m - a.base_m).norm();
            if length <= 1e-6 {
                return Err(invalid(
                    at("platen_m"),
                    "a platen point apart from the base point (the actuator has zero length)",
                ));
            }
            Ok(length)
        }
        Mount::Pad(pad) => {
            finite_point(&at("pad.contact_m"), &pad.contact_m)?;
            if !pad.axis.iter().all(|c| c.is_finite()) || pad.axis[2].abs() < 1e-3 {
                return Err(invalid(
                    at("pad.axis"),
                    "a direction that crosses the platen's underside (not horizontal)",
                ));
            }
            non_negative(
                at("pad.friction_coefficient"),
                pad.friction_coefficient,
                "1",
            )?;
            Ok(0.0)
        }
    }
}

/// Checks hold-down strut `j` of `parts` (its name unique among struts and actuators, its
/// points, area, pressure, gas and exponent); its length at neutral, m.
fn check_strut(parts: &TableParts, j: usize) -> Result<f64> {
    let s = &parts.struts[j];
    let at = |key: &str| format!("hold_down_struts[{j}].{key}");
    check_name(at("name"), &s.name)?;
    if parts.struts[..j].iter().any(|b| b.name == s.name)
        || parts.actuators.iter().any(|a| a.name == s.name)
    {
        return Err(invalid(
            at("name"),
            format!("a name used once (`{}` repeats)", s.name),
        ));
    }
    finite_point(&at("base_m"), &s.base_m)?;
    finite_point(&at("platen_m"), &s.platen_m)?;
    positive(at("area_m2"), s.area_m2, "m²")?;
    non_negative(at("pressure_pa"), s.pressure_pa, "Pa")?;
    positive(at("gas_volume_m3"), s.gas_volume_m3, "m³")?;
    if !(s.polytropic_exponent.is_finite() && (1.0..=2.0).contains(&s.polytropic_exponent)) {
        return Err(invalid(at("polytropic_exponent"), "a number in [1, 2]"));
    }
    let length = (s.platen_m - s.base_m).norm();
    if length <= 1e-6 {
        return Err(invalid(
            at("platen_m"),
            "a platen point apart from the base point",
        ));
    }
    Ok(length)
}

/// Checks bearing `k` of `parts`: its point, its friction and its load (a constant force or
/// a swivel-mounted actuator's).
fn check_bearing(parts: &TableParts, k: usize) -> Result<()> {
    let b = &parts.bearings[k];
    let at = |key: &str| format!("bearings[{k}].{key}");
    finite_point(&at("platen_m"), &b.platen_m)?;
    non_negative(at("friction_coefficient"), b.friction_coefficient, "1")?;
    match b.load {
        BearingLoad::Constant(n) => {
            non_negative(at("normal_force_n"), n, "N")?;
        }
        BearingLoad::Actuator(i) => match parts.actuators.get(i).map(|a| &a.mount) {
            Some(Mount::Swivel { .. }) => {}
            _ => {
                return Err(invalid(
                    at("actuator"),
                    "the name of a swivel-mounted actuator (a pad carries its own friction)",
                ))
            }
        },
    }
    Ok(())
}

/// Where a pad's axis meets the underside of the platen whose z axis is `normal` and whose
/// reference point is at `t`, and how far along the axis from its neutral contact, m.
pub(crate) fn pad_point(pad: &Pad, t: &Vector3<f64>, normal: &Vector3<f64>) -> (Point, f64) {
    // The axis point c + s·a on the plane {t + R·p : p_z = c_z}.
    let s = (pad.contact_m[2] - normal.dot(&(pad.contact_m - t))) / normal.dot(&pad.axis);
    (pad.contact_m + pad.axis.into_inner() * s, s)
}

impl MultiAxisTable {
    /// Validates `parts` into a table.
    ///
    /// # Errors
    /// [`ModelError::InvalidTable`] naming the contract path of the first bad value (a
    /// zero-length actuator or strut, a pad axis in the underside's plane, a negative area,
    /// a bearing on an unknown or pad actuator, duplicate names, …), and
    /// [`ModelError::UncontrolledDof`] when the actuators cannot move a DOF that is not held.
    pub fn new(parts: TableParts) -> Result<Self> {
        positive(
            "oil_bulk_modulus_pa".into(),
            parts.oil_bulk_modulus_pa,
            "Pa",
        )?;
        if parts.held.complement().iter().next().is_none() {
            return Err(invalid(
                "held_dofs",
                "at most five of the six DOFs: with every DOF held the platen cannot move",
            ));
        }
        let neutral_lengths_m = (0..parts.actuators.len())
            .map(|i| check_actuator(&parts, i))
            .collect::<Result<Vec<_>>>()?;
        let strut_neutral_m = (0..parts.struts.len())
            .map(|j| check_strut(&parts, j))
            .collect::<Result<Vec<_>>>()?;
        for k in 0..parts.bearings.len() {
            check_bearing(&parts, k)?;
        }
        let table = MultiAxisTable {
            parts,
            neutral_lengths_m,
            strut_neutral_m,
        };
        table.check_controlled()?;
        Ok(table)
    }

    /// The rank check: the actuators' unit wrenches at neutral must span every DOF that is
    /// not held. Names the free direction the actuators cannot push (its largest component).
    fn check_controlled(&self) -> Result<()> {
        let free: Vec<Dof> = self.free().iter().collect();
        let n = self.parts.actuators.len();
        let neutral = Coords::zeros();
        let mut g = DMatrix::zeros(free.len(), n);
        for i in 0..n {
            let w = self.actuator_at(i, &neutral).unit_wrench;
            for (r, d) in free.iter().enumerate() {
                g[(r, i)] = w[d.index()];
            }
        }
        let gram = &g * g.transpose();
        let eig = nalgebra::SymmetricEigen::new(gram);
        let top = eig.eigenvalues.max().max(0.0);
        for (c, &lambda) in eig.eigenvalues.iter().enumerate() {
            if lambda <= 1e-12 * top || top == 0.0 {
                let v = eig.eigenvectors.column(c);
                let (r, _) = v.iamax_full();
                return Err(ModelError::UncontrolledDof {
                    dof: free.get(r).map_or("x", |d| d.name()),
                });
            }
        }
        Ok(())
    }

    /// Its parts.
    pub fn parts(&self) -> &TableParts {
        &self.parts
    }

    /// The platen.
    pub fn platen(&self) -> &RigidPlaten {
        &self.parts.platen
    }

    /// The actuators.
    pub fn actuators(&self) -> &[Actuator] {
        &self.parts.actuators
    }

    /// The hold-down struts.
    pub fn struts(&self) -> &[Strut] {
        &self.parts.struts
    }

    /// The held DOFs.
    pub fn held(&self) -> DofSet {
        self.parts.held
    }

    /// The DOFs that move.
    pub fn free(&self) -> DofSet {
        self.parts.held.complement()
    }

    /// The platen's frame at pose `q`: what every point's position needs, computed once.
    pub fn frame(&self, q: &Coords) -> Frame {
        let r = rotation(q);
        Frame {
            rotation: r,
            translation: translation(q),
            normal: r * Vector3::z(),
        }
    }

    /// The platen's kinematics at pose `q` with rates `qd`: its frame, rate map, angular
    /// velocity and its mass's place and inertia in table axes, computed once.
    pub fn kinematics(&self, q: &Coords, qd: &Coords) -> Kinematics {
        let frame = self.frame(q);
        let e = angular_rate_map(q);
        let p = &self.parts.platen;
        let r = frame.rotation;
        Kinematics {
            frame,
            rate_map: e,
            omega_rad_s: e * qd.fixed_rows::<3>(3),
            velocity_m_s: Vector3::new(qd[0], qd[1], qd[2]),
            rate_bias_rad_s2: angular_rate_bias(q, qd),
            centre_of_mass_m: r * p.centre_of_mass_m,
            inertia_kg_m2: r * p.inertia_kg_m2 * r.transpose(),
        }
    }

    /// Actuator `i` at pose `q`.
    ///
    /// # Panics
    /// If `i` is out of range.
    pub fn actuator_at(&self, i: usize, q: &Coords) -> ActuatorPose {
        self.actuator_in(i, &self.frame(q))
    }

    /// Actuator `i` in the platen's frame `f` ([`MultiAxisTable::frame`]).
    ///
    /// # Panics
    /// If `i` is out of range.
    pub fn actuator_in(&self, i: usize, f: &Frame) -> ActuatorPose {
        let a = &self.parts.actuators[i];
        let t = f.translation;
        match &a.mount {
            Mount::Swivel { platen_m } => {
                let arm = f.rotation * platen_m;
                let point = t + arm;
                let line = point - a.base_m;
                let length = line.norm();
                let unit = line / length;
                ActuatorPose {
                    stroke_m: length - self.neutral_lengths_m[i],
                    unit,
                    point_m: point,
                    unit_wrench: point_wrench(&arm, &unit),
                }
            }
            Mount::Pad(pad) => {
                let (point, s) = pad_point(pad, &t, &f.normal);
                ActuatorPose {
                    stroke_m: s,
                    unit: pad.axis.into_inner(),
                    point_m: point,
                    unit_wrench: point_wrench(&(point - t), &pad.axis),
                }
            }
        }
    }

    /// The rate of actuator `i`'s stroke, m/s, at `pose` (its pose in the frame `f`) with the
    /// reference point's velocity `td` and the angular velocity `omega` (see
    /// [`MultiAxisTable::stroke_rate_m_s`]).
    ///
    /// # Panics
    /// If `i` is out of range.
    pub fn stroke_rate_in(
        &self,
        i: usize,
        f: &Frame,
        pose: &ActuatorPose,
        td: &Vector3<f64>,
        omega: &Vector3<f64>,
    ) -> f64 {
        let t = f.translation;
        match &self.parts.actuators[i].mount {
            Mount::Swivel { .. } => pose.unit.dot(&(td + omega.cross(&(pose.point_m - t)))),
            Mount::Pad(pad) => {
                let n = f.normal;
                let nd = omega.cross(&n);
                let a = pad.axis.into_inner();
                (n.dot(td) - nd.dot(&(pad.contact_m - t)) - pose.stroke_m * nd.dot(&a)) / n.dot(&a)
            }
        }
    }

    /// The rate of actuator `i`'s stroke at pose `q` with rates `qd`, m/s: a swivel's
    /// `u·(ṫ + ω × (p − t))` (its length's rate); a pad's rate of the axis point's travel
    /// `ṡ = (n·ṫ − ṅ·(c − t) − s·ṅ·a)/(n·a)`, `n = R·e_z` the underside's normal,
    /// `ṅ = ω × n` (from `s·(n·a) = c_z − n·(c − t)`), which is the piston's speed.
    ///
    /// # Panics
    /// If `i` is out of range.
    pub fn stroke_rate_m_s(&self, i: usize, q: &Coords, qd: &Coords) -> f64 {
        let f = self.frame(q);
        let pose = self.actuator_in(i, &f);
        let omega = angular_velocity(q, qd);
        let td = Vector3::new(qd[0], qd[1], qd[2]);
        self.stroke_rate_in(i, &f, &pose, &td, &omega)
    }

    /// Strut `j` at pose `q`.
    ///
    /// # Panics
    /// If `j` is out of range.
    pub fn strut_at(&self, j: usize, q: &Coords) -> StrutPose {
        self.strut_in(j, &self.frame(q))
    }

    /// Strut `j` in the platen's frame `f`.
    ///
    /// # Panics
    /// If `j` is out of range.
    pub fn strut_in(&self, j: usize, f: &Frame) -> StrutPose {
        let s = &self.parts.struts[j];
        let arm = f.rotation * s.platen_m;
        let line = f.translation + arm - s.base_m;
        let length = line.norm();
        let pressure = s.pressure_at_pa(length, self.strut_neutral_m[j]);
        let force = pressure * s.area_m2;
        StrutPose {
            length_m: length,
            pressure_pa: pressure,
            force_n: force,
            wrench: point_wrench(&arm, &(-line / length * force)),
        }
    }

    /// The struts' wrench on the platen at pose `q`.
    pub fn struts_wrench(&self, q: &Coords) -> Wrench {
        self.struts_wrench_in(&self.frame(q))
    }

    /// The struts' wrench on the platen in its frame `f`.
    pub fn struts_wrench_in(&self, f: &Frame) -> Wrench {
        (0..self.parts.struts.len())
            .map(|j| self.strut_in(j, f).wrench)
            .sum()
    }

    /// The rigid-body mass matrix about the reference point in table axes at pose `q`:
    /// `[[m·I, −m·[r_c]×], [m·[r_c]×, I_w − m·[r_c]×[r_c]×]]` acting on (ẗ, ω̇), with
    /// `r_c = R·c` and `I_w = R·I_c·Rᵀ`.
    pub fn spatial_mass_matrix(&self, q: &Coords) -> Matrix6<f64> {
        self.spatial_mass_matrix_in(&self.kinematics(q, &Coords::zeros()))
    }

    /// [`MultiAxisTable::spatial_mass_matrix`] with the platen's kinematics `k`.
    pub fn spatial_mass_matrix_in(&self, k: &Kinematics) -> Matrix6<f64> {
        let x = k.centre_of_mass_m.cross_matrix();
        let m = self.parts.platen.mass_kg;
        let mut out = Matrix6::zeros();
        out.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * m));
        out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-x * m));
        out.fixed_view_mut::<3, 3>(3, 0).copy_from(&(x * m));
        out.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(k.inertia_kg_m2 - x * x * m));
        out
    }

    /// The velocity terms of Newton–Euler about the reference point, `h(q, ω)`:
    /// `[m·ω×(ω×r_c); ω×(I_w·ω) + m·r_c×(ω×(ω×r_c))]`, so that
    /// `M·(ẗ, ω̇) + h = W_applied + W_gravity`.
    pub fn velocity_wrench(&self, q: &Coords, omega: &Vector3<f64>) -> Wrench {
        let k = self.kinematics(q, &Coords::zeros());
        self.velocity_wrench_with(&k.centre_of_mass_m, &k.inertia_kg_m2, omega)
    }

    /// `h` with the centre of mass `rc` and inertia `iw` in table axes.
    fn velocity_wrench_with(
        &self,
        rc: &Vector3<f64>,
        iw: &Matrix3<f64>,
        omega: &Vector3<f64>,
    ) -> Wrench {
        let p = &self.parts.platen;
        let centripetal = omega.cross(&omega.cross(rc)) * p.mass_kg;
        let moment = omega.cross(&(iw * omega)) + rc.cross(&centripetal);
        Wrench::new(
            centripetal[0],
            centripetal[1],
            centripetal[2],
            moment[0],
            moment[1],
            moment[2],
        )
    }

    /// Gravity's wrench on the platen about the reference point at pose `q`.
    pub fn gravity_wrench(&self, q: &Coords) -> Wrench {
        self.gravity_wrench_with(&(rotation(q) * self.parts.platen.centre_of_mass_m))
    }

    /// Gravity's wrench with the centre of mass at `rc` from the reference point.
    fn gravity_wrench_with(&self, rc: &Vector3<f64>) -> Wrench {
        let weight = Vector3::new(0.0, 0.0, -self.parts.platen.mass_kg * STANDARD_GRAVITY_M_S2);
        point_wrench(rc, &weight)
    }

    /// The wrench about the reference point that every applied force but gravity must exert
    /// for the platen to move with `q`, `qd`, `qdd` (the six coordinates and their
    /// derivatives): `M·(ẗ, ω̇) + h − W_gravity`, with `ω̇ = E·θ̈ + Ė·θ̇`.
    pub fn required_wrench(&self, q: &Coords, qd: &Coords, qdd: &Coords) -> Wrench {
        let e = angular_rate_map(q);
        let omega = e * qd.fixed_rows::<3>(3);
        let alpha = e * qdd.fixed_rows::<3>(3) + angular_rate_bias(q, qd);
        let acc = Vector6::new(qdd[0], qdd[1], qdd[2], alpha[0], alpha[1], alpha[2]);
        self.spatial_mass_matrix(q) * acc + self.velocity_wrench(q, &omega) - self.gravity_wrench(q)
    }

    /// The generalised force `Q = Jᵀ·W` of a wrench about the reference point, with
    /// `J = diag(I, E)` the map from the coordinate rates to (ṫ, ω): what the wrench does per
    /// metre and per radian of the six coordinates.
    pub fn generalised_force(&self, q: &Coords, wrench: &Wrench) -> Coords {
        let e = angular_rate_map(q);
        let m = e.transpose() * wrench.fixed_rows::<3>(3);
        Coords::new(wrench[0], wrench[1], wrench[2], m[0], m[1], m[2])
    }

    /// The coordinates' second derivatives under the applied wrench `applied` (every force
    /// but gravity, about the reference point) at `q`, `qd`, the held DOFs' at zero. `None`
    /// where the mass matrix is not positive definite (pitch at ±π/2).
    pub fn accelerations(&self, q: &Coords, qd: &Coords, applied: &Wrench) -> Option<Coords> {
        self.accelerations_in(&self.kinematics(q, qd), applied)
    }

    /// [`MultiAxisTable::accelerations`] with the platen's kinematics `k`.
    pub fn accelerations_in(&self, k: &Kinematics, applied: &Wrench) -> Option<Coords> {
        let (mq, rhs) = self.coordinate_dynamics_in(k, applied);
        Cholesky::new(mq).map(|c| c.solve(&rhs))
    }

    /// The coordinates' mass matrix `Jᵀ·M·J` and right-hand side `Jᵀ·(W + W_g − h − M·J̇·q̇)`
    /// under the applied wrench `applied`, the held DOFs' rows and columns identity and zero.
    pub(crate) fn coordinate_dynamics(
        &self,
        q: &Coords,
        qd: &Coords,
        applied: &Wrench,
    ) -> (Matrix6<f64>, Coords) {
        self.coordinate_dynamics_in(&self.kinematics(q, qd), applied)
    }

    /// [`MultiAxisTable::coordinate_dynamics`] with the platen's kinematics `k`.
    fn coordinate_dynamics_in(&self, k: &Kinematics, applied: &Wrench) -> (Matrix6<f64>, Coords) {
        let m6 = self.spatial_mass_matrix_in(k);
        let mut j = Matrix6::identity();
        j.fixed_view_mut::<3, 3>(3, 3).copy_from(&k.rate_map);
        let mut jdqd = Wrench::zeros();
        jdqd.fixed_rows_mut::<3>(3).copy_from(&k.rate_bias_rad_s2);
        let rc = &k.centre_of_mass_m;
        let rhs_w = applied + self.gravity_wrench_with(rc)
            - self.velocity_wrench_with(rc, &k.inertia_kg_m2, &k.omega_rad_s)
            - m6 * jdqd;
        let mut mq = j.transpose() * m6 * j;
        let mut rhs = j.transpose() * rhs_w;
        for d in self.held().iter() {
            let k = d.index();
            mq.row_mut(k).fill(0.0);
            mq.column_mut(k).fill(0.0);
            mq[(k, k)] = 1.0;
            rhs[k] = 0.0;
        }
        (mq, rhs)
    }

    /// The actuator forces that exert the generalised force `target` on the free DOFs
    /// (`Q = Jᵀ·Σ fᵢ·wᵢ`, the held DOFs' components ignored), the redundant combinations
    /// resolved to zero as a force balance does: the minimum-norm solution, orthogonal to the
    /// combinations that move nothing. `extra` adds, per actuator, a wrench per newton of its
    /// force (the friction its normal force causes). `None` if the free DOFs lose rank here.
    pub fn resolve_forces(
        &self,
        q: &Coords,
        target: &Coords,
        extra: Option<&[Wrench]>,
    ) -> Option<Vec<f64>> {
        let free: Vec<usize> = self.free().iter().map(Dof::index).collect();
        let n = self.parts.actuators.len();
        let mut a = DMatrix::zeros(free.len(), n);
        for i in 0..n {
            let mut w = self.actuator_at(i, q).unit_wrench;
            if let Some(x) = extra {
                w += x[i];
            }
            let g = self.generalised_force(q, &w);
            for (r, &k) in free.iter().enumerate() {
                a[(r, i)] = g[k];
            }
        }
        let b = nalgebra::DVector::from_iterator(free.len(), free.iter().map(|&k| target[k]));
        let svd = SVD::new(a, true, true);
        let top = svd.singular_values.max();
        if svd.singular_values.min() <= 1e-12 * top {
            return None;
        }
        svd.solve(&b, 0.0).ok().map(|f| f.iter().copied().collect())
    }
}
