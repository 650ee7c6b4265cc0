//! What the user should know about an identification: per-test flags, warnings, and the
//! reasons and sources they name. Each is typed; `Display` gives the sentence.

use std::fmt;

use platen_model::IdentifiedKey;

use crate::record::TestKind;

/// Why a test does not support an estimate, or what to know about it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Flag {
    /// Sine test whose inertial force amplitude `Mₑ·max|ā|` is below a quarter of its
    /// dissipative force (paper: S1–S3, "extremely small accelerations … not reliable"): not
    /// used for the mass.
    SmallInertialForce {
        /// Inertial force amplitude over the dissipative force at peak velocity.
        ratio: f64,
    },
    /// Sine test whose displacement is not sinusoidal (harmonic distortion above 5 %; paper:
    /// S12, "the sinusoidal pulses are distorted"): not used for the mass.
    Distorted {
        /// Harmonic distortion of the displacement (harmonics 2–7 over the fundamental).
        harmonic_distortion: f64,
    },
    /// Sine test whose mass estimate has a relative standard error above 10 %: not used.
    ImpreciseMass {
        /// Relative standard error.
        relative_std_error: f64,
    },
    /// Triangle test with constant velocity over less than a quarter of its cycle (severely
    /// rounded or distorted reversals): not used for the stiffness.
    ShortPlateau {
        /// Fraction of the cycle at constant velocity.
        fraction: f64,
    },
    /// Only one full cycle in the record: the cycle analysed may not be in steady state.
    SingleCycle,
    /// The waveform given (manifest) differs from the one recognised from the data; the given
    /// one is used.
    KindMismatch {
        /// The waveform the data look like.
        detected: TestKind,
    },
}

impl Flag {
    /// A short machine-readable code (`small_inertial_force`, `distorted`, …).
    pub fn code(&self) -> &'static str {
        match self {
            Flag::SmallInertialForce { .. } => "small_inertial_force",
            Flag::Distorted { .. } => "distorted",
            Flag::ImpreciseMass { .. } => "imprecise_mass",
            Flag::ShortPlateau { .. } => "short_plateau",
            Flag::SingleCycle => "single_cycle",
            Flag::KindMismatch { .. } => "kind_mismatch",
        }
    }

    /// A sentence saying what the flag means for this test (its `Display`).
    pub fn message(&self) -> String {
        self.to_string()
    }
}

impl fmt::Display for Flag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Flag::SmallInertialForce { ratio } => write!(
                f,
                "inertial force only {:.0} % of the dissipative force: mass not reliable, not used",
                100.0 * ratio
            ),
            Flag::Distorted {
                harmonic_distortion,
            } => write!(
                f,
                "displacement distorted ({:.1} % harmonics): mass not used",
                100.0 * harmonic_distortion
            ),
            Flag::ImpreciseMass { relative_std_error } => write!(
                f,
                "mass standard error {:.1} %: not used",
                100.0 * relative_std_error
            ),
            Flag::ShortPlateau { fraction } => write!(
                f,
                "constant velocity over only {:.0} % of the cycle: stiffness not used",
                100.0 * fraction
            ),
            Flag::SingleCycle => f.write_str(
                "only one full cycle: steady state not verified (the paper uses the second-to-last)",
            ),
            Flag::KindMismatch { detected } => write!(
                f,
                "the data look like a {} test; the given waveform is used",
                detected.name()
            ),
        }
    }
}

/// Where the stiffness of a pressure group comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum StiffnessSource {
    /// No test at this pressure determines it.
    None,
    /// The mean of the group's usable triangle tests (Eq. 16/17).
    TriangleTests,
    /// Mass and stiffness together from sine tests at two or more frequencies.
    SineFrequencies,
}

impl fmt::Display for StiffnessSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StiffnessSource::None => "none",
            StiffnessSource::TriangleTests => "triangle tests",
            StiffnessSource::SineFrequencies => "sine tests at two or more frequencies",
        })
    }
}

/// Why the viscous law (`F_μ`, `Cₑ`, `α`) could not be identified.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ViscousLawProblem {
    /// No Eq. 20 point at the reference pressure.
    NoPoints,
    /// The points lie at one speed level (10th and 90th weighted percentiles given, m/s).
    OneSpeedLevel {
        /// 10th percentile of the speeds, m/s.
        low_m_s: f64,
        /// 90th percentile of the speeds, m/s.
        high_m_s: f64,
    },
    /// The fit does not separate the parameters (values and standard errors at the optimum).
    NotSeparated {
        /// `Cₑ`, N/(m/s)^α.
        viscous_coefficient: f64,
        /// Its standard error.
        viscous_coefficient_std_error: f64,
        /// `α`.
        viscous_exponent: f64,
        /// Its standard error.
        viscous_exponent_std_error: f64,
    },
}

impl fmt::Display for ViscousLawProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ViscousLawProblem::NoPoints => {
                f.write_str("no dissipative points at the reference pressure")
            }
            ViscousLawProblem::OneSpeedLevel { low_m_s, high_m_s } => write!(
                f,
                "the dissipative points span one speed level only ({low_m_s:.4}–{high_m_s:.4} m/s): F_μ, Cₑ and α cannot be told apart; add tests at other velocities",
            ),
            ViscousLawProblem::NotSeparated {
                viscous_coefficient,
                viscous_coefficient_std_error,
                viscous_exponent,
                viscous_exponent_std_error,
            } => write!(
                f,
                "the dissipative points do not separate F_μ, Cₑ and α (Cₑ = {viscous_coefficient:.0} ± {viscous_coefficient_std_error:.0}, α = {viscous_exponent:.3} ± {viscous_exponent_std_error:.3}); add tests at other velocities",
            ),
        }
    }
}

/// Why the low-velocity term `a·e^(−b|v|)` was left out (`a = 0`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum LowVelocityOmission {
    /// Fitted, but not significant (values and standard errors of the fit).
    NotSignificant {
        /// `a`, N.
        force_n: f64,
        /// Its standard error, N.
        force_std_error_n: f64,
        /// `b`, s/m.
        decay_s_per_m: f64,
        /// Its standard error, s/m.
        decay_std_error_s_per_m: f64,
    },
    /// No dissipative points below the given speed, m/s.
    NoLowSpeedPoints {
        /// The speed below which the term acts, m/s.
        below_m_s: f64,
    },
    /// The fit with the term could not be made (too few points for its parameters); the
    /// reason's text is empty.
    NoFit,
}

impl fmt::Display for LowVelocityOmission {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LowVelocityOmission::NotSignificant {
                force_n,
                force_std_error_n,
                decay_s_per_m,
                decay_std_error_s_per_m,
            } => write!(
                f,
                "the low-velocity term is not significant in these tests (a = {force_n:.0} ± {force_std_error_n:.0} N, b = {decay_s_per_m:.1} ± {decay_std_error_s_per_m:.1} s/m): left out (a = 0)",
            ),
            LowVelocityOmission::NoLowSpeedPoints { below_m_s } => write!(
                f,
                "low-velocity term not identifiable: no dissipative points below {below_m_s} m/s (it needs tests with peak velocities of a few cm/s); left out (a = 0)"
            ),
            LowVelocityOmission::NoFit => Ok(()),
        }
    }
}

/// Something the user should know about an identification: a parameter not identifiable, a
/// flagged test, fits that disagree. `Display` gives the sentence.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// Tests without a hold-down pressure form their own group.
    TestsWithoutPressure {
        /// How many.
        count: usize,
    },
    /// The viscous law could not be identified.
    ViscousLawNotIdentifiable(ViscousLawProblem),
    /// The low-velocity term was left out.
    LowVelocityTermLeftOut(LowVelocityOmission),
    /// No sine test: the mass comes from the triangle tests' reversal arcs.
    MassFromTriangleArcs,
    /// The reference pressure's stiffness comes from somewhere other than triangle tests.
    StiffnessNotFromTriangles {
        /// Where it comes from.
        source: StiffnessSource,
    },
    /// The triangle stiffnesses of one pressure group disagree.
    StiffnessSpread {
        /// The group's pressure, Pa.
        pressure_pa: Option<f64>,
        /// Largest distance from the mean, N/m.
        spread_n_per_m: f64,
        /// The mean, N/m.
        mean_n_per_m: f64,
    },
    /// A test carries a flag.
    FlaggedTest {
        /// The test's name.
        test: String,
        /// The flag.
        flag: Flag,
    },
    /// Eq. 21 could not be fitted as the paper did.
    PaperFitNotPossible,
    /// The global fit was not run.
    GlobalFitNotRun,
    /// The global fit and the hysteresis-loop estimate disagree on a parameter.
    GlobalDisagreement {
        /// The parameter.
        key: IdentifiedKey,
        /// The hysteresis-loop estimate.
        loop_value: f64,
        /// The global fit's.
        global_value: f64,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::TestsWithoutPressure { count } => write!(
                f,
                "{count} test(s) have no hold-down pressure: they form their own group and do not enter μₑ"
            ),
            Warning::ViscousLawNotIdentifiable(reason) => {
                write!(f, "viscous law not identifiable: {reason}")
            }
            Warning::LowVelocityTermLeftOut(reason) => write!(f, "{reason}"),
            Warning::MassFromTriangleArcs => f.write_str(
                "no sine test: the mass comes from the reversal arcs of the triangle tests \
                 (the paper uses sine tests, Eq. 18/19)",
            ),
            Warning::StiffnessNotFromTriangles { source } => write!(
                f,
                "stiffness from {source}: no usable triangle test at the reference pressure"
            ),
            Warning::StiffnessSpread {
                pressure_pa,
                spread_n_per_m,
                mean_n_per_m,
            } => write!(
                f,
                "triangle stiffnesses at {} differ by up to {:.0} kN/m from their mean of {:.0} kN/m: tests at different hold-down pressures? give each test its pressure",
                pressure_label(*pressure_pa),
                spread_n_per_m / 1e3,
                mean_n_per_m / 1e3
            ),
            Warning::FlaggedTest { test, flag } => write!(f, "test `{test}`: {flag}"),
            Warning::PaperFitNotPossible => f.write_str(
                "Eq. 21 (paper) fit not possible: it needs the peak points of three or more tests at two or more velocity levels above 3 cm/s at the reference pressure",
            ),
            Warning::GlobalFitNotRun => f.write_str(
                "global fit not run: it needs the mass and the viscous law as a start",
            ),
            Warning::GlobalDisagreement {
                key,
                loop_value: a,
                global_value: b,
            } => write!(
                f,
                "{}: hysteresis-loop estimate {:.6e} and global fit {:.6e} disagree ({:.1} %)",
                key.name(),
                a,
                b,
                100.0 * (a - b).abs() / a.abs().max(f64::MIN_POSITIVE)
            ),
        }
    }
}

/// `"13.8 MPa"`, or `"unknown pressure"`.
fn pressure_label(p: Option<f64>) -> String {
    match p {
        Some(p) => format!("{} MPa", p / 1e6),
        None => "unknown pressure".to_owned(),
    }
}
