//! Physically inconsistent estimates, flagged: a mass that is not positive or a negative
//! stiffness, a static friction that no recorded force could overcome, an output-error check
//! that lands on an implausible mass. Each is a [`RecordWarning`]; none changes an estimate.

use platen_model::IdentifiedKey;

use crate::estimate::Parameter;
use crate::record::TestRecord;
use crate::result::ParameterEstimates;

use super::result::{FitKind, RecordWarning};
use super::separable::{COULOMB, LOW_FORCE};

/// Largest ratio between the output error's mass and the equation error's (either way) that
/// can still count as a check. The two fits of a record that determines the mass agree within
/// a few per cent ([`crate::fit_agreement`]: 2 %); a factor of two is far outside anything
/// the fits' different weighting of the data explains.
pub(crate) const OUTPUT_ERROR_MASS_RATIO: f64 = 2.0;

/// Appends the plausibility warnings of a fit: `ee` and `oe` the equation- and output-error
/// parameters, `stiffness_clamped` whether `Kₑ ≥ 0` was imposed and is active, `full` the
/// equation error's full parameter vector (for `F_μ + a`).
pub(crate) fn check(
    ee: &ParameterEstimates,
    oe: Option<&ParameterEstimates>,
    stiffness_clamped: bool,
    full: &[f64],
    records: &[TestRecord],
    warnings: &mut Vec<RecordWarning>,
) {
    if stiffness_clamped {
        warnings.push(RecordWarning::StiffnessConstrained);
    }
    let fits =
        std::iter::once((FitKind::EquationError, ee)).chain(oe.map(|p| (FitKind::OutputError, p)));
    for (fit, params) in fits {
        for key in [IdentifiedKey::EffectiveMass, IdentifiedKey::Stiffness] {
            let p = params.get(key);
            let Some(value) = p.value() else { continue };
            let impossible = match key {
                IdentifiedKey::EffectiveMass => value <= 0.0,
                _ => value < 0.0,
            };
            if impossible {
                warnings.push(RecordWarning::NegativeEstimate {
                    fit,
                    key,
                    value,
                    ci95: match p {
                        Parameter::Estimated(e) => Some([e.ci95_low, e.ci95_high]),
                        _ => None,
                    },
                });
            }
        }
    }
    // The static friction against the largest force swing of any record (half its
    // peak-to-peak: a force offset does not move the platen).
    let static_friction_n = full[COULOMB] + full[LOW_FORCE];
    let peak_force_n = records
        .iter()
        .map(|r| {
            let (lo, hi) = r
                .force_n()
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &f| {
                    (lo.min(f), hi.max(f))
                });
            0.5 * (hi - lo)
        })
        .fold(0.0, f64::max);
    if static_friction_n > peak_force_n {
        warnings.push(RecordWarning::FrictionAbovePeakForce {
            static_friction_n,
            peak_force_n,
        });
    }
    if let (Some(oe), Some(m_ee)) = (oe, ee.get(IdentifiedKey::EffectiveMass).value()) {
        if let Some(m_oe) = oe.get(IdentifiedKey::EffectiveMass).value() {
            let ratio = m_oe / m_ee;
            if m_ee > 0.0
                && m_oe > 0.0
                && !(1.0 / OUTPUT_ERROR_MASS_RATIO..=OUTPUT_ERROR_MASS_RATIO).contains(&ratio)
            {
                warnings.push(RecordWarning::OutputErrorImplausible {
                    key: IdentifiedKey::EffectiveMass,
                    equation_error: m_ee,
                    output_error: m_oe,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(value: f64) -> Parameter {
        Parameter::Fixed {
            value,
            reason: "test".into(),
        }
    }

    fn params(mass_kg: f64, stiffness_n_per_m: f64) -> ParameterEstimates {
        ParameterEstimates {
            effective_mass_kg: fixed(mass_kg),
            stiffness_n_per_m: fixed(stiffness_n_per_m),
            coulomb_force_n: fixed(25e3),
            viscous_coefficient: fixed(4e4),
            viscous_exponent: fixed(0.5),
            low_velocity_force_n: fixed(12e3),
            low_velocity_decay_s_per_m: fixed(78.5),
        }
    }

    /// A record whose force swings ±`half_range_n` about an offset of 5 kN.
    fn rec(half_range_n: f64) -> TestRecord {
        let n = 400;
        let f = (0..n)
            .map(|i| 5e3 + half_range_n * (i as f64 * 0.05).sin().signum())
            .collect();
        TestRecord::from_rate("r", 100.0, vec![0.0; n], vec![0.0; n], f).unwrap()
    }

    fn full() -> Vec<f64> {
        let mut f = vec![0.0; 7];
        f[COULOMB] = 25e3;
        f[LOW_FORCE] = 12e3;
        f
    }

    #[test]
    fn a_static_friction_beyond_every_force_swing_is_flagged() {
        // F_μ + a = 37 kN against a ±30 kN swing (its 5 kN offset does not count).
        let mut w = Vec::new();
        check(
            &params(144e3, 1.266e6),
            None,
            false,
            &full(),
            &[rec(30e3)],
            &mut w,
        );
        assert_eq!(
            w,
            vec![RecordWarning::FrictionAbovePeakForce {
                static_friction_n: 37e3,
                peak_force_n: 30e3
            }]
        );
        let mut w = Vec::new();
        check(
            &params(144e3, 1.266e6),
            None,
            false,
            &full(),
            &[rec(40e3)],
            &mut w,
        );
        assert!(w.is_empty(), "{w:?}");
    }

    #[test]
    fn an_output_error_mass_off_by_more_than_twice_is_flagged_and_a_negative_mass_too() {
        let mut w = Vec::new();
        let ee = params(800.0, 0.0);
        check(
            &ee,
            Some(&params(47e3, 0.0)),
            false,
            &full(),
            &[rec(1e6)],
            &mut w,
        );
        assert_eq!(
            w,
            vec![RecordWarning::OutputErrorImplausible {
                key: IdentifiedKey::EffectiveMass,
                equation_error: 800.0,
                output_error: 47e3
            }]
        );
        let mut w = Vec::new();
        check(
            &ee,
            Some(&params(1500.0, 0.0)),
            false,
            &full(),
            &[rec(1e6)],
            &mut w,
        );
        assert!(w.is_empty(), "within a factor of two: {w:?}");
        let mut w = Vec::new();
        check(
            &params(-10.0, 1.0),
            None,
            false,
            &full(),
            &[rec(1e6)],
            &mut w,
        );
        assert!(matches!(
            w.as_slice(),
            [RecordWarning::NegativeEstimate { key: IdentifiedKey::EffectiveMass, value, ci95: None, .. }] if *value == -10.0
        ));
    }
}
