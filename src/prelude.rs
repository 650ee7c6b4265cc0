//! What most programs need, in one `use platen::prelude::*;`: scenarios, the models and
//! their presets, records and motions, the integrators (whole runs and stepping), the table
//! system in closed loop, and the facade's [`Error`].
//!
//! A closed loop on the LHPOST, driven by a 5 cm, 0.5 Hz displacement command:
//!
//! ```
//! use platen::prelude::*;
//!
//! let model = preset::lhpost_2008_identified(13.8e6).build()?;
//! let system = platen::system::preset::lhpost_2008();
//! let t: Vec<f64> = (0..2049).map(|j| j as f64 / 1024.0).collect();
//! let u = t.iter().map(|t| 0.05 * (std::f64::consts::PI * t).sin()).collect();
//! let command = Motion::from_displacement(t, u)?;
//! let run = LoopRun { system: &system, specimen: None, command: &command,
//!     method: LoopMethod::Rk4 { steps_per_period: 7 }, initial: State::default() };
//! let mut out = Trajectory::default();
//! forward_closed_loop(&model, &run, command.len(), &mut out)?;
//! assert!((out.u_m.last().unwrap() - 0.0).abs() < 5e-3); // back near the centre at t = 2 s
//! # Ok::<(), platen::Error>(())
//! ```

pub use crate::{Error, Result};
pub use platen_integrate::{
    forward_closed_loop, forward_dopri5, forward_rk4, forward_specimen, inverse, Dopri5Settings,
    EventKind, ForceRecord, LoopMethod, LoopRun, Method, Motion, Rk4, RunStats, Sample, SampleSink,
    State, Step, Stepping, Trajectory,
};
pub use platen_model::{preset, IdentifiedModel, IdentifiedParams, PlatenModel, Specimen, Storey};
pub use platen_scenario::{simulate, PlatenScenario, RunResult, Scenario};
pub use platen_system::TableSystem;
