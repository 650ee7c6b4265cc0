//! Test planning on a simulated shake table: can the table run this target, what limits it
//! and what scale fits, and which drive makes the table reproduce it. Physics-free: every
//! answer comes from running a rig's closed loop ([`platen_scenario::Rig`]: its model,
//! `table_system` and specimen) with displacement commands.
//!
//! One entry for every table ([`plan()`](fn@plan)): a scenario read for planning
//! ([`PlanScenario`], uniaxial or multi-axis), its target ([`PlanTarget`]), the settings
//! ([`PlanSettings`]), the plan ([`Planned`]) and its summary ([`PlannedSummary`]). From a
//! scenario file and a target CSV, as `platen plan` does, writing the drive:
//!
//! ```no_run
//! use std::path::Path;
//! use platen_io::columns::ColumnMap;
//! use platen_io::csv::CsvWriter;
//! use platen_plan::{plan, PlanScenario, PlanSettings, PlanTarget};
//!
//! // Uniaxial (a `table_system`) or multi-axis (a `table`): the same path. Its excitation is
//! // ignored.
//! let path = Path::new("scenarios/table-system/northridge-closed-loop.json");
//! let scenario = PlanScenario::load(path)?;
//! // t_s and a_m_s2 (or u_m); on a multi-axis table x_m_s2, y_m_s2, z_m_s2.
//! let target = PlanTarget::read_csv(&scenario, Path::new("target.csv"), &ColumnMap::default())?;
//! let settings = PlanSettings::with_max_scale();
//! let p = plan(&scenario, &target, &settings, &mut |_| {})?;
//! let writer = CsvWriter::create(Path::new("drive.csv"), scenario.drive_columns())?;
//! let written = p.write_drive_rows(writer)?;
//! let summary = p.summary(&settings, written.then_some(Path::new("drive.csv")));
//! println!("{}", serde_json::to_string_pretty(&summary).unwrap());
//! # Ok::<(), platen_plan::PlanError>(())
//! ```
//!
//! A 2 Hz, 2 m/s² sine planned on a uniaxial table built in memory (the `lhpost-2008`
//! platen and table system) with the uniaxial planner [`plan_platen`], which
//! [`plan()`](fn@plan) calls for such a scenario:
//!
//! ```
//! use std::path::Path;
//! use platen_plan::{plan_platen, PlanSettings, PlatenLoop, Target};
//!
//! let json = r#"{"model": {"preset": "lhpost-2008"}, "table_system": {"preset": "lhpost-2008"}}"#;
//! let rig = platen_scenario::LoadedRig::parse(Path::new("lhpost.json"), json)?;
//! let table = PlatenLoop::of_loaded(&rig, Path::new("lhpost.json"))?;
//! let t: Vec<f64> = (0..4097).map(|j| j as f64 / 1024.0).collect(); // 4 s at 1024 Hz
//! let a = t.iter().map(|t| 2.0 * (std::f64::consts::TAU * 2.0 * t).sin()).collect();
//! let target = Target::acceleration(Path::new("sine"), t, a)?;
//! let p = plan_platen(&table, &rig.name, Path::new("lhpost.json"), &target,
//!                     &PlanSettings::default(), &mut |_| {})?;
//! let best = p.iteration().unwrap().best_record();
//! assert!(p.feasibility.feasible && best.acceleration_nrmse < 0.1);
//! if let Some(it) = p.iteration() {
//!     for r in &it.records {
//!         println!("{}: acceleration NRMSE {:.3}", r.iteration, r.acceleration_nrmse);
//!     }
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # What is here
//!
//! * [`Target`]: the target (acceleration or displacement, uniform time base), validated.
//! * [`TargetMotion`] ([`baseline`]): the displacement command of a target, integrated from
//!   an acceleration with a baseline treatment that starts and ends at rest and keeps the
//!   displacement as small as a polynomial correction can.
//! * [`PlatenLoop`]: a rig's closed loop driven by any command ([`Achieved`]).
//! * [`feasibility()`](feasibility::feasibility), [`max_scale`] ([`feasibility`]): peaks and
//!   margins of stroke, velocity, acceleration, actuator force, valve flow and supply
//!   pressure; the limits that fail; the largest scale that fits, by bisection on the
//!   simulated loop.
//! * [`FrequencyResponse`] ([`frf`]): the loop's `Ĥ`, linearised or measured with white
//!   noise.
//! * [`iterate()`](fn@iterate), [`iterate_with`] ([`mod@iterate`]): offline drive iteration
//!   `D_{k+1} = D_k + g·Ĥ⁻¹(T − R_k)` with a regularised inverse in a band, and its stop
//!   criteria; written once for any number of coupled axes ([`iterate_axes`],
//!   [`iterate_mimo`], [`DriveCorrection`]), one axis being the case `p = 1`.
//! * [`plan()`](fn@plan) ([`mod@entry`]): all of it, for every table, with the summary
//!   `platen plan --json` prints ([`PlannedSummary`]); the uniaxial table's plan
//!   [`plan_platen`] ([`Plan`]), the multi-axis table's [`plan_multi_axis`] ([`six_dof`],
//!   [`TablePlan`]), the steps they share written once.
//!
//! # Conventions
//!
//! SI units, unit in every name. The drive is a displacement command at the target's time
//! stamps; its velocity and acceleration are derived exactly as `simulate` derives them from a
//! `motion_csv` holding `t_s` and `u_m` ([`command_motion`]), so a drive written to CSV and
//! replayed through `simulate` is the run the plan reports. Everything is deterministic: the
//! same inputs give the same bytes.

#![warn(missing_docs)]

mod acceptance;
pub mod baseline;
mod correction;
pub mod entry;
mod error;
pub mod feasibility;
pub mod frf;
pub mod iterate;
pub mod mimo;
mod plan;
mod platen_loop;
pub mod rrs;
mod settings;
pub mod six_dof;
mod steps;
mod target;

pub use baseline::{command_motion, BaselineSettings, EndCorrection, TargetMotion};
pub use entry::{plan, PlanScenario, PlanTarget, Planned, PlannedSummary};
pub use error::{PlanError, Result};
pub use feasibility::{
    max_scale, search_max_scale, Feasibility, LimitUse, MaxScale, MaxScaleSettings,
};
pub use frf::{FrequencyResponse, FrfSource, NoiseSettings};
pub use iterate::{
    iterate, iterate_axes, iterate_observed, iterate_with, spectrum_acceptance, Correction,
    DriveCorrection, Iteration, IterationRecord, IterationSettings, Response, SpectrumAcceptance,
    SpectrumMiss, Stop, TransferMatrix, ACCEPTANCE_BAND,
};
pub use mimo::{iterate_mimo, AxisRecord, AxisTarget, MimoIteration, MimoRecord};
pub use plan::{
    load_rig, plan_platen, write_drive, DriveSummary, FrfSummary, Plan, PlanSettings, PlanSummary,
    PlannedDrive, TargetSummary, UNIAXIAL_DRIVE_COLUMNS,
};
pub use platen_loop::{Achieved, PlatenLoop};
pub use rrs::{RequiredSpectrum, DEFAULT_RRS_DAMPING};
pub use six_dof::{
    plan_multi_axis, pose_command, AxisTargets, TableAchieved, TableFeasibility, TableIteratedAt,
    TableLimitUse, TablePlan, TablePlannedDrive, TablePlant,
};
pub use steps::{IteratedAt, SCALED_UP_ERROR_WARNED};

/// The name [`PlatenLoop`] had before the words were settled (`docs/library.md`: "table"
/// names a multi-axis table, "platen" the uniaxial one).
#[deprecated(note = "renamed PlatenLoop: the uniaxial platen's closed loop")]
pub type Table<'a> = PlatenLoop<'a>;
pub use target::{
    enveloped_sines_m_s2, synthetic_three_component_m_s2, Target, TargetKind, MIN_TARGET_SAMPLES,
};
