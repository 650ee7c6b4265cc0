//! The forward and inverse runs against closed-form solutions and exact statements.

use platen_integrate::{
    forward_rk4, inverse, ForceRecord, Motion, Rk4, RunStats, State, Trajectory,
};
use platen_model::{IdentifiedParams, PlatenModel};

const K_N_PER_M: f64 = 1.266e6;
const M_KG: f64 = 144e3;

fn model(coulomb_n: f64, viscous: f64, alpha: f64, low_n: f64) -> platen_model::IdentifiedModel {
    IdentifiedParams {
        effective_mass_kg: M_KG,
        stiffness_n_per_m: K_N_PER_M,
        coulomb_force_n: coulomb_n,
        viscous_coefficient: viscous,
        viscous_exponent: alpha,
        low_velocity_force_n: low_n,
        low_velocity_decay_s_per_m: 78.5,
    }
    .build()
    .unwrap()
}

fn run<M: PlatenModel>(
    m: &M,
    record: &ForceRecord,
    k: u32,
    initial: State,
) -> (Trajectory, RunStats) {
    let mut out = Trajectory::with_capacity(record.len());
    let stats = forward_rk4(
        m,
        record,
        Rk4::with_steps_per_sample(k).unwrap(),
        initial,
        record.len(),
        &mut out,
    )
    .unwrap();
    (out, stats)
}

/// Free damped linear SDOF (α = 1, no friction): u = e^(−ζωt)(u₀ cos ω_d t + ζω u₀/ω_d sin ω_d t).
fn damped_free_vibration(t: f64, u0: f64, c: f64) -> f64 {
    let w = (K_N_PER_M / M_KG).sqrt();
    let zeta = c / (2.0 * (K_N_PER_M * M_KG).sqrt());
    let wd = w * (1.0 - zeta * zeta).sqrt();
    (-zeta * w * t).exp() * (u0 * (wd * t).cos() + zeta * w * u0 / wd * (wd * t).sin())
}

/// Linear viscous damping (α = 1) with friction off is a linear SDOF; velocity reversals still
/// go through the event machinery (the friction law has no jump there).
#[test]
fn linear_sdof_matches_its_closed_form_and_rk4_converges_at_fourth_order() {
    let c = 0.05 * 2.0 * (K_N_PER_M * M_KG).sqrt(); // 5 % of critical
    let m = model(0.0, c, 1.0, 0.0);
    // A coarse 32 Hz record of zero force over 8 s, so the errors stay far above round-off.
    let rate = 32.0;
    let record = ForceRecord::from_rate(rate, vec![0.0; 8 * 32 + 1]).unwrap();
    let u0 = 0.3;
    let mut errors = Vec::new();
    for k in [1, 2, 4, 8] {
        let (out, stats) = run(
            &m,
            &record,
            k,
            State {
                u_m: u0,
                v_m_s: 0.0,
            },
        );
        assert!(stats.reversals >= 4, "{stats:?}");
        let err = out
            .t_s
            .iter()
            .zip(&out.u_m)
            .map(|(&t, &u)| (u - damped_free_vibration(t, u0, c)).abs())
            .fold(0.0, f64::max);
        errors.push(err);
    }
    eprintln!("max errors for k = 1, 2, 4, 8 steps per sample: {errors:?}");
    // ωh = 2.965/32 ≈ 0.093 at k = 1: RK4's global error ≈ (ωh)⁴·u₀·ωt/120 ≈ 1e-6 m.
    assert!(errors[0] < 5e-6, "{errors:?}");
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(
            (3.8..=4.2).contains(&order),
            "observed order {order:.2}, errors {errors:?}"
        );
    }
}

/// Coulomb free decay from u₀ at rest: each half cycle is a half cosine about ±F/K, so the
/// extreme displacement shrinks by 2F/K per half cycle (4F/K per cycle); the platen stops at
/// the first reversal inside the band |Ku| ≤ F_s and stays there.
/// u₀ = 0.3 m, F = 25.445 kN, K = 1.266 MN/m: 2F/K = 40.20 mm; the extremes are
/// 0.3, −0.2598, 0.2196, …, and after 7 half cycles |u| = 0.3 − 7·2F/K = 18.6 mm ≤ F/K = 20.1 mm.
#[test]
fn coulomb_free_decay_loses_4f_over_k_per_cycle_and_stops_inside_the_band() {
    let f = 0.0044 * 5783e3;
    let m = model(f, 0.0, 0.5, 0.0);
    let rate = 1024.0;
    let record = ForceRecord::from_rate(rate, vec![0.0; 12 * 1024 + 1]).unwrap();
    let u0 = 0.3;
    let (out, stats) = run(
        &m,
        &record,
        1,
        State {
            u_m: u0,
            v_m_s: 0.0,
        },
    );
    let step = 2.0 * f / K_N_PER_M;
    let half_cycles = ((u0 - f / K_N_PER_M) / step).ceil() as i32;
    assert_eq!(half_cycles, 7);
    assert_eq!(stats.reversals, 6, "{stats:?}");
    assert_eq!(stats.stick_events, 1, "{stats:?}");
    // Final rest position: exact piecewise-cosine solution, RK4 at ωh = 0.003 is at round-off.
    let expected_rest = -(u0 - 7.0 * step);
    let rest = *out.u_m.last().unwrap();
    assert!(
        (rest - expected_rest).abs() < 1e-9,
        "rest at {rest}, expected {expected_rest}"
    );
    assert!(K_N_PER_M * rest.abs() <= f);
    // Extremes per half cycle, read from the samples: within ½·a·Δt² ≈ 1.4e-6 m of the event.
    let mut extremes = Vec::new();
    for i in 1..out.len() - 1 {
        let (a, b, c) = (out.u_m[i - 1], out.u_m[i], out.u_m[i + 1]);
        if (b > a && b >= c || b < a && b <= c) && out.v_m_s[i + 1] != 0.0 {
            extremes.push(b);
        }
    }
    assert_eq!(extremes.len(), 6, "{extremes:?}");
    for (n, e) in extremes.iter().enumerate() {
        let expected = (u0 - (n + 1) as f64 * step) * if n % 2 == 0 { -1.0 } else { 1.0 };
        assert!(
            (e - expected).abs() < 2e-6,
            "half cycle {}: {e} vs {expected}",
            n + 1
        );
    }
    // Once stopped, stopped: every later sample is exactly at rest.
    let stop = out.v_m_s.iter().rposition(|&v| v != 0.0).unwrap() + 1;
    assert!(out.t_s[stop] < 7.5, "stopped at {}", out.t_s[stop]);
    for i in stop..out.len() {
        assert_eq!(out.u_m[i], rest);
        assert_eq!(out.a_m_s2[i], 0.0);
    }
}

/// The paper's identified model under a constant push at 80 % of its static threshold
/// (0.8 × 37.49 kN) from rest does not move at all: u is exactly 0, not creeping.
#[test]
fn a_constant_force_below_the_static_threshold_leaves_the_platen_exactly_at_rest() {
    let m = platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    let f = 0.8 * m.static_threshold_n(0.0);
    let record = ForceRecord::from_rate(1024.0, vec![f; 10 * 1024 + 1]).unwrap();
    let (out, stats) = run(&m, &record, 1, State::default());
    assert!(out.u_m.iter().all(|&u| u == 0.0));
    assert!(out.v_m_s.iter().all(|&v| v == 0.0));
    assert_eq!(stats.breakaways, 0);
    assert!((stats.stick_time_s - 10.0).abs() < 1e-9);
    // The static friction reaction balances the push.
    assert!(out.dissipative_force_n.iter().all(|&d| d == f));
}

/// A ramp F = r·t from rest breaks away exactly when it reaches F_s: t_b = F_s/r.
/// With r = 10 kN/s and F_s = 37.485 kN, t_b = 3.7485 s (between samples). (Later the platen
/// lurches and sticks again: past its peak at 0.56 mm/s the Eq. 22 law falls with velocity.)
#[test]
fn a_ramp_breaks_away_exactly_when_it_crosses_the_static_threshold() {
    let m = platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    let r = 10e3;
    let record = ForceRecord::from_rate(
        1024.0,
        (0..=6 * 1024).map(|j| r * j as f64 / 1024.0).collect(),
    )
    .unwrap();
    let t_b = m.static_threshold_n(0.0) / r;
    // Run up to the first sample after t_b: exactly one stick interval, [0, t_b].
    let samples = (t_b * 1024.0).ceil() as usize + 1;
    let mut out = Trajectory::default();
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    let stats = forward_rk4(&m, &record, rk4, State::default(), samples, &mut out).unwrap();
    assert_eq!(stats.breakaways, 1);
    assert!(
        (stats.stick_time_s - t_b).abs() < 1e-12,
        "stuck for {} s, expected {t_b}",
        stats.stick_time_s
    );
    let last = out.len() - 1;
    assert!(
        out.u_m[..last].iter().all(|&u| u == 0.0),
        "moved before breakaway"
    );
    assert!(
        out.u_m[last] > 0.0 && out.v_m_s[last] > 0.0,
        "not moving after breakaway"
    );
}

fn smooth_motion(t: &[f64], v_mean: f64, amp: f64, w: f64) -> Motion {
    let u = t
        .iter()
        .map(|&t| v_mean * t + amp * (w * t).sin())
        .collect();
    let v = t
        .iter()
        .map(|&t| v_mean + amp * w * (w * t).cos())
        .collect();
    let a = t.iter().map(|&t| -amp * w * w * (w * t).sin()).collect();
    Motion::new(t.to_vec(), u, v, a).unwrap()
}

fn round_trip_error(rate: f64) -> f64 {
    let m = platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    let n = (5.0 * rate) as usize;
    let t: Vec<f64> = (0..=n).map(|j| j as f64 / rate).collect();
    let motion = smooth_motion(&t, 0.4, 0.05, 2.0 * std::f64::consts::PI * 0.8);
    let mut forces = Trajectory::default();
    inverse(&m, &motion, &mut forces);
    let record = ForceRecord::new(t.clone(), forces.force_n.clone()).unwrap();
    let initial = State {
        u_m: motion.u_m()[0],
        v_m_s: motion.v_m_s()[0],
    };
    let (out, _) = run(&m, &record, 1, initial);
    out.u_m
        .iter()
        .zip(motion.u_m())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Force from a motion that never reverses, then motion from that force. The only error left
/// is the linear interpolation of the force between samples: it biases each interval's mean
/// force by about F″Δt²/12, an acceleration error of ü″Δt²/12, i.e. δu ≈ Δt²/12·|ü| ≈ 1.0e-7 m
/// at 1024 Hz (|ü| = 1.26 m/s²), amplified by the table's response near its 0.47 Hz natural
/// frequency (measured 2.5e-7 m). The error must fall as Δt²: halving Δt quarters it.
#[test]
fn forward_of_the_inverse_force_returns_the_motion_without_reversals() {
    let e1024 = round_trip_error(1024.0);
    let e2048 = round_trip_error(2048.0);
    eprintln!("round trip without reversals: max |Δu| = {e1024:.3e} m at 1024 Hz, {e2048:.3e} m at 2048 Hz");
    assert!(e1024 < 5e-7, "{e1024}");
    let ratio = e1024 / e2048;
    assert!(
        (3.5..=4.5).contains(&ratio),
        "interpolation error should scale as Δt²: ratio {ratio}"
    );
}

/// The same round trip for the full Lagrangian model.
#[test]
fn forward_of_the_inverse_force_returns_the_motion_for_the_full_model() {
    let m = platen_model::preset::lhpost_2008_physical(13.8e6)
        .build()
        .unwrap();
    let t: Vec<f64> = (0..=5 * 1024).map(|j| j as f64 / 1024.0).collect();
    let motion = smooth_motion(&t, 0.3, 0.05, 2.0 * std::f64::consts::PI * 0.8);
    let mut forces = Trajectory::default();
    inverse(&m, &motion, &mut forces);
    let record = ForceRecord::new(t.clone(), forces.force_n.clone()).unwrap();
    let initial = State {
        u_m: motion.u_m()[0],
        v_m_s: motion.v_m_s()[0],
    };
    let (out, _) = run(&m, &record, 1, initial);
    let du = out
        .u_m
        .iter()
        .zip(motion.u_m())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!("full-model round trip: max |Δu| = {du:.3e} m");
    // Same interpolation-error bound as the identified model's round trip.
    assert!(du < 5e-7, "{du}");
}

/// A sine motion reverses at sample times, where the motion states v = 0 exactly. The inverse
/// force jumps by 2F_s there (sign(0) = 0 at the sample itself) and the record's linear
/// interpolation smears the jump over one sample on each side. The two smears carry opposite
/// impulses (∓F_sΔt/2) that cancel, but the first makes the platen reach rest
/// δt = F_sΔt/(2Mₑ|ü|) ≈ 32 µs early, and during δt friction already acts the other way: an
/// impulse 2F_sδt, i.e. δv = F_s²Δt/(Mₑ²|ü|) ≈ 1.7e-5 m/s and δu ≈ δv/ω ≈ 2.7e-6 m per
/// reversal (1 Hz, 0.1 m: |ü| = 3.95 m/s²). Eight reversals of alternating sign: bound 2e-5 m.
#[test]
fn forward_of_the_inverse_force_returns_a_reversing_sine_motion() {
    let m = platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    let t: Vec<f64> = (0..=4 * 1024).map(|j| j as f64 / 1024.0).collect();
    let w = 2.0 * std::f64::consts::PI * 1.0;
    let amp = 0.1;
    let u = t.iter().map(|&t| amp * (w * t).sin()).collect();
    // cos(ωt) at the quarter periods is ~1e-16, not 0: state the reversals exactly.
    let v = t
        .iter()
        .map(|&t| {
            let v = amp * w * (w * t).cos();
            if v.abs() < 1e-12 {
                0.0
            } else {
                v
            }
        })
        .collect();
    let a = t.iter().map(|&t| -amp * w * w * (w * t).sin()).collect();
    let motion = Motion::new(t.clone(), u, v, a).unwrap();
    let mut forces = Trajectory::default();
    inverse(&m, &motion, &mut forces);
    let record = ForceRecord::new(t.clone(), forces.force_n.clone()).unwrap();
    let (out, stats) = run(
        &m,
        &record,
        1,
        State {
            u_m: 0.0,
            v_m_s: amp * w,
        },
    );
    let du = out
        .u_m
        .iter()
        .zip(motion.u_m())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!("reversing round trip: max |Δu| = {du:.3e} m, {stats:?}");
    assert_eq!(stats.reversals, 8, "{stats:?}");
    assert!(du < 2e-5, "{du}");
}

/// Odd force → odd response: the model and the integrator treat both directions alike.
#[test]
fn mirrored_force_gives_the_mirrored_motion_exactly() {
    let m = platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap();
    let f: Vec<f64> = (0..=6 * 1024)
        .map(|j| {
            let t = j as f64 / 1024.0;
            (t / 2.0).min(1.0)
                * (120e3 * (2.0 * std::f64::consts::PI * 0.4 * t).sin() + 30e3 * (9.0 * t).cos())
        })
        .collect();
    let neg: Vec<f64> = f.iter().map(|x| -x).collect();
    let (a, sa) = run(
        &m,
        &ForceRecord::from_rate(1024.0, f).unwrap(),
        1,
        State::default(),
    );
    let (b, sb) = run(
        &m,
        &ForceRecord::from_rate(1024.0, neg).unwrap(),
        1,
        State::default(),
    );
    assert_eq!(sa, sb);
    for i in 0..a.len() {
        assert_eq!(a.u_m[i], -b.u_m[i]);
        assert_eq!(a.v_m_s[i], -b.v_m_s[i]);
    }
}

/// Eq. 1 holds at every output sample: F_I + F_E + F_D = F_A to rounding.
#[test]
fn the_force_decomposition_adds_up_to_the_actuator_force() {
    let m = platen_model::preset::lhpost_2008_physical(13.8e6)
        .build()
        .unwrap();
    let f: Vec<f64> = (0..=8 * 1024)
        .map(|j| 300e3 * (2.0 * std::f64::consts::PI * 0.35 * j as f64 / 1024.0).sin())
        .collect();
    let (out, _) = run(
        &m,
        &ForceRecord::from_rate(1024.0, f).unwrap(),
        2,
        State::default(),
    );
    for i in 0..out.len() {
        let sum = out.inertial_force_n[i] + out.elastic_force_n[i] + out.dissipative_force_n[i];
        assert!((sum - out.force_n[i]).abs() <= 1e-9 * 300e3, "sample {i}");
    }
}
