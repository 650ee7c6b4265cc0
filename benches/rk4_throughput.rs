//! Step throughput of the forward RK4 with exact stick-slip, against the plain-loop baseline
//! (`baseline_rk4` of `benches/common/baseline.rs`) measured in the same run, and the ratio
//! of the two medians.
//!
//! Two records, each at 60 s and 600 s (`BenchmarkId` over the record length), sampled at
//! 1024 Hz and stepped at 1/1024 s on the `lhpost-2008` preset at 13.8 MPa, from rest:
//!
//! * `no_stick`: a 100 kN, 0.5 Hz sine force (the workload of `platen bench` and of
//!   `benches/c/rk4_baseline.c`, a table test within the LHPOST's limits): after the
//!   breakaway from rest the platen slips throughout, reversing directly every half period;
//! * `stick`: a 45 kN, 0.5 Hz sine force, just above the 37.5 kN static threshold: two stick
//!   phases per period, ≈ 22 % of the time stuck.
//!
//! Each runs the identified model (Eq. 22/23) and the full Lagrangian model (Eq. 1–8) with a
//! [`Peaks`] sink (the integrator's own cost; `platen bench` keeps the whole trajectory), and
//! the baseline on the same force samples. After each group the medians and the ratios are
//! printed. Run: `cargo bench --bench rk4_throughput -- --warm-up-time 1 --measurement-time 3`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::integrate::{forward_rk4, ForceRecord, Peaks, Rk4, State};
use platen::model::preset;

use common::baseline::baseline_rk4;
use common::{report_ratios, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 20;
const LENGTHS_S: [usize; 2] = [60, 600];

fn bench_record(c: &mut Criterion, group_name: &str, amplitude_n: f64) {
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let identified = params.build().unwrap();
    let full = preset::lhpost_2008_physical(PRESSURE_PA).build().unwrap();
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    let mut group = c.benchmark_group(group_name);
    group.sample_size(SAMPLE_SIZE);
    let mut names = Vec::new();
    for seconds in LENGTHS_S {
        let force = sine_force(amplitude_n, seconds);
        let steps = (force.len() - 1) as u64;
        group.throughput(Throughput::Elements(steps));
        let record = ForceRecord::from_rate(RATE_HZ, force.clone()).unwrap();
        let key = |what: &str| format!("{group_name}/{what}/{seconds}");
        group.bench_with_input(
            BenchmarkId::new("plain_loop_baseline", seconds),
            &force,
            |b, f| {
                timed(b, &key("plain_loop_baseline"), || {
                    baseline_rk4(&params, black_box(f), 1.0 / RATE_HZ, State::default())
                })
            },
        );
        group.bench_with_input(
            BenchmarkId::new("identified_stick_slip", seconds),
            &record,
            |b, r| {
                timed(b, &key("identified_stick_slip"), || {
                    let mut peaks = Peaks::default();
                    forward_rk4(
                        &identified,
                        black_box(r),
                        rk4,
                        State::default(),
                        r.len(),
                        &mut peaks,
                    )
                    .unwrap();
                    peaks
                })
            },
        );
        group.bench_with_input(
            BenchmarkId::new("full_stick_slip", seconds),
            &record,
            |b, r| {
                timed(b, &key("full_stick_slip"), || {
                    let mut peaks = Peaks::default();
                    forward_rk4(
                        &full,
                        black_box(r),
                        rk4,
                        State::default(),
                        r.len(),
                        &mut peaks,
                    )
                    .unwrap();
                    peaks
                })
            },
        );
        names.push((seconds, steps));
    }
    group.finish();
    for (seconds, steps) in names {
        let key = |what: &str| format!("{group_name}/{what}/{seconds}");
        report_ratios(
            &format!("{group_name}, {seconds} s record"),
            SAMPLE_SIZE,
            (&key("plain_loop_baseline"), steps),
            &[
                (&key("identified_stick_slip"), steps),
                (&key("full_stick_slip"), steps),
            ],
            "step",
        );
    }
}

fn no_stick(c: &mut Criterion) {
    bench_record(c, "forward_rk4_no_stick", 100e3);
}

fn stick(c: &mut Criterion) {
    bench_record(c, "forward_rk4_stick", 45e3);
}

criterion_group!(benches, no_stick, stick);
criterion_main!(benches);
