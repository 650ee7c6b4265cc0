//! Settings of the any-record method, validated once.

use std::ops::Deref;

use crate::error::{IdentError, Result};

/// How the any-record method works. [`Default`] gives the choices documented on each field.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordSettings {
    /// Crossover frequency of the velocity estimate made from `u` and `a` when a record has
    /// no velocity channel, Hz (default 2, as the periodic method).
    pub crossover_hz: f64,
    /// Samples slower than this are left out of the equation-error fit, m/s (default
    /// 0.002). At rest friction is set-valued (anything within `±F_s`) and the sign of a
    /// velocity estimate whose error is ~0.3 mm/s (an accelerometer with 0.003 g of noise
    /// integrated above 2 Hz) is not known below ~1 mm/s; 2 mm/s leaves a margin of six
    /// such errors. The output-error refinement uses every sample.
    pub min_speed_m_s: f64,
    /// Samples within this time of either end of a record are left out, s (default 0.25:
    /// the crossover filter's edge transient, ~1/(2f_c)).
    pub edge_s: f64,
    /// The viscous exponent `α`: `None` fits it (default), `Some(α)` holds it.
    pub viscous_exponent: Option<f64>,
    /// Whether to fit the low-velocity term `a·e^(−b|v|)` (default true; it is left out,
    /// `a = 0`, when the record does not determine it).
    pub low_velocity_term: bool,
    /// Whether to refine by output error (forward simulation with the recorded force,
    /// fitted to the measured displacement and acceleration; default true).
    pub output_error: bool,
    /// RK4 steps per sample interval of the output-error simulations (default 2: at 204.8 Hz
    /// a 2.4 ms step, where the RK4's error on the platen's 0.5 Hz mode and on the 20 Hz
    /// content of a test record is below 10⁻⁶ of the motion).
    pub steps_per_sample: u32,
    /// Most Levenberg–Marquardt iterations of the output-error fit (default 40).
    pub output_error_iterations: usize,
    /// Speeds at which the dissipative law's confidence band is reported (default 41).
    pub band_points: usize,
    /// Whether to remove the sensors' noise from the equation error's normal equations
    /// (default true). Noise on the regressors biases least squares towards zero by
    /// `σ²_noise/σ²_signal`: an accelerometer with 0.003 g of white noise on a white-noise
    /// test of 0.05 g RMS makes `Mₑ` 3 % low. The noise variance is estimated from each
    /// channel ([`crate::anyrecord`] docs) and `n·σ²` taken off `Σa²` and `Σu²`
    /// (corrected least squares, Fuller 1987 §2.2).
    pub noise_correction: bool,
    /// Whether to hold the stiffness at `Kₑ ≥ 0` (default false). A table without a
    /// restoring stiffness of its own (bearings only) can come out with a slightly negative
    /// `Kₑ` from noise or a drifting displacement transducer; with this set the fit is
    /// constrained, and [`crate::RecordWarning::StiffnessConstrained`] says when the bound is
    /// active. Without it a negative estimate is kept and flagged
    /// ([`crate::RecordWarning::NegativeEstimate`]).
    pub nonnegative_stiffness: bool,
}

impl Default for RecordSettings {
    fn default() -> Self {
        Self {
            crossover_hz: 2.0,
            min_speed_m_s: 0.002,
            edge_s: 0.25,
            viscous_exponent: None,
            low_velocity_term: true,
            output_error: true,
            steps_per_sample: 2,
            output_error_iterations: 40,
            band_points: 41,
            noise_correction: true,
            nonnegative_stiffness: false,
        }
    }
}

/// Checked [`RecordSettings`] ([`RecordSettings::build`]), read through `Deref`. The
/// default is [`RecordSettings::default`], which is valid.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ValidRecordSettings(RecordSettings);

impl Deref for ValidRecordSettings {
    type Target = RecordSettings;

    fn deref(&self) -> &RecordSettings {
        &self.0
    }
}

fn bad(name: &'static str, value: f64, expected: &'static str) -> Result<()> {
    Err(IdentError::InvalidSetting {
        name,
        value,
        expected,
    })
}

impl RecordSettings {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`IdentError::InvalidSetting`] naming the first bad one.
    pub fn build(&self) -> Result<ValidRecordSettings> {
        if !(self.crossover_hz.is_finite() && self.crossover_hz > 0.0) {
            bad("crossover_hz", self.crossover_hz, "a frequency > 0 Hz")?;
        }
        if !(self.min_speed_m_s.is_finite() && self.min_speed_m_s > 0.0) {
            bad("min_speed_m_s", self.min_speed_m_s, "a speed > 0 m/s")?;
        }
        if !(self.edge_s.is_finite() && self.edge_s >= 0.0) {
            bad("edge_s", self.edge_s, "a time >= 0 s")?;
        }
        if let Some(alpha) = self.viscous_exponent {
            if !(alpha.is_finite() && (0.0..=1.0).contains(&alpha)) {
                bad("viscous_exponent", alpha, "an exponent in [0, 1]")?;
            }
        }
        if !(1..=64).contains(&self.steps_per_sample) {
            bad(
                "steps_per_sample",
                f64::from(self.steps_per_sample),
                "1 to 64 RK4 steps per sample",
            )?;
        }
        if !(1..=1000).contains(&self.output_error_iterations) {
            bad(
                "output_error_iterations",
                self.output_error_iterations as f64,
                "1 to 1000 iterations",
            )?;
        }
        if !(2..=10_000).contains(&self.band_points) {
            bad("band_points", self.band_points as f64, "2 to 10000 speeds")?;
        }
        Ok(ValidRecordSettings(self.clone()))
    }
}
