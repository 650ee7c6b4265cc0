//! Three-component test planning on the LHPOST6 (`platen plan` on a multi-axis scenario):
//! 10 drive corrections of a 40 s three-component acceleration target through the table's
//! linearised transfer matrix, the speed goal (under 30 s on one core). Each planning
//! task is one feasibility run of the target's own commands (iteration 0) and 10 corrected
//! runs: 11 closed-loop runs of the six-DOF table at its 2048 Hz controller. Two tables:
//!
//! * `lhpost6_bare`: the `lhpost6` preset alone;
//! * `lhpost6_tower`: with the shipped 120 t, 12 m eccentric tower of
//!   `scenarios/multi-axis/lhpost6-northridge-25.json` (six more DOFs, and the rocking that
//!   loads the vertical actuators).
//!
//! The target is synthetic (no PEER record needed): per axis five sines under a rise–hold–decay
//! envelope, 1024 Hz, peaks near Tarzana's at 25 % (x 0.25 g, y 0.2 g, z 0.15 g). The
//! plain-loop baseline (`baseline_rk4`, 40 s at 1024 Hz) is measured in the same run; the
//! ratio is per 1024 Hz target sample of one whole planning task.
//!
//! Run: `cargo bench --bench plan_three_component -- --warm-up-time 1 --measurement-time 10`
//! (each sample is one planning task of tens of seconds: about 10 minutes in all).

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use platen::integrate::State;
use platen::model::preset;
use platen::plan::six_dof::table_scenario_file;
use platen::plan::{
    plan_multi_axis, synthetic_three_component_m_s2, AxisTargets, IterationSettings, PlanSettings,
    Target,
};
use platen::scenario::file::ScenarioFile;

use common::baseline::baseline_rk4;
use common::{report_ratios, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 10;
const SECONDS: usize = 40;

/// The three axes' targets ([`synthetic_three_component_m_s2`]), each with its own spectrum.
fn targets(origin: &Path) -> AxisTargets {
    let n = SECONDS * RATE_HZ as usize + 1;
    let t_s: Vec<f64> = (0..n).map(|j| j as f64 / RATE_HZ).collect();
    let axes = synthetic_three_component_m_s2(&t_s)
        .map(|a| Some(Target::acceleration(origin, t_s.clone(), a).unwrap()));
    AxisTargets::new(origin, axes).unwrap()
}

/// The shipped LHPOST6 tower scenario without its record (and, for `bare`, its specimen).
fn scenario(path: &Path, bare: bool) -> ScenarioFile {
    let text = std::fs::read_to_string(path).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let object = value.as_object_mut().unwrap();
    object.remove("excitation");
    if bare {
        object.remove("specimen");
    }
    table_scenario_file(path, &value.to_string())
        .unwrap()
        .expect("a multi-axis scenario")
}

fn bench(c: &mut Criterion) {
    let params = preset::lhpost_2008_identified(PRESSURE_PA);
    let force = sine_force(100e3, SECONDS);
    let base_samples = (force.len() - 1) as u64;
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/multi-axis/lhpost6-northridge-25.json");
    let targets = targets(Path::new("three-component-quake"));
    let settings = PlanSettings {
        iteration: IterationSettings {
            max_iterations: 10,
            target_nrmse: 0.0,
            stall_iterations: 100,
            ..Default::default()
        },
        ..PlanSettings::default()
    };
    let tables = [
        ("lhpost6_bare", scenario(&path, true)),
        ("lhpost6_tower", scenario(&path, false)),
    ];
    for (name, file) in &tables {
        let plan = plan_multi_axis(&path, file, &targets, &settings, &mut |_| {}).unwrap();
        let it = plan.iteration().expect("the target fits: iterated");
        let records = &it.records;
        let best = it.best_record();
        println!(
            "{name}: {} iterations, overall acceleration NRMSE {:.2} % → {:.2} % (iteration {}), \
             feasible {}",
            records.len() - 1,
            100.0 * records[0].acceleration_nrmse,
            100.0 * best.acceleration_nrmse,
            it.best,
            plan.feasibility.feasible
        );
    }
    let mut group = c.benchmark_group("plan_three_component");
    group.sample_size(SAMPLE_SIZE);
    group.bench_function("plain_loop_baseline", |b| {
        timed(b, "plan_three_component/plain_loop_baseline", || {
            baseline_rk4(&params, black_box(&force), 1.0 / RATE_HZ, State::default())
        })
    });
    for (name, file) in &tables {
        let id = format!("plan_three_component/{name}_iterate_10");
        group.bench_function(format!("{name}_iterate_10"), |b| {
            timed(b, &id, || {
                plan_multi_axis(&path, file, black_box(&targets), &settings, &mut |_| {})
                    .unwrap()
                    .iteration()
                    .map(|it| it.best)
            })
        });
    }
    group.finish();
    report_ratios(
        &format!("plan, {SECONDS} s three-component target at 1024 Hz, per target sample"),
        SAMPLE_SIZE,
        ("plan_three_component/plain_loop_baseline", base_samples),
        &[
            ("plan_three_component/lhpost6_bare_iterate_10", base_samples),
            (
                "plan_three_component/lhpost6_tower_iterate_10",
                base_samples,
            ),
        ],
        "sample",
    );
    for (name, _) in &tables {
        let id = format!("plan_three_component/{name}_iterate_10");
        if let Some(ns) = common::median_ns(&id, SAMPLE_SIZE) {
            println!(
                "  {id}: median {:.2} s per planning task (goal: under 30 s)",
                ns * 1e-9
            );
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
