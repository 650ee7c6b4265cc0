//! Errors of identification: records that cannot be used, and settings out of range.

use platen_signal::SignalError;

/// Why a record or a setting was rejected.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentError {
    /// A record's channels do not fit together (lengths, non-finite values, sampling).
    #[error("test `{test}`: {message}")]
    InvalidRecord {
        /// The test's name (the file it came from, for the CLI).
        test: String,
        /// What is wrong.
        message: String,
    },
    /// A record in which no periodic motion can be found.
    #[error("test `{test}` is not a periodic test: {reason}")]
    NotPeriodic {
        /// The test's name.
        test: String,
        /// What was looked for and not found.
        reason: String,
    },
    /// A record too short to hold one full cycle of its own period.
    #[error(
        "test `{test}` holds no full cycle: period {period_s:.4} s, record {span_s:.4} s long; \
         the method needs at least one full cycle (the paper uses the second-to-last)"
    )]
    NoFullCycle {
        /// The test's name.
        test: String,
        /// The period found, s.
        period_s: f64,
        /// The record's length, s.
        span_s: f64,
    },
    /// A filter could not be designed for a record (a test frequency too high for its rate).
    #[error("test `{test}`: {source}")]
    Signal {
        /// The test's name.
        test: String,
        /// The filter's error.
        source: SignalError,
    },
    /// A setting out of range.
    #[error("setting `{name}` = {value} is invalid: expected {expected}")]
    InvalidSetting {
        /// The setting.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// What a valid value looks like.
        expected: &'static str,
    },
    /// Closed-loop records that cannot show the loop (`identify --system`): no drive, or a
    /// command that does not move the table.
    #[error("the table's loop cannot be identified from `{record}`: {reason}")]
    LoopNotIdentifiable {
        /// The record's name (the file it came from).
        record: String,
        /// Why, and what would make it identifiable.
        reason: String,
    },
    /// Nothing to identify from.
    #[error("no test records given: identification needs periodic sine and/or triangle tests")]
    NoTests,
}

/// Result alias of this crate.
pub type Result<T, E = IdentError> = std::result::Result<T, E>;
