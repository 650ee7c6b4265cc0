//! The multi-axis platen's planar stick-slip forward, against closed forms and against the
//! uniaxial machine (whose exact stick-slip has its own independent references):
//!
//! * a straight slide (diagonal, no turning) decelerates at `μ·ΣN/m`, stops at
//!   `t* = m·v₀/(μ·ΣN)` and stays at exactly zero velocity;
//! * a force ramp along a diagonal breaks the platen away when it reaches `μ·ΣN` and moves it
//!   by `k·(t − t_b)³/(6m)` after;
//! * a torque breaks it away when it reaches the bearings' `Σ μ·N·r` about the friction
//!   centre (the limit surface's pure turn);
//! * with y, z, roll, pitch and yaw held and two x actuators, the run equals the uniaxial run
//!   of a Coulomb platen of the same mass, friction and stick included;
//! * the actuators' work equals kinetic and potential energy plus the friction's dissipation,
//!   with and without a specimen;
//! * a general linear specimen given as a shear frame's matrices, on that held table, equals
//!   the uniaxial machine's storeys run.

use nalgebra::DMatrix;
use nalgebra::{Matrix3, Unit, Vector3};
use platen_integrate::{
    forward_rk4, forward_rk4_specimen, forward_table, table_kinetic_energy_j,
    table_potential_energy_j, ActuatorForces, Dopri5Settings, ForceRecord, Method, Rk4, State,
    TableRun, Trajectory,
};
use platen_model::multi_axis::{
    Actuator, Bearing, BearingLoad, Coords, Dof, DofSet, LinearSpecimen, Mount, MultiAxisTable,
    Pad, RigidPlaten, Strut, TableParts,
};
use platen_model::{IdentifiedModel, IdentifiedParams, Specimen, Storey, STANDARD_GRAVITY_M_S2};

const MASS_KG: f64 = 50_000.0;
const MU: f64 = 0.01;

fn swivel(name: &str, base: [f64; 3], platen: [f64; 3]) -> Actuator {
    Actuator {
        name: name.into(),
        base_m: Vector3::from(base),
        mount: Mount::Swivel {
            platen_m: Vector3::from(platen),
        },
        cap_side_area_m2: 0.05,
        rod_side_area_m2: 0.03,
        chamber_volume_m3: 0.05,
        stroke_m: 0.5,
    }
}

/// A flat platen on four passive bearings at (±2, ±2, −1) m carrying its weight equally,
/// the centre of mass above their centre; `actuators` move it; `held` DOFs held.
fn table(actuators: Vec<Actuator>, held: &[Dof]) -> MultiAxisTable {
    let platen = RigidPlaten::new(
        MASS_KG,
        Matrix3::from_diagonal(&Vector3::new(2.0e5, 3.0e5, 4.0e5)),
        Vector3::new(0.0, 0.0, -0.5),
    )
    .unwrap();
    let n = MASS_KG * STANDARD_GRAVITY_M_S2 / 4.0;
    let bearings = [(2.0, 2.0), (2.0, -2.0), (-2.0, 2.0), (-2.0, -2.0)]
        .iter()
        .map(|&(x, y)| Bearing {
            platen_m: Vector3::new(x, y, -1.0),
            friction_coefficient: MU,
            load: BearingLoad::Constant(n),
        })
        .collect();
    MultiAxisTable::new(TableParts {
        platen,
        actuators,
        struts: Vec::new(),
        bearings,
        held: DofSet::of(held),
        oil_bulk_modulus_pa: 1.4e9,
    })
    .unwrap()
}

/// Two x actuators and two y actuators, all in the plane of the centre of mass, their bases
/// `base_m` from the platen's centre (their platen ends 3 m from it).
fn planar_table_of(base_m: f64) -> MultiAxisTable {
    table(
        vec![
            swivel("x1", [-base_m, 1.0, -0.5], [-3.0, 1.0, -0.5]),
            swivel("x2", [-base_m, -1.0, -0.5], [-3.0, -1.0, -0.5]),
            swivel("y1", [2.0, -base_m, -0.5], [2.0, -3.0, -0.5]),
            swivel("y2", [-2.0, -base_m, -0.5], [-2.0, -3.0, -0.5]),
        ],
        &[Dof::Z, Dof::Roll, Dof::Pitch],
    )
}

/// [`planar_table_of`] with 2 m actuators.
fn planar_table() -> MultiAxisTable {
    planar_table_of(5.0)
}

/// [`planar_table_of`] with actuators 10 km long, whose lines do not turn as the platen moves
/// (which the closed forms do not know).
fn long_table() -> MultiAxisTable {
    planar_table_of(1e4)
}

/// The bearings' Coulomb force `μ·ΣN`, N.
fn coulomb_n() -> f64 {
    MU * MASS_KG * STANDARD_GRAVITY_M_S2
}

fn grid(rate_hz: f64, duration_s: f64) -> Vec<f64> {
    let n = (duration_s * rate_hz).round() as usize;
    (0..=n).map(|i| i as f64 / rate_hz).collect()
}

fn rk4(k: u32) -> Method {
    Method::Rk4(Rk4::with_steps_per_sample(k).unwrap())
}

fn dopri5() -> Method {
    Method::Dopri5(Dopri5Settings::new(1e-10, 1e-12).unwrap())
}

fn col<'a>(run: &'a TableRun, name: &str) -> &'a [f64] {
    run.column(name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// A slide from `v₀` along 30° with no actuator force: `v = v₀ − (μ·ΣN/m)·t` until
/// `t* = m·v₀/(μ·ΣN)`, then exactly zero, at rest `v₀²/(2a)` from the start.
fn straight_slide(method: Method) {
    let t = planar_table();
    let time = grid(256.0, 4.0);
    let forces = ActuatorForces::new(time.clone(), vec![vec![0.0; time.len()]; 4]).unwrap();
    let (v0, angle) = (0.3, 30f64.to_radians());
    let dir = (angle.cos(), angle.sin());
    let rates = Coords::new(v0 * dir.0, v0 * dir.1, 0.0, 0.0, 0.0, 0.0);
    let run = forward_table(&t, None, &forces, method, Coords::zeros(), rates).unwrap();
    let a = coulomb_n() / MASS_KG;
    let t_stop = MASS_KG * v0 / coulomb_n();
    let reach = v0 * v0 / (2.0 * a);
    let (x, y, vx, vy, yaw) = (
        col(&run, "x_m"),
        col(&run, "y_m"),
        col(&run, "x_m_s"),
        col(&run, "y_m_s"),
        col(&run, "yaw_rad"),
    );
    let stuck = col(&run, "stuck");
    // Tolerances: the motion is quadratic in time, which RK4 and Dopri5 integrate exactly
    // but for rounding (1e-15 of 0.46 m over 800 steps) and the stop, located to a few ulps
    // of a step: 1e-12 m and 1e-12 m/s.
    for (i, &ti) in time.iter().enumerate() {
        let (s, speed) = if ti < t_stop {
            (v0 * ti - 0.5 * a * ti * ti, v0 - a * ti)
        } else {
            (reach, 0.0)
        };
        assert!(
            (x[i] - s * dir.0).abs() < 1e-12,
            "x at {ti}: {} vs {}",
            x[i],
            s * dir.0
        );
        assert!((y[i] - s * dir.1).abs() < 1e-12, "y at {ti}");
        assert!((vx[i] - speed * dir.0).abs() < 1e-12, "vx at {ti}");
        assert!(yaw[i].abs() < 1e-14, "no turning: yaw {} at {ti}", yaw[i]);
        if ti >= t_stop {
            // At rest exactly: no creep, no chatter.
            assert_eq!((vx[i], vy[i], stuck[i]), (0.0, 0.0, 1.0), "at {ti}");
        } else {
            assert_eq!(stuck[i], 0.0, "still sliding at {ti}");
        }
    }
}

#[test]
fn a_straight_slide_stops_at_its_closed_form_time_and_stays_stopped_rk4() {
    straight_slide(rk4(1));
}

#[test]
fn a_straight_slide_stops_at_its_closed_form_time_and_stays_stopped_dopri5() {
    straight_slide(dopri5());
}

/// A force ramp `k·t` along a diagonal (split over the x and y actuators) from rest: stuck
/// until `t_b = μ·ΣN/k`, then `s = k·(t − t_b)³/(6m)` along the diagonal.
#[test]
fn a_ramp_breaks_the_platen_away_at_the_friction_force_along_its_direction() {
    let t = long_table();
    let time = grid(128.0, 0.6);
    let k = 20_000.0; // N/s
    let angle = 40f64.to_radians();
    let (fx, fy) = (k * angle.cos(), k * angle.sin());
    // Each pair shares its component; the y actuators push towards +y, the x ones +x.
    let record = |c: f64| time.iter().map(|&ti| 0.5 * c * ti).collect::<Vec<_>>();
    let forces = ActuatorForces::new(
        time.clone(),
        vec![record(fx), record(fx), record(fy), record(fy)],
    )
    .unwrap();
    for method in [rk4(2), dopri5()] {
        let run =
            forward_table(&t, None, &forces, method, Coords::zeros(), Coords::zeros()).unwrap();
        let t_b = coulomb_n() / k;
        let (x, y, stuck) = (col(&run, "x_m"), col(&run, "y_m"), col(&run, "stuck"));
        // Tolerance: the motion is cubic in time after the breakaway, which is located to a
        // few ulps; the actuators' lines still turn by 1e-7 rad (2 mm over 10 km), 1e-10 m
        // on the 2 mm slide; 1e-9 m.
        for (i, &ti) in time.iter().enumerate() {
            let s = if ti > t_b {
                k * (ti - t_b).powi(3) / (6.0 * MASS_KG)
            } else {
                0.0
            };
            assert!((x[i] - s * angle.cos()).abs() < 1e-9, "x at {ti}: {}", x[i]);
            assert!((y[i] - s * angle.sin()).abs() < 1e-9, "y at {ti}: {}", y[i]);
            if ti <= t_b {
                assert_eq!((x[i], y[i], stuck[i]), (0.0, 0.0, 1.0), "stuck at {ti}");
            } else {
                assert_eq!(stuck[i], 0.0, "sliding at {ti}");
            }
        }
    }
}

/// A torque ramp from the two y actuators pushing opposite ways 4 m apart: the platen turns
/// when the torque reaches the bearings' `Σ μ·N·r` (each bearing 2√2 m from the friction
/// centre: the limit surface's pure turn), not before, turns as the closed form says, and
/// does not translate.
#[test]
fn a_torque_breaks_the_platen_away_at_the_bearings_moment() {
    let t = long_table();
    let time = grid(512.0, 0.5);
    let k = 100_000.0; // N·m/s
    let push = time.iter().map(|&ti| k * ti / 4.0).collect::<Vec<_>>();
    let pull = push.iter().map(|f| -f).collect::<Vec<_>>();
    let zero = vec![0.0; time.len()];
    // y1 at x = +2 pushes +y, y2 at x = −2 pulls: a torque k·t about z.
    let forces = ActuatorForces::new(time.clone(), vec![zero.clone(), zero, push, pull]).unwrap();
    let run = forward_table(&t, None, &forces, rk4(4), Coords::zeros(), Coords::zeros()).unwrap();
    let moment = coulomb_n() * 2.0 * 2f64.sqrt();
    let t_b = moment / k;
    let (yaw, x, y) = (col(&run, "yaw_rad"), col(&run, "x_m"), col(&run, "y_m"));
    let first = yaw.iter().position(|&v| v != 0.0).expect("it turns");
    // The first sample that moved is the first after t_b (one sample: 2 ms).
    assert!(
        time[first] > t_b && time[first - 1] <= t_b,
        "turned at {}",
        time[first]
    );
    for i in 0..time.len() {
        // After the breakaway the bearings resist with exactly `Σ μ·N·r` (every contact
        // slides tangentially about the centre): ψ = k·(t − t_b)³/(6·I_zz). Tolerance: the
        // actuators' arm shrinks by cos ψ (4e-6 at 3 mrad) and their lines turn by 2 m·ψ
        // over 10 km.
        let psi = if time[i] > t_b {
            k * (time[i] - t_b).powi(3) / (6.0 * 4.0e5)
        } else {
            0.0
        };
        assert!(
            (yaw[i] - psi).abs() <= 1e-5 * psi + 1e-14,
            "yaw at {}: {} vs {psi}",
            time[i],
            yaw[i]
        );
        assert!(
            x[i].abs() < 1e-10 && y[i].abs() < 1e-10,
            "no slide at {}: {} {} yaw {}",
            time[i],
            x[i],
            y[i],
            yaw[i]
        );
    }
}

/// A Coulomb platen: the uniaxial model of the same mass and friction, nothing else.
fn coulomb_platen() -> IdentifiedModel {
    IdentifiedParams {
        effective_mass_kg: MASS_KG,
        stiffness_n_per_m: 0.0,
        coulomb_force_n: coulomb_n(),
        viscous_coefficient: 0.0,
        viscous_exponent: 0.5,
        low_velocity_force_n: 0.0,
        low_velocity_decay_s_per_m: 0.0,
    }
    .build()
    .unwrap()
}

/// The uniaxial run of [`coulomb_platen`] under `record`.
fn uniaxial(record: &ForceRecord) -> Trajectory {
    let mut out = Trajectory::with_capacity(record.len());
    forward_rk4(
        &coulomb_platen(),
        record,
        Rk4::with_steps_per_sample(2).unwrap(),
        State::default(),
        record.len(),
        &mut out,
    )
    .unwrap();
    out
}

/// The table held but in x, on two x actuators.
fn x_table() -> MultiAxisTable {
    table(
        vec![
            swivel("x1", [-5.0, 1.0, -0.5], [-3.0, 1.0, -0.5]),
            swivel("x2", [-5.0, -1.0, -0.5], [-3.0, -1.0, -0.5]),
        ],
        &[Dof::Y, Dof::Z, Dof::Roll, Dof::Pitch, Dof::Yaw],
    )
}

/// Two tones whose sum dwells below the friction force (stick intervals, breakaways,
/// reversals), 8 s at 256 Hz: the total and each x actuator's half.
fn two_tones() -> (Vec<f64>, Vec<f64>, ActuatorForces) {
    let time = grid(256.0, 8.0);
    let total: Vec<f64> = time
        .iter()
        .map(|&ti| {
            let w = 2.0 * std::f64::consts::PI * ti;
            9_000.0 * (0.5 * w).sin() + 3_000.0 * (1.7 * w).sin()
        })
        .collect();
    let half: Vec<f64> = total.iter().map(|f| 0.5 * f).collect();
    let forces = ActuatorForces::new(time.clone(), vec![half.clone(), half]).unwrap();
    (time, total, forces)
}

#[test]
fn with_y_and_yaw_held_it_is_the_uniaxial_exact_stick_slip() {
    let t = x_table();
    let (time, total, forces) = two_tones();
    let run = forward_table(&t, None, &forces, rk4(2), Coords::zeros(), Coords::zeros()).unwrap();
    let reference = uniaxial(&ForceRecord::new(time.clone(), total).unwrap());
    let (x, vx, stuck) = (col(&run, "x_m"), col(&run, "x_m_s"), col(&run, "stuck"));
    let stuck_samples = stuck.iter().filter(|&&s| s == 1.0).count();
    assert!(
        stuck_samples > 100,
        "the case sticks ({stuck_samples} samples)"
    );
    let mut worst: f64 = 0.0;
    for i in 0..time.len() {
        worst = worst.max((x[i] - reference.u_m[i]).abs());
        assert!(
            (vx[i] - reference.v_m_s[i]).abs() < 1e-9,
            "v at {}",
            time[i]
        );
        if stuck[i] == 1.0 {
            assert_eq!(vx[i], 0.0, "at rest exactly at {}", time[i]);
        }
    }
    eprintln!("uniaxial: {worst:e} m");
    // Tolerance: 1e-9 m (the issue's); the two machines locate the same events each to a
    // few ulps of a step.
    assert!(worst < 1e-9, "{worst} m");
}

/// A platen free in all six DOFs on four horizontal actuators and three vertical bearing
/// actuators (pads with friction), held down by two gas struts.
fn six_dof_table() -> MultiAxisTable {
    six_dof_table_holding(&[])
}

/// [`six_dof_table`] with the `held` DOFs held.
fn six_dof_table_holding(held: &[Dof]) -> MultiAxisTable {
    let platen = RigidPlaten::new(
        MASS_KG,
        Matrix3::from_diagonal(&Vector3::new(2.0e5, 3.0e5, 4.0e5)),
        Vector3::new(0.0, 0.0, -0.5),
    )
    .unwrap();
    let pad = |name: &str, x: f64, y: f64| Actuator {
        name: name.into(),
        base_m: Vector3::new(x, y, -3.0),
        mount: Mount::Pad(Pad {
            axis: Unit::new_normalize(Vector3::z()),
            contact_m: Vector3::new(x, y, -1.0),
            friction_coefficient: 0.02,
        }),
        ..swivel(name, [0.0; 3], [1.0; 3])
    };
    let strut = |name: &str, x: f64, y: f64| Strut {
        name: name.into(),
        base_m: Vector3::new(x, y, -4.0),
        platen_m: Vector3::new(x, y, -1.0),
        area_m2: 0.01,
        pressure_pa: 5.0e6,
        gas_volume_m3: 0.05,
        polytropic_exponent: 1.4,
    };
    MultiAxisTable::new(TableParts {
        platen,
        actuators: vec![
            swivel("x1", [-5.0, 1.0, -0.5], [-3.0, 1.0, -0.5]),
            swivel("x2", [-5.0, -1.0, -0.5], [-3.0, -1.0, -0.5]),
            swivel("y1", [2.0, -5.0, -0.5], [2.0, -3.0, -0.5]),
            swivel("y2", [-2.0, -5.0, -0.5], [-2.0, -3.0, -0.5]),
            pad("v1", 2.0, 2.0),
            pad("v2", 2.0, -2.0),
            pad("v3", -2.0, 0.0),
        ],
        struts: vec![strut("s1", 0.0, 1.0), strut("s2", 0.0, -1.0)],
        bearings: Vec::new(),
        held: DofSet::of(held),
        oil_bulk_modulus_pa: 1.4e9,
    })
    .unwrap()
}

/// Forces that carry the platen's weight, the struts' pull and `extra_weight_n` over the
/// pads and shake it in every direction, 4 s at 256 Hz.
fn six_dof_forces(extra_weight_n: f64) -> ActuatorForces {
    let time = grid(256.0, 4.0);
    // The static hold at neutral: weight plus the struts' pull over the three pads, in
    // proportion to their share of the weight about the centre of mass (x: 2, 2, −2 → the
    // third carries half).
    let hold = MASS_KG * STANDARD_GRAVITY_M_S2 + 2.0 * 5.0e6 * 0.01 + extra_weight_n;
    let shares = [0.25, 0.25, 0.5];
    let wave = |a: f64, f: f64, ti: f64| a * (2.0 * std::f64::consts::PI * f * ti).sin();
    let mut records: Vec<Vec<f64>> = Vec::new();
    for (a, f) in [
        (12_000.0, 1.0),
        (9_000.0, 1.0),
        (10_000.0, 0.7),
        (-4_000.0, 0.7),
    ] {
        records.push(time.iter().map(|&ti| wave(a, f, ti)).collect());
    }
    for (s, f) in shares.iter().zip([2.0, 2.5, 3.0]) {
        records.push(
            time.iter()
                .map(|&ti| s * hold + wave(2_000.0, f, ti))
                .collect(),
        );
    }
    ActuatorForces::new(time, records).unwrap()
}

/// The LHPOST6-like layout with friction on its pads and hold-down struts, free in all six
/// DOFs, under forces that carry its weight and shake it: actuator work = kinetic + gravity
/// and gas energy + friction's dissipation.
#[test]
fn the_actuators_work_is_the_energy_plus_the_friction_dissipation() {
    let t = six_dof_table();
    let forces = six_dof_forces(0.0);
    let time = forces.t_s().to_vec();
    let run = forward_table(&t, None, &forces, rk4(4), Coords::zeros(), Coords::zeros()).unwrap();
    let last = time.len() - 1;
    let q = Coords::from_fn(|k, _| col(&run, pose_name(k))[last]);
    let qd = Coords::from_fn(|k, _| col(&run, &format!("{}_s", pose_name(k)))[last]);
    let work = col(&run, "actuator_work_j")[last];
    let lost = col(&run, "dissipated_j")[last];
    let stored = table_kinetic_energy_j(&t, &q, &qd) + table_potential_energy_j(&t, &q);
    let stuck = col(&run, "stuck");
    assert!(stuck.contains(&1.0) && stuck.contains(&0.0));
    assert!(lost > 0.0, "friction dissipates: {lost} J");
    eprintln!("energy: {:e} of the work", (work - stored - lost) / work);
    // Tolerance: measured 7.3e-8 of the work (RK4 at 1/1024 s: the friction's kinks are
    // located at its events, but its direction turns fast near rest); 3e-7.
    assert!(
        (work - stored - lost).abs() < 3e-7 * work.abs(),
        "work {work} J, stored {stored} J, dissipated {lost} J"
    );
}

fn pose_name(k: usize) -> &'static str {
    ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"][k]
}

/// Two storeys along x as a general linear specimen, its shear frame's matrices written out
/// here (not through the storeys' own builder), on the table held but in x: the platen and
/// the base shear equal the uniaxial machine's storeys run, friction and stick included.
#[test]
fn a_general_specimen_of_a_shear_frame_is_the_storeys_run() {
    let (k1, k2, c1, c2, m1, m2) = (4e6, 3e6, 2e4, 1.5e4, 20e3, 15e3);
    let matrix = |a: [f64; 4]| DMatrix::from_row_slice(2, 2, &a);
    let mut influence = DMatrix::zeros(2, 6);
    influence[(0, 0)] = 1.0;
    influence[(1, 0)] = 1.0;
    let general = LinearSpecimen::new(
        matrix([m1, 0.0, 0.0, m2]),
        matrix([k1 + k2, -k2, -k2, k2]),
        matrix([c1 + c2, -c2, -c2, c2]),
        influence,
    )
    .unwrap();
    let storeys = Specimen::new(vec![
        Storey {
            mass_kg: m1,
            stiffness_n_per_m: k1,
            damping_n_s_per_m: c1,
        },
        Storey {
            mass_kg: m2,
            stiffness_n_per_m: k2,
            damping_n_s_per_m: c2,
        },
    ])
    .unwrap();
    let t = x_table();
    let (time, total, forces) = two_tones();
    let run = forward_table(
        &t,
        Some(&general),
        &forces,
        rk4(2),
        Coords::zeros(),
        Coords::zeros(),
    )
    .unwrap();
    let record = ForceRecord::new(time.clone(), total).unwrap();
    let mut reference = Trajectory::with_capacity(record.len());
    forward_rk4_specimen(
        &coulomb_platen(),
        &storeys,
        &record,
        Rk4::with_steps_per_sample(2).unwrap(),
        State::default(),
        record.len(),
        &mut reference,
    )
    .unwrap();
    let shear = &reference.specimen.as_ref().unwrap().base_shear_n;
    let top = &reference.specimen.as_ref().unwrap().u_m[1];
    let (x, base, z2) = (
        col(&run, "x_m"),
        col(&run, "base_force_x_n"),
        col(&run, "specimen2_z"),
    );
    let stuck = col(&run, "stuck");
    assert!(
        stuck.iter().filter(|&&s| s == 1.0).count() > 50,
        "the case sticks"
    );
    let (mut dx, mut dz, mut db): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for i in 0..time.len() {
        dx = dx.max((x[i] - reference.u_m[i]).abs());
        dz = dz.max((z2[i] - top[i]).abs());
        db = db.max((base[i] - shear[i]).abs());
    }
    // Tolerances: 1e-9 m (the issue's) on the platen and the top storey; the base shear to
    // the same share of its 10 kN scale (1e-9 m of a 7 MN/m frame).
    eprintln!("storeys: platen {dx:e} m, top storey {dz:e} m, base shear {db:e} N");
    assert!(dx < 1e-9 && dz < 1e-9, "{dx} m, {dz} m");
    assert!(db < 1e-2, "{db} N");
}

/// The six-DOF table of the energy test with a specimen that sways along x and bounces
/// along z (translations only, so its absolute displacement is `z + Γ·t` exactly): the
/// actuators' work equals the platen's and the specimen's kinetic, elastic and gravity
/// energy plus the friction's and the dampers' dissipation.
#[test]
fn the_energy_balances_with_a_specimen() {
    let t = six_dof_table();
    let mut influence = DMatrix::zeros(2, 6);
    influence[(0, 0)] = 1.0;
    influence[(1, 2)] = 1.0;
    let (mass, stiffness, damping) = (
        DMatrix::from_row_slice(2, 2, &[8e3, 0.0, 0.0, 6e3]),
        DMatrix::from_row_slice(2, 2, &[3e6, 0.0, 0.0, 5e6]),
        DMatrix::from_row_slice(2, 2, &[1e4, 0.0, 0.0, 2e4]),
    );
    let s =
        LinearSpecimen::new(mass.clone(), stiffness.clone(), damping, influence.clone()).unwrap();
    let forces = six_dof_forces(6e3 * STANDARD_GRAVITY_M_S2);
    let run = forward_table(
        &t,
        Some(&s),
        &forces,
        rk4(4),
        Coords::zeros(),
        Coords::zeros(),
    )
    .unwrap();
    let energy = |i: usize| {
        let q = Coords::from_fn(|k, _| col(&run, pose_name(k))[i]);
        let qd = Coords::from_fn(|k, _| col(&run, &format!("{}_s", pose_name(k)))[i]);
        let z = nalgebra::DVector::from_fn(2, |j, _| col(&run, &format!("specimen{}_z", j + 1))[i]);
        let zd =
            nalgebra::DVector::from_fn(2, |j, _| col(&run, &format!("specimen{}_zdot", j + 1))[i]);
        // Translations only: the twist's translation part is q̇'s.
        let twist = nalgebra::DVector::from_fn(6, |k, _| if k < 3 { qd[k] } else { 0.0 });
        let shift = nalgebra::DVector::from_fn(6, |k, _| if k < 3 { q[k] } else { 0.0 });
        let gravity =
            nalgebra::DVector::from_fn(6, |k, _| if k == 2 { -STANDARD_GRAVITY_M_S2 } else { 0.0 });
        let u = &zd + &influence * &twist;
        let absolute = &z + &influence * &shift;
        let specimen = 0.5 * u.dot(&(&mass * &u)) + 0.5 * z.dot(&(&stiffness * &z))
            - absolute.dot(&(&mass * (&influence * &gravity)));
        table_kinetic_energy_j(&t, &q, &qd)
            + table_potential_energy_j(&t, &q)
            + specimen
            + col(&run, "dissipated_j")[i]
            + col(&run, "specimen_damping_j")[i]
    };
    let last = col(&run, "t_s").len() - 1;
    let work = col(&run, "actuator_work_j")[last];
    let change = energy(last) - energy(0);
    assert!(col(&run, "specimen_damping_j")[last] > 0.0);
    eprintln!(
        "energy with a specimen: {:e} of the work",
        (work - change) / work
    );
    // Tolerance: as without a specimen (measured 3.6e-8 here); 3e-7.
    assert!(
        (work - change).abs() < 3e-7 * work.abs(),
        "work {work} J, energy change {change} J"
    );
}

/// Pads whose actuators pull press nothing: the platen (z, roll and pitch held) rests on them
/// held by nothing, and a push along −x (against the gauge's default direction) that starts
/// then slides it free of friction, without a stall; pressed again, with the push gone, it
/// sticks.
#[test]
fn a_platen_on_pads_that_press_nothing_slides_free() {
    let t = six_dof_table_holding(&[Dof::Z, Dof::Roll, Dof::Pitch]);
    let time = grid(256.0, 1.0);
    let weight = MASS_KG * STANDARD_GRAVITY_M_S2 + 2.0 * 5.0e6 * 0.01;
    // The pads pull from 0.3 s to 0.5 s; the x actuators pull 5 kN from 0.35 s to 0.5 s.
    let lifted = |ti: f64| (0.3..0.5).contains(&ti);
    let mut records: Vec<Vec<f64>> = (0..4)
        .map(|k| {
            time.iter()
                .map(|&ti| {
                    if k < 2 && (0.35..0.5).contains(&ti) {
                        -2_500.0
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    for s in [0.25, 0.25, 0.5] {
        records.push(
            time.iter()
                .map(|&ti| if lifted(ti) { -1_000.0 } else { s * weight })
                .collect(),
        );
    }
    let forces = ActuatorForces::new(time.clone(), records).unwrap();
    let run = forward_table(&t, None, &forces, rk4(4), Coords::zeros(), Coords::zeros()).unwrap();
    let (x, stuck, lost) = (
        col(&run, "x_m"),
        col(&run, "stuck"),
        col(&run, "dissipated_j"),
    );
    let at = |ts: f64| time.iter().position(|&ti| ti >= ts).unwrap();
    // Lifted, nothing pushing: at rest.
    assert_eq!((x[at(0.34)], stuck[at(0.34)]), (0.0, 1.0));
    // Pushed, pressing nothing: it slides, and the friction takes no work.
    assert!(
        x[at(0.45)] < 0.0 && stuck[at(0.45)] == 0.0,
        "{}",
        x[at(0.45)]
    );
    assert_eq!(lost[at(0.45)], 0.0);
    // Pressed again, the push gone: friction stops it, and it stays.
    let last = time.len() - 1;
    assert_eq!(stuck[last], 1.0);
    assert_eq!(x[last], x[last - 1]);
    assert!(lost[last] > 0.0);
}
