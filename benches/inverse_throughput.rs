//! Throughput of inverse runs (a prescribed motion → the actuator force and its
//! decomposition, Eq. 1–4), per sample, on both model forms of the `lhpost-2008` preset.
//!
//! Workload: the paper's S9 sine motion (0.2 m at 0.6 Hz) with its exact velocity and
//! acceleration, sampled at 1024 Hz, over 60 s and 600 s (`BenchmarkId` over the length),
//! into a [`Peaks`] sink. There is no plain-loop baseline here: an inverse run is one
//! evaluation of the model per sample, with nothing to integrate and no event to locate.
//! Run: `cargo bench --bench inverse_throughput -- --warm-up-time 1 --measurement-time 3`.

#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::integrate::{inverse, Motion, Peaks};
use platen::model::preset;

use common::{median_ns, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 20;

/// `platen bench`'s S9 motion over `seconds` s.
fn s9_motion(seconds: usize) -> Motion {
    platen_bench::s9_motion(seconds * RATE_HZ as usize + 1).unwrap()
}

fn bench(c: &mut Criterion) {
    let identified = preset::lhpost_2008_identified(PRESSURE_PA).build().unwrap();
    let full = preset::lhpost_2008_physical(PRESSURE_PA).build().unwrap();
    let mut group = c.benchmark_group("inverse");
    group.sample_size(SAMPLE_SIZE);
    let mut rows = Vec::new();
    for seconds in [60usize, 600] {
        let motion = s9_motion(seconds);
        let samples = motion.len() as u64;
        group.throughput(Throughput::Elements(samples));
        let key = |what: &str| format!("inverse/{what}/{seconds}");
        group.bench_with_input(BenchmarkId::new("identified", seconds), &motion, |b, m| {
            timed(b, &key("identified"), || {
                let mut peaks = Peaks::default();
                inverse(&identified, black_box(m), &mut peaks);
                peaks
            })
        });
        group.bench_with_input(BenchmarkId::new("full", seconds), &motion, |b, m| {
            timed(b, &key("full"), || {
                let mut peaks = Peaks::default();
                inverse(&full, black_box(m), &mut peaks);
                peaks
            })
        });
        rows.push((key("identified"), samples));
        rows.push((key("full"), samples));
    }
    group.finish();
    println!("\ninverse: median ns/sample");
    for (name, samples) in rows {
        if let Some(t) = median_ns(&name, SAMPLE_SIZE) {
            println!("  {name:<32} {:>8.2}", t / samples as f64);
        }
    }
    println!();
}

criterion_group!(benches, bench);
criterion_main!(benches);
