//! The multi-axis linearisation ([`TableLinearisation`]) reduced to one DOF: two identical
//! actuators along x with every other DOF held are the uniaxial loop of two actuators
//! ([`TableSystem::closed_loop_response`], [`TableSystem::loop_gain`], whose own tests hold
//! it to the Merritt closed forms and an independent NumPy reference).

use nalgebra::{Matrix3, Vector3};
use num_complex::Complex64 as C64;
use platen_model::multi_axis::{
    Actuator, Dof, DofSet, LinearSpecimen, Mount, MultiAxisTable, RigidPlaten, TableParts,
};
use platen_system::{
    open_loop, ActuatorHydraulics, ActuatorState, Controller, DofController, DofGeometry,
    FlowGains, HydraulicState, Mechanics, ServoValve, Supply, SystemError, TableHydraulics,
    TableHydraulicsParts, TableLinearisation, TableSystem, TableSystemParts,
};

const MASS_KG: f64 = 30_000.0;
const CHAMBER_M3: f64 = 0.03;
const LEAKAGE_M3_S_PER_PA: f64 = 3e-11;
const BETA_PA: f64 = 1.2e9;
const SUPPLY_PA: f64 = 21e6;
const RETURN_PA: f64 = 0.5e6;
const RATE_HZ: f64 = 1024.0;
const FREQUENCIES_HZ: [f64; 7] = [0.05, 0.5, 2.0, 5.0, 9.0, 20.0, 60.0];

fn valve() -> ServoValve {
    ServoValve {
        count: 2,
        rated_flow_m3_s: 0.1667,
        rated_pressure_drop_pa: 7e6,
        natural_frequency_hz: 246.0,
        damping_ratio: 0.5,
        delay_s: 0.0005,
    }
}

/// Every term of the law at work.
fn gains() -> Controller {
    Controller {
        sample_rate_hz: RATE_HZ,
        displacement_gain_per_m: 10.0,
        integral_gain_per_m_s: 3.0,
        velocity_feedforward_s_per_m: 0.15,
        acceleration_feedforward_s2_per_m: 1e-3,
        velocity_feedback_s_per_m: 0.02,
        acceleration_feedback_s2_per_m: 2e-4,
        delta_p_gain_per_pa: 1e-8,
        delta_p_highpass_hz: 0.5,
    }
}

/// Two double-acting actuators along +x at y = ±1 m through the centre of mass's height,
/// every DOF but x held.
fn x_table(cap_m2: f64, rod_m2: f64) -> MultiAxisTable {
    let platen = RigidPlaten::new(
        MASS_KG,
        Matrix3::from_diagonal(&Vector3::new(1e5, 2e5, 3e5)),
        Vector3::new(0.0, 0.0, -0.5),
    )
    .unwrap();
    let actuator = |name: &str, y: f64| Actuator {
        name: name.into(),
        base_m: Vector3::new(-8.0, y, -0.5),
        mount: Mount::Swivel {
            platen_m: Vector3::new(-6.0, y, -0.5),
        },
        cap_side_area_m2: cap_m2,
        rod_side_area_m2: rod_m2,
        chamber_volume_m3: CHAMBER_M3,
        stroke_m: 0.3,
    };
    MultiAxisTable::new(TableParts {
        platen,
        actuators: vec![actuator("a1", 1.0), actuator("a2", -1.0)],
        struts: Vec::new(),
        bearings: Vec::new(),
        held: DofSet::of(&[Dof::Y, Dof::Z, Dof::Roll, Dof::Pitch, Dof::Yaw]),
        oil_bulk_modulus_pa: BETA_PA,
    })
    .unwrap()
}

fn hydraulics_of(table: &MultiAxisTable) -> TableHydraulics {
    let actuators = table
        .actuators()
        .iter()
        .map(|a| ActuatorHydraulics {
            cap_area_m2: a.cap_side_area_m2,
            rod_area_m2: a.rod_side_area_m2,
            chamber_volume_m3: a.chamber_volume_m3,
            leakage_m3_s_per_pa: LEAKAGE_M3_S_PER_PA,
            servo_valve: valve(),
        })
        .collect();
    let strokes: Vec<f64> = table.actuators().iter().map(|a| a.stroke_m).collect();
    TableHydraulics::new(
        TableHydraulicsParts {
            actuators,
            oil_bulk_modulus_pa: BETA_PA,
            supply_pressure_pa: SUPPLY_PA,
            return_pressure_pa: RETURN_PA,
            supply: Supply::Constant,
        },
        &strokes,
    )
    .unwrap()
}

fn controller_of(table: &MultiAxisTable) -> DofController {
    let mut loops = [open_loop(RATE_HZ); 6];
    loops[Dof::X.index()] = gains();
    DofController::new(RATE_HZ, loops, 3e-8, DofGeometry::of_table(table).unwrap()).unwrap()
}

/// The uniaxial system of the same values: two actuators, chambers of equal volume.
fn uniaxial(cap_m2: f64, rod_m2: f64) -> TableSystem {
    TableSystem::new(
        TableSystemParts {
            actuator: platen_system::Actuator {
                count: 2,
                cap_area_m2: cap_m2,
                rod_area_m2: rod_m2,
                cap_volume_m3: CHAMBER_M3,
                rod_volume_m3: CHAMBER_M3,
                leakage_m3_s_per_pa: LEAKAGE_M3_S_PER_PA,
            },
            servo_valve: valve(),
            oil_bulk_modulus_pa: BETA_PA,
            supply_pressure_pa: SUPPLY_PA,
            return_pressure_pa: RETURN_PA,
            supply: Supply::Constant,
            controller: gains(),
        },
        0.3,
    )
    .unwrap()
}

fn close(a: C64, b: C64, tol: f64, what: &str) {
    let err = (a - b).norm() / b.norm();
    println!("{what}: {err:.2e}");
    assert!(err <= tol, "{what}: {a} vs {b} ({err:.2e})");
}

/// Double-ended actuators (`A_a = A_b`): null pressures at mid-supply, where the opening-
/// and closing-side gains of a land are equal, so the uniaxial linearisation's own flow gains
/// are the multi-axis ones and the two models agree with nothing adjusted.
#[test]
fn two_double_ended_x_actuators_are_the_uniaxial_loop() {
    let table = x_table(0.05, 0.05);
    let lin = TableLinearisation::new(&table, &hydraulics_of(&table), &controller_of(&table), None)
        .unwrap();
    let sys = uniaxial(0.05, 0.05);
    let mech = Mechanics {
        mass_kg: MASS_KG,
        stiffness_n_per_m: 0.0,
        damping_n_s_per_m: 0.0,
    };
    let uni = sys.linearise(mech, 0.0);
    assert!((lin.actuators()[0].flow_gain_a_m3_s / uni.flow_gain_a_m3_s - 1.0).abs() < 1e-14);
    for f in FREQUENCIES_HZ {
        let h = lin.transfer_matrix(f);
        close(h[0][0], sys.closed_loop_response(&uni, f), 1e-9, "U/R");
        close(
            lin.loop_gain(Dof::X, f).unwrap(),
            sys.loop_gain(&uni, f),
            1e-9,
            "L",
        );
        // The held DOFs' rows and columns are zero.
        for (i, row) in h.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                assert!((i, j) == (0, 0) || *x == C64::from(0.0), "{i} {j}");
            }
        }
    }
    let (a, b) = (lin.margins(Dof::X).unwrap(), sys.margins(&uni));
    let near = |x: Option<f64>, y: Option<f64>| (x.unwrap() - y.unwrap()).abs() < 1e-6;
    assert!(near(a.phase_margin_deg, b.phase_margin_deg), "{a:?} {b:?}");
    assert!(near(a.gain_margin_db, b.gain_margin_db), "{a:?} {b:?}");
    assert!(
        near(a.gain_crossover_hz, b.gain_crossover_hz),
        "{a:?} {b:?}"
    );
    assert_eq!(a.stable, b.stable);
    assert!((a.peak_gain / b.peak_gain - 1.0).abs() < 1e-9);
    assert!(lin.loop_gain(Dof::Y, 1.0).is_none() && lin.margins(Dof::Pitch).is_none());
}

/// Unequal areas put the null pressures off mid-supply: a land then opens onto a different
/// drop on either side of the null, and the multi-axis model takes the fundamental a small
/// sine sees, the mean of the two gains, `K·(√(P_s − p_a0) + √(p_a0 − P_R))/2` (the uniaxial
/// [`TableSystem::linearise`] takes the opening side's, `K·√(P_s − p_a0)`). With the uniaxial
/// model given those gains, the two agree.
#[test]
fn two_unequal_area_x_actuators_are_the_uniaxial_loop_with_the_mean_flow_gains() {
    let (cap, rod) = (0.06, 0.035);
    let table = x_table(cap, rod);
    let lin = TableLinearisation::new(&table, &hydraulics_of(&table), &controller_of(&table), None)
        .unwrap();
    let sys = uniaxial(cap, rod);
    let mech = Mechanics {
        mass_kg: MASS_KG,
        stiffness_n_per_m: 0.0,
        damping_n_s_per_m: 0.0,
    };
    let mut uni = sys.linearise(mech, 0.0);
    // No static force along x: A_a·p_a0 = A_b·p_b0, p_a0 + p_b0 = P_s + P_R.
    let p_a0 = rod * (SUPPLY_PA + RETURN_PA) / (cap + rod);
    let p_b0 = SUPPLY_PA + RETURN_PA - p_a0;
    let k = valve().land_coefficient();
    let mean = |p: f64| k * ((SUPPLY_PA - p).sqrt() + (p - RETURN_PA).sqrt()) / 2.0;
    let a = lin.actuators()[0];
    assert!((a.null_pressure_a_pa / p_a0 - 1.0).abs() < 1e-12);
    assert!((a.flow_gain_a_m3_s / mean(p_a0) - 1.0).abs() < 1e-12);
    assert!((a.flow_gain_b_m3_s / mean(p_b0) - 1.0).abs() < 1e-12);
    // The opening side alone differs by percents here: the adjustment is not idle.
    assert!((uni.flow_gain_a_m3_s / mean(p_a0) - 1.0).abs() > 0.01);
    uni.flow_gain_a_m3_s = a.flow_gain_a_m3_s;
    uni.flow_gain_b_m3_s = a.flow_gain_b_m3_s;
    for f in FREQUENCIES_HZ {
        close(
            lin.transfer_matrix(f)[0][0],
            sys.closed_loop_response(&uni, f),
            1e-9,
            "U/R",
        );
        close(
            lin.loop_gain(Dof::X, f).unwrap(),
            sys.loop_gain(&uni, f),
            1e-9,
            "L",
        );
    }
}

/// At rest the valves make up the leakage across the pistons, `C_L·(p_a0 − p_b0) < 0` here
/// (`p_a0 < p_b0`): they rest a little closed, where each land's gain is its closing side's,
/// `K·√(p_a0 − P_R)` for chamber a and `K·√(P_s − p_b0)` (the same) for chamber b, and the
/// opening that passes the leakage is `C_L·(p_a0 − p_b0)/(K·√(p_a0 − P_R))`.
#[test]
fn at_rest_the_valves_rest_on_the_side_that_makes_up_the_leakage() {
    let (cap, rod) = (0.06, 0.035);
    let table = x_table(cap, rod);
    let lin = TableLinearisation::with_flow_gains(
        &table,
        &hydraulics_of(&table),
        &controller_of(&table),
        None,
        FlowGains::AtRest,
    )
    .unwrap();
    let p_a0 = rod * (SUPPLY_PA + RETURN_PA) / (cap + rod);
    let p_b0 = SUPPLY_PA + RETURN_PA - p_a0;
    let k = valve().land_coefficient();
    let closing = k * (p_a0 - RETURN_PA).sqrt();
    let a = lin.actuators()[1];
    assert!((a.flow_gain_a_m3_s / closing - 1.0).abs() < 1e-12);
    assert!((a.flow_gain_b_m3_s / (k * (SUPPLY_PA - p_b0).sqrt()) - 1.0).abs() < 1e-12);
    let rest = LEAKAGE_M3_S_PER_PA * (p_a0 - p_b0) / closing;
    assert!(rest < 0.0 && (a.rest_opening / rest - 1.0).abs() < 1e-12);
}

/// A flexible, damped specimen (10 t on a spring along x, 3 Hz, 5 % damping) pushes on the
/// platen as its dynamic mass `m·(k + jωc)/(k + jωc − mω²)`: at each frequency the loop
/// equals the uniaxial one whose mechanics have that dynamic stiffness
/// (`M + Re m_dyn` as the mass, `−ω·Im m_dyn` as the damping).
#[test]
fn a_flexible_specimen_is_its_dynamic_mass() {
    let table = x_table(0.05, 0.05);
    let (m_s, f_s, zeta) = (10_000.0, 3.0, 0.05);
    let w_s = std::f64::consts::TAU * f_s;
    let (k_s, c_s) = (m_s * w_s * w_s, 2.0 * zeta * m_s * w_s);
    let mut influence = nalgebra::DMatrix::zeros(1, 6);
    influence[(0, 0)] = 1.0;
    let one = |x: f64| nalgebra::DMatrix::from_element(1, 1, x);
    let specimen = LinearSpecimen::new(one(m_s), one(k_s), one(c_s), influence).unwrap();
    let lin = TableLinearisation::new(
        &table,
        &hydraulics_of(&table),
        &controller_of(&table),
        Some(&specimen),
    )
    .unwrap();
    let sys = uniaxial(0.05, 0.05);
    for f in [0.5, 2.0, 3.0, 5.0, 20.0] {
        let w = std::f64::consts::TAU * f;
        let spring = C64::new(k_s, w * c_s);
        let dynamic = m_s * spring / (spring - m_s * w * w);
        let uni = sys.linearise(
            Mechanics {
                mass_kg: MASS_KG + dynamic.re,
                stiffness_n_per_m: 0.0,
                damping_n_s_per_m: -w * dynamic.im,
            },
            0.0,
        );
        close(
            lin.transfer_matrix(f)[0][0],
            sys.closed_loop_response(&uni, f),
            1e-9,
            "U/R with a flexible specimen",
        );
    }
}

/// Parts that do not belong together are refused with what differs.
#[test]
fn hydraulics_of_another_table_are_refused() {
    let table = x_table(0.05, 0.05);
    let mut parts = hydraulics_of(&table).parts().clone();
    parts.actuators.pop();
    let one = TableHydraulics::new(parts, &[0.3]).unwrap();
    let err = TableLinearisation::new(&table, &one, &controller_of(&table), None).unwrap_err();
    assert!(matches!(err, SystemError::Mismatch { .. }), "{err}");
}

/// A multi-axis actuator's stiffest pressure rate (the step the integrator cuts to near an
/// orifice's laminar drop) is the largest diagonal entry of its pressures' Jacobian, by
/// central differences of its own right-hand side: double-acting and single-acting
/// (a cap chamber alone), either sign of the opening, at the working point and within a
/// few kPa of the supply or the return. The double-acting one equals the uniaxial loop's
/// rate with the same values to 1e-12, and the bound over the stroke (`None`) is at least
/// the rate at any stroke. Bound 1e-6: the differences' truncation and rounding.
#[test]
fn the_stiffest_pressure_rate_is_the_jacobians_diagonal_on_a_multi_axis_actuator() {
    let p_t = platen_system::LAMINAR_FRACTION * valve().rated_pressure_drop_pa;
    for (cap, rod) in [(0.02, 0.02), (0.02, 0.012), (0.02, 0.0)] {
        let hyd = hydraulics_of(&x_table(cap, rod));
        let cases = [
            (0.0, 12e6, 9e6, 0.3, 10.0),
            (0.2, SUPPLY_PA - 4e3, 1e6, 1.0, 1.0),
            (-0.25, SUPPLY_PA - 0.3 * p_t, 2e6, 0.9, 0.01),
            (0.1, RETURN_PA + 0.4 * p_t, 8e6, -1.0, 0.01),
            (0.1, 2e6, SUPPLY_PA - 0.5 * p_t, -1.0, 0.01),
        ];
        for (s_m, p_a, p_b, spool, d) in cases {
            let p_b = if rod == 0.0 { RETURN_PA } else { p_b };
            let state = ActuatorState {
                p_a_pa: p_a,
                p_b_pa: p_b,
                spool,
                spool_rate_1_s: 0.0,
            };
            let rates = |s: ActuatorState| hyd.actuator_rates(0, s_m, 0.05, 0.0, &s, SUPPLY_PA);
            let fd_a = (rates(ActuatorState {
                p_a_pa: p_a + d,
                ..state
            })
            .p_a - rates(ActuatorState {
                p_a_pa: p_a - d,
                ..state
            })
            .p_a)
                / (2.0 * d);
            let fd_b = (rates(ActuatorState {
                p_b_pa: p_b + d,
                ..state
            })
            .p_b - rates(ActuatorState {
                p_b_pa: p_b - d,
                ..state
            })
            .p_b)
                / (2.0 * d);
            let expected = fd_a.abs().max(fd_b.abs());
            let r = hyd.pressure_rate_1_s(0, Some(s_m), &state, SUPPLY_PA);
            println!(
                "cap {cap}, rod {rod}, stroke {s_m}, spool {spool}: {:.6e} 1/s, differences \
                 {fd_a:.6e} {fd_b:.6e}",
                r.rate_1_s
            );
            assert!(
                (r.rate_1_s / expected - 1.0).abs() < 1e-6,
                "{} vs {expected}",
                r.rate_1_s
            );
            let bound = hyd.pressure_rate_1_s(0, None, &state, SUPPLY_PA).rate_1_s;
            assert!(bound >= r.rate_1_s, "{bound} < {}", r.rate_1_s);
            if cap == rod {
                let sys = uniaxial(cap, rod);
                let h = HydraulicState {
                    p_a_pa: p_a,
                    p_b_pa: p_b,
                    spool,
                    spool_rate_1_s: 0.0,
                    accumulator_oil_m3: 0.0,
                    supply_pressure_pa: SUPPLY_PA,
                };
                let uni = sys.pressure_rate_1_s(&sys.constants(), s_m, &h);
                assert!(
                    (uni / r.rate_1_s - 1.0).abs() < 1e-12,
                    "{uni} vs {}",
                    r.rate_1_s
                );
            }
        }
    }
}
