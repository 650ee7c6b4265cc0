//! Frictionless tables (`F_μ = a = 0`, so the static threshold `F_s = 0`), with and without
//! stiffness and viscous damping, against closed forms: `v = 0` is a crossing, never a stick
//! phase, and no run may fail on finite input (issue 26).

use std::f64::consts::PI;

use platen_integrate::{
    forward_dopri5, forward_rk4, inverse, Dopri5Settings, ForceRecord, Motion, Rk4, RunStats,
    State, Trajectory,
};
use platen_model::IdentifiedModel;

mod common;
use common::{frictionless, sine_fit, sine_record, M_KG, RATE_HZ};

/// Both integrators from rest over the whole record: RK4 at one step per sample
/// (h = 1/1024 s) and Dopri5 at rtol 1e-10, atol 1e-12.
fn both(
    model: &IdentifiedModel,
    record: &ForceRecord,
) -> [(&'static str, Trajectory, RunStats); 2] {
    let mut rk4 = Trajectory::with_capacity(record.len());
    let s_rk4 = forward_rk4(
        model,
        record,
        Rk4::with_steps_per_sample(1).unwrap(),
        State::default(),
        record.len(),
        &mut rk4,
    )
    .unwrap();
    let mut dp5 = Trajectory::with_capacity(record.len());
    let s_dp5 = forward_dopri5(
        model,
        record,
        Dopri5Settings::new(1e-10, 1e-12).unwrap(),
        State::default(),
        record.len(),
        &mut dp5,
    )
    .unwrap();
    [("rk4", rk4, s_rk4), ("dopri5", dp5, s_dp5)]
}

/// `M·ü + C·u̇ + K·u = F₀ sin ωt` (α = 1, friction off): after the transient, the displacement
/// is `X·sin(ωt − φ)` with `X = F₀/√((K − Mω²)² + (Cω)²)` and `tan φ = Cω/(K − Mω²)`.
///
/// ζ = 0.2 of critical: the transient decays as `e^(−ζω_n t)`, by e^(−16.6) = 6e-8 at 28 s,
/// where the fit over the last 12 periods (1 Hz) starts. The remaining errors: RK4's global
/// error at h = 1/1024 s is of order `(ωh)⁴ ≈ 1e-9`; the record's force is linear between
/// samples, whose fundamental is the sine's times `sinc²(ωΔt/2) ≈ 1 − (ωΔt)²/12 = 1 − 3.1e-6`.
/// So 1e-4 relative on the amplitude (and 1e-4 rad on the phase) holds with a margin of 30
/// over the largest of these, and fails for any wrong mass, stiffness or damping term (a 1e-4
/// change of M moves X by 1.2e-4) or for a lost half-cycle at a reversal.
#[test]
fn a_linear_frictionless_platen_has_the_closed_form_steady_state() {
    let k = 1.266e6;
    let c = 0.2 * 2.0 * (k * M_KG).sqrt();
    let model = frictionless(k, c, 1.0);
    let omega = 2.0 * PI;
    let f0 = 1e5;
    let record = sine_record(f0, omega, 40.0);
    let x_exact = f0 / ((k - M_KG * omega * omega).powi(2) + (c * omega).powi(2)).sqrt();
    let phi_exact = (c * omega).atan2(k - M_KG * omega * omega);
    for (name, out, stats) in both(&model, &record) {
        let (a, b) = sine_fit(&out.t_s, &out.u_m, omega, 28 * 1024, 12 * 1024);
        let x = a.hypot(b);
        // u = X sin(ωt − φ) = X cos φ·sin ωt − X sin φ·cos ωt.
        let phi = (-b).atan2(a);
        let rel = (x / x_exact - 1.0).abs();
        eprintln!(
            "{name}: X = {x:.9e} m vs {x_exact:.9e} m ({rel:.2e} relative), φ = {phi:.9} vs \
             {phi_exact:.9} rad; {} reversals, {} stick events, stick time {:.1e} s",
            stats.reversals, stats.stick_events, stats.stick_time_s
        );
        assert!(rel < 1e-4, "{name}: amplitude {x} vs {x_exact}");
        assert!(
            (phi - phi_exact).abs() < 1e-4,
            "{name}: phase {phi} vs {phi_exact}"
        );
        // No friction: every v = 0 is a crossing (two a period), never a stop.
        assert_eq!(stats.stick_events, 0, "{name}: {stats:?}");
        assert!(stats.reversals >= 78, "{name}: {stats:?}");
        assert!(stats.stick_time_s < 1e-9, "{name}: {stats:?}");
    }
}

/// `t(v)` of a platen without stiffness or friction pushed from rest by a constant force
/// `F₀` against `C·√v`: `M·v̇ = F₀ − C√v` integrates (with `s = √v`) to
/// `t = 2M/C²·(−C√v − F₀·ln(1 − C√v/F₀))`.
fn time_to_reach(v: f64, f0: f64, c: f64) -> f64 {
    let s = v.sqrt();
    2.0 * M_KG / (c * c) * (-c * s - f0 * (-c * s / f0).ln_1p())
}

/// Kₑ = 0, F_μ = a = 0, α = 0.5: a constant force from rest follows the closed form `t(v)`,
/// and a sine force (a reversal every half period, each leaving rest through the infinite
/// slope of `√|v|` at 0) runs to the end with both integrators; the inverse of the forward
/// motion gives back the force.
///
/// Tolerances: the closed-form check compares each sample's time with `t(v)` at its
/// velocity, as a velocity error `a·|Δt|`. Leaving rest the law is singular like `√t`; the
/// graded first step holds RK4's error there near 1e-10 m/s, and Dopri5 runs at rtol 1e-10:
/// 1e-8 m/s on speeds up to 1 m/s bounds both with margin and fails for a wrong law (a 1e-6
/// change of C moves v by about 1e-6 m/s). The inverse rebuilds `M·a + C·√|v|·sign v` from the
/// run's own samples, so it agrees to rounding: 1e-9 of the peak force.
#[test]
fn a_platen_without_stiffness_or_friction_runs_forward_and_inverse() {
    let c = 44.58e3;
    let model = frictionless(0.0, c, 0.5);
    let f0 = 50e3;
    let constant = ForceRecord::from_rate(RATE_HZ, vec![f0; 20 * 1024 + 1]).unwrap();
    for (name, out, stats) in both(&model, &constant) {
        let mut worst = 0.0f64;
        for j in 1..out.t_s.len() {
            let (v, a) = (out.v_m_s[j], out.a_m_s2[j]);
            let dv = a * (time_to_reach(v, f0, c) - out.t_s[j]);
            worst = worst.max(dv.abs());
        }
        eprintln!("{name}: constant force from rest: max |Δv| = {worst:.2e} m/s ({stats:?})");
        assert!(worst < 1e-8, "{name}: {worst}");
        assert_eq!(stats.stick_events + stats.reversals, 0, "{name}: {stats:?}");
    }

    let omega = 2.0 * PI * 0.5;
    let record = sine_record(1e5, omega, 20.0);
    for (name, out, stats) in both(&model, &record) {
        assert_eq!(out.t_s.len(), record.len(), "{name}: ran to the end");
        assert_eq!(stats.stick_events, 0, "{name}: {stats:?}");
        // From rest under F₀ sin ωt, v reverses once per period after the first half.
        assert!(stats.reversals >= 19, "{name}: {stats:?}");
        let motion = Motion::new(
            out.t_s.clone(),
            out.u_m.clone(),
            out.v_m_s.clone(),
            out.a_m_s2.clone(),
        )
        .unwrap();
        let mut back = Trajectory::default();
        inverse(&model, &motion, &mut back);
        let worst = back
            .force_n
            .iter()
            .zip(record.force_n())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        eprintln!("{name}: sine force: {stats:?}; inverse of the forward motion: max |ΔF| = {worst:.2e} N");
        assert!(worst < 1e-9 * 1e5, "{name}: {worst}");
    }
}

/// No damping, no stiffness, no friction: `M·ü = F₀ sin ωt` from rest gives
/// `v = F₀/(Mω)·(1 − cos ωt) ≥ 0`, which touches `v = 0` once a period with zero net force
/// there, the case where a zero-friction `v = 0` used to make endless events. The force is
/// linear between samples, which changes the impulse by `Δt²/12·(F′(t) − F′(0))` (the
/// trapezoid rule's error, summed), at most `Δt²·F₀ω/(6M)` = 6.9e-7 m/s in velocity: the
/// runs must stay within 1 % above that bound (the integrators' own error is below 1e-9).
#[test]
fn a_free_mass_touching_rest_each_period_follows_the_closed_form() {
    let model = frictionless(0.0, 0.0, 1.0);
    let omega = 2.0 * PI;
    let f0 = 1e5;
    let record = sine_record(f0, omega, 8.0);
    for (name, out, stats) in both(&model, &record) {
        let worst = out
            .t_s
            .iter()
            .zip(&out.v_m_s)
            .map(|(&t, &v)| (v - f0 / (M_KG * omega) * (1.0 - (omega * t).cos())).abs())
            .fold(0.0, f64::max);
        let bound = f0 * omega / (6.0 * M_KG * RATE_HZ * RATE_HZ);
        eprintln!("{name}: free mass: max |Δv| = {worst:.3e} m/s, bound {bound:.3e} ({stats:?})");
        assert!(worst < 1.01 * bound, "{name}: {worst}");
    }
}

/// α < 1 with a force that hovers near zero and changes sign inside sample intervals (the
/// creep regime, where the law is too stiff for an explicit step): every run finishes. These
/// are the records that stalled the event loop ("4097 stick-slip events inside one step").
#[test]
fn a_frictionless_creeping_platen_never_stalls() {
    for (k, c, alpha) in [
        (0.0, 44.58e3, 0.5),
        (1e3, 44.58e3, 0.5),
        (1.266e6, 1e6, 0.2),
        (0.0, 1e6, 0.5),
    ] {
        let model = frictionless(k, c, alpha);
        for amplitude_n in [1e-6, 1.0, 1e3] {
            let record = sine_record(amplitude_n, 2.0 * PI * 1.5, 2.0);
            for (name, out, stats) in both(&model, &record) {
                assert_eq!(out.t_s.len(), record.len(), "{name} {k} {c} {alpha}");
                // Rest is reached only where the net force is exactly zero, and lasts no
                // time: nothing holds a frictionless platen.
                assert!(
                    stats.stick_time_s < 1e-12,
                    "{name} {k} {c} {alpha}: {stats:?}"
                );
            }
            // A force that jumps sign every few samples, with exact zeros.
            let force = (0..2049)
                .map(|j| amplitude_n * [1.0, 0.0, -1.0, -0.5, 0.0, 0.25][(j / 3) % 6])
                .collect();
            let record = ForceRecord::from_rate(RATE_HZ, force).unwrap();
            for (name, out, _) in both(&model, &record) {
                assert_eq!(out.t_s.len(), record.len(), "{name} {k} {c} {alpha}");
            }
        }
    }
}

/// `C = 1e6`, `α = 0.2`, no stiffness, started slipping at 1e-9 m/s under a 1e5 N, 1.5 Hz
/// sine: the law's stiff speed at one sample interval is 1.9 mm/s and the creep speed
/// `(|F|/C)^(1/α)` at most 1e-5 m/s, so the platen creeps throughout. Dopri5 used to resolve
/// the slip's relaxation towards the creep speed (τ = M/D′ down to 1e-13 s) and gave up after
/// its 100 000 steps at t = 4e-4 s (issue 38); it creeps now, as RK4 does.
///
/// Against the quasi-static creep integrated independently here (`u̇ = sign(F)·(|F|/C)^5`, the
/// force linear between samples, Simpson's rule on 64 pieces a sample): the neglected inertia
/// lags the creep by `τ·w` with `τ = M·w^(1−α)/(α·C)` ≤ 7.2e-5 s at the peak speed 1e-5 m/s,
/// so by at most 7.2e-10 m; the runs must agree to 2e-9 m (the displacement reaches 1.1e-6 m).
#[test]
fn a_platen_slipping_below_the_stiff_speed_creeps_with_both_integrators() {
    let (c, alpha, f0) = (1e6, 0.2, 1e5);
    let model = frictionless(0.0, c, alpha);
    let omega = 2.0 * PI * 1.5;
    let record = sine_record(f0, omega, 2.0);
    let start = State {
        u_m: 0.0,
        v_m_s: 1e-9,
    };
    let mut dp5 = Trajectory::with_capacity(record.len());
    forward_dopri5(
        &model,
        &record,
        Dopri5Settings::new(1e-10, 1e-12).unwrap(),
        start,
        record.len(),
        &mut dp5,
    )
    .unwrap();
    let mut rk4 = Trajectory::with_capacity(record.len());
    forward_rk4(
        &model,
        &record,
        Rk4::with_steps_per_sample(1).unwrap(),
        start,
        record.len(),
        &mut rk4,
    )
    .unwrap();
    // The quasi-static creep, from the samples of the force.
    let force: Vec<f64> = (0..record.len())
        .map(|j| f0 * (omega * j as f64 / RATE_HZ).sin())
        .collect();
    let speed = |f: f64| f.signum() * (f.abs() / c).powf(1.0 / alpha);
    let mut u_qs = vec![0.0; record.len()];
    let pieces = 64;
    for j in 1..record.len() {
        let at = |x: f64| speed(force[j - 1] + (force[j] - force[j - 1]) * x);
        let h = 1.0 / pieces as f64;
        let simpson: f64 = (0..pieces)
            .map(|p| {
                let x = p as f64 * h;
                h / 6.0 * (at(x) + 4.0 * at(x + 0.5 * h) + at(x + h))
            })
            .sum();
        u_qs[j] = u_qs[j - 1] + simpson / RATE_HZ;
    }
    let peak = u_qs.iter().fold(0.0_f64, |m, u| m.max(u.abs()));
    assert!(peak > 1e-6, "{peak}");
    for (name, out) in [("dopri5", &dp5), ("rk4", &rk4)] {
        assert_eq!(out.t_s.len(), record.len(), "{name}");
        let worst = out
            .u_m
            .iter()
            .zip(&u_qs)
            .map(|(u, q)| (u - q).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: creep from 1e-9 m/s: max |u − u_qs| = {worst:.3e} m (peak {peak:.3e} m)"
        );
        assert!(worst < 2e-9, "{name}: {worst}");
    }
}
