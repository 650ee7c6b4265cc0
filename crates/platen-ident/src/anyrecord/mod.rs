//! Identification from any test record (earthquake, white noise, periodic): equation error
//! by separable least squares, refined by output error, with uncertainties that account for
//! serially correlated residuals.
//!
//! See [`identify_records`].

mod data;
mod hac;
mod output_error;
mod plausible;
mod refit;
mod reports;
pub(crate) mod result;
mod separable;
pub(crate) mod settings;
mod skew;
pub mod summary;

pub use crate::record::DELAYABLE_CHANNELS;
pub use reports::{INERTIAL_SHARE_JUDGED, MASS_DETERMINED, MASS_SPREAD_WARNED};
pub use skew::{ChannelDelay, MIN_APPLIED_SAMPLES, SIGNIFICANT};

use nalgebra::DMatrix;
use platen_model::{DissipativeLaw, Exponent, IdentifiedKey};

use crate::error::{IdentError, Result};
use crate::estimate::{Estimate, Parameter};
use crate::record::TestRecord;
use crate::result::ParameterEstimates;

use data::{prepare, Block, Prepared, Stacked};
use hac::Hac;
use output_error::OutputError;
use refit::{Refit, Refits};
use reports::{record_reports, reports_disagreement};
use result::{
    BandPoint, Correlations, EquationErrorFit, FitKind, FitUncertainty, OutputErrorFit,
    RecordIdentification, RecordWarning,
};
use separable::{Separable, SeparableFit, Shape, LOW_DECAY, LOW_FORCE, OFFSETS, STIFFNESS};
use settings::ValidRecordSettings;

/// Estimates correlated beyond this (in absolute value) are reported as not separable
/// ([`RecordWarning::NotSeparable`]): at 0.95 the variance of either alone is ten times what
/// it would be with the other known.
pub const MAX_CORRELATION: f64 = 0.95;

/// A parameter whose standard error exceeds this fraction of its value is reported as
/// poorly determined ([`RecordWarning::Imprecise`]).
pub const MAX_RELATIVE_STD_ERROR: f64 = 0.1;

/// Fewer than this fraction of the fitted samples below `3/b` draws
/// [`RecordWarning::FewLowSpeedSamples`].
pub const MIN_LOW_SPEED_FRACTION: f64 = 0.02;

/// Largest relative difference between the equation-error and output-error estimates of a
/// parameter before [`RecordWarning::FitsDisagree`] (when also beyond three combined
/// standard errors): 2 % for mass and stiffness, 5 % for `F_μ` and `Cₑ`, 0.05 (absolute)
/// for `α`, 20 % for the low-velocity term, which the two fits see differently (the equation
/// error only above its minimum speed).
pub fn fit_agreement(key: IdentifiedKey) -> f64 {
    match key {
        IdentifiedKey::EffectiveMass | IdentifiedKey::Stiffness => 0.02,
        IdentifiedKey::CoulombForce | IdentifiedKey::ViscousCoefficient => 0.05,
        IdentifiedKey::ViscousExponent => 0.05,
        IdentifiedKey::LowVelocityForce | IdentifiedKey::LowVelocityDecay => 0.2,
    }
}

/// Full-vector index of each key.
fn index(key: IdentifiedKey) -> usize {
    match key {
        IdentifiedKey::EffectiveMass => 0,
        IdentifiedKey::Stiffness => 1,
        IdentifiedKey::CoulombForce => 2,
        IdentifiedKey::ViscousCoefficient => 3,
        IdentifiedKey::ViscousExponent => 4,
        IdentifiedKey::LowVelocityForce => 5,
        IdentifiedKey::LowVelocityDecay => 6,
    }
}

/// Identifies the platen's parameters from any records (see the crate docs, "Any record").
///
/// All records are fitted jointly: one set of the seven parameters, one force offset per
/// record. Records with floor accelerations have had the base shear removed from their force
/// ([`TestRecord::with_floors`]).
///
/// # Errors
/// [`IdentError::NoTests`] for no records; [`IdentError::InvalidRecord`] if the records hold
/// too few samples faster than the minimum speed; [`IdentError::Signal`] if the crossover
/// filter cannot be made for a record's rate.
pub fn identify_records(
    records: &[TestRecord],
    settings: &ValidRecordSettings,
) -> Result<RecordIdentification> {
    if records.is_empty() {
        return Err(IdentError::NoTests);
    }
    // Channel skew (module `skew`): from here on the records are the corrected ones.
    let corrected = skew::correct(records)?;
    let records = corrected.records.as_slice();
    let prepared = prepare(records, settings)?;
    let data = Stacked::new(records, &prepared);
    let mut shape = Shape::of(settings, records.len());
    enough_points(&data, &shape, records, settings)?;
    let mut warnings = Vec::new();
    let (fit, mut hac, low_dropped) = fit_with_low_term(&data, &mut shape, &mut warnings);
    let skew_refits = skew_covariance(&mut hac, &fit, shape, &data, &corrected, settings)?;
    let clamped = fit.clamped.clone();
    let fixed_reason = |key: IdentifiedKey| fixed_reason(key, &clamped, low_dropped.is_some());
    let free = fit.free.clone();
    let (ee_params, ee_corr) = parameters(&fit.full, &free, &hac, &fixed_reason);
    let speeds = speed_range(&data);
    ee_warnings(
        &fit,
        &hac,
        &free,
        &ee_params,
        &ee_corr,
        &data,
        settings,
        speeds,
        &mut warnings,
    );
    let equation_error = equation_error_fit(
        &fit,
        &hac,
        (ee_params.clone(), ee_corr),
        &data,
        settings,
        skew_refits,
    );
    let (simulated, output_error) = output_error_check(
        records,
        &prepared,
        (&fit.full, &free),
        &ee_params,
        settings,
        &fixed_reason,
        &mut warnings,
    );
    plausible::check(
        &ee_params,
        output_error.as_ref().map(|oe| &oe.parameters),
        fit.clamped.contains(&STIFFNESS),
        &fit.full,
        records,
        &mut warnings,
    );
    let band = band(
        &fit.full,
        &(free.clone(), hac.cov_estimable.clone(), hac.critical_value),
        speeds,
        settings.band_points,
    );
    let reports = record_reports(records, &prepared, &fit, simulated, corrected.delays);
    warnings.extend(reports_disagreement(&reports, fit.full[0]));
    Ok(RecordIdentification {
        parameters: ee_params,
        equation_error,
        output_error,
        law: fitted_law(&fit.full),
        band,
        records: reports,
        warnings,
    })
}

/// Why a parameter is not estimated: at its bound (`clamped`, full-vector indices), the
/// exponent held at the value given, the low-velocity term left out (`low_dropped`) or off.
fn fixed_reason(key: IdentifiedKey, clamped: &[usize], low_dropped: bool) -> String {
    match key {
        _ if clamped.contains(&index(key)) => {
            "at its bound (0): a negative value fits this record better".to_owned()
        }
        IdentifiedKey::ViscousExponent => "held at the value given".to_owned(),
        _ if low_dropped => {
            "left out: the low-velocity term is not significant in this record".to_owned()
        }
        _ => "not fitted (low-velocity term off)".to_owned(),
    }
}

/// The equation-error fit's report: `fit` with its covariance `hac`, the parameters and
/// their correlations (`ee`), each record's offset, the residual over `data` and the skew
/// refits made (`[Newton, search]`).
fn equation_error_fit(
    fit: &SeparableFit,
    hac: &Hac,
    (parameters, correlations): (ParameterEstimates, Correlations),
    data: &Stacked,
    settings: &ValidRecordSettings,
    skew_refits: [usize; 2],
) -> EquationErrorFit {
    let free = &fit.free;
    let offsets_n = (0..fit.full.len() - OFFSETS)
        .map(|r| {
            let k = free_position(free, OFFSETS + r);
            estimate(fit.full[OFFSETS + r], hac.cov[(k, k)], hac, free.len())
        })
        .collect();
    EquationErrorFit {
        parameters,
        offsets_n,
        uncertainty: uncertainty(hac, correlations),
        rms_residual_n: (fit.residual.iter().map(|r| r * r).sum::<f64>() / data.len() as f64)
            .sqrt(),
        points: data.len(),
        min_speed_m_s: settings.min_speed_m_s,
        iterations: fit.iterations,
        converged: fit.converged,
        stop: stop_name(fit.stop).to_owned(),
        not_identified: fit
            .held
            .iter()
            .map(|&i| {
                let key = IdentifiedKey::ALL[i];
                (key, held_reason(key, fit.full[i]))
            })
            .collect(),
        skew_refits_newton: skew_refits[0],
        skew_refits_searched: skew_refits[1],
    }
}

/// The any-record method needs ten points per free parameter and two more.
fn enough_points(
    data: &Stacked,
    shape: &Shape,
    records: &[TestRecord],
    settings: &ValidRecordSettings,
) -> Result<()> {
    let needed = 10 * (shape.free().len() + 2);
    if data.len() < needed {
        return Err(IdentError::InvalidRecord {
            test: records[0].name().to_owned(),
            message: format!(
                "{} samples move faster than {} m/s over all records; the any-record method needs at least {needed}",
                data.len(),
                settings.min_speed_m_s
            ),
        });
    }
    Ok(())
}

/// The equation-error fit with its covariance; a low-velocity term that the fit clamps at
/// its bound is left out (with a warning) and the fit made again without it. Returns the
/// fit, its covariance and the term left out (its force and standard error), if any.
fn fit_with_low_term(
    data: &Stacked,
    shape: &mut Shape,
    warnings: &mut Vec<RecordWarning>,
) -> (SeparableFit, Hac, Option<(f64, f64)>) {
    let mut fit = Separable::new(data, *shape).fit();
    let mut hac = ee_covariance(&fit, data);
    let mut low_dropped = None;
    if shape.low {
        let (a, se) = match fit.free.iter().position(|&i| i == LOW_FORCE) {
            Some(k) => (fit.full[LOW_FORCE], hac.cov[(k, k)].sqrt()),
            None => (0.0, f64::NAN),
        };
        if fit.clamped.contains(&LOW_FORCE) {
            warnings.push(RecordWarning::LowVelocityTermLeftOut {
                force_n: a,
                std_error_n: se,
            });
            low_dropped = Some((a, se));
            shape.low = false;
            fit = Separable::new(data, *shape).fit();
            hac = ee_covariance(&fit, data);
        }
    }
    (fit, hac, low_dropped)
}

/// The output-error check (when `settings` ask for it) from the equation error's `full`
/// vector with the `free` parameters: each record's simulated motion and the fit, or a
/// warning saying why it was not used; its warnings and its comparison with `ee_params`.
#[allow(clippy::type_complexity)]
fn output_error_check(
    records: &[TestRecord],
    prepared: &[Prepared],
    (full, free): (&[f64], &[usize]),
    ee_params: &ParameterEstimates,
    settings: &ValidRecordSettings,
    fixed_reason: &dyn Fn(IdentifiedKey) -> String,
    warnings: &mut Vec<RecordWarning>,
) -> (Vec<Option<Vec<f64>>>, Option<OutputErrorFit>) {
    let velocities: Vec<Vec<f64>> = prepared.iter().map(|p| p.v_m_s.clone()).collect();
    let mut simulated = vec![None; records.len()];
    let mut output_error = None;
    if settings.output_error {
        let model_free: Vec<usize> = free.iter().copied().filter(|&i| i < OFFSETS).collect();
        match run_output_error(
            records,
            &velocities,
            full,
            &model_free,
            settings,
            fixed_reason,
        ) {
            Ok(oe) => {
                simulated = oe.simulated;
                compare_fits(ee_params, &oe.fit.parameters, warnings);
                oe_warnings(&oe.fit, warnings);
                output_error = Some(oe.fit);
            }
            Err(reason) => warnings.push(RecordWarning::OutputErrorNotUsed { reason }),
        }
    }
    (simulated, output_error)
}

/// Adds the variance of the estimated channel delays to the equation error's covariance
/// (module `skew`): `g·gᵀ·MSE(τ)` per delay, `g` the central difference of the fitted
/// vector over the delay. A perturbed fit that frees or clamps other parameters than `fit`
/// says nothing about `g` along them and is skipped. Each refit prepares the one record whose
/// channel moved and shares every other record's samples and sums with `data`; it follows
/// the fit's minimum by Newton's method from the expanded sums (module `refit`, a nonlinear
/// parameter on its bound held there), or, where that does not apply, runs the fit's own
/// search from the joint fit's `(α, b)` (not from the start grid: the grid's best node moves
/// along a flat valley with the channel, and a search from it costs tens of passes over
/// every record). Returns how many refits were made each way, `[Newton, search]`.
fn skew_covariance(
    hac: &mut Hac,
    fit: &SeparableFit,
    shape: Shape,
    data: &Stacked,
    corrected: &skew::Corrected,
    settings: &ValidRecordSettings,
) -> Result<[usize; 2]> {
    let perturbations = skew::perturbations(corrected)?;
    let mut counts = [0; 2];
    if perturbations.is_empty() {
        return Ok(counts);
    }
    let refits = Refits::new(data, fit, shape, refit::Sums::Expanded);
    let start: Vec<f64> = shape.nonlinear().iter().map(|&i| fit.full[i]).collect();
    for p in perturbations {
        let mut refit = |rec: &TestRecord| -> Result<Refit> {
            let prepared = prepare(std::slice::from_ref(rec), settings)?;
            let block = Block::new(p.record, rec, &prepared[0]);
            let data = data.with_block(p.record, block);
            if let Some(r) = refits.refit(&data, p.record) {
                counts[0] += 1;
                return Ok(r);
            }
            counts[1] += 1;
            let f = Separable::new(&data, shape).fit_from(&start);
            Ok(Refit {
                full: f.full,
                free: f.free,
            })
        };
        let (minus, plus) = (refit(&p.minus)?, refit(&p.plus)?);
        if minus.free != fit.free || plus.free != fit.free {
            continue;
        }
        let g: Vec<f64> = fit
            .free
            .iter()
            .map(|&i| (plus.full[i] - minus.full[i]) / (2.0 * p.h_s))
            .collect();
        for cov in [&mut hac.cov, &mut hac.cov_estimable] {
            for (a, ga) in g.iter().enumerate() {
                for (b, gb) in g.iter().enumerate() {
                    cov[(a, b)] += ga * gb * p.mse_s2;
                }
            }
        }
    }
    Ok(counts)
}

/// The name of a search's stop ([`EquationErrorFit::stop`]).
fn stop_name(stop: crate::lm::Stop) -> &'static str {
    match stop {
        crate::lm::Stop::Tolerance => "tolerance",
        crate::lm::Stop::Statistical => "statistical",
        crate::lm::Stop::NoDescent => "no descent",
        crate::lm::Stop::IterationLimit => "iteration limit",
    }
}

/// Why a nonlinear parameter on its bound is not identified
/// ([`EquationErrorFit::not_identified`]).
fn held_reason(key: IdentifiedKey, value: f64) -> String {
    format!(
        "held on its bound ({value}): the records' cost still falls beyond it, so they do not determine {} within the model's range; \
         the search held it there rather than crawl along the bound",
        key.name()
    )
}

fn free_position(free: &[usize], full: usize) -> usize {
    free.iter()
        .position(|&i| i == full)
        .expect("the parameter is fitted")
}

fn ee_covariance(fit: &SeparableFit, data: &Stacked) -> Hac {
    let (time, group) = data.layout();
    hac::covariance(&fit.jacobian, &fit.residual, &time, &group)
}

/// An estimate with the sandwich's variance and the fixed-b critical value; the degrees of
/// freedom reported are the effective samples less the parameters.
fn estimate(value: f64, var: f64, hac: &Hac, params: usize) -> Estimate {
    estimate_with(
        value,
        var,
        hac.critical_value,
        hac.effective_samples,
        params,
    )
}

fn estimate_with(value: f64, var: f64, critical: f64, effective: f64, params: usize) -> Estimate {
    let se = var.max(0.0).sqrt();
    Estimate {
        value,
        std_error: se,
        ci95_low: value - critical * se,
        ci95_high: value + critical * se,
        dof: (effective - params as f64).max(1.0),
    }
}

/// The seven parameters and their correlations from a fit's full vector and covariance
/// (`free`: full-vector indices of the covariance's rows).
fn parameters(
    full: &[f64],
    free: &[usize],
    hac: &Hac,
    fixed_reason: &dyn Fn(IdentifiedKey) -> String,
) -> (ParameterEstimates, Correlations) {
    let param = |key: IdentifiedKey| -> Parameter {
        let i = index(key);
        match free.iter().position(|&x| x == i) {
            None => Parameter::Fixed {
                value: full[i],
                reason: fixed_reason(key),
            },
            Some(k) if hac.singular[k] => Parameter::NotIdentifiable {
                reason: "singular: the record does not determine it".to_owned(),
            },
            Some(k) => Parameter::Estimated(estimate(full[i], hac.cov[(k, k)], hac, free.len())),
        }
    };
    let p = ParameterEstimates {
        effective_mass_kg: param(IdentifiedKey::EffectiveMass),
        stiffness_n_per_m: param(IdentifiedKey::Stiffness),
        coulomb_force_n: param(IdentifiedKey::CoulombForce),
        viscous_coefficient: param(IdentifiedKey::ViscousCoefficient),
        viscous_exponent: param(IdentifiedKey::ViscousExponent),
        low_velocity_force_n: param(IdentifiedKey::LowVelocityForce),
        low_velocity_decay_s_per_m: param(IdentifiedKey::LowVelocityDecay),
    };
    let keys: Vec<IdentifiedKey> = IdentifiedKey::ALL
        .into_iter()
        .filter(|&k| p.get(k).estimate().is_some())
        .collect();
    let pos = |k: IdentifiedKey| free_position(free, index(k));
    let matrix = keys
        .iter()
        .map(|&a| {
            keys.iter()
                .map(|&b| {
                    let (i, j) = (pos(a), pos(b));
                    hac.cov[(i, j)] / (hac.cov[(i, i)] * hac.cov[(j, j)]).sqrt()
                })
                .collect()
        })
        .collect();
    (p, Correlations { keys, matrix })
}

fn uncertainty(hac: &Hac, correlations: Correlations) -> FitUncertainty {
    FitUncertainty {
        correlations,
        bandwidth_samples: hac.bandwidth,
        critical_value: hac.critical_value,
        effective_samples: hac.effective_samples,
        condition_number: hac.condition,
    }
}

/// Smallest and largest speed of the fitted samples, m/s.
fn speed_range(data: &Stacked) -> [f64; 2] {
    data.speeds()
        .fold([f64::INFINITY, 0.0], |[lo, hi], w| [lo.min(w), hi.max(w)])
}

/// The equation error's identifiability warnings.
#[allow(clippy::too_many_arguments)]
fn ee_warnings(
    fit: &SeparableFit,
    hac: &Hac,
    free: &[usize],
    params: &ParameterEstimates,
    corr: &Correlations,
    data: &Stacked,
    settings: &ValidRecordSettings,
    speeds: [f64; 2],
    warnings: &mut Vec<RecordWarning>,
) {
    for &i in fit.at_bound.iter().chain(&fit.clamped) {
        let key = IdentifiedKey::ALL[i];
        warnings.push(RecordWarning::AtBound {
            key,
            value: fit.full[i],
        });
    }
    for (k, &i) in free.iter().enumerate() {
        if i < OFFSETS && hac.singular[k] {
            warnings.push(RecordWarning::NotIdentifiable {
                fit: FitKind::EquationError,
                key: IdentifiedKey::ALL[i],
            });
        }
    }
    let b = fit.full[LOW_DECAY];
    correlation_warnings(FitKind::EquationError, params, corr, speeds, b, warnings);
    if params.low_velocity_force_n.estimate().is_some() && b > 0.0 {
        let reach = 3.0 / b;
        let below = data.speeds().filter(|&w| w < reach).count() as f64 / data.len() as f64;
        if below < MIN_LOW_SPEED_FRACTION {
            warnings.push(RecordWarning::FewLowSpeedSamples {
                below_m_s: reach,
                fraction: below,
                min_speed_m_s: settings.min_speed_m_s,
            });
        }
    }
}

/// Correlated pairs and imprecise parameters of a fit.
fn correlation_warnings(
    fit: FitKind,
    params: &ParameterEstimates,
    corr: &Correlations,
    speeds: [f64; 2],
    b: f64,
    warnings: &mut Vec<RecordWarning>,
) {
    for (i, &a) in corr.keys.iter().enumerate() {
        for (j, &c) in corr.keys.iter().enumerate().skip(i + 1) {
            let r = corr.matrix[i][j];
            if r.abs() > MAX_CORRELATION {
                let pair = (a, c) == (IdentifiedKey::CoulombForce, IdentifiedKey::LowVelocityForce);
                warnings.push(RecordWarning::NotSeparable {
                    fit,
                    first: a,
                    second: c,
                    correlation: r,
                    speeds_m_s: if pair && b > 0.0 {
                        [speeds[0], 3.0 / b]
                    } else {
                        speeds
                    },
                });
            }
        }
    }
    for (key, p) in params.iter() {
        if let Some(e) = p.estimate() {
            let rel = if key == IdentifiedKey::ViscousExponent {
                e.std_error
            } else {
                e.relative_std_error()
            };
            if rel > MAX_RELATIVE_STD_ERROR {
                warnings.push(RecordWarning::Imprecise {
                    fit,
                    key,
                    relative_std_error: rel,
                });
            }
        }
    }
}

/// What the output error found.
struct OeOutcome {
    fit: OutputErrorFit,
    simulated: Vec<Option<Vec<f64>>>,
}

fn run_output_error(
    records: &[TestRecord],
    velocities: &[Vec<f64>],
    ee_full: &[f64],
    model_free: &[usize],
    settings: &ValidRecordSettings,
    fixed_reason: &dyn Fn(IdentifiedKey) -> String,
) -> std::result::Result<OeOutcome, String> {
    let (problem, start) = OutputError::new(
        records,
        velocities,
        ee_full,
        model_free.to_vec(),
        settings.steps_per_sample,
    )
    .ok_or_else(|| {
        "the equation error's parameters give no valid model to simulate, or the simulation failed"
            .to_owned()
    })?;
    let (lower, upper) = problem.bounds();
    let res = crate::lm::minimize(
        &problem,
        &start,
        &lower,
        &upper,
        crate::lm::LmSettings {
            max_iterations: settings.output_error_iterations,
            cost_tolerance: 1e-6,
            step_tolerance: 1e-6,
            ..crate::lm::LmSettings::default()
        },
    );
    let (time, group) = problem.residual_layout();
    let hac = hac::covariance(&res.jacobian, &res.residuals, &time, &group);
    let q = problem.model_vector(&res.params);
    let mut full = q.to_vec();
    full.extend(std::iter::repeat_n(0.0, records.len()));
    // Covariance rows: the model parameters first (model_free order), then the states.
    let mut free_full: Vec<usize> = model_free.to_vec();
    free_full.extend((0..2 * records.len()).map(|k| 1000 + k));
    let (params, corr) = parameters(&full, &free_full, &hac, fixed_reason);
    let (simulated, rms_end): (Vec<_>, Vec<_>) = problem
        .finish(&res.params)
        .into_iter()
        .map(|end| (end.simulated_u_m, end.rms))
        .unzip();
    let rms_start = problem.start_rms();
    Ok(OeOutcome {
        fit: OutputErrorFit {
            parameters: params,
            uncertainty: uncertainty(&hac, corr),
            rms_u_m: rms_start
                .iter()
                .zip(&rms_end)
                .map(|(s, e)| [s.0, e.0])
                .collect(),
            rms_a_m_s2: rms_start
                .iter()
                .zip(&rms_end)
                .map(|(s, e)| [s.1, e.1])
                .collect(),
            iterations: res.iterations,
            converged: res.converged,
            simulations: problem.runs(),
        },
        simulated,
    })
}

fn oe_warnings(fit: &OutputErrorFit, warnings: &mut Vec<RecordWarning>) {
    if !fit.converged {
        warnings.push(RecordWarning::OutputErrorNotUsed {
            reason: format!("it did not converge in {} iterations", fit.iterations),
        });
    }
    for (key, p) in fit.parameters.iter() {
        if matches!(p, Parameter::NotIdentifiable { .. }) {
            warnings.push(RecordWarning::NotIdentifiable {
                fit: FitKind::OutputError,
                key,
            });
        }
    }
}

/// Warns where the two fits disagree.
fn compare_fits(
    ee: &ParameterEstimates,
    oe: &ParameterEstimates,
    warnings: &mut Vec<RecordWarning>,
) {
    for (key, p) in ee.iter() {
        let (Some(a), Some(b)) = (p.estimate(), oe.get(key).estimate()) else {
            continue;
        };
        if crate::estimate::fits_disagree(key, a, b, fit_agreement(key)) {
            warnings.push(RecordWarning::FitsDisagree {
                key,
                equation_error: a.value,
                output_error: b.value,
            });
        }
    }
}

/// `F_D(|v|)` of the fitted vector `full` with its pointwise 95 % band from the covariance
/// `cov` (rows: full-vector indices `free`), at `points` speeds spaced evenly in `ln |v|`
/// over `speeds`. The law is determined even where its parameters are not (the fit's
/// minimum-norm solution along a singular direction changes no fitted force).
fn band(
    full: &[f64],
    cov: &(Vec<usize>, DMatrix<f64>, f64),
    speeds: [f64; 2],
    points: usize,
) -> Vec<BandPoint> {
    let law = fitted_law(full);
    let (free, c, critical) = cov;
    // Gradient order of DissipativeLaw::gradient: (F_μ, Cₑ, α, a, b) = full indices 2..=6.
    let law_index = [2, 3, 4, 5, 6];
    let (lo, hi) = (speeds[0].max(1e-6), speeds[1].max(speeds[0] * 1.0001));
    (0..points)
        .map(|k| {
            let w = lo * (hi / lo).powf(k as f64 / (points - 1) as f64);
            let g = law.gradient(w, w.ln());
            let mut var = 0.0;
            for (a, &ia) in law_index.iter().enumerate() {
                let Some(pa) = free.iter().position(|&x| x == ia) else {
                    continue;
                };
                for (b, &ib) in law_index.iter().enumerate() {
                    let Some(pb) = free.iter().position(|&x| x == ib) else {
                        continue;
                    };
                    let x = c[(pa, pb)];
                    if x.is_finite() {
                        var += g[a] * g[b] * x;
                    }
                }
            }
            let f = law.magnitude_from_ln_n(w, w.ln());
            let half = critical * var.max(0.0).sqrt();
            BandPoint {
                speed_m_s: w,
                force_n: f,
                low_n: f - half,
                high_n: f + half,
            }
        })
        .collect()
}

/// The law of a full parameter vector.
fn fitted_law(q: &[f64]) -> DissipativeLaw {
    DissipativeLaw {
        coulomb_force_n: q[2],
        viscous_coefficient: q[3],
        exponent: Exponent::new(q[4].clamp(0.0, 1.0)),
        low_velocity_force_n: q[5],
        low_velocity_decay_s_per_m: q[6],
    }
}
