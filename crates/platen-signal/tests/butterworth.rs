//! Forward–backward Butterworth low-pass: design, measured gain and phase on sines, edges.

mod common;

use common::{fit_sine, max_abs_diff, peak_lag, sine};
use platen_signal::{ButterworthLowpass, SignalError, ZeroPhaseFilter};

const FS_HZ: f64 = 1024.0;

/// The input of the SciPy comparisons: `x[i] = sin(0.05i) + 0.3·cos(0.31i) + 0.01i`, 200 samples.
fn scipy_input() -> Vec<f64> {
    (0..200)
        .map(|i| {
            let i = i as f64;
            (0.05 * i).sin() + 0.3 * (0.31 * i).cos() + 0.01 * i
        })
        .collect()
}

/// With SciPy's extension length `3·(N + 1)` the result must be SciPy's:
/// `sosfiltfilt(butter(N, 10.0, output='sos', fs=256.0), x)` (SciPy 1.17), samples 0, 1, 7, 50,
/// 100, 199, for N = 4 and N = 3 (odd: a first-order section). SciPy splits the gain between
/// sections differently and orders them differently, which only changes rounding: 1e-11.
#[test]
fn with_scipy_padding_the_result_matches_scipy_sosfiltfilt() {
    let x = scipy_input();
    let cases = [
        (
            4,
            15,
            [
                0.275_942_317_704_410_97,
                0.270_663_026_663_931_1,
                0.336_270_190_110_571_63,
                1.061_595_612_044_914_4,
                0.077_020_084_129_690_14,
                1.556_164_042_290_781_2,
            ],
        ),
        (
            3,
            12,
            [
                0.260_394_662_164_941_3,
                0.257_904_175_729_48,
                0.334_972_765_773_955_9,
                1.041_467_743_273_399_4,
                0.094_591_063_079_997_82,
                1.567_541_611_229_357_9,
            ],
        ),
    ];
    for (order, pad, expected) in cases {
        let f = ButterworthLowpass::new(order, 10.0, 256.0)
            .unwrap()
            .with_pad_len(pad)
            .unwrap();
        let y = f.apply(&x).unwrap();
        for (&i, e) in [0, 1, 7, 50, 100, 199].iter().zip(expected) {
            assert!(
                (y[i] - e).abs() < 1e-11,
                "N = {order}, sample {i}: {} vs SciPy {e}",
                y[i]
            );
        }
    }
}

/// Measured gain: sine fit over the interior (2 s from each edge, ≥ 30 time constants of the
/// slowest pole, so what is left of the start-up transient is far below 1e-9) against the
/// design `1/(1 + (tan(πf/f_s)/tan(πf_c/f_s))^{2N})`; tolerance 1e-9 of the unit amplitude
/// (measured 5e-14) covers the rounding of ~10⁴ recursive steps in each direction. Design: 0.5 exactly at the cut-off,
/// pass band within (f/f_c)^{2N} of one, stop band below (f_c/f)^{2N}.
#[test]
fn measured_gain_on_sines_matches_the_design_in_pass_band_cutoff_and_stop_band() {
    let order = 4;
    let fc = 8.0;
    let f = ButterworthLowpass::new(order, fc, FS_HZ).unwrap();
    let n = 6 * 1024;
    let interior = 2048..n - 2048;
    let mut worst = 0.0_f64;
    for &hz in &[0.5, 2.0, 4.0, 6.0, 8.0, 10.0, 16.0, 32.0] {
        let x = sine(n, FS_HZ, hz, 1.0, 0.7);
        let y = f.apply(&x).unwrap();
        let (gain, phase) = fit_sine(&y, FS_HZ, hz, interior.clone());
        let design = f.gain(hz);
        worst = worst.max((gain - design).abs());
        assert!(
            (gain - design).abs() < 1e-9,
            "{hz} Hz: measured {gain}, design {design}"
        );
        if design > 1e-6 {
            assert!((phase - 0.7).abs() < 1e-6, "{hz} Hz: phase {phase} rad");
        }
        let ratio: f64 = hz / fc;
        if hz < fc {
            assert!(1.0 - design <= ratio.powi(2 * order as i32) * 1.01);
        }
        if hz > fc {
            assert!(design <= ratio.powi(-2 * (order as i32)));
        }
        assert_eq!(f.phase_rad(hz), 0.0);
    }
    // Measured: 5e-14.
    assert!(worst < 1e-9);
    assert!((f.gain(fc) - 0.5).abs() < 1e-15);
    assert!((f.single_pass_gain(fc) - 0.5f64.sqrt()).abs() < 1e-15);
}

/// A pass-band multi-sine comes out in phase (cross-correlation peak at lag 0 within 0.01
/// sample, as for the FIR), where one causal pass would lag by the group delay (≈ 2.6/ω_c,
/// 53 samples at 8 Hz).
#[test]
fn output_is_zero_phase_cross_correlation_peaks_at_lag_zero() {
    let f = ButterworthLowpass::new(4, 8.0, FS_HZ).unwrap();
    let n = 8192;
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / FS_HZ;
            (2.0 * std::f64::consts::PI * 1.3 * t).sin()
                + 0.5 * (2.0 * std::f64::consts::PI * 3.1 * t + 1.0).sin()
        })
        .collect();
    let y = f.apply(&x).unwrap();
    let lag = peak_lag(&x, &y, 1024..n - 1024, 100);
    assert!(lag.abs() < 1e-2, "lag {lag} samples");
}

/// Lag of a ramp behind one causal pass of a Butterworth of order `N`: the DC group delay
/// `τ_g = Σ_k sin θ_k / ω_c` over the prototype poles at angles `θ_k = (2k − 1)π/(2N)`, s.
fn dc_group_delay_s(order: usize, cutoff_hz: f64) -> f64 {
    let wc = 2.0 * std::f64::consts::PI * cutoff_hz;
    (1..=order)
        .map(|k| ((2 * k - 1) as f64 * std::f64::consts::PI / (2 * order) as f64).sin())
        .sum::<f64>()
        / wc
}

/// A constant passes untouched: the steady-state initial conditions leave only rounding, which
/// the recursion amplifies by `1/(1 + a₁ + a₂)` ≈ 7·10⁴ for poles this close to `z = 1`
/// (0.6 Hz at 1024 Hz), hence the bound 1e-10 relative (measured 1e-11).
///
/// On a constant plus ramp the start-up mismatch is the ramp's lag `slope·τ_g`; the default
/// extension (9 time constants of the slowest pole) lets it decay by `e⁻⁹` before the record
/// starts, so the edge error is below `e⁻⁹·slope·τ_g`. For N = 4 at 0.6 Hz on 1024 Hz data and a
/// ramp of 0.25 m/s (a triangular test's constant velocity): `τ_g = 0.693 s`, bound 2.1e-5 m
/// (measured 4.9e-6 m), against ≈ `slope·τ_g` = 0.17 m with SciPy's 15-sample extension, which
/// this test measures too.
#[test]
fn constant_passes_exactly_and_constant_plus_ramp_has_a_small_edge_transient() {
    let f = ButterworthLowpass::new(4, 0.6, FS_HZ).unwrap();
    let constant = vec![0.37; 4096];
    let err = max_abs_diff(&constant, &f.apply(&constant).unwrap());
    assert!(err < 1e-10 * 0.37, "constant: error {err}");

    let slope_m_s = 0.25;
    let ramp: Vec<f64> = (0..10 * 1024)
        .map(|i| 0.1 + slope_m_s * i as f64 / FS_HZ)
        .collect();
    let lag_m = slope_m_s * dc_group_delay_s(4, 0.6);
    assert!((lag_m - 0.173).abs() < 1e-3, "lag {lag_m} m");
    let ours = max_abs_diff(&ramp, &f.apply(&ramp).unwrap());
    assert!(
        ours < (-9.0f64).exp() * lag_m,
        "default extension: edge error {ours} m"
    );
    let scipy_like = f.clone().with_pad_len(15).unwrap();
    let theirs = max_abs_diff(&ramp, &scipy_like.apply(&ramp).unwrap());
    assert!(
        theirs > 0.5 * lag_m,
        "SciPy-length extension: edge error {theirs} m"
    );
}

/// Short records and records shorter than the extension (repeated reflection) are handled: a
/// 5-sample line (slope 1 per sample) through N = 2 at 1 Hz, whose lag is `τ_g = 230` samples,
/// comes out within `e⁻⁹·230 = 0.028` of itself.
#[test]
fn short_records_are_handled() {
    let f = ButterworthLowpass::new(2, 1.0, FS_HZ).unwrap();
    assert!(f.pad_len() > 1000);
    assert_eq!(f.apply(&[]).unwrap(), Vec::<f64>::new());
    let one = f.apply(&[1.25]).unwrap();
    assert!((one[0] - 1.25).abs() < 1e-12);
    let line = [1.0, 2.0, 3.0, 4.0, 5.0];
    let y = f.apply(&line).unwrap();
    let bound = (-9.0f64).exp() * dc_group_delay_s(2, 1.0) * FS_HZ;
    assert!(max_abs_diff(&line, &y) < bound, "{y:?}, bound {bound}");
}

#[test]
fn invalid_designs_are_rejected_with_what_was_expected() {
    assert!(matches!(
        ButterworthLowpass::new(0, 8.0, FS_HZ),
        Err(SignalError::InvalidCount {
            name: "order",
            value: 0,
            ..
        })
    ));
    assert!(ButterworthLowpass::new(17, 8.0, FS_HZ).is_err());
    let e = ButterworthLowpass::new(4, 600.0, FS_HZ).unwrap_err();
    assert!(e.to_string().contains("below the Nyquist frequency"), "{e}");
    assert!(ButterworthLowpass::new(4, 8.0, 0.0).is_err());
    assert!(ButterworthLowpass::new(4, 8.0, FS_HZ)
        .unwrap()
        .with_pad_len(0)
        .is_err());
}
