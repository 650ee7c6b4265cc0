//! Differentiation, trapezoidal integration and baseline correction.

mod common;

use std::f64::consts::PI;

use common::{max_abs_diff, times};
use platen_signal::{
    cumulative_trapezoid, differentiate, Baseline, InitialMotion, MotionIntegrator, SampleRate,
    SignalError,
};

/// Second-order central differences in the interior and second-order one-sided formulas at the
/// ends are exact for quadratics; the tolerance 1e-9 m/s covers the rounding of differences of
/// values up to ~60 m divided by 2Δt = 1/512 s (60·1e-16·512 ≈ 3e-12, with margin).
#[test]
fn differentiation_is_exact_on_quadratics_including_the_end_samples() {
    let rate = SampleRate::new(1024.0).unwrap();
    let t = times(3000, rate.hz());
    let (c0, c1, c2) = (0.3, -1.7, 2.25);
    let x: Vec<f64> = t.iter().map(|t| c0 + c1 * t + c2 * t * t).collect();
    let exact: Vec<f64> = t.iter().map(|t| c1 + 2.0 * c2 * t).collect();
    let d = differentiate(&x, rate);
    assert!(
        max_abs_diff(&d, &exact) < 1e-9,
        "{}",
        max_abs_diff(&d, &exact)
    );
    // Short records.
    assert_eq!(differentiate(&[], rate), Vec::<f64>::new());
    assert_eq!(differentiate(&[4.0], rate), vec![0.0]);
    assert_eq!(differentiate(&[1.0, 1.5], rate), vec![512.0, 512.0]);
    let three = differentiate(&[0.0, 1.0, 4.0], SampleRate::new(1.0).unwrap());
    assert_eq!(three, vec![0.0, 2.0, 4.0]); // x = i², x' = 2i
}

/// On a sine the central difference has zero phase and the gain `sin(ωΔt)/(ωΔt)`; the error
/// halves twice (second order) when the rate doubles: ratio within 4 ± 0.1.
#[test]
fn differentiation_converges_at_second_order_on_a_sine() {
    let f_hz = 2.0;
    let err = |fs: f64| {
        let rate = SampleRate::new(fs).unwrap();
        let n = (2.0 * fs) as usize;
        let t = times(n, fs);
        let x: Vec<f64> = t.iter().map(|t| (2.0 * PI * f_hz * t).sin()).collect();
        let exact: Vec<f64> = t
            .iter()
            .map(|t| 2.0 * PI * f_hz * (2.0 * PI * f_hz * t).cos())
            .collect();
        max_abs_diff(&differentiate(&x, rate), &exact)
    };
    let (e1, e2) = (err(256.0), err(512.0));
    assert!((e1 / e2 - 4.0).abs() < 0.1, "ratio {}", e1 / e2);
}

/// Trapezoidal integration of `a = A·sin(ωt)` from the exact initial values reproduces
/// `v = A/ω·(1 − cos ωt)` + v₀ and `u` within the trapezoid's bounds:
/// `|e_v(T)| ≤ T·Δt²·max|a''|/12 = T·Δt²·Aω²/12` and, integrating that error and adding the
/// trapezoid error on v, `|e_u(T)| ≤ Δt²·A·(ω²T²/24 + ωT/12)`. The errors also shrink by 4 when
/// the rate doubles (within 4 ± 0.1).
#[test]
fn integration_of_a_sine_acceleration_is_within_the_trapezoid_error_bound() {
    let (amp, f_hz, duration_s) = (3.0, 1.5, 10.0);
    let w = 2.0 * PI * f_hz;
    let (v0, u0) = (0.2, -0.05);
    let run = |fs: f64| {
        let n = (duration_s * fs) as usize + 1;
        let t = times(n, fs);
        let a: Vec<f64> = t.iter().map(|t| amp * (w * t).sin()).collect();
        let v: Vec<f64> = t
            .iter()
            .map(|t| v0 + amp / w * (1.0 - (w * t).cos()))
            .collect();
        let u: Vec<f64> = t
            .iter()
            .map(|t| u0 + v0 * t + amp / w * (t - (w * t).sin() / w))
            .collect();
        let m = MotionIntegrator::new(fs, Baseline::None)
            .unwrap()
            .integrate(&a, InitialMotion { u_m: u0, v_m_s: v0 })
            .unwrap();
        assert_eq!(m.v_m_s()[0], v0);
        assert_eq!(m.u_m()[0], u0);
        let dt = 1.0 / fs;
        let bound_v = duration_s * dt * dt * amp * w * w / 12.0;
        let bound_u =
            dt * dt * amp * (w * w * duration_s * duration_s / 24.0 + w * duration_s / 12.0);
        let (ev, eu) = (max_abs_diff(m.v_m_s(), &v), max_abs_diff(m.u_m(), &u));
        assert!(
            ev <= bound_v,
            "{fs} Hz: velocity error {ev} > bound {bound_v}"
        );
        assert!(
            eu <= bound_u,
            "{fs} Hz: displacement error {eu} > bound {bound_u}"
        );
        (ev, eu)
    };
    let (ev1, eu1) = run(256.0);
    let (ev2, eu2) = run(512.0);
    assert!(
        (ev1 / ev2 - 4.0).abs() < 0.1,
        "velocity ratio {}",
        ev1 / ev2
    );
    assert!(
        (eu1 / eu2 - 4.0).abs() < 0.1,
        "displacement ratio {}",
        eu1 / eu2
    );
    let direct = cumulative_trapezoid(&[1.0, 3.0, 5.0], SampleRate::new(2.0).unwrap(), 10.0);
    assert_eq!(direct, vec![10.0, 11.0, 13.0]);
}

/// An accelerometer bias of 0.02 m/s² grows into 0.2 m/s of velocity drift and 1 m of
/// displacement drift in 10 s. The true acceleration `sin(ωt)` over 11 whole cycles has a zero
/// sample mean, so removing the least-squares constant from the acceleration (order 0) removes
/// exactly the bias and leaves the trapezoid's error: bounds 2e-4 m/s and 1e-3 m (the bounds of
/// the previous test, `T·Δt²·ω²/12 = 1.5e-4` and `Δt²(ω²T²/24 + ωT/12) = 7.6e-4`).
/// Removing a velocity line (order 1) after integrating instead removes the bias's ramp and the
/// velocity's own mean `1/ω`, leaving `v − 1/ω` to 1e-3 m/s (the line fit leaks a little of the
/// oscillation).
#[test]
fn baseline_correction_removes_an_accelerometer_bias() {
    let fs = 512.0;
    let n = 10 * 512 + 1;
    let t = times(n, fs);
    let w = 2.0 * PI * 1.1;
    let a_true: Vec<f64> = t.iter().map(|t| (w * t).sin()).collect();
    let v_true: Vec<f64> = t.iter().map(|t| (1.0 - (w * t).cos()) / w).collect();
    let u_true: Vec<f64> = t.iter().map(|t| (t - (w * t).sin() / w) / w).collect();
    let biased: Vec<f64> = a_true.iter().map(|a| a + 0.02).collect();

    let plain = MotionIntegrator::new(fs, Baseline::None)
        .unwrap()
        .integrate(&biased, InitialMotion::default())
        .unwrap();
    let drift = max_abs_diff(plain.v_m_s(), &v_true);
    assert!((drift - 0.2).abs() < 0.01, "plain drift {drift}");

    let corrected = MotionIntegrator::new(fs, Baseline::Acceleration { order: 0 })
        .unwrap()
        .integrate(&biased, InitialMotion::default())
        .unwrap();
    let ev = max_abs_diff(corrected.v_m_s(), &v_true);
    assert!(ev < 2e-4, "acceleration baseline: velocity error {ev}");
    let eu = max_abs_diff(corrected.u_m(), &u_true);
    assert!(eu < 1e-3, "acceleration baseline: displacement error {eu}");

    let by_velocity = MotionIntegrator::new(fs, Baseline::Velocity { order: 1 })
        .unwrap()
        .integrate(&biased, InitialMotion::default())
        .unwrap();
    let centred: Vec<f64> = v_true.iter().map(|v| v - 1.0 / w).collect();
    let ev = max_abs_diff(by_velocity.v_m_s(), &centred);
    assert!(ev < 1e-3, "velocity baseline: velocity error {ev}");
    // The velocity line's slope (the bias, 0.02 m/s², and what the line fit takes of the
    // oscillation) is gone from the acceleration too: the velocity's derivative is the
    // motion's acceleration to the trapezoid's `Δt²·ω²/12·|a| ≈ 4e-5` plus the differences'
    // own error, at every sample; the raw acceleration is off by the bias.
    let rate = SampleRate::new(fs).unwrap();
    let dv = differentiate(by_velocity.v_m_s(), rate);
    let interior = 1..n - 1;
    let ea = max_abs_diff(
        &dv[interior.clone()],
        &by_velocity.a_m_s2()[interior.clone()],
    );
    assert!(
        ea < 1e-4,
        "velocity baseline: acceleration off the velocity by {ea}"
    );
    let raw = max_abs_diff(&dv[interior.clone()], &biased[interior]);
    assert!((raw - 0.02).abs() < 1e-3, "raw acceleration off by {raw}");
}

/// The motion of an acceleration record: sample `i` at `i/f_s`, the velocity and displacement
/// the cumulative trapezoids from the initial values, and the acceleration the record itself
/// (no baseline) or the record less its polynomial (an acceleration baseline): bit for bit.
#[test]
fn the_integrated_motion_is_the_record_and_its_trapezoids() {
    let fs = 200.0;
    let rate = SampleRate::new(fs).unwrap();
    let a: Vec<f64> = (0..401).map(|i| (i as f64 * 0.05).sin() + 0.3).collect();
    let initial = InitialMotion {
        u_m: 0.01,
        v_m_s: -0.2,
    };
    let m = MotionIntegrator::new(fs, Baseline::None)
        .unwrap()
        .integrate(&a, initial)
        .unwrap();
    assert_eq!(m.t_s(), times(a.len(), fs));
    assert_eq!(m.a_m_s2(), a);
    let v = cumulative_trapezoid(&a, rate, -0.2);
    assert_eq!(m.v_m_s(), v);
    assert_eq!(m.u_m(), cumulative_trapezoid(&v, rate, 0.01));
    assert_eq!(m.rest_velocity_m_s(), None);

    let m = MotionIntegrator::new(fs, Baseline::Acceleration { order: 2 })
        .unwrap()
        .integrate(&a, initial)
        .unwrap();
    let mut corrected = a.clone();
    platen_signal::remove_polynomial(&mut corrected, 2);
    assert_eq!(m.a_m_s2(), corrected);
    assert_eq!(m.v_m_s(), cumulative_trapezoid(&corrected, rate, -0.2));

    let mut bad = a;
    bad[7] = f64::NAN;
    let e = MotionIntegrator::new(fs, Baseline::None)
        .unwrap()
        .integrate(&bad, initial)
        .unwrap_err();
    assert_eq!(e.to_string(), "a_m_s2[7] = NaN is not finite");
}

#[test]
fn baseline_orders_above_the_maximum_are_rejected() {
    assert!(matches!(
        MotionIntegrator::new(100.0, Baseline::Velocity { order: 9 }),
        Err(SignalError::InvalidCount { value: 9, .. })
    ));
    assert!(MotionIntegrator::new(-1.0, Baseline::None).is_err());
    let m = MotionIntegrator::new(100.0, Baseline::Acceleration { order: 8 }).unwrap();
    assert_eq!(m.baseline(), Baseline::Acceleration { order: 8 });
    assert_eq!(
        m.integrate(&[1.0], InitialMotion::default()),
        Err(SignalError::TooFewSamples {
            found: 1,
            needed: 2
        })
    );
}
