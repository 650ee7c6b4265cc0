//! Bearing friction and the inverse problem of the multi-axis platen: the actuator forces a
//! prescribed motion needs, with each term of their decomposition.

use nalgebra::Vector3;

use super::dof::{angular_velocity, rotation, translation, Coords};
use super::table::{BearingLoad, Mount, MultiAxisTable, Point, Wrench};

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
        let r = rotation(q);
        let t = translation(q);
        let normal = r * Vector3::z();
        let pads = self
            .actuators()
            .iter()
            .enumerate()
            .filter_map(|(i, a)| match &a.mount {
                Mount::Pad(pad) => Some(Contact {
                    point_m: self.actuator_at(i, q).point_m,
                    normal,
                    friction_coefficient: pad.friction_coefficient,
                    load: ContactLoad::Actuator(i),
                }),
                Mount::Swivel { .. } => None,
            });
        let bearings = self.parts().bearings.iter().map(|b| Contact {
            point_m: t + r * b.platen_m,
            normal,
            friction_coefficient: b.friction_coefficient,
            load: match b.load {
                BearingLoad::Actuator(i) => ContactLoad::Actuator(i),
                BearingLoad::Constant(n) => ContactLoad::Constant(n),
            },
        });
        pads.chain(bearings).collect()
    }

    /// The platen's sliding velocity at `contact` (its material point's velocity less the
    /// normal part), m/s, at pose `q` with rates `qd`.
    pub fn sliding_velocity(&self, contact: &Contact, q: &Coords, qd: &Coords) -> Vector3<f64> {
        let omega = angular_velocity(q, qd);
        let v =
            Vector3::new(qd[0], qd[1], qd[2]) + omega.cross(&(contact.point_m - translation(q)));
        v - contact.normal * contact.normal.dot(&v)
    }

    /// The wrench about the reference point of a contact's friction per newton of normal force
    /// (`−μ·ŝ` at its point, `ŝ` the sliding direction; zero where it does not slide, as
    /// `sign(0) = 0` in the uniaxial Eq. 23).
    pub fn friction_per_newton(&self, contact: &Contact, q: &Coords, qd: &Coords) -> Wrench {
        let s = self.sliding_velocity(contact, q, qd);
        let speed = s.norm();
        if speed == 0.0 || contact.friction_coefficient == 0.0 {
            return Wrench::zeros();
        }
        let f = s * (-contact.friction_coefficient / speed);
        let m = (contact.point_m - translation(q)).cross(&f);
        Wrench::new(f[0], f[1], f[2], m[0], m[1], m[2])
    }
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
