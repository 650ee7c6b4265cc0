//! Channel skew: the delay estimate and the fractional shift, against records written from
//! their formula at the delayed times (the delay is in the formula, not made by the code under
//! test).

mod common;

use std::f64::consts::PI;

use common::Rng;
use platen_signal::{advance, DelayEstimator, SignalError};

const FS_HZ: f64 = 204.8;

/// A displacement-like record: five sines (0.4–13 Hz) under the envelope `sin⁴(πt/T)`,
/// which starts and ends at rest (value and three derivatives zero), with its exact first two
/// derivatives.
struct Motion {
    duration_s: f64,
}

const TONES: [(f64, f64, f64); 5] = [
    // (amplitude m, frequency Hz, phase rad)
    (0.05, 0.4, 0.3),
    (0.02, 1.3, 1.1),
    (0.006, 3.7, -0.4),
    (0.0015, 7.9, 2.0),
    (0.0004, 13.0, -1.5),
];

impl Motion {
    /// `(u, u̇, ü)` at `t_s` (zero outside the record).
    fn at(&self, t_s: f64) -> [f64; 3] {
        if !(0.0..=self.duration_s).contains(&t_s) {
            return [0.0; 3];
        }
        let c = PI / self.duration_s;
        let (s, co) = (c * t_s).sin_cos();
        let e = [
            s.powi(4),
            4.0 * s.powi(3) * co * c,
            c * c * (12.0 * s * s * co * co - 4.0 * s.powi(4)),
        ];
        let mut x = [0.0; 3];
        for (a, f, p) in TONES {
            let w = 2.0 * PI * f;
            let (sn, cs) = (w * t_s + p).sin_cos();
            x[0] += a * sn;
            x[1] += a * w * cs;
            x[2] -= a * w * w * sn;
        }
        [
            x[0] * e[0],
            x[1] * e[0] + x[0] * e[1],
            x[2] * e[0] + 2.0 * x[1] * e[1] + x[0] * e[2],
        ]
    }

    fn samples(&self) -> usize {
        (self.duration_s * FS_HZ).round() as usize + 1
    }

    /// Channel `k` (0: u, 2: a) sampled at `i/f_s − delay_s`.
    fn channel(&self, k: usize, delay_s: f64) -> Vec<f64> {
        (0..self.samples())
            .map(|i| self.at(i as f64 / FS_HZ - delay_s)[k])
            .collect()
    }
}

/// Advancing the formula's record sampled `k + f` samples late gives the formula's record
/// on time. Tolerance 1e-9 of the peak: the record is not exactly band-limited (the envelope
/// is C³ at the ends, so its spectrum falls as f⁻⁵ and what lies above the Nyquist frequency
/// aliases), measured 3e-11; rounding of the FFTs is 1e-15.
#[test]
fn advancing_a_record_sampled_late_restores_the_record_on_time() {
    let m = Motion { duration_s: 30.0 };
    let on_time = m.channel(0, 0.0);
    let peak = on_time.iter().fold(0.0f64, |p, x| p.max(x.abs()));
    for shift in [2.37, 0.5, -1.61, 7.0] {
        let late = m.channel(0, shift / FS_HZ);
        let fixed = advance(&late, shift).unwrap();
        let err = fixed
            .iter()
            .zip(&on_time)
            .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
        assert!(err < 1e-9 * peak, "shift {shift}: error {err:e} of {peak}");
        // Not a no-op: the late record differs from the record on time by far more.
        let before = late
            .iter()
            .zip(&on_time)
            .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
        assert!(before > 1e-4 * peak, "shift {shift}: {before:e}");
    }
}

/// A record that does not start or end at rest (two sines, amplitude 1.3, cut anywhere) is
/// shifted exactly away from its ends, where the odd extension is not its true continuation:
/// within 1e-6 beyond 100 samples of either end (measured 1.8e-7), 5e-3 nearer (measured
/// 1.1e-3), and the last three samples, which a 2.37-sample advance takes from beyond the
/// record (extrapolation by the odd extension), within 0.5 (measured 0.23).
#[test]
fn a_record_cut_anywhere_is_shifted_exactly_away_from_its_ends() {
    let n = 4000;
    let x = |t: f64| (2.0 * PI * 3.0 * t + 0.7).sin() + 0.3 * (2.0 * PI * 11.3 * t).cos();
    let shift = 2.37;
    let late: Vec<f64> = (0..n).map(|i| x((i as f64 - shift) / FS_HZ)).collect();
    let fixed = advance(&late, shift).unwrap();
    let mut worst = [0.0f64; 3];
    for (i, v) in fixed.iter().enumerate() {
        let e = (v - x(i as f64 / FS_HZ)).abs();
        let region = if i + 3 >= n {
            2
        } else if i < 100 || i + 100 >= n {
            1
        } else {
            0
        };
        worst[region] = worst[region].max(e);
    }
    assert!(
        worst[0] < 1e-6 && worst[1] < 5e-3 && worst[2] < 0.5,
        "{worst:?}"
    );
}

/// The delay of an accelerometer sampled 2.37 samples late against the displacement, with a
/// lab's noise (0.03 m/s² on a, 0.02 mm on u): within three standard errors, and the
/// standard error is a small fraction of a sample.
#[test]
fn the_delay_of_a_late_accelerometer_is_found_to_a_fraction_of_a_sample() {
    let m = Motion { duration_s: 30.0 };
    let tau_s = 2.37 / FS_HZ;
    let mut rng = Rng::new(7);
    let mut u = m.channel(0, 0.0);
    let mut a = m.channel(2, tau_s);
    for (x, e) in u.iter_mut().zip(rng.white(m.samples(), 2e-5)) {
        *x += e;
    }
    for (x, e) in a.iter_mut().zip(rng.white(m.samples(), 0.03)) {
        *x += e + 0.012;
    }
    let est = DelayEstimator::new(FS_HZ)
        .unwrap()
        .acceleration_against_displacement(&a, &u)
        .unwrap();
    let err = est.delay_s - tau_s;
    assert!(
        err.abs() < 3.0 * est.std_error_s,
        "τ̂ = {} samples ± {}",
        est.delay_s * FS_HZ,
        est.std_error_s * FS_HZ
    );
    assert!(est.std_error_s * FS_HZ < 0.05, "{est:?}");
    assert!(est.band_hz[0] < 1.0 && est.band_hz[1] > 10.0, "{est:?}");
    // With a hundredth of the noise, to within a hundredth of a sample.
    let a_quiet: Vec<f64> = m
        .channel(2, tau_s)
        .iter()
        .zip(rng.white(m.samples(), 3e-4))
        .map(|(v, e)| v + e)
        .collect();
    let u_quiet: Vec<f64> = m
        .channel(0, 0.0)
        .iter()
        .zip(rng.white(m.samples(), 2e-7))
        .map(|(v, e)| v + e)
        .collect();
    let quiet = DelayEstimator::new(FS_HZ)
        .unwrap()
        .acceleration_against_displacement(&a_quiet, &u_quiet)
        .unwrap();
    assert!(
        (quiet.delay_s - tau_s).abs() * FS_HZ < 0.01,
        "{}",
        quiet.delay_s * FS_HZ
    );
}

/// A channel that leads its reference (negative delay) by 1.4 samples, the general
/// estimate (channel and reference of the same kind).
#[test]
fn a_channel_that_leads_has_a_negative_delay() {
    let m = Motion { duration_s: 20.0 };
    let tau_s = -1.4 / FS_HZ;
    let mut rng = Rng::new(11);
    let x: Vec<f64> = m
        .channel(1, 0.0)
        .iter()
        .zip(rng.white(m.samples(), 1e-3))
        .map(|(v, e)| v + e)
        .collect();
    let y: Vec<f64> = m
        .channel(1, tau_s)
        .iter()
        .zip(rng.white(m.samples(), 1e-3))
        .map(|(v, e)| 2.5 * v + e)
        .collect();
    let est = DelayEstimator::new(FS_HZ)
        .unwrap()
        .estimate(&y, &x)
        .unwrap();
    assert!(
        (est.delay_s - tau_s).abs() < 3.0 * est.std_error_s,
        "{} vs {}",
        est.delay_s * FS_HZ,
        tau_s * FS_HZ
    );
}

/// The standard error is honest: over 40 noise draws the errors' RMS in standard errors is
/// near 1 (0.5–1.5: with 40 draws the RMS of unit normals scatters by ±0.11; the lower bound
/// allows for the χ² inflation making the error conservative, the upper one would fail an
/// error understated by half).
#[test]
fn the_standard_error_matches_the_scatter_over_noise_draws() {
    let m = Motion { duration_s: 30.0 };
    let tau_s = 2.0 / FS_HZ;
    let u0 = m.channel(0, 0.0);
    let a0 = m.channel(2, tau_s);
    let est = DelayEstimator::new(FS_HZ).unwrap();
    let mut z2 = 0.0;
    let draws = 40;
    for seed in 0..draws {
        let mut rng = Rng::new(1000 + seed);
        let u: Vec<f64> = u0
            .iter()
            .zip(rng.white(u0.len(), 2e-5))
            .map(|(v, e)| v + e)
            .collect();
        // Strong noise, so that the estimate scatters well above the formula's own error.
        let a: Vec<f64> = a0
            .iter()
            .zip(rng.white(a0.len(), 0.3))
            .map(|(v, e)| v + e)
            .collect();
        let e = est.acceleration_against_displacement(&a, &u).unwrap();
        z2 += ((e.delay_s - tau_s) / e.std_error_s).powi(2);
    }
    let rms = (z2 / draws as f64).sqrt();
    assert!((0.5..1.5).contains(&rms), "RMS error {rms} standard errors");
}

#[test]
fn unrelated_channels_are_incoherent_and_bad_input_is_an_error() {
    let mut rng = Rng::new(3);
    let x = rng.white(4096, 1.0);
    let y = rng.white(4096, 1.0);
    let est = DelayEstimator::new(FS_HZ).unwrap();
    assert!(matches!(
        est.estimate(&y, &x),
        Err(SignalError::Incoherent { .. })
    ));
    assert!(matches!(
        est.estimate(&y[..100], &x[..100]),
        Err(SignalError::RecordTooShort { .. })
    ));
    assert!(matches!(
        est.estimate(&y[..1000], &x),
        Err(SignalError::LengthMismatch { .. })
    ));
    assert!(DelayEstimator::new(0.0).is_err());
}
