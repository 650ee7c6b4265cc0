//! Throughput of the ensemble RK4 (`forward_rk4_lanes`, SIMD lanes) against the scalar
//! `forward_rk4` on the same cases, measured in the same run: the median ns per step per
//! trajectory of each and their ratio (goal ≤ 0.6).
//!
//! The cases are a sweep's: the `lhpost-2008` identified model at 6.9 and 13.8 MPa under the
//! 0.5 Hz sine force of `platen bench` (100 kN) scaled by 0.8, 0.9, 1.1 and 1.2, sampled at
//! 1024 Hz and stepped at 1/1024 s for 60 s from rest: eight cases, every one breaking away
//! and reversing every half period. The scalar routine runs the eight one after the other;
//! the ensemble runs them in 4 or 8 lanes. A second group does the same at 45 kN (two stick
//! phases per period, ≈ 22 % of the time stuck, stepped by the scalar path).
//! Run: `cargo bench --bench ensemble -- --warm-up-time 1 --measurement-time 3`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use platen::integrate::{
    forward_rk4, forward_rk4_lanes, EnsembleCase, ForceRecord, Peaks, Rk4, State,
};
use platen::model::{preset, IdentifiedModel};

use common::{median_ns, sine_force, timed, RATE_HZ};

const SAMPLE_SIZE: usize = 20;
const SECONDS: usize = 60;
const SCALES: [f64; 4] = [0.8, 0.9, 1.1, 1.2];
const PRESSURES_PA: [f64; 2] = [6.9e6, 13.8e6];

fn bench_cases(c: &mut Criterion, group_name: &str, amplitude_n: f64) {
    let mut models: Vec<IdentifiedModel> = Vec::new();
    let mut records: Vec<ForceRecord> = Vec::new();
    for scale in SCALES {
        for pressure in PRESSURES_PA {
            models.push(preset::lhpost_2008_identified(pressure).build().unwrap());
            let force = sine_force(amplitude_n * scale, SECONDS);
            records.push(ForceRecord::from_rate(RATE_HZ, force).unwrap());
        }
    }
    let cases: Vec<EnsembleCase<'_>> = models
        .iter()
        .zip(&records)
        .map(|(model, record)| EnsembleCase {
            model,
            record,
            initial: State::default(),
        })
        .collect();
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    let samples = records[0].len();
    let steps = ((samples - 1) * cases.len()) as u64;
    let mut group = c.benchmark_group(group_name);
    group.sample_size(SAMPLE_SIZE);
    group.throughput(Throughput::Elements(steps));
    let key = |what: &str| format!("{group_name}/{what}");
    group.bench_function("scalar", |b| {
        timed(b, &key("scalar"), || {
            cases
                .iter()
                .map(|c| {
                    let mut peaks = Peaks::default();
                    forward_rk4(
                        c.model,
                        black_box(c.record),
                        rk4,
                        c.initial,
                        samples,
                        &mut peaks,
                    )
                    .unwrap();
                    peaks
                })
                .collect::<Vec<_>>()
        })
    });
    group.bench_function("ensemble_4_lanes", |b| {
        timed(b, &key("ensemble_4_lanes"), || {
            let mut peaks = vec![Peaks::default(); cases.len()];
            let r = forward_rk4_lanes::<4, _>(black_box(&cases), rk4, samples, &mut peaks);
            (r.len(), peaks)
        })
    });
    group.bench_function("ensemble_8_lanes", |b| {
        timed(b, &key("ensemble_8_lanes"), || {
            let mut peaks = vec![Peaks::default(); cases.len()];
            let r = forward_rk4_lanes::<8, _>(black_box(&cases), rk4, samples, &mut peaks);
            (r.len(), peaks)
        })
    });
    group.finish();
    let Some(base) = median_ns(&key("scalar"), SAMPLE_SIZE).map(|t| t / steps as f64) else {
        return;
    };
    println!("\n{group_name}: median ns/step/trajectory, ratio to the scalar step of this run");
    println!("  {:<40} {:>10.2} {:>8}", key("scalar"), base, "1");
    for what in ["ensemble_4_lanes", "ensemble_8_lanes"] {
        if let Some(t) = median_ns(&key(what), SAMPLE_SIZE) {
            let per = t / steps as f64;
            println!("  {:<40} {:>10.2} {:>8.3}", key(what), per, per / base);
        }
    }
    println!();
}

fn no_stick(c: &mut Criterion) {
    bench_cases(c, "ensemble_no_stick", 100e3);
}

fn stick(c: &mut Criterion) {
    bench_cases(c, "ensemble_stick", 45e3);
}

criterion_group!(benches, no_stick, stick);
criterion_main!(benches);
