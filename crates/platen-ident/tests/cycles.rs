//! Cycle handling (§3): period, waveform, the steady-state cycle and its alignment, filters
//! scaled with the sample rate, and records that cannot be used.

mod common;

use std::f64::consts::PI;

use platen_ident::{identify, Flag, IdentError, Settings, TestKind, TestRecord, ValidSettings};
use platen_integrate::Motion;

fn nominal() -> platen_model::IdentifiedParams {
    platen_model::preset::lhpost_2008_identified(13.8e6)
}

/// A sine of `amp` about `offset` at `f` Hz starting at phase `phase`, sampled at `rate` for
/// `duration` s, with up to a 3rd-harmonic `h3` (relative) for distortion.
fn sine(amp: f64, offset: f64, f: f64, phase: f64, h3: f64, rate: f64, duration: f64) -> Motion {
    let n = (duration * rate) as usize + 1;
    let w = 2.0 * PI * f;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
    let u = t
        .iter()
        .map(|t| offset + amp * ((w * t + phase).sin() + h3 * (3.0 * (w * t + phase)).sin()))
        .collect();
    let v = t
        .iter()
        .map(|t| amp * w * ((w * t + phase).cos() + 3.0 * h3 * (3.0 * (w * t + phase)).cos()))
        .collect();
    let a = t
        .iter()
        .map(|t| -amp * w * w * ((w * t + phase).sin() + 9.0 * h3 * (3.0 * (w * t + phase)).sin()))
        .collect();
    Motion::new(t, u, v, a).unwrap()
}

/// A sine with an offset, an arbitrary starting phase and a non-whole number of cycles: the
/// period comes out to 10⁻⁴, the second-to-last full cycle is used, and it starts at the
/// upward crossing of the offset, so the displacement peaks a quarter period in.
#[test]
fn the_period_and_the_aligned_second_to_last_cycle_are_found_in_any_sine() {
    let motion = sine(0.1, 0.013, 0.7, 1.1, 0.0, 512.0, 9.3);
    let rec = common::record_of_motion("s", &motion, &nominal(), 13.8e6, &Default::default(), 2);
    let tri = common::nominal_records(&["T7", "T8"], &Default::default(), 4);
    let id = identify(
        &[rec, tri[0].clone(), tri[1].clone()],
        &ValidSettings::default(),
    )
    .unwrap();
    let c = &id.tests[0].cycle;
    assert!((c.period_s * 0.7 - 1.0).abs() < 1e-4, "{}", c.period_s);
    assert!((c.offset_m - 0.013).abs() < 1e-4, "{}", c.offset_m);
    // First upward crossing at (2π − 1.1)/(2π·0.7) = 1.178 s; full cycles up to 9.3 s: 5.
    assert_eq!(c.full_cycles, 5);
    assert_eq!(c.cycle_used, 4);
    // u = offset + A·sin(ωt + φ) crosses upward where ωt + φ = 2πk.
    let k = ((0.7 * 2.0 * PI * c.cycle_start_s + 1.1) / (2.0 * PI)).round();
    let want = (2.0 * PI * k - 1.1) / (2.0 * PI * 0.7);
    assert!(
        (c.cycle_start_s - want).abs() < 2e-4,
        "{} vs {want}",
        c.cycle_start_s
    );
    assert_eq!(id.tests[0].kind, TestKind::Sine);
    let m = id.tests[0].effective_mass.unwrap().value;
    assert!((m / 144e3 - 1.0).abs() < 0.01, "{m}");
}

/// A sine with 10 % third harmonic is "distorted" (S12 in the paper): flagged, mass not used.
#[test]
fn a_distorted_sine_is_flagged_and_left_out_of_the_mass() {
    let motion = sine(0.1, 0.0, 0.8, 0.0, 0.1, 512.0, 6.25);
    let bad = common::record_of_motion("bad", &motion, &nominal(), 13.8e6, &Default::default(), 2);
    let mut records = common::nominal_records(&["S7", "S9", "T7", "T8"], &Default::default(), 8);
    records.push(bad);
    let id = identify(&records, &ValidSettings::default()).unwrap();
    let t = id.tests.iter().find(|t| t.name == "bad").unwrap();
    assert!(
        t.flags.iter().any(
            |f| matches!(f, Flag::Distorted { harmonic_distortion } if *harmonic_distortion > 0.09)
        ),
        "{:?}",
        t.flags
    );
    assert!(!t.used_for_mass);
}

/// A waveform given in a manifest is used even when the data disagree, with a flag.
#[test]
fn a_given_waveform_that_disagrees_with_the_data_is_flagged() {
    let mut records = common::nominal_records(&["S7", "S9", "T7", "T8"], &Default::default(), 8);
    records[3] = records[3].clone().with_kind(TestKind::Sine);
    let id = identify(&records, &ValidSettings::default()).unwrap();
    assert_eq!(id.tests[3].kind, TestKind::Sine);
    assert!(id.tests[3].kind_given);
    assert!(id.tests[3].flags.contains(&Flag::KindMismatch {
        detected: TestKind::Triangle
    }));
}

/// At 1024 Hz (the DAQ's rate) the dissipative FIR is twice as long and the results are the
/// same; without a velocity channel the crossover estimate is made from u and a.
#[test]
fn records_at_1024_hz_and_records_without_velocity_give_the_same_parameters() {
    let params = nominal();
    let tests = common::tests_named(&["S4", "S6", "S9", "S11", "T4", "T6", "T8", "T10"]);
    let mut fast = Vec::new();
    let mut no_v = Vec::new();
    for (k, t) in tests.iter().enumerate() {
        let m = t.motion(1024.0);
        fast.push(common::record_of_motion(
            &t.name,
            &m,
            &params,
            13.8e6,
            &Default::default(),
            k as u64,
        ));
        let r = common::record(&t.name, t, &params, 13.8e6, &Default::default(), k as u64);
        no_v.push(
            TestRecord::from_rate(
                t.name.clone(),
                r.sample_rate_hz(),
                r.u_m().to_vec(),
                r.a_m_s2().to_vec(),
                r.force_n().to_vec(),
            )
            .unwrap(),
        );
    }
    for records in [fast, no_v] {
        let id = identify(&records, &ValidSettings::default()).unwrap();
        let p = id.params().unwrap();
        assert!((p.effective_mass_kg / 144e3 - 1.0).abs() < 0.01, "{p:?}");
        assert!((p.stiffness_n_per_m / 1.266e6 - 1.0).abs() < 0.01, "{p:?}");
        assert!(
            (p.viscous_coefficient / 44.58e3 - 1.0).abs() < 0.10,
            "{p:?}"
        );
        assert!((p.viscous_exponent - 0.5).abs() < 0.05, "{p:?}");
    }
}

#[test]
fn a_record_that_is_not_periodic_is_rejected_by_name() {
    let n = 4096;
    // A ramp: the displacement never comes back.
    let u: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let rec = TestRecord::from_rate("ramp.csv", 512.0, u, vec![0.0; n], vec![0.0; n]).unwrap();
    let err = identify(&[rec], &ValidSettings::default()).unwrap_err();
    assert!(
        matches!(err, IdentError::NotPeriodic { ref test, .. } if test == "ramp.csv"),
        "{err}"
    );
    assert!(err.to_string().contains("ramp.csv"));

    // Irregular crossings: a chirp.
    let u: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / 512.0;
            (2.0 * PI * (0.2 * t + 0.05 * t * t)).sin()
        })
        .collect();
    let rec = TestRecord::from_rate("chirp.csv", 512.0, u, vec![0.0; n], vec![0.0; n]).unwrap();
    let err = identify(&[rec], &ValidSettings::default()).unwrap_err();
    assert!(err.to_string().contains("irregular"), "{err}");
}

#[test]
fn a_record_shorter_than_its_period_has_no_full_cycle() {
    let motion = sine(0.05, 0.0, 0.5, 0.3, 0.0, 512.0, 1.9);
    let rec =
        common::record_of_motion("short", &motion, &nominal(), 13.8e6, &Default::default(), 1);
    let err = identify(&[rec], &ValidSettings::default()).unwrap_err();
    assert!(
        matches!(
            err,
            IdentError::NoFullCycle { .. } | IdentError::NotPeriodic { .. }
        ),
        "{err}"
    );
}

#[test]
fn bad_records_and_settings_are_rejected_with_what_is_wrong() {
    let err = TestRecord::from_rate("x", 512.0, vec![0.0; 100], vec![0.0; 99], vec![0.0; 100])
        .unwrap_err();
    assert!(err.to_string().contains("`a_m_s2` has 99 samples"), "{err}");
    let mut u = vec![0.0; 100];
    u[7] = f64::NAN;
    let err = TestRecord::from_rate("x", 512.0, u, vec![0.0; 100], vec![0.0; 100]).unwrap_err();
    assert!(err.to_string().contains("sample 7"), "{err}");
    let t: Vec<f64> = (0..100)
        .map(|i| if i == 50 { 50.5 } else { i as f64 } / 512.0)
        .collect();
    let err = TestRecord::new("x", &t, vec![0.0; 100], vec![0.0; 100], vec![0.0; 100]).unwrap_err();
    assert!(err.to_string().contains("time column"), "{err}");
    assert_eq!(
        identify(&[], &ValidSettings::default()).unwrap_err(),
        IdentError::NoTests
    );
    let bad = Settings {
        viscous_exponent: Some(1.5),
        ..Settings::default()
    };
    assert!(matches!(
        bad.build(),
        Err(IdentError::InvalidSetting {
            name: "viscous_exponent",
            ..
        })
    ));
}
