//! Physically inconsistent estimates are flagged, never silently returned: a negative
//! stiffness (and the `Kₑ ≥ 0` constraint that says when it is active), a static friction
//! that no recorded force overcomes, an output-error mass far from the equation error's.
//!
//! The records are exact data of the identified LHPOST model (its inverse) with the force
//! changed by arithmetic in the test, so the truth each check must find is known.

use platen_ident::{identify_records, IdentifiedKey, RecordSettings, RecordWarning, TestRecord};
use platen_integrate::{inverse, Trajectory};
use platen_model::preset;
use platen_scenario::generate::white_noise_motion;

const RATE_HZ: f64 = 256.0;

/// White-noise motion of the LHPOST model; the force with `extra_stiffness` N/m of elastic
/// force added (a negative value makes the record's stiffness negative) and scaled by
/// `force_scale`.
fn record(extra_stiffness_n_per_m: f64, force_scale: f64) -> TestRecord {
    let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
    let motion = white_noise_motion(1.0, (0.3, 8.0), 5, RATE_HZ, 20.0).unwrap();
    let mut out = Trajectory::with_capacity(motion.len());
    inverse(&model, &motion, &mut out);
    let f: Vec<f64> = out
        .force_n
        .iter()
        .zip(&out.u_m)
        .map(|(f, u)| force_scale * (f + extra_stiffness_n_per_m * u))
        .collect();
    TestRecord::from_rate("wn", RATE_HZ, out.u_m, out.a_m_s2, f)
        .unwrap()
        .with_velocity(out.v_m_s)
        .unwrap()
}

fn settings(nonnegative_stiffness: bool) -> platen_ident::ValidRecordSettings {
    RecordSettings {
        output_error: false,
        nonnegative_stiffness,
        ..RecordSettings::default()
    }
    .build()
    .unwrap()
}

/// The LHPOST's identified Kₑ (paper Eq. 22): 1.266 MN/m. Adding −1.5 MN/m of elastic force
/// makes the record's stiffness −0.234 MN/m.
const KE_N_PER_M: f64 = 1.266e6;

#[test]
fn a_negative_stiffness_is_flagged_and_the_constraint_says_when_it_is_active() {
    let rec = record(-1.5e6, 1.0);
    let id = identify_records(std::slice::from_ref(&rec), &settings(false)).unwrap();
    let k = id.parameters.get(IdentifiedKey::Stiffness).value().unwrap();
    // Exact data: the fit recovers the record's stiffness (noise-free, 0.1 % covers the
    // band-limited record's edge effects).
    assert!((k - (KE_N_PER_M - 1.5e6)).abs() < 1e-3 * 1.5e6, "Kₑ = {k}");
    assert!(
        id.warnings.iter().any(|w| matches!(w, RecordWarning::NegativeEstimate { key: IdentifiedKey::Stiffness, value, .. } if *value == k)),
        "{:?}",
        id.warnings
    );
    assert!(!id
        .warnings
        .iter()
        .any(|w| matches!(w, RecordWarning::StiffnessConstrained)));

    let held = identify_records(std::slice::from_ref(&rec), &settings(true)).unwrap();
    assert_eq!(
        held.parameters.get(IdentifiedKey::Stiffness).value(),
        Some(0.0),
        "held at its bound"
    );
    assert!(held
        .warnings
        .iter()
        .any(|w| matches!(w, RecordWarning::StiffnessConstrained)));
    assert!(!held
        .warnings
        .iter()
        .any(|w| matches!(w, RecordWarning::NegativeEstimate { .. })));

    // On the true LHPOST record the constraint is inactive and changes nothing.
    let true_rec = record(0.0, 1.0);
    let free = identify_records(std::slice::from_ref(&true_rec), &settings(false)).unwrap();
    let held = identify_records(std::slice::from_ref(&true_rec), &settings(true)).unwrap();
    assert_eq!(free.parameters, held.parameters);
    assert!(!held.warnings.iter().any(|w| matches!(
        w,
        RecordWarning::StiffnessConstrained | RecordWarning::NegativeEstimate { .. }
    )));
}

#[test]
fn no_warning_of_implausibility_on_a_plausible_record() {
    let id = identify_records(&[record(0.0, 1.0)], &settings(false)).unwrap();
    assert!(
        !id.warnings.iter().any(|w| matches!(
            w,
            RecordWarning::NegativeEstimate { .. }
                | RecordWarning::FrictionAbovePeakForce { .. }
                | RecordWarning::OutputErrorImplausible { .. }
        )),
        "{:?}",
        id.warnings
    );
}
