//! Comparison metrics on constructed signals whose answers are known in closed form.

mod common;

use std::f64::consts::PI;

use common::Rng;
use platen_signal::metrics::{
    correlation_by_lag, interpolate_linear, lag_by_cross_correlation, pearson, rms, Comparator,
};
use platen_signal::SignalError;

const FS_HZ: f64 = 200.0;

/// A smooth, band-limited test signal: five sines between 0.3 and 3 Hz with seeded phases,
/// evaluated at any time (so a delayed copy is exact, not interpolated).
struct Smooth {
    parts: Vec<(f64, f64, f64)>,
}

impl Smooth {
    fn new(seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let parts = [0.3, 0.7, 1.1, 1.9, 3.0]
            .iter()
            .map(|&f| (f, 0.5 + rng.uniform(), 2.0 * PI * rng.uniform()))
            .collect();
        Self { parts }
    }

    fn at(&self, t: f64) -> f64 {
        self.parts
            .iter()
            .map(|(f, a, p)| a * (2.0 * PI * f * t + p).sin())
            .sum()
    }

    /// `n` samples at `FS_HZ` from t = 0, delayed by `delay_s`: `x(t − delay)`.
    fn sampled(&self, n: usize, delay_s: f64) -> Vec<f64> {
        (0..n)
            .map(|i| self.at(i as f64 / FS_HZ - delay_s))
            .collect()
    }
}

fn comparator(max_lag_s: f64) -> Comparator {
    Comparator::new(FS_HZ, 0.0, max_lag_s).unwrap()
}

#[test]
fn identical_signals_have_zero_error_unit_correlation_and_zero_lag() {
    let x = Smooth::new(1).sampled(4000, 0.0);
    let m = comparator(0.5).compare(&x, &x).unwrap();
    assert_eq!(m.samples, 4000);
    assert_eq!(m.span_s, [0.0, 3999.0 / FS_HZ]);
    assert_eq!(m.rms_error, 0.0);
    assert_eq!(m.nrmse, Some(0.0));
    assert_eq!(m.peak_ratio, Some(1.0));
    assert_eq!(m.peak_recorded, m.peak_simulated);
    assert!((m.correlation.unwrap() - 1.0).abs() < 1e-14);
    let lag = m.lag.unwrap();
    // Zero to rounding: the parabola through a symmetric peak has its vertex on it.
    assert!(lag.lag_s.abs() < 1e-12, "{}", lag.lag_s);
    assert!(!lag.at_search_limit);
    assert!((lag.peak_correlation - 1.0).abs() < 1e-12);
}

/// `simulated = s·recorded`: the error is `(s − 1)·recorded`, so `rms_error = |1 − s|·rms`,
/// `nrmse = |1 − s|`, the peak ratio is `|s|`, the correlation is `sign(s)` and the lag 0.
#[test]
fn a_scaled_copy_gives_that_peak_ratio_and_an_nrmse_of_one_minus_the_scale() {
    let x = Smooth::new(2).sampled(3000, 0.0);
    for s in [0.8, 0.97, 1.0, 1.25, 2.0] {
        let y: Vec<f64> = x.iter().map(|v| s * v).collect();
        let m = comparator(0.5).compare(&x, &y).unwrap();
        let expected = (1.0f64 - s).abs();
        assert!(
            (m.nrmse.unwrap() - expected).abs() < 1e-12,
            "s = {s}: {m:?}"
        );
        assert!((m.rms_error - expected * rms(&x)).abs() < 1e-12);
        assert!((m.peak_ratio.unwrap() - s).abs() < 1e-12, "s = {s}");
        assert_eq!(m.peak_simulated.t_s, m.peak_recorded.t_s);
        assert!((m.correlation.unwrap() - 1.0).abs() < 1e-12);
        assert!(m.lag.unwrap().lag_s.abs() < 1e-12, "s = {s}");
    }
    // A negative scale: the signed peaks have opposite signs, the ratio is of magnitudes.
    let y: Vec<f64> = x.iter().map(|v| -0.5 * v).collect();
    let m = comparator(0.5).compare(&x, &y).unwrap();
    assert!((m.nrmse.unwrap() - 1.5).abs() < 1e-12);
    assert!((m.peak_ratio.unwrap() - 0.5).abs() < 1e-12);
    assert_eq!(
        m.peak_simulated.value.signum(),
        -m.peak_recorded.value.signum()
    );
    assert!((m.correlation.unwrap() + 1.0).abs() < 1e-12);
}

/// A pure delay `x(t − τ)` of a smooth signal gives the lag τ, whole samples or not, either
/// sign. The normalised cross-correlation near its peak is `1 − c·(kΔt − τ)²` to within the
/// fourth-order term, so the parabola through three samples finds τ to a small fraction of a
/// sample (here better than 1 % of Δt = 5 ms).
#[test]
fn a_pure_delay_gives_that_lag() {
    let n = 6000;
    let signal = Smooth::new(3);
    let x = signal.sampled(n, 0.0);
    let dt = 1.0 / FS_HZ;
    for delay_s in [0.0, 7.0 * dt, 2.46 * dt, 0.0123, -3.3 * dt, -0.1, 0.2377] {
        let y = signal.sampled(n, delay_s);
        let lag = comparator(0.25).compare(&x, &y).unwrap().lag.unwrap();
        assert!(
            (lag.lag_s - delay_s).abs() < 0.01 * dt,
            "delay {delay_s} s: found {} s",
            lag.lag_s
        );
        assert!(!lag.at_search_limit);
        assert!(lag.peak_correlation > 0.999);
        // The free function agrees with the comparator.
        let free = lag_by_cross_correlation(&x, &y, FS_HZ, 0.25)
            .unwrap()
            .unwrap();
        assert_eq!(free, lag);
    }
}

/// A sine delayed by τ has `nrmse = |1 − e^(−iωτ)| = 2|sin(ωτ/2)|` over whole periods.
#[test]
fn a_delayed_sine_has_the_nrmse_of_its_phase_error() {
    let (f, tau) = (0.5, 0.02);
    let n = (10.0 * FS_HZ) as usize; // 5 whole periods
    let x: Vec<f64> = (0..n)
        .map(|i| (2.0 * PI * f * i as f64 / FS_HZ).sin())
        .collect();
    let y: Vec<f64> = (0..n)
        .map(|i| (2.0 * PI * f * (i as f64 / FS_HZ - tau)).sin())
        .collect();
    let m = comparator(0.25).compare(&x, &y).unwrap();
    let expected = 2.0 * (PI * f * tau).sin().abs();
    assert!(
        (m.nrmse.unwrap() - expected).abs() < 1e-9,
        "{} vs {expected}",
        m.nrmse.unwrap()
    );
    assert!((m.lag.unwrap().lag_s - tau).abs() < 1e-5);
    assert!((m.correlation.unwrap() - (2.0 * PI * f * tau).cos()).abs() < 1e-9);
}

#[test]
fn a_delay_beyond_the_search_bound_is_reported_at_the_limit() {
    let signal = Smooth::new(4);
    let x = signal.sampled(4000, 0.0);
    let y = signal.sampled(4000, 0.3);
    let lag = comparator(0.1).compare(&x, &y).unwrap().lag.unwrap();
    assert!(lag.at_search_limit);
    assert_eq!(lag.lag_s, 0.1);
}

#[test]
fn signed_peaks_keep_their_sign_and_time() {
    let mut x = vec![0.0; 100];
    x[10] = 2.0;
    x[40] = -3.0;
    x[70] = 3.0; // a tie in magnitude: the first one counts
    let mut y = vec![0.0; 100];
    y[55] = -1.5;
    let c = Comparator::new(10.0, 100.0, 0.0).unwrap();
    let m = c.compare(&x, &y).unwrap();
    assert_eq!(m.peak_recorded.value, -3.0);
    assert!((m.peak_recorded.t_s - 104.0).abs() < 1e-12);
    assert_eq!(m.peak_simulated.value, -1.5);
    assert!((m.peak_simulated.t_s - 105.5).abs() < 1e-12);
    assert_eq!(m.peak_ratio, Some(0.5));
}

/// Outside the window the simulation is wrong by 1; inside it is exact, so every metric of
/// the window is that of identical signals, and the span is the window's.
#[test]
fn a_window_restricts_every_metric_to_its_samples() {
    let x = Smooth::new(5).sampled(2000, 0.0);
    let mut y = x.clone();
    for (i, v) in y.iter_mut().enumerate() {
        let t = i as f64 / FS_HZ;
        if !(2.0..=6.0).contains(&t) {
            *v += 1.0;
        }
    }
    let whole = comparator(0.1).compare(&x, &y).unwrap();
    assert!(whole.nrmse.unwrap() > 0.1);
    let windowed = comparator(0.1)
        .with_window_s(2.0, 6.0)
        .unwrap()
        .compare(&x, &y)
        .unwrap();
    assert_eq!(windowed.samples, 801);
    assert_eq!(windowed.span_s, [2.0, 6.0]);
    assert_eq!(windowed.rms_error, 0.0);
    assert!(windowed.lag.unwrap().lag_s.abs() < 1e-12);
    assert!((windowed.correlation.unwrap() - 1.0).abs() < 1e-12);
    // A window that misses the record is an error, not a silent empty result.
    let missed = comparator(0.1)
        .with_window_s(50.0, 60.0)
        .unwrap()
        .compare(&x, &y)
        .unwrap_err();
    assert!(matches!(
        missed,
        SignalError::RecordTooShort { found: 0, .. }
    ));
}

#[test]
fn undefined_metrics_are_none_not_nan() {
    let zero = vec![0.0; 50];
    let constant = vec![2.0; 50];
    let varying: Vec<f64> = (0..50).map(|i| (i as f64 * 0.3).sin()).collect();
    let m = comparator(0.05).compare(&zero, &varying).unwrap();
    assert_eq!(m.nrmse, None);
    assert_eq!(m.peak_ratio, None);
    assert_eq!(m.correlation, None);
    assert_eq!(m.lag, None);
    let m = comparator(0.05).compare(&varying, &constant).unwrap();
    assert!(m.nrmse.unwrap().is_finite());
    assert_eq!(m.correlation, None);
    assert_eq!(m.lag, None);
}

#[test]
fn bad_plans_and_inputs_are_rejected() {
    assert!(Comparator::new(0.0, 0.0, 1.0).is_err());
    assert!(Comparator::new(100.0, f64::NAN, 1.0).is_err());
    assert!(Comparator::new(100.0, 0.0, -1.0).is_err());
    assert!(comparator(1.0).with_window_s(2.0, 2.0).is_err());
    assert!(comparator(1.0).with_window_s(f64::NAN, 2.0).is_err());
    assert!(matches!(
        comparator(1.0).compare(&[1.0, 2.0, 3.0], &[1.0, 2.0]),
        Err(SignalError::LengthMismatch { .. })
    ));
    assert!(matches!(
        comparator(1.0).compare(&[1.0], &[1.0]),
        Err(SignalError::RecordTooShort { .. })
    ));
    assert!(pearson(&[1.0, 2.0], &[1.0]).is_err());
}

/// The FFT-and-prefix-sum coefficients equal Pearson's coefficient of the overlapping parts
/// computed directly, on seeded random input with an offset (so the centring matters).
#[test]
fn the_coefficient_at_every_lag_equals_the_direct_pearson_coefficient() {
    let mut rng = Rng::new(42);
    let n = 300;
    let x: Vec<f64> = (0..n).map(|_| 5.0 + rng.normal()).collect();
    let y: Vec<f64> = (0..n).map(|_| -3.0 + 2.0 * rng.normal()).collect();
    let table = correlation_by_lag(&x, &y, 40).unwrap();
    assert_eq!(table.len(), 81);
    for (k, rho) in table {
        let pairs: Vec<(f64, f64)> = (0..n as isize)
            .filter(|i| (0..n as isize).contains(&(i + k)))
            .map(|i| (x[i as usize], y[(i + k) as usize]))
            .collect();
        let (a, b): (Vec<f64>, Vec<f64>) = pairs.into_iter().unzip();
        let direct = pearson(&a, &b).unwrap().unwrap();
        assert!((rho.unwrap() - direct).abs() < 1e-12, "k = {k}");
    }
}

#[test]
fn linear_interpolation_is_exact_at_the_stamps_linear_between_and_constant_outside() {
    let t = [0.0, 1.0, 3.0];
    let y = [1.0, 3.0, -1.0];
    let got = interpolate_linear(&t, &y, &[-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0]).unwrap();
    assert_eq!(got, vec![1.0, 1.0, 2.0, 3.0, 1.0, -1.0, -1.0]);
    assert!(interpolate_linear(&[0.0, 0.0], &[1.0, 2.0], &[0.0]).is_err());
    assert!(interpolate_linear(&[0.0, 1.0], &[1.0], &[0.0]).is_err());
    assert!(interpolate_linear(&[], &[], &[0.0]).is_err());
    assert!(interpolate_linear(&[0.0, 1.0], &[1.0, 2.0], &[f64::NAN]).is_err());
}
