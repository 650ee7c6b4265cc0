//! Every record accounted for: a mixed set of periodic tests (some with irregular starts) and
//! non-periodic records (white noise, an earthquake-like record whose crossings are regular
//! but whose cycles change shape, a real PEER displacement record where available) goes each
//! to its method, and none is lost; a forced periodic fit of a non-periodic record falls back
//! to the any-record method with its reason.
//!
//! The records are exact data of the identified LHPOST model (its inverse), so the truth of
//! the routing is known by construction: the periodic ones are made periodic, the others are
//! not.

use std::f64::consts::PI;

use platen_ident::{
    identify_any, route, Method, MethodRequest, RecordSettings, Route, Settings, TestRecord,
};
use platen_integrate::{inverse, Motion, Trajectory};
use platen_model::preset;
use platen_scenario::generate::{sine_motion, triangle_motion, white_noise_motion};

const RATE_HZ: f64 = 256.0;

fn record(name: &str, motion: &Motion) -> TestRecord {
    let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
    let mut out = Trajectory::with_capacity(motion.len());
    inverse(&model, motion, &mut out);
    TestRecord::from_rate(name, RATE_HZ, out.u_m, out.a_m_s2, out.force_n)
        .unwrap()
        .with_velocity(out.v_m_s)
        .unwrap()
        .with_pressure_pa(13.8e6)
        .unwrap()
}

/// A displacement given as a function of time, with exact derivatives by central differences
/// of the function itself (step 1e-5 s: errors ~1e-10 of the motion, far below what routing
/// looks at).
fn motion_of(duration_s: f64, u: impl Fn(f64) -> f64) -> Motion {
    let n = (duration_s * RATE_HZ) as usize;
    let h = 1e-5;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / RATE_HZ).collect();
    let uu = t.iter().map(|&t| u(t)).collect();
    let v = t
        .iter()
        .map(|&t| (u(t + h) - u(t - h)) / (2.0 * h))
        .collect();
    let a = t
        .iter()
        .map(|&t| (u(t + h) - 2.0 * u(t) + u(t - h)) / (h * h))
        .collect();
    Motion::new(t, uu, v, a).unwrap()
}

/// A sine test that starts late and ramps in and out over one cycle each (cosine taper), as
/// lab tests do: 2 s at rest, 8 cycles at 0.8 Hz, 2 s at rest.
fn tapered_sine(t: f64) -> f64 {
    let (f, start, cycles) = (0.8, 2.0, 8.0);
    let tau = t - start;
    let len = cycles / f;
    if !(0.0..=len).contains(&tau) {
        return 0.0;
    }
    let ramp = 1.0 / f;
    let w = if tau < ramp {
        0.5 * (1.0 - (PI * tau / ramp).cos())
    } else if tau > len - ramp {
        0.5 * (1.0 - (PI * (len - tau) / ramp).cos())
    } else {
        1.0
    };
    0.15 * w * (2.0 * PI * f * tau).sin()
}

/// Crossings at exactly every half period (sin(ωt) and sin(3ωt) vanish together), so the old
/// crossing test alone took it for a sine test; but its third harmonic changes sign every
/// half-cycle, slowly, so consecutive half-cycles do not have one shape: not periodic at the
/// fundamental.
fn regular_crossings_changing_shape(t: f64) -> f64 {
    let w = 2.0 * PI * 0.5;
    let s = (w * t / 2.0).cos(); // flips sign once per period, smoothly
    0.1 * ((w * t).sin() + 0.6 * s * (3.0 * w * t).sin())
}

fn settings() -> (
    platen_ident::ValidSettings,
    platen_ident::ValidRecordSettings,
) {
    (
        Settings::default().build().unwrap(),
        RecordSettings {
            output_error: false,
            ..RecordSettings::default()
        }
        .build()
        .unwrap(),
    )
}

#[test]
fn mixed_records_each_go_to_their_method_and_none_is_lost() {
    let recs = vec![
        record("S9", &sine_motion(0.2, 0.6, RATE_HZ, 10.0).unwrap()),
        record(
            "T7",
            &triangle_motion(0.375, 0.25, 0.8333, RATE_HZ, 19.8).unwrap(),
        ),
        record("late-tapered-sine", &motion_of(14.0, tapered_sine)),
        record(
            "white-noise",
            &white_noise_motion(0.5, (0.5, 10.0), 7, RATE_HZ, 20.0).unwrap(),
        ),
        record(
            "shape-changing",
            &motion_of(16.0, regular_crossings_changing_shape),
        ),
    ];
    let expected = [
        Method::Periodic,
        Method::Periodic,
        Method::Periodic,
        Method::Record,
        Method::Record,
    ];
    let (s, rs) = settings();
    let id = identify_any(&recs, &[false; 5], MethodRequest::Auto, &s, &rs).unwrap();
    assert_eq!(id.accounts.len(), recs.len(), "one account per record");
    for ((a, r), want) in id.accounts.iter().zip(&recs).zip(expected) {
        assert_eq!(a.method, want, "{}: {a:?}", r.name());
        assert!(a.used, "{} not used: {a:?}", r.name());
        assert!(a.reason.is_none());
        assert!(!a.routing.is_empty());
    }
    let (p, p_idx) = id.periodic.as_ref().expect("the periodic method ran");
    assert_eq!(p_idx, &[0, 1, 2]);
    assert_eq!(p.tests.len(), 3);
    let (r, r_idx) = id.records.as_ref().expect("the any-record method ran");
    assert_eq!(r_idx, &[3, 4]);
    assert_eq!(r.records.len(), 2);
    // The shape-changing record's crossings are regular: it is the half-cycle test that
    // sends it away, and says so.
    let why = &id.accounts[4].routing;
    assert!(why.contains("half-cycles do not repeat"), "{why}");
}

#[test]
fn the_shape_test_measures_what_it_says() {
    // A pure sine: consecutive half-cycles are the same inverted.
    let sine = record("sine", &sine_motion(0.1, 0.5, RATE_HZ, 12.0).unwrap());
    assert!(
        matches!(route(&sine), Route::Periodic { frequency_hz } if (frequency_hz - 0.5).abs() < 1e-3)
    );
    // The shape-changing record: the mismatch the router reports is the one computed here
    // from the formula itself (consecutive half-cycles from each crossing at k·T/2 but the
    // last two, 2000 points each, about the sampled mid-range; the lower median).
    let duration_s = 16.0;
    let r = record(
        "shape",
        &motion_of(duration_s, regular_crossings_changing_shape),
    );
    let samples: Vec<f64> = (0..(duration_s * RATE_HZ) as usize)
        .map(|i| regular_crossings_changing_shape(i as f64 / RATE_HZ))
        .collect();
    let lo = samples.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = samples.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mid = 0.5 * (lo + hi);
    let (period_s, half_s) = (2.0, 1.0);
    let crossings: Vec<f64> = (1..)
        .map(|k| k as f64 * half_s)
        .take_while(|&t| t < duration_s - 0.1 * period_s)
        .collect();
    let mut mismatch: Vec<f64> = crossings[..crossings.len() - 2]
        .iter()
        .map(|&t0| {
            let (mut num, mut den) = (0.0, 0.0);
            for j in 0..2000 {
                let t = t0 + half_s * j as f64 / 2000.0;
                let x1 = regular_crossings_changing_shape(t) - mid;
                let x2 = regular_crossings_changing_shape(t + half_s) - mid;
                num += (x1 + x2).powi(2);
                den += x1 * x1 + x2 * x2;
            }
            (num / den).sqrt()
        })
        .collect();
    mismatch.sort_by(f64::total_cmp);
    let expected = mismatch[(mismatch.len() - 1) / 2];
    assert!(expected > platen_ident::HALF_CYCLE_MISMATCH);
    match route(&r) {
        Route::Record { reason } => {
            let m: f64 = reason
                .split("median mismatch ")
                .nth(1)
                .and_then(|x| x.split_whitespace().next())
                .and_then(|x| x.parse().ok())
                .unwrap_or_else(|| panic!("{reason}"));
            // Printed to two decimals; the sampled interpolation adds < 0.005.
            assert!(
                (m - expected).abs() < 0.01,
                "reported {m}, expected {expected:.4}: {reason}"
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_forced_periodic_fit_of_a_non_periodic_record_falls_back_with_its_reason() {
    let recs = vec![
        record("S9", &sine_motion(0.2, 0.6, RATE_HZ, 10.0).unwrap()),
        record(
            "quake-like",
            &white_noise_motion(0.8, (0.3, 8.0), 11, RATE_HZ, 30.0).unwrap(),
        ),
    ];
    let (s, rs) = settings();
    let id = identify_any(&recs, &[false; 2], MethodRequest::Periodic, &s, &rs).unwrap();
    assert_eq!(id.accounts[0].method, Method::Periodic);
    let a = &id.accounts[1];
    assert_eq!(a.method, Method::Record, "{a:?}");
    assert!(a.used);
    assert!(a.routing.starts_with("not a periodic test: "), "{a:?}");
    assert!(id.records.is_some(), "the fallback was identified");
}

#[test]
fn a_declared_record_is_not_taken_for_a_periodic_test() {
    let recs = vec![
        record("S9", &sine_motion(0.2, 0.6, RATE_HZ, 10.0).unwrap()),
        record("S11", &sine_motion(0.2, 1.2, RATE_HZ, 6.0).unwrap()),
    ];
    let (s, rs) = settings();
    let id = identify_any(&recs, &[false, true], MethodRequest::Auto, &s, &rs).unwrap();
    assert_eq!(id.accounts[0].method, Method::Periodic);
    assert_eq!(id.accounts[1].method, Method::Record);
    assert!(id.accounts[1].routing.contains("declared a record"));
}

/// Real earthquake displacement records (PEER NGA DT2 files), when the records folder is
/// given: none is a periodic test.
#[test]
fn real_earthquake_displacements_are_not_periodic_tests() {
    let Some(dir) = std::env::var_os("PLATEN_RECORDS_DIR") else {
        eprintln!("skipped: PLATEN_RECORDS_DIR is not set (the PEER records are not shipped)");
        return;
    };
    let dir = std::path::PathBuf::from(dir);
    let mut seen = 0;
    for name in [
        "RSN1087_NORTHR_TAR090.DT2",
        "RSN1087_NORTHR_TAR360.DT2",
        "RSN1106_KOBE_KJM000.DT2",
        "RSN1106_KOBE_KJM090.DT2",
    ] {
        let path = dir.join(name);
        if !path.exists() {
            continue;
        }
        let peer = platen_io::peer::read_peer(&path).unwrap();
        let rate = 1.0 / peer.dt_s;
        let u: Vec<f64> = peer.values.clone();
        let n = u.len();
        let rec = TestRecord::from_rate(name, rate, u, vec![0.0; n], vec![0.0; n]).unwrap();
        let r = route(&rec);
        assert_eq!(r.method(), Method::Record, "{name}: {r:?}");
        seen += 1;
    }
    assert!(seen > 0, "no DT2 record found in {}", dir.display());
}
