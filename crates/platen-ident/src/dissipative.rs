//! The dissipative force: the law `F_μ + Cₑ|v|^α + a·e^(−b|v|)` fitted to the Eq. 20 points
//! at the reference pressure (alternating with the correction of the filter's smearing of
//! the friction jump), `F_μ` at every pressure, and `μₑ` from those.

use crate::estimate::{Estimate, Parameter};
use crate::law::{self, law_values, LawFit, LawPoints};
use crate::result::LawReport;
use crate::settings::ValidSettings;
use crate::warning::{LowVelocityOmission, ViscousLawProblem, Warning};
use crate::work::Work;

/// The viscous law (`Cₑ`, `α`) needs the dissipative points to span speeds in a ratio of at
/// least 1.5 between their 10th and 90th percentiles: with one speed level `F_μ + Cₑ·v^α` is a
/// single number and `F_μ`, `Cₑ`, `α` cannot be told apart.
pub const MIN_SPEED_SPREAD: f64 = 1.5;

/// The low-velocity term acts below ≈ 3 cm/s ("negligibly small for velocities higher than
/// 3 cm/s", §3.4); it is fitted only if at least 2 % of the points' weight lies below that.
pub const LOW_SPEED_M_S: f64 = 0.03;

/// Rounds of "fit the law, then remove from the data the part of the filtered friction jump
/// the fitted law predicts". The correction changes by well under 1 % of itself from the
/// second round on, so three rounds leave nothing measurable.
const SMEARING_ITERATIONS: usize = 3;

/// The five parameters of the dissipative law, each with its status.
#[derive(Debug, Clone)]
pub(crate) struct LawEstimates {
    pub(crate) coulomb_force_n: Parameter,
    pub(crate) viscous_coefficient: Parameter,
    pub(crate) viscous_exponent: Parameter,
    pub(crate) low_velocity_force_n: Parameter,
    pub(crate) low_velocity_decay_s_per_m: Parameter,
}

impl Dissipative {
    /// The law's five parameters, the fit behind them and its report; when the viscous law
    /// is not identifiable at all, the five with the reason, and a warning.
    pub(crate) fn law(
        self,
        warnings: &mut Vec<Warning>,
    ) -> (LawEstimates, Option<LawFit>, Option<LawReport>) {
        let ref_points = self.ref_points;
        match self.outcome {
            Some((params, fit)) => {
                let report = LawReport {
                    points: fit.points,
                    rms_n: fit.rms_n,
                    condition_number: fit.condition,
                    speed_range_m_s: [
                        ref_points.speed_quantile(0.1),
                        ref_points.speed_quantile(0.9),
                    ],
                };
                (params, Some(fit), Some(report))
            }
            None => {
                let problem = if ref_points.len() == 0 {
                    ViscousLawProblem::NoPoints
                } else {
                    ViscousLawProblem::OneSpeedLevel {
                        low_m_s: ref_points.speed_quantile(0.1),
                        high_m_s: ref_points.speed_quantile(0.9),
                    }
                };
                let params = LawEstimates::not_identifiable(&problem);
                warnings.push(Warning::ViscousLawNotIdentifiable(problem));
                (params, None, None)
            }
        }
    }
}

impl LawEstimates {
    /// Every parameter not identifiable, for `problem`.
    pub(crate) fn not_identifiable(problem: &ViscousLawProblem) -> Self {
        let ni = || Parameter::NotIdentifiable {
            reason: problem.to_string(),
        };
        Self {
            coulomb_force_n: ni(),
            viscous_coefficient: ni(),
            viscous_exponent: ni(),
            low_velocity_force_n: ni(),
            low_velocity_decay_s_per_m: ni(),
        }
    }
}

/// The law fit at the reference pressure and `F_μ` per pressure, with their warnings.
pub(crate) struct Dissipative {
    pub(crate) outcome: Option<(LawEstimates, LawFit)>,
    pub(crate) group_coulomb: Vec<Option<Estimate>>,
    pub(crate) ref_points: LawPoints,
    pub(crate) warnings: Vec<Warning>,
}

/// Fits the law to the reference pressure's Eq. 20 points, alternating with the correction
/// of the filter's smearing of the friction jump; then `F_μ` at every pressure with the rest
/// of the law held (and the smearing corrected with that `F_μ`).
pub(crate) fn fit_dissipative(
    work: &mut [Work],
    groups: usize,
    reference_group: usize,
    settings: &ValidSettings,
    corr: f64,
) -> Dissipative {
    for w in work.iter_mut() {
        w.odd_corr.iter_mut().for_each(|c| *c = 0.0);
        w.rec_corr.clear();
        w.update_peak();
    }
    let mut outcome = None;
    let mut warnings = Vec::new();
    for _ in 0..SMEARING_ITERATIONS {
        warnings.clear();
        outcome = fit_law(
            &group_points(work, reference_group),
            settings,
            corr,
            &mut warnings,
        );
        let Some((_, fit)) = &outcome else { break };
        for w in work.iter_mut().filter(|w| w.group == reference_group) {
            w.correct_smearing(&fit.law);
        }
    }
    let mut group_coulomb: Vec<Option<Estimate>> = vec![None; groups];
    if let Some((_, fit)) = &outcome {
        for (g, slot) in group_coulomb.iter_mut().enumerate() {
            *slot = group_coulomb_force(work, (g, reference_group), fit, corr);
        }
    }
    Dissipative {
        outcome,
        group_coulomb,
        ref_points: group_points(work, reference_group),
        warnings,
    }
}

/// The Eq. 20 points of pressure group `group`'s tests.
fn group_points(work: &[Work], group: usize) -> LawPoints {
    let mut pts = LawPoints::default();
    for w in work.iter().filter(|w| w.group == group) {
        pts.extend(&w.weighted_points());
    }
    pts
}

/// `F_μ` of pressure group `g` with the rest of the reference group's law `fit` held,
/// alternating with the correction of the smearing by it (the reference group's own is the
/// joint fit's); `None` when it cannot be fitted.
fn group_coulomb_force(
    work: &mut [Work],
    (g, reference_group): (usize, usize),
    fit: &LawFit,
    corr: f64,
) -> Option<Estimate> {
    let mut slot = None;
    let mut law_g = fit.law;
    for round in 0..SMEARING_ITERATIONS {
        if g != reference_group || round == 0 {
            let pts = group_points(work, g);
            let mut base = law_values(&law_g);
            base[law::COULOMB] = 0.0;
            let Some(f) = law::fit(&pts, [true, false, false, false, false], base, corr) else {
                break;
            };
            // One standard error everywhere: the reference pressure's `F_μ` is the
            // joint fit's (the top-level value and its standard error); another
            // pressure's carries the uncertainty of the law held from that fit too.
            slot = Some(if g == reference_group {
                Estimate::new(
                    fit.law.coulomb_force_n,
                    fit.std_errors[law::COULOMB],
                    fit.dof,
                )
            } else {
                let se = law::coulomb_std_error_with_held(
                    &pts,
                    &f.law,
                    f.std_errors[law::COULOMB],
                    &fit.covariance,
                );
                Estimate::new(f.law.coulomb_force_n, se, f.dof.min(fit.dof))
            });
            law_g.coulomb_force_n = f.law.coulomb_force_n;
        }
        if g == reference_group {
            break;
        }
        for w in work.iter_mut().filter(|w| w.group == g) {
            w.correct_smearing(&law_g);
        }
    }
    slot
}

/// Fits the law at the reference pressure; decides which parameters the data determine.
/// Returns the five law parameters and the fit, or `None` if the viscous law is not
/// identifiable at all.
fn fit_law(
    pts: &LawPoints,
    settings: &ValidSettings,
    corr: f64,
    warnings: &mut Vec<Warning>,
) -> Option<(LawEstimates, LawFit)> {
    if pts.len() < 8 {
        return None;
    }
    let (q10, q90) = (pts.speed_quantile(0.1), pts.speed_quantile(0.9));
    if q90 < MIN_SPEED_SPREAD * q10 {
        return None;
    }
    let alpha_free = settings.viscous_exponent.is_none();
    let alpha0 = settings.viscous_exponent.unwrap_or(0.5);
    let base = [0.0, 0.0, alpha0, 0.0, 0.0];
    let (chosen, low_status) = fit_low_velocity(pts, settings, alpha_free, base, corr);
    let fit = match chosen {
        Some(f) => f,
        None => law::fit(pts, [true, true, alpha_free, false, false], base, corr)?,
    };
    let dof = fit.dof;
    let est = |i: usize| Estimate::new(law_values(&fit.law)[i], fit.std_errors[i], dof);
    let c = est(law::VISCOUS);
    if viscous_bad(&fit, alpha_free) {
        let problem = ViscousLawProblem::NotSeparated {
            viscous_coefficient: c.value,
            viscous_coefficient_std_error: c.std_error,
            viscous_exponent: fit.law.exponent.value(),
            viscous_exponent_std_error: fit.std_errors[law::EXPONENT],
        };
        let estimates = LawEstimates::not_identifiable(&problem);
        warnings.push(Warning::ViscousLawNotIdentifiable(problem));
        return Some((estimates, fit));
    }
    let viscous_exponent = if alpha_free {
        Parameter::Estimated(est(law::EXPONENT))
    } else {
        Parameter::Fixed {
            value: alpha0,
            reason: "held at the value given".into(),
        }
    };
    let (a, b) = if fit.free[law::LOW_FORCE] {
        (
            Parameter::Estimated(est(law::LOW_FORCE)),
            Parameter::Estimated(est(law::LOW_DECAY)),
        )
    } else {
        left_out_low_velocity_term(settings, low_status, warnings)
    };
    let estimates = LawEstimates {
        coulomb_force_n: Parameter::Estimated(est(law::COULOMB)),
        viscous_coefficient: Parameter::Estimated(c),
        viscous_exponent,
        low_velocity_force_n: a,
        low_velocity_decay_s_per_m: b,
    };
    Some((estimates, fit))
}

/// Whether the fit leaves `F_μ`, `Cₑ` and a free `α` undetermined: singular, or `Cₑ` with a
/// relative standard error above 50 %, or a free `α` with a standard error above 0.25 (a
/// quarter of its whole range).
fn viscous_bad(fit: &LawFit, alpha_free: bool) -> bool {
    const MAX_VISCOUS_RELATIVE_STD_ERROR: f64 = 0.5;
    const MAX_EXPONENT_STD_ERROR: f64 = 0.25;
    let c = Estimate::new(
        fit.law.viscous_coefficient,
        fit.std_errors[law::VISCOUS],
        fit.dof,
    );
    fit.singular[law::COULOMB]
        || fit.singular[law::VISCOUS]
        || (alpha_free && fit.singular[law::EXPONENT])
        || c.relative_std_error() > MAX_VISCOUS_RELATIVE_STD_ERROR
        || (alpha_free && fit.std_errors[law::EXPONENT] > MAX_EXPONENT_STD_ERROR)
}

/// The law with the low-velocity term, if the settings ask for it, the data reach low
/// speeds, and the term comes out significant; else why it is left out.
fn fit_low_velocity(
    pts: &LawPoints,
    settings: &ValidSettings,
    alpha_free: bool,
    base: [f64; 5],
    corr: f64,
) -> (Option<LawFit>, LowVelocityOmission) {
    if !settings.low_velocity_term {
        return (None, LowVelocityOmission::NoFit);
    }
    // At least 2 % of the points' weight below LOW_SPEED_M_S.
    const MIN_LOW_SPEED_WEIGHT: f64 = 0.02;
    if pts.weight_below(LOW_SPEED_M_S) < MIN_LOW_SPEED_WEIGHT {
        let omission = LowVelocityOmission::NoLowSpeedPoints {
            below_m_s: LOW_SPEED_M_S,
        };
        return (None, omission);
    }
    let Some(f) = law::fit(pts, [true, true, alpha_free, true, true], base, corr) else {
        return (None, LowVelocityOmission::NoFit);
    };
    let a = f.law.low_velocity_force_n;
    let b = f.law.low_velocity_decay_s_per_m;
    let (sa, sb) = (f.std_errors[law::LOW_FORCE], f.std_errors[law::LOW_DECAY]);
    // Kept only if `a` is at least 3 standard errors from zero and `b` is known within 50 %;
    // otherwise it is set to zero and reported as not significant.
    const MIN_SIGNIFICANCE: f64 = 3.0;
    const MAX_DECAY_RELATIVE_STD_ERROR: f64 = 0.5;
    let significant = !f.singular[law::LOW_FORCE]
        && !f.singular[law::LOW_DECAY]
        && a > MIN_SIGNIFICANCE * sa
        && b > 0.0
        && sb <= MAX_DECAY_RELATIVE_STD_ERROR * b;
    if significant {
        return (Some(f), LowVelocityOmission::NoFit);
    }
    let omission = LowVelocityOmission::NotSignificant {
        force_n: a,
        force_std_error_n: sa,
        decay_s_per_m: b,
        decay_std_error_s_per_m: sb,
    };
    (None, omission)
}

/// `a` and `b` of a law fitted without the low-velocity term: held at zero, switched off or
/// (with a warning) not significant or not shown by the data.
fn left_out_low_velocity_term(
    settings: &ValidSettings,
    omission: LowVelocityOmission,
    warnings: &mut Vec<Warning>,
) -> (Parameter, Parameter) {
    let reason = if settings.low_velocity_term {
        // Not significant, or no data to show it: the term is left out of the fit (a = 0),
        // and the seven parameters still form a usable model.
        let reason = omission.to_string();
        warnings.push(Warning::LowVelocityTermLeftOut(omission));
        reason
    } else {
        "low-velocity term not fitted (switched off)".to_owned()
    };
    let fixed = || Parameter::Fixed {
        value: 0.0,
        reason: reason.clone(),
    };
    (fixed(), fixed())
}

/// `μₑ` as the slope through the origin of `F_μ` against `F_z` (Fig. 8): with two or more
/// pressures the standard error comes from the scatter about the line; with one, from that
/// `F_μ`'s.
pub(crate) fn friction_coefficient(
    points: impl Iterator<Item = (f64, Estimate)>,
) -> Option<Estimate> {
    let pts: Vec<(f64, Estimate)> = points.collect();
    match pts.len() {
        0 => None,
        1 => {
            let (fz, f) = pts[0];
            (fz > 0.0).then(|| Estimate::new(f.value / fz, f.std_error / fz, f.dof))
        }
        n => {
            let szz: f64 = pts.iter().map(|(z, _)| z * z).sum();
            if szz <= 0.0 {
                return None;
            }
            let mu = pts.iter().map(|(z, f)| z * f.value).sum::<f64>() / szz;
            let ssr: f64 = pts.iter().map(|(z, f)| (f.value - mu * z).powi(2)).sum();
            let s2 = ssr / (n as f64 - 1.0);
            Some(Estimate::new(mu, (s2 / szz).sqrt(), n as f64 - 1.0))
        }
    }
}
