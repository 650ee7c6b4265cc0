//! Every record accounted for: which method identified each record, whether it was used, and
//! why not. [`identify_any`] is what `platen identify` runs on a set of files: it routes each
//! record ([`crate::route`]), tries the periodic records on the paper's method and sends
//! those it rejects to the any-record method instead of losing them, runs both methods, and
//! returns one [`RecordAccount`] per input record, in input order.

use serde::Serialize;

use crate::anyrecord::result::{RecordIdentification, RecordWarning};
use crate::anyrecord::settings::ValidRecordSettings;
use crate::anyrecord::summary::{RecordInfoSummary, RecordSummary};
use crate::cycle::{self, RatePlan};
use crate::error::{IdentError, Result};
use crate::record::TestRecord;
use crate::result::Identification;
pub use crate::route::RecordAccount;
use crate::route::{route, Method, Route};
use crate::settings::ValidSettings;
use crate::summary::IdentificationSummary;

/// The method a front end asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MethodRequest {
    /// Each record by its data: periodic tests to the paper's method, the rest to the
    /// any-record method.
    #[default]
    Auto,
    /// The paper's method wherever the data allow it; a record that is not periodic, or that
    /// the periodic method rejects, falls back to the any-record method (with its reason).
    Periodic,
    /// The any-record method on every record, fitted jointly.
    Record,
    /// Periodic records through both methods, every record through the any-record method.
    Both,
}

/// The result of [`identify_any`].
#[derive(Debug, Clone)]
pub struct Identified {
    /// The paper's method on the periodic records, if any went there, with their indices in
    /// the input.
    pub periodic: Option<(Identification, Vec<usize>)>,
    /// The any-record method on the other records, if any went there (and it could run),
    /// with their indices in the input.
    pub records: Option<(RecordIdentification, Vec<usize>)>,
    /// One per input record, in input order.
    pub accounts: Vec<RecordAccount>,
}

impl Identified {
    /// Whether only the paper's method ran (every record a periodic test): the output is the
    /// periodic method's alone.
    pub fn periodic_only(&self) -> bool {
        self.records.is_none() && self.accounts.iter().all(|a| a.method == Method::Periodic)
    }
}

/// Routes and identifies `records`: see the module docs. `declared_record[k]` says the user
/// declared record `k` not a periodic test (a manifest's `"kind": "record"`).
///
/// # Errors
/// [`IdentError::NoTests`] for no records; the periodic method's errors on the records it
/// accepted; the any-record method's errors when it is the only method that could run (when
/// the periodic method ran, records the any-record method cannot use are reported unused
/// with its error as the reason).
pub fn identify_any(
    records: &[TestRecord],
    declared_record: &[bool],
    request: MethodRequest,
    settings: &ValidSettings,
    record_settings: &ValidRecordSettings,
) -> Result<Identified> {
    if records.is_empty() {
        return Err(IdentError::NoTests);
    }
    let (mut accounts, periodic_idx, record_idx) =
        route_all(records, declared_record, request, settings);
    let periodic = if periodic_idx.is_empty() {
        None
    } else {
        let recs: Vec<TestRecord> = periodic_idx.iter().map(|&k| records[k].clone()).collect();
        Some((crate::identify(&recs, settings)?, periodic_idx))
    };
    let records_id = if record_idx.is_empty() {
        None
    } else {
        let recs: Vec<TestRecord> = record_idx.iter().map(|&k| records[k].clone()).collect();
        match crate::identify_records(&recs, record_settings) {
            Ok(mut id) => {
                for &k in &record_idx {
                    let declared = declared_record.get(k).copied().unwrap_or(false);
                    if records[k].kind().is_some()
                        && !declared
                        && accounts[k].method == Method::Record
                    {
                        id.warnings.push(RecordWarning::DeclaredPeriodicButNot {
                            test: records[k].name().to_owned(),
                            reason: accounts[k].routing.clone(),
                        });
                    }
                }
                for (report, &k) in id.records.iter().zip(&record_idx) {
                    if report.used_samples == 0 && accounts[k].method == Method::Record {
                        accounts[k].used = false;
                        accounts[k].reason = Some(format!(
                            "no sample moves faster than {} m/s away from its ends: nothing to fit",
                            record_settings.min_speed_m_s
                        ));
                    }
                }
                Some((id, record_idx))
            }
            Err(e) if periodic.is_some() => {
                for &k in &record_idx {
                    if accounts[k].method == Method::Record {
                        accounts[k].used = false;
                        accounts[k].reason = Some(format!(
                            "the any-record method could not run on the records routed to it: {}",
                            cause(&e)
                        ));
                    }
                }
                None
            }
            Err(e) => return Err(e),
        }
    };
    Ok(Identified {
        periodic,
        records: records_id,
        accounts,
    })
}

/// Routes every record to its method (module docs): its account, and the records of each
/// method (with `Both`, every record goes to the any-record method too).
fn route_all(
    records: &[TestRecord],
    declared_record: &[bool],
    request: MethodRequest,
    settings: &ValidSettings,
) -> (Vec<RecordAccount>, Vec<usize>, Vec<usize>) {
    let mut accounts = Vec::with_capacity(records.len());
    let mut periodic_idx = Vec::new();
    let mut record_idx = Vec::new();
    let mut plans: Vec<RatePlan> = Vec::new();
    for (k, rec) in records.iter().enumerate() {
        let declared = declared_record.get(k).copied().unwrap_or(false);
        let r = if declared {
            Route::Record {
                reason: "declared a record (kind \"record\")".to_owned(),
            }
        } else {
            route(rec)
        };
        let mut account = RecordAccount {
            method: Method::Record,
            used: true,
            reason: None,
            routing: String::new(),
        };
        match (&r, request) {
            (_, MethodRequest::Record) => {
                account.routing = "the any-record method on every record (forced)".to_owned();
            }
            (Route::Record { reason }, _) => {
                account.routing = format!("not a periodic test: {reason}");
            }
            (Route::Periodic { frequency_hz }, _) => {
                match periodic_analysable(rec, settings, &mut plans) {
                    Ok(()) => {
                        account.method = Method::Periodic;
                        account.routing =
                            format!("a periodic test at {frequency_hz:.4} Hz (regular cycles)");
                        periodic_idx.push(k);
                    }
                    Err(e) => {
                        account.routing = format!(
                            "the periodic method rejected it ({}): identified by the any-record method instead",
                            cause(&e)
                        );
                    }
                }
            }
        }
        let to_record = account.method == Method::Record || request == MethodRequest::Both;
        if to_record {
            record_idx.push(k);
        }
        accounts.push(account);
    }
    (accounts, periodic_idx, record_idx)
}

/// Whether the paper's method can analyse `rec` alone (its cycle, filters and waveform).
fn periodic_analysable(
    rec: &TestRecord,
    settings: &ValidSettings,
    plans: &mut Vec<RatePlan>,
) -> Result<()> {
    let plan = RatePlan::for_record(plans, rec, settings)?;
    cycle::analyse(rec, &plans[plan], settings).map(|_| ())
}

/// The error's sentence without the record's name (the account belongs to the record).
fn cause(e: &IdentError) -> String {
    match e {
        IdentError::NotPeriodic { reason, .. } => reason.clone(),
        IdentError::InvalidRecord { message, .. } => message.clone(),
        other => other.to_string(),
    }
}

/// The machine-readable result of [`identify_any`]: what `platen identify --json` prints (less
/// the files it wrote) and `platen.identify` returns. Serialises as one flat object.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum IdentifyOutput {
    /// Every record a periodic test: the paper's method's summary, with the records' accounts.
    Periodic {
        /// The paper's method.
        #[serde(flatten)]
        summary: Box<IdentificationSummary>,
        /// Every input record, with what was done with it.
        records: Vec<RecordInfoSummary>,
    },
    /// The any-record method's summary (its `records` list every input record), with the
    /// paper's method on the periodic tests under `periodic`.
    Records {
        /// The any-record method.
        #[serde(flatten)]
        summary: Box<RecordSummary>,
        /// `record` (any-record method only), `mixed` (periodic tests by the paper's method
        /// too) or `both` (forced).
        method: &'static str,
        /// The paper's method on the periodic tests, when run.
        periodic: Option<Box<IdentificationSummary>>,
    },
}

impl Identified {
    /// The output of this identification of `records`, read from `files` (same order);
    /// `request` as given to [`identify_any`].
    pub fn output(
        &self,
        records: &[TestRecord],
        files: &[String],
        request: MethodRequest,
    ) -> IdentifyOutput {
        let entries = self.record_entries(records, files);
        let subset =
            |idx: &[usize]| -> Vec<String> { idx.iter().map(|&k| files[k].clone()).collect() };
        let periodic = self
            .periodic
            .as_ref()
            .map(|(p, idx)| Box::new(IdentificationSummary::new(p, &subset(idx))));
        match (&self.records, periodic) {
            (None, Some(summary)) if self.periodic_only() => IdentifyOutput::Periodic {
                summary,
                records: entries,
            },
            (Some((rid, idx)), periodic) => {
                let mut summary = RecordSummary::new(rid, &subset(idx));
                summary.records = entries;
                IdentifyOutput::Records {
                    summary: Box::new(summary),
                    method: match request {
                        MethodRequest::Both => "both",
                        _ if periodic.is_some() => "mixed",
                        _ => "record",
                    },
                    periodic,
                }
            }
            // The periodic method ran and the any-record method could not (its records are
            // accounted for as not used).
            (None, periodic) => IdentifyOutput::Periodic {
                summary: periodic.expect("identify_any ran at least one method"),
                records: entries,
            },
        }
    }
}

impl Identified {
    /// Every input record, in input order, with its account ([`identify_any`]): the
    /// any-record method's entries carry its per-record figures too. `files[k]` is where
    /// `records[k]` was read from.
    pub fn record_entries(
        &self,
        records: &[TestRecord],
        files: &[String],
    ) -> Vec<RecordInfoSummary> {
        let id = self;
        let mut fitted: Vec<Option<RecordInfoSummary>> = vec![None; records.len()];
        if let Some((rid, idx)) = &id.records {
            let sub_files: Vec<String> = idx.iter().map(|&k| files[k].clone()).collect();
            for (entry, &k) in RecordSummary::new(rid, &sub_files)
                .records
                .into_iter()
                .zip(idx)
            {
                fitted[k] = Some(entry);
            }
        }
        fitted
            .into_iter()
            .enumerate()
            .map(|(k, entry)| {
                let account = &id.accounts[k];
                match entry {
                    // A periodic record that also entered the any-record fit (`both`) keeps the
                    // any-record figures under its periodic account.
                    Some(mut e) => {
                        e.account = Some(account.clone());
                        e
                    }
                    None => RecordInfoSummary::accounted_only(&records[k], &files[k], account),
                }
            })
            .collect()
    }
}
