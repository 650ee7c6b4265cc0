//! Crossover velocity estimate from displacement and acceleration (paper §1.5, ref. [14]).

mod common;

use std::f64::consts::PI;

use common::{fit_sine, rms_diff, sine, times, Rng};
use platen_signal::{
    differentiate, Baseline, ButterworthLowpass, CrossoverVelocity, InitialMotion,
    MotionIntegrator, SampleRate, SignalError, ZeroPhaseFilter,
};

const FS_HZ: f64 = 1024.0;

/// The weights `L(f)` and `1 − L(f)` add to one at every frequency (to rounding), and each
/// path, measured on a sine fed to it alone, has the gain the estimator documents:
/// displacement path `L·sin(ωΔt)/(ωΔt)`, acceleration path
/// `(1 − L)·(ωΔt/2)/tan(ωΔt/2)·cos²(ωΔt/2)`, both zero phase. Measured over the middle 8 s of
/// 16 s, within 1e-6 (the edge effects of the 1 Hz crossover, time constant 0.23 s, have
/// decayed by e⁻¹⁷). Their sum is one within the discretisation factors, which stay above
/// `1 − (ωΔt)²/3` (central difference `1 − (ωΔt)²/6`, trapezoids and difference on the
/// acceleration path `1 − (ωΔt)²/3`): 8·10⁻⁴ at 8 Hz.
#[test]
fn the_two_paths_sum_to_one_at_every_frequency() {
    let x = CrossoverVelocity::butterworth(2, 1.0, FS_HZ).unwrap();
    for &hz in &[0.0, 0.1, 0.5, 1.0, 2.0, 8.0, 100.0, 511.0] {
        let sum = x.displacement_weight(hz) + x.acceleration_weight(hz);
        assert!((sum - 1.0).abs() < 1e-15, "{hz} Hz: weights sum to {sum}");
    }
    assert!((x.displacement_weight(1.0) - 0.5).abs() < 1e-12);

    let n = 16 * 1024;
    let middle = 4096..n - 4096;
    let zeros = vec![0.0; n];
    for &hz in &[0.25, 0.5, 1.0, 2.0, 4.0, 8.0] {
        let w = 2.0 * PI * hz;
        // u = sin(ωt)/ω has velocity cos(ωt) = sin(ωt + π/2) and acceleration −ω·sin(ωt).
        let u = sine(n, FS_HZ, hz, 1.0 / w, 0.0);
        let a = sine(n, FS_HZ, hz, -w, 0.0);
        let (g_u, ph_u) = fit_sine(&x.estimate(&u, &zeros).unwrap(), FS_HZ, hz, middle.clone());
        let (g_a, ph_a) = fit_sine(&x.estimate(&zeros, &a).unwrap(), FS_HZ, hz, middle.clone());
        let (g, ph) = fit_sine(&x.estimate(&u, &a).unwrap(), FS_HZ, hz, middle.clone());
        assert!(
            (g_u - x.displacement_path_gain(hz)).abs() < 1e-6,
            "{hz} Hz: u path {g_u}"
        );
        assert!(
            (g_a - x.acceleration_path_gain(hz)).abs() < 1e-6,
            "{hz} Hz: a path {g_a}"
        );
        for (p, what) in [(ph_u, "u"), (ph_a, "a"), (ph, "sum")] {
            assert!(
                (p - PI / 2.0).abs() < 1e-6,
                "{hz} Hz: {what} path phase {p}"
            );
        }
        let discretisation = (w / FS_HZ).powi(2) / 3.0;
        assert!(
            g <= 1.0 + 1e-6 && g > 1.0 - discretisation - 1e-6,
            "{hz} Hz: sum gain {g}"
        );
        assert!(
            (g_u + g_a - g).abs() < 1e-9,
            "{hz} Hz: paths are not additive"
        );
    }
}

/// The motion: `u = 0.2 m·sin(2π·0.5t) + 0.02 m·sin(2π·3t + 1)` for 20 s at 1024 Hz (a
/// shakedown sine with a harmonic). The sensors:
/// * displacement + white noise, σ = 0.1 mm (seeded);
/// * acceleration + white noise, σ = 0.02 m/s², + a bias of 0.01 m/s² (seeded).
///
/// RMS velocity errors over the whole record, edges included (measured, m/s): crossover
/// (order 2 at 1 Hz) 1.4e-4; differentiated displacement 7.3e-2 raw and 7.9e-3 after a 10 Hz
/// zero-phase low-pass that keeps the motion (5e-4 away from the edges, but the filter passes
/// the noisy one-sided derivative at the end samples); integrated acceleration from the true
/// initial velocity 0.12 (the bias drifts 0.2 m/s in 20 s) and 1.6e-3 with the mean
/// acceleration removed. The test asks the crossover to be at least five times better than the
/// best single-source estimate and below 3e-4 m/s. Hand estimate:
/// `√(2σ_a²/f_s/(4π²f_c)) ≈ 1.4e-4` from the high-passed acceleration noise, plus
/// `σ_u·√(2/f_s·(2π)²·f_c³/3) ≈ 1.6e-5` from the low-passed derivative noise.
#[test]
fn crossover_beats_either_source_alone_on_noisy_biased_records() {
    let n = 20 * 1024;
    let t = times(n, FS_HZ);
    let (w1, w2) = (2.0 * PI * 0.5, 2.0 * PI * 3.0);
    let u_true: Vec<f64> = t
        .iter()
        .map(|t| 0.2 * (w1 * t).sin() + 0.02 * (w2 * t + 1.0).sin())
        .collect();
    let v_true: Vec<f64> = t
        .iter()
        .map(|t| 0.2 * w1 * (w1 * t).cos() + 0.02 * w2 * (w2 * t + 1.0).cos())
        .collect();
    let a_true: Vec<f64> = t
        .iter()
        .map(|t| -0.2 * w1 * w1 * (w1 * t).sin() - 0.02 * w2 * w2 * (w2 * t + 1.0).sin())
        .collect();
    let mut rng = Rng::new(20080101);
    let u: Vec<f64> = u_true.iter().map(|u| u + 1e-4 * rng.normal()).collect();
    let a: Vec<f64> = a_true
        .iter()
        .map(|a| a + 0.01 + 0.02 * rng.normal())
        .collect();

    let crossover = CrossoverVelocity::butterworth(2, 1.0, FS_HZ).unwrap();
    let v_x = crossover.estimate(&u, &a).unwrap();
    let e_x = rms_diff(&v_x, &v_true);

    let rate = SampleRate::new(FS_HZ).unwrap();
    let v_d = differentiate(&u, rate);
    let e_d_raw = rms_diff(&v_d, &v_true);
    let smooth = ButterworthLowpass::new(2, 10.0, FS_HZ).unwrap();
    let e_d = rms_diff(&smooth.apply(&v_d).unwrap(), &v_true);

    let v0 = InitialMotion {
        u_m: u_true[0],
        v_m_s: v_true[0],
    };
    let plain = MotionIntegrator::new(FS_HZ, Baseline::None).unwrap();
    let e_a_raw = rms_diff(plain.integrate(&a, v0).unwrap().v_m_s(), &v_true);
    let corrected = MotionIntegrator::new(FS_HZ, Baseline::Acceleration { order: 0 }).unwrap();
    let e_a = rms_diff(corrected.integrate(&a, v0).unwrap().v_m_s(), &v_true);

    let best_single = e_d_raw.min(e_d).min(e_a_raw).min(e_a);
    let report = format!(
        "crossover {e_x:.2e}; displacement raw {e_d_raw:.2e}, low-passed {e_d:.2e}; \
         acceleration raw {e_a_raw:.2e}, baseline-corrected {e_a:.2e}"
    );
    assert!(e_x < 0.2 * best_single, "{report}");
    assert!(e_x < 3e-4, "{report}");
}

/// A constant acceleration bias and an unknown initial velocity make a ramp and a constant in
/// the integrated acceleration; the complementary high-pass removes both, so on a noise-free
/// record with a large bias (0.5 m/s², a 0.4 g offset) and no initial velocity given, the
/// estimate is still within the discretisation error of the truth everywhere, edges included
/// (the quadratic `u₀ + v₀t + bt²/2` is removed before filtering).
#[test]
fn integration_drift_is_removed_by_the_complementary_high_pass() {
    let n = 16 * 1024;
    let t = times(n, FS_HZ);
    let w = 2.0 * PI * 0.7;
    let u: Vec<f64> = t.iter().map(|t| 0.3 * (w * t).cos() + 0.1 * t).collect();
    let v: Vec<f64> = t.iter().map(|t| -0.3 * w * (w * t).sin() + 0.1).collect();
    let a: Vec<f64> = t
        .iter()
        .map(|t| -0.3 * w * w * (w * t).cos() + 0.5)
        .collect();
    let x = CrossoverVelocity::butterworth(2, 1.0, FS_HZ).unwrap();
    let est = x.estimate(&u, &a).unwrap();
    let err = common::max_abs_diff(&est[..], &v[..]);
    // The estimate carries the discretisation factors of the paths, within (ωΔt)²/3 of one:
    // 6·10⁻⁶ of the 1.3 m/s oscillation at 0.7 Hz (measured 6.2e-6 m/s).
    let bound = (w / FS_HZ).powi(2) / 3.0 * 0.3 * w + 1e-6;
    assert!(err < bound, "max error {err}, bound {bound}");
}

#[test]
fn records_of_different_lengths_are_rejected() {
    let x = CrossoverVelocity::butterworth(2, 1.0, FS_HZ).unwrap();
    assert!(matches!(
        x.estimate(&[0.0; 10], &[0.0; 9]),
        Err(SignalError::LengthMismatch {
            what: "a_m_s2",
            expected: 10,
            found: 9,
            ..
        })
    ));
    let e = CrossoverVelocity::butterworth(2, 600.0, FS_HZ).unwrap_err();
    assert!(
        matches!(
            e,
            SignalError::CutoffOutOfRange {
                name: "crossover_hz",
                ..
            }
        ),
        "{e}"
    );
    // Any zero-phase low-pass will do, by reference too.
    let fir = platen_signal::FirLowpass::new(2048, 1.0, FS_HZ, Default::default()).unwrap();
    let by_ref = CrossoverVelocity::new(&fir).unwrap();
    assert_eq!(by_ref.low_pass().sample_rate_hz(), FS_HZ);
    assert!((by_ref.displacement_weight(0.0) - 1.0).abs() < 1e-12);
}
