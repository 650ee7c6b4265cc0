//! Integrators for the platen models of [`platen_model`], kept apart from the physics.
//!
//! * [`forward_rk4`]: a recorded or generated actuator force → displacement, velocity,
//!   acceleration and the force decomposition, with fixed-step RK4 and exact stick-slip
//!   (modes slip+, slip−, stick; `v = 0` located inside the step; breakaway solved exactly).
//! * [`inverse`]: a prescribed motion → the actuator force it needs and its decomposition.
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
//! regularised.

#![warn(missing_docs)]

pub mod baseline;
mod dopri5;
mod error;
mod inverse;
mod method;
mod output;
mod record;
mod rk4;

pub use dopri5::{forward_dopri5, Dopri5Settings};
pub use error::{IntegrateError, Result};
pub use inverse::inverse;
pub use method::{ForwardIntegrator, Method};
pub use output::{Exceedance, Peak, Peaks, Sample, SampleSink, Trajectory};
pub use record::{
    derivative, second_derivative, uniform_interval_s, ForceRecord, Motion,
    UNIFORM_RELATIVE_TOLERANCE,
};
pub use rk4::{forward_rk4, EnergyBalance, Rk4, RunStats, State};
