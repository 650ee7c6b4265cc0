//! `identify --system` (the whole loop: skews, gains, plant, and the judging runs with the
//! black box) on a small table's records as a lab exports them (`tests/data/small_table`,
//! 204.8 Hz, 40 s each), with 1, 2 and 4 training records and one held out, so the time per
//! second of data shows (issue 33: cost linear in the data; four 90 s records under 30 s).
//! The records are read once, outside the timing.

// criterion's macros generate undocumented items.
#![allow(missing_docs)]

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use platen::app::read_system_records;
use platen::ident::system::{identify_system, SystemSettings};
use platen::io::columns::ColumnMap;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/small_table")
        .join(name)
}

fn bench(c: &mut Criterion) {
    let map = ColumnMap::load(&data("columns.json")).unwrap();
    let training = ["wn.csv", "sweep.csv", "eq1.csv", "eq2.csv"];
    let mut group = c.benchmark_group("identify_system");
    group.sample_size(10);
    for n in [1usize, 2, 4] {
        let files: Vec<PathBuf> = training[..n]
            .iter()
            .chain(&["eq4.csv"])
            .map(|f| data(f))
            .collect();
        let records = read_system_records(&files, &map).unwrap();
        let samples: usize = records.iter().map(|r| r.t_s.len()).sum();
        let fit: Vec<bool> = (0..files.len()).map(|i| i < n).collect();
        let settings = SystemSettings {
            judge: true,
            ..SystemSettings::default()
        };
        group.throughput(Throughput::Elements(samples as u64));
        group.bench_with_input(BenchmarkId::new("training_records", n), &n, |b, _| {
            b.iter(|| black_box(identify_system(&records, &fit, &settings).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
