//! Channel skew in the any-record method: the variance an estimated delay adds to the
//! intervals, checked against fits with the delay given (no estimate, no added variance) on
//! the independent NumPy record of `tests/data/skew` (acceleration two samples late).

use platen_ident::{
    identify_records, IdentifiedKey, RecordIdentification, RecordSettings, TestRecord,
};

fn record() -> TestRecord {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/skew/skewed-eq.csv"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let mut cols = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for line in text.lines().skip(1) {
        for (c, x) in cols.iter_mut().zip(line.split(',')) {
            c.push(x.parse::<f64>().unwrap());
        }
    }
    let [t, u, a, f] = cols;
    TestRecord::new("skewed-eq", &t, u, a, f).unwrap()
}

fn identify(rec: TestRecord) -> RecordIdentification {
    let settings = RecordSettings {
        output_error: false,
        ..RecordSettings::default()
    }
    .build()
    .unwrap();
    identify_records(&[rec], &settings).unwrap()
}

fn value(id: &RecordIdentification, key: IdentifiedKey) -> (f64, f64) {
    let e = id.parameters.get(key).estimate().unwrap();
    (e.value, e.std_error)
}

/// With the delay estimated the estimates are those of the same delay given (the same
/// correction), and their variance exceeds the given delay's by `g²·se²`: `se` the delay's
/// standard error, `g = ∂θ/∂τ` the secant of fits with the delay given at `τ̂ ± 0.25` sample
/// (the method's own step here, where `2·se` is far smaller; it perturbs the corrected record
/// instead, a second shift). Tolerance 10 % of the added variance: the fits' own jitter
/// (their `(α, b)` search stops within a tolerance; a few kg on `Mₑ`) over a slope of ~100 kg
/// per sample.
#[test]
fn an_estimated_delay_widens_the_intervals_by_its_own_variance() {
    let fs = 204.8;
    let est = identify(record());
    let d = &est.records[0].channel_delays;
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].column, "a_m_s2");
    assert!(d[0].applied && d[0].estimated(), "{d:?}");
    let (tau, se) = (d[0].delay_s, d[0].std_error_s.unwrap());
    assert!((tau * fs - 2.0).abs() < 0.05, "{} samples", tau * fs);
    let given = |delay_s: f64| identify(record().with_channel_delay_s("a_m_s2", delay_s).unwrap());
    let same = given(tau);
    assert!(!same.records[0].channel_delays[0].estimated());
    let step_s = 0.25 / fs;
    let (lo, hi) = (given(tau - step_s), given(tau + step_s));
    for key in [IdentifiedKey::EffectiveMass, IdentifiedKey::Stiffness] {
        let (v_est, se_est) = value(&est, key);
        let (v_given, se_given) = value(&same, key);
        assert!((v_est - v_given).abs() <= 1e-12 * v_given.abs(), "{key:?}");
        let g = (value(&hi, key).0 - value(&lo, key).0) / (2.0 * step_s);
        let added = se_est * se_est - se_given * se_given;
        let expected = g * g * se * se;
        assert!(
            expected > 0.0 && (added / expected - 1.0).abs() < 0.10,
            "{key:?}: added variance {added:e}, g²se² {expected:e}"
        );
    }
}

/// A given delay of 0 turns the estimate off: the channel is used as recorded and nothing
/// is estimated.
#[test]
fn a_given_zero_delay_turns_the_estimate_off() {
    let id = identify(record().with_channel_delay_s("a_m_s2", 0.0).unwrap());
    let d = &id.records[0].channel_delays;
    assert_eq!(d.len(), 1);
    assert!(
        !d[0].applied && !d[0].estimated() && d[0].delay_s == 0.0,
        "{d:?}"
    );
}
