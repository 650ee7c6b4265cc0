//! Integrators for the platen models of [`platen_model`], kept apart from the physics.
//!
//! * [`forward_rk4`]: a recorded or generated actuator force → displacement, velocity,
//!   acceleration and the force decomposition, with fixed-step RK4 and exact stick-slip
//!   (modes slip+, slip−, stick; `v = 0` located inside the step; breakaway solved exactly).
//! * [`forward_rk4_ensemble`]: several such runs of the identified model (a sweep's cases)
//!   advanced together in SIMD lanes, bit for bit the runs of [`forward_rk4`].
//! * [`forward_dopri5`]: the same with adaptive Dormand–Prince 5(4) pieces.
//! * [`ForwardIntegrator`] and [`Method`]: one entry point for both, as a scenario selects it.
//! * [`inverse`]: a prescribed [`Motion`] → the actuator force it needs and its
//!   decomposition. The motion is `platen_signal`'s (re-exported here), so an acceleration
//!   record integrated there runs as it is; its checks' errors convert into
//!   [`IntegrateError`] with `?`.
//! * [`forward_specimen`] ([`forward_rk4_specimen`]): the platen carrying a shear-building
//!   specimen under a force record, with RK4 or Dopri5.
//! * [`forward_closed_loop`]: a displacement command → the table system's controller, valves
//!   and actuators ([`platen_system::TableSystem`]) → the platen (and a specimen), in closed
//!   loop, with RK4 or Dopri5.
//! * [`forward_table`] ([`forward_table_into`]): the multi-axis table under recorded actuator
//!   forces, with the bearings' exact planar stick-slip; [`inverse_table`] its inverse.
//! * [`forward_table_loop`] ([`forward_table_loop_into`]): a six-DOF command → the DOF
//!   controller, each actuator's valves and chambers → the multi-axis table, in closed loop.
//! * [`Stepping`]: a specimen or closed-loop run advanced a [`Step`] at a time (an event with
//!   its time and kind, a sample, the end), bit for bit the whole-record run.
//!
//! The bare platen's RK4, the specimen, the uniaxial closed loop and the multi-axis table
//! are *plants* of one mode machine (the friction modes, their events and resets, RK4 and
//! Dopri5 pieces, written once); a new plant plugs into it by saying its state, its rates per
//! mode, its net force and its clock (a force record's grid, or seconds), kept apart from
//! them. Both tables' closed loops are one driver (the controller's samples, the valves'
//! delay, the cuts of the grid, [`LoopStats`]) around their plants. The bare platen rests
//! exactly: nothing else moves while it sticks and the force is linear between samples, so
//! its breakaway and its creep are its own closed forms.
//!
//! Every plant's forward integrators share one event module (the friction modes, the `v = 0` root
//! finder, the stick decision and the exact breakaway; the [`EventKind`]s it counts in
//! [`RunStats`]), and say why a run stopped with a [`StopReason`]: `Finished` in the
//! [`RunStats`] of a run that returns, `Failed` with the time and the typed [`Failure`] from
//! [`IntegrateError::stop_reason`] of one that does not.
//!
//! ```
//! use platen_integrate::{forward_rk4, ForceRecord, Rk4, State, Trajectory};
//! use platen_model::preset;
//!
//! let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
//! // A constant 30 kN push: below the 37.5 kN static threshold, so the platen never moves.
//! let record = ForceRecord::from_rate(1024.0, vec![30e3; 1025]).unwrap();
//! let mut out = Trajectory::with_capacity(record.len());
//! let rk4 = Rk4::with_steps_per_sample(1).unwrap();
//! forward_rk4(&model, &record, rk4, State::default(), record.len(), &mut out).unwrap();
//! assert!(out.u_m.iter().all(|&u| u == 0.0));
//! ```
//!
//! # Conventions
//!
//! SI units; `u`, `v`, `a` positive along the actuator force. Output is delivered at the
//! input record's own sample times, one sample per input sample. The force of a record is
//! linear between samples. Friction at `v = 0` is set-valued and resolved exactly, never
//! regularised. Time inside a fixed-step run comes from an integer step counter,
//! `t = t₀ + n·h`, never from accumulated floats. A run never allocates per step; it
//! allocates only what its [`SampleSink`] (a multi-axis run's [`TableSink`]) stores. Samples before a failure have already been
//! delivered to the sink when the error returns.

#![warn(missing_docs)]

mod bare;
mod clock;
mod closed_loop;
mod control;
mod creep;
mod dopri5;
mod ensemble;
mod error;
mod event;
mod grid;
mod hysteretic;
mod inverse;
mod machine;
mod method;
mod multi_axis;
mod output;
mod record;
mod rk4;
mod run;
mod specimen;
mod steppable;
mod stepping;
mod stop;
mod table_forward;
mod table_loop;
mod table_plant;

pub use dopri5::{forward_dopri5, Dopri5Settings};
pub use ensemble::{forward_rk4_ensemble, forward_rk4_lanes, EnsembleCase, ENSEMBLE_LANES};
pub use error::{IntegrateError, Result};
pub use event::EventKind;
pub use hysteretic::StoreyEvent;
pub use inverse::{inverse, inverse_specimen, inverse_specimen_events, INVERSE_SPECIMEN_SUBSTEPS};
pub use method::{ForwardIntegrator, Method};
pub use multi_axis::{
    inverse_table, inverse_table_columns, inverse_table_into, PoseMotion, TableRun,
};
pub use output::{
    Exceedance, Peak, Peaks, Sample, SampleSink, SpecimenColumns, SpecimenSample, SystemColumns,
    SystemSample, TableSink, Trajectory,
};
// The prescribed motion of inverse and closed-loop runs, and the derivatives its
// constructors use, are platen-signal's; their errors convert into IntegrateError with `?`.
pub use closed_loop::{forward_closed_loop, LoopRun};
pub use control::{LoopMethod, LoopStats};
pub use platen_signal::{derivative, second_derivative, Motion};
pub use record::{
    sampling_grid, uniform_interval_s, ForceRecord, SamplingGrid, UNIFORM_RELATIVE_TOLERANCE,
};
pub use rk4::{forward_rk4, Rk4};
pub use run::{EnergyBalance, RunStats, State};
pub use specimen::{forward_rk4_specimen, forward_specimen};
pub use stepping::{Step, Stepping};
pub use stop::{AdaptiveFailure, Failure, StopReason};
pub use table_forward::{
    forward_table, forward_table_into, table_columns, table_kinetic_energy_j,
    table_potential_energy_j, ActuatorForces,
};
pub use table_loop::{
    forward_table_loop, forward_table_loop_into, table_loop_columns, TableLoopRun, TableLoopStats,
    MAX_LOOP_ACTUATORS, SPENT_GAS_FRACTION,
};
pub use table_plant::{MAX_TABLE_ACTUATORS, MAX_TABLE_SPECIMEN_DOFS};
