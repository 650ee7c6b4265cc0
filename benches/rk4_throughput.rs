//! Step throughput of the forward RK4 with exact stick-slip, against the plain-loop baseline
//! (`baseline_rk4` of `platen_bench::baseline`) measured in the same run, and the ratio
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
//! printed.
//!
//! A third group, `forward_rk4_specimen`, runs the `no_stick` force with a specimen on the
//! identified model ([`forward_rk4_specimen`]): the 3-storey, 60 t frame of `platen bench`
//! (`bench_specimen` in `platen_bench` (crates/platen-bench): 20 t floors, 40, 32 and 24 MN/m,
//! dampers 3 ms times each stiffness) and a 2-storey, 55 t frame (the one of
//! `scenarios/specimen/frame-forward.json`), next to the bare identified run and the baseline
//! of the same run (the target: a specimen step at most 1.6 × the baseline).
//!
//! Run: `cargo bench --bench rk4_throughput -- --warm-up-time 1 --measurement-time 3`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::measurement::WallTime;
use criterion::{
    criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion, Throughput,
};
use platen::integrate::{forward_rk4, forward_rk4_specimen, ForceRecord, Peaks, Rk4, State};
use platen::model::{preset, IdentifiedParams, PlatenModel, Specimen, Storey};

use common::baseline::baseline_rk4;
use common::{report_ratios, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 20;
const LENGTHS_S: [usize; 2] = [60, 600];

/// The criterion group the benches register in.
type Group<'a> = BenchmarkGroup<'a, WallTime>;

/// Registers `plain_loop_baseline`: the plain RK4 loop of `params` on the `force` samples.
fn bench_baseline(
    group: &mut Group<'_>,
    key: &str,
    seconds: usize,
    params: &IdentifiedParams,
    force: &[f64],
) {
    group.bench_with_input(
        BenchmarkId::new("plain_loop_baseline", seconds),
        force,
        |b, f| {
            timed(b, &format!("{key}/plain_loop_baseline/{seconds}"), || {
                baseline_rk4(params, black_box(f), 1.0 / RATE_HZ, State::default())
            })
        },
    );
}

/// Registers `name`: the forward RK4 of `model` over `record` into a [`Peaks`] sink.
fn bench_forward<M: PlatenModel>(
    group: &mut Group<'_>,
    key: &str,
    name: &str,
    seconds: usize,
    model: &M,
    record: &ForceRecord,
) {
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    group.bench_with_input(BenchmarkId::new(name, seconds), record, |b, r| {
        timed(b, &format!("{key}/{name}/{seconds}"), || {
            let mut peaks = Peaks::default();
            forward_rk4(
                model,
                black_box(r),
                rk4,
                State::default(),
                r.len(),
                &mut peaks,
            )
            .unwrap();
            peaks
        })
    });
}

fn bench_record(c: &mut Criterion, group_name: &str, amplitude_n: f64) {
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let identified = params.build().unwrap();
    let full = preset::lhpost_2008_physical(PRESSURE_PA).build().unwrap();
    let mut group = c.benchmark_group(group_name);
    group.sample_size(SAMPLE_SIZE);
    let mut names = Vec::new();
    for seconds in LENGTHS_S {
        let force = sine_force(amplitude_n, seconds);
        let steps = (force.len() - 1) as u64;
        group.throughput(Throughput::Elements(steps));
        let record = ForceRecord::from_rate(RATE_HZ, force.clone()).unwrap();
        bench_baseline(&mut group, group_name, seconds, &params, &force);
        bench_forward(
            &mut group,
            group_name,
            "identified_stick_slip",
            seconds,
            &identified,
            &record,
        );
        bench_forward(
            &mut group,
            group_name,
            "full_stick_slip",
            seconds,
            &full,
            &record,
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

/// A storey of `mass_kg`, stiffness `k` and damping `c`.
fn storey(mass_kg: f64, k: f64, c: f64) -> Storey {
    Storey {
        mass_kg,
        stiffness_n_per_m: k,
        damping_n_s_per_m: c,
    }
}

fn specimen(c: &mut Criterion) {
    let group_name = "forward_rk4_specimen";
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let identified = params.build().unwrap();
    let rk4 = Rk4::with_steps_per_sample(1).unwrap();
    // `platen bench`'s frame and the shipped 2-storey frame.
    let three = platen_bench::bench_specimen().unwrap();
    let two = Specimen::new(vec![
        storey(30e3, 27_083_177.88, 86_208.43),
        storey(25e3, 19_345_127.06, 61_577.45),
    ])
    .unwrap();
    let seconds = 60;
    let force = sine_force(100e3, seconds);
    let steps = (force.len() - 1) as u64;
    let record = ForceRecord::from_rate(RATE_HZ, force.clone()).unwrap();
    let key = |what: &str| format!("{group_name}/{what}/{seconds}");
    let mut group = c.benchmark_group(group_name);
    group.sample_size(SAMPLE_SIZE);
    group.throughput(Throughput::Elements(steps));
    bench_baseline(&mut group, group_name, seconds, &params, &force);
    bench_forward(
        &mut group,
        group_name,
        "identified_stick_slip",
        seconds,
        &identified,
        &record,
    );
    for (name, spec) in [("two_storeys", &two), ("three_storeys", &three)] {
        group.bench_with_input(BenchmarkId::new(name, seconds), &record, |b, r| {
            timed(b, &key(name), || {
                let mut peaks = Peaks::default();
                forward_rk4_specimen(
                    &identified,
                    black_box(spec),
                    black_box(r),
                    rk4,
                    State::default(),
                    r.len(),
                    &mut peaks,
                )
                .unwrap();
                peaks
            })
        });
    }
    group.finish();
    report_ratios(
        &format!("{group_name}, {seconds} s record"),
        SAMPLE_SIZE,
        (&key("plain_loop_baseline"), steps),
        &[
            (&key("identified_stick_slip"), steps),
            (&key("two_storeys"), steps),
            (&key("three_storeys"), steps),
        ],
        "step",
    );
}

criterion_group!(benches, no_stick, stick, specimen);
criterion_main!(benches);
