//! Resampling to a new rate.

mod common;

use std::f64::consts::PI;

use common::max_abs_diff;
use platen_signal::{Interpolation, Resampler, SignalError};

/// A band-limited motion: components at 1, 3.7 and 9 Hz (amplitudes 1, 0.5, 0.25).
fn motion(t_s: f64) -> f64 {
    [(1.0, 1.0, 0.0), (3.7, 0.5, 1.0), (9.0, 0.25, 2.0)]
        .iter()
        .map(|(f, a, p)| a * (2.0 * PI * f * t_s + p).sin())
        .sum()
}

/// 8 s at 1024 Hz down to 128 Hz and back up to 1024 Hz (cubic spline).
///
/// * Down: the anti-alias filter passes 9 Hz (7 % of the new rate, well inside its pass band
///   below 0.3·128 = 38 Hz) with a gain within the Hamming ripple, so the 128 Hz samples match
///   the motion at their times within 2e-3 (measured 9.8e-4; the ripple is ≤ 0.5 % of the 0.25
///   and 0.5 amplitudes).
/// * Up: the spline's error on a 9 Hz component sampled at 128 Hz (`2πf/f_s = 0.44`) is about
///   `(5/384)·0.44⁴·0.25 = 1.2e-4`. The round trip matches the original within 3e-3 everywhere,
///   edges included (measured 1.0e-3), for a signal of peak ≈ 1.75.
#[test]
fn down_and_up_sampling_preserves_a_band_limited_signal() {
    let (fast, slow) = (1024.0, 128.0);
    let x: Vec<f64> = (0..8 * 1024 + 1).map(|i| motion(i as f64 / fast)).collect();
    let down = Resampler::new(fast, slow, Interpolation::Cubic).unwrap();
    let d = down.apply(&x).unwrap();
    assert_eq!(d.len(), 8 * 128 + 1);
    let exact: Vec<f64> = (0..d.len()).map(|k| motion(k as f64 / slow)).collect();
    let e_down = max_abs_diff(&d, &exact);
    assert!(e_down < 2e-3, "downsampled error {e_down}");

    let up = Resampler::new(slow, fast, Interpolation::Cubic).unwrap();
    let y = up.apply(&d).unwrap();
    assert_eq!(y.len(), x.len());
    let e_round = max_abs_diff(&y, &x);
    assert!(e_round < 3e-3, "round-trip error {e_round}");
}

/// Upsampling a unit sine by interpolation, errors over the whole record against the sine at
/// the new times. Cubic spline: the interior error of cubic-spline interpolation is about
/// `(5/384)·(2πf/f_s)⁴`, 1.3e-4 at `f_s/20` and 4.9e-3 at `f_s/8`; the not-a-knot ends roughly
/// double it (measured 1.6e-4 and 1.06e-2): bounds 2e-4 and 1.2e-2. Linear: below
/// `(π/20)²/2 = 1.23e-2` at `f_s/20` (measured 1.22e-2), some 75 times the spline's error.
#[test]
fn upsampling_error_matches_the_interpolation_order() {
    let (from, to) = (100.0, 1000.0);
    let error = |f: f64, method| {
        let x: Vec<f64> = (0..800)
            .map(|i| (2.0 * PI * f * i as f64 / from).sin())
            .collect();
        let y = Resampler::new(from, to, method).unwrap().apply(&x).unwrap();
        let exact: Vec<f64> = (0..y.len())
            .map(|k| (2.0 * PI * f * k as f64 / to).sin())
            .collect();
        max_abs_diff(&y, &exact)
    };
    let cubic_20 = error(from / 20.0, Interpolation::Cubic);
    let cubic_8 = error(from / 8.0, Interpolation::Cubic);
    let linear_20 = error(from / 20.0, Interpolation::Linear);
    let report =
        format!("cubic f_s/20 {cubic_20:e}, f_s/8 {cubic_8:e}; linear f_s/20 {linear_20:e}");
    assert!(cubic_20 < 2e-4, "{report}");
    assert!(cubic_8 < 1.2e-2, "{report}");
    assert!(
        linear_20 < 1.234e-2 && linear_20 > 50.0 * cubic_20,
        "{report}"
    );
}

/// Content above the new Nyquist frequency does not alias: a 100 Hz sine (above 64 Hz) taken
/// down from 1024 to 128 Hz, where it would alias to 28 Hz, comes out below 3.2e-3 (−50 dB,
/// the anti-alias filter's stop band) away from the edges.
#[test]
fn downsampling_rejects_content_above_the_new_nyquist_frequency() {
    let x: Vec<f64> = (0..8192)
        .map(|i| (2.0 * PI * 100.0 * i as f64 / 1024.0).sin())
        .collect();
    let r = Resampler::new(1024.0, 128.0, Interpolation::Cubic).unwrap();
    assert!(r.gain(100.0) < 3.2e-3);
    assert!((r.gain(0.3 * 128.0) - 1.0).abs() < 5e-3);
    let y = r.apply(&x).unwrap();
    let interior = &y[64..y.len() - 64];
    let peak = interior.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(peak < 3.2e-3, "aliased residue {peak}");
}

/// Constants and ramps are resampled exactly (1e-12), in both directions and at a non-integer
/// ratio; lengths follow `⌊(n − 1)·to/from⌋ + 1`.
#[test]
fn ramps_resample_exactly_and_lengths_cover_the_span() {
    for (from, to) in [(1024.0, 200.0), (200.0, 1024.0), (512.0, 512.0)] {
        let x: Vec<f64> = (0..1000).map(|i| 0.5 + 0.01 * i as f64 / from).collect();
        for method in [Interpolation::Linear, Interpolation::Cubic] {
            let r = Resampler::new(from, to, method).unwrap();
            let y = r.apply(&x).unwrap();
            assert_eq!(y.len(), (999.0 * to / from) as usize + 1);
            let exact: Vec<f64> = (0..y.len()).map(|k| 0.5 + 0.01 * k as f64 / to).collect();
            assert!(
                max_abs_diff(&y, &exact) < 1e-12,
                "{from} → {to} Hz, {method:?}"
            );
        }
    }
    let r = Resampler::new(100.0, 50.0, Interpolation::Cubic).unwrap();
    assert_eq!(r.apply(&[]).unwrap(), Vec::<f64>::new());
    let one = r.apply(&[3.0]).unwrap();
    assert!(one.len() == 1 && (one[0] - 3.0).abs() < 1e-12, "{one:?}");
    assert_eq!(r.output_len(3), 2);
}

#[test]
fn bad_rates_and_output_lengths_are_rejected() {
    assert!(matches!(
        Resampler::new(0.0, 100.0, Interpolation::Cubic),
        Err(SignalError::InvalidParameter {
            name: "from_hz",
            ..
        })
    ));
    assert!(matches!(
        Resampler::new(100.0, f64::NAN, Interpolation::Cubic),
        Err(SignalError::InvalidParameter { name: "to_hz", .. })
    ));
    let r = Resampler::new(100.0, 50.0, Interpolation::Linear).unwrap();
    assert!(matches!(
        r.process(&[0.0; 10], &mut [0.0; 4]),
        Err(SignalError::LengthMismatch {
            expected: 5,
            found: 4,
            ..
        })
    ));
}
