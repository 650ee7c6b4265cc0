//! Test planning (`platen plan`): the offline drive iteration of a 40 s synthetic
//! earthquake-like acceleration target on the `lhpost-2008` closed loop (bare table, `Ĥ`
//! linearised, 10 corrections: 11 closed-loop runs of 40 s), and the largest scale that fits
//! (`max_scale`, bisection on the simulated loop), against the plain-loop baseline
//! (`baseline_rk4` of `platen_bench::baseline`) measured in the same run; the ratio is
//! per 1024 Hz target sample of one planning task (not per integration step).
//!
//! Run: `cargo bench --bench plan -- --warm-up-time 1 --measurement-time 10`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use platen::integrate::State;
use platen::model::preset;
use platen::plan::{
    enveloped_sines_m_s2, iterate, max_scale, BaselineSettings, FrfSource, IterationSettings,
    MaxScaleSettings, PlatenLoop, Target, TargetMotion,
};
use platen::scenario::LoadedRig;

use common::baseline::baseline_rk4;
use common::{report_ratios, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 10;
const SECONDS: usize = 40;

/// An earthquake-like acceleration: five sines under a rise–hold–decay envelope, 0.3 g peak
/// ([`enveloped_sines_m_s2`]).
fn quake(t: f64) -> f64 {
    enveloped_sines_m_s2(
        t,
        0.3,
        &[
            (0.7, 0.3, 0.0),
            (1.9, 1.0, 1.1),
            (3.3, 0.8, 2.3),
            (6.1, 0.6, 0.4),
            (11.0, 0.4, 5.0),
        ],
    )
}

/// The LHPOST's identified platen in its preset table system's loop.
fn rig(path: &Path) -> LoadedRig {
    LoadedRig::parse(
        path,
        r#"{"name": "LHPOST closed loop", "model": {"preset": "lhpost-2008"},
            "table_system": {"preset": "lhpost-2008"}}"#,
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let force = sine_force(100e3, SECONDS);
    let base_steps = (force.len() - 1) as u64;
    let path = PathBuf::from("lhpost-closed-loop.json");
    let loaded = rig(&path);
    let table = PlatenLoop::of_loaded(&loaded, &path).unwrap();
    let n = SECONDS * RATE_HZ as usize + 1;
    let t_s: Vec<f64> = (0..n).map(|j| j as f64 / RATE_HZ).collect();
    let a_m_s2: Vec<f64> = t_s.iter().map(|&t| quake(t)).collect();
    let target = Target::acceleration(&path, t_s, a_m_s2).unwrap();
    let motion = TargetMotion::new(
        &target,
        &BaselineSettings::default(),
        loaded.rig.limits.stroke_m,
        RATE_HZ,
    )
    .unwrap();
    let settings = IterationSettings {
        max_iterations: 10,
        target_nrmse: 0.0,
        stall_iterations: 100,
        frf: FrfSource::Linearised,
        ..Default::default()
    };
    let it = iterate(&table, &motion, &settings).unwrap();
    let first = it.records[0].acceleration_nrmse;
    let best = it.best_record().acceleration_nrmse;
    let ms = max_scale(&table, &motion, &MaxScaleSettings::default()).unwrap();
    println!(
        "plan, {SECONDS} s target: {} iterations, acceleration NRMSE {:.2} % → {:.2} % \
         (iteration {}); max_scale {:.4} in {} runs",
        it.records.len() - 1,
        100.0 * first,
        100.0 * best,
        it.best,
        ms.scale,
        ms.runs
    );
    let mut group = c.benchmark_group("plan");
    group.sample_size(SAMPLE_SIZE);
    group.bench_function("plain_loop_baseline", |b| {
        timed(b, "plan/plain_loop_baseline", || {
            baseline_rk4(&params, black_box(&force), 1.0 / RATE_HZ, State::default())
        })
    });
    group.bench_function("iterate_10", |b| {
        timed(b, "plan/iterate_10", || {
            iterate(&table, black_box(&motion), &settings).unwrap().best
        })
    });
    group.bench_function("max_scale", |b| {
        timed(b, "plan/max_scale", || {
            max_scale(&table, black_box(&motion), &MaxScaleSettings::default())
                .unwrap()
                .scale
        })
    });
    group.finish();
    report_ratios(
        &format!("plan, {SECONDS} s synthetic target at 1024 Hz, per target sample"),
        SAMPLE_SIZE,
        ("plan/plain_loop_baseline", base_steps),
        &[
            ("plan/iterate_10", base_steps),
            ("plan/max_scale", base_steps),
        ],
        "sample",
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
