//! Scenarios of a multi-axis (six-DOF) table: a scenario file with a `table` (see the
//! contract in `docs/multi-axis.md`). [`TableSpec`] is the key as written; [`TableScenario`]
//! the validated scenario and its run.
//!
//! What runs:
//! * the **inverse** of a prescribed six-DOF motion (`excitation.motion_csv` with `t_s` and
//!   any of `x_m` … `yaw_rad`, absent ones at 0, optional rates `x_m_s` … and accelerations
//!   `x_m_s2` …, derived from the pose where absent; or `excitation.ground_motion` per axis),
//!   with a storeys or general linear specimen;
//! * the **forward** run from recorded actuator forces (`excitation.force_csv`);
//! * the **closed loop** when the table has a `controller`: the same motion excitations are
//!   the DOF controller's command, and every actuator has its servo-valves.
//!
//! `{"preset": "lhpost6"}` lays the given values over the LHPOST6's (see `docs/lhpost6.md`).

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Unit, Vector3};
use serde::Serialize;

use platen_integrate::{
    forward_table_into, forward_table_loop_into, inverse_table_columns, inverse_table_into,
    table_columns, table_loop_columns, ActuatorForces, ForceRecord, IntegrateError, LoopMethod,
    Method, PoseMotion, TableLoopRun, TableLoopStats, TableRun, TableSink,
};
use platen_model::multi_axis::{
    Actuator, Bearing, BearingLoad, Coords, Dof, DofSet, LinearSpecimen, Mount, MultiAxisTable,
    Pad, RigidPlaten, Strut, TableParts,
};
use platen_model::ModelError;
use platen_system::{
    open_loop, ActuatorHydraulics, DofController, DofGeometry, SystemError, TableHydraulics,
    TableHydraulicsParts,
};

use crate::ctx::{check_finite, check_positive, value_at, Ctx};
use crate::error::{Result, ScenarioError};
use crate::excitation::MotionGenerator;
use crate::excitation::{motion_run, read_mapped, Derived};
use crate::file::{GroundMotionSpec, ScenarioFile};
use crate::scenario::Run;
use crate::system::{complete_servo_valve_under, controller_gains, loop_method_at, supply_under};
use crate::system_file::Overlay;
pub use crate::table_file::{
    ActuatorSpec, AxisLimitsSpec, BearingSpec, DofGainsSpec, PadSpec, PlatenSpec,
    RotationLimitSpec, StrutSpec, TableControllerSpec, TableSpec, TranslationLimitSpec,
};

mod build;
mod describe;
mod excitation;
mod peaks;
mod preset;
mod scenario;
mod summary;

use build::*;
pub use describe::*;
use excitation::*;
pub use peaks::*;
pub use preset::*;
pub use scenario::*;
pub use summary::*;

pub use crate::specimen::PLAUSIBLE_GEOMETRY_M;

/// The fastest a scenario's pose may move, m/s (rad/s for a rotation): shake tables reach a
/// few m/s, so a rate beyond is a unit slip (mm/s written as m/s), refused at its key.
pub const PLAUSIBLE_RATE_M_S: f64 = 100.0;
/// The largest acceleration a scenario's pose may have, m/s² (rad/s² for a rotation): about
/// 100 g, ten times any shake table's; beyond is a unit slip (mm/s² written as m/s²).
pub const PLAUSIBLE_ACCELERATION_M_S2: f64 = 1000.0;

/// Default oil bulk modulus, Pa.
pub const DEFAULT_OIL_BULK_MODULUS_PA: f64 = 1.5e9;
/// Default supply pressure, Pa (3 000 psi).
pub const DEFAULT_SUPPLY_PRESSURE_PA: f64 = 20.7e6;
/// Default return pressure, Pa.
pub const DEFAULT_RETURN_PRESSURE_PA: f64 = 0.5e6;

/// The pose columns of a six-DOF motion or run, x … yaw.
pub const POSE_COLUMNS: [&str; 6] = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"];
/// Their rates.
pub const RATE_COLUMNS: [&str; 6] = [
    "x_m_s",
    "y_m_s",
    "z_m_s",
    "roll_rad_s",
    "pitch_rad_s",
    "yaw_rad_s",
];
/// Their second derivatives.
pub const ACCELERATION_COLUMNS: [&str; 6] = [
    "x_m_s2",
    "y_m_s2",
    "z_m_s2",
    "roll_rad_s2",
    "pitch_rad_s2",
    "yaw_rad_s2",
];
