//! The drive iteration on a linear plant whose `Ĥ` is exact: the plant is the FFT
//! multiplication by a known `H(f)` (a second-order loop with a delay), the iteration is told
//! that same `H`, and the acceleration error shrinks by exactly `1 − g` per iteration.

use std::f64::consts::TAU;

use proptest::prelude::*;
use rustfft::num_complex::Complex64 as C64;
use rustfft::FftPlanner;

use platen_plan::{iterate_with, IterationSettings, Response, Stop, TargetKind, TargetMotion};

/// The plant's response: `ωₙ²/(s² + 2ζωₙs + ωₙ²)·e^{−sτ}`, a 12 Hz loop with 30 % damping and
/// 4 ms of delay (resonant, lagging: nothing like 1).
fn plant_h(f_hz: f64) -> C64 {
    let s = C64::new(0.0, TAU * f_hz);
    let wn = TAU * 12.0;
    let zeta = 0.3;
    wn * wn / (s * s + 2.0 * zeta * wn * s + wn * wn) * (-s * 0.004).exp()
}

/// `x` filtered by `g(f)` on the circle of its own length (Hermitian: real in, real out).
fn filter(x: &[f64], rate_hz: f64, g: impl Fn(f64) -> C64) -> Vec<f64> {
    let n = x.len();
    let mut planner = FftPlanner::<f64>::new();
    let mut buf: Vec<C64> = x.iter().map(|&v| C64::new(v, 0.0)).collect();
    planner.plan_fft_forward(n).process(&mut buf);
    for (k, b) in buf.iter_mut().enumerate() {
        let (f, conj) = if k <= n / 2 {
            (k as f64 * rate_hz / n as f64, false)
        } else {
            ((n - k) as f64 * rate_hz / n as f64, true)
        };
        let gk = if k == 0 || (n % 2 == 0 && k == n / 2) {
            C64::new(0.0, 0.0)
        } else if conj {
            g(f).conj()
        } else {
            g(f)
        };
        *b *= gk;
    }
    planner.plan_fft_inverse(n).process(&mut buf);
    buf.iter().map(|c| c.re / n as f64).collect()
}

/// What the linear plant achieves.
struct Linear {
    u: Vec<f64>,
    a: Vec<f64>,
}

impl Response for Linear {
    fn u_m(&self, _axis: usize) -> &[f64] {
        &self.u
    }
    fn a_m_s2(&self, _axis: usize) -> &[f64] {
        &self.a
    }
}

/// A band-limited target on the circle: `components` sines on whole bins between `f_lo` and
/// `f_hi`, with the displacement its exact double integral (so the motion is one motion).
fn target(rate_hz: f64, n: usize, sines: &[(f64, f64, f64)]) -> TargetMotion {
    let t_s: Vec<f64> = (0..n).map(|j| j as f64 / rate_hz).collect();
    let df = rate_hz / n as f64;
    let (mut u, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for &(f_hz, amp, phase) in sines {
        let f = (f_hz / df).round().max(1.0) * df;
        let w = TAU * f;
        for j in 0..n {
            let arg = w * t_s[j] + phase;
            a[j] += amp * arg.sin();
            v[j] -= amp / w * arg.cos();
            u[j] -= amp / (w * w) * arg.sin();
        }
    }
    let rms = (a.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
    TargetMotion {
        t_s,
        u_m: u,
        v_m_s: v,
        a_m_s2: a,
        kind: TargetKind::Acceleration,
        end_degree: None,
        correction_rms_m_s2: 0.0,
        correction_peak_m_s2: 0.0,
        target_rms_m_s2: rms,
    }
}

/// The iteration with the exact inverse on the circle: no padding, no taper, no roll-off, no
/// regularisation, every iteration run.
fn exact_settings(gain: f64, iterations: usize) -> IterationSettings {
    IterationSettings {
        max_iterations: iterations,
        gain,
        target_nrmse: 0.0,
        band_hz: Some((0.2, 40.0)),
        edge_fraction: 0.0,
        regularisation: 0.0,
        stall_iterations: 100,
        min_improvement: 0.0,
        pad_s: Some(0.0),
        taper_s: 0.0,
        ..IterationSettings::default()
    }
}

fn run(motion: &TargetMotion, gain: f64, iterations: usize) -> Vec<f64> {
    let rate = 1.0 / motion.interval_s();
    let out = iterate_with(
        motion,
        &plant_h,
        &exact_settings(gain, iterations),
        |drive, _| {
            Ok(Linear {
                u: filter(drive, rate, plant_h),
                a: filter(drive, rate, |f| -(TAU * f).powi(2) * plant_h(f)),
            })
        },
    )
    .unwrap();
    assert_eq!(out.stop, Stop::MaxIterations);
    out.records.iter().map(|r| r.acceleration_nrmse).collect()
}

#[test]
fn the_error_shrinks_by_one_minus_the_gain_on_an_exact_plant() {
    let motion = target(
        256.0,
        2048,
        &[(1.0, 2.0, 0.3), (3.5, 1.0, 1.0), (9.0, 0.5, 2.0)],
    );
    let nrmse = run(&motion, 0.5, 6);
    assert!(
        nrmse[0] > 0.3,
        "the plant is not the identity: {}",
        nrmse[0]
    );
    for k in 1..nrmse.len() {
        let ratio = nrmse[k] / nrmse[k - 1];
        assert!((ratio - 0.5).abs() < 1e-9, "iteration {k}: ratio {ratio}");
    }
    // A gain of 1 with the exact inverse: done in one step.
    let one = run(&motion, 1.0, 1);
    assert!(one[1] < 1e-12 * one[0], "{one:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Any gain in (0.1, 1), any band-limited target: `e_{k+1} = (1 − g)·e_k`.
    #[test]
    fn the_error_shrinks_by_one_minus_the_gain_for_any_gain_and_target(
        gain in 0.1f64..1.0,
        sines in prop::collection::vec((0.3f64..30.0, 0.1f64..3.0, 0.0f64..TAU), 1..8),
        log2_n in 10u32..13,
    ) {
        let motion = target(256.0, 1 << log2_n, &sines);
        let nrmse = run(&motion, gain, 4);
        prop_assume!(nrmse[0] > 1e-6);
        for k in 1..nrmse.len() {
            let expected = nrmse[k - 1] * (1.0 - gain);
            prop_assert!(
                (nrmse[k] - expected).abs() <= 1e-8 * nrmse[0],
                "iteration {}: {} vs {} (g = {})", k, nrmse[k], expected, gain
            );
        }
    }
}

#[test]
fn content_outside_the_band_is_left_alone_and_the_rest_still_converges() {
    // Content at 60 Hz is outside the band [0.2, 40]: it is never corrected, so the error
    // there stays what the plant makes of it, and the in-band error still shrinks.
    let motion = target(256.0, 2048, &[(2.0, 1.0, 0.0), (60.0, 0.3, 0.0)]);
    let nrmse = run(&motion, 0.5, 8);
    let floor = nrmse[nrmse.len() - 1];
    assert!(floor > 0.05, "the out-of-band part is left alone: {floor}");
    assert!(nrmse.windows(2).all(|w| w[1] <= w[0] + 1e-12), "{nrmse:?}");
}
