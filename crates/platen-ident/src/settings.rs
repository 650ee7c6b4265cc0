//! Settings of the identification, with the paper's choices as defaults.

use std::ops::Deref;

use platen_model::{
    LHPOST_HOLD_DOWN_FORCE_AT_NOMINAL_N, LHPOST_NOMINAL_PRESSURE_PA, LHPOST_SUPPORTED_WEIGHT_N,
};

use crate::error::{IdentError, Result};

/// The vertical force `F_z` on the bearings as a function of the hold-down pressure `p`:
/// `F_z = W + F_hd·p/p_nom`, used to turn Coulomb forces into a friction coefficient
/// (paper §3.4, Fig. 8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalLoad {
    /// Weight carried by the bearings with unpressurised struts `W`, N.
    pub supported_weight_n: f64,
    /// Total hold-down force of the struts at the nominal pressure `F_hd`, N.
    pub hold_down_force_n: f64,
    /// The nominal pressure `p_nom`, Pa.
    pub nominal_pressure_pa: f64,
}

impl VerticalLoad {
    /// The LHPOST (paper §1.4, §3.2, §3.4): `W = 1.613 MN`, `F_hd = 2 × 2085 kN` at
    /// 13.8 MPa, so `F_z` = 1.613, 3.698 and 5.783 MN at 0, 6.9 and 13.8 MPa, as in the
    /// `lhpost-2008` preset of `platen-model`, whose constants these are.
    pub fn lhpost_2008() -> Self {
        Self {
            supported_weight_n: LHPOST_SUPPORTED_WEIGHT_N,
            hold_down_force_n: LHPOST_HOLD_DOWN_FORCE_AT_NOMINAL_N,
            nominal_pressure_pa: LHPOST_NOMINAL_PRESSURE_PA,
        }
    }

    /// `F_z` at hold-down pressure `pressure_pa`, N.
    pub fn vertical_force_n(&self, pressure_pa: f64) -> f64 {
        self.supported_weight_n + self.hold_down_force_n * pressure_pa / self.nominal_pressure_pa
    }
}

/// How the identification is done. [`Default`] gives the paper's method (§3).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Cut-off of the zero-phase low-pass for inertial and elastic forces, as a multiple of
    /// the test's fundamental frequency (default 4: "four times the fundamental frequency …
    /// to keep the first few harmonics", §3).
    pub inertial_cutoff_factor: f64,
    /// Order of that Butterworth low-pass, run forward and backward (default 4: gain
    /// `1 − 4⁻⁸ ≈ 1 − 1.5·10⁻⁵` at the fundamental).
    pub butterworth_order: usize,
    /// Cut-off of the FIR low-pass for dissipative forces, Hz (default 8: "well above the
    /// frequencies of the tests, but below the oil-column frequency", §3.3). Raised to the
    /// inertial cut-off for a test whose 4th harmonic lies above it.
    pub dissipative_cutoff_hz: f64,
    /// Length of that FIR, s (default 1: order 512 at the paper's 512 Hz; the order scales
    /// with the sample rate so the filter stays the same).
    pub dissipative_filter_length_s: f64,
    /// Crossover frequency between displacement and accelerometer, Hz (default 2): of the
    /// velocity estimated when a record has no velocity channel, and of the acceleration
    /// used for the inertial force of sine tests.
    pub crossover_hz: f64,
    /// The viscous exponent `α`: `None` fits it (default), `Some(α)` holds it (Eq. 21 uses
    /// 0.5).
    pub viscous_exponent: Option<f64>,
    /// Whether to fit the low-velocity term `a·e^(−b|v|)` of Eq. 22 (default true; it is
    /// kept only when the data determine it).
    pub low_velocity_term: bool,
    /// The vertical bearing load as a function of pressure (default: the LHPOST's).
    pub vertical_load: VerticalLoad,
    /// Hold-down pressure of the final estimate, Pa (default: the highest pressure among the
    /// tests, the operational one of a shakedown). Must be one of the tests' pressures.
    pub reference_pressure_pa: Option<f64>,
    /// Whether to run the global fit of Eq. 23 over every test as a cross-check (default
    /// true).
    pub global_fit: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            inertial_cutoff_factor: 4.0,
            butterworth_order: 4,
            dissipative_cutoff_hz: 8.0,
            dissipative_filter_length_s: 1.0,
            crossover_hz: 2.0,
            viscous_exponent: None,
            low_velocity_term: true,
            vertical_load: VerticalLoad::lhpost_2008(),
            reference_pressure_pa: None,
            global_fit: true,
        }
    }
}

/// Settings that have been checked ([`Settings::build`]): what [`crate::identify`] takes, so
/// the physics never re-checks them. Read them through `Deref`.
#[derive(Debug, Clone, PartialEq)]
pub struct ValidSettings(Settings);

impl Deref for ValidSettings {
    type Target = Settings;

    fn deref(&self) -> &Settings {
        &self.0
    }
}

impl Default for ValidSettings {
    /// The paper's method ([`Settings::default`]), which is valid.
    fn default() -> Self {
        Self(Settings::default())
    }
}

impl TryFrom<Settings> for ValidSettings {
    type Error = IdentError;

    fn try_from(settings: Settings) -> Result<Self> {
        settings.check_filters()?;
        settings.check_model()?;
        Ok(Self(settings))
    }
}

fn bad(name: &'static str, value: f64, expected: &'static str) -> Result<()> {
    Err(IdentError::InvalidSetting {
        name,
        value,
        expected,
    })
}

impl Settings {
    /// Checks every setting and returns them validated.
    ///
    /// # Errors
    /// [`IdentError::InvalidSetting`] naming the first bad one.
    pub fn build(&self) -> Result<ValidSettings> {
        ValidSettings::try_from(self.clone())
    }

    /// The filter and cycle settings.
    fn check_filters(&self) -> Result<()> {
        if !(self.inertial_cutoff_factor.is_finite() && self.inertial_cutoff_factor >= 2.0) {
            return bad(
                "inertial_cutoff_factor",
                self.inertial_cutoff_factor,
                "a multiple of the fundamental >= 2 (the paper's 4 keeps the first harmonics)",
            );
        }
        if !(1..=8).contains(&self.butterworth_order) {
            return bad(
                "butterworth_order",
                self.butterworth_order as f64,
                "an order in 1..=8",
            );
        }
        if !(self.dissipative_cutoff_hz.is_finite() && self.dissipative_cutoff_hz > 0.0) {
            return bad(
                "dissipative_cutoff_hz",
                self.dissipative_cutoff_hz,
                "a cut-off > 0 Hz",
            );
        }
        if !(self.dissipative_filter_length_s.is_finite() && self.dissipative_filter_length_s > 0.0)
        {
            return bad(
                "dissipative_filter_length_s",
                self.dissipative_filter_length_s,
                "a length > 0 s",
            );
        }
        if !(self.crossover_hz.is_finite() && self.crossover_hz > 0.0) {
            return bad("crossover_hz", self.crossover_hz, "a frequency > 0 Hz");
        }
        Ok(())
    }

    /// The settings of the model and its reference.
    fn check_model(&self) -> Result<()> {
        if let Some(alpha) = self.viscous_exponent {
            if !(alpha.is_finite() && (0.0..=1.0).contains(&alpha)) {
                return bad("viscous_exponent", alpha, "an exponent in [0, 1]");
            }
        }
        let v = &self.vertical_load;
        for (name, value) in [
            ("vertical_load.supported_weight_n", v.supported_weight_n),
            ("vertical_load.hold_down_force_n", v.hold_down_force_n),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return bad(name, value, "a force >= 0 N");
            }
        }
        if !(v.nominal_pressure_pa.is_finite() && v.nominal_pressure_pa > 0.0) {
            return bad(
                "vertical_load.nominal_pressure_pa",
                v.nominal_pressure_pa,
                "a pressure > 0 Pa",
            );
        }
        if let Some(p) = self.reference_pressure_pa {
            if !(p.is_finite() && p >= 0.0) {
                return bad("reference_pressure_pa", p, "a pressure >= 0 Pa");
            }
        }
        Ok(())
    }
}
