//! Bearing friction and the inverse problem of the multi-axis platen: the actuator forces a
//! prescribed motion needs, with each term of their decomposition.

use nalgebra::{DMatrix, DVector, Matrix6, Vector2, Vector3};

use super::dof::{translation, Coords, Dof};
use super::table::{
    pad_point, point_wrench, BearingLoad, Frame, Mount, MultiAxisTable, Point, Wrench,
};

/// What presses a friction contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactLoad {
    /// The force of actuator `i` (its pad, or the swivel actuator under a bearing).
    Actuator(usize),
    /// A constant normal force, N.
    Constant(f64),
}

/// A friction contact at a pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Where the platen touches it, table axes, m.
    pub point_m: Point,
    /// The normal of the sliding plane (the platen's z axis), table axes.
    pub normal: Vector3<f64>,
    /// Its Coulomb coefficient.
    pub friction_coefficient: f64,
    /// What presses it.
    pub load: ContactLoad,
}

impl MultiAxisTable {
    /// The friction contacts at pose `q`: every pad (at its axis point) and every bearing.
    pub fn contacts_at(&self, q: &Coords) -> Vec<Contact> {
        self.contacts(q).collect()
    }

    /// The friction contacts at pose `q`, without collecting them.
    pub(crate) fn contacts(&self, q: &Coords) -> impl Iterator<Item = Contact> + '_ {
        self.contacts_in(self.frame(q))
    }

    /// The friction contacts in the platen's frame `f`.
    pub(crate) fn contacts_in(&self, f: Frame) -> impl Iterator<Item = Contact> + '_ {
        let (r, t, normal) = (f.rotation, f.translation, f.normal);
        let pads = self
            .actuators()
            .iter()
            .enumerate()
            .filter_map(move |(i, a)| match &a.mount {
                Mount::Pad(pad) => Some(Contact {
                    point_m: pad_point(pad, &t, &normal).0,
                    normal,
                    friction_coefficient: pad.friction_coefficient,
                    load: ContactLoad::Actuator(i),
                }),
                Mount::Swivel { .. } => None,
            });
        let bearings = self.parts().bearings.iter().map(move |b| Contact {
            point_m: t + r * b.platen_m,
            normal,
            friction_coefficient: b.friction_coefficient,
            load: match b.load {
                BearingLoad::Actuator(i) => ContactLoad::Actuator(i),
                BearingLoad::Constant(n) => ContactLoad::Constant(n),
            },
        });
        pads.chain(bearings)
    }

    /// Whether any contact has friction (a coefficient above zero).
    pub fn has_friction(&self) -> bool {
        self.contacts(&Coords::zeros())
            .any(|c| c.friction_coefficient > 0.0)
    }

    /// The platen's sliding velocity at `contact`, m/s: the horizontal velocity of its point
    /// in the platen's in-plane motion ([`planar_rate`]) at pose `q` with rates `qd`.
    pub fn sliding_velocity(&self, contact: &Contact, q: &Coords, qd: &Coords) -> Vector3<f64> {
        let v = planar_sliding(&contact.point_m, &translation(q), &planar_rate(qd));
        Vector3::new(v[0], v[1], 0.0)
    }

    /// The wrench about the reference point of a contact's friction per newton of normal force
    /// (`−μ·ŝ` at its point, `ŝ` the horizontal sliding direction; zero where it does not
    /// slide, as `sign(0) = 0` in the uniaxial Eq. 23).
    pub fn friction_per_newton(&self, contact: &Contact, q: &Coords, qd: &Coords) -> Wrench {
        let s = planar_sliding(&contact.point_m, &translation(q), &planar_rate(qd));
        let speed = s.norm();
        if speed == 0.0 || contact.friction_coefficient == 0.0 {
            return Wrench::zeros();
        }
        let f = Vector3::new(s[0], s[1], 0.0) * (-contact.friction_coefficient / speed);
        point_wrench(&(contact.point_m - translation(q)), &f)
    }

    /// The bearings' Coulomb capacity at pose `q` with the actuator forces `forces_n` (which
    /// press the pads and the bearings on actuators; a pulling actuator presses nothing).
    pub fn friction_capacity(&self, q: &Coords, forces_n: &[f64]) -> FrictionCapacity {
        self.friction_capacity_in(&self.frame(q), forces_n)
    }

    /// [`MultiAxisTable::friction_capacity`] in the platen's frame `f`.
    pub fn friction_capacity_in(&self, f: &Frame, forces_n: &[f64]) -> FrictionCapacity {
        let (mut total, mut centre) = (0.0, Point::zeros());
        for c in self.contacts_in(*f) {
            let mu_n = c.friction_coefficient * normal_force_n(c.load, forces_n);
            total += mu_n;
            centre += c.point_m * mu_n;
        }
        if total == 0.0 {
            return FrictionCapacity {
                force_n: 0.0,
                moment_n_m: 0.0,
                centre_m: f.translation,
            };
        }
        centre /= total;
        let moment = self
            .contacts_in(*f)
            .map(|c| {
                let mu_n = c.friction_coefficient * normal_force_n(c.load, forces_n);
                mu_n * (c.point_m - centre).xy().norm()
            })
            .sum();
        FrictionCapacity {
            force_n: total,
            moment_n_m: moment,
            centre_m: centre,
        }
    }

    /// The bearings' friction on the platen sliding with rates `qd` at pose `q`, with the
    /// bearings' `capacity` there: the limit surface's law, a horizontal force at the
    /// friction centre and a moment about the vertical through it,
    /// `(F, M/ρ) = −F_max·τ/|τ|`, `τ = (v_c, ρ·ψ̇)`, `ρ = M_max/F_max`, `v_c` the friction
    /// centre's in-plane velocity: the point of the ellipsoid
    /// ([`MultiAxisTable::stick`]) whose normal is the motion (maximum dissipation). A slide
    /// without turning has the contacts' own Coulomb friction `−Σ μᵢ·Nᵢ·v̂` exactly, a pure
    /// turn about the centre their `−Σ μᵢ·Nᵢ·rᵢ`; in between the ellipsoid approximates the
    /// contacts' limit surface, and keeps stick and slip one law. The wrench is about the
    /// reference point.
    ///
    /// `τ` is blended with `blend_m_s` of the unit `τ` of the in-plane motion `along` (the
    /// direction the slide was last known to go): a slide along `along` has exactly its
    /// direction, far above the blend the direction is the motion's. Near rest the Coulomb
    /// direction `τ/|τ|` is stiff across the motion (it turns the velocity in a time
    /// `m·|τ|/F_max`, shorter than any step as `|τ| → 0`); the blend bounds that time by
    /// `m·ε/F_max`, which is what lets an explicit step leave rest and arrive at it along the
    /// right direction.
    pub fn sliding_friction(
        &self,
        q: &Coords,
        qd: &Coords,
        capacity: &FrictionCapacity,
        along: &PlanarRate,
        blend_m_s: f64,
    ) -> Wrench {
        if capacity.force_n == 0.0 {
            return Wrench::zeros();
        }
        let t = translation(q);
        let arm = capacity.centre_m - t;
        let rho = capacity.moment_n_m / capacity.force_n;
        let scaled =
            |w: &PlanarRate| Vector3::new(w[0] - w[2] * arm[1], w[1] + w[2] * arm[0], w[2] * rho);
        let mut tau = scaled(&planar_rate(qd));
        let g = scaled(along);
        let g_norm = g.norm();
        if g_norm > 0.0 {
            tau += g * (blend_m_s / g_norm);
        }
        let speed = tau.norm();
        if speed == 0.0 {
            return Wrench::zeros();
        }
        let k = -capacity.force_n / speed;
        let force = Vector3::new(tau[0] * k, tau[1] * k, 0.0);
        let mut w = point_wrench(&arm, &force);
        w[5] += tau[2] * k * rho;
        w
    }

    /// The in-plane motion (of the reference point, unit speed in the limit surface's metric)
    /// in which the platen leaves rest when the friction that would hold it, `stick`, is
    /// outside the limit surface of `capacity` (ratio > 1), at pose `q` with rates `qd` under
    /// `applied`. The friction it slides against is the point `b` of the surface nearest to
    /// the holding friction in the platen's own inertia (Gauss's least constraint: `b`
    /// minimises `(b − λ)ᵀ·G·(b − λ)`, `G` the in-plane accelerations per unit of friction at
    /// the centre), and the platen moves along that point's normal, against it. At the
    /// breakaway itself (ratio → 1) this is the normal at the holding friction; past it, it
    /// turns with the platen's inertia so that the motion and its friction agree. Where
    /// nothing holds (every contact lifted off), the direction of its in-plane acceleration.
    pub fn breakaway(
        &self,
        q: &Coords,
        qd: &Coords,
        applied: &Wrench,
        capacity: &FrictionCapacity,
        stick: &Stick,
    ) -> PlanarRate {
        let limits = [capacity.force_n, capacity.force_n, capacity.moment_n_m];
        let dofs = [Dof::X, Dof::Y, Dof::Yaw];
        // The in-plane DOFs the friction holds: free, with a limit.
        let active: Vec<usize> = (0..3)
            .filter(|&k| !self.held().contains(dofs[k]) && limits[k] > 0.0)
            .collect();
        let n = active.len();
        if n == 0 {
            return self.flight_direction(q, qd, applied);
        }
        let arm = capacity.centre_m - translation(q);
        let Some(g) = self.friction_mobility(q, qd, applied, &active, &arm) else {
            return PlanarRate::zeros();
        };
        let sv = DVector::from_fn(n, |r, _| limits[active[r]]);
        let lambda = DVector::from_fn(n, |r, _| stick.holding[active[r]]);
        let Some(beta) = nearest_on_limit_surface(&g, &sv, &lambda) else {
            return PlanarRate::zeros();
        };
        leaving_motion(&active, &beta, &sv, &arm, capacity)
    }

    /// Where nothing holds (every contact lifted off): the direction of the platen's in-plane
    /// acceleration, along which it flies (zero when it has none).
    fn flight_direction(&self, q: &Coords, qd: &Coords, applied: &Wrench) -> PlanarRate {
        let a = self
            .accelerations(q, qd, applied)
            .unwrap_or_else(Coords::zeros);
        let w = planar_rate(&a);
        let size = w.norm();
        if size > 0.0 {
            w / size
        } else {
            w
        }
    }

    /// `G`: the friction centre's in-plane accelerations per unit of each `active` friction
    /// component (x and y forces at the centre, `arm` from the reference point, and the yaw
    /// moment), from the dynamics with the other DOFs free as they are; symmetrised. `None`
    /// where the dynamics are singular.
    fn friction_mobility(
        &self,
        q: &Coords,
        qd: &Coords,
        applied: &Wrench,
        active: &[usize],
        arm: &Vector3<f64>,
    ) -> Option<DMatrix<f64>> {
        let n = active.len();
        let basis = [
            point_wrench(arm, &Vector3::x()),
            point_wrench(arm, &Vector3::y()),
            Wrench::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        ];
        let base = self.accelerations(q, qd, applied)?;
        let centre = |a: &Coords| Vector3::new(a[0] - a[5] * arm[1], a[1] + a[5] * arm[0], a[5]);
        let mut g = DMatrix::zeros(n, n);
        for (c, &k) in active.iter().enumerate() {
            let a = self.accelerations(q, qd, &(applied + basis[k]))?;
            let response = centre(&(a - base));
            for (r, &j) in active.iter().enumerate() {
                g[(r, c)] = response[j];
            }
        }
        Some((&g + g.transpose()) * 0.5)
    }

    /// The platen at rest in its plane (x, y and yaw, where free, held by the bearings'
    /// friction) at pose `q` with rates `qd` (their in-plane ones zero) under the applied
    /// wrench `applied` (every force but gravity and friction): the accelerations of the other
    /// DOFs and the friction it takes to hold it, measured against `capacity`. `None` where
    /// the equations are singular.
    ///
    /// The holding friction is a force at the friction centre and a moment about the vertical
    /// through it; the ratio is the limit surface's ellipsoid,
    /// `√((F_x² + F_y²)/F_max² + M_z²/M_max²)` (exact for a pure force through the centre and
    /// for a pure turn about it; an approximation of the exact limit surface in between, as
    /// in Goyal, Ruina and Papadopoulos 1991).
    pub fn stick(
        &self,
        q: &Coords,
        qd: &Coords,
        applied: &Wrench,
        capacity: &FrictionCapacity,
    ) -> Option<Stick> {
        let (mq, rhs) = self.coordinate_dynamics(q, qd, applied);
        let held = self.held();
        let arm = capacity.centre_m - translation(q);
        let basis = [
            (Dof::X, point_wrench(&arm, &Vector3::x())),
            (Dof::Y, point_wrench(&arm, &Vector3::y())),
            (Dof::Yaw, Wrench::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0)),
        ];
        // Unknowns per DOF: a held DOF none (identity), an in-plane DOF its holding
        // friction, any other its acceleration.
        let mut a = Matrix6::identity();
        let mut b = Coords::zeros();
        for d in Dof::ALL {
            let k = d.index();
            if held.contains(d) {
                continue;
            }
            b[k] = rhs[k];
            let column: Coords = match basis.iter().find(|(s, _)| *s == d) {
                Some((_, w)) => -self.generalised_force(q, w),
                None => mq.column(k).into(),
            };
            for r in Dof::ALL {
                a[(r.index(), k)] = if held.contains(r) {
                    f64::from(r == d)
                } else {
                    column[r.index()]
                };
            }
        }
        let z = a.lu().solve(&b)?;
        let mut accelerations = Coords::zeros();
        let mut holding = Vector3::zeros();
        let mut wrench = Wrench::zeros();
        for d in self.free().iter() {
            let k = d.index();
            match basis.iter().position(|(s, _)| *s == d) {
                Some(i) => {
                    holding[i] = z[k];
                    wrench += basis[i].1 * z[k];
                }
                None => accelerations[k] = z[k],
            }
        }
        let part = |value: f64, limit: f64| {
            if value == 0.0 {
                0.0
            } else if limit > 0.0 {
                (value / limit).powi(2)
            } else {
                f64::INFINITY
            }
        };
        let ratio = (part(holding[0], capacity.force_n)
            + part(holding[1], capacity.force_n)
            + part(holding[2], capacity.moment_n_m))
        .sqrt();
        Some(Stick {
            accelerations,
            holding,
            wrench,
            ratio,
        })
    }
}

/// The in-plane motion the bearings' friction sees: the reference point's velocity along x
/// and y (m/s) and the yaw rate (rad/s). The rocking's share of a contact's sliding (the roll
/// and pitch rates times the contact's depth) is left out, so that a platen whose in-plane
/// coordinates are still does not slide.
pub type PlanarRate = Vector3<f64>;

/// The point `b = S·β` of the limit surface (limits `sv` on the diagonal of `S`) nearest to
/// the holding friction `lambda` in the metric `g`, as `β`. In `β = S⁻¹·b` the surface is the
/// unit ball: minimise `βᵀHβ − 2βᵀc`, `H = S·G·S`, `c = S·G·λ`, over `|β| ≤ 1` (the
/// trust-region problem: `β = (H + νI)⁻¹·c` with `ν ≥ 0` the root of `|β(ν)| = 1`, by
/// bisection; `|β|` falls as `ν` grows). When the surface holds `λ` after all, the direction
/// of `S⁻¹·λ` (the normal at `λ`); `None` when that is zero.
fn nearest_on_limit_surface(
    g: &DMatrix<f64>,
    sv: &DVector<f64>,
    lambda: &DVector<f64>,
) -> Option<DVector<f64>> {
    let n = sv.len();
    let h = DMatrix::from_fn(n, n, |r, c| sv[r] * g[(r, c)] * sv[c]);
    let cvec = sv.component_mul(&(g * lambda));
    let eig = h.symmetric_eigen();
    let proj = eig.eigenvectors.transpose() * &cvec;
    let beta_at = |nu: f64| {
        let y = DVector::from_fn(n, |i, _| proj[i] / (eig.eigenvalues[i] + nu));
        &eig.eigenvectors * y
    };
    let (mut lo, mut hi) = (0.0, cvec.norm().max(f64::MIN_POSITIVE));
    if beta_at(lo).norm() <= 1.0 {
        // Held after all (the surface holds it): leave along the normal at λ.
        hi = 0.0;
    }
    for _ in 0..200 {
        if hi - lo <= 1e-15 * hi {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if beta_at(mid).norm() > 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    if hi == 0.0 {
        let l = DVector::from_fn(n, |r, _| lambda[r] / sv[r]);
        let norm = l.norm();
        if norm == 0.0 {
            return None;
        }
        Some(l / norm)
    } else {
        Some(beta_at(hi))
    }
}

/// The motion along the normal at `b = S·β`, against it: the friction centre's velocity and
/// the yaw rate `∝ −S⁻¹·β` (over the `active` DOFs), then the reference point's, `arm` away,
/// at unit speed in the limit surface's metric.
fn leaving_motion(
    active: &[usize],
    beta: &DVector<f64>,
    sv: &DVector<f64>,
    arm: &Vector3<f64>,
    capacity: &FrictionCapacity,
) -> PlanarRate {
    let mut u = Vector3::zeros();
    for (r, &k) in active.iter().enumerate() {
        u[k] = -beta[r] / sv[r];
    }
    let w = PlanarRate::new(u[0] + u[2] * arm[1], u[1] - u[2] * arm[0], u[2]);
    let rho = capacity.moment_n_m / capacity.force_n;
    let size = Vector3::new(u[0], u[1], u[2] * rho).norm();
    if size > 0.0 {
        w / size
    } else {
        w
    }
}

/// The in-plane motion of the rates `qd`.
pub fn planar_rate(qd: &Coords) -> PlanarRate {
    Vector3::new(qd[0], qd[1], qd[5])
}

/// The horizontal sliding velocity of the platen point at `point` (table axes) under the
/// in-plane motion `w` of the reference point `t`, m/s.
fn planar_sliding(point: &Point, t: &Vector3<f64>, w: &PlanarRate) -> Vector2<f64> {
    let r = point - t;
    Vector2::new(w[0] - w[2] * r[1], w[1] + w[2] * r[0])
}

/// The normal force of a contact pressed by `load` under the actuator forces `forces_n`, N.
fn normal_force_n(load: ContactLoad, forces_n: &[f64]) -> f64 {
    match load {
        ContactLoad::Actuator(i) => forces_n[i].max(0.0),
        ContactLoad::Constant(n) => n,
    }
}

/// The Coulomb capacity of the bearings at an instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionCapacity {
    /// The largest in-plane force they hold, `Σ μᵢ·Nᵢ`, N.
    pub force_n: f64,
    /// The largest moment about the vertical through the friction centre they hold,
    /// `Σ μᵢ·Nᵢ·|rᵢ − c|` (horizontal distances), N·m.
    pub moment_n_m: f64,
    /// The friction centre `c = Σ μᵢ·Nᵢ·rᵢ / Σ μᵢ·Nᵢ` (table axes), m; the reference point
    /// when nothing presses.
    pub centre_m: Point,
}

/// The platen at rest in its plane ([`MultiAxisTable::stick`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stick {
    /// The coordinates' second derivatives (the in-plane and held ones zero).
    pub accelerations: Coords,
    /// The holding friction: force along x and y at the friction centre (N), moment about
    /// the vertical through it (N·m); zero for a held DOF.
    pub holding: Vector3<f64>,
    /// The holding friction's wrench about the reference point.
    pub wrench: Wrench,
    /// The holding friction on the limit surface's scale: the platen stays at rest while it
    /// is at most 1.
    pub ratio: f64,
}

/// The inverse at one instant: the actuator forces and what they balance.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseSample {
    /// Each actuator's force, N (positive pushes the platen away from its base or along its
    /// axis).
    pub actuator_forces_n: Vec<f64>,
    /// `M·a + h`: the wrench the platen's motion takes (inertia, gyroscopic and centripetal
    /// terms).
    pub inertial: Wrench,
    /// The wrench gravity exerts on the platen.
    pub gravity: Wrench,
    /// The wrench the hold-down struts exert on the platen.
    pub struts: Wrench,
    /// The wrench of the bearings' friction on the platen (at these actuator forces).
    pub friction: Wrench,
    /// The wrench the specimen exerts on the platen.
    pub specimen: Wrench,
    /// The wrench the held DOFs' constraints exert (its generalised force is zero in the free
    /// DOFs).
    pub constraint: Wrench,
}

impl MultiAxisTable {
    /// The actuator forces that move the platen with `q`, `qd`, `qdd` while the specimen
    /// pushes with `specimen` (zero without one): the required wrench less gravity, struts and
    /// the friction of constant loads, resolved over the actuators with each one's friction
    /// included (a pad's friction is `μ` times its own force), the redundant combinations at
    /// zero as a force balance leaves them ([`MultiAxisTable::resolve_forces`]). `None` where
    /// the actuators lose rank on the free DOFs.
    pub fn inverse(
        &self,
        q: &Coords,
        qd: &Coords,
        qdd: &Coords,
        specimen: &Wrench,
    ) -> Option<InverseSample> {
        let needed = self.required_wrench(q, qd, qdd);
        let gravity = self.gravity_wrench(q);
        let inertial = needed + gravity;
        let struts = self.struts_wrench(q);
        let contacts = self.contacts_at(q);
        let mut per_actuator = vec![Wrench::zeros(); self.actuators().len()];
        let mut constant = Wrench::zeros();
        for c in &contacts {
            let w = self.friction_per_newton(c, q, qd);
            match c.load {
                ContactLoad::Actuator(i) => per_actuator[i] += w,
                ContactLoad::Constant(n) => constant += w * n,
            }
        }
        let target = self.generalised_force(q, &(needed - struts - constant - specimen));
        let forces = self.resolve_forces(q, &target, Some(&per_actuator))?;
        let friction = constant
            + per_actuator
                .iter()
                .zip(&forces)
                .map(|(w, f)| w * *f)
                .sum::<Wrench>();
        let actuators: Wrench = (0..forces.len())
            .map(|i| self.actuator_at(i, q).unit_wrench * forces[i])
            .sum();
        let constraint = inertial - gravity - struts - friction - specimen - actuators;
        Some(InverseSample {
            actuator_forces_n: forces,
            inertial,
            gravity,
            struts,
            friction,
            specimen: *specimen,
            constraint,
        })
    }
}
