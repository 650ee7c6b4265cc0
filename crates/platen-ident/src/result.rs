//! What identification returns: the final estimate, the per-test tables, the fits behind
//! them, and the warnings.

use std::ops::Index;

use platen_model::{DissipativeLaw, Exponent, IdentifiedKey, IdentifiedParams};

use crate::cycle::CycleInfo;
use crate::estimate::{Estimate, Parameter};
use crate::record::TestKind;
use crate::warning::{Flag, StiffnessSource, Warning};

/// The dissipative force at the peak velocity of a test (one point of the paper's Fig. 7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeakForce {
    /// Peak velocity, m/s.
    pub velocity_m_s: f64,
    /// Dissipative force there, N.
    pub force_n: f64,
}

/// Everything found for one test.
#[derive(Debug, Clone, PartialEq)]
pub struct TestResult {
    /// The test's name.
    pub name: String,
    /// The waveform used.
    pub kind: TestKind,
    /// Whether the waveform was given (else recognised from the data).
    pub kind_given: bool,
    /// Hold-down pressure, Pa, if given.
    pub pressure_pa: Option<f64>,
    /// Period, cycle choice, filters.
    pub cycle: CycleInfo,
    /// Peak (sine) or plateau (triangle) velocity, m/s.
    pub peak_velocity_m_s: f64,
    /// Peak acceleration over the analysed cycle (4× fundamental low-pass), m/s².
    pub peak_acceleration_m_s2: f64,
    /// Triangle tests: `Kₑ` from Eq. 16/17 over the constant-velocity portions (Table I).
    pub stiffness: Option<Estimate>,
    /// Sine tests: `Mₑ` from Eq. 18/19 (Table II).
    pub effective_mass: Option<Estimate>,
    /// The dissipative force at peak velocity (Eq. 20).
    pub peak_dissipative: Option<PeakForce>,
    /// Whether the stiffness of this test enters the average.
    pub used_for_stiffness: bool,
    /// Whether the mass of this test enters the average.
    pub used_for_mass: bool,
    /// Flags.
    pub flags: Vec<Flag>,
    /// Triangle tests: the elastic force curve `(ū, F_E(ū))` of Eq. 16/17 over the
    /// constant-velocity portions, m and N.
    pub elastic_curve: Vec<[f64; 2]>,
    /// Sine tests: the inertial force curve `(ā, Mₑā)` of Eq. 18/19, m/s² and N.
    pub inertial_curve: Vec<[f64; 2]>,
    /// The dissipative force curve `(|v̄|, F_D)` of Eq. 20 used in the fits, m/s and N.
    pub dissipative_curve: Vec<[f64; 2]>,
}

/// What was found at one hold-down pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureGroup {
    /// Hold-down pressure, Pa (`None`: tests given without one).
    pub pressure_pa: Option<f64>,
    /// Vertical bearing load `F_z` at that pressure, N.
    pub vertical_force_n: Option<f64>,
    /// Sine tests at this pressure.
    pub sine_tests: usize,
    /// Triangle tests at this pressure.
    pub triangle_tests: usize,
    /// `Kₑ` at this pressure: the mean of the triangle tests used (paper: T1–T8), or from
    /// sine tests at two or more frequencies when there is no triangle test.
    pub stiffness: Option<Estimate>,
    /// Where the stiffness comes from.
    pub stiffness_source: StiffnessSource,
    /// `F_μ` at this pressure with the rest of the dissipative law held at the reference
    /// pressure's (the instantaneous points of every test at this pressure).
    pub coulomb_force: Option<Estimate>,
    /// The paper's route (§3.3): `F_μ` from the sine tests' peak points with `Cₑ` of Eq. 21
    /// held.
    pub paper_coulomb_force_sine: Option<Estimate>,
    /// The same from the triangle tests.
    pub paper_coulomb_force_triangle: Option<Estimate>,
}

/// Eq. 21 fitted as the paper did: `F_D = F_μ + Cₑ|v|^0.5` to the peak points of the sine
/// tests at the reference pressure; then `F_μ` per group with `Cₑ` held, and `μₑ` from those.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperFit {
    /// `F_μ`, N (paper: 26.00 kN).
    pub coulomb_force: Estimate,
    /// `Cₑ`, N/(m/s)^0.5 (paper: 44.58 kN/(m/s)^0.5).
    pub viscous_coefficient: Estimate,
    /// Number of peak points fitted.
    pub points: usize,
    /// Whether only sine tests were used (else every test at the reference pressure).
    pub sine_only: bool,
    /// `μₑ` from the mean of the sine and triangle `F_μ` at each pressure against `F_z`
    /// (paper: 0.44 %).
    pub friction_coefficient: Option<Estimate>,
}

/// The dissipative law fitted to the instantaneous `(|v̄|, F_D)` points of Eq. 20 at the
/// reference pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct LawReport {
    /// Points fitted.
    pub points: usize,
    /// Weighted RMS residual, N.
    pub rms_n: f64,
    /// Condition number of `JᵀJ` scaled to unit diagonal at the optimum (large: parameters
    /// that trade off against each other; `∞`: singular).
    pub condition_number: f64,
    /// Speeds spanned by the points (10th and 90th weighted percentiles), m/s.
    pub speed_range_m_s: [f64; 2],
}

/// The global fit (beyond the paper): every parameter at once from the instantaneous residual
/// of Eq. 23 plus the low-velocity term, over every sample of every test (away from velocity
/// reversals), with `Kₑ` and `F_μ` per pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalFit {
    /// The seven parameters at the reference pressure.
    pub parameters: ParameterEstimates,
    /// `(pressure, Kₑ, F_μ)` per pressure group.
    pub groups: Vec<(Option<f64>, Estimate, Estimate)>,
    /// RMS of the force residual, N.
    pub rms_residual_n: f64,
    /// Samples fitted.
    pub points: usize,
    /// Whether Levenberg–Marquardt met its tolerance.
    pub converged: bool,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Condition number of `JᵀJ` scaled to unit diagonal at the optimum.
    pub condition_number: f64,
}

/// The seven identified parameters by name, each with its status.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterEstimates {
    /// `Mₑ`, kg.
    pub effective_mass_kg: Parameter,
    /// `Kₑ`, N/m.
    pub stiffness_n_per_m: Parameter,
    /// `F_μ`, N.
    pub coulomb_force_n: Parameter,
    /// `Cₑ`, N/(m/s)^α.
    pub viscous_coefficient: Parameter,
    /// `α`.
    pub viscous_exponent: Parameter,
    /// `a`, N.
    pub low_velocity_force_n: Parameter,
    /// `b`, s/m.
    pub low_velocity_decay_s_per_m: Parameter,
}

impl ParameterEstimates {
    /// The parameter of `key`.
    pub fn get(&self, key: IdentifiedKey) -> &Parameter {
        match key {
            IdentifiedKey::EffectiveMass => &self.effective_mass_kg,
            IdentifiedKey::Stiffness => &self.stiffness_n_per_m,
            IdentifiedKey::CoulombForce => &self.coulomb_force_n,
            IdentifiedKey::ViscousCoefficient => &self.viscous_coefficient,
            IdentifiedKey::ViscousExponent => &self.viscous_exponent,
            IdentifiedKey::LowVelocityForce => &self.low_velocity_force_n,
            IdentifiedKey::LowVelocityDecay => &self.low_velocity_decay_s_per_m,
        }
    }

    /// The seven `(key, parameter)` pairs in the contract's order.
    pub fn iter(&self) -> impl Iterator<Item = (IdentifiedKey, &Parameter)> + '_ {
        IdentifiedKey::ALL.into_iter().map(|k| (k, self.get(k)))
    }

    /// The identified model's parameters, if all seven have a value.
    pub fn values(&self) -> Option<IdentifiedParams> {
        let mut params = IdentifiedParams::from_fn(|_| 0.0);
        for (key, p) in self.iter() {
            params.set(key, p.value()?);
        }
        Some(params)
    }

    /// The dissipative law (`F_μ`, `Cₑ`, `α`, `a`, `b`), if each of its parameters has a
    /// value.
    pub fn law(&self) -> Option<DissipativeLaw> {
        Some(DissipativeLaw {
            coulomb_force_n: self.coulomb_force_n.value()?,
            viscous_coefficient: self.viscous_coefficient.value()?,
            exponent: Exponent::new(self.viscous_exponent.value()?),
            low_velocity_force_n: self.low_velocity_force_n.value()?,
            low_velocity_decay_s_per_m: self.low_velocity_decay_s_per_m.value()?,
        })
    }
}

impl Index<IdentifiedKey> for ParameterEstimates {
    type Output = Parameter;

    fn index(&self, key: IdentifiedKey) -> &Parameter {
        self.get(key)
    }
}

/// The result of [`crate::identify`].
#[derive(Debug, Clone, PartialEq)]
pub struct Identification {
    /// The hold-down pressure the final stiffness and Coulomb force belong to, Pa.
    pub reference_pressure_pa: Option<f64>,
    /// The seven parameters (the final estimate): `Mₑ` (mean of the reliable sine tests),
    /// `Kₑ` (mean of the triangle tests at the reference pressure), and `F_μ`, `Cₑ`, `α`,
    /// `a`, `b` (the law fitted to the Eq. 20 points at the reference pressure).
    pub parameters: ParameterEstimates,
    /// `μₑ = F_μ/F_z`: slope through the origin of the per-pressure `F_μ` against `F_z`
    /// (needs tests at known pressures).
    pub friction_coefficient: Option<Estimate>,
    /// Per-test results, in input order.
    pub tests: Vec<TestResult>,
    /// Per-pressure results, by increasing pressure (tests without a pressure first).
    pub pressures: Vec<PressureGroup>,
    /// Eq. 21 as the paper fitted it.
    pub paper_fit: Option<PaperFit>,
    /// The law fit behind the final dissipative parameters.
    pub law: Option<LawReport>,
    /// The global fit, when run.
    pub global: Option<GlobalFit>,
    /// Everything the user should know: parameters not identifiable, flagged tests, fits
    /// that disagree.
    pub warnings: Vec<Warning>,
}

impl Identification {
    /// The identified model's parameters, if all seven have a value.
    pub fn params(&self) -> Option<IdentifiedParams> {
        self.parameters.values()
    }
}
