//! The ensemble integrator is the scalar RK4 bit for bit: for sweep-like cases (force scales
//! and hold-down pressures, with stick phases, breakaways, reversals and creep), every output
//! sample of every case, its statistics and its error are those of `forward_rk4` on the case
//! alone, whatever the number of lanes and the grouping.

use platen_integrate::{
    forward_rk4, forward_rk4_ensemble, forward_rk4_lanes, EnsembleCase, ForceRecord, Result, Rk4,
    RunStats, Sample, SampleSink, State,
};
use platen_model::{preset, IdentifiedModel};

/// Every field of every sample, as bits.
#[derive(Default, Debug, PartialEq)]
struct Bits(Vec<[u64; 10]>);

impl SampleSink for Bits {
    fn accept(&mut self, s: &Sample) {
        self.0.push([
            s.index as u64,
            s.t_s.to_bits(),
            s.u_m.to_bits(),
            s.v_m_s.to_bits(),
            s.a_m_s2.to_bits(),
            s.terms.inertial_n.to_bits(),
            s.terms.elastic_n.to_bits(),
            s.terms.dissipative_n.to_bits(),
            s.terms.actuator_n.to_bits(),
            u64::from(s.stuck),
        ]);
    }
}

const RATE_HZ: f64 = 1024.0;

/// A 0.5 Hz sine force of `amplitude_n` plus a 3.1 Hz ripple of a fifth of it, for
/// `seconds`.
fn force(amplitude_n: f64, seconds: f64) -> Vec<f64> {
    let n = (seconds * RATE_HZ) as usize;
    (0..=n)
        .map(|j| {
            let t = j as f64 / RATE_HZ;
            amplitude_n
                * ((std::f64::consts::PI * t).sin()
                    + 0.2 * (2.0 * std::f64::consts::PI * 3.1 * t).sin())
        })
        .collect()
}

fn model(pressure_mpa: f64, alpha: Option<f64>) -> IdentifiedModel {
    let mut p = preset::lhpost_2008_identified(pressure_mpa * 1e6);
    if let Some(alpha) = alpha {
        p.viscous_exponent = alpha;
    }
    p.build().unwrap()
}

fn debug<T: std::fmt::Debug>(r: &Result<T>) -> String {
    format!("{r:?}")
}

/// Runs `cases` scalar and as an ensemble of `N` lanes and compares everything.
fn check<const N: usize>(cases: &[EnsembleCase<'_>], rk4: Rk4, samples: usize) {
    let scalar: Vec<(Bits, Result<RunStats>)> = cases
        .iter()
        .map(|c| {
            let mut bits = Bits::default();
            let r = forward_rk4(c.model, c.record, rk4, c.initial, samples, &mut bits);
            (bits, r)
        })
        .collect();
    let mut sinks: Vec<Bits> = cases.iter().map(|_| Bits::default()).collect();
    let results = forward_rk4_lanes::<N, _>(cases, rk4, samples, &mut sinks);
    assert_eq!(results.len(), cases.len());
    for (i, ((bits, r), (ens_bits, ens_r))) in
        scalar.iter().zip(sinks.iter().zip(&results)).enumerate()
    {
        assert_eq!(bits.0.len(), ens_bits.0.len(), "case {i}: sample count");
        if let Some(s) = bits.0.iter().zip(&ens_bits.0).position(|(a, b)| a != b) {
            panic!(
                "case {i}, lanes {N}: sample {s} differs: scalar {:?}, ensemble {:?}",
                bits.0[s], ens_bits.0[s]
            );
        }
        assert_eq!(debug(r), debug(ens_r), "case {i}: statistics or error");
    }
}

struct Sweep {
    models: Vec<IdentifiedModel>,
    records: Vec<ForceRecord>,
}

/// Scales 0.3 (never leaves rest at 13.8 MPa), 0.6 (stick phases), 1, 1.5 (reversals) of a
/// 100 kN sine with ripple, at 0, 6.9 and 13.8 MPa: twelve cases.
fn sweep(seconds: f64, alpha: Option<f64>) -> Sweep {
    let mut models = Vec::new();
    let mut records = Vec::new();
    for scale in [0.3, 0.6, 1.0, 1.5] {
        for pressure in [0.0, 6.9, 13.8] {
            models.push(model(pressure, alpha));
            records.push(ForceRecord::from_rate(RATE_HZ, force(100e3 * scale, seconds)).unwrap());
        }
    }
    Sweep { models, records }
}

impl Sweep {
    fn cases(&self) -> Vec<EnsembleCase<'_>> {
        self.models
            .iter()
            .zip(&self.records)
            .map(|(model, record)| EnsembleCase {
                model,
                record,
                initial: State::default(),
            })
            .collect()
    }
}

#[test]
fn sweep_cases_are_the_scalar_runs_bit_for_bit_in_4_and_8_lanes() {
    let s = sweep(6.0, None);
    let cases = s.cases();
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    let samples = s.records[0].len();
    check::<4>(&cases, rk4, samples);
    check::<8>(&cases, rk4, samples);
    check::<2>(&cases[..5], rk4, samples);
}

#[test]
fn the_runs_have_stick_phases_breakaways_and_reversals() {
    let s = sweep(6.0, None);
    let cases = s.cases();
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    let mut sinks: Vec<Bits> = cases.iter().map(|_| Bits::default()).collect();
    let results = forward_rk4_ensemble(&cases, rk4, s.records[0].len(), &mut sinks);
    let stats: Vec<RunStats> = results.into_iter().map(|r| r.unwrap()).collect();
    assert!(
        stats.iter().any(|s| s.breakaways == 0),
        "a case that never moves"
    );
    assert!(stats.iter().any(|s| s.stick_events > 2 && s.breakaways > 2));
    assert!(stats.iter().any(|s| s.reversals > 4));
}

#[test]
fn several_steps_per_sample_other_exponents_and_moving_starts_are_bit_for_bit() {
    let rk4 = Rk4::with_steps_per_sample(3).unwrap();
    // α = 0.3 (powf per lane), and mixed exponents in one group.
    let s = sweep(3.0, Some(0.3));
    let mut cases = s.cases();
    let samples = s.records[0].len();
    check::<4>(&cases, rk4, samples);
    let half = sweep(3.0, None);
    let mut mixed = half.cases();
    mixed.truncate(6);
    mixed.extend(cases.iter().take(6).copied());
    check::<4>(&mixed, rk4, samples);
    // Moving starts in both directions, and fewer samples than the record holds.
    for (i, c) in cases.iter_mut().enumerate() {
        c.initial = State {
            u_m: 0.01 * i as f64,
            v_m_s: if i % 2 == 0 { 0.3 } else { -0.2 },
        };
    }
    check::<4>(&cases, rk4, samples - 100);
}

#[test]
fn cases_on_other_grids_or_that_cannot_run_are_handled_as_the_scalar_path() {
    let s = sweep(2.0, None);
    let mut cases = s.cases();
    let other = ForceRecord::from_rate(512.0, force(80e3, 4.0)).unwrap();
    let short = ForceRecord::from_rate(RATE_HZ, force(80e3, 1.0)).unwrap();
    cases[2].record = &other;
    cases[5].record = &short;
    cases[7].initial = State {
        u_m: f64::NAN,
        v_m_s: 0.0,
    };
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    let samples = s.records[0].len();
    check::<4>(&cases, rk4, samples);
    check::<4>(&cases, rk4, 1);
    check::<4>(&cases, rk4, 0);
}
