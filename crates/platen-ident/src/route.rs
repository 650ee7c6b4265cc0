//! Which method identifies a record: periodic tests go to the paper's hysteresis-loop method,
//! any other record to the any-record method.

use serde::Serialize;

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

#[cfg(test)]
mod tests {
    use super::*;

    fn record(u: Vec<f64>) -> TestRecord {
        let n = u.len();
        TestRecord::from_rate("r", 200.0, u, vec![0.0; n], vec![0.0; n]).unwrap()
    }

    #[test]
    fn a_sine_is_periodic_and_a_chirp_is_not() {
        let sine: Vec<f64> = (0..2000)
            .map(|i| (std::f64::consts::TAU * 1.0 * i as f64 / 200.0).sin())
            .collect();
        assert!(
            matches!(route(&record(sine)), Route::Periodic { frequency_hz }
            if (frequency_hz - 1.0).abs() < 0.01)
        );
        // Frequency doubling over the record: crossings at irregular intervals.
        let chirp: Vec<f64> = (0..2000)
            .map(|i| {
                let t = i as f64 / 200.0;
                (std::f64::consts::TAU * (0.5 * t + 0.1 * t * t)).sin()
            })
            .collect();
        let r = route(&record(chirp));
        assert_eq!(r.method(), Method::Record, "{r:?}");
    }
}

/// What identification did with one record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordAccount {
    /// `"periodic"` or `"record"`: the method that identified it (with
    /// [`crate::MethodRequest::Both`], a periodic record's is `"periodic"`; it enters the
    /// any-record fit too).
    #[serde(serialize_with = "method_name")]
    pub method: Method,
    /// Whether it entered the identification.
    pub used: bool,
    /// Why it was not used (`null` when used).
    pub reason: Option<String>,
    /// Why it went to its method: the periodic test's fundamental, why it is not a periodic
    /// test, or why the periodic method rejected it.
    pub routing: String,
}

fn method_name<S: serde::Serializer>(m: &Method, s: S) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_str(m.name())
}
