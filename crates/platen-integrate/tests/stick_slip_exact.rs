//! Exact stick-slip where it is hardest, against references computed independently with SciPy
//! by `tools/reference/stick_slip_cases.py` (see `tests/data/reference/README.md`), on models
//! whose parameters are not the paper's:
//!
//! * **creep**: a constant force `F_s + δ` from rest, δ from 0 to 100 N. The `|v|^α` law makes
//!   the start singular and the creep stiff; an explicit step used to stall or chatter here.
//! * **swing**: a ±X force swing across one sample from slow slip that reverses the platen
//!   twice inside that sample.
//! * **raw**: an unfiltered recorded-like force (slow small sine, 246 Hz valve tone, noise)
//!   with many stick intervals shorter than a sample.
//!
//! Plus a property test over random piecewise-linear forces near the threshold.

use std::collections::BTreeMap;
use std::path::PathBuf;

use platen_integrate::{
    forward_dopri5, forward_rk4, Dopri5Settings, ForceRecord, Rk4, RunStats, Sample, SampleSink,
    State, Trajectory,
};
use platen_model::{IdentifiedModel, IdentifiedParams, PlatenModel};
use proptest::prelude::*;

fn data_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/reference")
        .join(name)
}

/// Reads a CSV with a header into rows of cells (test helper, not the product reader).
fn read_rows(name: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(data_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.trim().to_string()).collect())
        .collect();
    (header, rows)
}

/// The numeric columns of a CSV.
fn read_columns(name: &str) -> Vec<Vec<f64>> {
    let (header, rows) = read_rows(name);
    let mut cols = vec![Vec::new(); header.len()];
    for row in rows {
        for (c, cell) in row.iter().enumerate() {
            cols[c].push(cell.parse::<f64>().expect("number"));
        }
    }
    cols
}

/// The two reference models (`tools/reference/stick_slip_cases.py`, `MODELS`).
fn model(name: &str) -> IdentifiedModel {
    let p = match name {
        "a07" => IdentifiedParams {
            effective_mass_kg: 95e3,
            stiffness_n_per_m: 2.1e6,
            coulomb_force_n: 18e3,
            viscous_coefficient: 30e3,
            viscous_exponent: 0.7,
            low_velocity_force_n: 8e3,
            low_velocity_decay_s_per_m: 50.0,
        },
        "a05" => IdentifiedParams {
            effective_mass_kg: 120e3,
            stiffness_n_per_m: 1.5e6,
            coulomb_force_n: 20e3,
            viscous_coefficient: 40e3,
            viscous_exponent: 0.5,
            low_velocity_force_n: 10e3,
            low_velocity_decay_s_per_m: 60.0,
        },
        other => panic!("unknown model {other}"),
    };
    p.build().unwrap()
}

/// Which samples were marked stuck (the trajectory does not keep the flag).
#[derive(Default)]
struct Stuck(Vec<bool>);

impl SampleSink for Stuck {
    fn accept(&mut self, sample: &Sample) {
        self.0.push(sample.stuck);
    }
}

#[derive(Debug, Clone, Copy)]
enum Integrator {
    Rk4,
    Dopri5,
}

fn forward<M: PlatenModel>(
    model: &M,
    record: &ForceRecord,
    integrator: Integrator,
) -> (Trajectory, RunStats) {
    let (out, _, stats) = forward_flagged(model, record, integrator);
    (out, stats)
}

fn forward_flagged<M: PlatenModel>(
    model: &M,
    record: &ForceRecord,
    integrator: Integrator,
) -> (Trajectory, Vec<bool>, RunStats) {
    let mut sink = (Trajectory::with_capacity(record.len()), Stuck::default());
    let out = &mut sink;
    let stats = match integrator {
        Integrator::Rk4 => forward_rk4(
            model,
            record,
            Rk4::with_steps_per_sample(1).unwrap(),
            State::default(),
            record.len(),
            out,
        ),
        Integrator::Dopri5 => forward_dopri5(
            model,
            record,
            Dopri5Settings::new(1e-10, 1e-13).unwrap(),
            State::default(),
            record.len(),
            out,
        ),
    }
    .unwrap_or_else(|e| panic!("{integrator:?}: {e}"));
    (sink.0, sink.1 .0, stats)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Stick intervals of a run: one per stop, plus the initial one if it starts stuck.
fn stick_intervals(stuck: &[bool], stats: &RunStats) -> u64 {
    stats.stick_events + u64::from(stuck[0])
}

/// A constant `F_s + δ` from rest for 2 s at 1024 Hz, δ ∈ {0, 1 ulp, 1e-9, 1e-6, 1e-3, 1,
/// 100} N, two laws (α = 0.7 and 0.5): both integrators finish, never count a reversal, never
/// move against the force, and match the Radau creep reference within 1e-9 m (the issue's
/// bar: for δ ≤ 1e-3 N the creep itself is below 1e-10 m; for 1 and 100 N it is 1e-9 to 1e-4 m,
/// where the quasi-static creep error bound `h·w_*` is about 2e-11 m).
#[test]
fn a_force_barely_above_the_threshold_creeps_without_stalling_or_chattering() {
    let (_, rows) = read_rows("creep_reference.csv");
    // (model, δ) → (force, [(t, u)]).
    type Marks = (f64, Vec<(f64, f64)>);
    let mut cases: BTreeMap<(String, String), Marks> = BTreeMap::new();
    for row in rows {
        let key = (row[0].clone(), row[1].clone());
        let force: f64 = row[2].parse().unwrap();
        let (t, u): (f64, f64) = (row[3].parse().unwrap(), row[4].parse().unwrap());
        cases
            .entry(key)
            .or_insert((force, Vec::new()))
            .1
            .push((t, u));
    }
    assert_eq!(cases.len(), 14, "two models × seven δ");
    for ((name, delta), (force, marks)) in &cases {
        let m = model(name);
        let fs = m.static_threshold_n(0.0);
        assert!(*force >= fs, "{name} {delta}: {force} below {fs}");
        let record = ForceRecord::from_rate(1024.0, vec![*force; 2049]).unwrap();
        for integrator in [Integrator::Rk4, Integrator::Dopri5] {
            let (out, stats) = forward(&m, &record, integrator);
            let what = format!("{name} δ={delta} {integrator:?}");
            assert_eq!(stats.reversals, 0, "{what}: {stats:?}");
            assert!(stats.breakaways <= 1, "{what}: {stats:?}");
            assert!(out.u_m.iter().all(|&u| u >= 0.0), "{what}: moved backwards");
            assert!(out.u_m.iter().all(|u| u.is_finite()));
            let mut worst = 0.0f64;
            for &(t, u_ref) in marks {
                let i = (t * 1024.0).round() as usize;
                worst = worst.max((out.u_m[i] - u_ref).abs());
            }
            eprintln!(
                "{what}: u(2 s) = {:.6e} m, max|Δu| = {worst:.2e} m",
                out.u_m[2048]
            );
            assert!(worst <= 1e-9, "{what}: max |Δu| = {worst:e} m");
            if *force == fs {
                assert_eq!(stats.breakaways, 0, "{what}: the threshold itself holds");
                assert!(out.u_m.iter().all(|&u| u == 0.0));
            }
        }
    }
}

/// A ±X swing across one sample from slow slip, X = 150 kN, 400 kN, 1 MN, reversing the
/// platen twice inside that sample (checked on the reference's own event list): RK4 at the
/// sample rate within 1e-8 m of the DOP853 reference everywhere (its error elsewhere on
/// these records is ~1e-9 m, and missing the double reversal cost 3e-7 to 1e-5 m), with the
/// same number of `v = 0` events.
#[test]
fn two_reversals_inside_one_step_are_both_located() {
    let (_, rows) = read_rows("swing_events.csv");
    assert!(rows.len() >= 3, "{rows:?}");
    let m = model("a07");
    for row in rows {
        let name = &row[0];
        let inside: u64 = row[3].parse().unwrap();
        let total: u64 = row[4].parse().unwrap();
        assert!(
            inside >= 2,
            "{name}: the reference has {inside} events in the swing"
        );
        let force = read_columns(&format!("{name}_force.csv"));
        let reference = read_columns(&format!("{name}_reference.csv"));
        let record = ForceRecord::new(force[0].clone(), force[1].clone()).unwrap();
        for integrator in [Integrator::Rk4, Integrator::Dopri5] {
            let (out, stats) = forward(&m, &record, integrator);
            let du = max_abs_diff(&out.u_m, &reference[1]);
            let dv = max_abs_diff(&out.v_m_s, &reference[2]);
            eprintln!("{name} {integrator:?}: max|Δu| = {du:.2e} m, |Δv| = {dv:.2e}, {stats:?}");
            assert_eq!(
                stats.stick_events + stats.reversals,
                total,
                "{name} {integrator:?}"
            );
            let bar = match integrator {
                Integrator::Rk4 => 1e-8,
                Integrator::Dopri5 => 1e-9,
            };
            assert!(du <= bar, "{name} {integrator:?}: max |Δu| = {du:e} m");
        }
    }
}

/// The unfiltered recorded-like force: RK4 at the sample rate within 1e-8 m and Dopri5 within
/// 1e-9 m of the reference, with exactly the reference's number of stick intervals (many of
/// them shorter than a sample).
#[test]
fn a_raw_recorded_force_with_sub_sample_stick_phases_is_followed_exactly() {
    let force = read_columns("raw_force.csv");
    let reference = read_columns("raw_reference.csv");
    let sticks = read_rows("raw_sticks.csv").1;
    let dt = 1.0 / 1024.0;
    let short = sticks
        .iter()
        .filter(|r| !r[1].is_empty())
        .filter(|r| r[1].parse::<f64>().unwrap() - r[0].parse::<f64>().unwrap() < dt)
        .count();
    assert!(
        short >= 10,
        "the record holds {short} sub-sample stick phases"
    );
    let m = model("a07");
    let record = ForceRecord::new(force[0].clone(), force[1].clone()).unwrap();
    for (integrator, bar) in [(Integrator::Rk4, 1e-8), (Integrator::Dopri5, 1e-9)] {
        let (out, stuck, stats) = forward_flagged(&m, &record, integrator);
        let du = max_abs_diff(&out.u_m, &reference[1]);
        let found = stick_intervals(&stuck, &stats);
        eprintln!(
            "raw {integrator:?}: max|Δu| = {du:.2e} m, {found} stick intervals \
             (reference {}, {short} shorter than a sample), {stats:?}",
            sticks.len()
        );
        assert_eq!(found, sticks.len() as u64, "{integrator:?}: {stats:?}");
        assert!(du <= bar, "{integrator:?}: max |Δu| = {du:e} m");
    }
}

/// Random piecewise-linear forces that hover around the threshold (±8 %, with sign changes
/// and plateaus exactly at it): every run finishes with finite samples, no step holds more
/// than a few events (no chatter), a force that never pushes backwards beyond the threshold
/// never reverses the platen, and every sample marked stuck is inside the friction cone.
fn near_threshold_force() -> impl Strategy<Value = (Vec<f64>, bool)> {
    let knot = prop_oneof![
        3 => 0.92f64..1.08,
        1 => Just(1.0),
        1 => -1.08f64..-0.92,
    ];
    (
        proptest::collection::vec((knot, 1usize..40), 2..12),
        any::<bool>(),
    )
        .prop_map(|(knots, law)| {
            let mut f = Vec::new();
            let mut last = knots[0].0;
            for (value, len) in knots {
                for i in 0..len {
                    f.push(last + (value - last) * i as f64 / len as f64);
                }
                last = value;
            }
            f.push(last);
            (f, law)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn forces_near_the_threshold_never_stall_chatter_or_leave_the_cone(
        (shape, law) in near_threshold_force()
    ) {
        let m = model(if law { "a07" } else { "a05" });
        let fs = m.static_threshold_n(0.0);
        let force: Vec<f64> = shape.iter().map(|s| s * fs).collect();
        let backwards = shape.iter().any(|&s| s < -0.5);
        let record = ForceRecord::from_rate(1024.0, force.clone()).unwrap();
        for integrator in [Integrator::Rk4, Integrator::Dopri5] {
            let (out, stuck, stats) = forward_flagged(&m, &record, integrator);
            prop_assert!(out.u_m.iter().chain(&out.v_m_s).all(|x| x.is_finite()));
            let steps = (record.len() - 1) as u64;
            prop_assert!(stats.events() <= 3 * steps + 1, "{:?}: {:?}", integrator, stats);
            if !backwards {
                prop_assert_eq!(stats.reversals, 0, "{:?}: {:?}", integrator, stats);
            }
            for i in 0..out.len() {
                if stuck[i] {
                    let net = force[i] - m.elastic_force_n(out.u_m[i]);
                    prop_assert!(
                        net.abs() <= m.static_threshold_n(out.u_m[i]) * (1.0 + 1e-12),
                        "{:?}: sample {} stuck with |N| = {} > F_s", integrator, i, net.abs()
                    );
                    prop_assert_eq!(out.v_m_s[i], 0.0);
                }
            }
        }
    }
}
