//! The errors of a comparison.

use std::path::PathBuf;

use platen_scenario::ScenarioError;
use platen_signal::SignalError;

use crate::Channel;

/// Why a comparison could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CompareError {
    /// The scenario, the column map or the record could not be read, or the run failed.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),

    /// The recording or a column map cannot be read.
    #[error(transparent)]
    Io(#[from] platen_io::IoError),

    /// The record does not cover the scenario's time span (within half its sample interval).
    #[error(
        "`{}` does not cover the scenario's time span: the record runs from {} s to {} s, \
         scenario `{}` from {} s to {} s; expected a record that starts no later than {} s \
         and ends no earlier than {} s (within half its sample interval, {tolerance_s} s)",
        recorded.display(),
        recorded_span_s.0,
        recorded_span_s.1,
        scenario.display(),
        simulated_span_s.0,
        simulated_span_s.1,
        simulated_span_s.0,
        simulated_span_s.1
    )]
    RecordTooShort {
        /// Recorded file.
        recorded: PathBuf,
        /// Scenario file.
        scenario: PathBuf,
        /// First and last recorded time, s.
        recorded_span_s: (f64, f64),
        /// First and last time of the run, s.
        simulated_span_s: (f64, f64),
        /// Half the recorded sample interval, s.
        tolerance_s: f64,
    },

    /// Fewer than two recorded samples lie within the scenario's span.
    #[error(
        "`{}` has {samples} sample(s) within the scenario's span {} s to {} s: a comparison \
         needs at least 2",
        recorded.display(),
        simulated_span_s.0,
        simulated_span_s.1
    )]
    TooFewRecordedSamples {
        /// Recorded file.
        recorded: PathBuf,
        /// Recorded samples within the span.
        samples: usize,
        /// First and last time of the run, s.
        simulated_span_s: (f64, f64),
    },

    /// The metrics window is not inside the compared span.
    #[error(
        "--window {},{} s is not inside the compared span {} s to {} s (the recorded samples \
         of `{}` within the scenario's span; a bound within half its sample interval, \
         {tolerance_s} s, outside the span is taken as the span's end)",
        window_s[0],
        window_s[1],
        compared_span_s.0,
        compared_span_s.1,
        recorded.display()
    )]
    WindowOutside {
        /// The window, s.
        window_s: [f64; 2],
        /// First and last compared recorded time, s.
        compared_span_s: (f64, f64),
        /// Recorded file.
        recorded: PathBuf,
        /// Half the recorded sample interval, s: how far outside the span a bound may lie.
        tolerance_s: f64,
    },

    /// The run produced fewer than two samples.
    #[error(
        "scenario `{}` produced {samples} sample(s): a comparison needs at least 2",
        scenario.display()
    )]
    TooFewSimulatedSamples {
        /// Scenario file.
        scenario: PathBuf,
        /// Samples produced.
        samples: usize,
    },

    /// The simulation could not be interpolated onto the recorded times.
    #[error("aligning the simulation on the record")]
    Align(#[source] SignalError),

    /// The record's sample rate is not usable.
    #[error("the record's sample rate")]
    SampleRate(#[source] SignalError),

    /// The metric settings (lag bound, window) are not usable.
    #[error(transparent)]
    Settings(SignalError),

    /// A channel the recording lacks could not be derived from the ones it has.
    #[error("`{}`: deriving the recorded {channel}", recorded.display())]
    Derived {
        /// The recorded file.
        recorded: PathBuf,
        /// The channel.
        channel: Channel,
        /// Why.
        #[source]
        source: SignalError,
    },

    /// The recording has a column for a storey the scenario's specimen does not have.
    #[error(
        "`{}` has a column `{column}` but the scenario's specimen has {storeys} storey(s): \
         expected storey columns storey1…storey{storeys} only",
        recorded.display()
    )]
    StoreyNotInSpecimen {
        /// Recorded file.
        recorded: PathBuf,
        /// The column.
        column: &'static str,
        /// Storeys of the specimen.
        storeys: usize,
    },

    /// The metrics of a channel could not be computed.
    #[error("comparing {channel}")]
    Metrics {
        /// The channel.
        channel: Channel,
        /// Why.
        #[source]
        source: SignalError,
    },
}

/// A result with a [`CompareError`].
pub type Result<T, E = CompareError> = std::result::Result<T, E>;
