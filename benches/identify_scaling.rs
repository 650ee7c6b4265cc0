//! How the any-record identification ([`identify_records`]) scales with the records (issue
//! 33): 1, 2, 4, 8, 16 and 34 records of a small table, 90 s each at 204.8 Hz (18 433
//! samples), identified jointly by the equation error alone and with the output-error check.
//! Criterion reports each as time and samples per second (`Throughput`); after each group the
//! median time per record and per sample is printed, which stays about constant when the
//! cost is linear in the data. The equation error runs on one core; the output-error check's
//! forward runs use every core (rayon's pool), so its figures depend on the machine's cores:
//! give them with the core count. 34 records (51 minutes, 626 722 samples) is the case of
//! issue 33; with the output-error check it takes over half a minute a run on two cores, so it
//! is measured only when `PLATEN_BENCH_34_OE` is set.
//!
//! The records are made once, outside the timing, by platen's own generators with fixed
//! seeds: a small table (2.5 t, [`small_table`]: made up for the bench, not a preset) run
//! forward (RK4, 4 steps per sample, exact stick-slip) from rest under a band-limited random
//! force (the acceleration of [`white_noise_motion`], 0.3–15 Hz, scaled to 5 kN RMS, ramped
//! over 5 s at both ends; the table then moves up to ±0.18 m at about 1 g), with white
//! noise on the displacement (0.02 mm), acceleration (0.03 m/s²) and force (20 N). No
//! velocity channel: the crossover estimate is used, as for lab files.
//!
//! **Stand-ins for real records (issue 51).** When `PLATEN_REAL_STANDINS` names a folder of
//! the 34 stand-ins written by `python3 tools/reference/real_table_records.py DIR` (numpy,
//! about 10 minutes; 55 minutes of records, 673 000 samples: a small table whose viscous
//! exponent the records barely fix, unequal lengths, per-record skews, 30–50 Hz content,
//! long stretches below the speed threshold), the first 1, 2, 4, 8, 16 and 34 of them
//! (sorted by name, read with the folder's `columns-anyrecord.json`) are timed too, by the
//! equation error alone and with the output-error check, and after each group the slope of
//! log time against log records (least squares) is printed: 1 for a cost linear in the
//! records. Without the variable the group is skipped with a message that says how to make
//! the folder. The output-error check on 16 and 34 of them takes minutes a run: it is
//! measured only when `PLATEN_BENCH_34_OE` is set.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::app::records::{read_records, RecordRequest};
use platen::ident::{identify_records, RecordSettings, TestRecord};
use platen::integrate::{forward_rk4, ForceRecord, Rk4, State, Trajectory};
use platen::io::columns::ColumnMap;
use platen::model::IdentifiedParams;
use platen::scenario::generate::{white_noise_motion, SplitMix64};

/// Sample rate of the records, Hz.
const RATE_HZ: f64 = 204.8;
/// Length of each record, s.
const SECONDS: f64 = 90.0;
/// The record counts timed.
const COUNTS: [usize; 6] = [1, 2, 4, 8, 16, 34];

/// The small table: 2.5 t, 40 kN/m (0.64 Hz), F_μ 400 N, Cₑ 1.5 kN/(m/s)^0.6, α 0.6,
/// a 150 N, b 60 s/m.
fn small_table() -> IdentifiedParams {
    IdentifiedParams {
        effective_mass_kg: 2500.0,
        stiffness_n_per_m: 40e3,
        coulomb_force_n: 400.0,
        viscous_coefficient: 1500.0,
        viscous_exponent: 0.6,
        low_velocity_force_n: 150.0,
        low_velocity_decay_s_per_m: 60.0,
    }
}

/// Record `k`: the small table under its own random force (seed `1000 + k`), with noise
/// (seed `77 + k`).
fn record(k: u64) -> TestRecord {
    let shape = white_noise_motion(1.0, (0.3, 15.0), 1000 + k, RATE_HZ, SECONDS).unwrap();
    let n = shape.len();
    let force: Vec<f64> = shape
        .a_m_s2()
        .iter()
        .enumerate()
        .map(|(j, a)| {
            let t = j as f64 / RATE_HZ;
            let ramp = (t / 5.0).min(1.0) * ((SECONDS - t) / 5.0).clamp(0.0, 1.0);
            5e3 * ramp * a
        })
        .collect();
    let model = small_table().build().unwrap();
    let input = ForceRecord::from_rate(RATE_HZ, force.clone()).unwrap();
    let mut out = Trajectory::with_capacity(n);
    let rk4 = Rk4::with_steps_per_sample(4).unwrap();
    forward_rk4(&model, &input, rk4, State::default(), n, &mut out).unwrap();
    let mut rng = SplitMix64::new(77 + k);
    let u = out.u_m.iter().map(|u| u + 2e-5 * rng.normal()).collect();
    let a = out.a_m_s2.iter().map(|a| a + 0.03 * rng.normal()).collect();
    let f = force.iter().map(|f| f + 20.0 * rng.normal()).collect();
    TestRecord::from_rate(format!("small-{k}"), RATE_HZ, u, a, f).unwrap()
}

/// Times `identify_records` on the first `count` records of `records` for each count, and
/// prints the median time per record and per sample.
fn scaling(c: &mut Criterion, name: &str, records: &[TestRecord], counts: &[usize], oe: bool) {
    let settings = RecordSettings {
        output_error: oe,
        ..RecordSettings::default()
    }
    .build()
    .unwrap();
    let mut group = c.benchmark_group(name);
    // One identification of 16 records with the output-error check takes half a minute:
    // ten samples, no warm-up beyond one run.
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_secs(1));
    let mut rows = Vec::new();
    for &count in counts {
        let set = &records[..count];
        let samples: usize = set.iter().map(TestRecord::len).sum();
        group.throughput(Throughput::Elements(samples as u64));
        let id = format!("{name}/{count}");
        group.bench_with_input(BenchmarkId::from_parameter(count), &set, |b, set| {
            common::timed(b, &id, || identify_records(set, &settings).unwrap())
        });
        rows.push((id, count, samples));
    }
    group.finish();
    println!("\n{name}: median time per run, per record and per sample");
    let mut points = Vec::new();
    for (id, count, samples) in rows {
        if let Some(t) = common::median_ns(&id, 10) {
            points.push(((count as f64).ln(), (t * 1e-9).ln()));
            println!(
                "  {count:>3} records {samples:>7} samples  {:>9.3} s  {:>7.3} s/record  {:>7.1} ns/sample",
                t * 1e-9,
                t * 1e-9 / count as f64,
                t / samples as f64
            );
        }
    }
    if let Some(slope) = slope(&points) {
        println!("  slope of log time against log records (least squares): {slope:.3}");
    }
    println!();
}

/// The least-squares slope of `y` against `x` (`None` for fewer than two distinct `x`).
fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (points.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

/// The stand-ins for real records in the folder `PLATEN_REAL_STANDINS` names, sorted by
/// file name, read with its `columns-anyrecord.json`; `None` (and a message) without it.
fn real_standins() -> Option<Vec<TestRecord>> {
    let Some(dir) = std::env::var_os("PLATEN_REAL_STANDINS") else {
        println!(
            "identify_scaling_real_standins: skipped (PLATEN_REAL_STANDINS is not set). Make the \
             34 stand-ins with `python3 tools/reference/real_table_records.py DIR` (about 10 \
             minutes) and set PLATEN_REAL_STANDINS=DIR."
        );
        return None;
    };
    let dir = std::path::PathBuf::from(dir);
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("PLATEN_REAL_STANDINS={}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            name.starts_with('r') && name.ends_with(".csv") && !name.ends_with("-clean.csv")
        })
        .collect();
    files.sort();
    let columns = ColumnMap::load(&dir.join("columns-anyrecord.json"))
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let request = RecordRequest {
        files,
        columns,
        ..RecordRequest::default()
    };
    let records = read_records(&request)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .records;
    println!(
        "identify_scaling_real_standins: {} records, {} samples, from {}",
        records.len(),
        records.iter().map(TestRecord::len).sum::<usize>(),
        dir.display()
    );
    Some(records)
}

fn bench(c: &mut Criterion) {
    let records: Vec<TestRecord> = (0..*COUNTS.last().unwrap() as u64).map(record).collect();
    scaling(
        c,
        "identify_scaling_equation_error",
        &records,
        &COUNTS,
        false,
    );
    let with_oe: Vec<usize> = COUNTS
        .into_iter()
        .filter(|&n| n < 34 || std::env::var_os("PLATEN_BENCH_34_OE").is_some())
        .collect();
    scaling(
        c,
        "identify_scaling_with_output_error",
        &records,
        &with_oe,
        true,
    );
    if let Some(standins) = real_standins() {
        let counts: Vec<usize> = COUNTS
            .into_iter()
            .filter(|&n| n <= standins.len())
            .collect();
        scaling(
            c,
            "identify_scaling_real_standins_equation_error",
            &standins,
            &counts,
            false,
        );
        let with_oe: Vec<usize> = counts
            .iter()
            .copied()
            .filter(|&n| n < 16 || std::env::var_os("PLATEN_BENCH_34_OE").is_some())
            .collect();
        scaling(
            c,
            "identify_scaling_real_standins_with_output_error",
            &standins,
            &with_oe,
            true,
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
