//! Errors raised when a filter or plan is built, or when a record does not fit it.

/// Why a signal-processing plan or a record was rejected.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SignalError {
    /// A real-valued parameter is non-finite or outside its range.
    #[error("parameter `{name}` = {value} is invalid: expected {expected}")]
    InvalidParameter {
        /// Name of the parameter (SI unit in the name).
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// What a valid value looks like.
        expected: &'static str,
    },
    /// An integer parameter (filter order, segment length, …) is outside its range.
    #[error("parameter `{name}` = {value} is invalid: expected {expected}")]
    InvalidCount {
        /// Name of the parameter.
        name: &'static str,
        /// The rejected value.
        value: usize,
        /// What a valid value looks like.
        expected: &'static str,
    },
    /// A cut-off frequency that is not strictly between 0 and the Nyquist frequency.
    #[error(
        "parameter `{name}` = {cutoff_hz} Hz is invalid: expected a frequency in (0, {nyquist_hz}) Hz, \
         i.e. above zero and below the Nyquist frequency of sample_rate_hz = {sample_rate_hz}"
    )]
    CutoffOutOfRange {
        /// Name of the parameter (`cutoff_hz`, `crossover_hz`, …).
        name: &'static str,
        /// The rejected cut-off, Hz.
        cutoff_hz: f64,
        /// The sample rate it was checked against, Hz.
        sample_rate_hz: f64,
        /// Half the sample rate, Hz.
        nyquist_hz: f64,
    },
    /// Two records that must have the same length do not.
    #[error("`{what}` has {found} samples: expected {expected}, the length of `{reference}`")]
    LengthMismatch {
        /// The record whose length is wrong.
        what: &'static str,
        /// The length it must have.
        expected: usize,
        /// The length it has.
        found: usize,
        /// The record (or plan) that fixes the expected length.
        reference: &'static str,
    },
    /// A record too short for the operation.
    #[error("`{what}` has {found} samples: expected at least {min}")]
    RecordTooShort {
        /// The record (and what it was needed for).
        what: &'static str,
        /// Its length.
        found: usize,
        /// The smallest length that works.
        min: usize,
    },
    /// The columns of a record (a [`Motion`](crate::Motion)) do not have the same length.
    #[error("record columns differ in length: {what} has {found} values, expected {expected}")]
    ColumnLengthMismatch {
        /// Which column.
        what: &'static str,
        /// Its length.
        found: usize,
        /// The length of the time column.
        expected: usize,
    },
    /// A record with a time column (a [`Motion`](crate::Motion)) has too few samples.
    #[error("record has {found} samples; at least {needed} are needed")]
    TooFewSamples {
        /// Samples present.
        found: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A value in a record is NaN or infinite.
    #[error("{what}[{index}] = {value} is not finite")]
    NonFiniteInput {
        /// Which column.
        what: &'static str,
        /// Zero-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A time column does not increase strictly.
    #[error("time is not strictly increasing at sample {index}: {previous_s} s then {value_s} s")]
    TimeNotIncreasing {
        /// Zero-based sample index.
        index: usize,
        /// The previous time, s.
        previous_s: f64,
        /// The offending time, s.
        value_s: f64,
    },
    /// A velocity dead band ([`Motion::with_rest_velocity`](crate::Motion::with_rest_velocity))
    /// that is not a finite positive number.
    #[error("rest_velocity_m_s = {value} is invalid: expected a finite velocity > 0 m/s")]
    InvalidRestVelocity {
        /// The value given, m/s.
        value: f64,
    },
    /// Two channels share too little coherent content for a delay estimate
    /// ([`crate::DelayEstimator`]).
    #[error(
        "only {bins} frequency bins have a coherence of at least {min_coherence}: a delay \
         estimate needs {min_bins} (the channels do not hold the same motion, or it is too small)"
    )]
    Incoherent {
        /// Coherent bins found.
        bins: usize,
        /// Bins needed.
        min_bins: usize,
        /// The coherence a bin needs.
        min_coherence: f64,
    },
}

/// Result alias of this crate.
pub type Result<T, E = SignalError> = std::result::Result<T, E>;

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(SignalError::InvalidParameter {
            name,
            value,
            expected: "a finite number > 0",
        })
    }
}

/// Checks that `cutoff_hz` is finite and strictly between 0 and `sample_rate_hz / 2`.
pub(crate) fn cutoff(name: &'static str, cutoff_hz: f64, sample_rate_hz: f64) -> Result<f64> {
    let nyquist_hz = 0.5 * sample_rate_hz;
    if cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < nyquist_hz {
        Ok(cutoff_hz)
    } else {
        Err(SignalError::CutoffOutOfRange {
            name,
            cutoff_hz,
            sample_rate_hz,
            nyquist_hz,
        })
    }
}

/// Checks that `output` has the length of `input`.
pub(crate) fn same_len(input: &[f64], output: &[f64]) -> Result<()> {
    if input.len() == output.len() {
        Ok(())
    } else {
        Err(SignalError::LengthMismatch {
            what: "output",
            expected: input.len(),
            found: output.len(),
            reference: "input",
        })
    }
}
