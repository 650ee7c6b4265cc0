//! Step throughput of the multi-axis closed loop (`forward_table_loop`: the `lhpost6`
//! preset's DOF controller, ten actuators' servo-valves and chambers, the accumulator, the
//! rigid platen with its pads' exact planar stick-slip), against the uniaxial closed loop
//! (`forward_closed_loop` of the `lhpost-2008` table system) measured in the same run, and
//! the ratio of the two medians per integration step. Both are commanded with `platen
//! bench`'s S9 sine motion (0.2 m, 0.6 Hz) along x over 40 s; each steps at its default RK4
//! steps per controller period. The second measurement is the end-to-end goal: a
//! 40 s record on the LHPOST6 under 5 s on one core.
//! Run: `cargo bench --bench six_dof_closed_loop -- --warm-up-time 1 --measurement-time 10`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use platen::integrate::{
    forward_closed_loop, forward_table_loop, LoopMethod, LoopRun, Peaks, State, TableLoopRun,
};
use platen::model::preset;
use platen::system::preset as system_preset;

use common::{report_ratios, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 10;
const SECONDS: usize = 40;

fn bench(c: &mut Criterion) {
    let model = preset::lhpost_2008_identified(PRESSURE_PA).build().unwrap();
    let command = platen_bench::s9_motion(SECONDS * RATE_HZ as usize + 1).unwrap();
    let system = system_preset::lhpost_2008();
    let k = system.default_steps_per_period(144e3, 0.75);
    let uniaxial = LoopRun {
        system: &system,
        specimen: None,
        command: &command,
        method: LoopMethod::Rk4 {
            steps_per_period: k,
        },
        initial: State::default(),
    };
    let uniaxial_steps =
        forward_closed_loop(&model, &uniaxial, command.len(), &mut Peaks::default())
            .unwrap()
            .run
            .steps;
    let (table, sys, pose) = platen_bench::bench_lhpost6(&command).unwrap();
    let run = TableLoopRun {
        table: &table,
        hydraulics: &sys.hydraulics,
        controller: &sys.controller,
        specimen: None,
        command: &pose,
        method: sys.method,
    };
    let six_dof_steps = forward_table_loop(&run).unwrap().1.run.steps;
    let mut group = c.benchmark_group("six_dof_closed_loop");
    group.sample_size(SAMPLE_SIZE);
    group.bench_function("uniaxial_closed_loop", |b| {
        timed(b, "six_dof_closed_loop/uniaxial_closed_loop", || {
            let mut peaks = Peaks::default();
            forward_closed_loop(black_box(&model), &uniaxial, command.len(), &mut peaks).unwrap();
            peaks
        })
    });
    group.bench_function("lhpost6_closed_loop", |b| {
        timed(b, "six_dof_closed_loop/lhpost6_closed_loop", || {
            forward_table_loop(black_box(&run)).unwrap()
        })
    });
    group.finish();
    report_ratios(
        &format!("six_dof_closed_loop, {SECONDS} s S9 command along x"),
        SAMPLE_SIZE,
        ("six_dof_closed_loop/uniaxial_closed_loop", uniaxial_steps),
        &[("six_dof_closed_loop/lhpost6_closed_loop", six_dof_steps)],
        "step",
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
