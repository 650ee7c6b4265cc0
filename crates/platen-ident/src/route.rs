//! Which method identifies a record: periodic tests go to the paper's hysteresis-loop method,
//! any other record to the any-record method.

use crate::error::IdentError;
use crate::record::TestRecord;

/// The identification method of a record, or forced for all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The paper's hysteresis-loop method ([`crate::identify`]): periodic tests only.
    Periodic,
    /// The any-record method ([`crate::identify_records`]).
    Record,
}

impl Method {
    /// `"periodic"` or `"record"`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Periodic => "periodic",
            Method::Record => "record",
        }
    }
}

/// Where a record goes without a forced method, and why.
#[derive(Debug, Clone, PartialEq)]
pub enum Route {
    /// A periodic test (regular zero crossings of the displacement): the paper's method.
    Periodic {
        /// Its fundamental frequency, Hz.
        frequency_hz: f64,
    },
    /// Any other record: the any-record method.
    Record {
        /// Why it is not a periodic test.
        reason: String,
    },
}

impl Route {
    /// The method of this route.
    pub fn method(&self) -> Method {
        match self {
            Route::Periodic { .. } => Method::Periodic,
            Route::Record { .. } => Method::Record,
        }
    }
}

/// Routes `record` by its data: periodic if its displacement crosses its mid-range at
/// regular intervals (three crossings at least, same-direction intervals within 10 % of the
/// mean period), else the any-record method. A declared kind ([`TestRecord::kind`]) plays
/// no part here: a record declared a sine whose data are not periodic is routed to the
/// any-record method (the caller may warn).
pub fn route(record: &TestRecord) -> Route {
    match crate::cycle::periodicity(record) {
        Ok(frequency_hz) => Route::Periodic { frequency_hz },
        Err(IdentError::NotPeriodic { reason, .. }) => Route::Record { reason },
        Err(other) => Route::Record {
            reason: other.to_string(),
        },
    }
}
