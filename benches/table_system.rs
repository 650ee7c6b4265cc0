//! Step throughput of the closed loop (`forward_closed_loop`: controller, servo-valves,
//! single-ended actuators and accumulator of the `lhpost-2008` table system driving the
//! identified platen with exact stick-slip), against the plain-loop baseline
//! (`baseline_rk4` of `platen_bench::baseline`, the platen alone under a recorded force)
//! measured in the same run, and the ratio of the two medians per integration step.
//!
//! The command is the paper's S9 sine motion (0.2 m, 0.6 Hz) over 60 s at 1024 Hz; the loop
//! steps at its default 7 RK4 steps per 1024 Hz controller period (resolving the 246 Hz
//! spool). The baseline steps once per sample of the 100 kN, 0.5 Hz sine force of
//! `platen bench`. Both with a [`Peaks`] sink (the integrators' own cost).
//! Run: `cargo bench --bench table_system -- --warm-up-time 1 --measurement-time 3`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use platen::integrate::{forward_closed_loop, LoopMethod, LoopRun, Motion, Peaks, State};
use platen::model::preset;
use platen::system::preset as system_preset;

use common::baseline::baseline_rk4;
use common::{report_ratios, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 20;
const SECONDS: usize = 60;

/// `platen bench`'s S9 motion over [`SECONDS`] s.
fn s9_command() -> Motion {
    platen_bench::s9_motion(SECONDS * RATE_HZ as usize + 1).unwrap()
}

fn bench(c: &mut Criterion) {
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let model = params.build().unwrap();
    let force = sine_force(100e3, SECONDS);
    let base_steps = (force.len() - 1) as u64;
    let system = system_preset::lhpost_2008();
    let k = system.default_steps_per_period(144e3, 0.75);
    let command = s9_command();
    let run = LoopRun {
        system: &system,
        specimen: None,
        command: &command,
        method: LoopMethod::Rk4 {
            steps_per_period: k,
        },
        initial: State::default(),
    };
    let loop_steps = forward_closed_loop(&model, &run, command.len(), &mut Peaks::default())
        .unwrap()
        .run
        .steps;
    let mut group = c.benchmark_group("table_system");
    group.sample_size(SAMPLE_SIZE);
    group.bench_function("plain_loop_baseline", |b| {
        timed(b, "table_system/plain_loop_baseline", || {
            baseline_rk4(&params, black_box(&force), 1.0 / RATE_HZ, State::default())
        })
    });
    group.bench_function("closed_loop", |b| {
        timed(b, "table_system/closed_loop", || {
            let mut peaks = Peaks::default();
            forward_closed_loop(black_box(&model), &run, command.len(), &mut peaks).unwrap();
            peaks
        })
    });
    group.finish();
    report_ratios(
        &format!("table_system, {SECONDS} s S9 command, {k} steps per controller period"),
        SAMPLE_SIZE,
        ("table_system/plain_loop_baseline", base_steps),
        &[("table_system/closed_loop", loop_steps)],
        "step",
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
