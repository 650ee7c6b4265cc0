//! What the any-record method returns: both fits with their uncertainty and correlations,
//! the dissipative law's confidence band, per-record details, and typed warnings.

use std::fmt;

use platen_model::{DissipativeLaw, IdentifiedKey};

use crate::estimate::Estimate;
use crate::result::ParameterEstimates;

/// Which fit a set of parameters comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitKind {
    /// The equation error (separable least squares on the force).
    EquationError,
    /// The output error (forward simulation fitted to the measured motion).
    OutputError,
}

impl FitKind {
    /// `"equation_error"` or `"output_error"`.
    pub fn name(self) -> &'static str {
        match self {
            FitKind::EquationError => "equation_error",
            FitKind::OutputError => "output_error",
        }
    }
}

/// Correlation coefficients between the estimated model parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Correlations {
    /// The parameters, in the contract's order (only those estimated).
    pub keys: Vec<IdentifiedKey>,
    /// `matrix[i][j]`: correlation of `keys[i]` and `keys[j]` (1 on the diagonal).
    pub matrix: Vec<Vec<f64>>,
}

impl Correlations {
    /// The correlation of two keys, if both were estimated.
    pub fn get(&self, a: IdentifiedKey, b: IdentifiedKey) -> Option<f64> {
        let i = self.keys.iter().position(|&k| k == a)?;
        let j = self.keys.iter().position(|&k| k == b)?;
        Some(self.matrix[i][j])
    }
}

/// How the uncertainty of a fit was computed, and what it found.
#[derive(Debug, Clone, PartialEq)]
pub struct FitUncertainty {
    /// Parameter correlations.
    pub correlations: Correlations,
    /// Bartlett bandwidth of the sandwich estimator, samples.
    pub bandwidth_samples: usize,
    /// Critical value of the 95 % intervals (fixed-b, Kiefer & Vogelsang 2005).
    pub critical_value: f64,
    /// Independent observations the residuals are worth (from the first parameter's score).
    pub effective_samples: f64,
    /// Condition number of `JᵀJ` scaled to unit diagonal.
    pub condition_number: f64,
}

/// The equation-error fit.
#[derive(Debug, Clone, PartialEq)]
pub struct EquationErrorFit {
    /// The seven parameters.
    pub parameters: ParameterEstimates,
    /// The force offset of each record, N.
    pub offsets_n: Vec<Estimate>,
    /// Uncertainty and correlations.
    pub uncertainty: FitUncertainty,
    /// RMS of the force residual, N.
    pub rms_residual_n: f64,
    /// Samples fitted (faster than the minimum speed, over every record).
    pub points: usize,
    /// The minimum speed of the samples fitted, m/s.
    pub min_speed_m_s: f64,
    /// Levenberg–Marquardt iterations over `(α, b)`.
    pub iterations: usize,
    /// Whether that search met its tolerance.
    pub converged: bool,
    /// Why that search stopped: `"tolerance"` (a step changed the parameters or the cost by
    /// less than its tolerances), `"statistical"` (what is left to gain is below a millionth
    /// of the residual variance: the optimum is within a thousandth of a standard error),
    /// `"no descent"` (no step lowers the cost: a constrained minimum), or
    /// `"iteration limit"`.
    pub stop: String,
    /// The nonlinear parameters (`α`, `b`) the search held on a bound, with why: the cost
    /// still falls beyond the bound, so the records do not determine the parameter within
    /// the model's range. Their values are the bound.
    pub not_identified: Vec<(IdentifiedKey, String)>,
    /// Channel-skew refits (module docs of `skew`) made by Newton's method from the joint
    /// fit's expansions.
    pub skew_refits_newton: usize,
    /// Channel-skew refits that Newton's method could not make, made by the search from the
    /// joint fit's `(α, b)`: each costs passes over every record, so these grow with the
    /// square of the records.
    pub skew_refits_searched: usize,
}

/// The output-error refinement.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputErrorFit {
    /// The seven parameters.
    pub parameters: ParameterEstimates,
    /// Uncertainty and correlations.
    pub uncertainty: FitUncertainty,
    /// Per record: RMS of the displacement residual (mean removed), m, at the start (the
    /// equation-error parameters) and at the end.
    pub rms_u_m: Vec<[f64; 2]>,
    /// Per record: RMS of the acceleration residual (mean removed), m/s², start and end.
    pub rms_a_m_s2: Vec<[f64; 2]>,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Whether it met its tolerance.
    pub converged: bool,
    /// Forward runs of a record (a run of every record counts one per record), including
    /// the difference quotients of the Jacobian: a model parameter's column reruns every
    /// record, a record's initial state only that record.
    pub simulations: usize,
}

/// One point of the dissipative law's confidence band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandPoint {
    /// Speed `|v|`, m/s.
    pub speed_m_s: f64,
    /// `F_D(|v|)` of the final parameters, N.
    pub force_n: f64,
    /// Lower end of the pointwise 95 % band, N.
    pub low_n: f64,
    /// Upper end, N.
    pub high_n: f64,
}

/// The specimen's floors of a record, as given.
#[derive(Debug, Clone, PartialEq)]
pub struct FloorsReport {
    /// The storeys' masses, kg, bottom first.
    pub masses_kg: Vec<f64>,
    /// Largest |Σ mᵢ·aᵢ| subtracted from the force, N.
    pub peak_base_shear_n: f64,
}

/// Per record.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordReport {
    /// The record's name.
    pub name: String,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Time of the first sample, s.
    pub start_s: f64,
    /// Samples.
    pub samples: usize,
    /// Whether a velocity channel was given (else the crossover estimate).
    pub velocity_given: bool,
    /// Samples used by the equation error.
    pub used_samples: usize,
    /// Speeds of those samples: smallest and largest, m/s.
    pub speed_range_m_s: [f64; 2],
    /// The floors subtracted, if any.
    pub floors: Option<FloorsReport>,
    /// The force the model explains (recorded, less the base shear), N.
    pub force_n: Vec<f64>,
    /// The equation error's fitted force (with its offset), N.
    pub fitted_force_n: Vec<f64>,
    /// Whether each sample was used by the equation error.
    pub used: Vec<bool>,
    /// The velocity used, m/s.
    pub velocity_m_s: Vec<f64>,
    /// The measured displacement, m.
    pub u_m: Vec<f64>,
    /// The output error's simulated displacement (its mean offset added), m, if run.
    pub simulated_u_m: Option<Vec<f64>>,
    /// The channels' delays against the displacement, given or estimated, and whether each
    /// was corrected ([`crate::anyrecord::ChannelDelay`]).
    pub channel_delays: Vec<crate::anyrecord::ChannelDelay>,
    /// The effective mass this record alone gives, kg: the mass (and its own offset) refitted
    /// to this record's samples with the other parameters held at the joint fit's (`None`
    /// without two used samples of different accelerations). Records of one table agree;
    /// records of different tables fitted jointly do not
    /// ([`RecordWarning::RecordsDisagree`]).
    pub mass_alone_kg: Option<f64>,
    /// Its standard error, kg (batch means over the record's time: infinite for a record of
    /// fewer than two blocks).
    pub mass_alone_std_error_kg: Option<f64>,
    /// The share of the record's force (RMS about its mean) its inertia makes: below
    /// one half, friction or stiffness dominate it and its mass alone is not judged.
    pub mass_alone_inertial_share: Option<f64>,
}

/// The result of [`crate::identify_records`].
#[derive(Debug, Clone, PartialEq)]
pub struct RecordIdentification {
    /// The seven parameters: the equation error's (see the crate docs, "Any record", for
    /// why the output error is the check and not the estimate).
    pub parameters: ParameterEstimates,
    /// The equation-error fit.
    pub equation_error: EquationErrorFit,
    /// The output-error refinement, if run.
    pub output_error: Option<OutputErrorFit>,
    /// The equation error's dissipative law as fitted (also where its parameters are not
    /// each identifiable: the law is).
    pub law: DissipativeLaw,
    /// `F_D(|v|)` with its pointwise 95 % band over the speeds the records reach.
    pub band: Vec<BandPoint>,
    /// Per record, in input order.
    pub records: Vec<RecordReport>,
    /// Identifiability and everything else the user should know.
    pub warnings: Vec<RecordWarning>,
}

/// Something the user should know about an any-record identification. `Display` gives the
/// sentence.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum RecordWarning {
    /// Two parameters trade off against each other: their estimates are correlated beyond
    /// [`crate::MAX_CORRELATION`], so the record determines a combination of them, not each.
    NotSeparable {
        /// The fit.
        fit: FitKind,
        /// The first parameter.
        first: IdentifiedKey,
        /// The second.
        second: IdentifiedKey,
        /// Their correlation.
        correlation: f64,
        /// The speed below which they would separate, m/s (the low-velocity term's reach
        /// `3/b` for `F_μ` and `a`), or the speed range of the record for the viscous law.
        speeds_m_s: [f64; 2],
    },
    /// A parameter's relative standard error exceeds [`crate::MAX_RELATIVE_STD_ERROR`].
    Imprecise {
        /// The fit.
        fit: FitKind,
        /// The parameter.
        key: IdentifiedKey,
        /// Its relative standard error.
        relative_std_error: f64,
    },
    /// A nonlinear parameter ended on its bound (`α` at 0 or 1, `b` at 0.1 or 10⁴ s/m).
    AtBound {
        /// The parameter.
        key: IdentifiedKey,
        /// Its value.
        value: f64,
    },
    /// The low-velocity term was fitted but its force came out at its bound (`a = 0`: the
    /// record is better fitted by a negative one): left out (`a = 0`, `b = 0`).
    LowVelocityTermLeftOut {
        /// `a`, N.
        force_n: f64,
        /// Its standard error, N.
        std_error_n: f64,
    },
    /// Few samples below the speed where the low-velocity term acts: it is extrapolated
    /// there.
    FewLowSpeedSamples {
        /// The speed, m/s (`3/b`).
        below_m_s: f64,
        /// Fraction of the fitted samples below it.
        fraction: f64,
        /// The minimum speed of the equation error, m/s.
        min_speed_m_s: f64,
    },
    /// A parameter the record cannot determine at all (singular direction).
    NotIdentifiable {
        /// The fit.
        fit: FitKind,
        /// The parameter.
        key: IdentifiedKey,
    },
    /// The output error did not converge or could not run: no check of the equation error.
    OutputErrorNotUsed {
        /// Why.
        reason: String,
    },
    /// The equation error and the output error disagree on a parameter by more than three
    /// combined standard errors and [`crate::fit_agreement`].
    FitsDisagree {
        /// The parameter.
        key: IdentifiedKey,
        /// The equation error's value.
        equation_error: f64,
        /// The output error's.
        output_error: f64,
    },
    /// A record was declared a periodic test (`kind` sine or triangle) but its data are not
    /// periodic: it went to the any-record method.
    DeclaredPeriodicButNot {
        /// The record.
        test: String,
        /// Why it is not periodic.
        reason: String,
    },
    /// A mass that is not positive, or a negative stiffness: no physical platen has one. A
    /// table without a restoring stiffness of its own (bearings only) comes out with a small
    /// negative `Kₑ` from noise or transducer drift; `nonnegative_stiffness` constrains it.
    NegativeEstimate {
        /// The fit.
        fit: FitKind,
        /// The parameter.
        key: IdentifiedKey,
        /// Its value.
        value: f64,
        /// Its 95 % interval, if estimated.
        ci95: Option<[f64; 2]>,
    },
    /// `Kₑ ≥ 0` was imposed and is active: the unconstrained fit wanted a negative stiffness,
    /// `Kₑ = 0` is reported.
    StiffnessConstrained,
    /// The static friction fitted (`F_μ + a`) exceeds the largest force in the records: the
    /// platen could never have moved. Look for a force in the wrong unit or a wrong channel.
    FrictionAbovePeakForce {
        /// `F_μ + a`, N.
        static_friction_n: f64,
        /// Largest |force| the model explains (recorded, less the base shear), N.
        peak_force_n: f64,
    },
    /// The output-error check came out physically implausible against the equation error
    /// (a mass more than twice or less than half the equation error's, or not positive),
    /// whatever its intervals: it is no check of the equation error.
    OutputErrorImplausible {
        /// The parameter.
        key: IdentifiedKey,
        /// The equation error's value.
        equation_error: f64,
        /// The output error's.
        output_error: f64,
    },
    /// The records put the effective mass far apart, each refitted alone with the other
    /// parameters held at the joint fit's ([`RecordReport::mass_alone_kg`]): records of
    /// different tables (or of one table with and without a payload) fitted as one.
    RecordsDisagree {
        /// The record giving the lightest mass, and that mass, kg.
        lightest: (String, f64),
        /// The record giving the heaviest mass, and that mass, kg.
        heaviest: (String, f64),
        /// The joint fit's mass, kg.
        joint_kg: f64,
    },
}

impl fmt::Display for RecordWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RecordWarning::NotSeparable {
                fit,
                first,
                second,
                correlation,
                speeds_m_s,
            } => not_separable(f, *fit, (*first, *second), *correlation, *speeds_m_s),
            RecordWarning::Imprecise {
                fit,
                key,
                relative_std_error,
            } => write!(
                f,
                "{} is poorly determined by this record ({}: relative standard error {:.0} %)",
                symbol(*key),
                fit.name(),
                100.0 * relative_std_error
            ),
            RecordWarning::AtBound { key, value } => write!(
                f,
                "{} ended on its bound ({value}): the record does not determine it",
                symbol(*key)
            ),
            RecordWarning::LowVelocityTermLeftOut {
                force_n,
                std_error_n,
            } => write!(
                f,
                "the low-velocity term is not supported by this record (a = {force_n:.0} ± {std_error_n:.0} N at its bound): left out (a = 0)"
            ),
            RecordWarning::FewLowSpeedSamples {
                below_m_s,
                fraction,
                min_speed_m_s,
            } => few_low_speed_samples(f, *below_m_s, *fraction, *min_speed_m_s),
            RecordWarning::NotIdentifiable { fit, key } => write!(
                f,
                "{} is not identifiable from this record ({}: singular)",
                symbol(*key),
                fit.name()
            ),
            RecordWarning::OutputErrorNotUsed { reason } => {
                write!(f, "output-error check incomplete: {reason}")
            }
            RecordWarning::FitsDisagree {
                key,
                equation_error,
                output_error,
            } => fits_disagree(f, *key, *equation_error, *output_error),
            RecordWarning::DeclaredPeriodicButNot { test, reason } => write!(
                f,
                "test `{test}` was declared periodic but is not ({reason}): identified by the any-record method"
            ),
            RecordWarning::NegativeEstimate {
                fit,
                key,
                value,
                ci95,
            } => negative_estimate(f, *fit, *key, *value, *ci95),
            RecordWarning::StiffnessConstrained => f.write_str(
                "Kₑ ≥ 0 is active: the unconstrained fit wants a negative stiffness; Kₑ = 0 is reported (held at its bound)",
            ),
            RecordWarning::FrictionAbovePeakForce {
                static_friction_n,
                peak_force_n,
            } => friction_above_peak_force(f, *static_friction_n, *peak_force_n),
            RecordWarning::OutputErrorImplausible {
                key,
                equation_error,
                output_error,
            } => output_error_implausible(f, *key, *equation_error, *output_error),
            RecordWarning::RecordsDisagree {
                lightest,
                heaviest,
                joint_kg,
            } => records_disagree(f, lightest, heaviest, *joint_kg),
        }
    }
}

/// [`RecordWarning::FewLowSpeedSamples`]'s message.
fn few_low_speed_samples(
    f: &mut fmt::Formatter<'_>,
    below_m_s: f64,
    fraction: f64,
    min_speed_m_s: f64,
) -> fmt::Result {
    write!(
        f,
        "only {:.1} % of the fitted samples are below {:.1} mm/s, where the low-velocity term acts (none below {:.1} mm/s): a and b rest on few samples",
        100.0 * fraction,
        1e3 * below_m_s,
        1e3 * min_speed_m_s
    )
}

/// [`RecordWarning::FitsDisagree`]'s message.
fn fits_disagree(
    f: &mut fmt::Formatter<'_>,
    key: IdentifiedKey,
    equation_error: f64,
    output_error: f64,
) -> fmt::Result {
    write!(
        f,
        "{}: equation error {equation_error:.6e} and output error {output_error:.6e} disagree ({:.1} %)",
        key.name(),
        100.0 * (equation_error - output_error).abs()
            / equation_error.abs().max(f64::MIN_POSITIVE)
    )
}

/// [`RecordWarning::FrictionAbovePeakForce`]'s message.
fn friction_above_peak_force(
    f: &mut fmt::Formatter<'_>,
    static_friction_n: f64,
    peak_force_n: f64,
) -> fmt::Result {
    write!(
        f,
        "implausible: the static friction F_μ + a = {:.1} kN exceeds the largest force in the records ({:.1} kN), so the platen could never have moved: is the force in the wrong unit or the wrong channel?",
        static_friction_n / 1e3,
        peak_force_n / 1e3
    )
}

/// [`RecordWarning::OutputErrorImplausible`]'s message.
fn output_error_implausible(
    f: &mut fmt::Formatter<'_>,
    key: IdentifiedKey,
    equation_error: f64,
    output_error: f64,
) -> fmt::Result {
    write!(
        f,
        "implausible output-error check: {} = {output_error:.4e} {} against {equation_error:.4e} from the equation error; it does not check the equation error (the record may not excite the platen enough for a forward simulation to pin it)",
        symbol(key),
        key.unit()
    )
}

/// [`RecordWarning::RecordsDisagree`]'s message.
fn records_disagree(
    f: &mut fmt::Formatter<'_>,
    lightest: &(String, f64),
    heaviest: &(String, f64),
    joint_kg: f64,
) -> fmt::Result {
    write!(
        f,
        "the records disagree on the platen's mass: `{}` alone gives {:.1} t, `{}` alone {:.1} t (the joint fit {:.1} t): records of different tables, or of one table with and without a payload, fitted as one; identify them apart",
        lightest.0,
        1e-3 * lightest.1,
        heaviest.0,
        1e-3 * heaviest.1,
        1e-3 * joint_kg
    )
}

/// [`RecordWarning::NotSeparable`]'s message.
fn not_separable(
    f: &mut fmt::Formatter<'_>,
    fit: FitKind,
    (first, second): (IdentifiedKey, IdentifiedKey),
    correlation: f64,
    speeds_m_s: [f64; 2],
) -> fmt::Result {
    let first = &first;
    let second = &second;
    let pair = (*first, *second);
    if pair == (IdentifiedKey::CoulombForce, IdentifiedKey::LowVelocityForce)
        || pair == (IdentifiedKey::LowVelocityForce, IdentifiedKey::CoulombForce)
    {
        write!(
            f,
            "{} and {} are not separable below {:.1} mm/s in this record ({}: correlation {correlation:+.3}): the record determines F_μ + a there, not each; add slower motion, or hold the low-velocity term (--no-low-velocity-term)",
            symbol(*first),
            symbol(*second),
            1e3 * speeds_m_s[1],
            fit.name()
        )
    } else {
        write!(
            f,
            "{} and {} are not separable over {:.1}–{:.0} mm/s in this record ({}: correlation {correlation:+.3}): they trade off; the law F_D(v) is better determined than either (see its band)",
            symbol(*first),
            symbol(*second),
            1e3 * speeds_m_s[0],
            1e3 * speeds_m_s[1],
            fit.name()
        )
    }
}

/// [`RecordWarning::NegativeEstimate`]'s message.
fn negative_estimate(
    f: &mut fmt::Formatter<'_>,
    fit: FitKind,
    key: IdentifiedKey,
    value: f64,
    ci95: Option<[f64; 2]>,
) -> fmt::Result {
    let key = &key;
    write!(
        f,
        "implausible: {} = {value:.4e} {} ({}{}) is {} on a physical platen",
        symbol(*key),
        key.unit(),
        fit.name(),
        ci95.map_or(String::new(), |[lo, hi]| format!(
            ", 95 % interval {lo:.4e} to {hi:.4e}"
        )),
        if *key == IdentifiedKey::EffectiveMass {
            "impossible: a mass is positive"
        } else {
            "impossible: a stiffness is never negative"
        }
    )?;
    if *key == IdentifiedKey::Stiffness {
        f.write_str(
            "; a table without a restoring stiffness of its own may use --nonnegative-stiffness",
        )?;
    }
    Ok(())
}

/// The parameter's symbol.
pub(crate) fn symbol(key: IdentifiedKey) -> &'static str {
    match key {
        IdentifiedKey::EffectiveMass => "Mₑ",
        IdentifiedKey::Stiffness => "Kₑ",
        IdentifiedKey::CoulombForce => "F_μ",
        IdentifiedKey::ViscousCoefficient => "Cₑ",
        IdentifiedKey::ViscousExponent => "α",
        IdentifiedKey::LowVelocityForce => "a",
        IdentifiedKey::LowVelocityDecay => "b",
    }
}
