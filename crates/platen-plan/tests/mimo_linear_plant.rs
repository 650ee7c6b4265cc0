//! The MIMO drive iteration on a cross-coupled linear plant whose `Ĥ` is exact: the plant
//! is the FFT multiplication of the three drives by a known 3 × 3 `H(f)` (second-order loops
//! with delays on the diagonal and strong couplings off it, as an eccentric specimen gives),
//! the iteration is told that same `H`, and every axis's acceleration error shrinks by
//! exactly `1 − g` per iteration, the axis held at zero included.

use std::f64::consts::TAU;

use rustfft::num_complex::Complex64 as C64;
use rustfft::FftPlanner;

use platen_plan::{iterate_mimo, AxisTarget, IterationSettings, Response, Stop, TransferMatrix};

/// `ωₙ²/(s² + 2ζωₙs + ωₙ²)·e^{−sτ}`.
fn loop_h(f_hz: f64, fn_hz: f64, zeta: f64, delay_s: f64) -> C64 {
    let s = C64::new(0.0, TAU * f_hz);
    let wn = TAU * fn_hz;
    wn * wn / (s * s + 2.0 * zeta * wn * s + wn * wn) * (-s * delay_s).exp()
}

/// The plant: x, y, z loops at 12, 9 and 15 Hz; x drives z at 40 % and y at 15 % (through a
/// band-pass: the specimen's rocking), z drives x at 20 %.
fn plant(f_hz: f64) -> TransferMatrix {
    let s = C64::new(0.0, TAU * f_hz);
    let rocking = s * TAU * 3.0 / (s * s + 0.4 * TAU * 3.0 * s + (TAU * 3.0).powi(2));
    let zero = C64::new(0.0, 0.0);
    vec![
        vec![loop_h(f_hz, 12.0, 0.3, 0.004), zero, rocking * 0.2],
        vec![rocking * 0.15, loop_h(f_hz, 9.0, 0.25, 0.003), zero],
        vec![rocking * 0.4, zero, loop_h(f_hz, 15.0, 0.35, 0.005)],
    ]
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

/// What the linear plant achieves, per axis.
struct Linear {
    u: Vec<Vec<f64>>,
    a: Vec<Vec<f64>>,
}

impl Response for Linear {
    fn u_m(&self, i: usize) -> &[f64] {
        &self.u[i]
    }
    fn a_m_s2(&self, i: usize) -> &[f64] {
        &self.a[i]
    }
}

fn run_plant(drives: &[Vec<f64>], rate: f64) -> Linear {
    let p = drives.len();
    let (mut u, mut a) = (
        vec![vec![0.0; drives[0].len()]; p],
        vec![vec![0.0; drives[0].len()]; p],
    );
    for i in 0..p {
        for (j, d) in drives.iter().enumerate() {
            let ui = filter(d, rate, |f| plant(f)[i][j]);
            let ai = filter(d, rate, |f| -(TAU * f).powi(2) * plant(f)[i][j]);
            for k in 0..ui.len() {
                u[i][k] += ui[k];
                a[i][k] += ai[k];
            }
        }
    }
    Linear { u, a }
}

/// An axis's band-limited target on the circle: sines on whole bins, the displacement the
/// exact double integral.
fn target(name: &'static str, rate_hz: f64, n: usize, sines: &[(f64, f64, f64)]) -> AxisTarget {
    let df = rate_hz / n as f64;
    let (mut u, mut a) = (vec![0.0; n], vec![0.0; n]);
    for &(f_hz, amp, phase) in sines {
        let w = TAU * (f_hz / df).round().max(1.0) * df;
        for j in 0..n {
            let arg = w * j as f64 / rate_hz + phase;
            a[j] += amp * arg.sin();
            u[j] -= amp / (w * w) * arg.sin();
        }
    }
    AxisTarget {
        name,
        u_m: u,
        a_m_s2: a,
    }
}

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

#[test]
fn every_axis_error_shrinks_by_one_minus_the_gain_on_an_exact_coupled_plant() {
    let (rate, n) = (256.0, 2048);
    let targets = vec![
        target(
            "x",
            rate,
            n,
            &[(1.0, 2.0, 0.3), (3.5, 1.0, 1.0), (9.0, 0.5, 2.0)],
        ),
        target("y", rate, n, &[(1.7, 1.0, 0.1), (6.0, 0.6, 2.5)]),
        AxisTarget::still("z", n),
    ];
    for gain in [0.5, 0.7] {
        let out = iterate_mimo(
            &targets,
            1.0 / rate,
            &plant,
            &exact_settings(gain, 6),
            |drives, _| Ok(run_plant(drives, rate)),
        )
        .unwrap();
        assert_eq!(out.stop, Stop::MaxIterations);
        let first = &out.records[0];
        // The coupling is real: z, commanded still, moves by the x drive's rocking.
        let z0 = first.axes["z"].rms_acceleration_error_m_s2;
        assert!(z0 > 0.1, "cross-talk into z: {z0}");
        assert!(first.axes["z"].acceleration_nrmse.is_none());
        for axis in ["x", "y", "z"] {
            let e: Vec<f64> = out
                .records
                .iter()
                .map(|r| r.axes[axis].rms_acceleration_error_m_s2)
                .collect();
            for k in 1..e.len() {
                let ratio = e[k] / e[k - 1];
                assert!(
                    (ratio - (1.0 - gain)).abs() < 1e-9,
                    "{axis}, iteration {k}, g = {gain}: ratio {ratio}"
                );
            }
        }
    }
    // A gain of 1 with the exact inverse: every axis done in one step.
    let out = iterate_mimo(
        &targets,
        1.0 / rate,
        &plant,
        &exact_settings(1.0, 1),
        |d, _| Ok(run_plant(d, rate)),
    )
    .unwrap();
    assert!(out.records[1].acceleration_nrmse < 1e-12 * out.records[0].acceleration_nrmse);
}

/// Correcting each axis through its own diagonal term alone (what a single-axis iteration
/// per axis does) does not remove the cross-talk the coupling makes; the matrix inverse
/// does (the reason for the MIMO iteration).
#[test]
fn the_diagonal_alone_leaves_the_cross_talk_the_matrix_removes() {
    let (rate, n) = (256.0, 2048);
    let targets = vec![
        target("x", rate, n, &[(2.0, 3.0, 0.0), (3.0, 2.0, 1.0)]),
        AxisTarget::still("y", n),
        AxisTarget::still("z", n),
    ];
    let diagonal = |f: f64| {
        let h = plant(f);
        let zero = C64::new(0.0, 0.0);
        (0..3)
            .map(|i| {
                (0..3)
                    .map(|j| if i == j { h[i][i] } else { zero })
                    .collect()
            })
            .collect::<TransferMatrix>()
    };
    let settings = exact_settings(0.7, 8);
    let full = iterate_mimo(&targets, 1.0 / rate, &plant, &settings, |d, _| {
        Ok(run_plant(d, rate))
    })
    .unwrap();
    let diag = iterate_mimo(&targets, 1.0 / rate, &diagonal, &settings, |d, _| {
        Ok(run_plant(d, rate))
    })
    .unwrap();
    let last =
        |it: &platen_plan::MimoIteration<Linear>| it.records.last().unwrap().acceleration_nrmse;
    eprintln!(
        "after 8: matrix {:e}, diagonal {:e}",
        last(&full),
        last(&diag)
    );
    assert!(last(&full) < 1e-3 * full.records[0].acceleration_nrmse);
    assert!(last(&diag) > 100.0 * last(&full));
}
