//! `platen simulate`: run a scenario, stream its time series to CSV, summarise it.
//!
//! The CSV is written as the samples are produced ([`CsvStream`]), to a temporary file next to
//! the target that is renamed over it when the run is complete and removed if it fails, so a
//! one-hour 1024 Hz run holds no trajectory in memory. The bytes are those that
//! [`platen_scenario::csv_io::write_csv_atomic`] writes for the same columns.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde_json::{json, Map, Value};

use platen_integrate::{ForwardIntegrator, Peaks, RunStats, Sample, SampleSink, Trajectory};
use platen_model::STANDARD_GRAVITY_M_S2;
use platen_scenario::csv_io::{create_temp_next_to, write_number};
use platen_scenario::{Run, RunOutput, Scenario, ScenarioError};

pub fn run(path: &Path, out: Option<&Path>, json_out: bool) -> Result<()> {
    let scenario = Scenario::load(path)?;
    // Create the temporary output first, so that an unwritable path fails before the run.
    let mut stream = out
        .map(|p| CsvStream::create(p, &Trajectory::COLUMN_NAMES))
        .transpose()?;
    let RunOutput { peaks, stats } = match stream.as_mut() {
        Some(sink) => scenario.run(sink)?,
        None => scenario.run(&mut NoOutput)?,
    };
    if let Some(stream) = stream {
        stream.finish()?;
    }
    let summary = summary_json(path, &scenario, &peaks, stats.as_ref(), out);
    if json_out {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_summary(&scenario, &peaks, stats.as_ref(), out);
    }
    Ok(())
}

/// A sink that keeps nothing (the summary's [`Peaks`] are collected alongside).
struct NoOutput;

impl SampleSink for NoOutput {
    #[inline]
    fn accept(&mut self, _: &Sample) {}
}

/// Capacity of the write buffer, bytes.
const BUFFER_BYTES: usize = 1 << 16;

/// A [`SampleSink`] that writes the contract's columns (in the order of
/// [`Trajectory::COLUMN_NAMES`]) as CSV rows while the run produces them.
///
/// Rows go to a temporary file next to the destination (`.NAME.PID.sN.tmp`);
/// [`CsvStream::finish`] flushes, syncs and renames it over the destination. Dropping the
/// stream without finishing it (a failed run) removes the temporary file and leaves an
/// existing destination untouched. Numbers are formatted by `write_number`, exactly as
/// `write_csv_atomic` formats them, so the file has the same bytes; a non-finite value is an
/// error naming the line it would have had, as there.
pub struct CsvStream {
    path: PathBuf,
    temp: PathBuf,
    header: &'static [&'static str],
    out: Option<BufWriter<File>>,
    rows: u64,
    error: Option<ScenarioError>,
}

impl CsvStream {
    /// Creates the temporary file next to `path` and writes the header.
    ///
    /// # Errors
    /// [`ScenarioError::Io`] if the temporary file cannot be created or written.
    pub fn create(path: &Path, header: &'static [&'static str]) -> Result<Self, ScenarioError> {
        let (temp, file) = create_temp_next_to(path)?;
        let mut stream = Self {
            path: path.to_path_buf(),
            temp,
            header,
            out: Some(BufWriter::with_capacity(BUFFER_BYTES, file)),
            rows: 0,
            error: None,
        };
        let line = header.join(",");
        if let Some(out) = stream.out.as_mut() {
            let written = out
                .write_all(line.as_bytes())
                .and_then(|()| out.write_all(b"\n"));
            if let Err(source) = written {
                return Err(write_error(path, source));
            }
        }
        Ok(stream)
    }

    /// Writes one row; the first error is kept and later rows are skipped.
    fn write_row(&mut self, values: &[f64]) {
        if self.error.is_some() {
            return;
        }
        let Some(out) = self.out.as_mut() else { return };
        if let Some(j) = values.iter().position(|v| !v.is_finite()) {
            self.error = Some(ScenarioError::NonFinite {
                path: self.path.clone(),
                line: self.rows + 2,
                column: self.header[j].to_owned(),
                value: values[j].to_string(),
            });
            return;
        }
        let written = (|| {
            for (j, &value) in values.iter().enumerate() {
                if j > 0 {
                    out.write_all(b",")?;
                }
                write_number(out, value)?;
            }
            out.write_all(b"\n")
        })();
        match written {
            Ok(()) => self.rows += 1,
            Err(source) => self.error = Some(write_error(&self.path, source)),
        }
    }

    /// Flushes and syncs the temporary file and renames it over the destination.
    ///
    /// # Errors
    /// The first error met while writing ([`ScenarioError::Io`] or
    /// [`ScenarioError::NonFinite`]), or one of flushing, syncing or renaming. The temporary
    /// file is removed on any error.
    pub fn finish(mut self) -> Result<(), ScenarioError> {
        if let Some(error) = self.error.take() {
            return Err(error);
        }
        let Some(out) = self.out.take() else {
            return Ok(());
        };
        let file = out
            .into_inner()
            .map_err(|e| write_error(&self.path, e.into_error()))?;
        file.sync_all()
            .map_err(|source| write_error(&self.path, source))?;
        drop(file);
        fs::rename(&self.temp, &self.path).map_err(|source| ScenarioError::Io {
            path: self.path.clone(),
            action: "renaming the temporary file onto",
            source,
        })?;
        // Renamed: nothing left for `drop` to remove.
        self.temp = PathBuf::new();
        sync_directory(directory_of(&self.path));
        Ok(())
    }
}

impl Drop for CsvStream {
    fn drop(&mut self) {
        self.out = None;
        if !self.temp.as_os_str().is_empty() {
            // Best effort: the error that led here is the one worth reporting.
            let _ = fs::remove_file(&self.temp);
        }
    }
}

impl SampleSink for CsvStream {
    #[inline]
    fn accept(&mut self, s: &Sample) {
        self.write_row(&[
            s.t_s,
            s.u_m,
            s.v_m_s,
            s.a_m_s2,
            s.terms.actuator_n,
            s.terms.inertial_n,
            s.terms.elastic_n,
            s.terms.dissipative_n,
        ]);
    }
}

fn write_error(path: &Path, source: io::Error) -> ScenarioError {
    ScenarioError::Io {
        path: path.to_path_buf(),
        action: "writing",
        source,
    }
}

/// The folder that holds `path` (`.` for a bare file name).
fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// Makes the rename durable where the platform allows it (best effort).
fn sync_directory(dir: &Path) {
    #[cfg(unix)]
    if let Ok(handle) = File::open(dir) {
        let _ = handle.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

fn summary_json(
    path: &Path,
    s: &Scenario,
    peaks: &Peaks,
    stats: Option<&RunStats>,
    out: Option<&Path>,
) -> Value {
    let mut m = Map::new();
    m.insert("scenario".into(), json!(path.display().to_string()));
    m.insert("name".into(), json!(s.name));
    m.insert(
        "direction".into(),
        json!(if stats.is_some() {
            "forward"
        } else {
            "inverse"
        }),
    );
    m.insert("model_form".into(), json!(s.model.form()));
    m.insert("preset".into(), json!(s.preset.name()));
    m.insert(
        "hold_down_pressure_mpa".into(),
        json!(s.hold_down_pressure_pa / 1e6),
    );
    m.insert("samples".into(), json!(peaks.samples));
    m.insert("duration_s".into(), json!(peaks.span_s.1 - peaks.span_s.0));
    for (key, peak) in [
        ("peak_u_m", peaks.u_m),
        ("peak_v_m_s", peaks.v_m_s),
        ("peak_a_m_s2", peaks.a_m_s2),
        ("peak_force_n", peaks.force_n),
    ] {
        m.insert(key.into(), json!(peak.value));
        m.insert(format!("{key}_t_s"), json!(peak.t_s));
    }
    if let Some(st) = stats {
        m.insert("stick_time_s".into(), json!(st.stick_time_s));
        m.insert("stick_events".into(), json!(st.stick_events));
        m.insert("breakaways".into(), json!(st.breakaways));
        m.insert("reversals".into(), json!(st.reversals));
        let method = match &s.run {
            Run::Forward { integrator, .. } => integrator.name(),
            Run::Inverse { .. } => "none",
        };
        m.insert(
            "solver".into(),
            json!({
                "method": method,
                "steps": st.steps,
                "accepted_steps": st.accepted_steps,
                "rejected_steps": st.rejected_steps,
                "rhs_evaluations": st.rhs_evaluations,
                "events_located": st.events(),
                "root_iterations": st.root_iterations,
            }),
        );
        let e = &st.energy;
        m.insert(
            "energy".into(),
            json!({
                "actuator_work_j": e.actuator_work_j,
                "kinetic_start_j": e.kinetic_start_j,
                "kinetic_end_j": e.kinetic_end_j,
                "elastic_start_j": e.elastic_start_j,
                "elastic_end_j": e.elastic_end_j,
                "dissipated_j": e.dissipated_j,
                "residual_j": e.residual_j(),
                "relative_residual": e.relative_residual(),
            }),
        );
    }
    let exceed: Vec<Value> = peaks
        .exceedances(&s.limits)
        .iter()
        .map(|e| json!({"quantity": e.quantity, "peak": e.peak, "limit": e.limit, "t_s": e.t_s}))
        .collect();
    m.insert("limit_exceedances".into(), Value::Array(exceed));
    // Every limit with the run's peak against it, so a report can say which ones it respects.
    let l = &s.limits;
    let check = |peak: f64, limit: f64| json!({"limit": limit, "peak": peak, "respected": peak.abs() <= limit});
    m.insert(
        "limits".into(),
        json!({
            "stroke_m": check(peaks.u_m.value, l.stroke_m),
            "velocity_m_s": check(peaks.v_m_s.value, l.velocity_m_s),
            "acceleration_m_s2": check(peaks.a_m_s2.value, l.acceleration_m_s2),
            "force_n": check(peaks.force_n.value, l.force_n),
        }),
    );
    m.insert("out".into(), json!(out.map(|p| p.display().to_string())));
    Value::Object(m)
}

fn print_summary(s: &Scenario, peaks: &Peaks, stats: Option<&RunStats>, out: Option<&Path>) {
    let dir = if stats.is_some() {
        "forward (force → motion)"
    } else {
        "inverse (motion → force)"
    };
    println!(
        "{}: {dir}, {} model, {} at {:.2} MPa",
        s.name,
        s.model.form(),
        s.preset.name(),
        s.hold_down_pressure_pa / 1e6
    );
    println!(
        "  {} samples over {:.3} s",
        peaks.samples,
        peaks.span_s.1 - peaks.span_s.0
    );
    println!(
        "  peak displacement {:>+10.4} m     at {:.3} s",
        peaks.u_m.value, peaks.u_m.t_s
    );
    println!(
        "  peak velocity     {:>+10.4} m/s   at {:.3} s",
        peaks.v_m_s.value, peaks.v_m_s.t_s
    );
    println!(
        "  peak acceleration {:>+10.4} m/s²  at {:.3} s ({:.3} g)",
        peaks.a_m_s2.value,
        peaks.a_m_s2.t_s,
        peaks.a_m_s2.value / STANDARD_GRAVITY_M_S2
    );
    println!(
        "  peak force        {:>+10.1} kN    at {:.3} s",
        peaks.force_n.value / 1e3,
        peaks.force_n.t_s
    );
    if let (Some(st), Run::Forward { integrator, .. }) = (stats, &s.run) {
        println!(
            "  stick: {:.3} s in all, {} stops, {} breakaways, {} reversals",
            st.stick_time_s, st.stick_events, st.breakaways, st.reversals
        );
        println!(
            "  solver: {}, {} steps ({} rejected), {} right-hand-side evaluations, {} events located",
            integrator.name(),
            st.steps,
            st.rejected_steps,
            st.rhs_evaluations,
            st.events()
        );
        println!(
            "  energy: actuator work {:.4e} J = ΔE_kin + ΔE_el + dissipated {:.4e} J; residual {:.2e} J ({:.1e} relative)",
            st.energy.actuator_work_j,
            st.energy.dissipated_j,
            st.energy.residual_j(),
            st.energy.relative_residual()
        );
    }
    let ex = peaks.exceedances(&s.limits);
    if ex.is_empty() {
        let l = &s.limits;
        println!(
            "  within the table's limits (stroke ±{} m, {} m/s, {:.1} g, {:.1} MN)",
            l.stroke_m,
            l.velocity_m_s,
            l.acceleration_m_s2 / STANDARD_GRAVITY_M_S2,
            l.force_n / 1e6
        );
    }
    for e in ex {
        println!(
            "  EXCEEDS {} limit: peak {:+.4} vs limit {:.4} (SI units) at {:.3} s",
            e.quantity, e.peak, e.limit, e.t_s
        );
    }
    if let Some(out) = out {
        println!("  wrote {}", out.display());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use platen_model::ForceTerms;
    use platen_scenario::csv_io::write_csv_atomic;

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
        }
    }

    /// The streamed file has the bytes that `write_csv_atomic` writes for the same run kept
    /// in memory, for each direction, model form and integrator of the shipped scenarios.
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
            let scenario = Scenario::load(&shipped(name)).unwrap();
            let mut trajectory = Trajectory::default();
            let in_memory_output = scenario.run(&mut trajectory).unwrap();
            let in_memory = dir.path().join("memory.csv");
            write_csv_atomic(&in_memory, &Trajectory::COLUMN_NAMES, &trajectory.columns()).unwrap();
            let streamed = dir.path().join("streamed.csv");
            let mut stream = CsvStream::create(&streamed, &Trajectory::COLUMN_NAMES).unwrap();
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
            let mut stream = CsvStream::create(&out, &Trajectory::COLUMN_NAMES).unwrap();
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
        let mut stream = CsvStream::create(&out, &Trajectory::COLUMN_NAMES).unwrap();
        stream.accept(&sample(0, 0.0));
        stream.accept(&sample(1, f64::NAN));
        stream.accept(&sample(2, 0.0));
        let error = stream.finish().unwrap_err();
        match &error {
            ScenarioError::NonFinite { line, column, .. } => {
                assert_eq!((*line, column.as_str()), (3, "u_m"), "{error}");
            }
            other => panic!("unexpected error {other}"),
        }
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
