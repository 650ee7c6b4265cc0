//! The table motion of an acceleration record ([`AccelerogramMotion`]): exact for what the
//! straight lines represent exactly, PEER's trapezoid at the record's samples, no overshoot,
//! and one consistent motion under every baseline correction.

mod common;

use platen_signal::{
    cumulative_trapezoid, differentiate, AccelerogramMotion, Baseline, SampleRate, SignalError,
};

/// A ramp `a = c + b·t` is a straight line between any samples, so its motion is exact:
/// `v = ct + bt²/2`, `u = ct²/2 + bt³/6`, at every 1024 Hz sample of a 50 Hz record
/// (the ratio 20.48 puts the table samples anywhere inside the record's intervals).
#[test]
fn a_ramp_acceleration_gives_its_closed_form_velocity_and_displacement() {
    let (c, b) = (0.7, -0.13);
    let a: Vec<f64> = (0..501).map(|k| c + b * k as f64 * 0.02).collect();
    let m = AccelerogramMotion::new(50.0, 1024.0, Baseline::None)
        .unwrap()
        .process(&a)
        .unwrap();
    assert_eq!(m.a_m_s2().len(), 10241);
    for j in 0..m.a_m_s2().len() {
        let t = j as f64 / 1024.0;
        assert!((m.a_m_s2()[j] - (c + b * t)).abs() < 1e-12, "a at {t}");
        assert!(
            (m.v_m_s()[j] - (c * t + b * t * t / 2.0)).abs() < 1e-11,
            "v at {t}"
        );
        let u = c * t * t / 2.0 + b * t * t * t / 6.0;
        assert!(
            (m.u_m()[j] - u).abs() < 1e-10,
            "u at {t}: {} vs {u}",
            m.u_m()[j]
        );
    }
}

/// At the record's own samples the velocity is the cumulative trapezoid of the record (PEER's
/// `.VT2`), computed here by the independent [`cumulative_trapezoid`]; 1000 Hz is an exact
/// multiple of 50 Hz, so every 20th table sample is a record sample.
#[test]
fn at_the_records_samples_the_velocity_is_the_trapezoid_of_the_acceleration() {
    let mut rng = common::Rng::new(7);
    let a = rng.white(400, 3.0);
    let m = AccelerogramMotion::new(50.0, 1000.0, Baseline::None)
        .unwrap()
        .process(&a)
        .unwrap();
    let trapezoid = cumulative_trapezoid(&a, SampleRate::new(50.0).unwrap(), 0.0);
    for (k, v) in trapezoid.iter().enumerate() {
        assert!((m.v_m_s()[20 * k] - v).abs() < 1e-12, "sample {k}");
        assert_eq!(m.a_m_s2()[20 * k], a[k]);
    }
}

/// Straight lines between samples cannot overshoot: every table sample lies between the two
/// record samples around it (seeded white noise, the worst case for a spline).
#[test]
fn the_upsampled_acceleration_never_leaves_the_range_of_its_neighbouring_samples() {
    let mut rng = common::Rng::new(11);
    let a = rng.white(1000, 5.0);
    let m = AccelerogramMotion::new(50.0, 1024.0, Baseline::None)
        .unwrap()
        .process(&a)
        .unwrap();
    for (j, &y) in m.a_m_s2().iter().enumerate() {
        let pos = j as f64 * 50.0 / 1024.0;
        let k = (pos.floor() as usize).min(a.len() - 2);
        let (lo, hi) = (a[k].min(a[k + 1]), a[k].max(a[k + 1]));
        assert!(
            y >= lo - 1e-12 && y <= hi + 1e-12,
            "sample {j}: {y} outside [{lo}, {hi}]"
        );
    }
}

/// Every baseline keeps one motion: the acceleration is the derivative of the velocity and
/// the velocity that of the displacement (central differences at 1024 Hz: the mean of the
/// derivative over two table intervals, off where the straight lines bend by about
/// Δt·|slope change|/4, 1e-3·0.07/4 m/s² on this 50 Hz sine; below 2e-4 of the peaks), and the velocity
/// correction leaves a velocity with no least-squares trend of its order at the record's
/// samples.
#[test]
fn every_baseline_correction_keeps_acceleration_velocity_and_displacement_consistent() {
    // A smooth record with a bias and a trend (what a baseline correction is for).
    let a: Vec<f64> = (0..1000)
        .map(|k| {
            let t = k as f64 * 0.02;
            2.0 * (1.3 * t).sin() + 0.05 + 0.01 * t
        })
        .collect();
    let rate = SampleRate::new(1024.0).unwrap();
    for baseline in [
        Baseline::None,
        Baseline::Acceleration { order: 0 },
        Baseline::Acceleration { order: 2 },
        Baseline::Velocity { order: 0 },
        Baseline::Velocity { order: 3 },
    ] {
        let m = AccelerogramMotion::new(50.0, 1024.0, baseline)
            .unwrap()
            .process(&a)
            .unwrap();
        let dv = differentiate(m.v_m_s(), rate);
        let du = differentiate(m.u_m(), rate);
        let peak = |x: &[f64]| x.iter().fold(0.0f64, |p, y| p.max(y.abs()));
        let inner = 2..m.v_m_s().len() - 2;
        let ea = (inner.clone())
            .map(|j| (dv[j] - m.a_m_s2()[j]).abs())
            .fold(0.0, f64::max);
        let ev = inner
            .map(|j| (du[j] - m.v_m_s()[j]).abs())
            .fold(0.0, f64::max);
        assert!(
            ea < 2e-4 * peak(m.a_m_s2()),
            "{baseline:?}: a vs dv/dt {ea}"
        );
        assert!(ev < 2e-4 * peak(m.v_m_s()), "{baseline:?}: v vs du/dt {ev}");
        if let Baseline::Velocity { order } = baseline {
            // The corrected velocity at the record's samples has no component along
            // 1, t, …, t^order (its least-squares fit of that order is zero).
            let v_rec: Vec<f64> = (0..a.len())
                .map(|k| {
                    let j = (k as f64 * 1024.0 / 50.0).round() as usize;
                    // Only the record samples that are table samples (every 25th: 0.5 s).
                    if k % 25 == 0 {
                        m.v_m_s()[j]
                    } else {
                        f64::NAN
                    }
                })
                .collect();
            let kept: Vec<(f64, f64)> = v_rec
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(k, &v)| (k as f64 * 0.02, v))
                .collect();
            for power in 0..=order as i32 {
                let projection: f64 = kept
                    .iter()
                    .map(|(t, v)| v * (t / 20.0).powi(power))
                    .sum::<f64>()
                    / kept.len() as f64;
                // Sampled every 0.5 s only, so the projection is small, not zero: 2 % of the
                // velocity's peak bounds it (uncorrected, the trend alone is 0.01·20²/2 = 2 m/s).
                assert!(
                    projection.abs() < 0.02 * peak(m.v_m_s()),
                    "{baseline:?}: projection on t^{power} {projection}"
                );
            }
        }
    }
}

#[test]
fn records_too_short_and_orders_too_high_are_rejected() {
    let plan = AccelerogramMotion::new(50.0, 1024.0, Baseline::None).unwrap();
    assert!(matches!(
        plan.process(&[1.0]),
        Err(SignalError::RecordTooShort { found: 1, .. })
    ));
    assert!(matches!(
        AccelerogramMotion::new(50.0, 1024.0, Baseline::Velocity { order: 9 }),
        Err(SignalError::InvalidCount { value: 9, .. })
    ));
    assert!(AccelerogramMotion::new(0.0, 1024.0, Baseline::None).is_err());
    // A non-finite sample is named, not carried into the motion.
    assert!(matches!(
        plan.process(&[0.0, 1.0, f64::NAN, 0.0]),
        Err(SignalError::NonFiniteInput {
            what: "a_m_s2",
            index: 2,
            ..
        })
    ));
}

#[test]
fn the_motion_is_stamped_at_the_table_rate_and_can_be_cut() {
    let a: Vec<f64> = (0..101).map(|k| (k as f64 * 0.1).sin()).collect();
    let m = AccelerogramMotion::new(50.0, 200.0, Baseline::None)
        .unwrap()
        .process(&a)
        .unwrap();
    assert_eq!(m.len(), 401, "⌊(n − 1)·to/from⌋ + 1");
    for (j, &t) in m.t_s().iter().enumerate() {
        assert_eq!(t, j as f64 / 200.0);
    }
    let cut = m.clone().truncated(10).unwrap();
    assert_eq!(cut.len(), 10);
    assert_eq!(cut.u_m(), &m.u_m()[..10]);
    assert!(m.truncated(1).is_err());
}
