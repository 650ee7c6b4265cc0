//! The loop's prediction-error fit ([`platen_ident::system::refine_loop`]).
//!
//! A round trip: records made by running a loop whose values the test sets (platen's own
//! closed loop, so the model's structure is exact), with noise added; the fit starts from
//! values 5–20 % off and must come back to the truth. The truth here is not independent of
//! the model (the independent check is `real_table_stand_ins` below, on records a numpy
//! reference made): what it checks is that the search, its parameters and their write-back
//! find the minimum the records define, not that the model is right.

use std::path::{Path, PathBuf};

use platen_ident::system::{
    identify_system, refine_loop, LoopValues, SystemIdentification, SystemRecord, SystemSettings,
};
use platen_integrate::{
    forward_closed_loop, LoopMethod, LoopRun, Motion, Sample, SampleSink, State,
};
use platen_model::{IdentifiedParams, Specimen, Storey};
use platen_system::{Actuator, Controller, ServoValve, Supply, TableSystem, TableSystemParts};

const RATE_HZ: f64 = 204.8;

/// A seeded uniform generator in `[-0.5, 0.5)`.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    /// About unit-variance Gaussian (sum of 12 uniforms).
    fn gauss(&mut self) -> f64 {
        (0..12).map(|_| self.next()).sum()
    }
}

/// The small table of `tests/data/real_table` (its truth.json), with a linear viscous law
/// (the loop's platen has no other when the equation error gives none) and damping in both
/// storeys.
fn truth() -> LoopValues {
    let parts = TableSystemParts {
        actuator: Actuator {
            count: 1,
            cap_area_m2: 0.002,
            rod_area_m2: 0.002,
            cap_volume_m3: 2.5e-4,
            rod_volume_m3: 2.5e-4,
            leakage_m3_s_per_pa: 1.2e-11,
        },
        servo_valve: ServoValve {
            count: 1,
            rated_flow_m3_s: 2.577e-3,
            rated_pressure_drop_pa: 7e6,
            natural_frequency_hz: 120.0,
            damping_ratio: 0.7,
            delay_s: 0.6e-3,
        },
        oil_bulk_modulus_pa: 1.4e9,
        supply_pressure_pa: 20.7e6,
        return_pressure_pa: 0.3e6,
        supply: Supply::Constant,
        controller: Controller {
            sample_rate_hz: RATE_HZ,
            displacement_gain_per_m: 14.3,
            integral_gain_per_m_s: 0.0,
            velocity_feedforward_s_per_m: 0.44,
            acceleration_feedforward_s2_per_m: 0.0,
            velocity_feedback_s_per_m: 0.0,
            acceleration_feedback_s2_per_m: 0.0,
            delta_p_gain_per_pa: 2.4e-9,
            delta_p_highpass_hz: 0.0,
        },
    };
    LoopValues {
        system: TableSystem::new(parts, 0.1).unwrap(),
        model: IdentifiedParams {
            effective_mass_kg: 400.0,
            stiffness_n_per_m: 0.0,
            coulomb_force_n: 260.0,
            viscous_coefficient: 600.0,
            viscous_exponent: 1.0,
            low_velocity_force_n: 0.0,
            low_velocity_decay_s_per_m: 0.0,
        },
        specimen: Some(
            Specimen::new(vec![
                Storey {
                    mass_kg: 320.0,
                    stiffness_n_per_m: 1.86e6,
                    damping_n_s_per_m: 330.0,
                },
                Storey {
                    mass_kg: 320.0,
                    stiffness_n_per_m: 1.86e6,
                    damping_n_s_per_m: 150.0,
                },
            ])
            .unwrap(),
        ),
    }
}

/// `values` with each of the plant's values scaled as the test's perturbed start (the
/// controller's gains are the drive regression's, which the prediction-error fit keeps).
fn perturbed(v: &LoopValues) -> LoopValues {
    let mut parts = v.system.into_parts();
    parts.servo_valve.rated_flow_m3_s *= 0.9;
    parts.servo_valve.delay_s *= 1.2;
    parts.servo_valve.natural_frequency_hz /= 1.2;
    parts.actuator.cap_volume_m3 *= 1.15;
    parts.actuator.rod_volume_m3 *= 1.15;
    let mut model = v.model;
    model.effective_mass_kg *= 1.15;
    model.coulomb_force_n *= 0.85;
    model.viscous_coefficient *= 1.2;
    let storeys: Vec<Storey> = v
        .specimen
        .as_ref()
        .unwrap()
        .storeys()
        .iter()
        .zip([(0.9, 1.12, 1.2), (1.1, 0.88, 0.8)])
        .map(|(s, (m, k, c))| Storey {
            mass_kg: s.mass_kg * m,
            stiffness_n_per_m: s.stiffness_n_per_m * k,
            damping_n_s_per_m: s.damping_n_s_per_m * c,
        })
        .collect();
    LoopValues {
        system: TableSystem::new(parts, 0.1).unwrap(),
        model,
        specimen: Some(Specimen::new(storeys).unwrap()),
    }
}

#[derive(Default)]
struct Collect {
    u: Vec<f64>,
    a: Vec<f64>,
    storeys: [Vec<f64>; 2],
    drive: Vec<f64>,
    dp: Vec<f64>,
}

impl SampleSink for Collect {
    fn accept(&mut self, s: &Sample) {
        self.u.push(s.u_m);
        self.a.push(s.a_m_s2);
        let sp = s.specimen.as_ref().unwrap();
        self.storeys[0].push(sp.a_m_s2[0]);
        self.storeys[1].push(sp.a_m_s2[1]);
        let sys = s.system.as_ref().unwrap();
        self.drive.push(sys.drive);
        self.dp.push(sys.delta_p_pa);
    }
}

/// A band-limited random command (sines 0.5–12 Hz, flat in acceleration, random phases),
/// at rest for its first and last second, `n` samples.
fn command(n: usize, rng: &mut Lcg) -> Vec<f64> {
    let t_end = n as f64 / RATE_HZ;
    let lines: Vec<(f64, f64)> = (0..60)
        .map(|k| {
            let f = 0.5 + 11.5 * k as f64 / 59.0;
            (f, std::f64::consts::TAU * rng.next())
        })
        .collect();
    (0..n)
        .map(|i| {
            let t = i as f64 / RATE_HZ;
            // A raised-cosine envelope from 1 s to t_end − 1 s.
            let ramp = |x: f64| {
                if x <= 0.0 {
                    0.0
                } else if x >= 1.0 {
                    1.0
                } else {
                    0.5 - 0.5 * (std::f64::consts::PI * x).cos()
                }
            };
            let env = ramp(t - 1.0) * ramp(t_end - 1.0 - t);
            let x: f64 = lines
                .iter()
                .map(|(f, ph)| (std::f64::consts::TAU * f * t + ph).sin() / (f * f))
                .sum();
            // Scaled for about 0.2 m/s² RMS of command acceleration.
            2.2e-4 * env * x
        })
        .collect()
}

/// A record of `truth` on a random command of `n` samples, with noise: 2 % of each
/// acceleration's RMS, 5 µm on the displacement, 5 kPa on Δp, the drive as sent.
fn record(truth: &LoopValues, n: usize, seed: u64) -> SystemRecord {
    let mut rng = Lcg(seed);
    let t_s: Vec<f64> = (0..n).map(|i| i as f64 / RATE_HZ).collect();
    let cmd = command(n, &mut rng);
    let motion = Motion::from_displacement(t_s.clone(), cmd.clone()).unwrap();
    let payload = truth.specimen.as_ref().map_or(0.0, Specimen::total_mass_kg);
    let steps = truth
        .system
        .default_steps_per_period(truth.model.effective_mass_kg + payload, 0.1);
    let run = LoopRun {
        system: &truth.system,
        specimen: truth.specimen.as_ref(),
        command: &motion,
        method: LoopMethod::Rk4 {
            steps_per_period: steps,
        },
        initial: State {
            u_m: cmd[0],
            v_m_s: 0.0,
        },
    };
    let mut c = Collect::default();
    forward_closed_loop(&truth.model.build().unwrap(), &run, n, &mut c).unwrap();
    let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
    let mut noisy =
        |x: &[f64], sd: f64| -> Vec<f64> { x.iter().map(|v| v + sd * rng.gauss()).collect() };
    let (ra, r1, r2) = (rms(&c.a), rms(&c.storeys[0]), rms(&c.storeys[1]));
    SystemRecord {
        name: format!("synthetic-{seed}"),
        t_s,
        command_u_m: cmd,
        u_m: noisy(&c.u, 5e-6),
        drive: Some(c.drive.clone()),
        delta_p_pa: Some(noisy(&c.dp, 5e3)),
        a_m_s2: Some(noisy(&c.a, 0.02 * ra)),
        cap_pressure_pa: None,
        rod_pressure_pa: None,
        storey_a_m_s2: vec![
            noisy(&c.storeys[0], 0.02 * r1),
            noisy(&c.storeys[1], 0.02 * r2),
        ],
    }
}

/// The values the test compares, by name.
fn values(v: &LoopValues) -> Vec<(&'static str, f64)> {
    let p = v.system.into_parts();
    let st = v.specimen.as_ref().unwrap().storeys();
    let lag = p.servo_valve.delay_s
        + 2.0 * p.servo_valve.damping_ratio
            / (std::f64::consts::TAU * p.servo_valve.natural_frequency_hz);
    vec![
        ("platen mass", v.model.effective_mass_kg),
        ("Coulomb force", v.model.coulomb_force_n),
        ("viscous coefficient", v.model.viscous_coefficient),
        ("storey 1 mass", st[0].mass_kg),
        ("storey 2 mass", st[1].mass_kg),
        ("storey 1 stiffness", st[0].stiffness_n_per_m),
        ("storey 2 stiffness", st[1].stiffness_n_per_m),
        ("storey 1 damping", st[0].damping_n_s_per_m),
        ("storey 2 damping", st[1].damping_n_s_per_m),
        ("rated flow", p.servo_valve.rated_flow_m3_s),
        ("valve lag", lag),
        ("chamber volume", p.actuator.cap_volume_m3),
    ]
}

/// From the plant's values 10–20 % off, the fit comes back to the loop that made the records
/// (measured: in 10 iterations, converged by the score test, each channel's NRMSE at the
/// noise's in-band 1.0–1.1 %, Δp's 2.2 %). Each value within its tolerance of the truth and
/// closer to it than its start: 2 % for the masses, stiffnesses, Coulomb force, flow and
/// volume (measured within 1.03 %: the 2 % noise on 2 × 1 600 samples gives standard errors
/// of 0.1–0.5 %), 5 % for the valve lag (measured 0.6 %: only `τ + 2ζ/ω_n` is seen), 10 % for
/// the storeys' damping (about 0.3 % of critical, measured within 1.8 %), 20 % for the
/// viscous coefficient (measured −14 %: at the records' speed, about 1 cm/s RMS, its force is
/// some 2 % of the Coulomb force's).
#[test]
fn a_perturbed_loop_is_refined_back_to_the_one_that_made_the_records() {
    let truth = truth();
    let records = vec![record(&truth, 1600, 1), record(&truth, 1600, 2)];
    let start = perturbed(&truth);
    let refined = refine_loop(&records, &[0, 1], &start).unwrap();
    let fit = &refined.fit;
    eprintln!("{fit:#?}");
    assert!(
        fit.cost_after < 0.1 * fit.cost_before,
        "{} → {}",
        fit.cost_before,
        fit.cost_after
    );
    let tolerance = |name: &str| {
        if name.contains("viscous") {
            0.2
        } else if name.contains("damping") {
            0.1
        } else if name.contains("lag") {
            0.05
        } else {
            0.02
        }
    };
    let (want, got, from) = (values(&truth), values(&refined.values), values(&start));
    let mut bad = 0;
    for (((name, t), (_, g)), (_, s)) in want.iter().zip(&got).zip(&from) {
        eprintln!(
            "{name}: {g:.6e} (truth {t:.6e}, {:+.3} %; start {:+.1} %)",
            100.0 * (g / t - 1.0),
            100.0 * (s / t - 1.0)
        );
        bad +=
            usize::from((g / t - 1.0).abs() >= tolerance(name) || (g - t).abs() >= (s - t).abs());
    }
    assert_eq!(bad, 0, "{bad} values off");
    for p in &fit.parameters {
        assert!(p.refined, "{} held: {:?}", p.key, refined.held);
    }
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/real_table")
        .join(name)
}

/// A stand-in record through its column map: times, mm → m, V → drive/10, bar → Pa, g →
/// m/s².
fn load(name: &str) -> SystemRecord {
    let text = std::fs::read_to_string(data(name)).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').map(str::trim).collect();
    let col = |h: &str| header.iter().position(|c| *c == h).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.trim().parse().unwrap()).collect())
        .collect();
    let take =
        |h: &str, scale: f64| -> Vec<f64> { rows.iter().map(|r| r[col(h)] * scale).collect() };
    let g = 9.80665;
    SystemRecord {
        name: name.into(),
        t_s: take("Time (s)", 1.0),
        command_u_m: take("Command (mm)", 1e-3),
        u_m: take("Actuator displacement (mm)", 1e-3),
        drive: Some(take("Voltage command (V)", 0.1)),
        delta_p_pa: Some(take("Delta P (bar)", 1e5)),
        a_m_s2: Some(take("Table acceleration (g)", g)),
        cap_pressure_pa: None,
        rod_pressure_pa: None,
        storey_a_m_s2: vec![
            take("Storey 1 acceleration (g)", g),
            take("Storey 2 acceleration (g)", g),
        ],
    }
}

fn truth_json() -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(data("truth.json")).unwrap()).unwrap()
}

fn identify(prediction_error: bool) -> SystemIdentification {
    let records: Vec<SystemRecord> = [
        "r01-wn.csv",
        "r02-eq.csv",
        "r03-wn.csv",
        "r04-eq.csv",
        "r05-wn.csv",
    ]
    .iter()
    .map(|n| load(n))
    .collect();
    let settings = SystemSettings {
        judge: true,
        prediction_error,
        ..SystemSettings::default()
    };
    identify_system(&records, &[true, true, true, true, false], &settings).unwrap()
}

/// The values compared with truth.json, as ratios to the actuator area where the records
/// show only those (the README's "ratios to the actuator area"), else as they are.
fn against_truth(id: &SystemIdentification) -> Vec<(&'static str, f64, f64)> {
    let t = truth_json();
    let r = &t["ratios_to_actuator_area"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let plant = id.plant.as_ref().unwrap();
    let area = plant.geometry.area_m2;
    let st = &plant.storeys;
    let g = id.gains.unwrap();
    let modes = &plant.specimen_modes;
    vec![
        (
            "platen mass / A",
            plant.model.unwrap().effective_mass_kg / area,
            f(&r["mass_kg_per_m2"]),
        ),
        (
            "storey 1 mass / A",
            st[0].mass_kg / area,
            f(&r["storey_masses_kg_per_m2"][0]),
        ),
        (
            "storey 2 mass / A",
            st[1].mass_kg / area,
            f(&r["storey_masses_kg_per_m2"][1]),
        ),
        (
            "storey 1 stiffness / A",
            st[0].stiffness_n_per_m / area,
            f(&r["storey_stiffness_n_per_m_per_m2"][0]),
        ),
        (
            "storey 2 stiffness / A",
            st[1].stiffness_n_per_m / area,
            f(&r["storey_stiffness_n_per_m_per_m2"][1]),
        ),
        ("mode 1, Hz", modes[0].frequency_hz, 7.5001),
        ("mode 2, Hz", modes[1].frequency_hz, 19.6351),
        (
            "K_p",
            g.displacement_gain_per_m,
            f(&t["controller"]["displacement_gain_per_m"]),
        ),
        (
            "K_vf",
            g.velocity_feedforward_s_per_m,
            f(&t["controller"]["velocity_feedforward_s_per_m"]),
        ),
        (
            "K_dp",
            g.delta_p_gain_per_pa,
            f(&t["controller"]["delta_p_gain_per_pa"]),
        ),
    ]
}

/// On the independent stand-ins (numpy): after the prediction-error fit the frame's masses and
/// stiffnesses (relative to the area) and its modes are within tolerances of truth.json, and
/// the held-out
/// record's table and storey accelerations are predicted better than before and better than
/// the black box.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "6 min unoptimised (two identifications, 30 Levenberg–Marquardt iterations), 30 s \
              optimised: cargo test --release -p platen-ident --test prediction_error"
)]
fn real_table_stand_ins_refined_closer_to_the_truth_and_the_held_out_record_predicted_better() {
    let before = identify(false);
    let after = identify(true);
    let fit = after.prediction_error.as_ref().unwrap();
    eprintln!("{fit:#?}");
    for ((name, b, t), (_, a, _)) in against_truth(&before).iter().zip(against_truth(&after)) {
        eprintln!(
            "{name}: {b:.5e} → {a:.5e} (truth {t:.5e}; {:+.2} % → {:+.2} %)",
            100.0 * (b / t - 1.0),
            100.0 * (a / t - 1.0)
        );
        // Within the tolerances of issue 51 after the fit: the modes within 1 % (measured
        // −0.05 and −0.01 %). The masses and stiffnesses relative to the area within 5 %:
        // accelerations show only ratios of forces, and the absolute scale (every mass and
        // stiffness together) rests on Δp alone, which the fit weighs as one channel among
        // four (measured +3.5 % on all four masses and +2.6/+3.6 % on the stiffnesses, the
        // modes unmoved). The equation error starts within both (+4.4 % on the platen).
        let tolerance = if name.starts_with("mode") {
            0.01
        } else if name.starts_with('K') {
            continue;
        } else {
            0.05
        };
        assert!(
            (a / t - 1.0).abs() < tolerance,
            "{name}: {a} is beyond {tolerance} of {t}"
        );
    }
    let held = |id: &SystemIdentification| {
        id.judgement
            .as_ref()
            .unwrap()
            .predictions
            .iter()
            .find(|p| !p.fitted)
            .unwrap()
            .clone()
    };
    let (b, a) = (held(&before), held(&after));
    eprintln!(
        "held out, table: {:.4} → {:.4} (black box {:.4})",
        b.model.acceleration_nrmse,
        a.model.acceleration_nrmse,
        a.black_box.as_ref().unwrap().acceleration_nrmse
    );
    assert!(a.model.acceleration_nrmse < b.model.acceleration_nrmse);
    assert!(a.model.acceleration_nrmse <= a.black_box.as_ref().unwrap().acceleration_nrmse);
    assert!(a.model.acceleration_nrmse <= a.perfect_tracking.acceleration_nrmse);
    for (k, (sa, sb)) in a
        .model
        .storey_acceleration_nrmse
        .iter()
        .zip(&b.model.storey_acceleration_nrmse)
        .enumerate()
    {
        let bb = a.black_box.as_ref().unwrap().storey_acceleration_nrmse[k];
        eprintln!(
            "held out, storey {}: {sb:.4} → {sa:.4} (black box {bb:.4})",
            k + 1
        );
        assert!(sa < sb);
        assert!(*sa < bb);
    }
}
