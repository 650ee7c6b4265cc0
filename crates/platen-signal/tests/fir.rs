//! Windowed-sinc FIR low-pass: design, measured gain and phase on sines, edges.

mod common;

use common::{fit_sine, max_abs_diff, peak_lag, sine};
use platen_signal::{FirLowpass, SignalError, Window, ZeroPhaseFilter};

const FS_HZ: f64 = 1024.0;

/// The paper's filter on 1024 Hz data (§3.3): order 512, cut-off 8 Hz.
fn paper_fir() -> FirLowpass {
    FirLowpass::new(512, 8.0, FS_HZ, Window::Hamming).unwrap()
}

/// `scipy.signal.firwin(513, 8.0, fs=1024.0, window='hamming')` (SciPy 1.17), taps 0, 100, 200,
/// 255 and 256: an independent implementation of the same design (sinc × Hamming, unit DC gain).
#[test]
fn taps_match_scipy_firwin() {
    let h = paper_fir();
    let scipy = [
        (0, -4.885_219_770_525_451e-20),
        (100, 7.725_167_494_743_913e-4),
        (200, 1.953_087_016_934_442_4e-3),
        (255, 1.565_826_621_281_162_7e-2),
        (256, 1.566_509_886_048_348_5e-2),
    ];
    for (k, expected) in scipy {
        assert!(
            (h.taps()[k] - expected).abs() < 1e-15,
            "tap {k}: {} vs SciPy {expected}",
            h.taps()[k]
        );
    }
}

/// Away from the edges the zero-phase convolution of a sine is exactly `A(f)` times the sine,
/// so the measured gain (least-squares sine fit over all samples at least `M` from an edge)
/// equals the design amplitude up to rounding; 1e-9 leaves six orders of margin over the
/// ~1e-15 rounding of 513-term sums. The design values themselves: unit gain within the
/// Hamming ripple (0.5 %) in the pass band, 0.5 within 0.2 % at the cut-off, and below 3·10⁻³
/// past the transition band (8 + 3.3 Hz at 1024 Hz).
#[test]
fn measured_gain_on_sines_matches_the_design_in_pass_band_cutoff_and_stop_band() {
    let fir = paper_fir();
    let n = 8192;
    let interior = 512..n - 512;
    for &(f_hz, low, high) in &[
        (0.5, 0.995, 1.005),
        (2.0, 0.995, 1.005),
        (4.0, 0.995, 1.005),
        (8.0, 0.499, 0.501),
        (12.0, 0.0, 3e-3),
        (20.0, 0.0, 3e-3),
        (40.0, 0.0, 3e-3),
    ] {
        let x = sine(n, FS_HZ, f_hz, 1.0, 0.3);
        let y = fir.apply(&x).unwrap();
        let (gain, phase) = fit_sine(&y, FS_HZ, f_hz, interior.clone());
        let design = fir.amplitude(f_hz);
        assert!(
            (gain - design.abs()).abs() < 1e-9,
            "{f_hz} Hz: measured {gain}, design {design}"
        );
        assert!(
            (low..=high).contains(&fir.gain(f_hz)),
            "{f_hz} Hz: design gain {} outside [{low}, {high}]",
            fir.gain(f_hz)
        );
        // Phase of the output relative to sin(ωt): the input's 0.3 rad (+π on a negative lobe).
        let expected = 0.3 + fir.phase_rad(f_hz);
        let wrapped = (phase - expected + std::f64::consts::PI)
            .rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        if design.abs() > 1e-6 {
            assert!(wrapped.abs() < 1e-6, "{f_hz} Hz: phase error {wrapped} rad");
        }
    }
}

/// A pass-band multi-sine comes out in phase: the cross-correlation of output against input
/// peaks at lag 0 to within 0.01 sample (a causal FIR of order 512 would peak at lag 256; the
/// same measurement on the output delayed by one sample reads 1 ± 0.01, which calibrates it).
/// The parabolic peak estimate over a finite window reads 0.0025 sample here because the
/// three components pass with slightly different gains (1.000–1.004); the per-sine phase of
/// the previous test is the precise check (10⁻⁶ rad).
#[test]
fn output_is_zero_phase_cross_correlation_peaks_at_lag_zero() {
    let fir = paper_fir();
    let n = 8192;
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / FS_HZ;
            (2.0 * std::f64::consts::PI * 1.3 * t).sin()
                + 0.5 * (2.0 * std::f64::consts::PI * 3.1 * t + 1.0).sin()
                + 0.3 * (2.0 * std::f64::consts::PI * 5.2 * t + 2.0).sin()
        })
        .collect();
    let y = fir.apply(&x).unwrap();
    let lag = peak_lag(&x, &y, 1024..n - 1024, 300);
    assert!(lag.abs() < 1e-2, "lag {lag} samples");
    let mut delayed = vec![y[0]];
    delayed.extend_from_slice(&y[..n - 1]);
    let lag = peak_lag(&x, &delayed, 1024..n - 1024, 300);
    assert!((lag - 1.0).abs() < 1e-2, "calibration: lag {lag} samples");
    for &f in &[1.3, 3.1, 5.2] {
        assert_eq!(fir.phase_rad(f), 0.0);
    }
}

/// Odd reflection reproduces a line, and a symmetric unit-DC filter passes lines exactly, so a
/// DC offset plus a ramp comes out unchanged to rounding at every sample, edges included
/// (bound 1e-12 of the signal's 3 m scale: 513-term sums of values ≤ 3 carry ~1e-15 rounding).
#[test]
fn constant_plus_ramp_passes_with_no_edge_transient() {
    for fir in [
        paper_fir(),
        FirLowpass::new(16, 100.0, FS_HZ, Window::Hann).unwrap(),
    ] {
        let x: Vec<f64> = (0..3000).map(|i| 1.5 + 0.5 * i as f64 / FS_HZ).collect();
        let y = fir.apply(&x).unwrap();
        let err = max_abs_diff(&x, &y);
        assert!(err < 1e-12, "order {}: edge error {err}", fir.order());
    }
}

/// Every window gives unit DC gain and ≈ −6 dB at the cut-off (tapered windows within 1 %).
#[test]
fn every_window_gives_unit_dc_gain_and_half_gain_at_the_cutoff() {
    for window in [
        Window::Rectangular,
        Window::Hann,
        Window::Hamming,
        Window::Blackman,
    ] {
        let fir = FirLowpass::new(256, 20.0, FS_HZ, window).unwrap();
        assert!((fir.gain(0.0) - 1.0).abs() < 1e-12, "{window:?}");
        // The untapered sinc's Gibbs ripple moves its cut-off gain to 0.47.
        let tolerance = if window == Window::Rectangular {
            0.05
        } else {
            0.01
        };
        let gain = fir.gain(20.0);
        assert!((gain - 0.5).abs() < tolerance, "{window:?}: {gain}");
        assert_eq!(fir.window(), window);
    }
}

/// Records shorter than the filter are filtered too (the reflection repeats); a constant
/// stays constant (to rounding, 1e-12) and so does a one-sample record.
#[test]
fn records_shorter_than_the_filter_are_handled() {
    let fir = paper_fir();
    assert_eq!(fir.apply(&[]).unwrap(), Vec::<f64>::new());
    let one = fir.apply(&[2.5]).unwrap();
    assert!(one.len() == 1 && (one[0] - 2.5).abs() < 1e-12, "{one:?}");
    let y = fir.apply(&[4.0; 10]).unwrap();
    assert!(y.iter().all(|v| (v - 4.0).abs() < 1e-12), "{y:?}");
}

#[test]
fn invalid_designs_are_rejected_with_what_was_expected() {
    let odd = FirLowpass::new(511, 8.0, FS_HZ, Window::Hamming).unwrap_err();
    assert!(matches!(
        odd,
        SignalError::InvalidCount {
            name: "order",
            value: 511,
            ..
        }
    ));
    assert!(odd.to_string().contains("even order"), "{odd}");
    let high = FirLowpass::new(512, 512.0, FS_HZ, Window::Hamming).unwrap_err();
    assert!(matches!(
        high,
        SignalError::CutoffOutOfRange {
            cutoff_hz: 512.0,
            nyquist_hz: 512.0,
            ..
        }
    ));
    assert!(high.to_string().contains("(0, 512) Hz"), "{high}");
    for bad in [0.0, -8.0, f64::NAN] {
        assert!(FirLowpass::new(512, bad, FS_HZ, Window::Hamming).is_err());
    }
    assert!(matches!(
        FirLowpass::new(512, 8.0, f64::INFINITY, Window::Hamming),
        Err(SignalError::InvalidParameter {
            name: "sample_rate_hz",
            ..
        })
    ));
    let fir = paper_fir();
    assert!(matches!(
        fir.process(&[1.0, 2.0], &mut [0.0; 3]),
        Err(SignalError::LengthMismatch {
            expected: 2,
            found: 3,
            ..
        })
    ));
}
