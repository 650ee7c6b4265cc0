//! A scenario run compared with a recorded test, channel by channel.
//!
//! * **Forward** scenarios (a force drives the model) compare the displacement `u_m` and the
//!   velocity `v_m_s` with the recorded file's columns; **inverse** scenarios (a motion drives
//!   the model) compare the actuator force `force_n` ([`Direction::channels`]). The scenario
//!   runs as it is, through [`PlatenScenario::run`](platen_scenario::PlatenScenario::run): its own
//!   excitation drives it (for a test, the recorded force or motion).
//! * A scenario with a specimen also compares the record's `base_shear_n`, `storey{i}_u_m` and
//!   `storey{i}_a_m_s2` where it has them ([`Channel::specimen_channels`]); a column for a
//!   storey the specimen lacks is [`CompareError::StoreyNotInSpecimen`].
//! * The record is read and checked (uniform sampling, coverage of the scenario's span within
//!   half a recorded sample interval at each end, the window inside the compared span)
//!   **before** anything is simulated, so a bad record fails fast.
//! * The two are aligned on the **recorded time base**: the simulated series is interpolated
//!   linearly onto the recorded samples that lie within the simulated span (exactly, where
//!   the time stamps coincide).
//! * Metrics are those of [`platen_signal::metrics`], over the whole compared span or the
//!   [`Settings::window`] (a bound within half a recorded sample interval outside the
//!   compared span is taken as the span's end).
//! * The recording itself is checked against the table's limits (the scenario's preset's,
//!   with its `limits` laid over): each of `u_m`, `v_m_s`, `a_m_s2`, `force_n` the file has,
//!   over the whole record ([`RecordedLimitCheck`], [`Comparison::recorded_limits`]).
//!
//! No figure is drawn here: `platen-report` draws them from a [`Comparison`].
//!
//! # Example
//!
//! ```
//! use std::path::Path;
//! use platen_compare::{Channel, Comparison, Settings};
//!
//! let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/sr9");
//! let c = Comparison::from_files(
//!     &root.join("sr9-forward.json"),
//!     &root.join("sr9-recorded.csv"),
//!     None,
//!     &Settings::default(),
//! )?;
//! assert_eq!(c.channels[0].channel, Channel::Displacement);
//! let nrmse = c.channels[0].metrics.nrmse.unwrap();
//! assert!(nrmse < 0.02, "{nrmse}");
//! let summary = c.summary(&[], None);
//! assert_eq!(summary.direction, "forward");
//! # Ok::<(), platen_compare::CompareError>(())
//! ```
//!
//! # Conventions
//!
//! * **Units**: SI everywhere (s, m, m/s, m/s², N), the unit in each field's name; a
//!   channel's values are in [`Channel::unit`].
//! * **Residual** (error) = **simulated − recorded**, on the recorded time base; NRMSE = RMS
//!   error / RMS of the recorded channel; peak ratio = |peak simulated| / |peak recorded|.
//! * **Lag** > 0 means the simulation is **late** (it lags the record); it is searched by
//!   cross-correlation within ±[`Settings::max_lag_s`].
//! * The recorded dissipative force is `F_A − F_I − F_E` of the recorded data under the
//!   scenario's model; a forward record without `force_n` uses the driving force instead, an
//!   inverse record without `u_m` the prescribed motion ([`Sources::notes`] says so).

mod channel;
mod comparison;
mod error;
mod limits;
mod recording;
mod settings;
mod summary;

pub use channel::{Channel, Direction};
pub use comparison::{ComparedChannel, Comparison, Quantities, Sources};
pub use error::{CompareError, Result};
pub use limits::{RecordedLimitCheck, TableLimit};
pub use recording::Recording;
pub use settings::{Settings, Window};
pub use summary::{ChannelSummary, Summary};
