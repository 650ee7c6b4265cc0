//! Speed of the CSV writer (issue 28), in MB/s of output text, against a baseline measured in
//! the same run.
//!
//! The data: the standard workload's trajectory (a 100 kN, 0.5 Hz sine force at 1024 Hz for
//! 600 s, stepped at 1/1024 s on the `lhpost-2008` preset at 13.8 MPa from rest), the eight
//! columns `platen simulate --out` writes (`t_s` … `dissipative_force_n`), 614 401 rows,
//! about 88 MB of text.
//!
//! * `format_baseline`: the writer before issue 28, into a `Vec<u8>`: `write!(buf, "{}", x)`
//!   (or `{:e}` below 1e-5 and from 1e16 on) per value, commas and line ends;
//! * `format_ryu`: the same bytes with [`platen::io::number`] (Ryū, the writer's formatter
//!   since issue 28), into a `Vec<u8>`;
//! * `write_csv_file`: [`write_csv_atomic`] to a file in a temporary folder (formatting, the
//!   writes, sync and rename: the whole writer);
//! * `write_parquet_file`: [`write_parquet_atomic`], the same columns to a Parquet file
//!   (float64, uncompressed), the same way (its MB/s are of the CSV's text, for comparison).
//!
//! Criterion reports each in bytes/s; after the group the medians and the ratios to the
//! baseline are printed, with MB/s. Run:
//! `cargo bench --bench writer -- --warm-up-time 1 --measurement-time 5`.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

mod common;

use std::hint::black_box;
use std::io::Write;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use platen::integrate::{forward_rk4, ForceRecord, Rk4, State, Trajectory};
use platen::io::csv::write_csv_atomic;
use platen::io::number::{format_number, NumberBuffer};
use platen::io::parquet::write_parquet_atomic;
use platen::model::preset;

use common::{median_ns, sine_force, timed, PRESSURE_PA, RATE_HZ};

const SAMPLE_SIZE: usize = 10;
const SECONDS: usize = 600;

/// The standard workload's trajectory, 600 s.
fn trajectory() -> Trajectory {
    let model = preset::lhpost_2008_identified(PRESSURE_PA).build().unwrap();
    let record = ForceRecord::from_rate(RATE_HZ, sine_force(100e3, SECONDS)).unwrap();
    let mut out = Trajectory::with_capacity(record.len());
    forward_rk4(
        &model,
        &record,
        Rk4::with_steps_per_sample(1).unwrap(),
        State::default(),
        record.len(),
        &mut out,
    )
    .unwrap();
    out
}

/// The rows of `columns` as CSV text (no header), each value written by `number`.
fn rows(columns: &[&[f64]], out: &mut Vec<u8>, mut number: impl FnMut(&mut Vec<u8>, f64)) {
    out.clear();
    for i in 0..columns[0].len() {
        for (j, column) in columns.iter().enumerate() {
            if j > 0 {
                out.push(b',');
            }
            number(out, column[i]);
        }
        out.push(b'\n');
    }
}

/// The writer before issue 28: `{}`, or `{:e}` below 1e-5 and from 1e16 on.
fn std_number(out: &mut Vec<u8>, value: f64) {
    let magnitude = value.abs();
    let _ = if magnitude == 0.0 || (1e-5..1e16).contains(&magnitude) {
        write!(out, "{value}")
    } else {
        write!(out, "{value:e}")
    };
}

fn writer(c: &mut Criterion) {
    let trajectory = trajectory();
    let columns = trajectory.columns();
    let mut baseline_text = Vec::new();
    rows(&columns, &mut baseline_text, std_number);
    let mut ryu_text = Vec::new();
    let mut number = NumberBuffer::new();
    rows(&columns, &mut ryu_text, |out, v| {
        format_number(&mut number, out, v)
    });
    assert!(baseline_text == ryu_text, "the two formatters differ");
    let bytes = baseline_text.len() as u64;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("writer.csv");

    let group_name = "csv_writer";
    let key = |what: &str| format!("{group_name}/{what}");
    let mut group = c.benchmark_group(group_name);
    group.sample_size(SAMPLE_SIZE);
    group.throughput(Throughput::Bytes(bytes));
    let mut buf = Vec::with_capacity(baseline_text.len());
    group.bench_function("format_baseline", |b| {
        timed(b, &key("format_baseline"), || {
            rows(black_box(&columns), &mut buf, std_number);
            buf.len()
        })
    });
    group.bench_function("format_ryu", |b| {
        timed(b, &key("format_ryu"), || {
            rows(black_box(&columns), &mut buf, |out, v| {
                format_number(&mut number, out, v)
            });
            buf.len()
        })
    });
    group.bench_function("write_csv_file", |b| {
        timed(b, &key("write_csv_file"), || {
            write_csv_atomic(&path, &Trajectory::COLUMN_NAMES, black_box(&columns)).unwrap()
        })
    });
    let parquet = dir.path().join("writer.parquet");
    group.bench_function("write_parquet_file", |b| {
        timed(b, &key("write_parquet_file"), || {
            write_parquet_atomic(&parquet, &Trajectory::COLUMN_NAMES, black_box(&columns)).unwrap()
        })
    });
    group.finish();

    let Some(base) = median_ns(&key("format_baseline"), SAMPLE_SIZE) else {
        return;
    };
    println!(
        "\n{group_name}: {} rows, {:.1} MB; median time, MB/s, ratio of speeds to the baseline of this run",
        columns[0].len(),
        bytes as f64 / 1e6
    );
    for what in [
        "format_baseline",
        "format_ryu",
        "write_csv_file",
        "write_parquet_file",
    ] {
        if let Some(t) = median_ns(&key(what), SAMPLE_SIZE) {
            println!(
                "  {:<32} {:>8.1} ms {:>8.0} MB/s {:>6.2}",
                key(what),
                t / 1e6,
                bytes as f64 / (t / 1e9) / 1e6,
                base / t
            );
        }
    }
    println!();
}

criterion_group!(benches, writer);
criterion_main!(benches);
