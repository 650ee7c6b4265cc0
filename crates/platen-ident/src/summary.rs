//! The machine-readable summary of an identification, as `platen identify --json` prints it:
//! serde types built from an [`Identification`].
//!
//! Non-finite numbers become `null` when serialised to JSON. Pressures are in MPa, as on
//! the command line.

use std::collections::BTreeMap;

use platen_model::IdentifiedKey;
use serde::Serialize;

use crate::estimate::{Estimate, Parameter};
use crate::record::TestKind;
use crate::result::{
    GlobalFit, Identification, LawReport, PaperFit, ParameterEstimates, PressureGroup, TestResult,
};
use crate::warning::Flag;

/// Points per curve in the summary (curves are decimated evenly to at most this many).
pub const CURVE_POINTS: usize = 40;

/// The whole summary: the seven identified keys at the top level (value, or null when not
/// identifiable), their uncertainties, and the tables and fits behind them.
#[derive(Debug, Clone, Serialize)]
pub struct IdentificationSummary {
    /// The seven keys' values.
    #[serde(flatten)]
    pub values: BTreeMap<&'static str, Option<f64>>,
    /// The reference pressure, MPa.
    pub reference_pressure_mpa: Option<f64>,
    /// Each key's status and uncertainty.
    pub uncertainty: BTreeMap<&'static str, ParameterSummary>,
    /// `μₑ`.
    pub friction_coefficient: Option<EstimateSummary>,
    /// The triangle tests, in input order.
    pub triangle_tests: Vec<TestSummary>,
    /// The sine tests, in input order.
    pub sine_tests: Vec<TestSummary>,
    /// Per pressure group.
    pub pressures: Vec<PressureSummary>,
    /// Eq. 21 as the paper fitted it.
    pub paper_eq21: Option<PaperFitSummary>,
    /// The law fit behind the final dissipative parameters.
    pub dissipative_fit: Option<LawSummary>,
    /// The global fit.
    pub global_fit: Option<GlobalSummary>,
    /// The warnings' sentences.
    pub warnings: Vec<String>,
}

impl IdentificationSummary {
    /// The summary of `id`, whose tests were read from `files` (in the same order).
    pub fn new(id: &Identification, files: &[String]) -> Self {
        let mut triangle_tests = Vec::new();
        let mut sine_tests = Vec::new();
        for (t, file) in id.tests.iter().zip(files) {
            let summary = TestSummary::new(t, file);
            match t.kind {
                TestKind::Triangle => triangle_tests.push(summary),
                TestKind::Sine => sine_tests.push(summary),
            }
        }
        Self {
            values: values(&id.parameters),
            reference_pressure_mpa: id.reference_pressure_pa.map(mpa),
            uncertainty: uncertainty(&id.parameters),
            friction_coefficient: id.friction_coefficient.as_ref().map(EstimateSummary::new),
            triangle_tests,
            sine_tests,
            pressures: id.pressures.iter().map(PressureSummary::new).collect(),
            paper_eq21: id.paper_fit.as_ref().map(PaperFitSummary::new),
            dissipative_fit: id.law.as_ref().map(LawSummary::new),
            global_fit: id.global.as_ref().map(GlobalSummary::new),
            warnings: id.warnings.iter().map(ToString::to_string).collect(),
        }
    }
}

fn mpa(p_pa: f64) -> f64 {
    p_pa / 1e6
}

/// The seven values by contract name.
fn values(p: &ParameterEstimates) -> BTreeMap<&'static str, Option<f64>> {
    p.iter().map(|(k, p)| (k.name(), p.value())).collect()
}

/// The seven statuses by contract name.
fn uncertainty(p: &ParameterEstimates) -> BTreeMap<&'static str, ParameterSummary> {
    p.iter()
        .map(|(k, p)| (IdentifiedKey::name(k), ParameterSummary::new(p)))
        .collect()
}

/// An estimate with its standard error, 95 % interval and degrees of freedom.
#[derive(Debug, Clone, Serialize)]
pub struct EstimateSummary {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub std_error: f64,
    /// The 95 % confidence interval.
    pub ci95: [f64; 2],
    /// The effective degrees of freedom of the interval's Student t: independent observations
    /// minus parameters, where residuals correlated over `ℓ` samples count `n/ℓ` independent
    /// observations (so not a whole number in general; see [`Estimate::dof`]).
    pub effective_dof: f64,
}

impl EstimateSummary {
    /// The summary of `e`.
    pub fn new(e: &Estimate) -> Self {
        Self {
            value: e.value,
            std_error: e.std_error,
            ci95: [e.ci95_low, e.ci95_high],
            effective_dof: e.dof,
        }
    }
}

/// A parameter's status (`status`: `estimated`, `fixed`, `not_identifiable`) with its
/// uncertainty or reason.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ParameterSummary {
    /// Estimated (the value is the key's top-level value).
    Estimated {
        /// Standard error.
        std_error: f64,
        /// 95 % confidence interval.
        ci95: [f64; 2],
        /// Effective degrees of freedom (see [`EstimateSummary::effective_dof`]).
        effective_dof: f64,
    },
    /// Held at a value.
    Fixed {
        /// The value.
        value: f64,
        /// Why.
        reason: String,
    },
    /// Not identifiable.
    NotIdentifiable {
        /// What is missing.
        reason: String,
    },
}

impl ParameterSummary {
    /// The summary of `p`.
    pub fn new(p: &Parameter) -> Self {
        match p {
            Parameter::Estimated(e) => ParameterSummary::Estimated {
                std_error: e.std_error,
                ci95: [e.ci95_low, e.ci95_high],
                effective_dof: e.dof,
            },
            Parameter::Fixed { value, reason } => ParameterSummary::Fixed {
                value: *value,
                reason: reason.clone(),
            },
            Parameter::NotIdentifiable { reason } => ParameterSummary::NotIdentifiable {
                reason: reason.clone(),
            },
        }
    }
}

/// A flag's code and sentence.
#[derive(Debug, Clone, Serialize)]
pub struct FlagSummary {
    /// [`Flag::code`].
    pub code: &'static str,
    /// The sentence.
    pub message: String,
}

/// One test.
#[derive(Debug, Clone, Serialize)]
pub struct TestSummary {
    /// The file it was read from.
    pub file: String,
    /// Its name.
    pub name: String,
    /// `sine` or `triangle`.
    pub kind: &'static str,
    /// `manifest` (given) or `data` (recognised).
    pub kind_source: &'static str,
    /// Hold-down pressure, MPa.
    pub pressure_mpa: Option<f64>,
    /// Fundamental frequency, Hz.
    pub frequency_hz: f64,
    /// Period, s.
    pub period_s: f64,
    /// Full cycles in the record.
    pub full_cycles: usize,
    /// The cycle analysed, 1-based.
    pub cycle_used: usize,
    /// Its start, s.
    pub cycle_start_s: f64,
    /// Displacement amplitude, m.
    pub amplitude_m: f64,
    /// Peak (sine) or plateau (triangle) velocity, m/s.
    pub peak_velocity_m_s: f64,
    /// Peak acceleration, m/s².
    pub peak_acceleration_m_s2: f64,
    /// Fraction of the cycle at constant velocity.
    pub plateau_fraction: f64,
    /// Harmonic distortion of the displacement.
    pub harmonic_distortion: f64,
    /// Dissipative force at peak velocity, N.
    pub dissipative_force_at_peak_n: Option<f64>,
    /// The velocity there, m/s.
    pub velocity_at_peak_m_s: Option<f64>,
    /// Flags.
    pub flags: Vec<FlagSummary>,
    /// Whether its estimate (stiffness or mass) enters the mean.
    pub used: bool,
    /// The dissipative force curve `(|v̄|, F_D)` of Eq. 20, m/s and N, decimated to
    /// [`CURVE_POINTS`].
    pub dissipative_curve: Vec<[f64; 2]>,
    /// What the test's waveform estimates.
    #[serde(flatten)]
    pub estimate: KindSummary,
}

impl TestSummary {
    /// The summary of `t`, read from `file`.
    pub fn new(t: &TestResult, file: &str) -> Self {
        let c = &t.cycle;
        Self {
            file: file.to_owned(),
            name: t.name.clone(),
            kind: t.kind.name(),
            kind_source: if t.kind_given { "manifest" } else { "data" },
            pressure_mpa: t.pressure_pa.map(mpa),
            frequency_hz: c.frequency_hz,
            period_s: c.period_s,
            full_cycles: c.full_cycles,
            cycle_used: c.cycle_used,
            cycle_start_s: c.cycle_start_s,
            amplitude_m: c.amplitude_m,
            peak_velocity_m_s: t.peak_velocity_m_s,
            peak_acceleration_m_s2: t.peak_acceleration_m_s2,
            plateau_fraction: c.plateau_fraction,
            harmonic_distortion: c.harmonic_distortion,
            dissipative_force_at_peak_n: t.peak_dissipative.map(|p| p.force_n),
            velocity_at_peak_m_s: t.peak_dissipative.map(|p| p.velocity_m_s),
            flags: t.flags.iter().map(flag_summary).collect(),
            used: match t.kind {
                TestKind::Triangle => t.used_for_stiffness,
                TestKind::Sine => t.used_for_mass,
            },
            dissipative_curve: decimate(&t.dissipative_curve, CURVE_POINTS),
            estimate: KindSummary::new(t),
        }
    }
}

fn flag_summary(f: &Flag) -> FlagSummary {
    FlagSummary {
        code: f.code(),
        message: f.message(),
    }
}

/// The estimate of a test's waveform: stiffness (triangle) or mass (sine), with its curve
/// decimated to [`CURVE_POINTS`].
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum KindSummary {
    /// A triangle test.
    Triangle {
        /// `Kₑ`, N/m.
        stiffness_n_per_m: Option<f64>,
        /// Its standard error.
        stiffness_std_error: Option<f64>,
        /// The elastic force curve `(ū, F_E)`, m and N.
        elastic_curve: Vec<[f64; 2]>,
    },
    /// A sine test.
    Sine {
        /// `Mₑ`, kg.
        effective_mass_kg: Option<f64>,
        /// Its standard error.
        effective_mass_std_error: Option<f64>,
        /// The inertial force curve `(ā, Mₑā)`, m/s² and N.
        inertial_curve: Vec<[f64; 2]>,
    },
}

impl KindSummary {
    fn new(t: &TestResult) -> Self {
        match t.kind {
            TestKind::Triangle => KindSummary::Triangle {
                stiffness_n_per_m: t.stiffness.map(|e| e.value),
                stiffness_std_error: t.stiffness.map(|e| e.std_error),
                elastic_curve: decimate(&t.elastic_curve, CURVE_POINTS),
            },
            TestKind::Sine => KindSummary::Sine {
                effective_mass_kg: t.effective_mass.map(|e| e.value),
                effective_mass_std_error: t.effective_mass.map(|e| e.std_error),
                inertial_curve: decimate(&t.inertial_curve, CURVE_POINTS),
            },
        }
    }
}

/// Up to `max` evenly spaced points of a curve.
fn decimate(curve: &[[f64; 2]], max: usize) -> Vec<[f64; 2]> {
    if curve.is_empty() {
        return Vec::new();
    }
    let step = curve.len().div_ceil(max).max(1);
    curve.iter().step_by(step).copied().collect()
}

/// One pressure group.
#[derive(Debug, Clone, Serialize)]
pub struct PressureSummary {
    /// Pressure, MPa.
    pub pressure_mpa: Option<f64>,
    /// `F_z`, N.
    pub vertical_force_n: Option<f64>,
    /// Sine tests.
    pub sine_tests: usize,
    /// Triangle tests.
    pub triangle_tests: usize,
    /// `Kₑ`.
    pub stiffness_n_per_m: Option<EstimateSummary>,
    /// Where it comes from.
    pub stiffness_source: String,
    /// `F_μ`.
    pub coulomb_force_n: Option<EstimateSummary>,
    /// `F_μ` from the sine tests' peak points with Eq. 21's `Cₑ`.
    pub paper_coulomb_force_sine_n: Option<EstimateSummary>,
    /// The same from the triangle tests.
    pub paper_coulomb_force_triangle_n: Option<EstimateSummary>,
}

impl PressureSummary {
    fn new(g: &PressureGroup) -> Self {
        let opt = |e: &Option<Estimate>| e.as_ref().map(EstimateSummary::new);
        Self {
            pressure_mpa: g.pressure_pa.map(mpa),
            vertical_force_n: g.vertical_force_n,
            sine_tests: g.sine_tests,
            triangle_tests: g.triangle_tests,
            stiffness_n_per_m: opt(&g.stiffness),
            stiffness_source: g.stiffness_source.to_string(),
            coulomb_force_n: opt(&g.coulomb_force),
            paper_coulomb_force_sine_n: opt(&g.paper_coulomb_force_sine),
            paper_coulomb_force_triangle_n: opt(&g.paper_coulomb_force_triangle),
        }
    }
}

/// Eq. 21 as the paper fitted it.
#[derive(Debug, Clone, Serialize)]
pub struct PaperFitSummary {
    /// `F_μ`.
    pub coulomb_force_n: EstimateSummary,
    /// `Cₑ`.
    pub viscous_coefficient: EstimateSummary,
    /// `α` (0.5, held).
    pub viscous_exponent: f64,
    /// Peak points fitted.
    pub points: usize,
    /// Whether only sine tests were used.
    pub sine_tests_only: bool,
    /// `μₑ`.
    pub friction_coefficient: Option<EstimateSummary>,
}

impl PaperFitSummary {
    fn new(p: &PaperFit) -> Self {
        Self {
            coulomb_force_n: EstimateSummary::new(&p.coulomb_force),
            viscous_coefficient: EstimateSummary::new(&p.viscous_coefficient),
            viscous_exponent: 0.5,
            points: p.points,
            sine_tests_only: p.sine_only,
            friction_coefficient: p.friction_coefficient.as_ref().map(EstimateSummary::new),
        }
    }
}

/// The law fit.
#[derive(Debug, Clone, Serialize)]
pub struct LawSummary {
    /// Points fitted.
    pub points: usize,
    /// Weighted RMS residual, N.
    pub rms_n: f64,
    /// Condition number.
    pub condition_number: f64,
    /// Speeds spanned (10th and 90th percentiles), m/s.
    pub speed_range_m_s: [f64; 2],
}

impl LawSummary {
    fn new(l: &LawReport) -> Self {
        Self {
            points: l.points,
            rms_n: l.rms_n,
            condition_number: l.condition_number,
            speed_range_m_s: l.speed_range_m_s,
        }
    }
}

/// One pressure group of the global fit.
#[derive(Debug, Clone, Serialize)]
pub struct GlobalPressureSummary {
    /// Pressure, MPa.
    pub pressure_mpa: Option<f64>,
    /// `Kₑ`.
    pub stiffness_n_per_m: EstimateSummary,
    /// `F_μ`.
    pub coulomb_force_n: EstimateSummary,
}

/// The global fit.
#[derive(Debug, Clone, Serialize)]
pub struct GlobalSummary {
    /// The seven keys' values.
    #[serde(flatten)]
    pub values: BTreeMap<&'static str, Option<f64>>,
    /// Each key's status and uncertainty.
    pub uncertainty: BTreeMap<&'static str, ParameterSummary>,
    /// Per pressure group.
    pub pressures: Vec<GlobalPressureSummary>,
    /// RMS residual, N.
    pub rms_residual_n: f64,
    /// Samples fitted.
    pub points: usize,
    /// Whether Levenberg–Marquardt converged.
    pub converged: bool,
    /// Its iterations.
    pub iterations: usize,
    /// Condition number.
    pub condition_number: f64,
}

impl GlobalSummary {
    fn new(g: &GlobalFit) -> Self {
        Self {
            values: values(&g.parameters),
            uncertainty: uncertainty(&g.parameters),
            pressures: g
                .groups
                .iter()
                .map(|(p, k, f)| GlobalPressureSummary {
                    pressure_mpa: p.map(mpa),
                    stiffness_n_per_m: EstimateSummary::new(k),
                    coulomb_force_n: EstimateSummary::new(f),
                })
                .collect(),
            rms_residual_n: g.rms_residual_n,
            points: g.points,
            converged: g.converged,
            iterations: g.iterations,
            condition_number: g.condition_number,
        }
    }
}
