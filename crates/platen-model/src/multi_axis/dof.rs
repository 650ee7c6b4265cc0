//! The six degrees of freedom, the pose and the map from the angle rates to the angular
//! velocity.

use nalgebra::{Matrix3, Rotation3, Vector3, Vector6};

/// One of the platen's six degrees of freedom, in the order of every six-vector here:
/// x, y, z (m), roll, pitch, yaw (rad).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Dof {
    /// Translation along x, the longitudinal axis (the uniaxial table's axis), m.
    X,
    /// Translation along y, transverse, m.
    Y,
    /// Translation along z, up, m.
    Z,
    /// Rotation about x, rad.
    Roll,
    /// Rotation about y, rad.
    Pitch,
    /// Rotation about z, rad.
    Yaw,
}

impl Dof {
    /// The six, in their order.
    pub const ALL: [Dof; 6] = [Dof::X, Dof::Y, Dof::Z, Dof::Roll, Dof::Pitch, Dof::Yaw];

    /// The position of this DOF in a six-vector.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The contract's name: `x`, `y`, `z`, `roll`, `pitch`, `yaw`.
    pub fn name(self) -> &'static str {
        ["x", "y", "z", "roll", "pitch", "yaw"][self.index()]
    }

    /// The DOF of a contract name, `None` for any other text.
    pub fn from_name(name: &str) -> Option<Dof> {
        Dof::ALL.into_iter().find(|d| d.name() == name)
    }

    /// Whether this is a rotation (rad) rather than a translation (m).
    pub fn is_rotation(self) -> bool {
        self.index() >= 3
    }

    /// The unit of its coordinate: `m` or `rad`.
    pub fn unit(self) -> &'static str {
        if self.is_rotation() {
            "rad"
        } else {
            "m"
        }
    }
}

/// A set of DOFs (for example the held ones).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct DofSet(u8);

impl DofSet {
    /// No DOF.
    pub const EMPTY: DofSet = DofSet(0);

    /// The set of these DOFs.
    pub fn of(dofs: &[Dof]) -> DofSet {
        dofs.iter().fold(DofSet::EMPTY, |s, &d| s.with(d))
    }

    /// This set with `dof` added.
    #[must_use]
    pub fn with(self, dof: Dof) -> DofSet {
        DofSet(self.0 | 1 << dof.index())
    }

    /// Whether `dof` is in the set.
    pub fn contains(self, dof: Dof) -> bool {
        self.0 & (1 << dof.index()) != 0
    }

    /// The DOFs in the set, in their order.
    pub fn iter(self) -> impl Iterator<Item = Dof> {
        Dof::ALL.into_iter().filter(move |&d| self.contains(d))
    }

    /// The DOFs not in the set, in their order.
    pub fn complement(self) -> DofSet {
        DofSet(!self.0 & 0b11_1111)
    }

    /// How many DOFs the set holds.
    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

/// The generalised coordinates `q = (x, y, z, roll, pitch, yaw)` (m and rad), their rates or
/// their second derivatives, or a generalised force (N and N·m per rad).
pub type Coords = Vector6<f64>;

/// The platen's rotation `R = Rz(yaw)·Ry(pitch)·Rx(roll)` at pose `q`.
pub fn rotation(q: &Coords) -> Rotation3<f64> {
    Rotation3::from_euler_angles(q[3], q[4], q[5])
}

/// The translation `(x, y, z)` of the reference point at pose `q`, m.
pub fn translation(q: &Coords) -> Vector3<f64> {
    Vector3::new(q[0], q[1], q[2])
}

/// The matrix `E(q)` with `ω = E·(roll′, pitch′, yaw′)`: the angular velocity in table axes
/// from the rates of the three angles. Its columns are the axes the three angles turn about:
/// `Rz·Ry·eₓ`, `Rz·e_y`, `e_z`. Singular at pitch = ±π/2 only (far outside any table's reach).
pub fn angular_rate_map(q: &Coords) -> Matrix3<f64> {
    let (sp, cp) = q[4].sin_cos();
    let (sy, cy) = q[5].sin_cos();
    Matrix3::new(cy * cp, -sy, 0.0, sy * cp, cy, 0.0, -sp, 0.0, 1.0)
}

/// `Ė·θ̇`: the part of the angular acceleration `ω̇ = E·θ̈ + Ė·θ̇` that the angle rates give
/// alone, rad/s².
pub fn angular_rate_bias(q: &Coords, qd: &Coords) -> Vector3<f64> {
    let (sp, cp) = q[4].sin_cos();
    let (sy, cy) = q[5].sin_cos();
    let (rd, pd, yd) = (qd[3], qd[4], qd[5]);
    // d/dt of the first column (cy·cp, sy·cp, −sp) times roll′, of the second (−sy, cy, 0)
    // times pitch′; the third is constant.
    Vector3::new(
        rd * (-sy * cp * yd - cy * sp * pd) - pd * cy * yd,
        rd * (cy * cp * yd - sy * sp * pd) - pd * sy * yd,
        -rd * cp * pd,
    )
}

/// The angular velocity in table axes at pose `q` with rates `qd`, rad/s.
pub fn angular_velocity(q: &Coords, qd: &Coords) -> Vector3<f64> {
    angular_rate_map(q) * Vector3::new(qd[3], qd[4], qd[5])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ω from `vee(Ṙ·Rᵀ)` with Ṙ by central differences: an independent route to E.
    #[test]
    fn the_rate_map_gives_the_angular_velocity_of_the_rotation() {
        let q = Coords::new(0.1, -0.2, 0.03, 0.15, -0.12, 0.19);
        let qd = Coords::new(0.5, 0.1, -0.2, 0.31, -0.27, 0.44);
        let h = 1e-6;
        let r = |s: f64| rotation(&(q + qd * s)).into_inner();
        let rdot = (r(h) - r(-h)) / (2.0 * h);
        let w = rdot * r(0.0).transpose();
        let vee = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        assert!((angular_velocity(&q, &qd) - vee).norm() < 1e-9, "{vee}");
        // And the bias: ω(t + h) − ω(t − h) over 2h with θ̈ = 0 is Ė·θ̇.
        let wd = (angular_velocity(&(q + qd * h), &qd) - angular_velocity(&(q - qd * h), &qd))
            / (2.0 * h);
        assert!((angular_rate_bias(&q, &qd) - wd).norm() < 1e-8);
    }

    #[test]
    fn names_round_trip_and_sets_count() {
        for d in Dof::ALL {
            assert_eq!(Dof::from_name(d.name()), Some(d));
        }
        assert_eq!(Dof::from_name("surge"), None);
        let held = DofSet::of(&[Dof::Y, Dof::Yaw]);
        assert_eq!(held.len(), 2);
        assert_eq!(held.complement().len(), 4);
        assert!(!held.complement().contains(Dof::Y));
    }
}
