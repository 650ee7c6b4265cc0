//! The table system's closed forms against published figures and hand calculations.

use platen_system::{
    preset, Actuator, Controller, ControllerInput, ControllerState, Mechanics, ServoValve, Supply,
    SystemError, TableSystem, TableSystemParts,
};

/// A double-ended actuator of area `a` and total oil volume `v_t` (half in each chamber).
fn symmetric(a: f64, v_t: f64, beta: f64) -> TableSystem {
    TableSystem::new(symmetric_parts(a, v_t, beta), 0.0).unwrap()
}

/// The values of [`symmetric`], to change before validating.
fn symmetric_parts(a: f64, v_t: f64, beta: f64) -> TableSystemParts {
    TableSystemParts {
        actuator: Actuator {
            count: 1,
            cap_area_m2: a,
            rod_area_m2: a,
            cap_volume_m3: 0.5 * v_t,
            rod_volume_m3: 0.5 * v_t,
            leakage_m3_s_per_pa: 0.0,
        },
        servo_valve: ServoValve {
            count: 1,
            rated_flow_m3_s: 1e-3,
            rated_pressure_drop_pa: 7e6,
            natural_frequency_hz: 100.0,
            damping_ratio: 0.7,
            delay_s: 0.0,
        },
        oil_bulk_modulus_pa: beta,
        supply_pressure_pa: 21e6,
        return_pressure_pa: 0.0,
        supply: Supply::Constant,
        controller: Controller {
            sample_rate_hz: 1000.0,
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

/// The LNEC 1-D table's published figures (A = 0.012456 m², V_t = 0.002659 m³,
/// β = 193.7 MPa, platen 1975 kg) give its measured 24.1 Hz by `4βA²/(V_t·M)`.
#[test]
fn the_lnec_table_rings_at_its_published_24_1_hz() {
    let sys = symmetric(0.012456, 0.002659, 193.7e6);
    let f = sys.oil_column_frequency_hz(1975.0, 0.0);
    let by_hand =
        (4.0 * 193.7e6 * 0.012456_f64.powi(2) / (0.002659 * 1975.0)).sqrt() / std::f64::consts::TAU;
    assert!((f / by_hand - 1.0).abs() < 1e-12);
    assert!((f - 24.1).abs() < 0.05, "{f}");
}

/// The LHPOST preset meets the published figures it was built from: 10.66 Hz with
/// `Mₑ` = 144 t, 4.2 MN compression and 2.6 MN tension per actuator, at least 1.8 m/s
/// valve-limited, 2 × 2 valves of 10 000 l/min at 7 MPa, the 246 Hz valve stage.
#[test]
fn the_lhpost_preset_meets_the_published_figures() {
    let sys = preset::lhpost_2008();
    assert!((sys.oil_column_frequency_hz(144e3, 0.0) / 10.66 - 1.0).abs() < 2e-3);
    let cap = sys.capacities();
    let n = f64::from(sys.actuator().count);
    assert_eq!(n, 2.0);
    assert!(
        (cap.push_force_n / n / 4.2e6 - 1.0).abs() < 1e-3,
        "{}",
        cap.push_force_n
    );
    assert!(
        (cap.pull_force_n / n / 2.6e6 - 1.0).abs() < 1e-3,
        "{}",
        cap.pull_force_n
    );
    assert!(cap.extend_velocity_m_s >= 1.8 && cap.retract_velocity_m_s >= 1.8);
    assert_eq!(sys.servo_valve().count, 2);
    assert!((sys.servo_valve().rated_flow_m3_s * 60_000.0 - 10_000.0).abs() < 1e-9);
    assert_eq!(sys.servo_valve().rated_pressure_drop_pa, 7e6);
    assert_eq!(sys.servo_valve().natural_frequency_hz, 246.0);
    // The rest of the stroke: a chamber keeps oil at ±0.75 m.
    sys.check_stroke(0.75).unwrap();
    // The loop is stable with margins.
    let mech = Mechanics {
        mass_kg: 144e3,
        stiffness_n_per_m: 1.266e6,
        damping_n_s_per_m: 20e3,
    };
    let m = sys.margins(&sys.linearise(mech, 0.0));
    assert!(m.stable && m.gain_margin_db.unwrap() > 8.0 && m.phase_margin_deg.unwrap() > 45.0);
}

/// No-load velocity of a single-ended actuator at full opening, by hand: `A_a·v = K√(P_s − p_a)`,
/// `A_b·v = K√(p_b − P_R)`, `A_a·p_a = A_b·p_b`; and the symmetric closed form
/// `m·Q_r·√((P_s − P_R)/Δp_r)/A`.
#[test]
fn the_valve_limited_velocities_are_the_orifice_law_at_no_load() {
    let sys = preset::lhpost_2008();
    let cap = sys.capacities();
    let k = 2.0 * (10_000.0 / 60_000.0) / (3.5e6_f64).sqrt();
    let (aa, ab, ps, pr) = (0.2051_f64, 0.1291_f64, 20.7e6, 0.35e6);
    let v = cap.extend_velocity_m_s;
    let p_a = ps - (aa * v / k).powi(2);
    let p_b = pr + (ab * v / k).powi(2);
    assert!(
        (aa * p_a - ab * p_b).abs() < 1e-6 * aa * ps,
        "force {}",
        aa * p_a - ab * p_b
    );
    let sym = symmetric(0.02, 0.02, 1e9);
    let expected = 1e-3 * (21e6 / 7e6_f64).sqrt() / 0.02;
    assert!((sym.capacities().extend_velocity_m_s / expected - 1.0).abs() < 1e-12);
    assert!((sym.capacities().retract_velocity_m_s / expected - 1.0).abs() < 1e-12);
}

/// The digital high-pass on `Δp` (Tustin of `s/(s + ω)`): a step of `Δp` passes at once and
/// decays as `((2/T − ω)/(2/T + ω))^k`, the bilinear map of `e^(−ωt)`.
#[test]
fn the_delta_p_highpass_is_the_bilinear_map_of_its_continuous_filter() {
    let mut parts = symmetric_parts(0.02, 0.02, 1e9);
    let c = &mut parts.controller;
    c.delta_p_gain_per_pa = 1e-7;
    c.delta_p_highpass_hz = 2.0;
    let sys = TableSystem::new(parts, 0.0).unwrap();
    let c = sys.controller();
    let mut st = ControllerState::default();
    let input = |dp: f64| ControllerInput {
        delta_p_pa: dp,
        ..ControllerInput::default()
    };
    assert_eq!(c.update(&mut st, &input(0.0)), 0.0);
    let t = 1.0 / c.sample_rate_hz;
    let w = std::f64::consts::TAU * 2.0;
    let r = (2.0 / t - w) / (2.0 / t + w);
    let first = 2.0 / t / (2.0 / t + w);
    for k in 0..50 {
        let d = c.update(&mut st, &input(1e6));
        let expected = -1e-7 * 1e6 * first * r.powi(k);
        assert!((d - expected).abs() < 1e-12, "{k}: {d} vs {expected}");
    }
}

/// The drive saturates at ±1 and the integrator does not wind up while it is saturated.
#[test]
fn the_drive_saturates_and_the_integrator_does_not_wind_up() {
    let mut parts = symmetric_parts(0.02, 0.02, 1e9);
    parts.controller.displacement_gain_per_m = 10.0;
    parts.controller.integral_gain_per_m_s = 100.0;
    let sys = TableSystem::new(parts, 0.0).unwrap();
    let c = sys.controller();
    let mut st = ControllerState::default();
    let at = |r: f64| ControllerInput {
        command_u_m: r,
        ..ControllerInput::default()
    };
    for _ in 0..1000 {
        assert_eq!(c.update(&mut st, &at(1.0)), 1.0);
        assert!(st.saturated);
    }
    // Back on target: the drive leaves saturation at once (no wound-up integral).
    let d = c.update(&mut st, &at(0.0));
    assert!(d.abs() < 1.0, "{d}");
}

/// Impossible systems are refused with the path of the offending value.
#[test]
fn impossible_systems_are_refused_with_their_path() {
    let good = symmetric_parts(0.02, 0.04, 1e9);
    type Spoil = Box<dyn Fn(&mut TableSystemParts)>;
    let cases: Vec<(&str, Spoil)> = vec![
        (
            "actuator.cap_side_area_m2",
            Box::new(|s| s.actuator.cap_area_m2 = -1.0),
        ),
        (
            "actuator.chamber_volume_m3",
            Box::new(|s| s.actuator.cap_volume_m3 = 0.01),
        ),
        (
            "oil_bulk_modulus_pa",
            Box::new(|s| s.oil_bulk_modulus_pa = 0.0),
        ),
        (
            "servo_valve.natural_frequency_hz",
            Box::new(|s| s.servo_valve.natural_frequency_hz = f64::NAN),
        ),
        (
            "return_pressure_pa",
            Box::new(|s| s.return_pressure_pa = 30e6),
        ),
        (
            "controller.sample_rate_hz",
            Box::new(|s| s.controller.sample_rate_hz = 0.0),
        ),
        (
            "controller.displacement_gain_per_m",
            Box::new(|s| s.controller.displacement_gain_per_m = -2.0),
        ),
    ];
    for (path, spoil) in cases {
        let mut s = good;
        spoil(&mut s);
        match TableSystem::new(s, 0.75) {
            Err(SystemError::Invalid { path: p, .. }) => assert_eq!(p, path),
            other => panic!("{path}: {other:?}"),
        }
    }
    TableSystem::new(good, 0.75).unwrap();
}
