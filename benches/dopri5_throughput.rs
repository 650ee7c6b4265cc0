//! Cost of the adaptive Dopri5 forward run (the mode machine's Dormand–Prince 5(4), exact
//! stick-slip) per accepted step, next to the fixed-step RK4 and the plain-loop baseline on
//! the same record in the same run.
//!
//! Workload: the 100 kN, 0.5 Hz sine force of `platen bench` at 1024 Hz, over 10 s and 60 s
//! (`BenchmarkId` over the length), from rest on the identified `lhpost-2008` model, at
//! rtol 1e-8 and 1e-6 (atol 1e-11), into a [`Peaks`] sink. Every sample interval is a Dopri5
//! segment (the force's slope jumps at samples), so Dopri5 takes at least one step of at
//! least 6 new stages per sample. The ratio printed is time per accepted Dopri5 step over
//! time per baseline RK4 step: the price of an adaptive step with error control and event
//! location, not a like-for-like speed comparison (the step lengths differ).
//! Run: `cargo bench --bench dopri5_throughput -- --warm-up-time 1 --measurement-time 3`.

#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::integrate::{forward_dopri5, Dopri5Settings, ForceRecord, Peaks, State};
use platen::model::preset;

use common::baseline::baseline_rk4;
use common::{report_ratios, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 10;

fn bench(c: &mut Criterion) {
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let model = params.build().unwrap();
    let mut group = c.benchmark_group("dopri5");
    group.sample_size(SAMPLE_SIZE);
    let mut reports = Vec::new();
    for seconds in [10usize, 60] {
        let force = sine_force(100e3, seconds);
        let record = ForceRecord::from_rate(RATE_HZ, force.clone()).unwrap();
        let baseline_steps = (force.len() - 1) as u64;
        let key = |what: &str| format!("dopri5/{what}/{seconds}");
        group.throughput(Throughput::Elements(baseline_steps));
        group.bench_with_input(
            BenchmarkId::new("plain_loop_baseline", seconds),
            &force,
            |b, f| {
                timed(b, &key("plain_loop_baseline"), || {
                    baseline_rk4(&params, black_box(f), 1.0 / RATE_HZ, State::default())
                })
            },
        );
        let mut rows = Vec::new();
        for rtol in [1e-8, 1e-6] {
            let settings = Dopri5Settings::new(rtol, 1e-11).unwrap();
            // Accepted steps of this run (deterministic), to time per accepted step.
            let accepted = forward_dopri5(
                &model,
                &record,
                settings,
                State::default(),
                record.len(),
                &mut Peaks::default(),
            )
            .unwrap()
            .accepted_steps;
            let name = format!("rtol_{rtol:e}");
            group.throughput(Throughput::Elements(accepted));
            group.bench_with_input(BenchmarkId::new(&name, seconds), &record, |b, r| {
                timed(b, &key(&name), || {
                    let mut peaks = Peaks::default();
                    forward_dopri5(
                        &model,
                        black_box(r),
                        settings,
                        State::default(),
                        r.len(),
                        &mut peaks,
                    )
                    .unwrap();
                    peaks
                })
            });
            rows.push((key(&name), accepted));
        }
        reports.push((seconds, key("plain_loop_baseline"), baseline_steps, rows));
    }
    group.finish();
    for (seconds, base, steps, rows) in reports {
        let rows: Vec<(&str, u64)> = rows.iter().map(|(n, s)| (n.as_str(), *s)).collect();
        report_ratios(
            &format!("dopri5, {seconds} s record (per accepted step)"),
            SAMPLE_SIZE,
            (&base, steps),
            &rows,
            "step",
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
