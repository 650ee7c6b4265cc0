//! The multi-axis (six-DOF) platen: a rigid body on actuators, hold-down struts and bearings.
//! Physics only: kinematics at a pose, Newton–Euler, the force resolution of redundant
//! actuators and the modes at neutral. The integrators step it in `platen-integrate`.
//!
//! # Conventions
//!
//! * Axes: x longitudinal (the uniaxial table's axis), y transverse, z up. The reference point
//!   is the centre of the platen's top surface at the neutral pose.
//! * The pose `q = (x, y, z, roll, pitch, yaw)` ([`Coords`]): the reference point moves by
//!   `t = (x, y, z)` m and the platen turns by `R = Rz(yaw)·Ry(pitch)·Rx(roll)` rad
//!   (nalgebra's `Rotation3::from_euler_angles(roll, pitch, yaw)`). A platen point `p`
//!   (platen frame, from the reference point) is at `t + R·p`. Exact kinematics, no
//!   small-angle approximation.
//! * Rates `q̇` are the rates of the six coordinates; the angular velocity in table axes is
//!   `ω = E(q)·θ̇` ([`angular_rate_map`]).
//! * Wrenches ([`Wrench`]) are (force, moment) in table axes about the *current* reference
//!   point `t`; generalised forces (per metre and per radian of the coordinates) are
//!   `Q = Jᵀ·W` with `J = diag(I, E)`.
//! * Gravity `g = 9.80665 m/s²` along −z.
//! * An actuator's force is positive when it pushes the platen away from its base (swivel)
//!   or along its axis (pad); a strut's pull `p·A` is positive and draws the platen towards
//!   its base.

mod capacity;
mod dof;
mod friction;
mod modes;
mod specimen;
mod table;

pub use capacity::AxisCapacity;
pub use dof::{
    angular_rate_bias, angular_rate_map, angular_velocity, rotation, translation, Coords, Dof,
    DofSet,
};
pub use friction::{
    planar_rate, Contact, ContactLoad, FrictionCapacity, InverseSample, PlanarRate, Stick,
};
pub use modes::Mode;
pub use specimen::{LinearSpecimen, MAX_SPECIMEN_DOFS};
pub use table::{
    Actuator, ActuatorPose, Bearing, BearingLoad, Frame, Kinematics, Mount, MultiAxisTable, Pad,
    Point, RigidPlaten, Strut, StrutPose, TableParts, Wrench, MAX_GEOMETRY_M, RESERVED_NAMES,
};
