//! Helpers shared by the integration tests: a seeded PRNG, sines, and a least-squares sine fit.
#![allow(dead_code)]

use std::f64::consts::PI;

/// SplitMix64: a small, fixed, seeded generator (so every test draws the same numbers).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }

    /// `n` samples of zero-mean white noise with standard deviation `sigma`.
    pub fn white(&mut self, n: usize, sigma: f64) -> Vec<f64> {
        (0..n).map(|_| sigma * self.normal()).collect()
    }
}

/// Times `t_s = i/fs` of `n` samples.
pub fn times(n: usize, fs_hz: f64) -> Vec<f64> {
    (0..n).map(|i| i as f64 / fs_hz).collect()
}

/// `amplitude·sin(2πft + phase)` sampled at `fs`.
pub fn sine(n: usize, fs_hz: f64, f_hz: f64, amplitude: f64, phase_rad: f64) -> Vec<f64> {
    (0..n)
        .map(|i| amplitude * (2.0 * PI * f_hz * i as f64 / fs_hz + phase_rad).sin())
        .collect()
}

/// Least-squares fit of `A·sin(2πft + φ)` to `x[range]` (time from sample 0); returns `(A, φ)`.
pub fn fit_sine(x: &[f64], fs_hz: f64, f_hz: f64, range: std::ops::Range<usize>) -> (f64, f64) {
    let (mut ss, mut sc, mut cc, mut xs, mut xc) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in range {
        let w = 2.0 * PI * f_hz * i as f64 / fs_hz;
        let (s, c) = w.sin_cos();
        ss += s * s;
        sc += s * c;
        cc += c * c;
        xs += x[i] * s;
        xc += x[i] * c;
    }
    let det = ss * cc - sc * sc;
    let a = (xs * cc - xc * sc) / det;
    let b = (xc * ss - xs * sc) / det;
    (a.hypot(b), b.atan2(a))
}

/// Largest `|a − b|` over the slices.
pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Root mean square of `a − b`.
pub fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

/// Lag of `y` behind `x`, samples, at the peak of their normalised cross-correlation over
/// `range`, refined by a parabola through the best integer lag and its neighbours (searched
/// within `±max_lag`). A causal filter with a delay of `d` samples gives ≈ `d`.
pub fn peak_lag(x: &[f64], y: &[f64], range: std::ops::Range<usize>, max_lag: isize) -> f64 {
    let corr = |l: isize| -> f64 {
        let (mut xy, mut xx, mut yy) = (0.0, 0.0, 0.0);
        for i in range.clone() {
            let (a, b) = (x[i], y[(i as isize + l) as usize]);
            xy += a * b;
            xx += a * a;
            yy += b * b;
        }
        xy / (xx * yy).sqrt()
    };
    let best = (-max_lag..=max_lag)
        .max_by(|&a, &b| corr(a).total_cmp(&corr(b)))
        .unwrap();
    let (cm, c0, cp) = (corr(best - 1), corr(best), corr(best + 1));
    best as f64 + 0.5 * (cm - cp) / (cm - 2.0 * c0 + cp)
}
