//! The streamed CSV output of a run ([`CsvSink`]): the same bytes as the trajectory written
//! from memory, nothing left behind when a run fails, non-finite values located.

use std::fs;
use std::path::{Path, PathBuf};

use platen_integrate::{Sample, SampleSink, Trajectory};
use platen_io::csv::write_csv_atomic;
use platen_io::IoError;
use platen_model::ForceTerms;
use platen_scenario::{CsvSink, PlatenScenario, ScenarioError};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios")
        .join(name)
}

fn sample(index: usize, u_m: f64) -> Sample {
    Sample {
        index,
        t_s: index as f64,
        u_m,
        v_m_s: 0.0,
        a_m_s2: 0.0,
        terms: ForceTerms::default(),
        stuck: true,
        specimen: None,
        system: None,
    }
}

/// The streamed file has the bytes that `write_csv_atomic` writes for the same run kept in
/// memory, for each direction, model form and integrator of the shipped scenarios.
#[test]
fn the_streamed_csv_equals_the_one_written_from_memory() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "sr9-like-sine-force.json",
        "paper-forward-force.json",
        "paper-forward-force-dopri5.json",
        "full-model-large-stroke.json",
        "s9-sine-motion.json",
    ] {
        let scenario = PlatenScenario::load(&shipped(name)).unwrap();
        let mut trajectory = Trajectory::default();
        let in_memory_output = scenario.run(&mut trajectory).unwrap();
        let in_memory = dir.path().join("memory.csv");
        write_csv_atomic(&in_memory, &Trajectory::COLUMN_NAMES, &trajectory.columns()).unwrap();
        let streamed = dir.path().join("streamed.csv");
        let mut stream = CsvSink::create(&streamed).unwrap();
        let streamed_output = scenario.run(&mut stream).unwrap();
        stream.finish().unwrap();
        assert_eq!(
            fs::read(&streamed).unwrap(),
            fs::read(&in_memory).unwrap(),
            "{name}"
        );
        assert_eq!(streamed_output, in_memory_output, "{name}");
    }
    let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 2, "no temporary file left behind");
}

#[test]
fn an_unfinished_stream_removes_its_temporary_file_and_keeps_the_previous_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    fs::write(&out, "previous result\n").unwrap();
    {
        let mut stream = CsvSink::create(&out).unwrap();
        stream.accept(&sample(0, 0.0));
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
        // Dropped without `finish`, as when the run fails.
    }
    assert_eq!(fs::read_to_string(&out).unwrap(), "previous result\n");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn a_non_finite_value_is_reported_with_its_line_and_column_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    let mut stream = CsvSink::create(&out).unwrap();
    stream.accept(&sample(0, 0.0));
    stream.accept(&sample(1, f64::NAN));
    stream.accept(&sample(2, 0.0));
    let error = stream.finish().unwrap_err();
    match &error {
        ScenarioError::Io(IoError::NonFinite { line, column, .. }) => {
            assert_eq!((*line, column.as_str()), (3, "u_m"), "{error}");
        }
        other => panic!("unexpected error {other}"),
    }
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
}
