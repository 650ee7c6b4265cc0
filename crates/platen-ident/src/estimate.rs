//! Estimates with their uncertainty, and the status of an identified parameter.

/// A value with its standard error and 95 % confidence interval.
///
/// The interval is `value ± t₀.₉₇₅(dof)·std_error` with Student's t quantile for the
/// estimate's degrees of freedom (the number of *independent* observations minus the
/// parameters fitted; see [`crate`] docs, Conventions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// Its standard error (same unit).
    pub std_error: f64,
    /// Lower end of the 95 % confidence interval.
    pub ci95_low: f64,
    /// Upper end of the 95 % confidence interval.
    pub ci95_high: f64,
    /// Degrees of freedom behind the interval.
    pub dof: f64,
}

impl Estimate {
    /// An estimate with a standard error and `dof` degrees of freedom.
    pub fn new(value: f64, std_error: f64, dof: f64) -> Self {
        let half = student_t_975(dof) * std_error;
        Self {
            value,
            std_error,
            ci95_low: value - half,
            ci95_high: value + half,
            dof,
        }
    }

    /// The standard error relative to the value (`∞` for a zero value).
    pub fn relative_std_error(&self) -> f64 {
        if self.value == 0.0 {
            f64::INFINITY
        } else {
            (self.std_error / self.value).abs()
        }
    }

    /// The mean of `values` with the standard error of the mean, `s/√n`
    /// (`n − 1` degrees of freedom). `None` for fewer than two values.
    pub fn mean_of(values: &[f64]) -> Option<Self> {
        let n = values.len();
        if n < 2 {
            return None;
        }
        let nf = n as f64;
        let mean = values.iter().sum::<f64>() / nf;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (nf - 1.0);
        Some(Self::new(mean, (var / nf).sqrt(), nf - 1.0))
    }

    /// Estimates pooled: none, the one, or the mean of their values ([`Estimate::mean_of`]).
    pub(crate) fn pooled(estimates: &[Estimate]) -> Option<Self> {
        match estimates {
            [] => None,
            [one] => Some(*one),
            _ => Self::mean_of(&estimates.iter().map(|e| e.value).collect::<Vec<_>>()),
        }
    }
}

/// The status of one identified parameter in the final estimate.
#[derive(Debug, Clone, PartialEq)]
pub enum Parameter {
    /// Estimated from the data.
    Estimated(Estimate),
    /// Held at a value (given by the user, or set to zero because the data show the term is
    /// not significant); the reason says which.
    Fixed {
        /// The value used.
        value: f64,
        /// Why it is fixed.
        reason: String,
    },
    /// The tests given cannot determine it; the reason says what is missing.
    NotIdentifiable {
        /// What is missing.
        reason: String,
    },
}

impl Parameter {
    /// The value, if there is one.
    pub fn value(&self) -> Option<f64> {
        match self {
            Parameter::Estimated(e) => Some(e.value),
            Parameter::Fixed { value, .. } => Some(*value),
            Parameter::NotIdentifiable { .. } => None,
        }
    }

    /// The estimate with its uncertainty, if estimated.
    pub fn estimate(&self) -> Option<&Estimate> {
        match self {
            Parameter::Estimated(e) => Some(e),
            _ => None,
        }
    }

    /// `"estimated"`, `"fixed"` or `"not_identifiable"`.
    pub fn status(&self) -> &'static str {
        match self {
            Parameter::Estimated(_) => "estimated",
            Parameter::Fixed { .. } => "fixed",
            Parameter::NotIdentifiable { .. } => "not_identifiable",
        }
    }
}

/// Student's t quantile `t₀.₉₇₅(ν)` (two-sided 95 %), for real `ν ≥ 1`.
///
/// Tabulated for `ν = 1…10` (interpolated linearly in `1/ν` between whole values, as
/// correlated residuals give fractional degrees of freedom); above, the Cornish–Fisher
/// expansion about the normal quantile to `ν⁻³` (Abramowitz & Stegun 26.7.5), within 10⁻⁴
/// of the exact value there.
pub fn student_t_975(dof: f64) -> f64 {
    const Z: f64 = 1.959_963_984_540_054;
    const TABLE: [f64; 10] = [
        12.706_204_736,
        4.302_652_730,
        3.182_446_305,
        2.776_445_105,
        2.570_581_836,
        2.446_911_851,
        2.364_624_252,
        2.306_004_135,
        2.262_157_163,
        2.228_138_852,
    ];
    if !dof.is_finite() || dof > 1e7 {
        return Z;
    }
    if dof <= 1.0 {
        return TABLE[0];
    }
    if dof <= 10.0 {
        let lo = dof.floor();
        let (a, b) = (TABLE[lo as usize - 1], TABLE[(lo as usize).min(9)]);
        if lo == dof || lo >= 10.0 {
            return a;
        }
        let w = (1.0 / lo - 1.0 / dof) / (1.0 / lo - 1.0 / (lo + 1.0));
        return a + w * (b - a);
    }
    let z = Z;
    let (z3, z5, z7) = (z.powi(3), z.powi(5), z.powi(7));
    let g1 = (z3 + z) / 4.0;
    let g2 = (5.0 * z5 + 16.0 * z3 + 3.0 * z) / 96.0;
    let g3 = (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / 384.0;
    z + g1 / dof + g2 / (dof * dof) + g3 / (dof * dof * dof)
}

/// Whether two estimates of the parameter `key` from different fits disagree: by more than
/// three of their combined standard errors *and* by more than `relative` of the larger value
/// (of 1 for the exponent α, which is dimensionless and near 1).
pub(crate) fn fits_disagree(
    key: platen_model::IdentifiedKey,
    a: &Estimate,
    b: &Estimate,
    relative: f64,
) -> bool {
    let diff = (a.value - b.value).abs();
    let scale = if key == platen_model::IdentifiedKey::ViscousExponent {
        1.0
    } else {
        a.value.abs().max(b.value.abs()).max(f64::MIN_POSITIVE)
    };
    let combined = (a.std_error.powi(2) + b.std_error.powi(2)).sqrt();
    diff > 3.0 * combined && diff > relative * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_tables() {
        // Tabulated t_0.975: ν = 1, 2, 3, 5, 10, 30, ∞.
        let table = [
            (1.0, 12.706),
            (2.0, 4.303),
            (3.0, 3.182),
            (5.0, 2.571),
            (10.0, 2.228),
            (11.0, 2.201),
            (30.0, 2.042),
            (1e9, 1.960),
        ];
        for (nu, t) in table {
            let q = student_t_975(nu);
            assert!((q / t - 1.0).abs() < 5e-4, "ν = {nu}: {q} vs {t}");
        }
        // Fractional degrees of freedom fall between their neighbours.
        let q = student_t_975(2.5);
        assert!(q < 4.303 && q > 3.182, "{q}");
    }

    #[test]
    fn the_mean_of_values_has_the_textbook_standard_error() {
        let e = Estimate::mean_of(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(e.value, 2.5);
        // s² = 5/3, se = √(5/12).
        assert!((e.std_error - (5.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert_eq!(e.dof, 3.0);
        assert!(Estimate::mean_of(&[1.0]).is_none());
    }
}
