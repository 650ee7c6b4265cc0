//! The closed loop (command → controller → valves → chambers → platen) against closed forms
//! and the paper's figures: the oil column's free oscillation (frequency and leakage decay),
//! the valve-limited velocity, the stall force, the payload's effect on the oil column, the
//! stick phase at a reversal, the energy balance, and RK4 against Dopri5.

use platen_integrate::{
    forward_closed_loop, LoopMethod, LoopRun, LoopStats, Motion, Sample, SampleSink, State,
    Trajectory,
};
use platen_model::{IdentifiedModel, IdentifiedParams, PlatenModel};
use platen_system::{
    preset, Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts,
};

struct Keep(Vec<Sample>);

impl SampleSink for Keep {
    fn accept(&mut self, s: &Sample) {
        self.0.push(*s);
    }
}

/// A linear platen: mass, stiffness, linear viscous damping, no friction.
fn linear(mass_kg: f64, stiffness: f64, damping: f64) -> IdentifiedModel {
    IdentifiedParams {
        effective_mass_kg: mass_kg,
        stiffness_n_per_m: stiffness,
        coulomb_force_n: 0.0,
        viscous_coefficient: damping,
        viscous_exponent: 1.0,
        low_velocity_force_n: 0.0,
        low_velocity_decay_s_per_m: 0.0,
    }
    .build()
    .unwrap()
}

fn lhpost_model() -> IdentifiedModel {
    platen_model::preset::lhpost_2008_identified(13.8e6)
        .build()
        .unwrap()
}

/// A symmetric mid-size table (not the LHPOST): one double-ended actuator of 0.02 m², 12 l
/// chambers, `valves` valves of 600 l/min at 7 MPa, 21/0.3 MPa supply/return; every gain 0.
fn symmetric(valves: u32, leakage: f64) -> TableSystem {
    TableSystem::new(symmetric_parts(valves, leakage), 0.0).unwrap()
}

/// The values of [`symmetric`], to change before validating.
fn symmetric_parts(valves: u32, leakage: f64) -> TableSystemParts {
    TableSystemParts {
        actuator: Actuator {
            count: 1,
            cap_area_m2: 0.02,
            rod_area_m2: 0.02,
            cap_volume_m3: 0.012,
            rod_volume_m3: 0.012,
            leakage_m3_s_per_pa: leakage,
        },
        servo_valve: ServoValve {
            count: valves,
            rated_flow_m3_s: 0.01,
            rated_pressure_drop_pa: 7e6,
            natural_frequency_hz: 120.0,
            damping_ratio: 0.7,
            delay_s: 0.0,
        },
        oil_bulk_modulus_pa: 1.2e9,
        supply_pressure_pa: 21e6,
        return_pressure_pa: 0.3e6,
        supply: Supply::Constant,
        controller: Controller {
            sample_rate_hz: 4096.0,
            displacement_gain_per_m: 0.0,
            integral_gain_per_m_s: 0.0,
            velocity_feedforward_s_per_m: 0.0,
            acceleration_feedforward_s2_per_m: 0.0,
            velocity_feedback_s_per_m: 0.0,
            acceleration_feedback_s2_per_m: 0.0,
            delta_p_gain_per_pa: 0.0,
            delta_p_highpass_hz: 0.0,
        },
    }
}

/// A command sampled at `rate_hz` for `duration_s` from a displacement function and its two
/// derivatives.
fn command(rate_hz: f64, duration_s: f64, u: impl Fn(f64) -> (f64, f64, f64)) -> Motion {
    let n = (duration_s * rate_hz).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / rate_hz).collect();
    let (mut us, mut vs, mut as_) = (Vec::new(), Vec::new(), Vec::new());
    for &ti in &t {
        let (a, b, c) = u(ti);
        us.push(a);
        vs.push(b);
        as_.push(c);
    }
    Motion::new(t, us, vs, as_).unwrap()
}

fn run<M: PlatenModel>(
    model: &M,
    system: &TableSystem,
    command: &Motion,
    method: LoopMethod,
    initial: State,
) -> (Vec<Sample>, LoopStats) {
    let mut keep = Keep(Vec::new());
    let run = LoopRun {
        system,
        specimen: None,
        command,
        method,
        initial,
    };
    let stats = forward_closed_loop(model, &run, command.len(), &mut keep).unwrap();
    (keep.0, stats)
}

const RK4_4: LoopMethod = LoopMethod::Rk4 {
    steps_per_period: 4,
};

/// Frequency of a signal from its zero crossings (linear interpolation between samples).
fn crossing_frequency_hz(t: &[f64], x: &[f64]) -> f64 {
    let mut crossings = Vec::new();
    for i in 1..x.len() {
        if x[i - 1] != 0.0 && x[i - 1].signum() != x[i].signum() {
            let w = x[i - 1] / (x[i - 1] - x[i]);
            crossings.push(t[i - 1] + w * (t[i] - t[i - 1]));
        }
    }
    let (first, last) = (crossings[0], crossings[crossings.len() - 1]);
    0.5 * (crossings.len() - 1) as f64 / (last - first)
}

/// The oil column's free oscillation, valve shut: the closed form
/// `f = (1/2π)·√(n·β·(A_a²/V_a + A_b²/V_b)/M)` within 0.5 % (the amplitude, 0.16 mm, changes
/// the volumes by 3e-4, so the linear closed form holds far better than that).
#[test]
fn the_oil_column_rings_at_its_closed_form_frequency() {
    let sys = symmetric(1, 0.0);
    let model = linear(20_000.0, 0.0, 0.0);
    let cmd = command(4096.0, 2.0, |_| (0.0, 0.0, 0.0));
    let initial = State {
        u_m: 0.0,
        v_m_s: 0.01,
    };
    let (s, _) = run(&model, &sys, &cmd, RK4_4, initial);
    let t: Vec<f64> = s.iter().map(|s| s.t_s).collect();
    let v: Vec<f64> = s.iter().map(|s| s.v_m_s).collect();
    let f = crossing_frequency_hz(&t, &v);
    let expected = sys.oil_column_frequency_hz(20_000.0, 0.0);
    let rel = (f / expected - 1.0).abs();
    println!("oil column: simulated {f:.5} Hz, closed form {expected:.5} Hz, {rel:.2e}");
    assert!(rel < 5e-3, "{f} vs {expected}");
}

/// With cross-port leakage the free oscillation decays as `e^(−σt)`, `σ = C_L·β/V` (a
/// symmetric actuator: `(V/β)·Ṗ = −2A·v − 2C_L·P` for `P = p_a − p_b`), within 0.5 %.
#[test]
fn leakage_damps_the_oil_column_at_its_closed_form_rate() {
    let leak = 2e-12;
    let sys = symmetric(1, leak);
    let model = linear(20_000.0, 0.0, 0.0);
    let cmd = command(4096.0, 2.0, |_| (0.0, 0.0, 0.0));
    let initial = State {
        u_m: 0.0,
        v_m_s: 0.01,
    };
    let (s, _) = run(&model, &sys, &cmd, RK4_4, initial);
    // Peaks of v, refined by a parabola through the three samples around each.
    let mut peaks = Vec::new();
    for i in 1..s.len() - 1 {
        let (a, b, c) = (s[i - 1].v_m_s, s[i].v_m_s, s[i + 1].v_m_s);
        if b > a && b >= c && b > 0.0 {
            let d = 0.5 * (a - c) / (a - 2.0 * b + c);
            let value = b - 0.25 * (a - c) * d;
            peaks.push((s[i].t_s + d / 4096.0, value));
        }
    }
    let (first, last) = (peaks[0], peaks[peaks.len() - 1]);
    let sigma = (first.1 / last.1).ln() / (last.0 - first.0);
    let expected = leak * sys.oil_bulk_modulus_pa() / 0.012;
    let rel = (sigma / expected - 1.0).abs();
    println!("decay: simulated {sigma:.5} 1/s, closed form {expected:.5} 1/s, {rel:.2e}");
    assert!(rel < 5e-3, "{sigma} vs {expected}");
}

/// Full opening with no load: the platen runs at the valve-limited velocity
/// `m·Q_r·√((P_s − P_R)/Δp_r)/A` within 1 %.
#[test]
fn a_full_opening_runs_at_the_valve_limited_velocity() {
    let mut parts = symmetric_parts(2, 0.0);
    parts.controller.velocity_feedforward_s_per_m = 10.0;
    let sys = TableSystem::new(parts, 0.0).unwrap();
    // A light platen with a whisper of damping: its load, 17 N, is 4e-5 of the supply.
    let model = linear(2000.0, 0.0, 10.0);
    let cmd = command(4096.0, 0.25, |t| (5.0 * t, 5.0, 0.0));
    let (s, stats) = run(&model, &sys, &cmd, RK4_4, State::default());
    let end = s.last().unwrap();
    let expected = 2.0 * 0.01 * ((21e6 - 0.3e6) / 7e6_f64).sqrt() / 0.02;
    let rel = (end.v_m_s / expected - 1.0).abs();
    println!(
        "valve-limited: simulated {:.5} m/s, closed form {expected:.5} m/s, {rel:.2e}",
        end.v_m_s
    );
    assert!(rel < 1e-2, "{} vs {expected}", end.v_m_s);
    assert!(stats.saturated_time_s > 0.2);
    let cap = sys.capacities();
    assert!((cap.extend_velocity_m_s / expected - 1.0).abs() < 1e-12);
}

/// A platen of `mass_kg` that friction locks (10 MN, far above any force of these loops).
fn locked(mass_kg: f64) -> IdentifiedModel {
    IdentifiedParams {
        effective_mass_kg: mass_kg,
        stiffness_n_per_m: 0.0,
        coulomb_force_n: 1e7,
        viscous_coefficient: 0.0,
        viscous_exponent: 1.0,
        low_velocity_force_n: 0.0,
        low_velocity_decay_s_per_m: 0.0,
    }
    .build()
    .unwrap()
}

/// Against a locked platen (friction far above the force capacity) a full opening builds the
/// force `A·(P_s − P_R)` (`p_a → P_s`, `p_b → P_R`), within 1e-4; the platen never moves.
#[test]
fn a_locked_platen_feels_the_stall_force() {
    let mut parts = symmetric_parts(1, 0.0);
    parts.controller.displacement_gain_per_m = 100.0;
    let sys = TableSystem::new(parts, 0.0).unwrap();
    let model = locked(20_000.0);
    let cmd = command(4096.0, 0.5, |_| (0.1, 0.0, 0.0));
    let (s, _) = run(&model, &sys, &cmd, RK4_4, State::default());
    assert!(s.iter().all(|s| s.u_m == 0.0 && s.v_m_s == 0.0 && s.stuck));
    let f = s.last().unwrap().terms.actuator_n;
    let expected = 0.02 * (21e6 - 0.3e6);
    let rel = (f / expected - 1.0).abs();
    println!("stall: {f:.1} N, closed form {expected:.1} N, {rel:.2e}");
    assert!(rel < 1e-4, "{f} vs {expected}");
    assert!((sys.capacities().push_force_n / expected - 1.0).abs() < 1e-12);
}

/// A rigid payload `m` lowers the oil column by `√(M/(M + m))`, within 0.5 %.
#[test]
fn a_payload_lowers_the_oil_column_as_the_closed_form_says() {
    let sys = symmetric(1, 0.0);
    let cmd = command(4096.0, 2.0, |_| (0.0, 0.0, 0.0));
    let initial = State {
        u_m: 0.0,
        v_m_s: 0.01,
    };
    let freq = |mass: f64| {
        let (s, _) = run(&linear(mass, 0.0, 0.0), &sys, &cmd, RK4_4, initial);
        let t: Vec<f64> = s.iter().map(|s| s.t_s).collect();
        let v: Vec<f64> = s.iter().map(|s| s.v_m_s).collect();
        crossing_frequency_hz(&t, &v)
    };
    let (bare, loaded) = (freq(20_000.0), freq(35_000.0));
    let ratio = loaded / bare;
    let expected = (20_000.0_f64 / 35_000.0).sqrt();
    println!("payload: ratio {ratio:.5}, closed form {expected:.5}");
    assert!((ratio / expected - 1.0).abs() < 5e-3);
}

/// The LHPOST preset: the closed form gives the paper's 10.66 Hz with `Mₑ` = 144 t at
/// mid-stroke, and the simulated oil column (valve shut, no leakage, no friction) rings there
/// within 2 %.
#[test]
fn the_lhpost_preset_rings_at_the_papers_oil_column_frequency() {
    let mut parts = preset::lhpost_2008().into_parts();
    parts.actuator.leakage_m3_s_per_pa = 0.0;
    parts.supply = Supply::Constant;
    let c = &mut parts.controller;
    c.displacement_gain_per_m = 0.0;
    c.velocity_feedforward_s_per_m = 0.0;
    c.acceleration_feedforward_s2_per_m = 0.0;
    c.delta_p_gain_per_pa = 0.0;
    let sys = TableSystem::new(parts, 0.0).unwrap();
    let closed = sys.oil_column_frequency_hz(144e3, 0.0);
    assert!((closed / 10.66 - 1.0).abs() < 2e-3, "{closed}");
    let cmd = command(1024.0, 3.0, |_| (0.0, 0.0, 0.0));
    let initial = State {
        u_m: 0.0,
        v_m_s: 0.01,
    };
    let (s, _) = run(&linear(144e3, 0.0, 0.0), &sys, &cmd, RK4_4, initial);
    let t: Vec<f64> = s.iter().map(|s| s.t_s).collect();
    let v: Vec<f64> = s.iter().map(|s| s.v_m_s).collect();
    let f = crossing_frequency_hz(&t, &v);
    println!("LHPOST oil column: simulated {f:.4} Hz, closed form {closed:.4} Hz");
    assert!((f / 10.66 - 1.0).abs() < 0.02, "{f}");
}

/// A slow command across a reversal on the LHPOST with its friction: the platen stops and
/// sticks exactly (`v = 0` at every sample of the stick interval), while the loop fights the
/// friction: the net force `|F_A − F_E|` ramps (monotonically) until it reaches the static
/// threshold, where the platen breaks away.
#[test]
fn at_a_slow_reversal_the_platen_sticks_and_the_loop_ramps_the_force_to_breakaway() {
    let sys = preset::lhpost_2008();
    let model = lhpost_model();
    let w = std::f64::consts::TAU * 0.2;
    let amp = 0.01;
    let cmd = command(1024.0, 4.0, |t| {
        (
            amp * (w * t).sin(),
            amp * w * (w * t).cos(),
            -amp * w * w * (w * t).sin(),
        )
    });
    let k = sys.default_steps_per_period(144e3, 0.75);
    let (s, stats) = run(
        &model,
        &sys,
        &cmd,
        LoopMethod::Rk4 {
            steps_per_period: k,
        },
        State::default(),
    );
    assert!(
        stats.run.stick_events >= 1 && stats.run.breakaways >= 1,
        "{stats:?}"
    );
    // The stick interval around the reversal at 1.25 s.
    let near = s
        .iter()
        .position(|s| s.t_s > 1.0 && s.stuck)
        .expect("a stick phase near the reversal");
    let end = near + s[near..].iter().position(|s| !s.stuck).unwrap();
    let stuck = &s[near..end];
    assert!(
        stuck.len() >= 5,
        "stick interval of {} samples",
        stuck.len()
    );
    assert!(stuck
        .iter()
        .all(|s| s.v_m_s == 0.0 && s.u_m == stuck[0].u_m));
    let fs = model.static_threshold_n(stuck[0].u_m);
    // The signed net force N = F_A − F_E: the loop drives it from the push that stopped the
    // platen through zero to the pull that breaks it away, monotonically.
    let net: Vec<f64> = stuck
        .iter()
        .map(|s| s.terms.actuator_n - s.terms.elastic_n)
        .collect();
    let falling = net[net.len() - 1] < net[0];
    assert!(
        net.windows(2).all(|w| (w[1] < w[0]) == falling),
        "not a ramp: {net:?}"
    );
    let last = net.last().unwrap().abs();
    println!(
        "stick {} samples ({:.3} s), net force {:.0} → {:.0} N, threshold {fs:.0} N",
        stuck.len(),
        stuck.len() as f64 / 1024.0,
        net[0],
        net[net.len() - 1]
    );
    assert!(last <= fs * (1.0 + 1e-9) && last > 0.95 * fs);
    // Just after: slipping the other way, pushed by more than the threshold.
    let after = &s[end];
    assert!(after.v_m_s != 0.0);
}

/// Energy: the hydraulic energy delivered into the chambers equals the platen's work plus the
/// leakage loss plus the oil's compression energy. For chamber pressures `p` and volumes `V(u)`
/// the model's continuity gives `(V/β)·p·ṗ = d(p²V/2β)/dt − p²·V̇/2β`, so
/// `E_h = W + E_L + Δ[nΣp²V/2β] − ∫n(p_a²A_a − p_b²A_b)·v/2β dt`. `E_h`, `W` and `E_L` are
/// integrated by the stepper; the rest is computed here from the output samples (trapezoid):
/// the residual is the quadrature's error, below 1e-5 of `E_h`.
#[test]
fn hydraulic_energy_balances_work_leakage_and_compression() {
    let sys = preset::lhpost_2008();
    let model = lhpost_model();
    let w = std::f64::consts::TAU;
    let amp = 0.05;
    let cmd = command(4096.0, 3.0, |t| {
        (
            amp * (w * t).sin(),
            amp * w * (w * t).cos(),
            -amp * w * w * (w * t).sin(),
        )
    });
    let (s, stats) = run(
        &model,
        &sys,
        &cmd,
        LoopMethod::Rk4 {
            steps_per_period: 8,
        },
        State::default(),
    );
    assert!(stats.cavitation_at_s.is_none());
    let act = sys.actuator();
    let (n, beta) = (f64::from(act.count), sys.oil_bulk_modulus_pa());
    let stored = |s: &Sample| {
        let sy = s.system.unwrap();
        let (va, vb) = sys.chamber_volumes_m3(s.u_m);
        n * (sy.p_a_pa.powi(2) * va + sy.p_b_pa.powi(2) * vb) / (2.0 * beta)
    };
    let g = |s: &Sample| {
        let sy = s.system.unwrap();
        n * (sy.p_a_pa.powi(2) * act.cap_area_m2 - sy.p_b_pa.powi(2) * act.rod_area_m2) * s.v_m_s
            / (2.0 * beta)
    };
    let mut correction = 0.0;
    for w in s.windows(2) {
        correction += 0.5 * (g(&w[0]) + g(&w[1])) * (w[1].t_s - w[0].t_s);
    }
    let (first, last) = (&s[0], s.last().unwrap());
    let rhs = stats.run.energy.actuator_work_j + stats.leakage_energy_j + stored(last)
        - stored(first)
        - correction;
    let residual = (stats.hydraulic_energy_j - rhs) / stats.hydraulic_energy_j.abs();
    println!(
        "energy: E_h {:.1} J, W {:.1} J, leak {:.1} J, compression {:.1} J, residual {residual:.2e}",
        stats.hydraulic_energy_j,
        stats.run.energy.actuator_work_j,
        stats.leakage_energy_j,
        stored(last) - stored(first) - correction
    );
    assert!(residual.abs() < 1e-5);
}

/// RK4 at the default step and Dopri5 at a tight tolerance run the same closed loop (the
/// LHPOST with its friction under a 0.5 Hz, 5 cm command) to within 1e-6 m.
#[test]
fn rk4_and_dopri5_agree_on_the_closed_loop() {
    let sys = preset::lhpost_2008();
    let model = lhpost_model();
    let w = std::f64::consts::PI;
    let amp = 0.05;
    let cmd = command(1024.0, 3.0, |t| {
        (
            amp * (w * t).sin(),
            amp * w * (w * t).cos(),
            -amp * w * w * (w * t).sin(),
        )
    });
    let k = sys.default_steps_per_period(144e3, 0.75);
    let (a, sa) = run(
        &model,
        &sys,
        &cmd,
        LoopMethod::Rk4 {
            steps_per_period: k,
        },
        State::default(),
    );
    let (b, sb) = run(
        &model,
        &sys,
        &cmd,
        LoopMethod::Dopri5 {
            steps_per_period: 1,
            rtol: 1e-10,
            atol: 1e-12,
        },
        State::default(),
    );
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x.u_m - y.u_m).abs())
        .fold(0.0, f64::max);
    println!(
        "RK4 (k = {k}) vs Dopri5: max |Δu| {worst:.2e} m; events {} / {}",
        sa.run.events(),
        sb.run.events()
    );
    assert!(worst < 1e-6, "{worst}");
}

/// RK4 and Dopri5 agree on the closed loop with a specimen and friction: the LHPOST with a
/// 55 t two-storey frame (fixed-base modes 3.0 and 7.06 Hz) under a 0.5 Hz, 5 cm command,
/// whose reversals stick the platen and ring the frame. Both run through the one mode
/// machine; the bound is the bare loop's 1e-6 m, on the platen and on the roof.
#[test]
fn rk4_and_dopri5_agree_on_the_closed_loop_with_a_specimen() {
    let sys = preset::lhpost_2008();
    let model = lhpost_model();
    let frame = platen_model::Specimen::new(vec![
        platen_model::Storey {
            mass_kg: 30e3,
            stiffness_n_per_m: 27_083_177.88,
            damping_n_s_per_m: 86_208.43,
        },
        platen_model::Storey {
            mass_kg: 25e3,
            stiffness_n_per_m: 19_345_127.06,
            damping_n_s_per_m: 61_577.45,
        },
    ])
    .unwrap();
    let w = std::f64::consts::PI;
    let amp = 0.05;
    let cmd = command(1024.0, 3.0, |t| {
        (
            amp * (w * t).sin(),
            amp * w * (w * t).cos(),
            -amp * w * w * (w * t).sin(),
        )
    });
    let k = sys.default_steps_per_period(144e3 + 55e3, 0.75);
    let run_with = |method| {
        let run = LoopRun {
            system: &sys,
            specimen: Some(&frame),
            command: &cmd,
            method,
            initial: State::default(),
        };
        let mut out = Trajectory::with_capacity(cmd.len());
        let stats = forward_closed_loop(&model, &run, cmd.len(), &mut out).unwrap();
        (out, stats)
    };
    let (a, sa) = run_with(LoopMethod::Rk4 {
        steps_per_period: k,
    });
    let (b, sb) = run_with(LoopMethod::Dopri5 {
        steps_per_period: 1,
        rtol: 1e-10,
        atol: 1e-12,
    });
    let worst = |x: &[f64], y: &[f64]| {
        x.iter()
            .zip(y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    };
    let platen = worst(&a.u_m, &b.u_m);
    let roof = |t: &Trajectory| t.specimen.as_ref().unwrap().u_m[1].clone();
    let roof = worst(&roof(&a), &roof(&b));
    println!(
        "RK4 (k = {k}) vs Dopri5 with a specimen: max |Δu| {platen:.2e} m, roof {roof:.2e} m; \
         stops {} / {}, breakaways {} / {}",
        sa.run.stick_events, sb.run.stick_events, sa.run.breakaways, sb.run.breakaways
    );
    assert!(sa.run.stick_events > 0, "{sa:?}");
    assert_eq!(sa.run.stick_events, sb.run.stick_events);
    assert!(platen < 1e-6 && roof < 1e-6, "{platen} {roof}");
}

/// The reference's table system and mechanics (`tests/data/reference/table_system_linear_params.json`).
fn reference_system() -> (TableSystem, f64, f64, f64) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/reference/table_system_linear_params.json"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let f = |p: &str| {
        v.pointer(p)
            .and_then(serde_json::Value::as_f64)
            .unwrap_or_else(|| panic!("{p}"))
    };
    let ts = "/table_system";
    let parts = TableSystemParts {
        actuator: Actuator {
            count: f(&format!("{ts}/actuator/count")) as u32,
            cap_area_m2: f(&format!("{ts}/actuator/cap_side_area_m2")),
            rod_area_m2: f(&format!("{ts}/actuator/rod_side_area_m2")),
            cap_volume_m3: f(&format!("{ts}/actuator/chamber_volume_m3/0")),
            rod_volume_m3: f(&format!("{ts}/actuator/chamber_volume_m3/1")),
            leakage_m3_s_per_pa: f(&format!("{ts}/actuator/leakage_m3_s_per_pa")),
        },
        servo_valve: ServoValve {
            count: f(&format!("{ts}/servo_valve/count")) as u32,
            rated_flow_m3_s: f(&format!("{ts}/servo_valve/rated_flow_m3_s")),
            rated_pressure_drop_pa: f(&format!("{ts}/servo_valve/rated_pressure_drop_pa")),
            natural_frequency_hz: f(&format!("{ts}/servo_valve/natural_frequency_hz")),
            damping_ratio: f(&format!("{ts}/servo_valve/damping_ratio")),
            delay_s: f(&format!("{ts}/servo_valve/delay_s")),
        },
        oil_bulk_modulus_pa: f(&format!("{ts}/oil_bulk_modulus_pa")),
        supply_pressure_pa: f(&format!("{ts}/supply_pressure_pa")),
        return_pressure_pa: f(&format!("{ts}/return_pressure_pa")),
        supply: Supply::Constant,
        controller: Controller {
            sample_rate_hz: f(&format!("{ts}/controller/sample_rate_hz")),
            displacement_gain_per_m: f(&format!("{ts}/controller/displacement_gain_per_m")),
            integral_gain_per_m_s: 0.0,
            velocity_feedforward_s_per_m: f(&format!(
                "{ts}/controller/velocity_feedforward_s_per_m"
            )),
            acceleration_feedforward_s2_per_m: f(&format!(
                "{ts}/controller/acceleration_feedforward_s2_per_m"
            )),
            velocity_feedback_s_per_m: f(&format!("{ts}/controller/velocity_feedback_s_per_m")),
            acceleration_feedback_s2_per_m: f(&format!(
                "{ts}/controller/acceleration_feedback_s2_per_m"
            )),
            delta_p_gain_per_pa: f(&format!("{ts}/controller/delta_p_gain_per_pa")),
            delta_p_highpass_hz: f(&format!("{ts}/controller/delta_p_highpass_hz")),
        },
    };
    let sys = TableSystem::new(parts, 0.0).unwrap();
    (
        sys,
        f("/mechanics/mass_kg"),
        f("/mechanics/stiffness_n_per_m"),
        f("/mechanics/viscous_n_s_per_m"),
    )
}

/// `(gain, phase in degrees)` of `y` against `sin(ωt)` by least squares on `a·sin + b·cos + c`.
fn sine_fit(t: &[f64], y: &[f64], w: f64) -> (f64, f64) {
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for (&ti, &yi) in t.iter().zip(y) {
        let basis = [(w * ti).sin(), (w * ti).cos(), 1.0];
        for (i, row) in m.iter_mut().enumerate() {
            r[i] += basis[i] * yi;
            row.iter_mut()
                .zip(basis)
                .for_each(|(x, b)| *x += basis[i] * b);
        }
    }
    // Gauss–Jordan on the 3 × 3 normal equations.
    for c in 0..3 {
        let p = m[c][c];
        m[c].iter_mut().for_each(|x| *x /= p);
        r[c] /= p;
        let pivot = m[c];
        for i in (0..3).filter(|&i| i != c) {
            let f = m[i][c];
            m[i].iter_mut().zip(pivot).for_each(|(x, p)| *x -= f * p);
            r[i] -= f * r[c];
        }
    }
    let (a, b) = (r[0], r[1]);
    (a.hypot(b), b.atan2(a).to_degrees())
}

/// Small-signal frequency response: sine commands of 10 µm from 0.5 Hz to 25 Hz (above the
/// 10.07 Hz oil column) through the nonlinear closed loop match the linearised closed-loop
/// transfer functions command → displacement and → acceleration written independently in
/// numpy (`tools/reference/table_system_linear.py`), within 2 % and 2° (the bar; the
/// amplitude is small enough for the orifice law's curvature to stay below 1e-4, and the
/// reference models the controller's sampling as its zero-order hold's response, which holds
/// to `(f/f_c)² ≈ 4e-5` here). The crate's own linearisation is held to the same reference.
#[test]
fn the_small_signal_response_matches_the_independent_linear_reference() {
    let (sys, mass, stiffness, damping) = reference_system();
    let model = linear(mass, stiffness, damping);
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/reference/table_system_frf.csv"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let rate = sys.controller().sample_rate_hz;
    let k = sys.default_steps_per_period(mass, 0.0);
    let mech = platen_system::Mechanics {
        mass_kg: mass,
        stiffness_n_per_m: stiffness,
        damping_n_s_per_m: damping,
    };
    let lin = sys.linearise(mech, 0.0);
    let (mut worst_gain, mut worst_phase) = (0.0f64, 0.0f64);
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let (f, gain_u, phase_u, gain_a, phase_a) = (v[0], v[1], v[2], v[3], v[4]);
        let w = std::f64::consts::TAU * f;
        let amp = 1e-5;
        // Settle for at least 2 s, then fit over whole periods (at least 1 s).
        let periods_fit = (f.ceil()).max(1.0);
        let settle = (2.0 * f).ceil() / f;
        let duration = settle + periods_fit / f;
        let cmd = command(rate, duration, |t| {
            (
                amp * (w * t).sin(),
                amp * w * (w * t).cos(),
                -amp * w * w * (w * t).sin(),
            )
        });
        let (s, _) = run(
            &model,
            &sys,
            &cmd,
            LoopMethod::Rk4 {
                steps_per_period: k,
            },
            State::default(),
        );
        let tail: Vec<&Sample> = s.iter().filter(|s| s.t_s >= settle - 1e-9).collect();
        let t: Vec<f64> = tail.iter().map(|s| s.t_s).collect();
        let u: Vec<f64> = tail.iter().map(|s| s.u_m / amp).collect();
        let a: Vec<f64> = tail.iter().map(|s| s.a_m_s2 / amp).collect();
        let (gu, pu) = sine_fit(&t, &u, w);
        let (ga, pa) = sine_fit(&t, &a, w);
        let wrap = |d: f64| (d + 540.0).rem_euclid(360.0) - 180.0;
        let rows = [
            ("u", gu, gain_u, wrap(pu - phase_u)),
            ("a", ga, gain_a, wrap(pa - phase_a)),
        ];
        for (name, g, g_ref, dphi) in rows {
            let dg = g / g_ref - 1.0;
            println!("{f:5} Hz {name}: gain {g:.6} vs {g_ref:.6} ({dg:+.2e}), phase {dphi:+.4}°");
            worst_gain = worst_gain.max(dg.abs());
            worst_phase = worst_phase.max(dphi.abs());
            assert!(dg.abs() < 0.02 && dphi.abs() < 2.0, "{f} Hz {name}");
        }
        let h = sys.closed_loop_response(&lin, f);
        assert!(
            (h.norm() / gain_u - 1.0).abs() < 1e-6,
            "linearisation at {f} Hz"
        );
        assert!(wrap(h.arg().to_degrees() - phase_u).abs() < 1e-4);
    }
    println!("worst: gain {worst_gain:.2e}, phase {worst_phase:.3}°");
}

/// A command beyond the actuators' reach stops the run cleanly at the end stop (a chamber's
/// volume gone), with its time and displacement, instead of running on to nonsense.
#[test]
fn a_command_past_the_actuators_reach_stops_at_the_end_stop() {
    let sys = preset::lhpost_2008();
    let model = lhpost_model();
    let w = std::f64::consts::TAU * 0.2;
    let cmd = command(1024.0, 5.0, |t| {
        (
            1.2 * (w * t).sin(),
            1.2 * w * (w * t).cos(),
            -1.2 * w * w * (w * t).sin(),
        )
    });
    let run = LoopRun {
        system: &sys,
        specimen: None,
        command: &cmd,
        method: LoopMethod::Rk4 {
            steps_per_period: sys.default_steps_per_period(144e3, 0.75),
        },
        initial: State::default(),
    };
    let err = forward_closed_loop(&model, &run, cmd.len(), &mut Keep(Vec::new())).unwrap_err();
    match err {
        platen_integrate::IntegrateError::EndStop { t_s, u_m } => {
            // The cap side empties at V_a0/A_a = 0.2122/0.2051 = 1.0346 m.
            assert!(
                (u_m - 0.2122 / 0.2051).abs() < 1e-3 && t_s > 0.5 && t_s < 1.25,
                "{u_m} {t_s}"
            );
        }
        other => panic!("{other}"),
    }
}

/// Dopri5 asked for a tolerance no step can meet (10⁻³⁰⁰, far below rounding) gives up: the
/// run stops with the adaptive failure, as the bare platen's Dopri5 does, instead of taking
/// the step it could not make accurate (the closed loop used to accept it silently once the
/// step had shrunk to 10⁻¹⁴ of the piece).
#[test]
fn dopri5_that_cannot_meet_its_tolerance_stops_with_the_failure() {
    let sys = preset::lhpost_2008();
    let model = lhpost_model();
    let w = std::f64::consts::TAU;
    let cmd = command(1024.0, 0.1, |t| {
        (
            0.01 * (w * t).sin(),
            0.01 * w * (w * t).cos(),
            -0.01 * w * w * (w * t).sin(),
        )
    });
    let run = LoopRun {
        system: &sys,
        specimen: None,
        command: &cmd,
        method: LoopMethod::Dopri5 {
            steps_per_period: 1,
            rtol: 1e-300,
            atol: 1e-300,
        },
        initial: State::default(),
    };
    let err = forward_closed_loop(&model, &run, cmd.len(), &mut Keep(Vec::new())).unwrap_err();
    match err {
        platen_integrate::IntegrateError::AdaptiveFailed { t_s, reason } => {
            // Which limit it meets first (the step budget or the smallest step) depends on
            // how many steps of exactly zero error the start at rest allows; either is a give-up.
            println!("gave up at t = {t_s} s: {reason}");
            assert!((0.0..0.1).contains(&t_s), "{t_s}");
        }
        other => panic!("{other}"),
    }
}

/// A stiff specimen (storey modes far above the oil column) moves with the platen as a rigid
/// payload: the oil column rings at the closed form with `M + Σmᵢ`, within 0.5 % (the storeys'
/// own modes, above 140 Hz, add `(7.6/140)²/2 ≈ 0.15 %` of effective mass).
#[test]
fn a_stiff_specimen_lowers_the_oil_column_like_a_rigid_payload() {
    let sys = symmetric(1, 0.0);
    let model = linear(20_000.0, 0.0, 0.0);
    let storey = |m: f64| platen_model::Storey {
        mass_kg: m,
        stiffness_n_per_m: m * (std::f64::consts::TAU * 200.0).powi(2),
        damping_n_s_per_m: 0.0,
    };
    let specimen = platen_model::Specimen::new(vec![storey(8000.0), storey(7000.0)]).unwrap();
    let cmd = command(4096.0, 2.0, |_| (0.0, 0.0, 0.0));
    let mut keep = Keep(Vec::new());
    let run = LoopRun {
        system: &sys,
        specimen: Some(&specimen),
        command: &cmd,
        method: LoopMethod::Rk4 {
            steps_per_period: 8,
        },
        initial: State {
            u_m: 0.0,
            v_m_s: 0.01,
        },
    };
    let stats = forward_closed_loop(&model, &run, cmd.len(), &mut keep).unwrap();
    // The platen's and the specimen's energy balance closes (work of the actuators = change
    // of kinetic, elastic and specimen energy + dissipation) to the integration's accuracy.
    let residual = stats.run.energy.relative_residual();
    println!("energy balance with the specimen: relative residual {residual:.2e}");
    assert!(residual.abs() < 1e-8, "{residual}");
    let t: Vec<f64> = keep.0.iter().map(|s| s.t_s).collect();
    let v: Vec<f64> = keep.0.iter().map(|s| s.v_m_s).collect();
    let f = crossing_frequency_hz(&t, &v);
    let expected = sys.oil_column_frequency_hz(35_000.0, 0.0);
    println!("stiff specimen: {f:.4} Hz, rigid payload closed form {expected:.4} Hz");
    assert!((f / expected - 1.0).abs() < 5e-3);
    assert!(keep
        .0
        .iter()
        .all(|s| s.specimen.is_some() && s.system.is_some()));
}

/// A loop whose orifice is the stiffest mode (the fuzzing find of issue 38): stiff oil
/// (10 GPa) in small chambers, four valves, a 1024 Hz controller, and a platen locked by
/// friction against a command it cannot follow. The valve opens fully and the cap chamber
/// fills to within the orifice's laminar drop of the supply, where the pressure's own rate
/// `β/V·K/√p_t` is some 1e5 1/s: at the default step (set by the spool and the oil column,
/// 3 per period) RK4 is 200 times past its stability bound there and the state used to go
/// non-finite. The step is now cut to that rate where the state reaches it: the stall force
/// `A·(P_s − P_R)` within 1e-4 (the locked-platen bound above), the rod chamber at the
/// return, and pieces only while the stall lasts.
#[test]
fn a_stiff_orifice_at_stall_is_integrated_where_the_default_step_would_blow_up() {
    let mut parts = symmetric_parts(4, 0.0);
    parts.oil_bulk_modulus_pa = 1e10;
    parts.supply_pressure_pa = 47e6;
    parts.controller.sample_rate_hz = 1024.0;
    parts.controller.displacement_gain_per_m = 100.0;
    let sys = TableSystem::new(parts, 0.0).unwrap();
    let model = locked(20_000.0);
    let k = sys.default_steps_per_period(20_000.0, 0.3);
    let h = sys.controller().period_s() / f64::from(k);
    // The laminar rate of the cap chamber at full opening, the stiffest the law gets.
    let c = sys.constants();
    let laminar = 1e10 / 0.012 * c.land_coefficient * c.laminar_slope;
    println!(
        "default {k} steps per period: h·λ_laminar = {:.0}",
        h * laminar
    );
    assert!(
        h * laminar > 100.0,
        "the case must be far past RK4's bound 2.8"
    );
    let cmd = command(1024.0, 0.5, |_| (0.1, 0.0, 0.0));
    let (s, stats) = run(
        &model,
        &sys,
        &cmd,
        LoopMethod::Rk4 {
            steps_per_period: k,
        },
        State::default(),
    );
    assert_eq!(s.len(), cmd.len());
    let last = s.last().unwrap();
    let f = last.terms.actuator_n;
    let expected = 0.02 * (47e6 - 0.3e6);
    let rel = (f / expected - 1.0).abs();
    let system = last.system.unwrap();
    println!(
        "stall: {f:.1} N, closed form {expected:.1} N, {rel:.2e}; p_b {:.1} Pa; \
         {} rhs evaluations for {} grid steps",
        system.p_b_pa, stats.run.rhs_evaluations, stats.run.steps
    );
    assert!(rel < 1e-4, "{f} vs {expected}");
    assert!((system.p_b_pa - 0.3e6).abs() < 1e-4 * 0.3e6);
}
