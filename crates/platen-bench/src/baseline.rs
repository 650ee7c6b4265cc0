//! A plain-loop RK4 used as a **measuring stick** for the speed of
//! [`platen_integrate::forward_rk4`]: not a physics integrator.
//!
//! [`baseline_rk4`] is the loop one would write for the purpose of timing the arithmetic of
//! the identified model (Eq. 22/23) and nothing else: classical RK4 at the force record's
//! sample interval, the force linearly interpolated (its mid-step value is the mean of the two
//! samples), one square root (`α = 0.5`) and one exponential per stage, and friction as
//! `copysign(D, v)`. It has **no stick logic** (a platen at rest chatters about `v = 0`
//! instead of sticking), no energy bookkeeping, no checks and no output: it returns the final
//! state only, so the whole run is one chain of dependent arithmetic. Its time per step is the
//! latency of that chain on the machine, the limit that an integrator of the same model with
//! exact stick-slip can approach but not beat.
//!
//! The criterion benches (`benches/rk4_throughput.rs`, `benches/dopri5_throughput.rs`, through
//! `benches/common/mod.rs`) and `platen bench` (through [`crate`]) all use this one
//! loop, time it in the same run as the real integrators and report their ratio to it;
//! `benches/c/rk4_baseline.c` is the same loop in C.
//!
//! Its test (that it computes the model it claims to) is in [`crate`]'s tests.
//!
//! Do not use it to simulate anything: with `sign(v)` friction it is off by ~4e-4 m on the
//! paper's reference record and never sits still (see the crate's stick-slip tests).

use platen_integrate::State;
use platen_model::{DissipativeLaw, Exponent, IdentifiedParams};

/// Runs the plain RK4 loop on the identified model with parameters `params` (the exponent
/// is taken as `α = 0.5` whatever `params.viscous_exponent` says: the loop is written for the
/// `lhpost-2008` preset) under the force samples `force_n` spaced `dt_s` apart, from
/// `initial`, one step per sample interval, and returns the state at the last sample.
///
/// No stick logic, no output, no checks: see the [module docs](self). Returns `initial` for
/// fewer than two samples.
pub fn baseline_rk4(
    params: &IdentifiedParams,
    force_n: &[f64],
    dt_s: f64,
    initial: State,
) -> State {
    let k = params.stiffness_n_per_m;
    let law = DissipativeLaw {
        exponent: Exponent::Half,
        ..params.dissipative_law()
    };
    let inv_m = 1.0 / params.effective_mass_kg;
    let h = dt_s;
    let acc = |f: f64, u: f64, v: f64| {
        let w = v.abs();
        (f - k * u - law.magnitude_n(w).copysign(v)) * inv_m
    };
    let (mut u, mut v) = (initial.u_m, initial.v_m_s);
    for pair in force_n.windows(2) {
        let (f0, f1) = (pair[0], pair[1]);
        let fm = 0.5 * (f0 + f1);
        let a1 = acc(f0, u, v);
        let v2 = v + 0.5 * h * a1;
        let a2 = acc(fm, u + 0.5 * h * v, v2);
        let v3 = v + 0.5 * h * a2;
        let a3 = acc(fm, u + 0.5 * h * v2, v3);
        let v4 = v + h * a3;
        let a4 = acc(f1, u + h * v3, v4);
        u += h / 6.0 * (v + 2.0 * (v2 + v3) + v4);
        v += h / 6.0 * (a1 + 2.0 * (a2 + a3) + a4);
    }
    State { u_m: u, v_m_s: v }
}
