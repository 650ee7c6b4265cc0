//! The machine-readable summary of an any-record identification (`platen identify --json`
//! for records that are not periodic tests): serde types built from a
//! [`RecordIdentification`]. Non-finite numbers become `null` in JSON.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::record::TestRecord;
use crate::result::ParameterEstimates;
use crate::route::RecordAccount;
use crate::summary::{EstimateSummary, ParameterSummary};

use super::result::{
    BandPoint, Correlations, EquationErrorFit, FitUncertainty, OutputErrorFit,
    RecordIdentification, RecordReport,
};

/// The whole summary: the seven identified keys at the top level (the equation error's),
/// their uncertainties, both fits, the dissipative band, the records and the warnings.
#[derive(Debug, Clone, Serialize)]
pub struct RecordSummary {
    /// The seven keys' values.
    #[serde(flatten)]
    pub values: BTreeMap<&'static str, Option<f64>>,
    /// Each key's status and uncertainty.
    pub uncertainty: BTreeMap<&'static str, ParameterSummary>,
    /// The equation-error fit.
    pub equation_error: EquationErrorSummary,
    /// The output-error check, if run.
    pub output_error: Option<OutputErrorSummary>,
    /// `F_D(|v|)` with its pointwise 95 % band.
    pub dissipative_band: Vec<BandSummary>,
    /// Per record.
    pub records: Vec<RecordInfoSummary>,
    /// The warnings' sentences.
    pub warnings: Vec<String>,
}

fn values(p: &ParameterEstimates) -> BTreeMap<&'static str, Option<f64>> {
    p.iter().map(|(k, p)| (k.name(), p.value())).collect()
}

fn uncertainty(p: &ParameterEstimates) -> BTreeMap<&'static str, ParameterSummary> {
    p.iter()
        .map(|(k, p)| (k.name(), ParameterSummary::new(p)))
        .collect()
}

impl RecordSummary {
    /// The summary of `id`, whose records were read from `files` (same order).
    pub fn new(id: &RecordIdentification, files: &[String]) -> Self {
        Self {
            values: values(&id.parameters),
            uncertainty: uncertainty(&id.parameters),
            equation_error: EquationErrorSummary::new(&id.equation_error),
            output_error: id.output_error.as_ref().map(OutputErrorSummary::new),
            dissipative_band: id.band.iter().map(BandSummary::new).collect(),
            records: id
                .records
                .iter()
                .zip(files)
                .enumerate()
                .map(|(r, (rec, file))| RecordInfoSummary::new(rec, file, id, r))
                .collect(),
            warnings: id.warnings.iter().map(ToString::to_string).collect(),
        }
    }
}

/// Parameter correlations: `keys[i]` against `keys[j]` is `matrix[i][j]`.
#[derive(Debug, Clone, Serialize)]
pub struct CorrelationSummary {
    /// The estimated parameters' names.
    pub keys: Vec<&'static str>,
    /// The correlation matrix.
    pub matrix: Vec<Vec<f64>>,
}

impl CorrelationSummary {
    fn new(c: &Correlations) -> Self {
        Self {
            keys: c.keys.iter().map(|k| k.name()).collect(),
            matrix: c.matrix.clone(),
        }
    }
}

/// How a fit's uncertainty was computed.
#[derive(Debug, Clone, Serialize)]
pub struct UncertaintySummary {
    /// Parameter correlations.
    pub correlations: CorrelationSummary,
    /// Samples per block of the batch-means sandwich.
    pub block_samples: usize,
    /// Critical value of the 95 % intervals.
    pub critical_value: f64,
    /// Independent observations the residuals are worth.
    pub effective_samples: f64,
    /// Condition number of the scaled `JᵀJ`.
    pub condition_number: f64,
}

impl UncertaintySummary {
    fn new(u: &FitUncertainty) -> Self {
        Self {
            correlations: CorrelationSummary::new(&u.correlations),
            block_samples: u.bandwidth_samples,
            critical_value: u.critical_value,
            effective_samples: u.effective_samples,
            condition_number: u.condition_number,
        }
    }
}

/// The equation-error fit.
#[derive(Debug, Clone, Serialize)]
pub struct EquationErrorSummary {
    /// The seven keys' values.
    #[serde(flatten)]
    pub values: BTreeMap<&'static str, Option<f64>>,
    /// Each key's status and uncertainty.
    pub uncertainty: BTreeMap<&'static str, ParameterSummary>,
    /// How the uncertainty was computed, and the correlations.
    pub statistics: UncertaintySummary,
    /// RMS force residual, N.
    pub rms_residual_n: f64,
    /// Samples fitted.
    pub points: usize,
    /// Slowest speed fitted, m/s.
    pub min_speed_m_s: f64,
    /// Iterations over `(α, b)`.
    pub iterations: usize,
    /// Whether that search converged.
    pub converged: bool,
    /// Why that search stopped ([`EquationErrorFit::stop`]).
    pub stop: String,
    /// The nonlinear parameters held on a bound, by key, with why
    /// ([`EquationErrorFit::not_identified`]).
    pub not_identified: BTreeMap<&'static str, String>,
    /// How the channel-skew refits were made.
    pub skew_refits: SkewRefitsSummary,
}

/// How the channel-skew refits of the equation error were made.
#[derive(Debug, Clone, Serialize)]
pub struct SkewRefitsSummary {
    /// By Newton's method from the joint fit's expansions.
    pub newton: usize,
    /// By the search (passes over every record each).
    pub searched: usize,
}

impl EquationErrorSummary {
    fn new(f: &EquationErrorFit) -> Self {
        Self {
            values: values(&f.parameters),
            uncertainty: uncertainty(&f.parameters),
            statistics: UncertaintySummary::new(&f.uncertainty),
            rms_residual_n: f.rms_residual_n,
            points: f.points,
            min_speed_m_s: f.min_speed_m_s,
            iterations: f.iterations,
            converged: f.converged,
            stop: f.stop.clone(),
            not_identified: f
                .not_identified
                .iter()
                .map(|(k, why)| (k.name(), why.clone()))
                .collect(),
            skew_refits: SkewRefitsSummary {
                newton: f.skew_refits_newton,
                searched: f.skew_refits_searched,
            },
        }
    }
}

/// The output-error check.
#[derive(Debug, Clone, Serialize)]
pub struct OutputErrorSummary {
    /// The seven keys' values.
    #[serde(flatten)]
    pub values: BTreeMap<&'static str, Option<f64>>,
    /// Each key's status and uncertainty.
    pub uncertainty: BTreeMap<&'static str, ParameterSummary>,
    /// How the uncertainty was computed, and the correlations.
    pub statistics: UncertaintySummary,
    /// Per record: RMS displacement residual at the start and at the end, m.
    pub rms_u_m: Vec<[f64; 2]>,
    /// Per record: RMS acceleration residual at the start and at the end, m/s².
    pub rms_a_m_s2: Vec<[f64; 2]>,
    /// Iterations.
    pub iterations: usize,
    /// Whether it converged.
    pub converged: bool,
    /// Forward runs of a record (a run of every record counts one per record).
    pub simulations: usize,
}

impl OutputErrorSummary {
    fn new(f: &OutputErrorFit) -> Self {
        Self {
            values: values(&f.parameters),
            uncertainty: uncertainty(&f.parameters),
            statistics: UncertaintySummary::new(&f.uncertainty),
            rms_u_m: f.rms_u_m.clone(),
            rms_a_m_s2: f.rms_a_m_s2.clone(),
            iterations: f.iterations,
            converged: f.converged,
            simulations: f.simulations,
        }
    }
}

/// One point of the band.
#[derive(Debug, Clone, Serialize)]
pub struct BandSummary {
    /// Speed, m/s.
    pub speed_m_s: f64,
    /// `F_D`, N.
    pub force_n: f64,
    /// The pointwise 95 % band, N.
    pub ci95: [f64; 2],
}

impl BandSummary {
    fn new(p: &BandPoint) -> Self {
        Self {
            speed_m_s: p.speed_m_s,
            force_n: p.force_n,
            ci95: [p.low_n, p.high_n],
        }
    }
}

/// One record: what identification did with it (every input file has one, whichever method
/// identified it) and, for the any-record method, what it fitted.
#[derive(Debug, Clone, Serialize)]
pub struct RecordInfoSummary {
    /// The file it was read from.
    pub file: String,
    /// Its name.
    pub name: String,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Samples.
    pub samples: usize,
    /// What identification did with it: `method`, `used`, `reason` (when not used) and
    /// `routing` (why that method).
    #[serde(flatten)]
    pub account: Option<RecordAccount>,
    /// `given` or `crossover` (any-record method).
    pub velocity: Option<&'static str>,
    /// Samples fitted by the equation error (any-record method).
    pub used_samples: Option<usize>,
    /// Speeds fitted, m/s (any-record method).
    pub speed_range_m_s: Option<[f64; 2]>,
    /// The force offset, N.
    pub offset_n: Option<EstimateSummary>,
    /// The effective mass this record alone gives, kg, the other parameters held at the
    /// joint fit's (any-record method; records of one table agree).
    pub mass_alone_kg: Option<f64>,
    /// Its standard error, kg (`null` where not estimated: a record of fewer than two
    /// blocks of 400 samples, or not fitted by the any-record method).
    pub mass_alone_std_error_kg: Option<f64>,
    /// The share of the record's force its inertia makes (`null` when not fitted by the
    /// any-record method): its mass alone is judged from one half.
    pub mass_alone_inertial_share: Option<f64>,
    /// The storeys' masses whose base shear was removed, kg.
    pub floor_masses_kg: Option<Vec<f64>>,
    /// Largest base shear removed, N.
    pub peak_base_shear_n: Option<f64>,
    /// Each channel's delay against the displacement, s: the acceleration's as estimated,
    /// and any given with the record. Positive: the channel lags `u_m`. The any-record method
    /// corrects a given delay, and an estimated one when significant; for a record it did not
    /// fit (a periodic test) the delays are reported only.
    pub channel_delay_s: Option<BTreeMap<&'static str, f64>>,
}

impl RecordInfoSummary {
    fn new(r: &RecordReport, file: &str, id: &RecordIdentification, index: usize) -> Self {
        Self {
            file: file.to_owned(),
            name: r.name.clone(),
            sample_rate_hz: r.sample_rate_hz,
            samples: r.samples,
            account: None,
            velocity: Some(if r.velocity_given {
                "given"
            } else {
                "crossover"
            }),
            used_samples: Some(r.used_samples),
            speed_range_m_s: Some(r.speed_range_m_s),
            offset_n: id
                .equation_error
                .offsets_n
                .get(index)
                .map(EstimateSummary::new),
            mass_alone_kg: r.mass_alone_kg,
            mass_alone_std_error_kg: r.mass_alone_std_error_kg.filter(|se| se.is_finite()),
            mass_alone_inertial_share: r.mass_alone_inertial_share,
            floor_masses_kg: r.floors.as_ref().map(|f| f.masses_kg.clone()),
            peak_base_shear_n: r.floors.as_ref().map(|f| f.peak_base_shear_n),
            channel_delay_s: Some(
                r.channel_delays
                    .iter()
                    .map(|d| (d.column, d.delay_s))
                    .collect(),
            ),
        }
    }
}

impl RecordInfoSummary {
    /// A record the any-record method did not fit (a periodic test, or one it could not
    /// use): its file, name, rate and account.
    pub(crate) fn accounted_only(rec: &TestRecord, file: &str, account: &RecordAccount) -> Self {
        Self {
            file: file.to_owned(),
            name: rec.name().to_owned(),
            sample_rate_hz: rec.sample_rate_hz(),
            samples: rec.len(),
            account: Some(account.clone()),
            velocity: None,
            used_samples: None,
            speed_range_m_s: None,
            offset_n: None,
            mass_alone_kg: None,
            mass_alone_std_error_kg: None,
            mass_alone_inertial_share: None,
            floor_masses_kg: None,
            peak_base_shear_n: None,
            channel_delay_s: Some(
                super::skew::delays_of(rec)
                    .iter()
                    .map(|d| (d.column, d.delay_s))
                    .collect(),
            ),
        }
    }
}
