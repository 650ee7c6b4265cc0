//! Step throughput of the forward RK4 with exact stick-slip, against a plain-loop baseline
//! measured in the same run.
//!
//! Workload (the one `platen bench` and the issue quote): a 600 kN, 0.5 Hz sine force sampled
//! at 1024 Hz drives the `lhpost-2008` model from rest, stepped at 1/1024 s. The baseline is
//! the same RK4 on the identified model written as a plain loop: √|v| and one exp per stage,
//! force interpolated, no stick logic, no output. The ratio of the two medians is what the
//! README quotes.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::integrate::{forward_rk4, ForceRecord, Peaks, Rk4, State};
use platen::model::preset;

const RATE_HZ: f64 = 1024.0;

fn sine_force(seconds: usize) -> Vec<f64> {
    (0..=seconds * RATE_HZ as usize)
        .map(|j| 600e3 * (2.0 * std::f64::consts::PI * 0.5 * j as f64 / RATE_HZ).sin())
        .collect()
}

/// The plain loop: identified model, RK4, force linearly interpolated at the half step.
fn baseline(force: &[f64]) -> (f64, f64) {
    let p = preset::lhpost_2008_identified(13.8e6);
    let (k, fmu, c, a, b) = (
        p.stiffness_n_per_m,
        p.coulomb_force_n,
        p.viscous_coefficient,
        p.low_velocity_force_n,
        p.low_velocity_decay_s_per_m,
    );
    let inv_m = 1.0 / p.effective_mass_kg;
    let h = 1.0 / RATE_HZ;
    let acc = |f: f64, u: f64, v: f64| {
        let w = v.abs();
        (f - k * u - (fmu + c * w.sqrt() + a * (-b * w).exp()).copysign(v)) * inv_m
    };
    let (mut u, mut v) = (0.0, 0.0);
    for j in 0..force.len() - 1 {
        let (f0, f1) = (force[j], force[j + 1]);
        let fm = 0.5 * (f0 + f1);
        let a1 = acc(f0, u, v);
        let a2 = acc(fm, u + 0.5 * h * v, v + 0.5 * h * a1);
        let v2 = v + 0.5 * h * a1;
        let a3 = acc(fm, u + 0.5 * h * v2, v + 0.5 * h * a2);
        let v3 = v + 0.5 * h * a2;
        let a4 = acc(f1, u + h * v3, v + h * a3);
        let v4 = v + h * a3;
        u += h / 6.0 * (v + 2.0 * (v2 + v3) + v4);
        v += h / 6.0 * (a1 + 2.0 * (a2 + a3) + a4);
    }
    (u, v)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("forward_rk4");
    group.sample_size(20);
    for seconds in [60usize, 600] {
        let force = sine_force(seconds);
        let steps = (force.len() - 1) as u64;
        group.throughput(Throughput::Elements(steps));
        let record = ForceRecord::from_rate(RATE_HZ, force.clone()).unwrap();
        let rk4 = Rk4::with_steps_per_sample(1).unwrap();
        let identified = preset::lhpost_2008_identified(13.8e6).build().unwrap();
        let full = preset::lhpost_2008_physical(13.8e6).build().unwrap();
        group.bench_with_input(
            BenchmarkId::new("plain_loop_baseline", seconds),
            &force,
            |bch, f| bch.iter(|| baseline(black_box(f))),
        );
        group.bench_with_input(
            BenchmarkId::new("identified_stick_slip", seconds),
            &record,
            |bch, r| {
                bch.iter(|| {
                    let mut peaks = Peaks::default();
                    forward_rk4(
                        &identified,
                        black_box(r),
                        rk4,
                        State::default(),
                        r.len(),
                        &mut peaks,
                    )
                    .unwrap()
                })
            },
        );
        group.bench_with_input(
            BenchmarkId::new("full_stick_slip", seconds),
            &record,
            |bch, r| {
                bch.iter(|| {
                    let mut peaks = Peaks::default();
                    forward_rk4(
                        &full,
                        black_box(r),
                        rk4,
                        State::default(),
                        r.len(),
                        &mut peaks,
                    )
                    .unwrap()
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
