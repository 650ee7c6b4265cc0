//! The identification procedure: cycles → symmetry identities (Eq. 10–20) → per-test tables
//! → fits (Eq. 21, the full law, μₑ) → the global fit → the final estimate.

use crate::cycle::{self, RatePlan};
use crate::dissipative::{fit_dissipative, friction_coefficient, LawEstimates};
use crate::elastic::{stiffness_parameter, GroupStiffness};
use crate::error::{IdentError, Result};
use crate::estimate::{Estimate, Parameter};
use crate::global;
use crate::groups::{self, Groups};
use crate::inertial::{alternate, mass_parameter};
use crate::paper_fit::paper_fit;
use crate::record::{TestKind, TestRecord};
use crate::result::{Identification, ParameterEstimates, PressureGroup};
use crate::settings::ValidSettings;
use crate::work::Work;

/// Identifies the platen's parameters from periodic tests (see the crate docs).
///
/// # Errors
/// [`IdentError::NoTests`] for an empty list, [`IdentError::InvalidSetting`] for a reference
/// pressure that is none of the tests', and the first record that cannot be analysed
/// ([`IdentError::NotPeriodic`], [`IdentError::NoFullCycle`], [`IdentError::Signal`]),
/// naming it.
pub fn identify(records: &[TestRecord], settings: &ValidSettings) -> Result<Identification> {
    if records.is_empty() {
        return Err(IdentError::NoTests);
    }
    groups::check_reference(records, settings)?;
    let mut warnings = Vec::new();
    let (plans, mut work) = analyse_records(records, settings)?;
    let groups = groups::group(&mut work, settings, &mut warnings);

    // Dissipative law at the reference pressure, from the instantaneous Eq. 20 points, and
    // F_μ at every pressure.
    let corr = plans
        .iter()
        .map(|p| p.rate_hz / (2.0 * p.fir.cutoff_hz()))
        .fold(1.0, f64::max);
    let mut dissipative = fit_dissipative(
        &mut work,
        groups.keys.len(),
        groups.reference,
        settings,
        corr,
    );
    warnings.append(&mut dissipative.warnings);
    let group_coulomb = std::mem::take(&mut dissipative.group_coulomb);
    let (law, law_fit, law_report) = dissipative.law(&mut warnings);
    for w in work.iter_mut() {
        w.update_peak();
    }

    // Inertial and elastic forces.
    let found = alternate(&mut work, groups.keys.len(), settings);
    let mass = mass_parameter(&work, &found, &mut warnings);
    let stiffness = stiffness_parameter(&work, &groups, &found.group_stiffness, &mut warnings);
    warnings.extend(work.iter().flat_map(Work::flag_warnings));

    let mut pressures = pressure_groups(
        &work,
        &groups,
        &found.group_stiffness,
        &group_coulomb,
        settings,
    );
    let friction_coefficient = friction_coefficient(
        pressures
            .iter()
            .filter_map(|g| Some((g.vertical_force_n?, g.coulomb_force?))),
    );
    let paper_fit = paper_fit(&work, groups.reference, &mut pressures, &mut warnings);
    let parameters = final_parameters(mass, stiffness, law);
    let global = if settings.global_fit {
        global::run(
            &work,
            &groups,
            &pressures,
            &plans,
            law_fit.as_ref(),
            &parameters,
            &mut warnings,
        )
    } else {
        None
    };
    Ok(Identification {
        reference_pressure_pa: groups.keys[groups.reference],
        parameters,
        friction_coefficient,
        tests: work.into_iter().map(Work::into_result).collect(),
        pressures,
        paper_fit,
        law: law_report,
        global,
        warnings,
    })
}

/// Analyses every record's cycles, with one filter plan per sample rate.
fn analyse_records(
    records: &[TestRecord],
    settings: &ValidSettings,
) -> Result<(Vec<RatePlan>, Vec<Work>)> {
    let mut plans: Vec<RatePlan> = Vec::new();
    let mut work = Vec::with_capacity(records.len());
    for rec in records {
        let plan_idx = RatePlan::for_record(&mut plans, rec, settings)?;
        let an = cycle::analyse(rec, &plans[plan_idx], settings)?;
        work.push(Work::new(rec, an, settings));
    }
    Ok((plans, work))
}

/// What was found at each hold-down pressure (the paper's Eq. 21 columns are filled in by
/// [`paper_fit`]).
fn pressure_groups(
    work: &[Work],
    groups: &Groups,
    group_stiffness: &[GroupStiffness],
    group_coulomb: &[Option<Estimate>],
    settings: &ValidSettings,
) -> Vec<PressureGroup> {
    let count = |g: usize, kind: TestKind| {
        work.iter()
            .filter(|w| w.group == g && w.kind == kind)
            .count()
    };
    groups
        .keys
        .iter()
        .enumerate()
        .map(|(g, &p)| PressureGroup {
            pressure_pa: p,
            vertical_force_n: p.map(|p| settings.vertical_load.vertical_force_n(p)),
            sine_tests: count(g, TestKind::Sine),
            triangle_tests: count(g, TestKind::Triangle),
            stiffness: group_stiffness[g].0,
            stiffness_source: group_stiffness[g].1,
            coulomb_force: group_coulomb[g],
            paper_coulomb_force_sine: None,
            paper_coulomb_force_triangle: None,
        })
        .collect()
}

/// The final seven: the mass, the reference pressure's stiffness and the law.
fn final_parameters(
    mass: Parameter,
    stiffness: Parameter,
    law: LawEstimates,
) -> ParameterEstimates {
    ParameterEstimates {
        effective_mass_kg: mass,
        stiffness_n_per_m: stiffness,
        coulomb_force_n: law.coulomb_force_n,
        viscous_coefficient: law.viscous_coefficient,
        viscous_exponent: law.viscous_exponent,
        low_velocity_force_n: law.low_velocity_force_n,
        low_velocity_decay_s_per_m: law.low_velocity_decay_s_per_m,
    }
}
