//! What a multi-axis table can do along each free DOF: its stroke, the force its actuators
//! add over the holding forces, and the acceleration they give, bare table at neutral.

use super::dof::{Coords, Dof};
use super::table::{Actuator, MultiAxisTable};

/// What the table can do along one DOF (bare table, at neutral).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisCapacity {
    /// The DOF.
    pub dof: Dof,
    /// The largest excursion either way before an actuator reaches its stroke (exact
    /// kinematics, the other DOFs at zero), m or rad.
    pub stroke: f64,
    /// The largest force (N) or moment (N·m) the actuators add either way along it, over the
    /// forces that hold the platen still at neutral (its weight and the struts' pull), with
    /// the force balance's distribution and the other DOFs' wrench at zero, before one
    /// reaches its force limit.
    pub force: f64,
    /// The largest acceleration along it (the other DOFs' at zero) from rest at neutral, m/s²
    /// or rad/s², gravity aside.
    pub acceleration: f64,
}

impl Actuator {
    /// Its force limits `(pull ≤ 0, push ≥ 0)` at supply `ps` and return `pr` pressures, N:
    /// push `A_cap·p_s − A_rod·p_r`, pull `−(A_rod·p_s − A_cap·p_r)` (none for a
    /// single-acting actuator, whose rod side is 0).
    pub fn force_limits_n(&self, supply_pa: f64, return_pa: f64) -> (f64, f64) {
        let push = self.cap_side_area_m2 * supply_pa - self.rod_side_area_m2 * return_pa;
        let pull = (self.rod_side_area_m2 * supply_pa - self.cap_side_area_m2 * return_pa).max(0.0);
        (-pull, push.max(0.0))
    }
}

impl MultiAxisTable {
    /// The capacities of every free DOF at supply and return pressures `supply_pa`,
    /// `return_pa` (see [`AxisCapacity`]); a held DOF has none.
    pub fn capacities(&self, supply_pa: f64, return_pa: f64) -> Vec<AxisCapacity> {
        let neutral = Coords::zeros();
        let limits: Vec<(f64, f64)> = self
            .actuators()
            .iter()
            .map(|a| a.force_limits_n(supply_pa, return_pa))
            .collect();
        // The forces that hold the platen still at neutral (its weight and the struts' pull
        // carried), about which the capacities are taken.
        let hold = -(self.gravity_wrench(&neutral) + self.struts_wrench(&neutral));
        let still = self
            .resolve_forces(&neutral, &self.generalised_force(&neutral, &hold), None)
            .unwrap_or_else(|| vec![0.0; limits.len()]);
        // The largest k with every force of still + k·f within its limits, either sign of k.
        let scale = |f: &[f64]| {
            let reach = |sign: f64| {
                f.iter()
                    .zip(&still)
                    .zip(&limits)
                    .map(|((&fi, &f0), &(pull, push))| {
                        let x = sign * fi;
                        if x > 0.0 {
                            ((push - f0) / x).max(0.0)
                        } else if x < 0.0 {
                            ((pull - f0) / x).max(0.0)
                        } else {
                            f64::INFINITY
                        }
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            reach(1.0).min(reach(-1.0))
        };
        let m6 = self.spatial_mass_matrix(&neutral);
        self.free()
            .iter()
            .map(|dof| {
                let mut unit = Coords::zeros();
                unit[dof.index()] = 1.0;
                let force = self
                    .resolve_forces(&neutral, &unit, None)
                    .map_or(0.0, |f| scale(&f));
                let per_acc = self.generalised_force(&neutral, &(m6 * unit));
                let acceleration = self
                    .resolve_forces(&neutral, &per_acc, None)
                    .map_or(0.0, |f| scale(&f));
                AxisCapacity {
                    dof,
                    stroke: self.stroke_along(dof),
                    force,
                    acceleration,
                }
            })
            .collect()
    }

    /// The largest excursion along `dof` both ways with every actuator within its stroke,
    /// by bisection on the exact kinematics to 1e-9 of the first bracket.
    fn stroke_along(&self, dof: Dof) -> f64 {
        let fits = |x: f64| {
            let mut q = Coords::zeros();
            q[dof.index()] = x;
            (0..self.actuators().len())
                .all(|i| self.actuator_at(i, &q).stroke_m.abs() <= self.actuators()[i].stroke_m)
        };
        let one_way = |sign: f64| {
            let mut hi = 1e-3;
            while fits(sign * hi) && hi < 1e3 {
                hi *= 2.0;
            }
            let mut lo = 0.0;
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if fits(sign * mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        one_way(1.0).min(one_way(-1.0))
    }
}
