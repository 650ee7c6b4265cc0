//! Throughput of the zero-phase filters and the crossover velocity estimate on 100 s of
//! 1024 Hz data (the paper's FIR of order 512 at 8 Hz, a 4th-order Butterworth at 2.4 Hz, the
//! brick wall at 0.6 Hz, the crossover at 2 Hz), reported per sample.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::signal::{
    ButterworthLowpass, CrossoverVelocity, FirLowpass, SpectralLowpass, Window, ZeroPhaseFilter,
};

const RATE_HZ: f64 = 1024.0;

fn signal(n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| {
            let t = j as f64 / RATE_HZ;
            (std::f64::consts::PI * t).sin() + 0.1 * (2.0 * std::f64::consts::PI * 10.66 * t).sin()
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("filters");
    group.sample_size(20);
    let n = 100 * 1024 + 1;
    let x = signal(n);
    let a: Vec<f64> = x.iter().map(|v| -v).collect();
    group.throughput(Throughput::Elements(n as u64));
    let fir = FirLowpass::new(512, 8.0, RATE_HZ, Window::Hamming).unwrap();
    let butter = ButterworthLowpass::new(4, 2.4, RATE_HZ).unwrap();
    let brick = SpectralLowpass::new(n, 0.6, RATE_HZ).unwrap();
    let crossover = CrossoverVelocity::butterworth(2, 2.0, RATE_HZ).unwrap();
    group.bench_with_input(BenchmarkId::new("fir_512_at_8hz", n), &x, |b, x| {
        b.iter(|| fir.apply(black_box(x)).unwrap())
    });
    group.bench_with_input(BenchmarkId::new("butterworth_4_at_2_4hz", n), &x, |b, x| {
        b.iter(|| butter.apply(black_box(x)).unwrap())
    });
    group.bench_with_input(BenchmarkId::new("brickwall_at_0_6hz", n), &x, |b, x| {
        b.iter(|| brick.apply(black_box(x)).unwrap())
    });
    group.bench_with_input(BenchmarkId::new("crossover_velocity_2hz", n), &x, |b, x| {
        b.iter(|| crossover.estimate(black_box(x), black_box(&a)).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
