//! Identification of the paper's whole S/T program (24 recorded-like tests at 13.8 MPa,
//! 512 Hz like the paper's recorder, with the data system's artefacts) on one core.
//! Target (issue): under 1 s. The records are made once, outside the timing.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use platen::ident::{identify, Settings, TestRecord};
use platen::integrate::{inverse, Trajectory};
use platen::model::{preset, PlatenModel};
use platen::scenario::generate::{sine_motion, triangle_motion};
use platen::scenario::recorded::{recorded_like, ArtefactSettings};

const RATE_HZ: f64 = 512.0;

/// The 24 tests of scenarios/paper-tests/13.8MPa as recorded-like data.
fn program() -> Vec<TestRecord> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper-tests/13.8MPa");
    let model = preset::lhpost_2008_identified(13.8e6).build().unwrap();
    let mut out = Vec::new();
    for (k, name) in (1..=12)
        .map(|k| format!("S{k}"))
        .chain((1..=12).map(|k| format!("T{k}")))
        .enumerate()
    {
        let v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(format!("{name}.json"))).unwrap(),
        )
        .unwrap();
        let d = v["duration_s"].as_f64().unwrap();
        let e = &v["excitation"];
        let motion = if let Some(s) = e.get("sine_motion") {
            sine_motion(
                s["amplitude_m"].as_f64().unwrap(),
                s["frequency_hz"].as_f64().unwrap(),
                RATE_HZ,
                d,
            )
        } else {
            let t = &e["triangle_motion"];
            triangle_motion(
                t["amplitude_m"].as_f64().unwrap(),
                t["velocity_m_s"].as_f64().unwrap(),
                t["reversal_acceleration_m_s2"].as_f64().unwrap(),
                RATE_HZ,
                d,
            )
        }
        .unwrap();
        let mut truth = Trajectory::with_capacity(motion.len());
        inverse(&model, &motion, &mut truth);
        let rec = recorded_like(
            &truth,
            model.static_threshold_n(0.0),
            &ArtefactSettings::default(),
            100 + k as u64,
        )
        .unwrap();
        out.push(
            TestRecord::new(&name, &rec.t_s, rec.u_m, rec.a_m_s2, rec.force_n)
                .unwrap()
                .with_velocity(rec.v_m_s)
                .unwrap()
                .with_pressure_pa(13.8e6)
                .unwrap(),
        );
    }
    out
}

fn bench(c: &mut Criterion) {
    let tests = program();
    let settings = Settings::default().build().unwrap();
    let mut group = c.benchmark_group("identification");
    group.sample_size(10);
    group.bench_function("paper_s_t_program_24_tests", |b| {
        b.iter(|| identify(black_box(&tests), &settings).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
