//! What the closed-form tests share: the frictionless table, the sine force record and the
//! projection fit of a steady sine.
#![allow(dead_code)]

use platen_integrate::ForceRecord;
use platen_model::{IdentifiedModel, IdentifiedParams};

/// The effective mass of every frictionless table here (the LHPOST's, 144 t), kg.
pub const M_KG: f64 = 144e3;
/// The sample rate of the sine records, Hz.
pub const RATE_HZ: f64 = 1024.0;

/// A table without friction (`F_μ = a = 0`, so `F_s = 0`): mass [`M_KG`], stiffness, and the
/// dissipative law `viscous·|v|^alpha`.
pub fn frictionless(stiffness_n_per_m: f64, viscous: f64, alpha: f64) -> IdentifiedModel {
    IdentifiedParams {
        effective_mass_kg: M_KG,
        stiffness_n_per_m,
        coulomb_force_n: 0.0,
        viscous_coefficient: viscous,
        viscous_exponent: alpha,
        low_velocity_force_n: 0.0,
        low_velocity_decay_s_per_m: 78.5,
    }
    .build()
    .unwrap()
}

/// `amplitude_n·sin(ω t)` sampled at [`RATE_HZ`] from 0 to `duration_s` inclusive.
pub fn sine_record(amplitude_n: f64, omega: f64, duration_s: f64) -> ForceRecord {
    let n = (duration_s * RATE_HZ) as usize;
    let force = (0..=n)
        .map(|j| amplitude_n * (omega * j as f64 / RATE_HZ).sin())
        .collect();
    ForceRecord::from_rate(RATE_HZ, force).unwrap()
}

/// Least-squares fit of `A·sin ωt + B·cos ωt` over the samples `from..from + n`, `n` a whole
/// number of periods of samples (there the sines and cosines are orthogonal, so the fit is
/// the projection `A = 2/n·Σ u sin ωt`, `B = 2/n·Σ u cos ωt`).
pub fn sine_fit(t: &[f64], u: &[f64], omega: f64, from: usize, n: usize) -> (f64, f64) {
    let (mut a, mut b) = (0.0, 0.0);
    for j in from..from + n {
        a += u[j] * (omega * t[j]).sin();
        b += u[j] * (omega * t[j]).cos();
    }
    (2.0 * a / n as f64, 2.0 * b / n as f64)
}
