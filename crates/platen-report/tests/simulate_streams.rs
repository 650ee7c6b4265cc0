//! `platen simulate` streams a multi-axis run as it streams a uniaxial one (issue 53): the
//! file, the summary and the figures it makes while the run goes, holding none of it, are
//! those of the same run held in memory and written whole, byte for byte. The in-memory
//! path is the one the library's `Scenario::run` gives (columns by name, the summary of the
//! whole columns, the figures of the whole columns); the streamed one gathers folds and
//! envelopes row by row. Equal bytes are the tolerance: both are the same arithmetic in
//! the same order, so any difference is a bug, not rounding.

use std::fs;
use std::path::{Path, PathBuf};

use platen_integrate::{Sample, SampleSink, TableSink};
use platen_report::simulate::{simulate, Outputs};
use platen_report::table_figures::write_table_figures;
use platen_report::FigureSize;
use platen_scenario::multi_axis::TableScenario;
use platen_scenario::Scenario;

/// A progress bar that counts.
#[derive(Default)]
struct Count(usize);

impl SampleSink for Count {
    fn accept(&mut self, _: &Sample) {
        self.0 += 1;
    }
}

impl TableSink for Count {
    fn start(&mut self, _: &[String], _: usize) {}

    fn accept(&mut self, _: &[f64]) {
        self.0 += 1;
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "platen-simulate-streams-{}-{name}",
        std::process::id()
    ));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// Every file of `dir` by name, with its bytes.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<_> = fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    out.sort();
    out
}

/// The scenario at `path`, streamed by `simulate` and held in memory, compared.
fn streamed_equals_held(path: &Path, name: &str) {
    let scenario = Scenario::load(path).unwrap();
    let Scenario::Table(table) = &scenario else {
        panic!("{} is a multi-axis scenario", path.display());
    };
    let dir = scratch(name);
    let (streamed_csv, streamed_figs) = (dir.join("streamed.csv"), dir.join("streamed"));
    let outputs = Outputs {
        out: Some(&streamed_csv),
        plot: Some(&streamed_figs),
        size: FigureSize::default(),
    };
    let mut count = Count::default();
    let simulated = simulate(&scenario, path, &outputs, &mut count).unwrap();

    // The same run held in memory, written whole.
    let (run, stats) = table.run_with_stats().unwrap();
    assert_eq!(count.0, run.len(), "every row ticks the progress bar");
    let held_csv = dir.join("held.csv");
    let header: Vec<&str> = run.columns.iter().map(|(n, _)| n.as_str()).collect();
    let columns: Vec<&[f64]> = run.columns.iter().map(|(_, c)| c.as_slice()).collect();
    platen_io::csv::write_csv_atomic(&held_csv, &header, &columns).unwrap();
    assert!(
        fs::read(&streamed_csv).unwrap() == fs::read(&held_csv).unwrap(),
        "{name}: the streamed CSV differs from the held run's"
    );
    assert_eq!(
        header,
        table.columns(),
        "{name}: the columns known before the run"
    );

    let held = table.summary_with(&run, stats.as_ref(), Some(&streamed_csv));
    let (a, b) = (
        serde_json::to_string(&simulated.summary).unwrap(),
        serde_json::to_string(&platen_scenario::Summary::Table(Box::new(held))).unwrap(),
    );
    assert_eq!(
        a, b,
        "{name}: the streamed summary differs from the held run's"
    );

    let held_figs = dir.join("held");
    write_table_figures(
        &run,
        &table.table,
        Some(&table.force_limits_n()),
        table.flow_capacities_m3_s().as_deref(),
        &held_figs,
        FigureSize::default(),
    )
    .unwrap();
    let (s, h) = (files(&streamed_figs), files(&held_figs));
    assert!(!s.is_empty(), "{name}: figures drawn");
    assert_eq!(
        s.iter().map(|f| &f.0).collect::<Vec<_>>(),
        h.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for ((file, a), (_, b)) in s.iter().zip(&h) {
        assert!(a == b, "{name}: figure {file} differs from the held run's");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_forward_run_streams_as_held() {
    // 2 001 rows with friction: every sample of the envelopes kept.
    streamed_equals_held(&root().join("scenarios/multi-axis/forward.json"), "forward");
}

#[test]
fn an_inverse_run_with_a_specimen_streams_as_held() {
    // 4 001 rows, past the envelopes' 2 200: bucketed, the overturning moments' peak.
    streamed_equals_held(
        &root().join("scenarios/multi-axis/tower-inverse.json"),
        "tower-inverse",
    );
}

#[test]
fn a_closed_loop_streams_as_held() {
    // A closed loop of sines on the LHPOST6: its tracking sums and drives' saturation.
    let dir = scratch("loop-scenario");
    let path = dir.join("lhpost6-sines.json");
    fs::write(
        &path,
        r#"{"name": "lhpost6 sines", "table": {"preset": "lhpost6"}, "duration_s": 2.5,
 "excitation": {"sine_motion": {
   "x": {"amplitude_m": 0.02, "frequency_hz": 1.0, "sample_rate_hz": 1024},
   "y": {"amplitude_m": 0.01, "frequency_hz": 1.5, "sample_rate_hz": 1024},
   "z": {"amplitude_m": 0.002, "frequency_hz": 3.0, "sample_rate_hz": 1024}}}}"#,
    )
    .unwrap();
    streamed_equals_held(&path, "loop");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn an_unwritable_output_fails_before_the_run() {
    let path = root().join("scenarios/multi-axis/forward.json");
    let scenario = Scenario::load(&path).unwrap();
    let dir = scratch("unwritable");
    // A folder that cannot be made: a file stands where it would be.
    fs::write(dir.join("a-file"), "not a folder").unwrap();
    let out = dir.join("a-file/out.csv");
    let outputs = Outputs {
        out: Some(&out),
        plot: None,
        size: FigureSize::default(),
    };
    let mut count = Count::default();
    let err = simulate(&scenario, &path, &outputs, &mut count).unwrap_err();
    assert_eq!(count.0, 0, "no row was computed: {err}");
    assert!(err.to_string().contains("a-file"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

/// A multi-axis scenario's columns are known before its run (the header written first).
#[test]
fn the_columns_are_known_before_the_run() {
    let path = root().join("scenarios/multi-axis/bare-inverse.json");
    let Scenario::Table(table) = Scenario::load(&path).unwrap() else {
        panic!("multi-axis");
    };
    let table: &TableScenario = &table;
    let run = table.run().unwrap();
    let names: Vec<String> = run.columns.iter().map(|(n, _)| n.clone()).collect();
    assert_eq!(names, table.columns());
    assert_eq!(run.len(), table.output_t_s().len());
}
